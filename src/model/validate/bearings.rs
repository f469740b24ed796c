//! `[[bearings]]` and `[[seals]]`: mounts, catalogue designations, friction models with their
//! constants, statics (at most two bearings per member or planet, one locating), heat targets.

use std::collections::{BTreeMap, BTreeSet};

use super::common::*;
use super::Ctx;
use crate::model::bearings::*;
use crate::model::gearbox::{Gear, GearMount, PlanetarySet};
use crate::model::problems::Problems;
use crate::physics::losses::bearings::skf::{DragForm, Lubrication, SkfInput};
use crate::physics::losses::bearings::{BearingFriction, BearingSize, Palmgren, Skf, SkfConstants, SkfKind};
use crate::physics::losses::seals::{LipSeal, SealLaw};

/// μ_bl of the SKF sliding term (both peers of docs/physics.md §Bearings).
const MU_BL: f64 = 0.12;
/// μ_EHL for mineral oils (the SKF online calculator's value, as the MATLAB peer notes; the SKF
/// catalogue text gives 0.05 for mineral oils, "other bearings").
const MU_EHL: f64 = 0.05;
/// μ_EHL of cylindrical roller bearings (SKF catalogue friction chapter, as shown at
/// yumpu.com/en/document/view/55668573/skf-rolling-bearings/105; the same in peer [P5]).
const MU_EHL_CYLINDRICAL: f64 = 0.02;
/// μ_EHL of tapered roller bearings (same source).
const MU_EHL_TAPERED: f64 = 0.002;
/// V_M of the roller drag term against H/d_m: SKF's diagram as digitised by peer [P5]
/// (`drag.py`, "graph digitization" — numbers read from a figure), linear in between, constant
/// beyond 1.2.
const DRAG_VM_ROLLER: [(f64, f64); 14] = [
    (0.0, 0.0),
    (0.025, 5e-6),
    (0.05, 3.0e-5),
    (0.075, 6.0e-5),
    (0.10, 1.0e-4),
    (0.125, 1.5e-4),
    (0.15, 2.1e-4),
    (0.175, 2.6e-4),
    (0.20, 3.0e-4),
    (0.30, 4.8e-4),
    (0.50, 6.8e-4),
    (0.80, 1.0e-3),
    (1.00, 1.25e-3),
    (1.20, 1.5e-3),
];

/// V_M of the ball drag term against H/d_m: the same digitised diagram of peer [P5] (its ball
/// curve; numbers read from a figure), linear in between, constant beyond 1.2.
const DRAG_VM_BALL: [(f64, f64); 14] = [
    (0.0, 0.0),
    (0.025, 2e-6),
    (0.05, 1.2e-5),
    (0.075, 3.0e-5),
    (0.10, 6.5e-5),
    (0.125, 1.0e-4),
    (0.15, 1.45e-4),
    (0.175, 1.95e-4),
    (0.20, 2.45e-4),
    (0.30, 3.8e-4),
    (0.50, 5.5e-4),
    (0.80, 8.0e-4),
    (1.00, 1.0e-3),
    (1.20, 1.25e-3),
];

/// V_M of the curve `table` at oil height `h_over_dm` (H/d_m).
fn drag_vm_on(table: &[(f64, f64); 14], h_over_dm: f64) -> f64 {
    let x = h_over_dm.clamp(0.0, 1.2);
    table.windows(2).find(|w| x <= w[1].0).map_or(table[13].1, |w| {
        w[0].1 + (w[1].1 - w[0].1) * (x - w[0].0) / (w[1].0 - w[0].0)
    })
}

/// V_M of a roller bearing at oil height `h_over_dm` (H/d_m).
fn drag_vm_roller(h_over_dm: f64) -> f64 {
    drag_vm_on(&DRAG_VM_ROLLER, h_over_dm)
}

/// V_M of a ball bearing at oil height `h_over_dm` (H/d_m).
fn drag_vm_ball(h_over_dm: f64) -> f64 {
    drag_vm_on(&DRAG_VM_BALL, h_over_dm)
}

