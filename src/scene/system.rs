//! The whole compiled scene: loss items feeding the thermal network, as one ODE right-hand side
//! `dy/dt = f(t, y)` with its Jacobian–vector product.
//!
//! State layout: `y = [T_1 … T_n (K) | E_1 … E_e (J, loss energy of each item, or of each source
//! when per-item energies are not asked for) | E_b (J, heat into boundaries)]`. The energies are quadratures (their columns of the Jacobian are zero), so
//! `Σ C_i ΔT_i + E_b − Σ E_k = 0` is a linear invariant the integrators preserve to round-off:
//! the energy balance checks the assembly, not the integration error.
//!
//! Losses depend on the temperatures only through the oil node (ν, ρ of the oil). The Jacobian is
//! analytic for the network and a one-sided finite difference in T_oil for the losses (and any
//! rotating-part-in-oil link), evaluated once per Jacobian (cached on T_oil and the sample).

use crate::model::gearbox::Gearbox;
use crate::physics::oil::OilProperties;

use super::losses::{
    LossScene, Needs, OperatingPoint, PerSource, SampleTerms, SceneError, Skipped, N_SOURCES,
};
use super::thermal::{End, NetworkWork, Operating, ThermalScene};

/// Inputs that hold during one cycle interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inputs {
    /// Gear-state index.
    pub state: usize,
    /// Gearbox input speed, rad/s.
    pub input_speed: f64,
    /// Loss-free input torque, N·m.
    pub input_torque: f64,
    /// Vehicle speed, m/s.
    pub vehicle_speed: f64,
}

/// What went wrong inside the right-hand side (reported when the solver gives up).
#[derive(Debug, Clone, PartialEq)]
pub struct RhsFailure {
    /// Time, s.
    pub time: f64,
    /// Node concerned.
    pub node: String,
    /// Loss item concerned, if any.
    pub item: Option<String>,
    /// What happened.
    pub what: String,
}

/// Step of the forward differences in T_oil, K.
fn oil_step(t_oil: f64) -> f64 {
    1e-4 * (1.0 + t_oil.abs() / 300.0)
}

/// The compiled scene.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Loss items (read through [`Scene::losses`]).
    pub(in crate::scene) losses: LossScene,
    /// Thermal network (read through [`Scene::thermal`]).
    pub(in crate::scene) thermal: ThermalScene,
    /// What the compile step left out and why ([`Scene::skipped`]).
    skipped: Vec<Skipped>,
    /// Oil temperature used for the oil properties instead of the oil node's (K); `None` for the
    /// normal coupled model. Used to measure the viscosity feedback. Set by the compile
    /// ([`Needs::frozen_oil_temp_k`]).
    frozen_oil_temp: Option<f64>,
    /// Energy quadrature (offset after the nodes) each loss item adds to.
    energy_slot: Vec<usize>,
    /// Number of energy quadratures (items, or 3 sources).
    energies: usize,
    /// True when each item has its own energy quadrature (slot k = item k).
    item_energies: bool,
    /// Clamp of the oil temperature used for the oil properties (K), if any: lets a runaway be
    /// followed past the oil's valid range without the property laws breaking down (used by the
    /// steady-state fallback to prove that no equilibrium exists in range).
    oil_temp_clamp: Option<(f64, f64)>,
}

/// Mutable work area of one solve: current inputs, sample values and buffers. No allocation after
/// creation.
#[derive(Debug, Clone)]
pub struct Work {
    /// Current inputs.
    pub inputs: Inputs,
    /// Network per-sample values.
    pub net: NetworkWork,
    /// Loss of each item at the last evaluation, W.
    pub q: Vec<f64>,
    /// Loss terms of the current sample (torque- and speed-dependent), computed at
    /// [`Scene::set_inputs`].
    pub terms: SampleTerms,
    heat: Vec<f64>,
    q2: Vec<f64>,
    q_base: Vec<f64>,
    heat2: Vec<f64>,
    /// Conductances of the rotating-in-oil links at the last heat balance (part of what `base`
    /// holds), W/K, and scratch for them at other points.
    oil_g: Vec<f64>,
    oil_g2: Vec<f64>,
    /// Their temperature derivatives, W/K² (as `oil_g` and `oil_g2`).
    oil_dg: Vec<f64>,
    oil_dg2: Vec<f64>,
    /// Mass flow of every circuit consumer (kg/s) and its temperature derivative (kg/s/K), scratch
    /// for the advection links' conductances.
    mdot: Vec<f64>,
    dmdot: Vec<f64>,
    /// ∂f/∂T_oil for the whole state (column of the Jacobian), cached.
    oil_col: Vec<f64>,
    col_key: Option<(u64, u64)>,
    sample_id: u64,
    /// The point (t, y, sample) whose heat balance `heat`, `q` and `base_to_b` hold, when they
    /// do (the finite-difference oil column starts from it instead of evaluating it again).
    base: Option<(u64, u64)>,
    base_y: Vec<f64>,
    /// The controllers' integrals at that point.
    base_integ: Vec<f64>,
    base_to_b: f64,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
    /// Jacobian column evaluations (finite differences in T_oil).
    pub jac_evals: usize,
    /// Last failure seen inside the right-hand side.
    pub failure: Option<RhsFailure>,
}

