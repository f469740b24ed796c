//! `[[bearings]]`: rolling bearings: mounts, catalogue designations, friction models with their
//! constants, statics (at most two bearings per member or planet, one locating), heat targets.

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};

use super::bearing_friction::*;
use super::common::*;
use super::gears::{Gear, GearMount};
use super::parts::Parts;
use crate::model::bearing_catalogue::{catalogue, BearingType};
use crate::model::choice::choice;
use crate::model::problems::Problems;
use crate::physics::losses::bearings::skf::{Lubrication, SkfInput};
use crate::physics::losses::bearings::{BearingFriction, BearingSize, Palmgren, Skf, SkfConstants, SkfKind};

/// Friction model choice of a bearing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BearingModelChoice {
    /// SKF (2004) (every type with a catalogue row: all but needle roller bearings).
    Skf,
    /// Palmgren.
    Palmgren,
}
choice!(BearingModelChoice {
    Skf = "skf",
    Palmgren = "palmgren",
});

/// Lubrication of a bearing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum LubricationChoice {
    /// Oil bath, splash or jet: K_rs 3e-8, with the drag term.
    #[default]
    OilBath,
    /// Grease or oil-air: K_rs 6e-8, no drag term.
    Grease,
}
choice!(LubricationChoice {
    OilBath = "oil_bath",
    Grease = "grease",
});

impl LubricationChoice {
    /// The lubrication method of the SKF model.
    pub fn method(self) -> Lubrication {
        match self {
            LubricationChoice::OilBath => Lubrication::OilBath,
            LubricationChoice::Grease => Lubrication::Grease,
        }
    }
}

/// `[[bearings]]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BearingSpec {
    /// Unique name.
    pub name: String,
    /// Member whose shaft runs in the bearing (inner ring); exclusive with `planet`.
    #[serde(default)]
    pub member: Option<String>,
    /// Planet gear the bearing supports on its carrier pin (one bearing per planet).
    #[serde(default)]
    pub planet: Option<String>,
    /// Member holding the outer ring (default: the housing).
    #[serde(default)]
    pub outer: Option<String>,
    /// Catalogue designation.
    pub designation: String,
    /// Axial position along the member, mm (the member's axis; gears have `position_mm` too).
    #[serde(default)]
    pub position_mm: f64,
    /// This bearing takes the member's axial load (default: the first bearing of the member).
    #[serde(default)]
    pub locating: Option<bool>,
    /// Friction model (default: `skf` where the type has an SKF row, else `palmgren`).
    #[serde(default)]
    pub model: Option<BearingModelChoice>,
    /// Constant radial load added to the gear loads (e.g. weight), N.
    #[serde(default)]
    pub radial_preload_n: f64,
    /// Constant axial load added to the gear loads (e.g. a preload), N.
    #[serde(default)]
    pub axial_preload_n: f64,
    /// Integral contact seals (SKF seal term; deep-groove ball bearings `-2RS`): `true` uses the
    /// SKF constants by outside diameter.
    #[serde(default)]
    pub sealed: bool,
    /// Lubrication (default `oil_bath`).
    #[serde(default)]
    pub lubrication: Option<LubricationChoice>,
    /// Thermal nodes that receive the heat with fractions (default: the member's or planet's
    /// body node, else the oil).
    #[serde(default)]
    pub heat_to: Option<Vec<(String, f64)>>,
    /// Where the entry's choices come from (free text, shown by `geartherm info`).
    #[serde(default)]
    pub source: Option<String>,
}

/// Where a bearing sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BearingMount {
    /// On a member (inner ring), outer ring in the housing or on another member.
    Member {
        /// Member index.
        member: usize,
        /// Outer-ring member (None: housing).
        outer: Option<usize>,
    },
    /// On a planet's pin: one bearing per planet of the set.
    Planet {
        /// Planet gear index.
        gear: usize,
    },
}

/// A checked bearing.
#[derive(Debug, Clone)]
pub struct Bearing {
    /// Name.
    pub name: String,
    /// Designation.
    pub designation: String,
    /// Mount.
    pub mount: BearingMount,
    /// Axial position on its member, m.
    pub position: f64,
    /// Takes the axial load of its member.
    pub locating: bool,
    /// Friction model with everything constant precomputed.
    pub friction: BearingFriction,
    /// Constant radial and axial loads, N.
    pub preload: (f64, f64),
    /// Heat destinations named in the file.
    pub heat_to: Option<Vec<(String, f64)>>,
}

fn normalise(s: &str) -> String {
    s.chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_uppercase()
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

/// Check `[[bearings]]`: names, mounts, catalogue designations, friction models with their
/// constants, heat targets (`nodes`: the thermal node names), and the statics (at most two
/// bearings per member or planet, one locating).
pub(crate) fn validate_bearings(
    specs: &[BearingSpec],
    nodes: &BTreeSet<&str>,
    parts: &Parts<'_>,
    gears: &[Gear],
    oil_level: f64,
    problems: &mut Problems,
) -> Vec<Bearing> {
    let (gear_specs, members) = (parts.gears.specs, parts.members.specs);
    let (series, catalogue) = catalogue();
    let mut names = BTreeSet::new();
    let mut out = Vec::new();
    let mut per_body: BodyBearings = BTreeMap::new();
    for (i, b) in specs.iter().enumerate() {
        let p = format!("bearings[{i}]");
        if !is_identifier(&b.name) {
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
                let member = parts.member(m, format!("{p}.member"), problems);
                let outer = b
                    .outer
                    .as_ref()
                    .and_then(|o| parts.member(o, format!("{p}.outer"), problems));
                member.map(|member| BearingMount::Member { member, outer })
            }
            (None, Some(g)) => {
                let gear = parts.gear(g, format!("{p}.planet"), problems);
                match gear {
                    Some(gi) if parts.is_planet(gi) => {
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
        let lubrication = b.lubrication.unwrap_or_default().method();
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
                .find(|g| g.name == gear_specs[gear].name)
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
                    _ => (MU_EHL, DRAG_VM),
                };
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
                    mu_bl: MU_BL,
                    mu_ehl,
                    seal,
                    oil_level: oil_above,
                    drag_vm,
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
        let heat = heat_to(&b.heat_to, nodes, &format!("{p}.heat_to"), problems);
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
            format!("member \"{}\"", members[*idx].name)
        } else {
            format!("planet \"{}\"", gear_specs[*idx].name)
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
    out
}
