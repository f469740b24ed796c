//! `[[planetary_sets]]`: roles, kinematic rows, generated meshes, planet mounts, assembly and
//! neighbour conditions.

use std::collections::{BTreeMap, HashMap};

use serde::{Deserialize, Serialize};

use super::common::*;
use super::gears::GearMount;
use super::meshes::{mesh_geometry, Mesh, MeshLoadPath};
use super::parts::Parts;
use crate::model::choice::{choice, Choice};
use crate::model::problems::Problems;
use crate::physics::geometry::MeshKind;
use crate::physics::kinematics::{planet_spin, ring_pinion_spin, Constraint};

/// Kind of planetary set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanetarySetKind {
    /// Sun – planet – ring.
    Simple,
    /// Sun – inner planet – outer planet – ring.
    DoublePinion,
    /// Large sun – long planet – ring, plus small sun – short planet – long planet.
    Ravigneaux,
}
choice!(PlanetarySetKind {
    Simple = "simple",
    DoublePinion = "double_pinion",
    Ravigneaux = "ravigneaux",
});

/// `[[planetary_sets]]` as written: which gears form the set, its carrier and its number of planets.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PlanetarySetSpec {
    /// Unique name.
    pub name: String,
    /// `simple`, `double_pinion` or `ravigneaux`.
    pub kind: PlanetarySetKind,
    /// Carrier member.
    pub carrier: String,
    /// Number of planets (of each planet type).
    pub planets: i64,
    /// Ring gear (all kinds).
    pub ring: String,
    /// Sun gear (simple, double_pinion).
    #[serde(default)]
    pub sun: Option<String>,
    /// Planet gear (simple).
    #[serde(default)]
    pub planet: Option<String>,
    /// Planet meshing the sun (double_pinion).
    #[serde(default)]
    pub inner_planet: Option<String>,
    /// Planet meshing the ring (double_pinion).
    #[serde(default)]
    pub outer_planet: Option<String>,
    /// Large sun, meshing the long planet (ravigneaux).
    #[serde(default)]
    pub large_sun: Option<String>,
    /// Small sun, meshing the short planet (ravigneaux).
    #[serde(default)]
    pub small_sun: Option<String>,
    /// Long planet: large sun, ring, short planet (ravigneaux).
    #[serde(default)]
    pub long_planet: Option<String>,
    /// Short planet: small sun, long planet (ravigneaux).
    #[serde(default)]
    pub short_planet: Option<String>,
}

/// Gears of a planetary set by role.
#[derive(Debug, Clone)]
pub struct PlanetarySet {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: PlanetarySetKind,
    /// Carrier member index.
    pub carrier: usize,
    /// Number of planets (of each planet type).
    pub planets: u32,
    /// Gear indices in role order: simple `[sun, planet, ring]`, double pinion
    /// `[sun, inner, outer, ring]`, Ravigneaux `[large_sun, small_sun, long, short, ring]`.
    pub gears: Vec<usize>,
}

/// Sets and the mount (and carrier) of every gear.
pub(crate) type Mounts = Vec<(GearMount, Option<usize>)>;

/// Planet roles: gear name → index of the set naming it as a planet.
pub(crate) fn planet_roles(specs: &[PlanetarySetSpec]) -> HashMap<&str, usize> {
    let mut planet_of: HashMap<&str, usize> = HashMap::new();
    for (si, s) in specs.iter().enumerate() {
        for p in [
            &s.planet,
            &s.inner_planet,
            &s.outer_planet,
            &s.long_planet,
            &s.short_planet,
        ]
        .into_iter()
        .flatten()
        {
            planet_of.insert(p.as_str(), si);
        }
    }

    planet_of
}

/// Validate `[[planetary_sets]]`: appends their rows to `fixed_rows` and their meshes to `meshes`.
pub(crate) fn validate_sets(
    specs: &[PlanetarySetSpec],
    parts: &Parts<'_>,
    meshes: &mut Vec<Mesh>,
    fixed_rows: &mut Vec<Constraint>,
    problems: &mut Problems,
) -> (Vec<PlanetarySet>, Mounts) {
    let mut sets: Vec<PlanetarySet> = Vec::new();
    let mut mounts: Mounts = vec![(GearMount::OnMember, None); parts.gears.specs.len()];
    for (si, s) in specs.iter().enumerate() {
        let p = format!("planetary_sets[{si}]");
        let carrier = parts.member(&s.carrier, format!("{p}.carrier"), problems);
        if !(1..=12).contains(&s.planets) {
            problems.push(format!("{p}.planets"), s.planets, "must be an integer in [1, 12]");
        }
        let roles = roles(s);
        check_unused_roles(s, &roles, &p, problems);
        let ix = role_gears(s, &roles, parts, &p, problems);
        let (Some(ix), Some(carrier)) = (ix, carrier) else {
            continue;
        };
        let set = Set {
            spec: s,
            index: si,
            path: p,
            carrier,
            planets: s.planets.clamp(1, 12) as u32,
            gears: ix,
        };
        if !check_role_gears(&set, &roles, parts, problems) {
            continue;
        }
        let generated = kinematics(&set, parts, fixed_rows, &mut mounts, problems);
        for &gi in &set.gears {
            if mounts[gi].1.is_none() {
                mounts[gi].1 = Some(carrier);
            }
        }
        generated_meshes(&set, generated, parts, &mounts, meshes, problems);
        sets.push(PlanetarySet {
            name: s.name.clone(),
            kind: s.kind,
            carrier,
            planets: set.planets,
            gears: set.gears,
        });
    }
    (sets, mounts)
}

