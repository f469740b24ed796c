//! The outputs of an instance at its communication point, read through `fmi2GetReal`: a table
//! built once per instance says which group of outputs each value reference needs; a read of
//! many variables computes each group it needs at most once per communication point (and not
//! at all when none of its variables is read), then copies the values.
//!
//! Groups: the node temperatures (the stepper's state at the point: it interpolates once per
//! `doStep`), the loss energies per source (sums over the loss items' energy states, by a
//! source → items index built with the run), the output speed and torque (from the inputs),
//! the oil viscosity (at the state's oil temperature), and the loss powers with the efficiency
//! and the input torque with losses. The last needs the loss model evaluated at the state of
//! the point: [`LossOutputs`] evaluates it through the stepper's work area, whose per-sample
//! loss terms (what depends on the held gear, speed and torque only) the integration prepared
//! for the same inputs, so only what depends on the oil temperature is computed per point; the
//! items' losses depend on the state only through the oil temperature, and an evaluation is
//! reused while the inputs and that temperature are unchanged (bit for bit). Losses are never
//! interpolated: they are those at the interpolated state.

use super::variables::{Role, Variable};
use crate::model::Gearbox;
use crate::physics::efficiency::efficiency;
use crate::scene::{Inputs, Scene, N_SOURCES};
use crate::solve::cosim::Stepper;

/// The node temperatures.
pub const TEMPS: u8 = 1;
/// The loss energies per source and total.
pub const ENERGIES: u8 = 2;
/// The output speed and torque.
pub const KINEMATICS: u8 = 4;
/// The oil viscosity.
pub const OIL: u8 = 8;
/// The loss powers per source and total, the efficiency, the input torque with losses.
pub const LOSSES: u8 = 16;
/// Every group.
pub const ALL: u8 = TEMPS | ENERGIES | KINEMATICS | OIL | LOSSES;

/// Where each output variable's value comes from, found once per instance.
#[derive(Debug, Clone, Default)]
pub struct ReadTable {
    /// Per variable (value reference − 1): the group a read of it needs (0: an input or a
    /// parameter, read as set).
    need: Vec<u8>,
    /// (position, node) of each node temperature output.
    temps: Vec<(usize, usize)>,
    /// (position, source index; [`N_SOURCES`] for the total) of each loss energy output.
    energies: Vec<(usize, usize)>,
    /// (position, role) of the output speed and torque.
    kinematics: Vec<(usize, Role)>,
    /// Position of the oil viscosity output.
    oil: Vec<usize>,
    /// (position, role) of each loss power, efficiency and input torque with losses output.
    losses: Vec<(usize, Role)>,
}

/// The group of an output of role `role` (0: not an output).
fn group_of(role: Role) -> u8 {
    match role {
        Role::NodeTemp(_) => TEMPS,
        Role::SourceEnergy(_) | Role::TotalEnergy => ENERGIES,
        Role::OutputSpeed | Role::OutputTorque => KINEMATICS,
        Role::OilViscosity => OIL,
        Role::SourceLoss(_) | Role::TotalLoss | Role::Efficiency | Role::InputTorqueWithLosses => LOSSES,
        _ => 0,
    }
}

impl ReadTable {
    /// The table of `vars`.
    pub fn of(vars: &[Variable]) -> ReadTable {
        let mut t = ReadTable {
            need: vars.iter().map(|v| group_of(v.role)).collect(),
            ..ReadTable::default()
        };
        for (k, v) in vars.iter().enumerate() {
            match v.role {
                Role::NodeTemp(i) => t.temps.push((k, i)),
                Role::SourceEnergy(s) => t.energies.push((k, s.index())),
                Role::TotalEnergy => t.energies.push((k, N_SOURCES)),
                Role::OutputSpeed | Role::OutputTorque => t.kinematics.push((k, v.role)),
                Role::OilViscosity => t.oil.push(k),
                r if group_of(r) == LOSSES => t.losses.push((k, r)),
                _ => {}
            }
        }
        t
    }

    /// The groups a read of the value references `vrs` needs; the first that does not exist as
    /// the error.
    pub fn needs(&self, vrs: &[u32]) -> Result<u8, u32> {
        let mut need = 0;
        for &vr in vrs {
            match (vr as usize).checked_sub(1).and_then(|k| self.need.get(k)) {
                Some(g) => need |= g,
                None => return Err(vr),
            }
        }
        Ok(need)
    }
}

/// The loss items' index and the last loss evaluation of a run (its scene): per source the
/// items, the items paid through the input shaft, and the sums of the last
/// evaluation with the inputs and oil temperature it was made at.
pub struct LossOutputs {
    /// The loss items grouped by source, each source's in item order (the order
    /// `sum_by_source` and `Scene::loss_energy_by_source` add them): source s has
    /// `by_source[starts[s]..starts[s + 1]]`.
    by_source: Vec<usize>,
    starts: [usize; N_SOURCES + 1],
    /// The items paid through the input shaft (not `LossItem::engine_side`), in item order.
    shaft_items: Vec<usize>,
    /// Loss per item of the last evaluation, W.
    q: Vec<f64>,
    /// The inputs (gear, speed, torque and vehicle speed bits) and oil temperature (bits) of
    /// the last evaluation.
    at: Option<([u64; 4], u64)>,
    /// Of the last evaluation: loss per source, total, supplied through the input shaft, W.
    by: [f64; N_SOURCES],
    total: f64,
    shaft: f64,
    /// Evaluations of the loss model so far.
    evaluations: usize,
}

