//! `[circuit]`: the lubrication circuit — sources that deliver oil (a share of the `[pump]`'s flow,
//! an electric pump with its own control, splash from a dipping gear) and the consumers it is split
//! over (a mesh, a jet at a mesh, a planetary set fed through its shaft, a clutch pack, a bearing),
//! by fixed shares or by orifices. The scene turns it into a flow per consumer at every state
//! (docs/physics.md §14, docs/model-file.md `[circuit]`).

use std::collections::BTreeSet;

use serde::{Deserialize, Serialize};

use super::common::{list, q, DEG, MM};
use crate::model::choice::{choice, Choice};
use crate::model::problems::Problems;
use crate::physics::losses::curve::Curve;

/// At most this many sources (the scene keeps their per-sample values in fixed arrays).
pub const MAX_SOURCES: usize = 8;

/// L/min → m³/s.
const L_PER_MIN: f64 = 1e-3 / 60.0;

/// `kind` of a source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceKindChoice {
    /// A share of the `[pump]`'s delivered flow.
    Pump,
    /// An electric pump with its own drive: flow over the gearbox input speed (its control map).
    ElectricPump,
    /// Oil thrown off a dipping gear: flow over the gear's pitch-line speed.
    Splash,
}
choice!(SourceKindChoice {
    Pump = "pump",
    ElectricPump = "electric_pump",
    Splash = "splash",
});

/// `kind` of a consumer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConsumerKindChoice {
    /// Oil delivered to a mesh (drip, splash).
    Mesh,
    /// A jet nozzle aimed at a mesh.
    Jet,
    /// A planetary set fed through its shaft.
    Set,
    /// A clutch pack (its drag then takes this flow).
    ClutchPack,
    /// A bearing.
    Bearing,
}
choice!(ConsumerKindChoice {
    Mesh = "mesh",
    Jet = "jet",
    Set = "set",
    ClutchPack = "clutch_pack",
    Bearing = "bearing",
});

/// A flow table: L/min over an abscissa.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FlowTable {
    /// Gearbox input speed, rpm (electric pump) — or pitch-line speed, m/s (splash).
    #[serde(default)]
    pub input_rpm: Option<Vec<f64>>,
    /// Pitch-line speed of the splashing gear, m/s.
    #[serde(default)]
    pub speed_m_s: Option<Vec<f64>>,
    /// Flow, L/min.
    pub l_per_min: Vec<f64>,
}

/// `[[circuit.sources]]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SourceSpec {
    /// Name (unique).
    pub name: String,
    /// `pump`, `electric_pump` or `splash`.
    pub kind: SourceKindChoice,
    /// `pump`: fraction of the pump's delivered flow sent to lubrication, (0, 1].
    #[serde(default)]
    pub share: Option<f64>,
    /// `electric_pump`: flow over input speed; `splash`: flow over pitch-line speed.
    #[serde(default)]
    pub flow: Option<FlowTable>,
    /// `splash`: the dipping gear.
    #[serde(default)]
    pub gear: Option<String>,
    /// Pressure ahead of the orifices, bar (`pump`: default the line pressure; `electric_pump`:
    /// required, also sets its drive power).
    #[serde(default)]
    pub pressure_bar: Option<f64>,
    /// `electric_pump`: pump efficiency (hydraulic power / drive power), (0.05, 1].
    #[serde(default)]
    pub efficiency: Option<f64>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// `[[circuit.consumers]]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ConsumerSpec {
    /// Name (unique).
    pub name: String,
    /// `mesh`, `jet`, `set`, `clutch_pack` or `bearing`.
    pub kind: ConsumerKindChoice,
    /// The mesh, planetary set, shift element (of a clutch pack) or bearing fed.
    pub target: String,
    /// The source (default: the only one).
    #[serde(default)]
    pub source: Option<String>,
    /// Fixed fraction of the source's flow, (0, 1].
    #[serde(default)]
    pub share: Option<f64>,
    /// Orifice diameter, mm (flow C_d·A·√(2p/ρ), scaled down together with the source's other
    /// orifices when they ask for more than it delivers).
    #[serde(default)]
    pub orifice_mm: Option<f64>,
    /// Discharge coefficient of the orifice (required with `orifice_mm`).
    #[serde(default)]
    pub discharge_coefficient: Option<f64>,
    /// Thermal node the oil flows through and leaves at its temperature (default: the body node of
    /// the target's gears for meshes, jets and sets; none for packs and bearings).
    #[serde(default)]
    pub node: Option<String>,
    /// `jet`: jet speed, m/s (default √(2p/ρ) from the source's pressure).
    #[serde(default)]
    pub jet_speed_m_s: Option<f64>,
    /// `jet`: angle between the jet and the teeth's pitch-line velocity, degrees (0: with the
    /// teeth, 90: radial, 180: against them; default 90).
    #[serde(default)]
    pub jet_angle_deg: Option<f64>,
    /// `set`: radius at which the flung oil leaves the carrier, mm (default: planet orbit + planet
    /// tip radius).
    #[serde(default)]
    pub fling_radius_mm: Option<f64>,
    /// Where the numbers come from, or why they were chosen.
    #[serde(default)]
    pub note: Option<String>,
}

