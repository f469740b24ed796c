//! `[[bearings]]`: rolling bearings: mounts, catalogue designations, friction models with their
//! constants, statics (at most two bearings per member or planet, one locating), heat targets.

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};

pub use super::bearing_friction::BearingMu;
use super::bearing_friction::*;
use super::common::*;
use super::gears::{Gear, GearMount};
use super::parts::Parts;
use crate::model::bearing_catalogue::{catalogue, CatalogueBearing, SeriesEntry};
use crate::model::catalogue::CatalogueOil;
use crate::model::choice::{choice, Choice};
use crate::model::problems::Problems;
use crate::physics::losses::bearings::skf::{DragForm, Lubrication};
use crate::physics::losses::bearings::BearingFriction;

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

/// `drag_form`: the edition of SKF's oil-bath drag term.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum DragFormChoice {
    /// The current SKF publication.
    #[default]
    Current,
    /// The older edition, as the FZG group's bearing code writes it.
    Older,
}
choice!(DragFormChoice {
    Current = "skf_current",
    Older = "skf_older",
});

impl DragFormChoice {
    /// The drag form of the SKF model.
    pub fn form(self) -> DragForm {
        match self {
            DragFormChoice::Current => DragForm::Current,
            DragFormChoice::Older => DragForm::Older,
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
    /// SKF μ_bl (default: the catalogue oil's fitted value for this kind of bearing, else 0.12).
    #[serde(default)]
    pub mu_bl: Option<f64>,
    /// SKF μ_EHL (default: the oil's fitted value, else SKF's by type: 0.05 balls, 0.02
    /// cylindrical, 0.002 tapered).
    #[serde(default)]
    pub mu_ehl: Option<f64>,
    /// SKF drag term (default `skf_current`; docs/physics.md §Bearings).
    #[serde(default)]
    pub drag_form: Option<DragFormChoice>,
    /// V_M of the drag term (default: SKF's diagram at the bearing's oil height).
    #[serde(default)]
    pub drag_vm: Option<f64>,
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
    /// SKF model: μ_bl and μ_EHL with their origins (None: Palmgren).
    pub mu: Option<BearingMu>,
    /// Keys the file sets that have no effect in this combination (key path and why).
    pub ineffective: Vec<(String, String)>,
    /// Every friction model of the bearing (`skf_current`, `skf_older`, `palmgren`), resolved
    /// or why not applicable (the model-form spread).
    pub alternatives: Vec<crate::model::alternative::Alternative<BearingFriction>>,
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

/// The oil the bearings run in.
pub(crate) struct OilBath<'a> {
    /// Static oil level above the datum, m.
    pub level: f64,
    /// The model's catalogue oil, if it names one (its fitted bearing μ).
    pub catalogue: Option<&'a CatalogueOil>,
}

/// Check `[[bearings]]`: names, mounts, catalogue designations, friction models with their
/// constants, heat targets (`nodes`: the thermal node names), and the statics (at most two
/// bearings per member or planet, one locating).
pub(crate) fn validate_bearings(
    specs: &[BearingSpec],
    nodes: &BTreeSet<&str>,
    parts: &Parts<'_>,
    gears: &[Gear],
    oil: &OilBath<'_>,
    problems: &mut Problems,
) -> Vec<Bearing> {
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
        let mount = mount(b, &p, parts, problems);
        let Some(entry) = catalogue_entry(&b.designation, catalogue, &p, problems) else {
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
        let axis = mount.and_then(|m| axis_height(m, parts, gears));
        let Some((friction, mu)) = friction(b, entry, series, axis, oil, &p, problems) else {
            continue;
        };
        let ineffective = ineffective_keys(b, mu.is_some(), axis, oil, entry, &p);
        let alternatives = friction_alternatives(b, entry, series, axis, oil, &p);
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
            mu,
            ineffective,
            alternatives,
        });
    }
    check_statics(&per_body, parts, &mut out, problems);
    out
}

