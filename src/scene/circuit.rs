//! The lubrication circuit of a compiled scene: each consumer's flow at every state, and the loss
//! items that follow from it (an electric pump's drive, the impulse of a jet, the oil flung through
//! a planet carrier).
//!
//! Compiled once: per source and gear state, the splash gear's pitch-line speed per unit input;
//! per consumer its share or orifice. Per cycle sample ([`CircuitScene::sample`]): what each
//! source delivers and the pressure ahead of its orifices (the pump's flow and line pressure follow
//! the engine speed and input torque). Per right-hand-side call: the flows at the oil density
//! ([`CircuitScene::flow`]). No allocation after compile.

use crate::model::gearbox::{GearMount, Gearbox, SourceKind, Split, Target};
use crate::model::sections::circuit::MAX_SOURCES;
use crate::physics::losses::{fling::fling_power, jet};
use crate::physics::lubrication::{delivered_pressure, orifice_coefficient, orifice_flow};
use crate::physics::oil::OilProperties;

use super::automatic::AutoSample;
use super::items::{DefaultHeat, LossItem, Source};

/// Per-sample values of the sources, in fixed arrays (at most [`MAX_SOURCES`] sources).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CircuitSample {
    /// Flow each source delivers, m³/s.
    supply: [f64; MAX_SOURCES],
    /// Pressure ahead of its orifices, Pa.
    pressure: [f64; MAX_SOURCES],
    /// Σ C_d A √(2p) of its orifices.
    k_sum: [f64; MAX_SOURCES],
}

#[derive(Debug, Clone)]
struct SourceEntry {
    kind: SourceKind,
    pressure: Option<f64>,
    /// Splash: the gear's pitch-line speed per unit input speed, per gear state (m/s per rad/s).
    splash_speed: Vec<f64>,
}

/// A loss item that follows a consumer's flow.
#[derive(Debug, Clone, Copy)]
enum FlowLoss {
    /// Jet impulse: pitch-line speed per unit input speed per state is `pitch[state]`.
    Jet {
        item: usize,
        consumer: usize,
        speed: Option<f64>,
        angle: f64,
    },
    /// Carrier fling: carrier speed per unit input is `carrier[state]`, radius `radius`.
    Fling {
        item: usize,
        consumer: usize,
        radius: f64,
    },
}

/// The compiled circuit.
#[derive(Debug, Clone, Default)]
pub struct CircuitScene {
    sources: Vec<SourceEntry>,
    /// Per consumer: (source, share or orifice C_d·A).
    consumers: Vec<(usize, Split)>,
    losses: Vec<FlowLoss>,
    /// Per flow loss: its speed per unit input speed per gear state (pitch-line m/s or carrier
    /// rad/s per rad/s).
    speed: Vec<Vec<f64>>,
    /// Electric pumps' drive items: (item, source).
    drives: Vec<(usize, usize)>,
}

impl CircuitScene {
    /// Compile the circuit of `gb`; its loss items (jets, flings, electric-pump drives) are
    /// appended to `items`.
    pub fn compile(gb: &Gearbox, items: &mut Vec<LossItem>) -> CircuitScene {
        let c = &gb.circuit;
        let n = gb.gear_states.len();
        let sources = c
            .sources
            .iter()
            .map(|s| SourceEntry {
                kind: s.kind.clone(),
                pressure: s.pressure,
                splash_speed: match s.kind {
                    SourceKind::Splash { gear, .. } => (0..n)
                        .map(|si| gb.gear_speeds(si)[gear].absolute.abs() * gb.gears[gear].geometry.d / 2.0)
                        .collect(),
                    _ => Vec::new(),
                },
            })
            .collect();
        let mut scene = CircuitScene {
            sources,
            consumers: c.consumers.iter().map(|x| (x.source, x.split)).collect(),
            ..Default::default()
        };
        for (k, s) in c.sources.iter().enumerate() {
            if matches!(s.kind, SourceKind::ElectricPump { .. }) {
                scene.drives.push((items.len(), k));
                items.push(item(Source::Pump, &s.name, true));
            }
        }
        for (ci, x) in c.consumers.iter().enumerate() {
            match x.target {
                Target::Jet { mesh, speed, angle } => {
                    let m = &gb.meshes[mesh];
                    let r = m.geometry.r_w1;
                    scene.speed.push(
                        (0..n)
                            .map(|si| gb.gear_speeds(si)[m.gear1].relative.abs() * r)
                            .collect(),
                    );
                    scene.losses.push(FlowLoss::Jet {
                        item: items.len(),
                        consumer: ci,
                        speed,
                        angle,
                    });
                    items.push(item(Source::Jet, &x.name, false));
                }
                Target::Set { set, fling_radius } => {
                    let s = &gb.planetary_sets[set];
                    let carrier = s.carrier;
                    scene.speed.push(
                        (0..n)
                            .map(|si| gb.gear_states[si].solution.speeds[carrier].abs())
                            .collect(),
                    );
                    scene.losses.push(FlowLoss::Fling {
                        item: items.len(),
                        consumer: ci,
                        radius: fling_radius.unwrap_or_else(|| default_fling_radius(gb, set)),
                    });
                    items.push(item(Source::Fling, &x.name, false));
                }
                _ => {}
            }
        }
        scene
    }