/// `[circuit]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CircuitSpec {
    /// Oil sources.
    #[serde(default)]
    pub sources: Vec<SourceSpec>,
    /// Consumers the flow is split over.
    #[serde(default)]
    pub consumers: Vec<ConsumerSpec>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// A checked source (SI).
#[derive(Debug, Clone, PartialEq)]
pub enum SourceKind {
    /// `share` of the `[pump]`'s delivered flow.
    Pump {
        /// Fraction of the pump's flow.
        share: f64,
    },
    /// Electric pump: flow (m³/s) over input speed (rad/s); drive power Q·p/efficiency.
    ElectricPump {
        /// Flow over input speed.
        flow: Curve,
        /// Efficiency.
        efficiency: f64,
    },
    /// Splash: flow (m³/s) over the pitch-line speed (m/s) of `gear`.
    Splash {
        /// Gear index.
        gear: usize,
        /// Flow over pitch-line speed.
        flow: Curve,
    },
}

/// A checked source.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowSource {
    /// Name.
    pub name: String,
    /// What delivers the oil.
    pub kind: SourceKind,
    /// Pressure ahead of the orifices, Pa (`None`: the pump's line pressure).
    pub pressure: Option<f64>,
}

/// How a consumer's flow is set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Split {
    /// Fixed fraction of the source's flow.
    Share(f64),
    /// Orifice with C_d·A (m²).
    Orifice(f64),
}

/// What a consumer feeds (indices into the gearbox's lists).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// A mesh.
    Mesh(usize),
    /// A jet at a mesh: speed (m/s, `None`: from the pressure) and angle (rad) to the teeth's
    /// pitch-line velocity.
    Jet {
        /// Mesh index.
        mesh: usize,
        /// Jet speed.
        speed: Option<f64>,
        /// Angle.
        angle: f64,
    },
    /// A planetary set fed through its shaft; radius where the oil leaves the carrier (m).
    Set {
        /// Set index.
        set: usize,
        /// Fling radius (`None`: planet orbit + planet tip radius).
        fling_radius: Option<f64>,
    },
    /// The clutch pack of a shift element (index into the gearbox's `clutch_packs`).
    ClutchPack(usize),
    /// A bearing (index into the gearbox's `bearings`).
    Bearing(usize),
}

/// A checked consumer.
#[derive(Debug, Clone, PartialEq)]
pub struct Consumer {
    /// Name.
    pub name: String,
    /// Source index.
    pub source: usize,
    /// Share or orifice.
    pub split: Split,
    /// What it feeds.
    pub target: Target,
    /// Thermal node the oil flows through (by name), if given.
    pub node: Option<String>,
}

/// The checked circuit.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Circuit {
    /// Sources.
    pub sources: Vec<FlowSource>,
    /// Consumers.
    pub consumers: Vec<Consumer>,
}

/// The names the circuit refers to, from the sections checked before it.
pub struct CircuitNames<'a> {
    /// Gear names.
    pub gears: Vec<&'a str>,
    /// Mesh names (fixed-axis and generated).
    pub meshes: Vec<&'a str>,
    /// Planetary-set names.
    pub sets: Vec<&'a str>,
    /// Clutch packs by shift-element name.
    pub packs: Vec<&'a str>,
    /// Bearing names.
    pub bearings: Vec<&'a str>,
    /// Thermal node names.
    pub nodes: &'a BTreeSet<&'a str>,
    /// True when the model has a `[pump]`.
    pub pump: bool,
}