impl Work {
    /// True when `heat`, `q` and `base_to_b` hold the heat balance of the last right-hand side
    /// and it was evaluated at time `t`, node temperatures `temps` and the current sample.
    fn holds_rhs_at(&self, t: f64, temps: &[f64]) -> bool {
        self.base == Some((t.to_bits(), self.sample_id))
            && self.base_y == temps
            && self.base_integ == self.net.integ
    }
}

impl Scene {
    /// Compile the scene of a gearbox with a thermal network, for every gear state.
    pub fn compile(gb: &Gearbox) -> Result<Scene, SceneError> {
        Self::compile_for(gb, &Needs::default())
    }

    /// This scene with the oil temperature seen by the oil properties held within `bounds` (K):
    /// the steady solver's transient fallback.
    pub fn with_oil_temp_clamp(mut self, bounds: (f64, f64)) -> Scene {
        self.oil_temp_clamp = Some(bounds);
        self
    }

    /// This scene starting from the state `initial` (K per node).
    pub fn with_initial(mut self, initial: Vec<f64>) -> Scene {
        self.thermal.initial = initial;
        self
    }

    /// This scene with PI valve `k`'s share held at its integral (gain 0, no integration): the
    /// steady state's search for the share at which the sensor sits at the set point
    /// (`solve::equilibrium`). Other controllers unchanged.
    pub fn with_pi_share_held(&self, k: usize) -> Scene {
        let mut s = self.clone();
        if let Some(c) = s.thermal.controls.get_mut(k) {
            if let super::controls::Law::Pi {
                gain, rate, inv_tt, ..
            } = &mut c.law
            {
                *gain = 0.0;
                *rate = 0.0;
                *inv_tt = 0.0;
            }
        }
        s
    }

    /// The loss items (read only: the compile builds them for the scenario).
    pub fn losses(&self) -> &LossScene {
        &self.losses
    }

    /// The per-sample loss terms of every sample of `inputs` (a cycle's segments) for this
    /// scene's compiled bearings, pump and converter and sliding power laws
    /// ([`super::SampleCache`]), to share with
    /// other scenes solved on the same cycle.
    pub fn sample_cache(&self, inputs: impl IntoIterator<Item = Inputs>) -> super::SampleCache {
        let at = |i: Inputs| (i.state, i.input_speed, i.input_torque, i.vehicle_speed);
        self.losses.sample_cache(inputs.into_iter().map(at))
    }

    /// Read per-sample loss terms from `cache` where this scene's compiled parts equal those it
    /// was built from (the results are bitwise those computed here); returns which parts are
    /// read.
    pub fn use_sample_cache(
        &mut self,
        cache: std::sync::Arc<super::SampleCache>,
    ) -> super::sample_cache::CacheParts {
        self.losses.use_sample_cache(cache)
    }

    /// The thermal network (read only: the compile builds it for the scenario). Outside the
    /// compile step the parts cannot be replaced or written:
    ///
    /// ```compile_fail
    /// fn patch(s: &mut geartherm::scene::system::Scene) {
    ///     s.thermal = s.thermal().clone();
    /// }
    /// ```
    ///
    /// ```compile_fail
    /// fn patch(s: &mut geartherm::scene::system::Scene) {
    ///     s.losses.items.clear();
    /// }
    /// ```
    pub fn thermal(&self) -> &ThermalScene {
        &self.thermal
    }

    /// Make boundary `index` go linearly from `temp0` at `t0` to `temp1` at `t1` (K): a
    /// co-simulation's boundary input over one communication step (the FMU's inputs, the one
    /// change a compiled scene takes; [`ThermalScene::set_boundary_ramp`]).
    pub(crate) fn set_boundary_ramp(&mut self, index: usize, from: (f64, f64), to: (f64, f64)) {
        self.thermal.set_boundary_ramp(index, from, to);
    }

    /// The temperature the oil properties are frozen at (K), when the scenario freezes them.
    pub fn frozen_oil_temp(&self) -> Option<f64> {
        self.frozen_oil_temp
    }

    /// What the compile step left out and why (read only: the list is the compile's).
    pub fn skipped(&self) -> &[Skipped] {
        &self.skipped
    }