/// A set whose gears were found, while its kinematics and meshes are built.
struct Set<'s> {
    /// As written.
    spec: &'s PlanetarySetSpec,
    /// Index among the sets.
    index: usize,
    /// Key path, `planetary_sets[i]`.
    path: String,
    /// Carrier member.
    carrier: usize,
    /// Number of planets of each type (1–12).
    planets: u32,
    /// Gear indices in role order, the ring last.
    gears: Vec<usize>,
}

/// A generated mesh: gear 1, gear 2, kind, load path (constraint row, sign).
type GenMesh = (usize, usize, MeshKind, Vec<(usize, f64)>);

/// The roles of a set's kind (the ring, which every kind has, aside) with the gears named.
fn roles(s: &PlanetarySetSpec) -> Vec<(&'static str, &Option<String>)> {
    match s.kind {
        PlanetarySetKind::Simple => vec![("sun", &s.sun), ("planet", &s.planet)],
        PlanetarySetKind::DoublePinion => vec![
            ("sun", &s.sun),
            ("inner_planet", &s.inner_planet),
            ("outer_planet", &s.outer_planet),
        ],
        PlanetarySetKind::Ravigneaux => vec![
            ("large_sun", &s.large_sun),
            ("small_sun", &s.small_sun),
            ("long_planet", &s.long_planet),
            ("short_planet", &s.short_planet),
        ],
    }
}

/// A role the set's kind does not use must not be given.
fn check_unused_roles(
    s: &PlanetarySetSpec,
    roles: &[(&str, &Option<String>)],
    p: &str,
    problems: &mut Problems,
) {
    let all_roles = [
        ("sun", &s.sun),
        ("planet", &s.planet),
        ("inner_planet", &s.inner_planet),
        ("outer_planet", &s.outer_planet),
        ("large_sun", &s.large_sun),
        ("small_sun", &s.small_sun),
        ("long_planet", &s.long_planet),
        ("short_planet", &s.short_planet),
    ];
    for (role, v) in all_roles {
        if v.is_some() && !roles.iter().any(|(r, _)| *r == role) {
            problems.push(
                format!("{p}.{role}"),
                q(v.as_deref().unwrap_or("")),
                format!(
                    "not used by a {:?} set; it takes: ring, {}",
                    s.kind,
                    list(roles.iter().map(|(r, _)| r))
                ),
            );
        }
    }
}

/// The gear of every role and the ring (None when one is missing or unknown).
fn role_gears(
    s: &PlanetarySetSpec,
    roles: &[(&str, &Option<String>)],
    parts: &Parts<'_>,
    p: &str,
    problems: &mut Problems,
) -> Option<Vec<usize>> {
    let mut ix: Vec<Option<usize>> = Vec::new();
    for (role, v) in roles {
        match v {
            None => {
                problems.push(
                    format!("{p}.{role}"),
                    "",
                    format!("required for a {} set", s.kind.name()),
                );
                ix.push(None);
            }
            Some(name) => ix.push(parts.gear(name, format!("{p}.{role}"), problems)),
        }
    }
    ix.push(parts.gear(&s.ring, format!("{p}.ring"), problems));
    ix.into_iter().collect()
}

