//! `[lubrication]`: oil level, sump volume, gear axis heights, immersion; completes the checked
//! gears.

use serde::{Deserialize, Serialize};

use super::common::*;
use super::gears::{Gear, GearMount};
use super::meshes::Mesh;
use super::parts::Parts;
use super::planetary_sets::{Mounts, PlanetarySet};
use crate::model::problems::Problems;

/// `[lubrication]` as written: dip lubrication geometry. Heights share one vertical datum (any, e.g. the sump floor).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LubricationSpec {
    /// Height of the static oil surface, mm.
    pub oil_level_mm: f64,
    /// Height of each non-planet gear's axis, mm, keyed by gear name. Planets orbit: their immersion
    /// is taken at the lowest position of the orbit (from the sun's axis height).
    pub centre_height_mm: std::collections::BTreeMap<String, f64>,
    /// Oil volume in the sump, litres (used by the Changenet–Velex churning model).
    #[serde(default)]
    pub sump_volume_l: Option<f64>,
}

/// Validate `[lubrication]` and build the checked gears; returns them with the oil level (m).
pub(crate) fn validate_lubrication(
    lub: &LubricationSpec,
    parts: &Parts<'_>,
    sets: &[PlanetarySet],
    meshes: &[Mesh],
    mounts: &Mounts,
    problems: &mut Problems,
) -> (Vec<Gear>, f64) {
    if !lub.oil_level_mm.is_finite() {
        problems.push(
            "lubrication.oil_level_mm",
            lub.oil_level_mm,
            "must be a finite number",
        );
    }
    if let Some(v) = lub.sump_volume_l {
        problems.positive("lubrication.sump_volume_l", v);
    }
    let mut heights = axis_heights(lub, parts, problems);
    // Planets: lowest orbit position = axis height of the set (its sun or ring) − orbit radius.
    for s in sets {
        let axis = s.gears.iter().find_map(|&gi| heights[gi]);
        for &gi in &s.gears {
            if let (GearMount::Planet { .. }, Some(axis)) = (mounts[gi].0, axis) {
                if let Some(orbit) = orbit_radius(gi, meshes, mounts) {
                    heights[gi] = Some(axis - orbit);
                }
            }
        }
    }
    let level = lub.oil_level_mm * MM;
    let mut gears = Vec::new();
    for (gi, g) in parts.gears.specs.iter().enumerate() {
        let (Some(geo), Some(h), Some(m)) =
            (parts.gears.geoms[gi].clone(), heights[gi], parts.gears.member[gi])
        else {
            continue;
        };
        // Lowest point of the gear body: the tip circle of an external gear; for a ring the root circle.
        let reach = if g.internal {
            geo.d_f.max(geo.d_a) / 2.0
        } else {
            geo.d_a / 2.0
        };
        let immersion = level - (h - reach);
        if immersion > 2.0 * reach {
            problems.push(
                format!("lubrication.centre_height_mm.{}", g.name),
                format!("{:.3}", h / MM),
                format!(
                    "gear fully submerged: immersion {:.2} mm exceeds its outer diameter {:.2} mm (immersion must be ≤ tip diameter)",
                    immersion / MM,
                    2.0 * reach / MM
                ),
            );
        }
        gears.push(Gear {
            name: g.name.clone(),
            member: m,
            geometry: geo,
            roughness_ra: g.roughness_ra_um.unwrap_or(0.5) * 1e-6,
            mount: mounts[gi].0,
            carrier: mounts[gi].1,
            centre_height: h,
            immersion,
            position: g.position_mm.unwrap_or(0.0) * MM,
        });
    }
    (gears, level)
}

/// `centre_height_mm`: known gears, no planets, every non-planet gear once with a finite height;
/// the axis height of each non-planet gear (m).
fn axis_heights(lub: &LubricationSpec, parts: &Parts<'_>, problems: &mut Problems) -> Vec<Option<f64>> {
    let gear_specs = parts.gears.specs;
    for name in lub.centre_height_mm.keys() {
        let path = format!("lubrication.centre_height_mm.{name}");
        match parts.gears.ix.get(name.as_str()) {
            None => problems.push(path, "", "unknown gear"),
            Some(&gi) if parts.is_planet(gi) => problems.push(
                path,
                "",
                "planets orbit: give the centre height of the set's sun instead (planets take the lowest orbit position)",
            ),
            _ => {}
        }
    }
    let mut heights: Vec<Option<f64>> = vec![None; gear_specs.len()];
    for (gi, g) in gear_specs.iter().enumerate() {
        if parts.is_planet(gi) {
            continue;
        }
        let path = format!("lubrication.centre_height_mm.{}", g.name);
        match lub.centre_height_mm.get(&g.name) {
            Some(h) if h.is_finite() => heights[gi] = Some(h * MM),
            Some(h) => problems.push(path, h, "must be a finite number"),
            None => problems.push(path, "", "missing: every non-planet gear needs its axis height"),
        }
    }
    heights
}

/// Distance of planet `gi`'s axis from its set's axis: the centre distance of its mesh with a
/// sun or the ring.
fn orbit_radius(gi: usize, meshes: &[Mesh], mounts: &Mounts) -> Option<f64> {
    let central = |g: usize| mounts[g].0 == GearMount::OnMember;
    meshes
        .iter()
        .find(|m| {
            m.set.is_some() && (m.gear1 == gi || m.gear2 == gi) && (central(m.gear1) || central(m.gear2))
        })
        .map(|m| m.geometry.a_w)
}
