//! `[[meshes]]`: fixed-axis gear pairs, their geometry and kinematic rows.

use super::common::*;
use super::geometry::mesh_geometry;
use super::Ctx;
use crate::model::gearbox::*;
use crate::model::problems::Problems;
use crate::model::schema::*;
use crate::physics::geometry::MeshKind;
use crate::physics::kinematics::Constraint;

/// Validate `[[meshes]]` into `meshes` with their constraint rows in `fixed_rows`.
pub(super) fn validate_meshes(
    ctx: &Ctx<'_>,
    meshes: &mut Vec<Mesh>,
    fixed_rows: &mut Vec<Constraint>,
    problems: &mut Problems,
) {
    let file = ctx.file;
    let (planet_of, geoms, gear_member) = (&ctx.planet_of, &ctx.gears.geoms, &ctx.gears.member);
    let gear_lookup = |name: &str, path: String, problems: &mut Problems| ctx.gear(name, path, problems);
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
        let Some(geo) = mesh_geometry(geoms, g1, g2, mk, a_w, &p, file, problems) else {
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
}