    /// Compile only what `needs` asks for (scene pruning): see [`LossScene::compile_for`].
    pub fn compile_for(gb: &Gearbox, needs: &Needs) -> Result<Scene, SceneError> {
        let net = gb.thermal.as_ref().ok_or_else(|| SceneError {
            what: "thermal network".into(),
            why: "the model has no [thermal] section; a transient or steady run needs one".into(),
        })?;
        let losses = LossScene::compile_for(gb, needs)?;
        let mut thermal = ThermalScene::compile(gb, net, &losses.items);
        if let Some(t) = needs.ambient_k {
            let idx = thermal.ambient.ok_or_else(|| SceneError {
                what: "ambient temperature".into(),
                why: "the model has no ambient boundary (name one `ambient` or set ambient = true)".into(),
            })?;
            thermal.set_boundary_fixed(idx, t)?;
        }
        let mut skipped = losses.skipped.clone();
        let (energy_slot, energies) = if needs.energy_per_source_only {
            skipped.push(Skipped {
                what: "energy of each loss item".into(),
                why: "not requested: loss energy is integrated per source".into(),
            });
            (
                losses.items.iter().map(|it| it.source.index()).collect(),
                N_SOURCES,
            )
        } else {
            ((0..losses.len()).collect(), losses.len())
        };
        let n = thermal.len();
        thermal.set_pi_row0(n + energies + 1 + thermal.control_rows());
        Ok(Scene {
            losses,
            thermal,
            skipped,
            energy_slot,
            energies,
            item_energies: !needs.energy_per_source_only,
            frozen_oil_temp: needs.frozen_oil_temp_k,
            oil_temp_clamp: None,
        })
    }

    /// Number of capacity nodes.
    pub fn nodes(&self) -> usize {
        self.thermal.len()
    }

    /// Number of loss items.
    pub fn items(&self) -> usize {
        self.losses.len()
    }

    /// Number of loss-energy quadratures in the state.
    pub fn energies(&self) -> usize {
        self.energies
    }

    /// True when the state holds the loss energy of every item.
    pub fn has_item_energies(&self) -> bool {
        self.item_energies
    }

    /// Length of the state vector.
    pub fn n_states(&self) -> usize {
        self.nodes() + self.energies + 1 + self.thermal.control_rows() + self.thermal.pi_rows()
    }

    /// Index of the first controller row in the state (each controller has
    /// [`ROWS_PER_CONTROL`](super::controls::ROWS_PER_CONTROL): the heat it moved, J, and its
    /// time on, s).
    pub fn control_row_index(&self) -> usize {
        self.boundary_energy_index() + 1
    }

    /// Number of controllers' switching functions.
    pub fn switching_count(&self) -> usize {
        (self.thermal.controls.len() + self.thermal.kinks.len()) * super::controls::EVENTS_PER_CONTROL
    }

    /// The controllers' switching functions at state `y` in the work area's modes into `g`,
    /// minimum on and off times aside (a steady state, or a scene without them).
    pub fn switching_functions(&self, y: &[f64], work: &Work, g: &mut [f64]) {
        self.switching_functions_at(f64::INFINITY, y, work, g);
    }

    /// The controllers' switching functions at time `t` (s) and state `y` into `g`: a
    /// controller within its minimum on or off time has the time event of its end.
    pub fn switching_functions_at(&self, t: f64, y: &[f64], work: &Work, g: &mut [f64]) {
        self.thermal.switching_functions(t, y, &work.net, g);
    }

    /// True when switching function `idx` at time `t` (s) is the end of a controller's minimum
    /// on or off time (a time event) rather than its switching surface.
    pub fn is_dwell_event(&self, t: f64, idx: usize, work: &Work) -> bool {
        let k = idx / super::controls::EVENTS_PER_CONTROL;
        let Some(c) = self.thermal.controls.get(k) else {
            return false;
        };
        let last = work.net.last_switch[k];
        c.dwell_end(work.net.mode[k], last)
            .is_some_and(|end| t <= end + 1e-9 * end.abs().max(1.0))
    }

    /// Set controller `k` to `mode` (counting a switch when it changes) and refresh what depends
    /// on it (the conductances of the links it switches).
    pub fn set_control_mode(&self, k: usize, mode: u8, work: &mut Work) {
        if work.net.mode[k] == mode {
            return;
        }
        work.net.mode[k] = mode;
        work.net.switches[k] += 1;
        work.sample_id = work.sample_id.wrapping_add(1);
        work.base = None;
        work.col_key = None;
        self.thermal
            .sample_conductances(&Self::operating(&work.inputs), &mut work.net);
    }

    /// Switch the controller of switching function `idx` (the function's root was found) at
    /// time `t` (s; its last switch when finite).
    pub fn switch_control(&self, t: f64, idx: usize, work: &mut Work) {
        let e = super::controls::EVENTS_PER_CONTROL;
        let (k, slot) = (idx / e, idx % e);
        if let Some(c) = self.thermal.controls.get(k) {
            let m = c.flip(work.net.mode[k], slot);
            self.set_control_mode(k, m, work);
            if t.is_finite() {
                work.net.last_switch[k] = t;
            }
        } else if let Some(c) = self.thermal.kinks.get(k - self.thermal.controls.len()) {
            let j = k - self.thermal.controls.len();
            work.net.kink_mode[j] = c.flip(work.net.kink_mode[j], slot);
        }
    }

