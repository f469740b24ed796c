//! Validation: a parsed [`ModelFile`] → a checked [`Gearbox`] in SI units, or the list of every
//! problem found (key path, value, what is allowed).
//!
//! The checks run section by section and keep going after a failure, so one run of
//! `geartherm check` shows everything that is wrong. Checks that need earlier sections (a mesh
//! needs its two gears' geometry) are skipped for entries whose inputs already failed, so one
//! mistake is reported once.

use std::collections::{BTreeSet, HashMap};

use super::catalogue;
use super::gearbox::*;
use super::problems::Problems;
use super::schema::*;
use super::source::Source;
use super::thermal::{validate_thermal, GearInfo, LossItemNames};
use crate::cycle::{GearTable, VehicleSpec};
use crate::physics::geometry::{GearGeometry, GearSpec, MeshGeometry, MeshKind};
use crate::physics::kinematics::{Constraint, GearTrain, KinematicsError};
use crate::physics::oil::{Oil, WaltherVariant, ALPHA_T_MINERAL, CST};

const MM: f64 = 1e-3;
const DEG: f64 = std::f64::consts::PI / 180.0;

/// Validate a parsed file. `problems` receives every problem; `None` if there was any.
pub fn validate(file: &ModelFile, problems: &mut Problems) -> Option<Gearbox> {
    let start = problems.len();
    if file.model.name.trim().is_empty() {
        problems.push("model.name", "\"\"", "must not be empty");
    }
    let oil = validate_oil(&file.oil, problems);
    let structure_start = problems.len();

    // Members.
    let mut member_ix: HashMap<&str, usize> = HashMap::new();
    for (i, m) in file.members.iter().enumerate() {
        if m.name.trim().is_empty() {
            problems.push(format!("members[{i}].name"), "\"\"", "must not be empty");
        } else if member_ix.insert(m.name.as_str(), i).is_some() {
            problems.push(format!("members[{i}].name"), q(&m.name), "duplicate member name");
        }
    }
    if file.members.len() < 2 {
        problems.push(
            "members",
            format!("{} member(s)", file.members.len()),
            "a gearbox needs at least two members (input and output)",
        );
    }
    let member = |name: &str, path: String, problems: &mut Problems| -> Option<usize> {
        let r = member_ix.get(name).copied();
        if r.is_none() {
            problems.push(
                path,
                q(name),
                format!(
                    "unknown member; defined members: {}",
                    list(file.members.iter().map(|m| &m.name))
                ),
            );
        }
        r
    };

    // Planet roles (a gear named as a planet by a set).
    let mut planet_of: HashMap<&str, usize> = HashMap::new();
    for (si, s) in file.planetary_sets.iter().enumerate() {
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

    // Gears.
    let mut gear_ix: HashMap<&str, usize> = HashMap::new();
    let mut geoms: Vec<Option<GearGeometry>> = Vec::new();
    let mut gear_member: Vec<Option<usize>> = Vec::new();
    for (i, g) in file.gears.iter().enumerate() {
        let p = format!("gears[{i}]");
        if g.name.trim().is_empty() {
            problems.push(format!("{p}.name"), "\"\"", "must not be empty");
        } else if gear_ix.insert(g.name.as_str(), i).is_some() {
            problems.push(format!("{p}.name"), q(&g.name), "duplicate gear name");
        }
        gear_member.push(member(&g.member, format!("{p}.member"), problems));
        geoms.push(gear_geometry(g, &p, problems));
    }
    if file.gears.is_empty() {
        problems.push("gears", "[]", "at least one [[gears]] entry is required");
    }

    // Train input/output.
    let input = member(&file.train.input, "train.input".into(), problems);
    let output = member(&file.train.output, "train.output".into(), problems);
    if input.is_some() && input == output {
        problems.push(
            "train.output",
            q(&file.train.output),
            "must differ from train.input",
        );
    }

    // Fixed-axis meshes.
    let mut meshes: Vec<Mesh> = Vec::new();
    let mut fixed_rows: Vec<Constraint> = Vec::new();
    let gear_lookup = |name: &str, path: String, problems: &mut Problems| -> Option<usize> {
        let r = gear_ix.get(name).copied();
        if r.is_none() {
            problems.push(
                path,
                q(name),
                format!(
                    "unknown gear; defined gears: {}",
                    list(file.gears.iter().map(|g| &g.name))
                ),
            );
        }
        r
    };
    for (i, m) in file.meshes.iter().enumerate() {
        let p = format!("meshes[{i}]");
        if m.gears.len() != 2 {
            problems.push(
                format!("{p}.gears"),
                format!("{:?}", m.gears),
                "must name exactly two gears",
            );
            continue;
        }
        let g1 = gear_lookup(&m.gears[0], format!("{p}.gears[0]"), problems);
        let g2 = gear_lookup(&m.gears[1], format!("{p}.gears[1]"), problems);
        let (Some(g1), Some(g2)) = (g1, g2) else { continue };
        if g1 == g2 {
            problems.push(
                format!("{p}.gears"),
                format!("{:?}", m.gears),
                "a gear cannot mesh with itself",
            );
            continue;
        }
        for (k, gi) in [(0, g1), (1, g2)] {
            if planet_of.contains_key(file.gears[gi].name.as_str()) {
                problems.push(
                    format!("{p}.gears[{k}]"),
                    q(&file.gears[gi].name),
                    "is a planet: meshes of planetary sets are generated from [[planetary_sets]], do not list them",
                );
            }
        }
        let kind = m.kind.unwrap_or(MeshKindSpec::External);
        let (i1, i2) = (file.gears[g1].internal, file.gears[g2].internal);
        let kind_ok = match kind {
            MeshKindSpec::External => !i1 && !i2,
            MeshKindSpec::Internal => !i1 && i2,
        };
        if !kind_ok {
            let allowed = match kind {
                MeshKindSpec::External => "an external mesh needs two external gears (internal = false)",
                MeshKindSpec::Internal => {
                    "an internal mesh lists the external pinion first and the internal (ring) gear second"
                }
            };
            problems.push(format!("{p}.kind"), format!("{kind:?}").to_lowercase(), allowed);
            continue;
        }
        let a_w = m.centre_distance_mm.map(|a| a * MM);
        if let Some(a) = m.centre_distance_mm {
            if !problems.positive(&format!("{p}.centre_distance_mm"), a) {
                continue;
            }
        }
        let (Some(m1), Some(m2)) = (gear_member[g1], gear_member[g2]) else {
            continue;
        };
        if m1 == m2 {
            problems.push(
                format!("{p}.gears"),
                format!("{:?}", m.gears),
                format!(
                    "both gears sit on member \"{}\": a mesh must join two different members",
                    file.members[m1].name
                ),
            );
            continue;
        }
        let name = m
            .name
            .clone()
            .unwrap_or_else(|| format!("{}/{}", m.gears[0], m.gears[1]));
        let mk = if kind == MeshKindSpec::Internal {
            MeshKind::Internal
        } else {
            MeshKind::External
        };
        let Some(geo) = mesh_geometry(&geoms, g1, g2, mk, a_w, &p, file, problems) else {
            continue;
        };
        let (z1, z2) = (file.gears[g1].teeth as f64, file.gears[g2].teeth as f64);
        let row = fixed_rows.len();
        fixed_rows.push(match kind {
            MeshKindSpec::External => Constraint::ExternalMesh {
                a: m1,
                b: m2,
                za: z1,
                zb: z2,
            },
            MeshKindSpec::Internal => Constraint::InternalMesh {
                pinion: m1,
                ring: m2,
                zp: z1,
                zr: z2,
            },
        });
        meshes.push(Mesh {
            name,
            gear1: g1,
            gear2: g2,
            geometry: geo,
            set: None,
            multiplicity: 1,
            load_path: MeshLoadPath {
                rows: vec![(row, 1.0)],
            },
        });
    }

    // Planetary sets.
    let mut sets: Vec<PlanetarySet> = Vec::new();
    let mut mounts: Vec<(GearMount, Option<usize>)> = vec![(GearMount::OnMember, None); file.gears.len()];
    for (si, s) in file.planetary_sets.iter().enumerate() {
        let p = format!("planetary_sets[{si}]");
        let carrier = member(&s.carrier, format!("{p}.carrier"), problems);
        if !(1..=12).contains(&s.planets) {
            problems.push(format!("{p}.planets"), s.planets, "must be an integer in [1, 12]");
        }
        let n_pl = s.planets.clamp(1, 12) as u32;
        let roles: &[(&str, &Option<String>)] = match s.kind {
            PlanetarySetKind::Simple => &[("sun", &s.sun), ("planet", &s.planet)],
            PlanetarySetKind::DoublePinion => &[
                ("sun", &s.sun),
                ("inner_planet", &s.inner_planet),
                ("outer_planet", &s.outer_planet),
            ],
            PlanetarySetKind::Ravigneaux => &[
                ("large_sun", &s.large_sun),
                ("small_sun", &s.small_sun),
                ("long_planet", &s.long_planet),
                ("short_planet", &s.short_planet),
            ],
        };
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
        let mut ix: Vec<Option<usize>> = Vec::new();
        for (role, v) in roles {
            match v {
                None => {
                    problems.push(
                        format!("{p}.{role}"),
                        "",
                        format!("required for a {} set", kind_name(s.kind)),
                    );
                    ix.push(None);
                }
                Some(name) => ix.push(gear_lookup(name, format!("{p}.{role}"), problems)),
            }
        }
        let ring = gear_lookup(&s.ring, format!("{p}.ring"), problems);
        ix.push(ring);
        if ix.iter().any(Option::is_none) || carrier.is_none() {
            continue;
        }
        let ix: Vec<usize> = ix.into_iter().flatten().collect();
        let carrier = carrier.unwrap_or_default();
        // Roles: internal only for the ring; planets mounted on the carrier; suns/ring on other members.
        let mut ok = true;
        let nroles = roles.len();
        for (k, &gi) in ix.iter().enumerate() {
            let role = if k == nroles { "ring" } else { roles[k].0 };
            let is_planet = role.contains("planet");
            let want_internal = role == "ring";
            if file.gears[gi].internal != want_internal {
                problems.push(
                    format!("{p}.{role}"),
                    q(&file.gears[gi].name),
                    if want_internal {
                        "the ring must be an internal gear (internal = true)"
                    } else {
                        "must be an external gear"
                    },
                );
                ok = false;
            }
            if let Some(gm) = gear_member[gi] {
                if is_planet && gm != carrier {
                    problems.push(
                        format!("gears[{gi}].member"),
                        q(&file.gears[gi].member),
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
                        q(&file.gears[gi].member),
                        "a sun or ring cannot sit on the set's carrier",
                    );
                    ok = false;
                }
            }
        }
        if !ok {
            continue;
        }
        let z = |gi: usize| file.gears[gi].teeth as f64;
        let mem = |gi: usize| gear_member[gi].unwrap_or_default();
        let first_row = fixed_rows.len();
        // Rows, generated meshes (gear1, gear2, kind, load path), and planet mounts.
        type GenMesh = (usize, usize, MeshKind, Vec<(usize, f64)>);
        let mut gen: Vec<GenMesh> = Vec::new();
        match s.kind {
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
                mounts[pl] = (
                    GearMount::Planet {
                        set: si,
                        reference: mem(sun),
                        factor: spin_from_sun(z(sun), z(pl)),
                    },
                    Some(carrier),
                );
                assembly(problems, &p, "(z_sun + z_ring)", z(sun) + z(ring), n_pl);
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
                mounts[inner] = (
                    GearMount::Planet {
                        set: si,
                        reference: mem(sun),
                        factor: spin_from_sun(z(sun), z(inner)),
                    },
                    Some(carrier),
                );
                mounts[outer] = (
                    GearMount::Planet {
                        set: si,
                        reference: mem(ring),
                        factor: spin_from_ring(z(ring), z(outer)),
                    },
                    Some(carrier),
                );
                assembly(problems, &p, "(z_ring − z_sun)", z(ring) - z(sun), n_pl);
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
                mounts[long] = (
                    GearMount::Planet {
                        set: si,
                        reference: mem(ls),
                        factor: spin_from_sun(z(ls), z(long)),
                    },
                    Some(carrier),
                );
                mounts[short] = (
                    GearMount::Planet {
                        set: si,
                        reference: mem(ss),
                        factor: spin_from_sun(z(ss), z(short)),
                    },
                    Some(carrier),
                );
                assembly(problems, &p, "(z_ring + z_large_sun)", z(ring) + z(ls), n_pl);
                assembly(problems, &p, "(z_ring − z_small_sun)", z(ring) - z(ss), n_pl);
            }
        }
        for &gi in &ix {
            if mounts[gi].1.is_none() {
                mounts[gi].1 = Some(carrier);
            }
        }
        // Geometry of the generated meshes; coaxiality of the central gears.
        let mut centre: HashMap<usize, f64> = HashMap::new();
        let mut gen_ok = true;
        for (g1, g2, mk, rows) in gen {
            let mp = format!("{p} mesh {}/{}", file.gears[g1].name, file.gears[g2].name);
            let Some(geo) = mesh_geometry(&geoms, g1, g2, mk, None, &mp, file, problems) else {
                gen_ok = false;
                continue;
            };
            // Distance of the planet axis from the set axis (sun–planet and planet–ring meshes).
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
                    if (prev - geo.a_w).abs() > 1e-3 * file.gears[pg].module_mm * MM {
                        problems.push(
                            p.to_string(),
                            format!("{:.4} mm vs {:.4} mm", prev / MM, geo.a_w / MM),
                            format!(
                                "planet \"{}\": its centre distances to the sun and to the ring must be equal (coaxial set); adjust profile shifts or tooth counts",
                                file.gears[pg].name
                            ),
                        );
                    }
                }
            }
            meshes.push(Mesh {
                name: format!("{}:{}/{}", s.name, file.gears[g1].name, file.gears[g2].name),
                gear1: g1,
                gear2: g2,
                geometry: geo,
                set: Some(si),
                multiplicity: n_pl,
                load_path: MeshLoadPath { rows },
            });
        }
        // Neighbour condition: planets of one type must not touch (2 a sin(π/N) > d_a).
        if gen_ok && n_pl > 1 {
            for (&pg, &a) in &centre {
                if let Some(g) = &geoms[pg] {
                    let gap = 2.0 * a * (std::f64::consts::PI / n_pl as f64).sin() - g.d_a;
                    if gap <= 0.0 {
                        problems.push(
                            format!("{p}.planets"),
                            n_pl,
                            format!(
                                "planets \"{}\" overlap: 2·a·sin(π/N) = {:.2} mm < tip diameter {:.2} mm",
                                file.gears[pg].name,
                                (gap + g.d_a) / MM,
                                g.d_a / MM
                            ),
                        );
                    }
                }
            }
        }
        sets.push(PlanetarySet {
            name: s.name.clone(),
            kind: s.kind,
            carrier,
            planets: n_pl,
            gears: ix,
        });
    }

    // Fixed members.
    for (i, m) in file.members.iter().enumerate() {
        if m.fixed {
            fixed_rows.push(Constraint::Brake { member: i });
        }
    }

    // Shift elements.
    let mut elem_ix: HashMap<&str, usize> = HashMap::new();
    let mut elements: Vec<ShiftElement> = Vec::new();
    let mut elem_ok = true;
    for (i, e) in file.shift_elements.iter().enumerate() {
        let p = format!("shift_elements[{i}]");
        if elem_ix.insert(e.name.as_str(), i).is_some() {
            problems.push(format!("{p}.name"), q(&e.name), "duplicate shift element name");
        }
        let want = match e.kind {
            ShiftElementKind::Clutch => 2,
            ShiftElementKind::Brake => 1,
        };
        if e.members.len() != want {
            problems.push(
                format!("{p}.members"),
                format!("{:?}", e.members),
                if want == 2 {
                    "a clutch joins exactly two members"
                } else {
                    "a brake holds exactly one member"
                },
            );
            elem_ok = false;
            continue;
        }
        let ms: Vec<Option<usize>> = e
            .members
            .iter()
            .enumerate()
            .map(|(k, n)| member(n, format!("{p}.members[{k}]"), problems))
            .collect();
        if ms.iter().any(Option::is_none) {
            elem_ok = false;
            continue;
        }
        let ms: Vec<usize> = ms.into_iter().flatten().collect();
        if want == 2 && ms[0] == ms[1] {
            problems.push(
                format!("{p}.members"),
                format!("{:?}", e.members),
                "a clutch must join two different members",
            );
            elem_ok = false;
        }
        elements.push(ShiftElement {
            name: e.name.clone(),
            kind: e.kind,
            members: ms,
        });
    }

    // Gear states.
    let mut states_spec = file.gear_states.clone();
    if states_spec.is_empty() {
        if file.shift_elements.is_empty() {
            states_spec.push(GearStateSpec {
                name: "1".into(),
                engaged: vec![],
            });
        } else {
            problems.push(
                "gear_states",
                "[]",
                "a gearbox with shift elements must list its [[gear_states]]",
            );
        }
    }
    let mut state_names = BTreeSet::new();
    let member_names: Vec<String> = file.members.iter().map(|m| m.name.clone()).collect();
    // Gear states are solved only on a sound structure, so one broken mesh is not also reported as
    // an under-determined state.
    let train = if problems.len() == structure_start {
        match GearTrain::new(member_names, fixed_rows) {
            Ok(t) => Some(t),
            Err(e) => {
                problems.push("members", "", format!("gear train: {e}"));
                None
            }
        }
    } else {
        None
    };
    let mut gear_states = Vec::new();
    for (i, st) in states_spec.iter().enumerate() {
        let p = format!("gear_states[{i}]");
        if !state_names.insert(st.name.clone()) {
            problems.push(format!("{p}.name"), q(&st.name), "duplicate gear state name");
        }
        let mut engaged = Vec::new();
        let mut seen = BTreeSet::new();
        let mut ok = true;
        for (k, en) in st.engaged.iter().enumerate() {
            match elem_ix.get(en.as_str()) {
                None => {
                    problems.push(
                        format!("{p}.engaged[{k}]"),
                        q(en),
                        format!(
                            "unknown shift element; defined: {}",
                            list(file.shift_elements.iter().map(|e| &e.name))
                        ),
                    );
                    ok = false;
                }
                Some(&j) => {
                    if !seen.insert(j) {
                        problems.push(format!("{p}.engaged[{k}]"), q(en), "listed twice");
                        ok = false;
                    }
                    engaged.push(j);
                }
            }
        }
        let (Some(train), Some(inp), Some(out), true, true) = (&train, input, output, ok, elem_ok) else {
            continue;
        };
        if input == output {
            continue;
        }
        let rows: Vec<Constraint> = engaged
            .iter()
            .map(|&j| {
                let e = &elements[j];
                match e.kind {
                    ShiftElementKind::Clutch => Constraint::Clutch {
                        a: e.members[0],
                        b: e.members[1],
                    },
                    ShiftElementKind::Brake => Constraint::Brake { member: e.members[0] },
                }
            })
            .collect();
        match train.solve_state(&rows, inp, out) {
            Ok(solution) => gear_states.push(GearState {
                name: st.name.clone(),
                engaged,
                solution,
            }),
            Err(e) => problems.push(p.clone(), q(&st.name), kinematics_message(&e, &st.engaged)),
        }
    }

    // Lubrication: heights and immersion.
    let lub = &file.lubrication;
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
    for name in lub.centre_height_mm.keys() {
        match gear_ix.get(name.as_str()) {
            None => problems.push(format!("lubrication.centre_height_mm.{name}"), "", "unknown gear"),
            Some(&gi) if planet_of.contains_key(file.gears[gi].name.as_str()) => problems.push(
                format!("lubrication.centre_height_mm.{name}"),
                "",
                "planets orbit: give the centre height of the set's sun instead (planets take the lowest orbit position)",
            ),
            _ => {}
        }
    }
    let mut heights: Vec<Option<f64>> = vec![None; file.gears.len()];
    for (gi, g) in file.gears.iter().enumerate() {
        if planet_of.contains_key(g.name.as_str()) {
            continue;
        }
        match lub.centre_height_mm.get(&g.name) {
            Some(h) if h.is_finite() => heights[gi] = Some(h * MM),
            Some(h) => problems.push(
                format!("lubrication.centre_height_mm.{}", g.name),
                h,
                "must be a finite number",
            ),
            None => problems.push(
                format!("lubrication.centre_height_mm.{}", g.name),
                "",
                "missing: every non-planet gear needs its axis height",
            ),
        }
    }
    // Planets: lowest orbit position = axis height of the set (its sun or ring) − orbit radius.
    for s in &sets {
        let axis = s.gears.iter().find_map(|&gi| heights[gi]);
        for &gi in &s.gears {
            if let (GearMount::Planet { .. }, Some(axis)) = (mounts[gi].0, axis) {
                let orbit = meshes
                    .iter()
                    .find(|m| {
                        m.set.is_some()
                            && (m.gear1 == gi || m.gear2 == gi)
                            && (mounts[m.gear1].0 == GearMount::OnMember
                                || mounts[m.gear2].0 == GearMount::OnMember)
                    })
                    .map(|m| m.geometry.a_w);
                if let Some(orbit) = orbit {
                    heights[gi] = Some(axis - orbit);
                }
            }
        }
    }
    let level = lub.oil_level_mm * MM;
    let mut gears = Vec::new();
    for (gi, g) in file.gears.iter().enumerate() {
        let (Some(geo), Some(h), Some(m)) = (geoms[gi].clone(), heights[gi], gear_member[gi]) else {
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
        });
    }

    let losses = super::losses::validate_losses(
        &file.losses.clone().unwrap_or_default(),
        lub.sump_volume_l,
        problems,
    );

    let thermal = file.thermal.as_ref().and_then(|spec| {
        let infos: Vec<GearInfo<'_>> = gears
            .iter()
            .map(|g: &Gear| GearInfo {
                name: &g.name,
                radius: 0.5 * g.geometry.d_a.max(g.geometry.d_f),
                face_width: g.geometry.spec.b,
            })
            .collect();
        let mut names = LossItemNames::default();
        names.set(Source::Churning, gears.iter().map(|g| g.name.as_str()));
        names.set(Source::Pocketing, meshes.iter().map(|m| m.name.as_str()));
        names.set(Source::Sliding, meshes.iter().map(|m| m.name.as_str()));
        validate_thermal(spec, &infos, &names, problems)
    });

    let vehicle = file.vehicle.as_ref().and_then(|table| {
        let gt = GearTable::new(
            gear_states
                .iter()
                .map(|g: &GearState| (g.name.clone(), g.ratio()))
                .collect(),
        );
        let checked = VehicleSpec::from_table(table).and_then(|spec| spec.validate(&gt));
        match checked {
            Ok(v) => Some(v),
            Err(list) => {
                for p in list {
                    problems.push(p.path, p.value, p.allowed);
                }
                None
            }
        }
    });

    if problems.len() > start {
        return None;
    }
    Some(Gearbox {
        name: file.model.name.clone(),
        description: file.model.description.clone().unwrap_or_default(),
        oil: oil?,
        members: file
            .members
            .iter()
            .map(|m| Member {
                name: m.name.clone(),
                kind: m.kind.unwrap_or(MemberKind::Shaft),
                fixed: m.fixed,
            })
            .collect(),
        gears,
        meshes,
        planetary_sets: sets,
        shift_elements: elements,
        gear_states,
        train: train?,
        input: input?,
        output: output?,
        oil_level: level,
        sump_volume: lub.sump_volume_l.map(|v| v * 1e-3),
        losses: losses?,
        thermal,
        vehicle,
    })
}