fn key(inputs: &Inputs) -> [u64; 4] {
    [
        inputs.state as u64,
        inputs.input_speed.to_bits(),
        inputs.input_torque.to_bits(),
        inputs.vehicle_speed.to_bits(),
    ]
}

impl LossOutputs {
    /// The index of `scene`'s loss items, nothing evaluated.
    pub fn of(scene: &Scene) -> LossOutputs {
        let items = &scene.losses().items;
        let mut by_source = Vec::with_capacity(items.len());
        let mut starts = [0; N_SOURCES + 1];
        for s in 0..N_SOURCES {
            by_source.extend((0..items.len()).filter(|&k| items[k].source.index() == s));
            starts[s + 1] = by_source.len();
        }
        LossOutputs {
            by_source,
            starts,
            shaft_items: (0..items.len()).filter(|&k| !items[k].engine_side).collect(),
            q: vec![0.0; items.len()],
            at: None,
            by: [0.0; N_SOURCES],
            total: 0.0,
            shaft: 0.0,
            evaluations: 0,
        }
    }

    /// Evaluations of the loss model so far.
    pub fn evaluations(&self) -> usize {
        self.evaluations
    }

    /// The sum over each source's items of `x` (per item), in item order.
    fn per_source(&self, x: &[f64]) -> [f64; N_SOURCES] {
        let mut by = [0.0; N_SOURCES];
        for (s, b) in by.iter_mut().enumerate() {
            let items = &self.by_source[self.starts[s]..self.starts[s + 1]];
            *b = items.iter().fold(0.0, |sum, &k| sum + x[k]);
        }
        by
    }

    /// Loss energy per source at state `y` of `scene`, J: the sums of
    /// `Scene::loss_energy_by_source` in the same order.
    fn energies(&self, scene: &Scene, y: &[f64]) -> [f64; N_SOURCES] {
        let n = scene.nodes();
        let mut energy = [0.0; N_SOURCES];
        if scene.has_item_energies() {
            energy = self.per_source(&y[n..]);
        } else {
            energy.copy_from_slice(&y[n..n + N_SOURCES]);
        }
        energy
    }

    /// The losses at the stepper's state with `inputs`: evaluated unless the last evaluation
    /// was at the same inputs and oil temperature.
    fn update(&mut self, stepper: &mut Stepper, scene: &Scene, inputs: Inputs) {
        let at = Some((key(&inputs), scene.oil_temp(stepper.state()).to_bits()));
        if self.at == at {
            return;
        }
        stepper.set_inputs(scene, inputs);
        stepper.losses_into(scene, &mut self.q);
        self.evaluations += 1;
        // Per source and total as `sum_by_source` and `geartherm run` sum them (item order),
        // and the losses supplied through the input shaft: not the converter's slip or an
        // engine-driven pump, paid ahead of it (as `timeseries.csv`'s input torque).
        self.by = self.per_source(&self.q);
        self.total = self.q.iter().sum();
        self.shaft = self.shaft_items.iter().map(|&k| self.q[k]).sum();
        self.at = at;
    }
}

/// What the outputs at a communication point are computed from: the run's model, scene,
/// stepper and loss index, and the inputs in force.
#[allow(missing_docs)]
pub struct Point<'a> {
    pub gearbox: &'a Gearbox,
    pub scene: &'a Scene,
    pub stepper: &'a mut Stepper,
    pub losses: &'a mut LossOutputs,
    pub inputs: Inputs,
}

/// The outputs of the groups `groups` into `values`; the position of the first that is not
/// finite, if any.
pub fn compute(t: &ReadTable, groups: u8, src: Point<'_>, values: &mut [f64]) -> Option<usize> {
    let Point {
        gearbox,
        scene,
        stepper,
        losses,
        inputs,
    } = src;
    let mut put = |k: usize, x: f64| {
        values[k] = x;
        x.is_finite()
    };
    let y = stepper.state();
    if groups & TEMPS != 0 {
        if let Some(&(k, _)) = t.temps.iter().find(|&&(k, i)| !put(k, y[i])) {
            return Some(k);
        }
    }
    if groups & ENERGIES != 0 {
        let e = losses.energies(scene, y);
        let value = |s: usize| if s < N_SOURCES { e[s] } else { e.iter().sum() };
        if let Some(&(k, _)) = t.energies.iter().find(|&&(k, s)| !put(k, value(s))) {
            return Some(k);
        }
    }
    if groups & KINEMATICS != 0 {
        let ratio = gearbox.gear_states[inputs.state].ratio();
        let value = |r: Role| match r {
            Role::OutputSpeed => inputs.input_speed / ratio,
            _ => inputs.input_torque * ratio,
        };
        if let Some(&(k, _)) = t.kinematics.iter().find(|&&(k, r)| !put(k, value(r))) {
            return Some(k);
        }
    }
    if groups & OIL != 0 {
        let nu = gearbox.oil.nu(scene.oil_temp(y));
        if let Some(&k) = t.oil.iter().find(|&&k| !put(k, nu)) {
            return Some(k);
        }
    }
    if groups & LOSSES != 0 {
        losses.update(stepper, scene, inputs);
        let l = &*losses;
        let (w, torque) = (inputs.input_speed, inputs.input_torque);
        let value = |r: Role| match r {
            Role::SourceLoss(s) => l.by[s.index()],
            Role::TotalLoss => l.total,
            Role::Efficiency => efficiency(torque * w, l.total).unwrap_or(0.0),
            _ => torque + if w > 0.0 { l.shaft / w } else { 0.0 },
        };
        if let Some(&(k, _)) = t.losses.iter().find(|&&(k, r)| !put(k, value(r))) {
            return Some(k);
        }
    }
    None
}