    /// Number of consumers.
    pub fn consumers(&self) -> usize {
        self.consumers.len()
    }

    /// True when the model has no circuit.
    pub fn is_empty(&self) -> bool {
        self.sources.is_empty()
    }

    /// The sources' values at gear state `state`, input speed `input_speed` (rad/s) and the
    /// sample's pump values `auto` (pump flow and line pressure). No allocation.
    pub fn sample(&self, state: usize, input_speed: f64, auto: &AutoSample) -> CircuitSample {
        let mut s = CircuitSample::default();
        for (k, src) in self.sources.iter().enumerate() {
            let (supply, line) = match &src.kind {
                SourceKind::Pump { share } => (share * auto.pump_flow, auto.line_pressure),
                SourceKind::ElectricPump { flow, .. } => (flow.at(input_speed.abs()), 0.0),
                SourceKind::Splash { flow, .. } => {
                    (flow.at(src.splash_speed[state] * input_speed.abs()), 0.0)
                }
            };
            s.supply[k] = supply;
            s.pressure[k] = src.pressure.unwrap_or(line);
        }
        for (src, split) in &self.consumers {
            if let Split::Orifice(a) = split {
                s.k_sum[*src] += orifice_coefficient(*a, s.pressure[*src]);
            }
        }
        s
    }

    /// Volume flow (m³/s) of consumer `c` in sample `s` at oil density `rho`, and d ln Q/d ln ρ.
    pub fn flow(&self, c: usize, s: &CircuitSample, rho: f64) -> (f64, f64) {
        let (src, split) = self.consumers[c];
        match split {
            Split::Share(f) => (f * s.supply[src], 0.0),
            Split::Orifice(a) => {
                let k = orifice_coefficient(a, s.pressure[src]);
                orifice_flow(k, s.k_sum[src], s.supply[src], rho)
            }
        }
    }

    /// Pressure (Pa) ahead of source `src`'s orifices in sample `s` at oil density `rho`: the
    /// nominal pressure, or, when the source delivers less than its orifices ask for, the lower
    /// pressure its flow implies ([`delivered_pressure`]).
    pub fn line_pressure(&self, src: usize, s: &CircuitSample, rho: f64) -> f64 {
        delivered_pressure(s.pressure[src], s.k_sum[src], s.supply[src], rho)
    }

    /// Mass flow (kg/s) of every consumer into `mdot`, and its temperature derivative (kg/s/K)
    /// into `dmdot` from the oil's d ln ρ/dT `dln_rho`. No allocation.
    pub fn mass_flows(&self, s: &CircuitSample, rho: f64, dln_rho: f64, mdot: &mut [f64], dmdot: &mut [f64]) {
        for (c, (m, d)) in mdot.iter_mut().zip(dmdot.iter_mut()).enumerate() {
            let (q, e) = self.flow(c, s, rho);
            *m = rho * q;
            *d = *m * (1.0 + e) * dln_rho;
        }
    }

    /// The circuit's loss items (W) into `out` at gear state `state`, input speed `w_in` (rad/s)
    /// and oil `oil`, in sample `s`. No allocation.
    pub fn evaluate(&self, state: usize, w_in: f64, oil: &OilProperties, s: &CircuitSample, out: &mut [f64]) {
        for &(item, k) in &self.drives {
            if let SourceKind::ElectricPump { efficiency, .. } = self.sources[k].kind {
                out[item] = s.supply[k] * self.line_pressure(k, s, oil.rho) / efficiency;
            }
        }
        for (l, v) in self.losses.iter().zip(&self.speed) {
            let speed = v[state] * w_in.abs();
            match *l {
                FlowLoss::Jet {
                    item,
                    consumer,
                    speed: vj,
                    angle,
                } => {
                    let q = self.flow(consumer, s, oil.rho).0;
                    let p = self.line_pressure(self.consumers[consumer].0, s, oil.rho);
                    let vj = vj.unwrap_or_else(|| jet::jet_speed(p, oil.rho));
                    out[item] = jet::impulse_power(oil.rho * q, speed, vj, angle);
                }
                FlowLoss::Fling {
                    item,
                    consumer,
                    radius,
                } => {
                    let q = self.flow(consumer, s, oil.rho).0;
                    out[item] = fling_power(oil.rho * q, speed, radius);
                }
            }
        }
    }
}

/// A circuit loss item: heat to the oil; `outside` when the input shaft does not drive it.
fn item(source: Source, name: &str, outside: bool) -> LossItem {
    LossItem {
        source,
        name: name.into(),
        gears: Vec::new(),
        heat: DefaultHeat::Oil,
        engine_side: outside,
    }
}

/// Radius at which oil leaves the carrier of set `set`: the largest planet orbit plus that
/// planet's tip radius.
fn default_fling_radius(gb: &Gearbox, set: usize) -> f64 {
    let s = &gb.planetary_sets[set];
    let axis = s
        .gears
        .iter()
        .find(|&&g| gb.gears[g].mount == GearMount::OnMember)
        .map_or(0.0, |&g| gb.gears[g].centre_height);
    s.gears
        .iter()
        .filter(|&&g| gb.gears[g].mount != GearMount::OnMember)
        .map(|&g| (axis - gb.gears[g].centre_height) + gb.gears[g].geometry.d_a / 2.0)
        .fold(0.0, f64::max)
}
