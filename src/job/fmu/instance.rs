//! One co-simulation instance of an exported model: FMI 2.0's state machine (instantiated →
//! initialisation → step mode → terminated; reset from anywhere), every value an importer sets
//! checked as the job layer checks the CLI's options, `doStep` through
//! [`crate::solve::cosim::Stepper`], outputs computed from the state at the current
//! communication point with the inputs in force. No FFI here: `fmu/` wraps it.
//!
//! Inputs over a communication step: the input speed, torque, vehicle speed and gear are held
//! (the scene's inputs are piecewise constant, as a drive cycle's samples); a boundary
//! temperature follows a line from its value with the first derivative the importer set
//! (`fmi2SetRealInputDerivatives`, order 1), held when none was set. Derivatives are forgotten
//! after each step.
//!
//! Exported model parameters (`param.KEYPATH`) are tunable: set between two `doStep`s, the model
//! is checked and compiled again with the new value ([`FmuModel::with_params`]) and the
//! integration restarts from the state at the current communication point, the boundary lines
//! in force carried over: the step change equals a run of two segments, the second started
//! from the first's end state with the new value. Initial temperatures and tolerances are fixed.

use crate::physics::units::{c_to_k, RAD_S_PER_RPM};
use std::sync::Arc;

use super::outputs::{self, LossOutputs, ReadTable};
use super::variables::{Causality, Role, Variable};
use super::FmuModel;
use crate::job::envelope::Envelope;
use crate::job::limits::{self, Limit};
use crate::job::run::DEFAULT_MAX_STEPS;
use crate::job::{JobError, Model};
use crate::scene::{Inputs, Scene};
use crate::solve::cosim::{Stepper, StepperStats};
use crate::solve::transient::{Method, TransientOptions};

/// Where an instance is in FMI's state machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// After instantiation or reset: parameters and start values may be set.
    Instantiated,
    /// Between enter and exit initialisation mode.
    Initialization,
    /// Stepping.
    Step,
    /// After terminate.
    Terminated,
    /// A call failed: only reset, terminate and free.
    Error,
}

/// An instance.
pub struct Instance {
    fm: Arc<FmuModel>,
    phase: Phase,
    /// Value of every variable by value reference − 1 (outputs: the last computed).
    values: Vec<f64>,
    /// First derivative of each input over the next step (boundaries only are used).
    deriv: Vec<f64>,
    /// Tolerance of `fmi2SetupExperiment`, when defined and `rtol` was not set.
    setup_tol: Option<f64>,
    rtol_set: bool,
    start_time: f64,
    run: Option<Run>,
    /// Where the inputs are in `values`.
    slots: Slots,
    /// The boundary inputs of the coming step (a buffer of [`Instance::do_step`]).
    lines: Vec<(f64, f64)>,
    /// The groups of outputs ([`outputs::ALL`]'s bits) whose values are those of the current
    /// state and inputs.
    fresh: u8,
    /// Which group of outputs each variable needs, found once (kept by a reset).
    table: Arc<ReadTable>,
}

/// Positions in `values` of the inputs read at every step, found once per instance.
#[derive(Debug, Clone, Default)]
struct Slots {
    input_speed: Option<usize>,
    input_torque: Option<usize>,
    vehicle_speed: Option<usize>,
    gear: Option<usize>,
    /// Every boundary input, in the order of the variables.
    boundaries: Vec<usize>,
}

impl Slots {
    fn of(vars: &[Variable]) -> Slots {
        let at = |role: Role| vars.iter().position(|v| v.role == role);
        Slots {
            input_speed: at(Role::InputSpeed),
            input_torque: at(Role::InputTorque),
            vehicle_speed: at(Role::VehicleSpeed),
            gear: at(Role::Gear),
            boundaries: (vars.iter().enumerate())
                .filter(|(_, v)| matches!(v.role, Role::Boundary(_)))
                .map(|(k, _)| k)
                .collect(),
        }
    }
}

/// A started instance: the model with its parameters, its scene, the stepper, the envelope its
/// states are checked against, and the boundary lines last applied.
struct Run {
    model: Model,
    scene: Scene,
    stepper: Stepper,
    opts: TransientOptions,
    envelope: Envelope,
    /// (value, derivative) of each boundary input as last applied to the scene.
    applied: Vec<(f64, f64)>,
    /// The scene's boundary lines start at `.0` and end at `.1`, s.
    line_span: (f64, f64),
    /// The loss items' index and the last loss evaluation for the outputs.
    losses: LossOutputs,
    /// The inputs the stepper integrates with since its last restart (the outputs may have
    /// switched its work area to inputs set after the last step).
    step_inputs: Inputs,
}