/// Check `[circuit]`.
pub(crate) fn validate_circuit(
    spec: &CircuitSpec,
    names: &CircuitNames<'_>,
    problems: &mut Problems,
) -> Option<Circuit> {
    let before = problems.len();
    if spec.sources.len() > MAX_SOURCES {
        problems.push(
            "circuit.sources",
            spec.sources.len(),
            format!("at most {MAX_SOURCES} sources"),
        );
    }
    check_unique(
        spec.sources.iter().map(|s| s.name.as_str()),
        "circuit.sources",
        problems,
    );
    check_unique(
        spec.consumers.iter().map(|c| c.name.as_str()),
        "circuit.consumers",
        problems,
    );
    let sources: Vec<Option<FlowSource>> = spec
        .sources
        .iter()
        .enumerate()
        .map(|(i, s)| source(s, &format!("circuit.sources[{i}]"), names, problems))
        .collect();
    let source_names: Vec<&str> = spec.sources.iter().map(|s| s.name.as_str()).collect();
    let consumers: Vec<Option<Consumer>> = spec
        .consumers
        .iter()
        .enumerate()
        .map(|(i, c)| {
            consumer(
                c,
                &format!("circuit.consumers[{i}]"),
                &source_names,
                names,
                problems,
            )
        })
        .collect();
    check_splits(spec, &consumers, problems);
    if problems.len() > before {
        return None;
    }
    Some(Circuit {
        sources: sources.into_iter().collect::<Option<Vec<_>>>()?,
        consumers: consumers.into_iter().collect::<Option<Vec<_>>>()?,
    })
}

/// Every name in `it` once.
fn check_unique<'a>(it: impl Iterator<Item = &'a str>, path: &str, problems: &mut Problems) {
    let mut seen = BTreeSet::new();
    for (i, n) in it.enumerate() {
        if n.is_empty() {
            problems.push(format!("{path}[{i}].name"), q(n), "must not be empty");
        } else if !seen.insert(n) {
            problems.push(format!("{path}[{i}].name"), q(n), "used twice");
        }
    }
}

/// A flow table with the abscissa `key` (the other one absent), in SI (x scaled by `x_si`).
fn flow_curve(
    t: &Option<FlowTable>,
    key: &str,
    x_si: f64,
    path: &str,
    problems: &mut Problems,
) -> Option<Curve> {
    let Some(t) = t else {
        problems.push(
            format!("{path}.flow"),
            "",
            format!("required: {{ {key} = […], l_per_min = […] }}"),
        );
        return None;
    };
    let (x, other) = match key {
        "input_rpm" => (&t.input_rpm, t.speed_m_s.is_some()),
        _ => (&t.speed_m_s, t.input_rpm.is_some()),
    };
    if other {
        problems.push(format!("{path}.flow"), "", format!("takes {key} as its abscissa"));
    }
    let Some(x) = x else {
        problems.push(format!("{path}.flow.{key}"), "", "required");
        return None;
    };
    for (k, v) in t.l_per_min.iter().enumerate() {
        problems.in_range(&format!("{path}.flow.l_per_min[{k}]"), *v, 0.0, 500.0, " L/min");
    }
    for (k, v) in x.iter().enumerate() {
        problems.in_range(&format!("{path}.flow.{key}[{k}]"), *v, 0.0, 1e5, "");
    }
    let curve = Curve::new(
        x.iter().map(|v| v * x_si).collect(),
        t.l_per_min.iter().map(|v| v * L_PER_MIN).collect(),
    );
    match curve {
        Ok(c) => Some(c),
        Err(e) => {
            problems.push(format!("{path}.flow.{key}"), format!("{x:?}"), e.to_string());
            None
        }
    }
}