    /// Settle every controller at state `y`: the modes in which no switching function is
    /// positive (the events due at this point), minimum times aside. Returns true when a mode
    /// changed.
    pub fn settle_controls(&self, y: &[f64], work: &mut Work) -> bool {
        self.settle_controls_at(f64::INFINITY, y, work)
    }

    /// [`Self::settle_controls`] at time `t` (s): a controller within its minimum on or off
    /// time keeps its mode; one that switches records `t` (when finite) as its last switch.
    pub fn settle_controls_at(&self, t: f64, y: &[f64], work: &mut Work) -> bool {
        let mut changed = false;
        for (k, c) in self.thermal.controls.iter().enumerate() {
            let s = self.thermal.signal_in(k, y);
            let m = c.settle_at(work.net.mode[k], t, work.net.last_switch[k], s);
            if m != work.net.mode[k] && t.is_finite() {
                work.net.last_switch[k] = t;
            }
            changed |= m != work.net.mode[k];
            self.set_control_mode(k, m, work);
        }
        for (j, c) in self.thermal.kinks.iter().enumerate() {
            let m = c.settle(work.net.kink_mode[j], y[c.sensor]);
            changed |= m != work.net.kink_mode[j];
            work.net.kink_mode[j] = m;
        }
        changed
    }

    /// Set every controller's mode from the initial state `y` (as a fresh work area does).
    pub fn initial_control_modes(&self, y: &[f64], work: &mut Work) {
        for (k, c) in self.thermal.controls.iter().enumerate() {
            let m = c.initial_mode(self.thermal.signal_in(k, y));
            self.set_control_mode(k, m, work);
            work.net.switches[k] = 0;
            work.net.last_switch[k] = f64::NEG_INFINITY;
        }
        for (j, c) in self.thermal.kinks.iter().enumerate() {
            work.net.kink_mode[j] = c.initial_mode(y[c.sensor]);
        }
    }

    /// Index of the boundary-heat quadrature in the state.
    pub fn boundary_energy_index(&self) -> usize {
        self.nodes() + self.energies
    }

    /// Total loss energy in state `y`, J.
    pub fn loss_energy(&self, y: &[f64]) -> f64 {
        let n = self.nodes();
        y[n..n + self.energies].iter().sum()
    }

    /// Loss energy per source (indexed by [`Source::index`](super::Source::index)) in state `y`, J.
    pub fn loss_energy_by_source(&self, y: &[f64]) -> PerSource {
        let n = self.nodes();
        let mut by = [0.0; N_SOURCES];
        if self.has_item_energies() {
            for (it, e) in self.losses.items.iter().zip(&y[n..n + self.energies]) {
                by[it.source.index()] += e;
            }
        } else {
            by.copy_from_slice(&y[n..n + N_SOURCES]);
        }
        by
    }

    /// Loss energy of item `k` in state `y` (J), when the state holds per-item energies.
    pub fn item_energy(&self, y: &[f64], k: usize) -> Option<f64> {
        self.has_item_energies().then(|| y[self.nodes() + k])
    }

    /// Initial state: node temperatures (K), zero energies. `initial_temp` overrides every node.
    pub fn initial_state(&self, initial_temp: Option<f64>) -> Vec<f64> {
        let mut y = vec![0.0; self.n_states()];
        for (x, t) in y.iter_mut().zip(&self.thermal.initial) {
            *x = initial_temp.unwrap_or(*t);
        }
        for (k, c) in self.thermal.controls.iter().enumerate() {
            if let Some(r) = self.thermal.integral_row(k) {
                y[r] = c.initial_integral();
            }
        }
        y
    }

    /// A fresh work area with the given inputs.
    pub fn work(&self, inputs: Inputs) -> Work {
        let n = self.nodes();
        let m = self.items();
        let mut w = Work {
            inputs,
            net: self.thermal.work(),
            q: vec![0.0; m],
            terms: self.losses.sample_terms(),
            heat: vec![0.0; n],
            q2: vec![0.0; m],
            q_base: vec![0.0; m],
            heat2: vec![0.0; n],
            oil_g: vec![0.0; self.thermal.oil_link_count()],
            oil_g2: vec![0.0; self.thermal.oil_link_count()],
            oil_dg: vec![0.0; self.thermal.oil_link_count()],
            oil_dg2: vec![0.0; self.thermal.oil_link_count()],
            mdot: vec![0.0; self.losses.circuit.consumers()],
            dmdot: vec![0.0; self.losses.circuit.consumers()],
            oil_col: vec![0.0; self.n_states()],
            col_key: None,
            sample_id: 0,
            base: None,
            base_y: vec![0.0; n],
            base_integ: vec![0.0; self.thermal.controls.len()],
            base_to_b: 0.0,
            rhs_evals: 0,
            jac_evals: 0,
            failure: None,
        };
        self.set_inputs(inputs, &mut w);
        w
    }

    fn operating(inputs: &Inputs) -> Operating {
        Operating {
            state: inputs.state,
            input_speed: inputs.input_speed,
            vehicle_speed: inputs.vehicle_speed,
        }
    }

