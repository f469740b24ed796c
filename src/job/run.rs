//! `run`: a drive-cycle (or rig-cycle) transient. Options, checks, the compiled problem, the
//! integration and the checks of its result.

use serde::{Deserialize, Serialize};

use crate::cycle::{CycleError, DriveCycle, Schedule};
use crate::model::gearbox::Gearbox;
use crate::physics::units::c_to_k;
use crate::report::run::{check_finite, run_warnings, summary, timeseries_csv, Summary};
use crate::scene::{Needs, Scene, SpreadScene};
use crate::solve::drive::{row_inputs, segments};
use crate::solve::transient::{
    check_stored_values, integrate, Method, Restart, Segment, Trajectory, TransientOptions,
};

use super::envelope::{Envelope, OilRange};
use super::limits::{self, Limit};
use super::{JobError, Model};

pub use crate::solve::transient::{DEFAULT_ATOL, DEFAULT_METHOD, DEFAULT_RTOL};

/// Largest relative energy-balance residual a run may return (a converged integration closes
/// it to about 1e-7; a residual near 1 means the numbers are meaningless).
pub const MAX_ENERGY_RESIDUAL: f64 = 1e-2;

/// Default step budget of a run.
pub const DEFAULT_MAX_STEPS: usize = 5_000_000;

/// Options of a drive-cycle run (`geartherm run`, a study's run job, `Model.run` in Python).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RunOptions {
    /// Bundled cycle name or a CSV file (vehicle or rig cycle); with `cycle_text`, the name the
    /// cycle goes by in messages and the summary.
    pub cycle: String,
    /// The cycle's CSV text, parsed instead of reading `cycle` (a DataFrame from Python, whose
    /// messages then name `cycle`, not a temporary file); not part of a command line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_text: Option<String>,
    /// Solver name (auto, ros3, tr-bdf2, esdirk34, bdf, tsit45).
    pub solver: String,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance on temperatures, K.
    pub atol: f64,
    /// Initial temperature of every node, °C (None: the model's).
    pub initial_temp_c: Option<f64>,
    /// Ambient temperature, °C (None: the model's ambient boundary).
    pub ambient_c: Option<f64>,
    /// Oil properties frozen at this temperature, °C (None: viscosity follows the oil).
    pub frozen_viscosity_c: Option<f64>,
    /// Step budget (the run fails beyond it).
    pub max_steps: usize,
    /// Summary only: no time series, loss energy per source instead of per item (faster).
    pub summary_only: bool,
    /// No scene pruning of unused gear states and idle items, no per-sample loss cache (for
    /// measuring what they save; results agree to rounding).
    pub evaluate_all: bool,
    /// Model-form spread: the energy each applicable model choice of every source would give
    /// along the run's own trajectory, in the summary (docs/uq.md).
    pub spread: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            cycle: "wltc".into(),
            cycle_text: None,
            solver: DEFAULT_METHOD.name().into(),
            rtol: DEFAULT_RTOL,
            atol: DEFAULT_ATOL,
            initial_temp_c: None,
            ambient_c: None,
            frozen_viscosity_c: None,
            max_steps: DEFAULT_MAX_STEPS,
            summary_only: false,
            evaluate_all: false,
            spread: false,
        }
    }
}

/// A solver name, or the error listing the allowed ones.
pub fn method(name: &str) -> Result<Method, JobError> {
    Method::parse(name).ok_or_else(|| {
        let allowed = Method::ALL.map(|m| m.name()).join(", ");
        JobError::option(
            "solver",
            name,
            allowed.clone(),
            format!("solver = {name}: unknown; allowed: {allowed}"),
        )
    })
}

impl RunOptions {
    /// Every range check of the options (the model and cycle are checked when read).
    pub fn check(&self) -> Result<Method, JobError> {
        let m = method(&self.solver)?;
        limits::RTOL.check(self.rtol)?;
        limits::ATOL.check(self.atol)?;
        limits::INITIAL_TEMP_C.check_opt(self.initial_temp_c)?;
        limits::AMBIENT_C.check_opt(self.ambient_c)?;
        limits::FROZEN_VISCOSITY_C.check_opt(self.frozen_viscosity_c)?;
        limits::MAX_STEPS.check(self.max_steps as f64)?;
        Ok(m)
    }