/// One source.
fn source(s: &SourceSpec, p: &str, names: &CircuitNames<'_>, problems: &mut Problems) -> Option<FlowSource> {
    let before = problems.len();
    let pressure = s.pressure_bar.and_then(|b| {
        problems
            .in_range(&format!("{p}.pressure_bar"), b, 0.01, 100.0, " bar")
            .then_some(b * 1e5)
    });
    let unused = |key: &str, set: bool, problems: &mut Problems| {
        if set {
            problems.push(
                format!("{p}.{key}"),
                "",
                format!("not used by kind {}", q(s.kind.name())),
            );
        }
    };
    let kind = match s.kind {
        SourceKindChoice::Pump => {
            if !names.pump {
                problems.push(format!("{p}.kind"), q("pump"), "the model has no [pump]");
            }
            unused("flow", s.flow.is_some(), problems);
            unused("gear", s.gear.is_some(), problems);
            unused("efficiency", s.efficiency.is_some(), problems);
            let share = s.share.unwrap_or(f64::NAN);
            if !(share > 0.0 && share <= 1.0) {
                problems.push(format!("{p}.share"), share, "required, in (0, 1]");
            }
            SourceKind::Pump { share }
        }
        SourceKindChoice::ElectricPump => {
            if names.pump && s.name == "pump" {
                // Its drive is loss item pump:<name>, the [pump]'s is pump:pump.
                problems.push(
                    format!("{p}.name"),
                    q("pump"),
                    "the [pump]'s loss item is pump:pump; name the electric pump otherwise",
                );
            }
            unused("share", s.share.is_some(), problems);
            unused("gear", s.gear.is_some(), problems);
            if s.pressure_bar.is_none() {
                problems.push(format!("{p}.pressure_bar"), "", "required for an electric pump");
            }
            let eff = s.efficiency.unwrap_or(f64::NAN);
            if !(eff > 0.05 && eff <= 1.0) {
                problems.push(format!("{p}.efficiency"), eff, "required, in (0.05, 1]");
            }
            let rpm = crate::physics::units::RAD_S_PER_RPM;
            let flow = flow_curve(&s.flow, "input_rpm", rpm, p, problems);
            SourceKind::ElectricPump {
                flow: flow.unwrap_or_else(zero_curve),
                efficiency: eff,
            }
        }
        SourceKindChoice::Splash => {
            unused("share", s.share.is_some(), problems);
            unused("efficiency", s.efficiency.is_some(), problems);
            let gear = match &s.gear {
                Some(g) => position(&names.gears, g, &format!("{p}.gear"), "gear", problems),
                None => {
                    problems.push(format!("{p}.gear"), "", "required: the dipping gear");
                    None
                }
            };
            let flow = flow_curve(&s.flow, "speed_m_s", 1.0, p, problems);
            SourceKind::Splash {
                gear: gear.unwrap_or(0),
                flow: flow.unwrap_or_else(zero_curve),
            }
        }
    };
    (problems.len() == before).then(|| FlowSource {
        name: s.name.clone(),
        kind,
        pressure,
    })
}

fn zero_curve() -> Curve {
    Curve::new(vec![0.0], vec![0.0]).expect("one finite point")
}

/// Index of `name` in `list`, or a problem naming the defined ones.
fn position(list: &[&str], name: &str, path: &str, what: &str, problems: &mut Problems) -> Option<usize> {
    let r = list.iter().position(|n| *n == name);
    if r.is_none() {
        problems.push(
            path,
            q(name),
            format!("unknown {what}; defined: {}", list_or_none(list)),
        );
    }
    r
}

fn list_or_none(l: &[&str]) -> String {
    list(l.iter().copied())
}

/// One consumer.
fn consumer(
    c: &ConsumerSpec,
    p: &str,
    sources: &[&str],
    names: &CircuitNames<'_>,
    problems: &mut Problems,
) -> Option<Consumer> {
    let before = problems.len();
    let source = match &c.source {
        Some(s) => position(sources, s, &format!("{p}.source"), "source", problems),
        None if sources.len() == 1 => Some(0),
        None => {
            problems.push(
                format!("{p}.source"),
                "",
                format!("required when the circuit has {} sources", sources.len()),
            );
            None
        }
    };
    let split = split(c, p, problems);
    let target = target(c, p, names, problems);
    if let Some(n) = &c.node {
        if !names.nodes.contains(n.as_str()) {
            problems.push(
                format!("{p}.node"),
                q(n),
                format!(
                    "unknown thermal node; nodes: {}",
                    list(names.nodes.iter().copied())
                ),
            );
        }
    }
    if problems.len() > before {
        return None;
    }
    Some(Consumer {
        name: c.name.clone(),
        source: source?,
        split: split?,
        target: target?,
        node: c.node.clone(),
    })
}

/// A share or an orifice, not both.
fn split(c: &ConsumerSpec, p: &str, problems: &mut Problems) -> Option<Split> {
    match (c.share, c.orifice_mm) {
        (Some(s), None) => {
            if c.discharge_coefficient.is_some() {
                problems.push(format!("{p}.discharge_coefficient"), "", "only with orifice_mm");
            }
            (s > 0.0 && s <= 1.0).then_some(Split::Share(s)).or_else(|| {
                problems.push(format!("{p}.share"), s, "must lie in (0, 1]");
                None
            })
        }
        (None, Some(d)) => {
            let ok = problems.in_range(&format!("{p}.orifice_mm"), d, 0.05, 50.0, " mm");
            let cd = c.discharge_coefficient;
            match cd {
                Some(cd)
                    if problems.in_range(&format!("{p}.discharge_coefficient"), cd, 0.1, 1.0, "") && ok =>
                {
                    let r = 0.5 * d * MM;
                    Some(Split::Orifice(cd * std::f64::consts::PI * r * r))
                }
                Some(_) => None,
                None => {
                    problems.push(
                        format!("{p}.discharge_coefficient"),
                        "",
                        "required with orifice_mm",
                    );
                    None
                }
            }
        }
        _ => {
            problems.push(format!("{p}.share"), "", "give either share or orifice_mm");
            None
        }
    }
}