/// Where bearing `b` sits: on a member (outer ring in the housing or on another member), or on
/// a planet's pin.
fn mount(b: &BearingSpec, p: &str, parts: &Parts<'_>, problems: &mut Problems) -> Option<BearingMount> {
    match (&b.member, &b.planet) {
        (Some(m), None) => {
            let member = parts.member(m, format!("{p}.member"), problems);
            let outer = b
                .outer
                .as_ref()
                .and_then(|o| parts.member(o, format!("{p}.outer"), problems));
            member.map(|member| BearingMount::Member { member, outer })
        }
        (None, Some(g)) => {
            let gi = parts.gear(g, format!("{p}.planet"), problems)?;
            if !parts.is_planet(gi) {
                problems.push(
                    format!("{p}.planet"),
                    q(g),
                    "not a planet of a [[planetary_sets]] entry",
                );
                return None;
            }
            if b.outer.is_some() {
                problems.push(
                    format!("{p}.outer"),
                    "",
                    "a planet bearing runs on its carrier pin: leave outer out",
                );
            }
            Some(BearingMount::Planet { gear: gi })
        }
        _ => {
            problems.push(
                p,
                "",
                "give exactly one of member (a shaft bearing) or planet (a planet-pin bearing)",
            );
            None
        }
    }
}

/// The catalogue bearing of `designation` (spaces and case ignored).
fn catalogue_entry<'c>(
    designation: &str,
    catalogue: &'c [CatalogueBearing],
    p: &str,
    problems: &mut Problems,
) -> Option<&'c CatalogueBearing> {
    let entry = catalogue
        .iter()
        .find(|c| normalise(&c.designation) == normalise(designation));
    if entry.is_none() {
        let keys: Vec<&str> = catalogue.iter().map(|c| c.designation.as_str()).collect();
        problems.push(
            format!("{p}.designation"),
            q(designation),
            format!(
                "not in the bearing catalogue models/bearings.toml; designations: {}",
                keys.join(", ")
            ),
        );
    }
    entry
}

/// Axis height of a bearing: its member's (a non-planet gear on it), or its planet's (the lowest
/// point of the orbit).
fn axis_height(mount: BearingMount, parts: &Parts<'_>, gears: &[Gear]) -> Option<f64> {
    match mount {
        BearingMount::Member { member, .. } => member_height(gears, member),
        BearingMount::Planet { gear } => gears
            .iter()
            .find(|g| g.name == parts.gears.specs[gear].name)
            .map(|g| g.centre_height),
    }
}

/// Height of the oil above the lowest point of bearing `b` (SKF's H), m: 0 for grease or an
/// unknown axis.
fn oil_above(b: &BearingSpec, entry: &CatalogueBearing, axis: Option<f64>, oil: &OilBath<'_>) -> f64 {
    match (axis, b.lubrication.unwrap_or_default().method()) {
        (Some(h), Lubrication::OilBath) => oil.level - (h - 0.5 * size_of(entry).outside),
        _ => 0.0,
    }
}

/// The friction model of bearing `b` (`model`, default SKF where the catalogue has its row),
/// with the oil height above its lowest point (SKF's H) for the drag term; for SKF also its μ
/// pair with their origins.
fn friction(
    b: &BearingSpec,
    entry: &CatalogueBearing,
    series: &[SeriesEntry],
    axis: Option<f64>,
    oil: &OilBath<'_>,
    p: &str,
    problems: &mut Problems,
) -> Option<(BearingFriction, Option<BearingMu>)> {
    match model_choice(b, entry) {
        BearingModelChoice::Skf => {
            let fitted = oil.catalogue.and_then(|o| {
                let (pair, kind) = if entry.kind.is_roller() {
                    (o.bearing_mu_roller, "roller")
                } else {
                    (o.bearing_mu_ball, "ball")
                };
                let src = o.bearing_mu_source.as_deref().unwrap_or("no source given");
                pair.map(|m| (m, format!("{} ({kind} pair: {src})", o.key)))
            });
            let choices = SkfChoices {
                sealed: b.sealed,
                lubrication: b.lubrication.unwrap_or_default().method(),
                oil_above: oil_above(b, entry, axis, oil),
                mu_bl: b.mu_bl,
                mu_ehl: b.mu_ehl,
                drag_form: b.drag_form.unwrap_or_default().form(),
                drag_vm: b.drag_vm,
                oil_mu: fitted,
            };
            let f = skf(entry, series, &choices, p, problems)?;
            let mu = skf_kind(entry.kind).map(|k| mu_pair(k, &choices));
            Some((f, mu))
        }
        BearingModelChoice::Palmgren => palmgren(entry, b.sealed, p, problems).map(|f| (f, None)),
    }
}

