//! The automatic transmission's own loss items in a compiled scene: the drag of every open
//! shift element's clutch pack, the oil pump and the torque converter.
//!
//! Compiled once per scene: per gear state, each pack's slip speed per unit input speed (from
//! the kinematic solution: |ω_a − ω_b| for a clutch, |ω| for a brake; zero where the element is
//! engaged) and the pump's speed per unit input when a member drives it. Per cycle sample
//! ([`AutoLosses::prepare`]): the converter's engine side (speed, slip loss) and the pump power,
//! which depend on the sample's speeds and torque but not on temperature. Per right-hand-side
//! call: the pack drags at the current oil viscosity. No allocation after compile.

use crate::cycle::LaunchDevice;
use crate::model::pump::{PumpDrive, PumpModel};
use crate::model::Gearbox;
use crate::physics::losses::clutch_drag::ClutchPack;
use crate::physics::oil::OilProperties;

use super::items::{DefaultHeat, LossItem, Skipped, Source};

#[derive(Debug, Clone, PartialEq)]
struct PackEntry {
    item: usize,
    pack: ClutchPack,
    /// The `[circuit]` consumer that feeds it (its flow replaces the pack's own), if any.
    feed: Option<usize>,
    /// Per gear state: |slip| per unit input speed.
    slip: Vec<f64>,
    /// The pack's [`ClutchPack::face_factor`] (geometry only), m².
    face: f64,
}

#[derive(Debug, Clone, PartialEq)]
struct PumpEntry {
    item: usize,
    model: PumpModel,
    /// Per gear state: |pump speed| per unit input speed when a member drives it.
    speed: Vec<f64>,
}

/// Compiled automatic-transmission losses.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AutoLosses {
    packs: Vec<PackEntry>,
    pump: Option<PumpEntry>,
    converter: Option<usize>,
    launch: Option<LaunchDevice>,
    /// Per gear state: vehicle speed per unit input speed (m/s per rad/s), when the model has a
    /// vehicle: r_w/(i_final·|ratio|).
    vehicle_per_input: Option<Vec<f64>>,
}

/// Per-sample values of the temperature-independent items.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AutoSample {
    /// (state, input speed, input torque, vehicle speed) bits the values belong to.
    key: Option<(usize, u64, u64, u64)>,
    /// Pump drive power, W.
    pub pump: f64,
    /// Pump delivered flow, m³/s.
    pub pump_flow: f64,
    /// Line pressure, Pa.
    pub line_pressure: f64,
    /// Converter slip loss, W.
    pub converter: f64,
    /// Engine-side speed, rad/s.
    pub engine_speed: f64,
}

impl AutoLosses {
    /// Compile the packs, pump and converter of `gb`; items are appended to `items`, parts left
    /// out to `skipped`. `needed(state)` tells which gear states the run visits.
    pub fn compile(
        gb: &Gearbox,
        needed: &dyn Fn(usize) -> bool,
        keep_all: bool,
        items: &mut Vec<LossItem>,
        skipped: &mut Vec<Skipped>,
    ) -> AutoLosses {
        let n = gb.gear_states.len();
        let clean = |v: f64| if v.abs() < 1e-12 { 0.0 } else { v.abs() };
        let mut packs = Vec::new();
        for (k, cp) in gb.clutch_packs.iter().enumerate() {
            let el = &gb.shift_elements[cp.element];
            let slip: Vec<f64> = (0..n)
                .map(|si| {
                    let w = &gb.gear_states[si].solution.speeds;
                    let s = match el.members.as_slice() {
                        [a, b] => w[*a] - w[*b],
                        [a] => w[*a],
                        _ => 0.0,
                    };
                    clean(s)
                })
                .collect();
            if !keep_all && !(0..n).any(|si| needed(si) && slip[si] != 0.0) {
                skipped.push(Skipped {
                    what: format!("clutch drag of {}", cp.name),
                    why: "engaged or without slip in every gear state the run uses".into(),
                });
                continue;
            }
            let feed = gb
                .circuit
                .consumers
                .iter()
                .position(|c| c.target == crate::model::gearbox::Target::ClutchPack(k));
            packs.push(PackEntry {
                item: items.len(),
                pack: cp.pack,
                feed,
                slip,
                face: cp.pack.face_factor(),
            });
            items.push(LossItem {
                source: Source::ClutchDrag,
                name: cp.name.clone(),
                gears: Vec::new(),
                heat: DefaultHeat::Oil,
                engine_side: false,
            });
        }
        let pump = gb.pump.as_ref().map(|m| {
            let speed = match m.drive {
                PumpDrive::Engine => vec![1.0; n],
                PumpDrive::Member(k) => (0..n)
                    .map(|si| gb.gear_states[si].solution.speeds[k].abs())
                    .collect(),
            };
            let e = PumpEntry {
                item: items.len(),
                model: m.clone(),
                speed,
            };
            items.push(LossItem {
                source: Source::Pump,
                name: "pump".into(),
                gears: Vec::new(),
                heat: DefaultHeat::Oil,
                engine_side: gb.launch.is_some() && matches!(m.drive, PumpDrive::Engine),
            });
            e
        });
        let converter = gb.launch.as_ref().map(|_| {
            items.push(LossItem {
                source: Source::Converter,
                name: "converter".into(),
                gears: Vec::new(),
                heat: DefaultHeat::Oil,
                engine_side: true,
            });
            items.len() - 1
        });
        let vehicle_per_input = gb.vehicle.as_ref().map(|v| {
            gb.gear_states
                .iter()
                .map(|s| v.wheel_radius / (v.final_drive_ratio * s.ratio().abs()))
                .collect()
        });
        AutoLosses {
            packs,
            pump,
            converter,
            launch: gb.launch.clone(),
            vehicle_per_input,
        }
    }