    /// Switch to new inputs (a new cycle interval): per-sample conductances and loss terms are
    /// recomputed here.
    pub fn set_inputs(&self, inputs: Inputs, work: &mut Work) {
        work.inputs = inputs;
        work.sample_id = work.sample_id.wrapping_add(1);
        self.thermal
            .sample_conductances(&Self::operating(&inputs), &mut work.net);
        self.losses.prepare_at(
            inputs.state,
            inputs.input_speed,
            inputs.input_torque,
            inputs.vehicle_speed,
            &mut work.terms,
        );
    }

    /// Oil temperature (K) that sets the oil properties.
    pub fn oil_temp(&self, y: &[f64]) -> f64 {
        let t = self.frozen_oil_temp.unwrap_or(y[self.thermal.oil]);
        match self.oil_temp_clamp {
            Some((lo, hi)) => t.clamp(lo, hi),
            None => t,
        }
    }

    /// Evaluate every loss item (W) at state `y` into `work.q` (also used for output).
    pub fn evaluate_losses(&self, y: &[f64], work: &mut Work) {
        work.base = None;
        let oil = self.thermal.oil_properties(self.oil_temp(y));
        let op = self.op(&work.inputs, oil);
        self.losses.evaluate_cached(&op, &work.terms, &mut work.q);
    }

    fn op(&self, inputs: &Inputs, oil: OilProperties) -> OperatingPoint {
        OperatingPoint {
            state: inputs.state,
            input_speed: inputs.input_speed,
            input_torque: inputs.input_torque,
            oil,
        }
    }

    /// Terms that depend on T_oil (losses to nodes, rotating-part-in-oil links) at oil
    /// temperature `t_oil`, plus the rest of the network: net heat per node into `heat`, loss per
    /// item into `q`; returns the heat into boundaries.
    #[allow(clippy::too_many_arguments)]
    fn heat_balance(
        &self,
        y: &[f64],
        t_oil: f64,
        inputs: &Inputs,
        terms: &SampleTerms,
        net: &NetworkWork,
        q: &mut [f64],
        oil_g: (&mut [f64], &mut [f64]),
        flows: (&mut [f64], &mut [f64]),
        heat: &mut [f64],
    ) -> f64 {
        let n = self.nodes();
        let (oil, slopes) = self.thermal.oil_properties_and_slopes(t_oil);
        let op = self.op(inputs, oil);
        self.losses.evaluate_cached(&op, terms, q);
        let (g, dg) = oil_g;
        let (m, dm) = flows;
        self.losses.consumer_flows(&op, terms, slopes.rho, m, dm);
        self.thermal
            .oil_link_conductances(&oil, &slopes, &Self::operating(inputs), m, dm, g, dg);
        let to_b = self.thermal.network_heat(&y[..n], g, net, heat);
        for (qk, dest) in q.iter().zip(&self.thermal.heat) {
            for &(node, f) in dest {
                heat[node] += f * qk;
            }
        }
        to_b
    }

    /// Right-hand side `dy = f(t, y)`. Allocation-free. A non-finite value is recorded in
    /// `work.failure` (time, node, item) and propagates as NaN so the solver rejects the step.
    pub fn rhs(&self, t: f64, y: &[f64], work: &mut Work, dy: &mut [f64]) {
        work.rhs_evals += 1;
        let n = self.nodes();
        self.thermal.boundary_temperatures(t, &mut work.net);
        self.thermal.load_integrals(y, &mut work.net);
        let t_oil = self.oil_temp(y);
        let to_b = self.heat_balance_in(y, t_oil, work, false);
        for ((d, h), c) in dy.iter_mut().zip(&work.heat).zip(&self.thermal.capacity) {
            *d = h / c;
        }
        work.base = Some((t.to_bits(), work.sample_id));
        work.base_y.copy_from_slice(&y[..n]);
        work.base_integ.copy_from_slice(&work.net.integ);
        work.base_to_b = to_b;
        let e = self.energies;
        dy[n..n + e].iter_mut().for_each(|x| *x = 0.0);
        for (q, &slot) in work.q.iter().zip(&self.energy_slot) {
            dy[n + slot] += q;
        }
        dy[n + e] = to_b;
        self.thermal
            .control_rates(&y[..n], &work.net, &mut dy[n + e + 1..]);
        if !dy.iter().all(|v| v.is_finite()) {
            work.failure = Some(self.diagnose(t, y, &work.q));
        }
    }

    /// Name what is non-finite: a loss item, else a node.
    fn diagnose(&self, t: f64, y: &[f64], q: &[f64]) -> RhsFailure {
        let n = self.nodes();
        let oil_name = self.thermal.names[self.thermal.oil].clone();
        if let Some(k) = q.iter().position(|v| !v.is_finite()) {
            let it = &self.losses.items[k];
            return RhsFailure {
                time: t,
                node: oil_name,
                item: Some(format!("{}:{}", it.source.as_str(), it.name)),
                what: format!(
                    "loss is {} at oil temperature {:.3} °C",
                    q[k],
                    crate::physics::units::k_to_c(self.oil_temp(y))
                ),
            };
        }
        let i = y[..n]
            .iter()
            .position(|v| !v.is_finite())
            .unwrap_or(self.thermal.oil);
        RhsFailure {
            time: t,
            node: self.thermal.names[i].clone(),
            item: None,
            what: format!("temperature is {}", y[i]),
        }
    }

