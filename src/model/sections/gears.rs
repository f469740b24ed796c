//! `[[gears]]`: cylindrical involute gears; names, members, geometry, and the name table later
//! sections look gears up in. The checked [`Gear`] is completed by `[lubrication]` (axis height,
//! immersion) and `[[planetary_sets]]` (mount).

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use super::common::*;
use super::members::Members;
use crate::model::problems::Problems;
use crate::physics::geometry::{GearGeometry, GearSpec};

/// `[[gears]]` as written: one cylindrical involute gear (planets: one entry per planet type,
/// counted by the set).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GearSpecFile {
    /// Unique name.
    pub name: String,
    /// Member the gear is fixed to (for planets: the carrier).
    pub member: String,
    /// Number of teeth.
    pub teeth: i64,
    /// Normal module, mm.
    pub module_mm: f64,
    /// Normal pressure angle, degrees (default 20).
    #[serde(default)]
    pub pressure_angle_deg: Option<f64>,
    /// Helix angle, degrees (default 0 = spur).
    #[serde(default)]
    pub helix_angle_deg: Option<f64>,
    /// Profile shift coefficient x (default 0).
    #[serde(default)]
    pub profile_shift: Option<f64>,
    /// Face width, mm.
    pub face_width_mm: f64,
    /// Tip diameter, mm (default from the basic rack).
    #[serde(default)]
    pub tip_diameter_mm: Option<f64>,
    /// Root diameter, mm (default from the basic rack).
    #[serde(default)]
    pub root_diameter_mm: Option<f64>,
    /// Addendum factor h_a* (default 1.0).
    #[serde(default)]
    pub addendum_factor: Option<f64>,
    /// Dedendum factor h_f* (default 1.25).
    #[serde(default)]
    pub dedendum_factor: Option<f64>,
    /// Tool tip radius factor ρ_fP* (default 0.25; usual 0.25–0.38).
    #[serde(default)]
    pub tool_tip_radius_factor: Option<f64>,
    /// Arithmetic mean flank roughness Ra, µm (default 0.5).
    #[serde(default)]
    pub roughness_ra_um: Option<f64>,
    /// `true` for an internal (ring) gear.
    #[serde(default)]
    pub internal: bool,
    /// Axial position of the face-width centre along the member (planets: along the pin), mm
    /// (default 0; bearing loads use it).
    #[serde(default)]
    pub position_mm: Option<f64>,
}

/// How a gear turns: with its member, or as a planet on a carrier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GearMount {
    /// Fixed to a member (shaft, sun, ring): turns at the member's speed.
    OnMember,
    /// A planet of a set: turns at the carrier speed plus its spin `ω_P − ω_C = factor·(ω_ref − ω_C)`,
    /// `reference` being the member whose gear drives the spin (a sun or the ring).
    Planet {
        /// Planetary set index.
        set: usize,
        /// Member that sets the spin (sun or ring member).
        reference: usize,
        /// Spin factor (e.g. −z_S/z_P for a planet meshing the sun).
        factor: f64,
    },
}

/// A gear: geometry, member, lubrication.
#[derive(Debug, Clone)]
pub struct Gear {
    /// Name from the file.
    pub name: String,
    /// Member index (for planets: the carrier).
    pub member: usize,
    /// Geometry (SI).
    pub geometry: GearGeometry,
    /// Flank roughness Ra, m.
    pub roughness_ra: f64,
    /// How it turns.
    pub mount: GearMount,
    /// Carrier member of the planetary set the gear belongs to (None: fixed-axis gear).
    pub carrier: Option<usize>,
    /// Height of the gear axis above the datum, m (planets: lowest point of the orbit).
    pub centre_height: f64,
    /// Depth of the gear's lowest point below the static oil level, m (≤ 0: not immersed).
    pub immersion: f64,
    /// Axial position of the face-width centre along its member (planets: along the pin), m.
    pub position: f64,
}

impl Gear {
    /// True when the gear dips into the oil.
    pub fn is_immersed(&self) -> bool {
        self.immersion > 0.0
    }
}

/// The gears by name, with the geometry and member of each (None where it failed).
pub(crate) struct Gears<'a> {
    /// As written.
    pub specs: &'a [GearSpecFile],
    /// Name → index.
    pub ix: HashMap<&'a str, usize>,
    /// Geometry per gear.
    pub geoms: Vec<Option<GearGeometry>>,
    /// Member per gear.
    pub member: Vec<Option<usize>>,
}

impl Gears<'_> {
    /// Index of gear `name`, or a problem at `path` listing the defined gears.
    pub fn lookup(&self, name: &str, path: String, problems: &mut Problems) -> Option<usize> {
        let defined = self.specs.iter().map(|g| &g.name);
        lookup(&self.ix, name, path, "gear", defined, problems)
    }
}

