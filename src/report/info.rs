//! `geartherm info`: gear states, ratios, member speeds, mesh geometry and immersion, as a
//! serializable report (JSON) and as text tables.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use crate::model::gearbox::{GearMount, Gearbox, ShiftElementKind};
use crate::physics::geometry::MeshKind;
use crate::physics::oil::{T100_K, T40_K};

const MM: f64 = 1e3;
const DEG: f64 = 180.0 / std::f64::consts::PI;

/// Speed of one gear per unit input speed.
#[derive(Debug, Serialize)]
pub struct GearSpeedInfo {
    /// Gear name.
    pub gear: String,
    /// Absolute speed / input speed.
    pub absolute: f64,
    /// Speed relative to its set's carrier / input speed (absolute for fixed-axis gears).
    pub relative_to_carrier: f64,
}

/// One gear state.
#[derive(Debug, Serialize)]
pub struct GearStateInfo {
    /// Name.
    pub name: String,
    /// ω_in / ω_out (negative for reverse).
    pub ratio: f64,
    /// Engaged shift elements.
    pub engaged: Vec<String>,
    /// Member speeds per unit input speed.
    pub member_speeds: BTreeMap<String, f64>,
    /// Gear speeds per unit input speed.
    pub gear_speeds: Vec<GearSpeedInfo>,
    /// Torque on the output member per unit input torque (lossless; = −ratio).
    pub output_torque_per_input: f64,
    /// Torque carried by each engaged shift element per unit input torque (clutch: on its first
    /// member; brake: housing reaction).
    pub element_torques: BTreeMap<String, f64>,
    /// Torque on gear 1 of each mesh (one planet's mesh) per unit input torque.
    pub mesh_torques: BTreeMap<String, f64>,
}

/// One mesh.
#[derive(Debug, Serialize)]
pub struct MeshInfo {
    /// Name.
    pub name: String,
    /// Gear 1 and gear 2.
    pub gears: [String; 2],
    /// `external` or `internal`.
    pub kind: &'static str,
    /// Planetary set, if any.
    pub planetary_set: Option<String>,
    /// Meshes in parallel (planets).
    pub multiplicity: u32,
    /// Operating centre distance, mm.
    pub centre_distance_mm: f64,
    /// Operating transverse pressure angle, degrees.
    pub operating_pressure_angle_deg: f64,
    /// Transverse contact ratio ε_α.
    pub transverse_contact_ratio: f64,
    /// Overlap ratio ε_β.
    pub overlap_ratio: f64,
    /// Total contact ratio ε_γ.
    pub total_contact_ratio: f64,
    /// Length of the path of contact g_α, mm.
    pub path_of_contact_mm: f64,
    /// Transverse base pitch, mm.
    pub base_pitch_mm: f64,
}

/// One gear.
#[derive(Debug, Serialize)]
pub struct GearInfo {
    /// Name.
    pub name: String,
    /// Member (carrier for planets).
    pub member: String,
    /// Planet of a set.
    pub planet: bool,
    /// Internal (ring) gear.
    pub internal: bool,
    /// Teeth.
    pub teeth: u32,
    /// Normal module, mm.
    pub module_mm: f64,
    /// Helix angle, degrees.
    pub helix_angle_deg: f64,
    /// Reference diameter, mm.
    pub reference_diameter_mm: f64,
    /// Base diameter, mm.
    pub base_diameter_mm: f64,
    /// Tip diameter, mm.
    pub tip_diameter_mm: f64,
    /// Root diameter, mm.
    pub root_diameter_mm: f64,
    /// Face width, mm.
    pub face_width_mm: f64,
    /// Depth of the lowest point below the static oil level, mm (≤ 0: not immersed).
    pub immersion_mm: f64,
    /// Dips into the oil.
    pub immersed: bool,
}

/// Oil summary.
#[derive(Debug, Serialize)]
pub struct OilInfo {
    /// Name.
    pub name: String,
    /// ν at 40 °C, cSt.
    pub nu40_cst: f64,
    /// ν at 100 °C, cSt.
    pub nu100_cst: f64,
    /// ρ at 15 °C, kg/m³.
    pub rho15_kg_m3: f64,
    /// Walther slope B.
    pub walther_b: f64,
}