    /// Jacobian–vector product `out = J(t, y)·v`. Allocation-free.
    pub fn jvp(&self, t: f64, y: &[f64], v: &[f64], work: &mut Work, out: &mut [f64]) {
        let n = self.nodes();
        work.base = None;
        self.thermal.boundary_temperatures(t, &mut work.net);
        self.thermal.load_integrals(y, &mut work.net);
        let oil_i = self.thermal.oil;
        let t_oil = self.oil_temp(y);
        let (oil, slopes) = self.thermal.oil_properties_and_slopes(t_oil);
        self.oil_link_state(oil, &slopes, work, false);
        let to_b = self
            .thermal
            .network_heat_jvp(&y[..n], &work.oil_g, &work.net, v, &mut work.heat);
        for ((o, h), c) in out.iter_mut().zip(&work.heat).zip(&self.thermal.capacity) {
            *o = h / c;
        }
        let e = self.energies;
        out[n..n + e].iter_mut().for_each(|x| *x = 0.0);
        out[n + e] = to_b;
        self.thermal
            .control_rate_derivative(&y[..n], &work.net, Some(v), None, &mut out[n + e + 1..]);
        if self.frozen_oil_temp.is_some() || v[oil_i] == 0.0 {
            return;
        }
        self.update_oil_column(t, y, t_oil, work);
        let s = v[oil_i];
        for (o, c) in out.iter_mut().zip(&work.oil_col) {
            *o += c * s;
        }
    }

    /// [`Self::heat_balance`] at oil temperature `t_oil` into the work area's scratch buffers
    /// (`q2`, `oil_g2`, `oil_dg2`, `heat2`), leaving the last right-hand side's intact.
    fn scratch_heat_balance(&self, y: &[f64], t_oil: f64, work: &mut Work) -> f64 {
        self.heat_balance_in(y, t_oil, work, true)
    }

    /// [`Self::heat_balance`] with the work area's inputs and terms, into the right-hand side's
    /// buffers (`q`, `oil_g`, `oil_dg`, `heat`) or, with `scratch`, into `q2`, `oil_g2`,
    /// `oil_dg2`, `heat2`.
    fn heat_balance_in(&self, y: &[f64], t_oil: f64, work: &mut Work, scratch: bool) -> f64 {
        let w = work;
        let (q, g, dg, heat) = if scratch {
            (&mut w.q2, &mut w.oil_g2, &mut w.oil_dg2, &mut w.heat2)
        } else {
            (&mut w.q, &mut w.oil_g, &mut w.oil_dg, &mut w.heat)
        };
        let flows = (&mut w.mdot[..], &mut w.dmdot[..]);
        self.heat_balance(y, t_oil, &w.inputs, &w.terms, &w.net, q, (g, dg), flows, heat)
    }

    /// ∂f/∂T_oil through the oil properties (all rows of the state), by a forward difference,
    /// cached per (T_oil, sample) in `work.oil_col`.
    fn update_oil_column(&self, t: f64, y: &[f64], t_oil: f64, work: &mut Work) {
        let n = self.nodes();
        let e = self.energies;
        let key = (t_oil.to_bits(), work.sample_id);
        if work.col_key == Some(key) {
            return;
        }
        work.jac_evals += 1;
        let h = oil_step(t_oil);
        let b0 = if work.holds_rhs_at(t, &y[..n]) {
            // The last right-hand side was evaluated here: start from its heat balance.
            work.oil_col[..n].copy_from_slice(&work.heat);
            work.q_base.copy_from_slice(&work.q);
            work.base_to_b
        } else {
            let b = self.scratch_heat_balance(y, t_oil, work);
            work.oil_col[..n].copy_from_slice(&work.heat2);
            work.q_base.copy_from_slice(&work.q2);
            b
        };
        // Only the oil properties move (t_oil + h); the node temperatures stay those of y, whose
        // effect is the analytic part.
        let b1 = self.scratch_heat_balance(y, t_oil + h, work);
        for i in 0..n {
            work.oil_col[i] = (work.heat2[i] - work.oil_col[i]) / h / self.thermal.capacity[i];
        }
        work.oil_col[n..n + e].iter_mut().for_each(|x| *x = 0.0);
        for ((q1, q0), &slot) in work.q2.iter().zip(&work.q_base).zip(&self.energy_slot) {
            work.oil_col[n + slot] += (q1 - q0) / h;
        }
        work.oil_col[n + e] = (b1 - b0) / h;
        work.oil_col[n + e + 1..].iter_mut().for_each(|x| *x = 0.0);
        work.col_key = Some(key);
    }