    /// Values of the temperature-independent items for gear state `state`, input speed (rad/s),
    /// input torque (N·m) and vehicle speed (m/s; used only when the model has no vehicle —
    /// with one, the vehicle speed follows from the input speed and the gear, exactly the cycle
    /// interval's mean speed, and single operating points get it too). No allocation.
    pub fn sample(
        &self,
        state: usize,
        input_speed: f64,
        input_torque: f64,
        vehicle_speed: f64,
    ) -> AutoSample {
        let w = input_speed.abs();
        let v = self
            .vehicle_per_input
            .as_ref()
            .map_or(vehicle_speed, |k| k[state] * w);
        let (engine_speed, converter) = match &self.launch {
            Some(l) => {
                let e = l.engine_side(state, v, w, input_torque);
                (e.impeller_speed, e.loss)
            }
            None => (w, 0.0),
        };
        let pump = self.pump.as_ref().map(|p| {
            let speed = match p.model.drive {
                PumpDrive::Engine => engine_speed,
                PumpDrive::Member(_) => p.speed[state] * w,
            };
            p.model.pump.point(speed, input_torque)
        });
        AutoSample {
            key: Some((
                state,
                input_speed.to_bits(),
                input_torque.to_bits(),
                vehicle_speed.to_bits(),
            )),
            pump: pump.map_or(0.0, |p| p.power),
            pump_flow: pump.map_or(0.0, |p| p.flow),
            line_pressure: pump.map_or(0.0, |p| p.pressure),
            converter,
            engine_speed,
        }
    }

    /// Prepare `s` for a sample (kept if it is already the one). No allocation.
    pub fn prepare(
        &self,
        state: usize,
        input_speed: f64,
        input_torque: f64,
        vehicle_speed: f64,
        s: &mut AutoSample,
    ) {
        let key = (
            state,
            input_speed.to_bits(),
            input_torque.to_bits(),
            vehicle_speed.to_bits(),
        );
        if s.key != Some(key) {
            *s = self.sample(state, input_speed, input_torque, vehicle_speed);
        }
    }

    /// Write every item's loss (W) into `out`: pack drags at `oil` (a pack fed by the circuit with
    /// the flow `feed_flow(consumer)`, m³/s), pump and converter from the prepared sample `s` if it
    /// is for `state`, `input_speed` and `input_torque`, else computed (vehicle speed from the
    /// input speed when the model has a vehicle, else 0: lock-up open). No allocation.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &self,
        state: usize,
        input_speed: f64,
        input_torque: f64,
        oil: &OilProperties,
        s: &AutoSample,
        feed_flow: impl Fn(usize) -> f64,
        out: &mut [f64],
    ) {
        let w = input_speed.abs();
        for p in &self.packs {
            let mut pack = p.pack;
            if let Some(c) = p.feed {
                pack.oil_flow = feed_flow(c);
            }
            out[p.item] = pack.drag_with(p.slip[state] * w, oil.mu, oil.rho, p.face).power;
        }
        if self.pump.is_none() && self.converter.is_none() {
            return;
        }
        let fresh;
        let s = match s.key {
            Some((st, a, b, _))
                if st == state && a == input_speed.to_bits() && b == input_torque.to_bits() =>
            {
                s
            }
            _ => {
                fresh = self.sample(state, input_speed, input_torque, 0.0);
                &fresh
            }
        };
        if let Some(p) = &self.pump {
            out[p.item] = s.pump;
        }
        if let Some(c) = self.converter {
            out[c] = s.converter;
        }
    }
}