/// What the consumer feeds, with its kind's own keys.
fn target(c: &ConsumerSpec, p: &str, names: &CircuitNames<'_>, problems: &mut Problems) -> Option<Target> {
    let tp = format!("{p}.target");
    let kind = c.kind;
    let only = |key: &str, set: bool, allowed: &[ConsumerKindChoice], problems: &mut Problems| {
        if set && !allowed.contains(&kind) {
            problems.push(
                format!("{p}.{key}"),
                "",
                format!("not used by kind {}", q(kind.name())),
            );
        }
    };
    only(
        "jet_speed_m_s",
        c.jet_speed_m_s.is_some(),
        &[ConsumerKindChoice::Jet],
        problems,
    );
    only(
        "jet_angle_deg",
        c.jet_angle_deg.is_some(),
        &[ConsumerKindChoice::Jet],
        problems,
    );
    only(
        "fling_radius_mm",
        c.fling_radius_mm.is_some(),
        &[ConsumerKindChoice::Set],
        problems,
    );
    match kind {
        ConsumerKindChoice::Mesh => {
            position(&names.meshes, &c.target, &tp, "mesh", problems).map(Target::Mesh)
        }
        ConsumerKindChoice::Jet => {
            let mesh = position(&names.meshes, &c.target, &tp, "mesh", problems);
            let speed = c.jet_speed_m_s;
            if let Some(v) = speed {
                problems.in_range(&format!("{p}.jet_speed_m_s"), v, 0.0, 300.0, " m/s");
            }
            let angle = c.jet_angle_deg.unwrap_or(90.0);
            problems.in_range(&format!("{p}.jet_angle_deg"), angle, 0.0, 180.0, " deg");
            Some(Target::Jet {
                mesh: mesh?,
                speed,
                angle: angle * DEG,
            })
        }
        ConsumerKindChoice::Set => {
            let set = position(&names.sets, &c.target, &tp, "planetary set", problems);
            let r = c.fling_radius_mm;
            if let Some(r) = r {
                problems.in_range(&format!("{p}.fling_radius_mm"), r, 1.0, 1000.0, " mm");
            }
            Some(Target::Set {
                set: set?,
                fling_radius: r.map(|r| r * MM),
            })
        }
        ConsumerKindChoice::ClutchPack => position(
            &names.packs,
            &c.target,
            &tp,
            "clutch pack (by shift element)",
            problems,
        )
        .map(Target::ClutchPack),
        ConsumerKindChoice::Bearing => {
            position(&names.bearings, &c.target, &tp, "bearing", problems).map(Target::Bearing)
        }
    }
}

/// Per source: consumers all by share or all by orifice; shares sum to at most 1; orifices need a
/// pressure (given, or the pump's line pressure); a clutch pack fed once.
fn check_splits(spec: &CircuitSpec, consumers: &[Option<Consumer>], problems: &mut Problems) {
    for (si, s) in spec.sources.iter().enumerate() {
        let mine: Vec<&Consumer> = consumers.iter().flatten().filter(|c| c.source == si).collect();
        let shares: f64 = mine
            .iter()
            .filter_map(|c| match c.split {
                Split::Share(f) => Some(f),
                Split::Orifice(_) => None,
            })
            .sum();
        let orifices = mine
            .iter()
            .filter(|c| matches!(c.split, Split::Orifice(_)))
            .count();
        let p = format!("circuit.sources[{si}]");
        if orifices > 0 && orifices < mine.len() {
            problems.push(
                p.clone(),
                q(&s.name),
                "its consumers must all take a share or all have an orifice",
            );
        }
        if shares > 1.0 + 1e-9 {
            problems.push(
                p.clone(),
                shares,
                "the shares of its consumers must sum to at most 1",
            );
        }
        if orifices > 0 && s.pressure_bar.is_none() && s.kind != SourceKindChoice::Pump {
            problems.push(
                format!("{p}.pressure_bar"),
                "",
                "required: its consumers have orifices",
            );
        }
    }
    let mut packs = BTreeSet::new();
    for (i, c) in consumers.iter().enumerate() {
        if let Some(Consumer {
            target: Target::ClutchPack(k),
            ..
        }) = c
        {
            if !packs.insert(*k) {
                problems.push(
                    format!("circuit.consumers[{i}].target"),
                    q(&spec.consumers[i].target),
                    "this clutch pack is fed by another consumer already",
                );
            }
        }
    }
}