    /// State row of a network end: its node, or the boundary-heat quadrature.
    fn row_of(&self, e: End) -> usize {
        match e {
            End::Node(i) => i,
            End::Boundary(_) => self.boundary_energy_index(),
        }
    }

    /// The (row, column) of every Jacobian entry [`Self::jacobian_values`] writes, in its order
    /// (entries may repeat: they add up). The network's analytic terms, then the whole oil column
    /// (the losses and the oil-dependent links through ν(T_oil)). Built once per solve; its length
    /// is O(links + states), so a sparse solver can use it as the pattern.
    pub fn jacobian_pattern(&self) -> Vec<(usize, usize)> {
        let n = self.nodes();
        let work = self.work(Inputs {
            state: 0,
            input_speed: 0.0,
            input_torque: 0.0,
            vehicle_speed: 0.0,
        });
        let y = self.initial_state(None);
        let mut out = Vec::new();
        self.thermal
            .network_heat_partials(&y[..n], &work.oil_g, &work.net, &mut |r, c, _| {
                out.push((self.row_of(r), c))
            });
        let r0 = self.control_row_index();
        self.thermal
            .control_rate_partials(&y[..n], &work.net, &mut |r, c, _| out.push((r0 + r, c)));
        out.extend((0..self.n_states()).map(|r| (r, self.thermal.oil)));
        out
    }

    /// Set the boundary temperatures to time `t` and make the oil links' conductances at (t, y)
    /// available: true when `work.oil_g` holds them (the last right-hand side was evaluated at
    /// this point), false when they were computed into `work.oil_g2`.
    fn oil_conductances_at(&self, t: f64, y: &[f64], work: &mut Work) -> bool {
        self.thermal.boundary_temperatures(t, &mut work.net);
        self.thermal.load_integrals(y, &mut work.net);
        if work.holds_rhs_at(t, &y[..self.nodes()]) {
            return true;
        }
        let (oil, slopes) = self.thermal.oil_properties_and_slopes(self.oil_temp(y));
        self.oil_link_state(oil, &slopes, work, true);
        false
    }

    /// The oil-state-dependent links' conductances and derivatives at oil state `oil` with the
    /// work area's inputs, into `oil_g`/`oil_dg` or, with `scratch`, `oil_g2`/`oil_dg2` (the
    /// circuit's flows into `mdot`/`dmdot` on the way).
    fn oil_link_state(
        &self,
        oil: OilProperties,
        slopes: &crate::physics::oil::OilLogSlopes,
        work: &mut Work,
        scratch: bool,
    ) {
        let op = self.op(&work.inputs, oil);
        self.losses
            .consumer_flows(&op, &work.terms, slopes.rho, &mut work.mdot, &mut work.dmdot);
        let (g, dg) = if scratch {
            (&mut work.oil_g2, &mut work.oil_dg2)
        } else {
            (&mut work.oil_g, &mut work.oil_dg)
        };
        self.thermal.oil_link_conductances(
            &oil,
            slopes,
            &Self::operating(&work.inputs),
            &work.mdot,
            &work.dmdot,
            g,
            dg,
        );
    }

    /// Values of the Jacobian entries of [`Self::jacobian_pattern`], in its order, at (t, y):
    /// ∂(dy_row)/∂y_col. Allocation-free; `vals` has the pattern's length.
    pub fn jacobian_values(&self, t: f64, y: &[f64], work: &mut Work, vals: &mut [f64]) {
        let (k, _) = self.network_partial_values(t, y, work, vals);
        let col = &mut vals[k..];
        if self.frozen_oil_temp.is_some() {
            col.iter_mut().for_each(|x| *x = 0.0);
        } else {
            self.update_oil_column(t, y, self.oil_temp(y), work);
            col.copy_from_slice(&work.oil_col);
        }
    }

    /// The network's analytic partials (the head of [`Self::jacobian_pattern`]) into `vals`;
    /// returns how many were written.
    /// The oil links' conductances at (t, y) are those of the last right-hand side when it was
    /// evaluated there (ROS3's Jacobian follows its first stage), else computed into scratch.
    /// Also returns whether the oil links' conductances (and their derivatives) are those of
    /// the last RHS (`oil_g`, `oil_dg`) or were computed into the scratch (`oil_g2`, `oil_dg2`).
    fn network_partial_values(&self, t: f64, y: &[f64], work: &mut Work, vals: &mut [f64]) -> (usize, bool) {
        let n = self.nodes();
        let held = self.oil_conductances_at(t, y, work);
        let oil_g = if held { &work.oil_g } else { &work.oil_g2 };
        let mut k = self
            .thermal
            .network_partial_values(&y[..n], oil_g, &work.net, vals);
        self.thermal
            .control_rate_partials(&y[..n], &work.net, &mut |_, _, d| {
                vals[k] = d;
                k += 1;
            });
        (k, held)
    }