/// Roles: internal only for the ring; planets mounted on the carrier; suns and the ring on other
/// members. False after a problem.
fn check_role_gears(
    set: &Set<'_>,
    roles: &[(&str, &Option<String>)],
    parts: &Parts<'_>,
    problems: &mut Problems,
) -> bool {
    let (gear_specs, gear_member) = (parts.gears.specs, &parts.gears.member);
    let (s, p, carrier) = (set.spec, &set.path, set.carrier);
    let mut ok = true;
    for (k, &gi) in set.gears.iter().enumerate() {
        let role = if k == roles.len() { "ring" } else { roles[k].0 };
        let is_planet = role.contains("planet");
        let want_internal = role == "ring";
        if gear_specs[gi].internal != want_internal {
            problems.push(
                format!("{p}.{role}"),
                q(&gear_specs[gi].name),
                if want_internal {
                    "the ring must be an internal gear (internal = true)"
                } else {
                    "must be an external gear"
                },
            );
            ok = false;
        }
        let Some(gm) = gear_member[gi] else { continue };
        if is_planet && gm != carrier {
            problems.push(
                format!("gears[{gi}].member"),
                q(&gear_specs[gi].member),
                format!(
                    "planet of set \"{}\": its member must be the carrier \"{}\"",
                    s.name, s.carrier
                ),
            );
            ok = false;
        }
        if !is_planet && gm == carrier {
            problems.push(
                format!("gears[{gi}].member"),
                q(&gear_specs[gi].member),
                "a sun or ring cannot sit on the set's carrier",
            );
            ok = false;
        }
    }
    ok
}

/// The set's constraint rows (appended to `fixed_rows`), its generated meshes with their load
/// paths, the mounts of its planets, and the assembly conditions.
fn kinematics(
    set: &Set<'_>,
    parts: &Parts<'_>,
    fixed_rows: &mut Vec<Constraint>,
    mounts: &mut Mounts,
    problems: &mut Problems,
) -> Vec<GenMesh> {
    let (gear_specs, gear_member) = (parts.gears.specs, &parts.gears.member);
    let (ix, carrier, p, n_pl) = (&set.gears, set.carrier, &set.path, set.planets);
    let z = |gi: usize| gear_specs[gi].teeth as f64;
    let mem = |gi: usize| gear_member[gi].unwrap_or_default();
    let planet = |reference: usize, factor: f64| {
        (
            GearMount::Planet {
                set: set.index,
                reference,
                factor,
            },
            Some(carrier),
        )
    };
    let first_row = fixed_rows.len();
    let mut gen: Vec<GenMesh> = Vec::new();
    match set.spec.kind {
        PlanetarySetKind::Simple => {
            let (sun, pl, ring) = (ix[0], ix[1], ix[2]);
            fixed_rows.push(Constraint::SimpleSet {
                sun: mem(sun),
                ring: mem(ring),
                carrier,
                zs: z(sun),
                zr: z(ring),
            });
            gen.push((sun, pl, MeshKind::External, vec![(first_row, 1.0)]));
            // Signs: torque applied to gear 1 of each mesh (see MeshLoadPath); the planet is in
            // equilibrium, so its ring mesh carries the opposite of its sun mesh.
            gen.push((pl, ring, MeshKind::Internal, vec![(first_row, -1.0)]));
            mounts[pl] = planet(mem(sun), spin_from_sun(z(sun), z(pl)));
            assembly(problems, p, "(z_sun + z_ring)", z(sun) + z(ring), n_pl);
        }
        PlanetarySetKind::DoublePinion => {
            let (sun, inner, outer, ring) = (ix[0], ix[1], ix[2], ix[3]);
            fixed_rows.push(Constraint::DoublePinionSet {
                sun: mem(sun),
                ring: mem(ring),
                carrier,
                zs: z(sun),
                zr: z(ring),
            });
            gen.push((sun, inner, MeshKind::External, vec![(first_row, 1.0)]));
            gen.push((inner, outer, MeshKind::External, vec![(first_row, -1.0)]));
            gen.push((outer, ring, MeshKind::Internal, vec![(first_row, 1.0)]));
            mounts[inner] = planet(mem(sun), spin_from_sun(z(sun), z(inner)));
            mounts[outer] = planet(mem(ring), spin_from_ring(z(ring), z(outer)));
            assembly(problems, p, "(z_ring − z_sun)", z(ring) - z(sun), n_pl);
        }
        PlanetarySetKind::Ravigneaux => {
            let (ls, ss, long, short, ring) = (ix[0], ix[1], ix[2], ix[3], ix[4]);
            let [r1, r2] =
                Constraint::ravigneaux(mem(ls), mem(ss), mem(ring), carrier, z(ls), z(ss), z(ring));
            fixed_rows.push(r1);
            fixed_rows.push(r2);
            let (k1, k2) = (first_row, first_row + 1);
            gen.push((ls, long, MeshKind::External, vec![(k1, 1.0)]));
            gen.push((ss, short, MeshKind::External, vec![(k2, 1.0)]));
            gen.push((short, long, MeshKind::External, vec![(k2, -1.0)]));
            // The long pinion–ring mesh carries both rows' ring force: ring torque z_R(λ1 − λ2).
            gen.push((long, ring, MeshKind::Internal, vec![(k1, -1.0), (k2, 1.0)]));
            mounts[long] = planet(mem(ls), spin_from_sun(z(ls), z(long)));
            mounts[short] = planet(mem(ss), spin_from_sun(z(ss), z(short)));
            assembly(problems, p, "(z_ring + z_large_sun)", z(ring) + z(ls), n_pl);
            assembly(problems, p, "(z_ring − z_small_sun)", z(ring) - z(ss), n_pl);
        }
    }
    gen
}