/// The drag form named in a model file.
fn drag_form(s: Option<&str>) -> Option<DragForm> {
    match s {
        None | Some("skf_current") => Some(DragForm::Current),
        Some("skf_older") => Some(DragForm::Older),
        Some(_) => None,
    }
}

/// SKF seal constants (K_S1, K_S2, β) by type and outside diameter D (mm): SKF, as listed by
/// thermca `bearing.seal_heat_loss` [SKF06] (the 62 < D ≤ 80 mm row agrees with the
/// eMotres catalogue).
fn seal_constants(kind: BearingType, outside_mm: f64) -> Option<(f64, f64, f64)> {
    match kind {
        BearingType::DeepGrooveBall => Some(if outside_mm <= 62.0 {
            (0.023, 2.0, 2.25)
        } else if outside_mm <= 80.0 {
            (0.018, 20.0, 2.25)
        } else if outside_mm <= 100.0 {
            (0.018, 15.0, 2.25)
        } else {
            (0.018, 0.0, 2.25)
        }),
        BearingType::AngularContactBall => Some((0.014, 10.0, 2.0)),
        BearingType::CylindricalRoller => Some((0.032, 50.0, 2.0)),
        _ => None,
    }
}

/// The fitted (μ_bl, μ_EHL) of the model's catalogue oil for roller or ball bearings, if it has
/// them.
fn oil_bearing_mu(file: &crate::model::schema::ModelFile, roller: bool) -> Option<[f64; 2]> {
    let oil = crate::model::catalogue::find(file.oil.catalogue.as_deref()?)?;
    if roller {
        oil.bearing_mu_roller
    } else {
        oil.bearing_mu_ball
    }
}

fn normalise(s: &str) -> String {
    s.chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_uppercase()
}

/// Check a `heat_to` list against the thermal node names.
fn heat_to(
    list: &Option<Vec<(String, f64)>>,
    nodes: &BTreeSet<&str>,
    path: &str,
    problems: &mut Problems,
) -> Option<Vec<(String, f64)>> {
    let l = list.as_ref()?;
    let mut sum = 0.0;
    for (k, (n, f)) in l.iter().enumerate() {
        if !nodes.contains(n.as_str()) {
            problems.push(
                format!("{path}[{k}]"),
                q(n),
                format!("unknown thermal node; nodes: {}", list_str(nodes)),
            );
        }
        problems.in_range(&format!("{path}[{k}]"), *f, 0.0, 1.0, "");
        sum += f;
    }
    if (sum - 1.0).abs() > 1e-9 {
        problems.push(path, sum, "fractions must sum to 1");
    }
    Some(l.clone())
}

fn list_str(s: &BTreeSet<&str>) -> String {
    if s.is_empty() {
        "(none: the model has no [thermal] nodes)".into()
    } else {
        s.iter().copied().collect::<Vec<_>>().join(", ")
    }
}

/// Axis height of a member: the centre height of one of its (non-planet) gears.
fn member_height(gears: &[Gear], member: usize) -> Option<f64> {
    gears
        .iter()
        .find(|g| g.member == member && g.mount == GearMount::OnMember)
        .map(|g| g.centre_height)
}

/// Bearings per body (0 member / 1 planet, index): (bearing index, `locating` as given).
type BodyBearings = BTreeMap<(u8, usize), Vec<(usize, Option<bool>)>>;