/// A boundary line is applied to the scene over this span beyond its communication point (or
/// the communication step, when longer), s: how far the stepper may step past the point while
/// the importer continues the line (`Stepper::step_ahead`).
const LINE_SPAN: f64 = 10.0;

/// A boundary input continues the line applied before when its value and its derivative over
/// the span agree with it to this, relative to the value (rounding of the importer's
/// difference quotients; far below any tolerance on temperatures).
const LINE_TOL: f64 = 1e-10;

impl Run {
    /// Whether the inputs `lines` at `now` continue the boundary lines applied, up to `t1`.
    fn lines_continue(&self, now: f64, t1: f64, lines: &[(f64, f64)]) -> bool {
        let (t0, t_end) = self.line_span;
        t1 <= t_end
            && lines.iter().zip(&self.applied).all(|(&(x, d), &(x0, d0))| {
                let tol = LINE_TOL * x.abs().max(1.0);
                (x - (x0 + d0 * (now - t0))).abs() <= tol && (d - d0).abs() * (t_end - now) <= tol
            })
    }
}

/// Every boundary from its input `lines` (value, derivative, in the order of the variables) over
/// [t, t + span] (a line with the input's derivative).
fn apply_lines(fm: &FmuModel, lines: &[(f64, f64)], scene: &mut Scene, t: f64, span: f64) {
    let boundaries = fm.vars.iter().filter_map(|v| match v.role {
        Role::Boundary(b) => Some(b),
        _ => None,
    });
    for (b, &(x, d)) in boundaries.zip(lines) {
        scene.set_boundary_ramp(b, (t, x), (t + span, x + d * span));
    }
}

/// Variable `vr` of `fm` (value references count from 1).
fn var_of(fm: &FmuModel, vr: u32) -> Result<&Variable, Message> {
    (vr as usize)
        .checked_sub(1)
        .and_then(|k| fm.vars.get(k))
        .ok_or_else(|| format!("value reference {vr} does not exist"))
}

/// A message for the importer's logger.
pub type Message = String;

fn check_limit(name: &str, limit: &Limit, v: f64) -> Result<(), Message> {
    limit.check(v).map(|_| ()).map_err(|_| {
        let why = if v.is_nan() {
            "not a number; allowed"
        } else {
            "outside"
        };
        format!("{name} = {v}: {why} {}", limit.allowed())
    })
}

/// Check that an export of `fm` can run: an instance initialises with its start values.
pub fn check_exportable(fm: &FmuModel) -> Result<(), JobError> {
    let fm = Arc::new(FmuModel::build(fm.payload.clone())?);
    let mut i = Instance::new(fm);
    i.enter_initialization().map_err(JobError::invalid)?;
    i.exit_initialization().map_err(JobError::invalid)?;
    Ok(())
}

impl Instance {
    /// A new instance with every start value.
    pub fn new(fm: Arc<FmuModel>) -> Instance {
        let table = Arc::new(ReadTable::of(&fm.vars));
        Instance::with_table(fm, table)
    }

    /// [`Instance::new`] with the read table of `fm`'s variables.
    fn with_table(fm: Arc<FmuModel>, table: Arc<ReadTable>) -> Instance {
        let values = fm.vars.iter().map(|v| v.start.unwrap_or(0.0)).collect();
        let n = fm.vars.len();
        Instance {
            phase: Phase::Instantiated,
            values,
            deriv: vec![0.0; n],
            setup_tol: None,
            rtol_set: false,
            start_time: 0.0,
            run: None,
            slots: Slots::of(&fm.vars),
            lines: Vec::new(),
            fresh: 0,
            table,
            fm,
        }
    }

    /// The phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The variables.
    pub fn variables(&self) -> &[Variable] {
        &self.fm.vars
    }

    /// Back to the start values (FMI `fmi2Reset`).
    pub fn reset(&mut self) {
        *self = Instance::with_table(self.fm.clone(), self.table.clone());
    }

    /// Enter the error phase with `m`.
    fn fail<T>(&mut self, m: Message) -> Result<T, Message> {
        self.phase = Phase::Error;
        Err(m)
    }