/// Geometry of the generated meshes (appended to `meshes`), coaxiality of the central gears,
/// and the neighbour condition of the planets.
fn generated_meshes(
    set: &Set<'_>,
    generated: Vec<GenMesh>,
    parts: &Parts<'_>,
    mounts: &Mounts,
    meshes: &mut Vec<Mesh>,
    problems: &mut Problems,
) {
    let (gear_specs, geoms) = (parts.gears.specs, &parts.gears.geoms);
    let p = &set.path;
    // Distance of each planet's axis from the set axis (sun–planet and planet–ring meshes).
    let mut centre: BTreeMap<usize, f64> = BTreeMap::new();
    let mut gen_ok = true;
    for (g1, g2, mk, rows) in generated {
        let mp = format!("{p} mesh {}/{}", gear_specs[g1].name, gear_specs[g2].name);
        let Some(geo) = mesh_geometry(gear_specs, geoms, (g1, g2), mk, None, &mp, problems) else {
            gen_ok = false;
            continue;
        };
        let planet = if mounts[g1].0 != GearMount::OnMember {
            None
        } else {
            Some(g2)
        };
        let planet = planet.or(if mounts[g2].0 == GearMount::OnMember {
            Some(g1)
        } else {
            None
        });
        if let Some(pg) = planet {
            if let Some(prev) = centre.insert(pg, geo.a_w) {
                check_coaxial(set, pg, (prev, geo.a_w), parts, problems);
            }
        }
        meshes.push(Mesh {
            name: format!(
                "{}:{}/{}",
                set.spec.name, gear_specs[g1].name, gear_specs[g2].name
            ),
            gear1: g1,
            gear2: g2,
            geometry: geo,
            set: Some(set.index),
            multiplicity: set.planets,
            load_path: MeshLoadPath { rows },
        });
    }
    if gen_ok && set.planets > 1 {
        check_neighbours(set, &centre, parts, problems);
    }
}

/// Coaxial set: planet `pg`'s two centre distances `(a1, a2)` (to the sun and to the ring, m)
/// agree to 0.001 m_n.
fn check_coaxial(set: &Set<'_>, pg: usize, (a1, a2): (f64, f64), parts: &Parts<'_>, problems: &mut Problems) {
    let g = &parts.gears.specs[pg];
    if (a1 - a2).abs() > 1e-3 * g.module_mm * MM {
        problems.push(
            set.path.clone(),
            format!("{:.4} mm vs {:.4} mm", a1 / MM, a2 / MM),
            format!(
                "planet \"{}\": its centre distances to the sun and to the ring must be equal (coaxial set); adjust profile shifts or tooth counts",
                g.name
            ),
        );
    }
}

/// Neighbour condition: planets of one type must not touch (2 a sin(π/N) > d_a).
fn check_neighbours(
    set: &Set<'_>,
    centre: &BTreeMap<usize, f64>,
    parts: &Parts<'_>,
    problems: &mut Problems,
) {
    let n_pl = set.planets;
    for (&pg, &a) in centre {
        let Some(g) = &parts.gears.geoms[pg] else { continue };
        let gap = 2.0 * a * (std::f64::consts::PI / n_pl as f64).sin() - g.d_a;
        if gap <= 0.0 {
            problems.push(
                format!("{}.planets", set.path),
                n_pl,
                format!(
                    "planets \"{}\" overlap: 2·a·sin(π/N) = {:.2} mm < tip diameter {:.2} mm",
                    parts.gears.specs[pg].name,
                    (gap + g.d_a) / MM,
                    g.d_a / MM
                ),
            );
        }
    }
}

/// Equal spacing of N planets needs `teeth_sum / N` to be an integer (standard assembly condition).
fn assembly(problems: &mut Problems, path: &str, what: &str, teeth_sum: f64, n: u32) {
    let q = teeth_sum / n as f64;
    if (q - q.round()).abs() > 1e-9 {
        problems.push(
            format!("{path}.planets"),
            n,
            format!("planets cannot be assembled equally spaced: {what} = {teeth_sum} is not divisible by the number of planets"),
        );
    }
}

/// Spin factor of a planet meshing the sun.
pub fn spin_from_sun(z_sun: f64, z_planet: f64) -> f64 {
    planet_spin(z_sun, z_planet, 1.0, 0.0)
}

/// Spin factor of a pinion meshing the ring.
pub fn spin_from_ring(z_ring: f64, z_planet: f64) -> f64 {
    ring_pinion_spin(z_ring, z_planet, 1.0, 0.0)
}