/// Bearing `b`'s friction with each model and SKF drag edition, by the checks of [`friction`]
/// on a copy of the entry with only that choice changed.
fn friction_alternatives(
    b: &BearingSpec,
    entry: &CatalogueBearing,
    series: &[SeriesEntry],
    axis: Option<f64>,
    oil: &OilBath<'_>,
    p: &str,
) -> Vec<crate::model::alternative::Alternative<BearingFriction>> {
    let chosen = model_choice(b, entry);
    let edition = b.drag_form.unwrap_or_default();
    [
        (BearingModelChoice::Skf, Some(DragFormChoice::Current)),
        (BearingModelChoice::Skf, Some(DragFormChoice::Older)),
        (BearingModelChoice::Palmgren, None),
    ]
    .into_iter()
    .map(|(model, drag)| {
        let spec = BearingSpec {
            model: Some(model),
            drag_form: drag.or(b.drag_form),
            ..b.clone()
        };
        let mut problems = Problems::default();
        let found = friction(&spec, entry, series, axis, oil, p, &mut problems).map(|f| f.0);
        let name = drag.map_or(model.name(), |d| d.name());
        let default = chosen == model && drag.map_or(true, |d| d == edition);
        crate::model::alternative::Alternative::checked(name, default, found, problems)
    })
    .collect()
}

/// The friction model bearing `b` asks for (default: SKF where the catalogue has its row).
fn model_choice(b: &BearingSpec, entry: &CatalogueBearing) -> BearingModelChoice {
    b.model
        .unwrap_or(if entry.kind.has_skf() && entry.series.is_some() {
            BearingModelChoice::Skf
        } else {
            BearingModelChoice::Palmgren
        })
}

/// Keys bearing `b` (at key path `p`) sets that change nothing in its combination, each with
/// the reason: the SKF keys (`mu_bl`, `mu_ehl`, `drag_form`, `drag_vm`) and `lubrication` with
/// the Palmgren model (its f0 is the oil-bath value, no drag term); the drag keys with grease or
/// with the bearing wholly above the static oil (SKF's drag term is zero there).
fn ineffective_keys(
    b: &BearingSpec,
    skf: bool,
    axis: Option<f64>,
    oil: &OilBath<'_>,
    entry: &CatalogueBearing,
    p: &str,
) -> Vec<(String, String)> {
    let drag_keys = [
        ("drag_form", b.drag_form.is_some()),
        ("drag_vm", b.drag_vm.is_some()),
    ];
    let mut out = Vec::new();
    if !skf {
        let set = [
            ("mu_bl", b.mu_bl.is_some()),
            ("mu_ehl", b.mu_ehl.is_some()),
            ("lubrication", b.lubrication.is_some()),
        ];
        for (k, _) in set.iter().chain(&drag_keys).filter(|x| x.1) {
            out.push((
                format!("{p}.{k}"),
                "model = \"palmgren\" does not use it (SKF keys; Palmgren's f0 is the oil-bath value)".into(),
            ));
        }
        return out;
    }
    let why = if b.lubrication.unwrap_or_default().method() == Lubrication::Grease {
        Some("grease: the SKF drag term applies to an oil bath only")
    } else if oil_above(b, entry, axis, oil) <= 0.0 {
        Some("the bearing lies wholly above the static oil: the SKF drag term is zero")
    } else {
        None
    };
    if let Some(why) = why {
        for (k, _) in drag_keys.iter().filter(|x| x.1) {
            out.push((format!("{p}.{k}"), why.into()));
        }
    }
    out
}

/// Statics: at most two bearings per body, at different positions; one locating (the one marked,
/// else the first).
fn check_statics(per_body: &BodyBearings, parts: &Parts<'_>, out: &mut [Bearing], problems: &mut Problems) {
    for ((kind, idx), list) in per_body {
        let what = if *kind == 0 {
            format!("member \"{}\"", parts.members.specs[*idx].name)
        } else {
            format!("planet \"{}\"", parts.gears.specs[*idx].name)
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
}