    /// The solver options these options ask for.
    fn transient(&self, method: Method) -> TransientOptions {
        TransientOptions {
            method,
            rtol: self.rtol,
            atol: self.atol,
            restart: Restart::AtJumps,
            max_steps: self.max_steps,
            initial_temp: self.initial_temp_c.map(c_to_k),
            record_losses: !self.summary_only,
            ..TransientOptions::default()
        }
    }
}

/// A checked, compiled run, ready to integrate.
pub struct Prepared {
    /// The scene compiled for this cycle (pruned to the gear states it visits).
    pub scene: Scene,
    /// The cycle.
    pub cycle: DriveCycle,
    /// Its schedule (gear, speeds, torques per interval).
    pub sched: Schedule,
    /// Integration segments.
    pub segs: Vec<Segment>,
    /// Solver options.
    pub opts: TransientOptions,
    /// The model-form alternatives (with `spread`).
    pub spread: Option<SpreadScene>,
    /// Check the loss models' ranges at every output row into the summary's `warnings` (true
    /// from [`prepare`]; a caller that keeps no warnings, such as a study's table row, sets it
    /// false and saves those evaluations).
    pub range_warnings: bool,
}

/// Check the options, read and schedule the cycle, compile the scene for it: everything that
/// can fail as invalid input fails here, before any output directory is touched.
pub fn prepare(m: &Model, o: &RunOptions) -> Result<Prepared, JobError> {
    prepare_with(m, o, &segments)
}

/// How a cycle is scheduled on a gearbox into solver segments ([`segments`], or a cache of its
/// results that returns the same values).
pub type SegmentsFn<'a> = dyn Fn(&Gearbox, &DriveCycle) -> Result<(Schedule, Vec<Segment>), CycleError> + 'a;

/// [`prepare`] with the cycle scheduled by `segments` (a study reuses one schedule for the cases
/// whose schedule inputs are equal).
pub fn prepare_with(m: &Model, o: &RunOptions, segments: &SegmentsFn) -> Result<Prepared, JobError> {
    let method = o.check()?;
    let oil = OilRange::of(&m.gearbox.oil);
    oil.check_option_opt(&limits::INITIAL_TEMP_C, o.initial_temp_c)?;
    oil.check_option_opt(&limits::FROZEN_VISCOSITY_C, o.frozen_viscosity_c)?;
    let cycle = match &o.cycle_text {
        Some(text) => DriveCycle::parse(text, &o.cycle)?,
        None => DriveCycle::resolve(&o.cycle)?,
    };
    let (sched, segs) =
        segments(&m.gearbox, &cycle).map_err(|e| JobError::invalid(format!("{}: {e}", m.label())))?;
    // Scene pruning: only the gear states this cycle visits, only the outputs asked for.
    let needs = Needs {
        states: Some(segs.iter().map(|s| s.inputs.state).collect()),
        evaluate_all: o.evaluate_all,
        energy_per_source_only: o.summary_only,
        ambient_k: m.ambient_k(o.ambient_c)?,
        frozen_oil_temp_k: o.frozen_viscosity_c.map(c_to_k),
    };
    let scene = m.compile(&needs)?;
    let opts = o.transient(method);
    let start = scene.initial_state(opts.initial_temp);
    Envelope::of(&scene).check(&start[..scene.nodes()]).map_err(|b| {
        JobError::invalid(format!(
            "{}: the initial state is outside the range where the models hold: {b} \
                 (thermal.initial_temp_c, the node's initial_temp_c or --initial-temp-c)",
            m.label()
        ))
    })?;
    check_stored_values(&scene, &segs, &opts)
        .map_err(|e| JobError::invalid(format!("{}: {e}", m.label())))?;
    let spread = o
        .spread
        .then(|| SpreadScene::compile(&m.gearbox, &needs, scene.losses()));
    Ok(Prepared {
        scene,
        cycle,
        sched,
        segs,
        opts,
        spread,
        range_warnings: true,
    })
}