fn kind_name(k: PlanetarySetKind) -> &'static str {
    match k {
        PlanetarySetKind::Simple => "simple",
        PlanetarySetKind::DoublePinion => "double_pinion",
        PlanetarySetKind::Ravigneaux => "ravigneaux",
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

fn kinematics_message(e: &KinematicsError, engaged: &[String]) -> String {
    let what = if engaged.is_empty() {
        "no shift element engaged".to_string()
    } else {
        format!("engaged {}", engaged.join("+"))
    };
    match e {
        KinematicsError::UnderDetermined { free_members, dof } => format!(
            "under-determined ({what}): {dof} degree(s) of freedom too many; members free to turn with the input held: {}",
            free_members.join(", ")
        ),
        KinematicsError::OverConstrained { locked_members, removable_elements } => format!(
            "over-constrained ({what}): the train locks; members held: {}{}",
            locked_members.join(", "),
            if removable_elements.is_empty() {
                String::new()
            } else {
                format!("; releasing any one of {} would free it", removable_elements.iter().map(|r| r.description.clone()).collect::<Vec<_>>().join(", "))
            }
        ),
        other => format!("({what}): {other}"),
    }
}

fn q(s: &str) -> String {
    format!("\"{s}\"")
}

fn list<'a, T: AsRef<str> + 'a + ?Sized>(it: impl Iterator<Item = &'a T>) -> String {
    let v: Vec<&str> = it.map(|s| s.as_ref()).collect();
    if v.is_empty() {
        "(none)".into()
    } else {
        v.join(", ")
    }
}

fn validate_oil(o: &OilSpec, problems: &mut Problems) -> Option<Oil> {
    let variant = o.walther.unwrap_or(WaltherVariant::AstmD341);
    let inline = o.nu40_cst.is_some() || o.nu100_cst.is_some() || o.rho15_kg_m3.is_some();
    let (name, nu40, nu100, rho15, alpha) = match (&o.catalogue, inline) {
        (Some(_), true) => {
            problems.push(
                "oil",
                "",
                "give either oil.catalogue or inline nu40_cst/nu100_cst/rho15_kg_m3, not both",
            );
            return None;
        }
        (Some(c), false) => match catalogue::find(c) {
            Some(e) => (
                e.name,
                e.nu40_cst,
                e.nu100_cst,
                e.rho15_kg_m3,
                o.thermal_expansion_per_k.unwrap_or(e.thermal_expansion_per_k),
            ),
            None => {
                let keys: Vec<String> = catalogue::oils().into_iter().map(|e| e.key).collect();
                problems.push(
                    "oil.catalogue",
                    q(c),
                    format!("unknown oil; catalogue keys: {}", keys.join(", ")),
                );
                return None;
            }
        },
        (None, _) => {
            let mut miss = false;
            for (k, v) in [
                ("nu40_cst", o.nu40_cst),
                ("nu100_cst", o.nu100_cst),
                ("rho15_kg_m3", o.rho15_kg_m3),
            ] {
                if v.is_none() {
                    problems.push(
                        format!("oil.{k}"),
                        "",
                        "required for an inline oil (or give oil.catalogue)",
                    );
                    miss = true;
                }
            }
            if miss {
                return None;
            }
            (
                o.name.clone().unwrap_or_else(|| "inline oil".into()),
                o.nu40_cst.unwrap_or_default(),
                o.nu100_cst.unwrap_or_default(),
                o.rho15_kg_m3.unwrap_or_default(),
                o.thermal_expansion_per_k.unwrap_or(ALPHA_T_MINERAL),
            )
        }
    };
    let mut ok = problems.in_range("oil.nu40_cst", nu40, 1.0, 10000.0, " cSt");
    ok &= problems.in_range("oil.nu100_cst", nu100, 0.5, 1000.0, " cSt");
    ok &= problems.in_range("oil.rho15_kg_m3", rho15, 600.0, 1200.0, " kg/m3");
    ok &= problems.in_range("oil.thermal_expansion_per_k", alpha, -2e-3, 0.0, " 1/K");
    if ok && nu40 <= nu100 {
        problems.push(
            "oil.nu100_cst",
            nu100,
            format!("must be less than nu40_cst = {nu40} (oils thin as they warm)"),
        );
        ok = false;
    }
    if !ok {
        return None;
    }
    match Oil::new(name, variant, nu40 * CST, nu100 * CST, rho15, alpha) {
        Ok(oil) => Some(oil),
        Err(e) => {
            problems.push("oil", "", e.to_string());
            None
        }
    }
}

fn gear_geometry(g: &GearSpecFile, p: &str, problems: &mut Problems) -> Option<GearGeometry> {
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
    let hf = g.dedendum_factor.unwrap_or(1.25);
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
    if let Some(d) = g.root_diameter_mm {
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

#[allow(clippy::too_many_arguments)]
fn mesh_geometry(
    geoms: &[Option<GearGeometry>],
    g1: usize,
    g2: usize,
    kind: MeshKind,
    a_w: Option<f64>,
    p: &str,
    file: &ModelFile,
    problems: &mut Problems,
) -> Option<MeshGeometry> {
    let (Some(a), Some(b)) = (&geoms[g1], &geoms[g2]) else {
        return None;
    };
    let (s1, s2) = (&file.gears[g1], &file.gears[g2]);
    let mut ok = true;
    if (s1.module_mm - s2.module_mm).abs() > 1e-9 * s1.module_mm {
        problems.push(
            format!("{p}.gears"),
            format!(
                "{} ({} mm) / {} ({} mm)",
                s1.name, s1.module_mm, s2.name, s2.module_mm
            ),
            "meshing gears must have equal normal module",
        );
        ok = false;
    }
    let (pa1, pa2) = (
        s1.pressure_angle_deg.unwrap_or(20.0),
        s2.pressure_angle_deg.unwrap_or(20.0),
    );
    if (pa1 - pa2).abs() > 1e-9 {
        problems.push(
            format!("{p}.gears"),
            format!("{} ({pa1}°) / {} ({pa2}°)", s1.name, s2.name),
            "meshing gears must have equal normal pressure angle",
        );
        ok = false;
    }
    let (b1, b2) = (
        s1.helix_angle_deg.unwrap_or(0.0),
        s2.helix_angle_deg.unwrap_or(0.0),
    );
    if (b1 - b2).abs() > 1e-9 {
        problems.push(
            format!("{p}.gears"),
            format!("{} ({b1}°) / {} ({b2}°)", s1.name, s2.name),
            "meshing gears must have equal helix angle",
        );
        ok = false;
    }
    if !ok {
        return None;
    }
    match MeshGeometry::new(a, b, kind, a_w) {
        Ok(m) => {
            if m.eps_alpha < 1.0 {
                problems.push(
                    p.to_string(),
                    format!("eps_alpha = {:.4}", m.eps_alpha),
                    format!(
                        "transverse contact ratio of {}/{} must be ≥ 1 (continuous contact)",
                        s1.name, s2.name
                    ),
                );
                return None;
            }
            let interference = [
                (
                    m.interference1,
                    format!(
                        "the tip of {} reaches {} below its form circle (involute interference)",
                        s2.name, s1.name
                    ),
                ),
                (
                    m.interference2,
                    format!(
                        "the tip of {} reaches {} beyond its form circle (involute interference)",
                        s1.name, s2.name
                    ),
                ),
                (
                    m.tip_interference,
                    format!("tip interference between pinion {} and ring {}", s1.name, s2.name),
                ),
            ];
            let mut clean = true;
            for (flag, what) in interference {
                if flag {
                    problems.push(
                        p.to_string(),
                        format!("{}/{}", s1.name, s2.name),
                        format!("{what}; shorten the tip (tip_diameter_mm) or change the profile shifts"),
                    );
                    clean = false;
                }
            }
            clean.then_some(m)
        }
        Err(e) => {
            problems.push(
                p.to_string(),
                format!("{}/{}", s1.name, s2.name),
                format!("impossible mesh: {e}"),
            );
            None
        }
    }
}