/// The whole `info` report.
#[derive(Debug, Serialize)]
pub struct Info {
    /// Model name.
    pub model: String,
    /// Oil.
    pub oil: OilInfo,
    /// Input member.
    pub input: String,
    /// Output member.
    pub output: String,
    /// Gear states.
    pub gear_states: Vec<GearStateInfo>,
    /// Meshes.
    pub meshes: Vec<MeshInfo>,
    /// Gears.
    pub gears: Vec<GearInfo>,
    /// Bearings: friction model and μ pair with its origin.
    pub bearings: Vec<super::bearing_info::BearingInfo>,
}

/// Build the report.
pub fn info(gb: &Gearbox) -> Info {
    let mname = |i: usize| gb.members[i].name.clone();
    let gear_states = gb
        .gear_states
        .iter()
        .enumerate()
        .map(|(si, st)| {
            let sol = &st.solution;
            let speeds = gb.gear_speeds(si);
            let torques = gb.mesh_torques(si);
            GearStateInfo {
                name: st.name.clone(),
                ratio: st.ratio(),
                engaged: st
                    .engaged
                    .iter()
                    .map(|&j| gb.shift_elements[j].name.clone())
                    .collect(),
                member_speeds: sol
                    .speeds
                    .iter()
                    .enumerate()
                    .map(|(i, w)| (mname(i), *w))
                    .collect(),
                gear_speeds: gb
                    .gears
                    .iter()
                    .zip(&speeds)
                    .map(|(g, s)| GearSpeedInfo {
                        gear: g.name.clone(),
                        absolute: s.absolute,
                        relative_to_carrier: s.relative,
                    })
                    .collect(),
                output_torque_per_input: sol.output_torque,
                element_torques: st
                    .engaged
                    .iter()
                    .enumerate()
                    .map(|(k, &j)| (gb.shift_elements[j].name.clone(), sol.element_torque(k)))
                    .collect(),
                mesh_torques: gb
                    .meshes
                    .iter()
                    .zip(&torques)
                    .map(|(m, t)| (m.name.clone(), *t))
                    .collect(),
            }
        })
        .collect();
    let meshes = gb
        .meshes
        .iter()
        .map(|m| {
            let g = &m.geometry;
            MeshInfo {
                name: m.name.clone(),
                gears: [gb.gears[m.gear1].name.clone(), gb.gears[m.gear2].name.clone()],
                kind: match g.kind {
                    MeshKind::External => "external",
                    MeshKind::Internal => "internal",
                },
                planetary_set: m.set.map(|s| gb.planetary_sets[s].name.clone()),
                multiplicity: m.multiplicity,
                centre_distance_mm: g.a_w * MM,
                operating_pressure_angle_deg: g.alpha_wt * DEG,
                transverse_contact_ratio: g.eps_alpha,
                overlap_ratio: g.eps_beta,
                total_contact_ratio: g.eps_gamma,
                path_of_contact_mm: g.g_alpha * MM,
                base_pitch_mm: g.p_bt * MM,
            }
        })
        .collect();
    let gears = gb
        .gears
        .iter()
        .map(|g| {
            let geo = &g.geometry;
            GearInfo {
                name: g.name.clone(),
                member: mname(g.member),
                planet: matches!(g.mount, GearMount::Planet { .. }),
                internal: geo.is_internal(),
                teeth: geo.z(),
                module_mm: geo.spec.mn * MM,
                helix_angle_deg: geo.spec.beta * DEG,
                reference_diameter_mm: geo.d * MM,
                base_diameter_mm: geo.d_b * MM,
                tip_diameter_mm: geo.d_a * MM,
                root_diameter_mm: geo.d_f * MM,
                face_width_mm: geo.spec.b * MM,
                immersion_mm: g.immersion * MM,
                immersed: g.is_immersed(),
            }
        })
        .collect();
    Info {
        model: gb.name.clone(),
        oil: OilInfo {
            name: gb.oil.name.clone(),
            nu40_cst: gb.oil.nu(T40_K) * 1e6,
            nu100_cst: gb.oil.nu(T100_K) * 1e6,
            rho15_kg_m3: gb.oil.rho15,
            walther_b: gb.oil.walther.b,
        },
        input: mname(gb.input),
        output: mname(gb.output),
        gear_states,
        meshes,
        gears,
        bearings: super::bearing_info::bearing_infos(gb),
    }
}