/// A finished run.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// The `summary.json` contents.
    pub summary: Summary,
    /// The `timeseries.csv` text (None with `summary_only`).
    pub timeseries_csv: Option<String>,
}

impl RunResult {
    /// The files of a run's output directory: `summary.json` and, unless summary-only,
    /// `timeseries.csv`.
    pub fn files(&self) -> Result<Vec<(&'static str, Vec<u8>)>, JobError> {
        let json = serde_json::to_vec_pretty(&self.summary)
            .map_err(|e| JobError::numerical(format!("cannot serialise the summary: {e}")))?;
        let mut files = Vec::with_capacity(2);
        if let Some(csv) = &self.timeseries_csv {
            files.push(("timeseries.csv", csv.clone().into_bytes()));
        }
        files.push(("summary.json", json));
        Ok(files)
    }
}

/// Run a drive (or rig) cycle. `progress(k, n)` is called after each of the `n` segments.
pub fn run(m: &Model, o: &RunOptions, progress: &mut dyn FnMut(usize, usize)) -> Result<RunResult, JobError> {
    solve(m, &prepare(m, o)?, progress)
}

/// Integrate a prepared run and check its result (the second half of [`run`], for a front end
/// that locks its output directory in between).
pub fn solve(m: &Model, p: &Prepared, progress: &mut dyn FnMut(usize, usize)) -> Result<RunResult, JobError> {
    solve_keeping(m, p, progress).map(|(r, _)| r)
}

/// [`solve`], also returning the integrated trajectory (for outputs derived from its states,
/// e.g. [`super::series`]).
pub fn solve_keeping(
    m: &Model,
    p: &Prepared,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(RunResult, Trajectory), JobError> {
    let traj = integrate(&p.scene, &p.segs, &p.opts, progress)
        .map_err(|e| JobError::numerical(format!("{}: {e}", m.label())))?;
    let r = finish(m, p, &traj)?;
    Ok((r, traj))
}

/// The post-solve checks and the outputs of an integrated run.
fn finish(m: &Model, p: &Prepared, traj: &Trajectory) -> Result<RunResult, JobError> {
    let rows = row_inputs(&m.gearbox, &p.sched, traj);
    let mut sum = summary(
        &p.scene,
        traj,
        &rows,
        &m.gearbox.name,
        &p.cycle.name,
        p.opts.method.name(),
        p.opts.rtol,
        p.opts.atol,
    );
    if p.range_warnings {
        sum.warnings = run_warnings(&p.scene, traj, &rows);
    }
    let numerical = |what: String| JobError::numerical(format!("{}: {what}", m.label()));
    check_finite(&p.scene, traj, &rows, &sum).map_err(numerical)?;
    if let Some(s) = &p.spread {
        sum.spread = Some(super::spread::along_run(s, &p.scene, &p.segs, traj));
    }
    Envelope::of(&p.scene)
        .check_run(&p.scene, &p.segs, traj)
        .map_err(numerical)?;
    if sum.energy_balance_relative > MAX_ENERGY_RESIDUAL {
        return Err(numerical(format!(
            "energy balance residual {:.2e} exceeds {MAX_ENERGY_RESIDUAL:e}: the integration is not trustworthy \
             (tighten --rtol or check the cycle's time steps)",
            sum.energy_balance_relative
        )));
    }
    let csv = p.opts.record_losses.then(|| {
        let work = std::cell::RefCell::new(p.scene.thermal().work());
        let bt = |t: f64| {
            let mut w = work.borrow_mut();
            p.scene.thermal().boundary_temperatures(t, &mut w);
            w.boundary_t.clone()
        };
        timeseries_csv(&p.scene, traj, &rows, &bt)
    });
    Ok(RunResult {
        summary: sum,
        timeseries_csv: csv,
    })
}

/// The limits a run's options are checked against (for tables and drift tests).
pub const LIMITS: [Limit; 6] = [
    limits::RTOL,
    limits::ATOL,
    limits::INITIAL_TEMP_C,
    limits::AMBIENT_C,
    limits::FROZEN_VISCOSITY_C,
    limits::MAX_STEPS,
];