/// Validate `[[bearings]]` and `[[seals]]`.
pub(super) fn validate_bearings(
    ctx: &Ctx<'_>,
    gears: &[Gear],
    sets: &[PlanetarySet],
    oil_level: f64,
    problems: &mut Problems,
) -> (Vec<Bearing>, Vec<Seal>) {
    let file = ctx.file;
    let (series, catalogue) = catalogue();
    let nodes: BTreeSet<&str> = file
        .thermal
        .as_ref()
        .map(|t| t.nodes.iter().map(|n| n.name.as_str()).collect())
        .unwrap_or_default();
    let mut names = BTreeSet::new();
    let mut out = Vec::new();
    let mut per_body: BodyBearings = BTreeMap::new();
    for (i, b) in file.bearings.iter().enumerate() {
        let p = format!("bearings[{i}]");
        if b.name.trim().is_empty() || !b.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            problems.push(
                format!("{p}.name"),
                q(&b.name),
                "must be an identifier (letters, digits, _)",
            );
        } else if !names.insert(b.name.clone()) {
            problems.push(format!("{p}.name"), q(&b.name), "duplicate bearing name");
        }
        let mount = match (&b.member, &b.planet) {
            (Some(m), None) => {
                let member = ctx.member(m, format!("{p}.member"), problems);
                let outer = b
                    .outer
                    .as_ref()
                    .and_then(|o| ctx.member(o, format!("{p}.outer"), problems));
                member.map(|member| BearingMount::Member { member, outer })
            }
            (None, Some(g)) => {
                let gear = ctx.gear(g, format!("{p}.planet"), problems);
                match gear {
                    Some(gi) if ctx.planet_of.contains_key(file.gears[gi].name.as_str()) => {
                        if b.outer.is_some() {
                            problems.push(
                                format!("{p}.outer"),
                                "",
                                "a planet bearing runs on its carrier pin: leave outer out",
                            );
                        }
                        Some(BearingMount::Planet { gear: gi })
                    }
                    Some(_) => {
                        problems.push(
                            format!("{p}.planet"),
                            q(g),
                            "not a planet of a [[planetary_sets]] entry",
                        );
                        None
                    }
                    None => None,
                }
            }
            _ => {
                problems.push(
                    &p,
                    "",
                    "give exactly one of member (a shaft bearing) or planet (a planet-pin bearing)",
                );
                None
            }
        };
        let entry = catalogue
            .iter()
            .find(|c| normalise(&c.designation) == normalise(&b.designation));
        let Some(entry) = entry else {
            let keys: Vec<&str> = catalogue.iter().map(|c| c.designation.as_str()).collect();
            problems.push(
                format!("{p}.designation"),
                q(&b.designation),
                format!(
                    "not in the bearing catalogue models/bearings.toml; designations: {}",
                    keys.join(", ")
                ),
            );
            continue;
        };
        if !b.position_mm.is_finite() {
            problems.push(
                format!("{p}.position_mm"),
                b.position_mm,
                "must be a finite number",
            );
        }
        problems.in_range(
            &format!("{p}.radial_preload_n"),
            b.radial_preload_n,
            0.0,
            1e7,
            " N",
        );
        problems.in_range(&format!("{p}.axial_preload_n"), b.axial_preload_n, 0.0, 1e7, " N");
        let lubrication = match b.lubrication.as_deref() {
            None | Some("oil_bath") => Lubrication::OilBath,
            Some("grease") => Lubrication::Grease,
            Some(other) => {
                problems.push(format!("{p}.lubrication"), q(other), "must be oil_bath or grease");
                Lubrication::OilBath
            }
        };
        let choice = b
            .model
            .unwrap_or(if entry.kind.has_skf() && entry.series.is_some() {
                BearingModelChoice::Skf
            } else {
                BearingModelChoice::Palmgren
            });
        let size = BearingSize {
            bore: entry.d_mm * MM,
            outside: entry.outside_mm * MM,
        };
        // Height of the oil above the bearing's lowest point (SKF's H), for the drag term.
        let axis = match mount {
            Some(BearingMount::Member { member, .. }) => member_height(gears, member),
            Some(BearingMount::Planet { gear }) => gears
                .iter()
                .find(|g| g.name == file.gears[gear].name)
                .map(|g| g.centre_height),
            None => None,
        };
        let oil_above = match (axis, lubrication) {
            (Some(h), Lubrication::OilBath) => oil_level - (h - 0.5 * size.outside),
            _ => 0.0,
        };
        let friction = match choice {
            BearingModelChoice::Skf => {
                let row = entry
                    .series
                    .as_ref()
                    .and_then(|s| series.iter().find(|r| &r.series == s && r.kind == entry.kind));
                let (Some(row), true) = (row, entry.kind.has_skf()) else {
                    problems.push(
                        format!("{p}.model"),
                        "skf",
                        format!(
                            "{} ({:?}): no SKF geometry constants for this bearing in the catalogue (needle roller \
                             bearings have no SKF row in any source found; other types need a `series` row); use model = \"palmgren\"",
                            entry.designation, entry.kind
                        ),
                    );
                    continue;
                };
                let seal = if b.sealed {
                    seal_constants(entry.kind, entry.outside_mm).map(|(k1, k2, beta)| {
                        // Seal counterface d_s ≈ d + 0.25(D − d) (eMotres catalogue estimate).
                        (
                            k1,
                            k2,
                            beta,
                            (entry.d_mm + 0.25 * (entry.outside_mm - entry.d_mm)) * MM,
                        )
                    })
                } else {
                    None
                };
                let kind = match entry.kind {
                    BearingType::AngularContactBall => SkfKind::AngularContactBall,
                    BearingType::FourPointContactBall => SkfKind::FourPointContactBall,
                    BearingType::CylindricalRoller => SkfKind::CylindricalRoller,
                    BearingType::TaperedRoller => SkfKind::TaperedRoller,
                    _ => SkfKind::DeepGrooveBall,
                };
                let (mu_ehl, drag_vm) = match entry.kind {
                    BearingType::CylindricalRoller | BearingType::TaperedRoller => (
                        if entry.kind == BearingType::TaperedRoller {
                            MU_EHL_TAPERED
                        } else {
                            MU_EHL_CYLINDRICAL
                        },
                        drag_vm_roller(oil_above / size.mean()),
                    ),
                    _ => (MU_EHL, drag_vm_ball(oil_above / size.mean())),
                };
                // μ_bl, μ_EHL: the entry's, else the oil's fitted pair for this kind of bearing,
                // else SKF's constants.
                let oil_mu = oil_bearing_mu(file, entry.kind.is_roller());
                let mu_bl = b.mu_bl.or(oil_mu.map(|m| m[0])).unwrap_or(MU_BL);
                let mu_ehl = b.mu_ehl.or(oil_mu.map(|m| m[1])).unwrap_or(mu_ehl);
                for (k, v) in [("mu_bl", mu_bl), ("mu_ehl", mu_ehl)] {
                    problems.in_range(&format!("{p}.{k}"), v, 0.0, 0.5, "");
                }
                let Some(form) = drag_form(b.drag_form.as_deref()) else {
                    problems.push(
                        format!("{p}.drag_form"),
                        q(b.drag_form.as_deref().unwrap_or_default()),
                        "must be skf_current or skf_older",
                    );
                    continue;
                };
                let drag_vm = b.drag_vm.unwrap_or(drag_vm);
                problems.in_range(&format!("{p}.drag_vm"), drag_vm, 0.0, 0.01, "");
                let input = SkfInput {
                    kind,
                    constants: SkfConstants {
                        r1: row.r1,
                        r2: row.r2,
                        r3: row.r3,
                        s1: row.s1,
                        s2: row.s2,
                        s3: row.s3,
                        k_z: row.k_z,
                        k_l: row.k_l,
                    },
                    size,
                    c0: entry.c0_kn * 1e3,
                    lubrication,
                    mu_bl,
                    mu_ehl,
                    seal,
                    oil_level: oil_above,
                    drag_vm,
                    drag_form: form,
                    rows: entry.rows.unwrap_or(1.0),
                    width: entry.b_mm * MM,
                    axial_factor_y: entry.y.unwrap_or(0.0),
                };
                match Skf::new(&input) {
                    Ok(m) => BearingFriction::Skf(m),
                    Err(e) => {
                        problems.push(&p, q(&entry.designation), e.to_string());
                        continue;
                    }
                }
            }
            BearingModelChoice::Palmgren => {
                if b.sealed {
                    problems.push(format!("{p}.sealed"), "true", "integral seals are modelled by the SKF seal term only: use model = \"skf\" or a [[seals]] entry");
                }
                let (f0_bath, f1, ka, kr) = entry.kind.palmgren_defaults();
                // Grease: f0 of thermca's grease column is not carried; oil bath is the gearbox case.
                let f0 = f0_bath;
                match Palmgren::new(size, f0, f1, ka, kr) {
                    Ok(m) => BearingFriction::Palmgren(m),
                    Err(e) => {
                        problems.push(&p, q(&entry.designation), e.to_string());
                        continue;
                    }
                }
            }
        };
        let heat = heat_to(&b.heat_to, &nodes, &format!("{p}.heat_to"), problems);
        let Some(mount) = mount else { continue };
        let key = match mount {
            BearingMount::Member { member, .. } => (0u8, member),
            BearingMount::Planet { gear } => (1u8, gear),
        };
        per_body.entry(key).or_default().push((out.len(), b.locating));
        out.push(Bearing {
            name: b.name.clone(),
            designation: entry.designation.clone(),
            mount,
            position: b.position_mm * MM,
            locating: false,
            friction,
            preload: (b.radial_preload_n, b.axial_preload_n),
            heat_to: heat,
        });
    }
    // Statics: at most two bearings per body, at different positions; one locating.
    for ((kind, idx), list) in &per_body {
        let what = if *kind == 0 {
            format!("member \"{}\"", file.members[*idx].name)
        } else {
            format!("planet \"{}\"", file.gears[*idx].name)
        };
        if list.len() > 2 {
            problems.push(
                "bearings",
                what.clone(),
                "more than two bearings on one member or planet: statically indeterminate; give at most two",
            );
            continue;
        }
        if list.len() == 2 && (out[list[0].0].position - out[list[1].0].position).abs() < 1e-9 {
            problems.push(
                "bearings",
                what.clone(),
                "its two bearings sit at the same position_mm",
            );
        }
        let explicit: Vec<usize> = list.iter().filter(|x| x.1 == Some(true)).map(|x| x.0).collect();
        match explicit.as_slice() {
            [] => out[list[0].0].locating = true,
            [k] => out[*k].locating = true,
            _ => problems.push("bearings", what, "more than one locating bearing"),
        }
    }
    let _ = sets;
    let seals = validate_seals(ctx, &nodes, problems);
    (out, seals)
}