/// Text tables for a terminal.
pub fn to_text(info: &Info, gb: &Gearbox) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "model: {}", info.model);
    let _ = writeln!(
        s,
        "oil:   {} (nu40 {:.2} cSt, nu100 {:.2} cSt, rho15 {:.1} kg/m3)",
        info.oil.name, info.oil.nu40_cst, info.oil.nu100_cst, info.oil.rho15_kg_m3
    );
    let _ = writeln!(s, "input: {}   output: {}\n", info.input, info.output);
    let _ = writeln!(
        s,
        "gear states (ratio = input speed / output speed; member speeds per unit input speed)"
    );
    let mut header = format!("  {:<6} {:>9}  {:<10}", "state", "ratio", "engaged");
    for m in &gb.members {
        let _ = write!(header, " {:>10}", truncate(&m.name, 10));
    }
    let _ = writeln!(s, "{header}");
    for st in &info.gear_states {
        let _ = write!(
            s,
            "  {:<6} {:>9.4}  {:<10}",
            st.name,
            st.ratio,
            st.engaged.join("+")
        );
        for m in &gb.members {
            let _ = write!(
                s,
                " {:>10.4}",
                st.member_speeds.get(&m.name).copied().unwrap_or(f64::NAN)
            );
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "\nshift-element torques per unit input torque");
    for st in &info.gear_states {
        let parts: Vec<String> = st
            .element_torques
            .iter()
            .map(|(k, v)| {
                let kind = gb.shift_elements.iter().find(|e| &e.name == k).map_or("", |e| {
                    if e.kind == ShiftElementKind::Clutch {
                        "clutch"
                    } else {
                        "brake"
                    }
                });
                format!("{k} ({kind}) {v:+.4}")
            })
            .collect();
        let _ = writeln!(
            s,
            "  {:<6} {}",
            st.name,
            if parts.is_empty() {
                "-".into()
            } else {
                parts.join(", ")
            }
        );
    }
    let _ = writeln!(s, "\nmeshes");
    let _ = writeln!(
        s,
        "  {:<28} {:<8} {:>3} {:>10} {:>8} {:>7} {:>7} {:>7}",
        "name", "kind", "n", "a_w [mm]", "a_wt [°]", "eps_a", "eps_b", "eps_g"
    );
    for m in &info.meshes {
        let _ = writeln!(
            s,
            "  {:<28} {:<8} {:>3} {:>10.4} {:>8.4} {:>7.4} {:>7.4} {:>7.4}",
            truncate(&m.name, 28),
            m.kind,
            m.multiplicity,
            m.centre_distance_mm,
            m.operating_pressure_angle_deg,
            m.transverse_contact_ratio,
            m.overlap_ratio,
            m.total_contact_ratio
        );
    }
    let _ = writeln!(s, "\ngears");
    let _ = writeln!(
        s,
        "  {:<14} {:<14} {:>4} {:>7} {:>9} {:>9} {:>9} {:>9} {:>11}",
        "name", "member", "z", "m [mm]", "d [mm]", "d_a [mm]", "d_f [mm]", "b [mm]", "immers.[mm]"
    );
    for g in &info.gears {
        let _ = writeln!(
            s,
            "  {:<14} {:<14} {:>4} {:>7.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>11}",
            truncate(&g.name, 14),
            truncate(&g.member, 14),
            g.teeth,
            g.module_mm,
            g.reference_diameter_mm,
            g.tip_diameter_mm,
            g.root_diameter_mm,
            g.face_width_mm,
            if g.immersed {
                format!("{:.2}", g.immersion_mm)
            } else {
                format!("- ({:.1})", g.immersion_mm)
            }
        );
    }
    s.push_str(&super::bearing_info::bearings_text(&info.bearings));
    s
}

fn truncate(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        s.chars().take(n - 1).chain(std::iter::once('…')).collect()
    }
}