    /// `fmi2SetupExperiment`.
    pub fn setup_experiment(&mut self, tolerance: Option<f64>, start: f64) -> Result<(), Message> {
        if self.phase != Phase::Instantiated {
            return Err("setupExperiment is allowed only after instantiation or reset".into());
        }
        if !start.is_finite() {
            return self.fail(format!("start time {start} is not finite"));
        }
        if let Some(t) = tolerance {
            check_limit("tolerance", &limits::RTOL, t)?;
        }
        self.setup_tol = tolerance;
        self.start_time = start;
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> Result<(), Message> {
        if self.phase != Phase::Instantiated {
            return Err("enterInitializationMode is allowed only after instantiation or reset".into());
        }
        self.phase = Phase::Initialization;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: the parameters are applied to the model (checked as the
    /// model file), the scene compiled, the stepper started.
    pub fn exit_initialization(&mut self) -> Result<(), Message> {
        if self.phase != Phase::Initialization {
            return Err("exitInitializationMode is allowed only in initialization mode".into());
        }
        match self.start() {
            Ok(run) => {
                self.run = Some(run);
                self.fresh = 0;
                self.phase = Phase::Step;
                Ok(())
            }
            Err(m) => self.fail(m),
        }
    }

    fn value_of(&self, role: Role) -> f64 {
        self.fm
            .vars
            .iter()
            .position(|v| v.role == role)
            .map_or(f64::NAN, |k| self.values[k])
    }

    fn inputs(&self) -> Inputs {
        let at = |k: Option<usize>| k.map_or(f64::NAN, |k| self.values[k]);
        let s = &self.slots;
        Inputs {
            state: at(s.gear) as usize,
            input_speed: at(s.input_speed),
            input_torque: at(s.input_torque),
            vehicle_speed: at(s.vehicle_speed),
        }
    }

    /// The model with the parameters, its scene and a stepper at the initial temperatures.
    fn start(&self) -> Result<Run, Message> {
        let fm = &self.fm;
        let params: Vec<f64> = (0..fm.params.len())
            .map(|k| self.value_of(Role::Param(k)))
            .collect();
        let (model, mut scene) = if params.iter().zip(&fm.params).all(|(v, p)| *v == p.value) {
            (
                fm.model.clone(),
                fm.model.compile(&super::needs()).map_err(|e| e.to_string())?,
            )
        } else {
            fm.with_params(&params).map_err(|e| e.to_string())?
        };
        let rtol = match (self.rtol_set, self.setup_tol) {
            (false, Some(t)) => t,
            _ => self.value_of(Role::Rtol),
        };
        check_limit("rtol", &limits::RTOL, rtol)?;
        let atol = self.value_of(Role::Atol);
        check_limit("atol", &limits::ATOL, atol)?;
        let mut y0 = scene.initial_state(None);
        for (k, y) in y0.iter_mut().enumerate().take(scene.nodes()) {
            *y = self.value_of(Role::InitialTemp(k));
        }
        Envelope::of(&scene)
            .check(&y0[..scene.nodes()])
            .map_err(|b| format!("initial temperatures (T_initial.*): {b}"))?;
        apply_lines(
            &self.fm,
            &self.boundary_inputs(),
            &mut scene,
            self.start_time,
            0.0,
        );
        let opts = TransientOptions {
            method: Method::Ros3,
            rtol,
            atol,
            max_steps: DEFAULT_MAX_STEPS,
            ..TransientOptions::default()
        };
        let stepper = Stepper::new(&scene, y0, self.inputs(), opts.clone(), self.start_time)?;
        Ok(Run {
            losses: LossOutputs::of(&scene),
            step_inputs: self.inputs(),
            opts,
            envelope: Envelope::of(&scene),
            applied: self.boundary_inputs(),
            line_span: (self.start_time, self.start_time),
            model,
            scene,
            stepper,
        })
    }

    /// (value, derivative) of every boundary input.
    fn boundary_inputs(&self) -> Vec<(f64, f64)> {
        let mut lines = Vec::new();
        self.boundary_inputs_into(&mut lines);
        lines
    }

    /// [`Instance::boundary_inputs`] into `lines`.
    fn boundary_inputs_into(&self, lines: &mut Vec<(f64, f64)>) {
        lines.clear();
        let at = |&k: &usize| (self.values[k], self.deriv[k]);
        lines.extend(self.slots.boundaries.iter().map(at));
    }

    /// Check a value set for `v`.
    fn check_value(&self, v: &Variable, x: f64) -> Result<(), Message> {
        let n = &v.name;
        match v.role {
            Role::InputSpeed => check_limit(n, &rad_per_s(&limits::SPEED_RPM), x),
            Role::InputTorque => check_limit(n, &limits::TORQUE_NM, x),
            Role::VehicleSpeed => check_limit(n, &m_per_s(&limits::VEHICLE_SPEED_KMH), x),
            Role::Gear => {
                let states = self.fm.model.gearbox.gear_states.len();
                if x.fract() == 0.0 && x >= 0.0 && (x as usize) < states {
                    Ok(())
                } else {
                    Err(format!(
                        "gear = {x}: outside [0, {}] (the gear states' indices)",
                        states - 1
                    ))
                }
            }
            Role::Boundary(_) => check_limit(n, &kelvin(&limits::AMBIENT_C), x),
            Role::InitialTemp(_) => check_limit(n, &kelvin(&limits::INITIAL_TEMP_C), x),
            Role::Rtol => check_limit(n, &limits::RTOL, x),
            Role::Atol => check_limit(n, &limits::ATOL, x),
            Role::Param(_) if !x.is_finite() => Err(format!("{n} = {x}: not a finite number")),
            _ => Ok(()),
        }
    }

    /// `fmi2SetReal` / `fmi2SetInteger` of one variable. A bad value is an error (the
    /// instance then needs a reset).
    pub fn set(&mut self, vr: u32, x: f64) -> Result<(), Message> {
        let v = var_of(&self.fm, vr)?;
        let role = v.role;
        let settable = match v.causality {
            Causality::Input => self.phase != Phase::Terminated && self.phase != Phase::Error,
            Causality::Parameter => {
                matches!(self.phase, Phase::Instantiated | Phase::Initialization)
                    || (self.phase == Phase::Step && matches!(v.role, Role::Param(_)))
            }
            Causality::Output => false,
        };
        if !settable {
            return Err(format!("{} cannot be set now ({:?})", v.name, self.phase));
        }
        if let Err(m) = self.check_value(v, x) {
            return self.fail(format!("t = {} s: {m}", self.time()));
        }
        if role == Role::Rtol {
            self.rtol_set = true;
        }
        let old = std::mem::replace(&mut self.values[vr as usize - 1], x);
        // An importer sets its inputs at every point, mostly to the values in force.
        if old.to_bits() != x.to_bits() {
            self.fresh = 0;
        }
        if self.phase == Phase::Step && matches!(role, Role::Param(_)) && old != x {
            let time = self.time();
            if let Err(m) = self.retune() {
                return self.fail(format!("t = {time} s: {m}"));
            }
        }
        Ok(())
    }

    /// A tunable parameter changed in step mode: the model with the parameters' values, checked
    /// and compiled, the boundary lines in force applied to its scene, and a stepper started
    /// from the state at the current time.
    fn retune(&mut self) -> Result<(), Message> {
        let params: Vec<f64> = (0..self.fm.params.len())
            .map(|k| self.value_of(Role::Param(k)))
            .collect();
        let (model, mut scene) = self.fm.with_params(&params).map_err(|e| e.to_string())?;
        let Some(run) = self.run.as_mut() else {
            return Err("no run".into());
        };
        let (t0, t_end) = run.line_span;
        apply_lines(&self.fm, &run.applied, &mut scene, t0, t_end - t0);
        let now = run.stepper.time();
        let y = run.stepper.state().to_vec();
        let inputs = run.step_inputs;
        run.stepper = Stepper::new(&scene, y, inputs, run.opts.clone(), now)?;
        run.envelope = Envelope::of(&scene);
        run.model = model;
        run.scene = scene;
        run.losses = LossOutputs::of(&run.scene);
        Ok(())
    }

    /// `fmi2SetRealInputDerivatives` of one variable (order 1; boundaries follow it, the other
    /// inputs are held and ignore it).
    pub fn set_derivative(&mut self, vr: u32, order: i32, d: f64) -> Result<(), Message> {
        let v = var_of(&self.fm, vr)?;
        if v.causality != Causality::Input || v.integer {
            return Err(format!("{}: derivatives only of real inputs", v.name));
        }
        if order != 1 {
            return Err(format!("{}: derivative of order {order}; only order 1", v.name));
        }
        if !d.is_finite() {
            return self.fail(format!("{}: derivative {d} is not finite", v.name));
        }
        self.deriv[vr as usize - 1] = d;
        Ok(())
    }

    /// `fmi2DoStep` from `t` (the current communication point) over `h`.
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), Message> {
        if self.phase != Phase::Step {
            return Err(format!("doStep is allowed only in step mode ({:?})", self.phase));
        }
        let inputs = self.inputs();
        let mut lines = std::mem::take(&mut self.lines);
        self.boundary_inputs_into(&mut lines);
        let Some(run) = self.run.as_mut() else {
            return Err("no run".into());
        };
        let now = run.stepper.time();
        if !(h.is_finite() && h > 0.0) || (t - now).abs() > 1e-9 * now.abs().max(1.0) {
            return self.fail(format!(
                "doStep from t = {t} s over {h} s: the instance is at t = {now} s and needs h > 0"
            ));
        }
        let t1 = now + h;
        // Unchanged inputs: the stepper may go on with a step it took past `now`; else it restarts
        // from its state at `now` with the new inputs.
        if run.step_inputs != inputs || !run.lines_continue(now, t1, &lines) {
            run.stepper.restart();
            // Boundaries held at their last values need no new line (nor a fresh work area).
            let span = h.max(LINE_SPAN);
            if lines != run.applied || lines.iter().any(|b| b.1 != 0.0) {
                apply_lines(&self.fm, &lines, &mut run.scene, now, span);
                run.stepper.refresh(&run.scene);
            }
            run.applied.clone_from(&lines);
            run.line_span = (now, now + span);
            run.step_inputs = inputs;
        }
        run.stepper.set_inputs(&run.scene, inputs);
        self.lines = lines;
        let r = run.stepper.step_ahead(&run.scene, t1, run.line_span.1);
        let breach = run.envelope.check(&run.stepper.state()[..run.scene.nodes()]);
        self.deriv.iter_mut().for_each(|d| *d = 0.0);
        self.fresh = 0;
        match (r, breach) {
            (Err(e), _) => self.fail(e.to_string()),
            (Ok(()), Err(b)) => self.fail(format!(
                "t = {t1} s: {b}: the result is outside the range where the models hold"
            )),
            (Ok(()), Ok(())) => Ok(()),
        }
    }

    /// `fmi2GetReal` / `fmi2GetInteger` of one variable.
    pub fn get(&mut self, vr: u32) -> Result<f64, Message> {
        let mut x = [0.0];
        self.get_many(&[vr], &mut x)?;
        Ok(x[0])
    }

    /// `fmi2GetReal` of the variables `vrs` into `out` (as long): each group of outputs they
    /// need is computed once, when it is not that of the current state and inputs already.
    pub fn get_many(&mut self, vrs: &[u32], out: &mut [f64]) -> Result<(), Message> {
        let need = (self.table.needs(vrs)).map_err(|vr| format!("value reference {vr} does not exist"))?;
        if need & !self.fresh != 0 {
            self.compute_outputs(need & !self.fresh)?;
        }
        for (o, &vr) in out.iter_mut().zip(vrs) {
            *o = self.values[vr as usize - 1];
        }
        Ok(())
    }

    /// Evaluations of the loss model for the outputs since the run started (a loss output read
    /// evaluates it at most once per communication point and set of inputs).
    pub fn loss_evaluations(&self) -> usize {
        self.run.as_ref().map_or(0, |r| r.losses.evaluations())
    }

    /// The stepper's counters since the run started (None before initialisation).
    pub fn stepper_stats(&self) -> Option<StepperStats> {
        self.run.as_ref().map(|r| r.stepper.stats())
    }

    /// The current time (the start time before initialisation).
    pub fn time(&self) -> f64 {
        self.run.as_ref().map_or(self.start_time, |r| r.stepper.time())
    }

    /// The outputs of the groups `groups` from the state at the current time with the inputs in
    /// force.
    #[inline(never)]
    fn compute_outputs(&mut self, groups: u8) -> Result<(), Message> {
        if self.run.is_none() {
            if self.phase != Phase::Initialization {
                return Err("outputs are available from initialization mode on".into());
            }
            self.run = Some(self.start()?);
        }
        let inputs = self.inputs();
        let Some(run) = self.run.as_mut() else {
            return Err("no run".into());
        };
        let at = outputs::Point {
            gearbox: &run.model.gearbox,
            scene: &run.scene,
            stepper: &mut run.stepper,
            losses: &mut run.losses,
            inputs,
        };
        if let Some(k) = outputs::compute(&self.table, groups, at, &mut self.values) {
            let t = run.stepper.time();
            self.phase = Phase::Error;
            let name = &self.fm.vars[k].name;
            return Err(format!("t = {t} s: output {name} is not finite"));
        }
        self.fresh |= groups;
        Ok(())
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) {
        self.phase = Phase::Terminated;
    }
}

/// A limit in rpm as one in rad/s.
fn rad_per_s(l: &Limit) -> Limit {
    let k = RAD_S_PER_RPM;
    Limit {
        lo: l.lo * k,
        hi: l.hi * k,
        unit: "rad/s",
        ..*l
    }
}

/// A limit in km/h as one in m/s.
fn m_per_s(l: &Limit) -> Limit {
    Limit {
        lo: l.lo / 3.6,
        hi: l.hi / 3.6,
        unit: "m/s",
        ..*l
    }
}

/// A limit in °C as one in K.
fn kelvin(l: &Limit) -> Limit {
    Limit {
        lo: c_to_k(l.lo),
        hi: c_to_k(l.hi),
        unit: "K",
        ..*l
    }
}