    /// As [`Self::jacobian_values`], with the losses' share of the oil column from given slopes
    /// `dq_dt[k]` = ∂q_k/∂T_oil (W/K) instead of a forward difference of every loss; the links
    /// whose conductance follows ν(T_oil) enter with their analytic derivative (no loss is
    /// evaluated).
    pub fn jacobian_values_with_slopes(
        &self,
        t: f64,
        y: &[f64],
        work: &mut Work,
        dq_dt: &[f64],
        vals: &mut [f64],
    ) {
        let (k, held) = self.network_partial_values(t, y, work, vals);
        let col = &mut vals[k..];
        col.iter_mut().for_each(|x| *x = 0.0);
        if self.moving_oil_temp(y).is_none() {
            return;
        }
        let n = self.nodes();
        let dg = if held { &work.oil_dg } else { &work.oil_dg2 };
        let to_b = self
            .thermal
            .oil_property_derivative(&y[..n], dg, &work.net, &mut col[..n]);
        for (d, dest) in dq_dt.iter().zip(&self.thermal.heat) {
            for &(node, f) in dest {
                col[node] += f * d;
            }
        }
        for (c, inv_cap) in col.iter_mut().zip(&self.thermal.inv_capacity) {
            *c *= inv_cap;
        }
        for (d, &slot) in dq_dt.iter().zip(&self.energy_slot) {
            col[n + slot] += d;
        }
        col[n + self.energies] = to_b;
    }

    /// The oil temperature that sets the properties, when it follows the state (not frozen, not
    /// held at a clamp bound).
    fn moving_oil_temp(&self, y: &[f64]) -> Option<f64> {
        if self.frozen_oil_temp.is_some() {
            return None;
        }
        let t = y[self.thermal.oil];
        match self.oil_temp_clamp {
            Some((lo, hi)) if t <= lo || t >= hi => None,
            _ => Some(t),
        }
    }

    /// ∂q_k/∂T_oil of every loss item (W/K) at state `y` with the current inputs, by a forward
    /// difference (one loss evaluation, or two when the last right-hand side was not at `y`).
    pub fn loss_slopes(&self, t: f64, y: &[f64], work: &mut Work, out: &mut [f64]) {
        let Some(t_oil) = self.moving_oil_temp(y) else {
            out.iter_mut().for_each(|x| *x = 0.0);
            return;
        };
        let n = self.nodes();
        let h = oil_step(t_oil);
        if work.holds_rhs_at(t, &y[..n]) {
            work.q_base.copy_from_slice(&work.q);
        } else {
            let op = self.op(&work.inputs, self.thermal.oil_properties(t_oil));
            self.losses.evaluate_cached(&op, &work.terms, &mut work.q_base);
        }
        let op = self.op(&work.inputs, self.thermal.oil_properties(t_oil + h));
        self.losses.evaluate_cached(&op, &work.terms, &mut work.q2);
        work.jac_evals += 1;
        for ((o, q1), q0) in out.iter_mut().zip(&work.q2).zip(&work.q_base) {
            *o = (q1 - q0) / h;
        }
    }

    /// ∂f/∂t at (t, y) into `out`: only boundary temperatures depend on time, so this is the
    /// network's response to their rates of change, analytic (boundary series are piecewise
    /// linear: the rate of the piece the series follows just after t, the one a step from t
    /// integrates over). The loss rows are zero. Allocation-free.
    pub fn time_derivative(&self, t: f64, y: &[f64], work: &mut Work, out: &mut [f64]) {
        let n = self.nodes();
        // The oil links' conductances of the last RHS when it was evaluated here (ROS3 asks at
        // the step's start, after its first stage), else computed into scratch; the last RHS's
        // heat balance is left intact.
        let held = self.oil_conductances_at(t, y, work);
        self.thermal.boundary_slopes(t, &mut work.net);
        let oil_g = if held { &work.oil_g } else { &work.oil_g2 };
        let to_b = self
            .thermal
            .network_heat_time_rate(&y[..n], oil_g, &work.net, &mut work.heat2);
        for ((o, h), c) in out.iter_mut().zip(&work.heat2).zip(&self.thermal.capacity) {
            *o = h / c;
        }
        let e = self.energies;
        out[n..n + e].iter_mut().for_each(|x| *x = 0.0);
        out[n + e] = to_b;
        self.thermal.control_rate_derivative(
            &y[..n],
            &work.net,
            None,
            Some(&work.net.boundary_slope),
            &mut out[n + e + 1..],
        );
    }

    /// Heat flow into each node (W) and into boundaries at state `y` with the current inputs (for
    /// the steady-state residual). `heat` has length [`Self::nodes`].
    pub fn net_heat(&self, t: f64, y: &[f64], work: &mut Work, heat: &mut [f64]) -> f64 {
        work.base = None;
        self.thermal.boundary_temperatures(t, &mut work.net);
        self.thermal.load_integrals(y, &mut work.net);
        let t_oil = self.oil_temp(y);
        let to_b = self.heat_balance_in(y, t_oil, work, false);
        heat.copy_from_slice(&work.heat);
        to_b
    }
}