/// Check `[[gears]]`: unique names, members, geometry. `roots` (mm, per gear) replaces the
/// default rack's root where a mating tip needs it ([`super::meshes::mating_tip_roots`]).
pub(crate) fn validate_gears<'a>(
    specs: &'a [GearSpecFile],
    members: &Members<'_>,
    roots: &[Option<f64>],
    problems: &mut Problems,
) -> Gears<'a> {
    let mut ix: HashMap<&str, usize> = HashMap::new();
    let mut geoms: Vec<Option<GearGeometry>> = Vec::new();
    let mut member: Vec<Option<usize>> = Vec::new();
    for (i, g) in specs.iter().enumerate() {
        let p = format!("gears[{i}]");
        if g.name.trim().is_empty() {
            problems.push(format!("{p}.name"), "\"\"", "must not be empty");
        } else if ix.insert(g.name.as_str(), i).is_some() {
            problems.push(format!("{p}.name"), q(&g.name), "duplicate gear name");
        }
        member.push(members.lookup(&g.member, format!("{p}.member"), problems));
        geoms.push(gear_geometry(g, &p, roots[i], problems));
    }
    if specs.is_empty() {
        problems.push("gears", "[]", "at least one [[gears]] entry is required");
    }
    Gears {
        specs,
        ix,
        geoms,
        member,
    }
}

/// Default dedendum factor h_fP of the generating rack, and its addendum h_aP: the basic rack's
/// bottom clearance is c_P = h_fP − h_aP = 0.25 m_n.
pub(crate) const RACK_DEDENDUM: f64 = 1.25;
/// Addendum h_aP of the default generating rack.
pub(crate) const RACK_ADDENDUM: f64 = 1.0;

/// Geometry of one `[[gears]]` entry at key path `p`; `root_default` (mm) replaces the default
/// rack's root.
fn gear_geometry(
    g: &GearSpecFile,
    p: &str,
    root_default: Option<f64>,
    problems: &mut Problems,
) -> Option<GearGeometry> {
    let before = problems.len();
    let min_teeth = if g.internal { 20 } else { 5 };
    if g.teeth < min_teeth || g.teeth > 1000 {
        problems.push(
            format!("{p}.teeth"),
            g.teeth,
            format!("must be an integer in [{min_teeth}, 1000]"),
        );
    }
    problems.in_range(&format!("{p}.module_mm"), g.module_mm, 0.05, 100.0, " mm");
    let alpha = g.pressure_angle_deg.unwrap_or(20.0);
    problems.in_range(&format!("{p}.pressure_angle_deg"), alpha, 10.0, 35.0, " deg");
    let beta = g.helix_angle_deg.unwrap_or(0.0);
    problems.in_range(&format!("{p}.helix_angle_deg"), beta, 0.0, 45.0, " deg");
    let x = g.profile_shift.unwrap_or(0.0);
    problems.in_range(&format!("{p}.profile_shift"), x, -1.5, 2.5, "");
    problems.in_range(
        &format!("{p}.face_width_mm"),
        g.face_width_mm,
        1e-3,
        2000.0,
        " mm",
    );
    let ha = g.addendum_factor.unwrap_or(1.0);
    problems.in_range(&format!("{p}.addendum_factor"), ha, 0.5, 1.5, "");
    let hf = g.dedendum_factor.unwrap_or(RACK_DEDENDUM);
    problems.in_range(&format!("{p}.dedendum_factor"), hf, 0.8, 1.8, "");
    let rho = g.tool_tip_radius_factor.unwrap_or(0.25);
    problems.in_range(&format!("{p}.tool_tip_radius_factor"), rho, 0.0, 0.5, "");
    if let Some(ra) = g.roughness_ra_um {
        problems.in_range(&format!("{p}.roughness_ra_um"), ra, 0.0, 25.0, " um");
    }
    if let Some(d) = g.tip_diameter_mm {
        problems.positive(&format!("{p}.tip_diameter_mm"), d);
    }
    if let Some(d) = g.root_diameter_mm {
        problems.positive(&format!("{p}.root_diameter_mm"), d);
    }
    if problems.len() > before {
        return None;
    }
    let mut spec = GearSpec::new(
        g.teeth as u32,
        g.module_mm * MM,
        alpha * DEG,
        beta * DEG,
        x,
        g.face_width_mm * MM,
    )
    .with_internal(g.internal)
    .with_rack(ha, hf, rho);
    if let Some(d) = g.tip_diameter_mm {
        spec = spec.with_tip_diameter(d * MM);
    }
    if let Some(d) = g.root_diameter_mm.or(root_default) {
        spec = spec.with_root_diameter(d * MM);
    }
    match GearGeometry::new(&spec) {
        Ok(geo) => Some(geo),
        Err(e) => {
            problems.push(
                p.to_string(),
                q(&g.name),
                format!("impossible gear geometry: {e}"),
            );
            None
        }
    }
}