fn validate_seals(ctx: &Ctx<'_>, nodes: &BTreeSet<&str>, problems: &mut Problems) -> Vec<Seal> {
    let mut names = BTreeSet::new();
    let mut out = Vec::new();
    for (i, s) in ctx.file.seals.iter().enumerate() {
        let p = format!("seals[{i}]");
        if s.name.trim().is_empty() || !s.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            problems.push(
                format!("{p}.name"),
                q(&s.name),
                "must be an identifier (letters, digits, _)",
            );
        } else if !names.insert(s.name.clone()) {
            problems.push(format!("{p}.name"), q(&s.name), "duplicate seal name");
        }
        let member = ctx.member(&s.member, format!("{p}.member"), problems);
        let outer = s
            .outer
            .as_ref()
            .and_then(|o| ctx.member(o, format!("{p}.outer"), problems));
        let ok = problems.in_range(
            &format!("{p}.shaft_diameter_mm"),
            s.shaft_diameter_mm,
            1.0,
            2000.0,
            " mm",
        );
        let law = match s.torque_nm {
            Some(t) => {
                problems.in_range(&format!("{p}.torque_nm"), t, 0.0, 1e4, " N m");
                SealLaw::Torque(t)
            }
            None => SealLaw::Iso14179,
        };
        let heat = heat_to(&s.heat_to, nodes, &format!("{p}.heat_to"), problems);
        if let (Some(member), true) = (member, ok) {
            out.push(Seal {
                name: s.name.clone(),
                member,
                outer,
                seal: LipSeal {
                    shaft_diameter: s.shaft_diameter_mm * MM,
                    law,
                },
                heat_to: heat,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::drag_vm_roller;

    /// The roller V_M curve as the peer P5 interpolates it (its printed values,
    /// docs/validation.md §Bearings).
    #[test]
    fn roller_vm_interpolates_like_the_p5_peer() {
        for (x, want) in [(0.75, 9.466667e-4), (1.2, 1.5e-3), (10.0 / 46.0, 3.313043e-4)] {
            assert!((drag_vm_roller(x) / want - 1.0).abs() < 1e-6, "{x}");
        }
        assert_eq!(drag_vm_roller(-1.0), 0.0);
        assert_eq!(drag_vm_roller(5.0), 1.5e-3);
    }
}
