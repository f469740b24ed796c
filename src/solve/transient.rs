//! Transient driver: integrates a [`Scene`] over piecewise-constant input segments (drive-cycle
//! intervals) with ROS3 ([`super::rosenbrock`], the default for lumped networks through
//! [`Method::Auto`]) or a diffsol solver (TR-BDF2 above 24 nodes, BDF, ESDIRK34, Tsit45). Both
//! share `Driver`: the rows, the step budget and the failure diagnosis.
//!
//! How the diffsol pitfalls of docs/numerics.md are handled (each has a test in `tests/transient.rs`):
//! 1. `max_nonlinear_solver_failures` counts over the solver's life: raised to the step budget;
//!    runaway runs are stopped by our own step budget instead.
//! 2. `TstopReached` may leave `t` one ulp short of the stop time: the segment index is kept here,
//!    never derived from `t`; the time is reset to the exact segment start at a restart.
//! 3. Roots are not used (samples and shifts are known times: stop times).
//! 4. After a restart the step size is re-estimated (Hairer–Nørsett–Wanner II.4 starting step with
//!    the new derivative), not kept from before the jump.
//! 5. Restarts only where the inputs jump ([`Restart::AtJumps`], default); `EveryInterval` exists
//!    for the benchmark.
//! 6. After changing the inputs the state's `dy` is set to `f(t⁺, y)`.

use std::cell::RefCell;
use std::time::Instant;

use diffsol::{FaerSparseMat, NalgebraMat, OdeBuilder, OdeEquations, OdeSolverMethod, OdeSolverStopReason};

use super::dense_lu::SmallDenseLu;
use super::equations::{HostVector, SceneEquations};
use super::rosenbrock;
use super::rows::Rows;
use super::sparse_lu::NetworkSparseLu;
use crate::scene::{Inputs, Scene, Work};

/// Linear algebra of the implicit methods' Newton iterations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinearAlgebra {
    /// Dense below [`SPARSE_FROM_STATES`] states, sparse from there on.
    Auto,
    /// Dense matrices and LU (nalgebra).
    Dense,
    /// Compressed-column matrices and faer's sparse LU (fill-reducing ordering, symbolic
    /// factorisation once per solve).
    Sparse,
}

/// State count from which [`LinearAlgebra::Auto`] uses the sparse LU (the measured crossover,
/// docs/performance.md "Large networks").
pub const SPARSE_FROM_STATES: usize = 50;

impl LinearAlgebra {
    /// True when a solve of `states` states uses the sparse LU.
    pub fn is_sparse(self, states: usize) -> bool {
        match self {
            LinearAlgebra::Auto => states >= SPARSE_FROM_STATES,
            LinearAlgebra::Dense => false,
            LinearAlgebra::Sparse => true,
        }
    }
}

/// Integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Variable-order BDF (1–5), implicit multistep.
    Bdf,
    /// ESDIRK3(4), L-stable singly diagonally implicit Runge–Kutta.
    Esdirk34,
    /// TR-BDF2, L-stable one-step method of order 2.
    TrBdf2,
    /// Tsitouras 5(4), explicit (not for stiff networks).
    Tsit45,
    /// ROS3, three-stage Rosenbrock method of order 3, L-stable, two evaluations of f per step
    /// ([`super::rosenbrock::ROS3`]).
    Ros3,
    /// ROS3 for networks of up to [`ROS3_MAX_NODES`] nodes, TR-BDF2 above (the default).
    Auto,
}

/// Largest network (capacity nodes) [`Method::Auto`] integrates with ROS3. ROS3 factorises the
/// node block at every step, TR-BDF2 keeps its LU over ≈ 7 steps: measured on the AT6 with a
/// meshed housing over the WLTC (docs/numerics.md, "ROS3"), ROS3 is 1.2–1.3× faster up to 15
/// nodes, the two tie at 20–25 nodes, and TR-BDF2 wins above (1.15× at 30–35 nodes, 4× at 1005).
pub const ROS3_MAX_NODES: usize = 24;

impl Method {
    /// All methods.
    pub const ALL: [Method; 6] = [
        Method::Bdf,
        Method::Esdirk34,
        Method::TrBdf2,
        Method::Tsit45,
        Method::Ros3,
        Method::Auto,
    ];

    /// Command-line name.
    pub const fn name(self) -> &'static str {
        match self {
            Method::Bdf => "bdf",
            Method::Esdirk34 => "esdirk34",
            Method::TrBdf2 => "tr-bdf2",
            Method::Tsit45 => "tsit45",
            Method::Ros3 => "ros3",
            Method::Auto => "auto",
        }
    }

    /// Parse a command-line name.
    pub fn parse(s: &str) -> Option<Method> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s || m.name().replace('-', "_") == s)
    }

    /// True for implicit methods.
    pub fn is_implicit(self) -> bool {
        self != Method::Tsit45
    }

    /// The method used for a network of `nodes` capacity nodes ([`Method::Auto`] resolved).
    pub fn resolve(self, nodes: usize) -> Method {
        match self {
            Method::Auto if nodes <= ROS3_MAX_NODES => Method::Ros3,
            Method::Auto => Method::TrBdf2,
            m => m,
        }
    }
}

/// When the integrator is restarted at a segment boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Restart {
    /// Only where the inputs change.
    AtJumps,
    /// At every segment boundary.
    EveryInterval,
    /// Never: the error control alone handles input jumps.
    Never,
}

/// One interval with constant inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Start, s.
    pub t0: f64,
    /// End, s.
    pub t1: f64,
    /// Inputs during the interval.
    pub inputs: Inputs,
}

/// Options of a transient run.
#[derive(Debug, Clone)]
pub struct TransientOptions {
    /// Method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance on temperatures, K (energies get `atol` × the mean node capacity, J).
    pub atol: f64,
    /// Restart policy.
    pub restart: Restart,
    /// Step budget for the whole run (the run fails with a clear message beyond it).
    pub max_steps: usize,
    /// Initial temperature of every node, K (None: the model's).
    pub initial_temp: Option<f64>,
    /// Guards against the diffsol pitfalls of docs/numerics.md (all on by default; the tests
    /// switch each off to show what it prevents).
    pub guards: Guards,
    /// Evaluate and keep the loss of every item at every output time (`Trajectory::losses`, for
    /// timeseries.csv and the plots); off when those outputs are not asked for.
    pub record_losses: bool,
    /// Dense or sparse linear algebra (default: by size).
    pub linear_algebra: LinearAlgebra,
    /// Assemble the Jacobian entry by entry (default). Off: one Jacobian–vector product per
    /// column (dense only; for measuring the difference).
    pub assembled_jacobian: bool,
}

/// Pitfall guards of the driver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Guards {
    /// Pitfall 1: raise `max_nonlinear_solver_failures` (a lifetime count in diffsol).
    pub raise_failure_limit: bool,
    /// Pitfall 4: re-estimate the step size at a restart.
    pub reset_step: bool,
    /// Pitfall 6: set `dy = f(t⁺, y)` at a restart.
    pub refresh_derivative: bool,
}

impl Default for Guards {
    fn default() -> Self {
        Self {
            raise_failure_limit: true,
            reset_step: true,
            refresh_derivative: true,
        }
    }
}

/// Default method (ROS3 on lumped networks, TR-BDF2 on large ones: docs/numerics.md "ROS3").
pub const DEFAULT_METHOD: Method = Method::Auto;
/// Default relative tolerance (docs/numerics.md).
pub const DEFAULT_RTOL: f64 = 1e-4;
/// Default absolute tolerance on temperatures, K.
pub const DEFAULT_ATOL: f64 = 1e-6;

impl Default for TransientOptions {
    fn default() -> Self {
        Self {
            method: DEFAULT_METHOD,
            rtol: DEFAULT_RTOL,
            atol: DEFAULT_ATOL,
            restart: Restart::AtJumps,
            max_steps: 5_000_000,
            initial_temp: None,
            guards: Guards::default(),
            record_losses: true,
            linear_algebra: LinearAlgebra::Auto,
            assembled_jacobian: true,
        }
    }
}

/// Solver work counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps (error test failures).
    pub rejected: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
    /// Jacobian evaluations (loss derivative columns).
    pub jac_evals: usize,
    /// LU factorisations (linear solver setups).
    pub lu_factorisations: usize,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Newton convergence failures.
    pub newton_failures: usize,
    /// Restarts at input jumps.
    pub restarts: usize,
    /// Cycle samples whose loss terms were prepared (once per distinct input sample).
    pub samples_prepared: usize,
    /// True when the Newton iterations used the sparse LU.
    pub sparse: bool,
    /// The method that integrated (`auto` resolved).
    pub method: &'static str,
}

/// The result: the state at every segment boundary, and the losses there.
#[derive(Debug, Clone)]
pub struct Trajectory {
    /// Output times, s (segment boundaries).
    pub times: Vec<f64>,
    /// State at each time (temperatures K, energies J).
    pub states: Rows,
    /// Loss of each item at each time (W), with the inputs of the segment that starts there (the
    /// last row: of the last segment). Empty when `TransientOptions::record_losses` is off.
    pub losses: Rows,
    /// Segment index whose inputs each row shows.
    pub segment: Vec<usize>,
    /// Counters.
    pub stats: Stats,
    /// Wall time of the integration, s.
    pub wall_time_s: f64,
}

/// The solver could not continue.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("numerical failure at t = {time:.6} s, node {node}{}: {message}", item.as_ref().map(|i| format!(", loss item {i}")).unwrap_or_default())]
pub struct NumericalFailure {
    /// Time, s.
    pub time: f64,
    /// Node concerned (the one changing fastest relative to its tolerance, or the one that became
    /// non-finite).
    pub node: String,
    /// Loss item concerned (non-finite, or the largest at that time).
    pub item: Option<String>,
    /// What happened.
    pub message: String,
}

/// Values a run keeps in memory for its output rows: one row per segment end (and the start),
/// each holding the state and, when recorded, every loss item.
pub fn stored_values(scene: &Scene, segments: &[Segment], opts: &TransientOptions) -> usize {
    let per_row = scene.n_states()
        + if opts.record_losses {
            scene.losses.items.len()
        } else {
            0
        };
    (segments.len() + 1).saturating_mul(per_row)
}

/// At most this many stored values (8 bytes each: 400 MB) per run: a larger run (a long cycle on
/// a finely meshed housing) is refused up front with the figures, not found out by the allocator.
pub const MAX_STORED_VALUES: usize = 50_000_000;

/// Refuse a run above [`MAX_STORED_VALUES`], saying what would help.
pub fn check_stored_values(
    scene: &Scene,
    segments: &[Segment],
    opts: &TransientOptions,
) -> Result<(), String> {
    let stored = stored_values(scene, segments, opts);
    if stored <= MAX_STORED_VALUES {
        return Ok(());
    }
    let rows = segments.len() + 1;
    let states_only = rows.saturating_mul(scene.n_states());
    let help = if opts.record_losses && states_only <= MAX_STORED_VALUES {
        "run with --summary-only (no per-row losses), shorten the cycle or use fewer wall patches"
    } else {
        "shorten the cycle or use fewer wall patches"
    };
    Err(format!(
        "this run would keep {rows} rows × {} values = {stored} values in memory, more than the \
         limit of {MAX_STORED_VALUES} (400 MB): {help}",
        stored / rows
    ))
}

/// Integrate `scene` over `segments` (contiguous, increasing). `progress(k, n)` is called after
/// each segment.
pub fn integrate(
    scene: &Scene,
    segments: &[Segment],
    opts: &TransientOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Trajectory, NumericalFailure> {
    let start = Instant::now();
    let first = segments.first().ok_or_else(|| NumericalFailure {
        time: 0.0,
        node: scene.thermal.names[scene.thermal.oil].clone(),
        item: None,
        message: "empty input: no segment to integrate".into(),
    })?;
    let n = scene.nodes();
    let method = opts.method.resolve(n);
    let ns = scene.n_states();
    let y0 = scene.initial_state(opts.initial_temp);
    let mean_c = scene.thermal.capacity.iter().sum::<f64>() / n as f64;
    let mut atol = vec![opts.atol; ns];
    for a in atol.iter_mut().skip(n) {
        *a = opts.atol * mean_c;
    }
    let work = RefCell::new(scene.work(first.inputs));
    let fail_build = |e: diffsol::error::DiffsolError| NumericalFailure {
        time: first.t0,
        node: scene.thermal.names[scene.thermal.oil].clone(),
        item: None,
        message: format!("could not set up the solver: {e}"),
    };
    let ctx = Driver {
        scene,
        work: &work,
        segments,
        opts,
        atol: &atol,
    };
    let mut traj = Trajectory {
        times: Vec::with_capacity(segments.len() + 1),
        states: Rows::with_capacity(scene.n_states(), segments.len() + 1),
        losses: Rows::with_capacity(
            scene.items(),
            if opts.record_losses { segments.len() + 1 } else { 0 },
        ),
        segment: Vec::with_capacity(segments.len() + 1),
        stats: Stats::default(),
        wall_time_s: 0.0,
    };
    // One body for both matrix types (the solvers' trait bounds are easiest met by concrete types).
    macro_rules! solve_with {
        ($m:ty, $ls:ty) => {{
            let mut eqn = SceneEquations::<$m>::new(scene, &work, y0.clone());
            eqn.assembled = opts.assembled_jacobian;
            let mut problem = OdeBuilder::<$m>::new()
                .t0(first.t0)
                .rtol(opts.rtol)
                .atol(atol.clone())
                .build_from_eqn(eqn)
                .map_err(fail_build)?;
            if opts.guards.raise_failure_limit {
                // Bounded by the run's own budget (which counts these failures too), so that
                // no single step can retry beyond it (a NaN step size never gets "too small").
                problem.ode_options.max_nonlinear_solver_failures = opts.max_steps;
            }
            match method {
                Method::Bdf => {
                    let mut s = problem.bdf::<$ls>().map_err(fail_build)?;
                    ctx.run(&mut s, &mut traj, progress)?;
                }
                Method::Esdirk34 => {
                    let mut s = problem.esdirk34::<$ls>().map_err(fail_build)?;
                    ctx.run(&mut s, &mut traj, progress)?;
                }
                Method::TrBdf2 => {
                    let mut s = problem.tr_bdf2::<$ls>().map_err(fail_build)?;
                    ctx.run(&mut s, &mut traj, progress)?;
                }
                Method::Tsit45 => {
                    let mut s = problem.tsit45().map_err(fail_build)?;
                    ctx.run(&mut s, &mut traj, progress)?;
                }
                // `method` is resolved: Auto is never seen here.
                Method::Ros3 | Method::Auto => {
                    let r = rosenbrock::run::<$m, $ls>(&ctx, &problem.eqn, &y0, &mut traj, progress)?;
                    traj.stats.steps = r.steps;
                    traj.stats.rejected = r.rejected;
                    traj.stats.lu_factorisations = r.lu;
                }
            }
        }};
    }
    let sparse = method.is_implicit() && opts.linear_algebra.is_sparse(ns);
    if sparse {
        solve_with!(FaerSparseMat<f64>, NetworkSparseLu);
    } else {
        solve_with!(NalgebraMat<f64>, SmallDenseLu);
    }
    traj.stats.sparse = sparse;
    traj.stats.method = method.name();
    let w = work.borrow();
    traj.stats.rhs_evals = w.rhs_evals;
    traj.stats.jac_evals = w.jac_evals;
    traj.stats.samples_prepared = w.terms.prepared;
    traj.wall_time_s = start.elapsed().as_secs_f64();
    Ok(traj)
}

/// What the integrators share: the scene, its work area, the segments and the tolerances.
pub(crate) struct Driver<'s> {
    scene: &'s Scene,
    work: &'s RefCell<Work>,
    pub(crate) segments: &'s [Segment],
    pub(crate) opts: &'s TransientOptions,
    pub(crate) atol: &'s [f64],
}

impl Driver<'_> {
    /// `dy = f(t, y)` with the current inputs (the losses stay in the work area).
    pub(crate) fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.scene.rhs(t, y, &mut self.work.borrow_mut(), dy);
    }

    /// True when some boundary temperature moves (then f depends on t).
    pub(crate) fn boundaries_move(&self) -> bool {
        self.scene.thermal.boundaries_move()
    }

    /// True when ∂f/∂t = 0 on the step from `t` (no boundary temperature moves there).
    pub(crate) fn time_rate_vanishes(&self, t: f64) -> bool {
        self.scene.thermal.boundaries_still_at(t)
    }

    /// ∂f/∂t at (t, y).
    pub(crate) fn time_derivative(&self, t: f64, y: &[f64], out: &mut [f64]) {
        self.scene.time_derivative(t, y, &mut self.work.borrow_mut(), out);
    }

    /// The losses (W per item) of the last right-hand side, into `out`.
    pub(crate) fn losses_into(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.work.borrow().q);
    }

    /// ∂q_k/∂T_oil of every item at (t, y) by a forward difference.
    pub(crate) fn loss_slopes(&self, t: f64, y: &[f64], out: &mut [f64]) {
        self.scene.loss_slopes(t, y, &mut self.work.borrow_mut(), out);
    }

    /// Number of loss items.
    pub(crate) fn items(&self) -> usize {
        self.scene.items()
    }

    /// Oil temperature that sets the oil properties at state `y`, K.
    pub(crate) fn oil_temp(&self, y: &[f64]) -> f64 {
        self.scene.oil_temp(y)
    }

    /// Switch to the inputs of segment `k`.
    pub(crate) fn switch_inputs(&self, k: usize) {
        self.scene
            .set_inputs(self.segments[k].inputs, &mut self.work.borrow_mut());
    }

    /// Forget a non-finite trial the integrator recovered from.
    pub(crate) fn clear_failure(&self) {
        self.work.borrow_mut().failure = None;
    }

    /// Record the row at time `t` whose losses [`Self::rhs`] has just evaluated at `y`.
    pub(crate) fn record_evaluated(&self, traj: &mut Trajectory, t: f64, y: &[f64], seg: usize) {
        if self.opts.record_losses {
            traj.losses.push(&self.work.borrow().q);
        }
        traj.times.push(t);
        traj.states.push(y);
        traj.segment.push(seg);
    }

    /// The step budget is spent.
    pub(crate) fn budget_failure(&self, t: f64, y: &[f64]) -> NumericalFailure {
        self.failure(
            t,
            y,
            format!(
                "step budget of {} exceeded (the network is too stiff for {} at this tolerance, or oscillates)",
                self.opts.max_steps,
                self.opts.method.resolve(self.scene.nodes()).name()
            ),
        )
    }

    /// Record the row at time `t`: the state and the losses with the current inputs (those of
    /// segment `seg`, which the caller has already switched to).
    fn record(&self, traj: &mut Trajectory, t: f64, y: &[f64], seg: usize) {
        if self.opts.record_losses {
            let mut w = self.work.borrow_mut();
            self.scene.evaluate_losses(y, &mut w);
            traj.losses.push(&w.q);
        }
        traj.times.push(t);
        traj.states.push(y);
        traj.segment.push(seg);
    }

    /// Failure at the solver's current state: names the node with the largest weighted rate and
    /// the item (non-finite, else the largest loss).
    pub(crate) fn failure(&self, t: f64, y: &[f64], message: String) -> NumericalFailure {
        let mut w = self.work.borrow_mut();
        if let Some(f) = w.failure.take() {
            return NumericalFailure {
                time: f.time,
                node: f.node,
                item: f.item,
                message: format!("{} ({message})", f.what),
            };
        }
        let n = self.scene.nodes();
        let mut dy = vec![0.0; y.len()];
        self.scene.rhs(t, y, &mut w, &mut dy);
        let node = (0..n)
            .max_by(|&a, &b| {
                let ra = dy[a].abs() / (self.atol[a] + self.opts.rtol * y[a].abs());
                let rb = dy[b].abs() / (self.atol[b] + self.opts.rtol * y[b].abs());
                ra.total_cmp(&rb)
            })
            .unwrap_or(self.scene.thermal.oil);
        let item =
            w.q.iter()
                .enumerate()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .map(|(k, _)| {
                    let it = &self.scene.losses.items[k];
                    format!("{}:{}", it.source.as_str(), it.name)
                });
        NumericalFailure {
            time: t,
            node: self.scene.thermal.names[node].clone(),
            item,
            message,
        }
    }

    /// Starting step after a restart (Hairer, Nørsett & Wanner I, II.4), capped by the previous
    /// step and the segment length.
    pub(crate) fn restart_step(&self, y: &[f64], f: &[f64], h_prev: f64, len: f64) -> f64 {
        let (mut d0, mut d1) = (0.0, 0.0);
        for ((yi, fi), ai) in y.iter().zip(f).zip(self.atol) {
            let w = ai + self.opts.rtol * yi.abs();
            d0 += (yi / w).powi(2);
            d1 += (fi / w).powi(2);
        }
        let k = y.len() as f64;
        let (d0, d1) = ((d0 / k).sqrt(), (d1 / k).sqrt());
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        h0.min(h_prev.abs().max(1e-6)).min(len).max(1e-10)
    }

    fn run<'a, Eqn, S>(
        &self,
        solver: &mut S,
        traj: &mut Trajectory,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<(), NumericalFailure>
    where
        Eqn: OdeEquations<T = f64, V: HostVector> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let segs = self.segments;
        let total = segs.len();
        {
            let st = solver.state();
            self.record(traj, segs[0].t0, st.y.host(), 0);
        }
        let mut restarts = 0;
        for (k, seg) in segs.iter().enumerate() {
            if k > 0 {
                // The inputs were switched to this segment's when the previous row was recorded.
                let changed = seg.inputs != segs[k - 1].inputs;
                let restart = match self.opts.restart {
                    Restart::AtJumps => changed,
                    Restart::EveryInterval => true,
                    Restart::Never => false,
                };
                if restart {
                    restarts += 1;
                    let g = self.opts.guards;
                    let st = solver.state_mut();
                    *st.t = seg.t0;
                    if g.refresh_derivative {
                        self.scene
                            .rhs(seg.t0, st.y.host(), &mut self.work.borrow_mut(), st.dy.host_mut());
                    }
                    if g.reset_step {
                        let h = self.restart_step(st.y.host(), st.dy.host(), *st.h, seg.t1 - seg.t0);
                        *st.h = h;
                    }
                }
            }
            solver.set_stop_time(seg.t1).map_err(|e| {
                let st = solver.state();
                self.failure(st.t.min(seg.t1), st.y.host(), format!("stop time rejected: {e}"))
            })?;
            loop {
                // Attempts, not only accepted steps: a solver that keeps rejecting must also
                // stop at the budget.
                let st = solver.get_statistics();
                let steps = st.number_of_steps
                    + st.number_of_error_test_failures
                    + st.number_of_nonlinear_solver_fails;
                if steps > self.opts.max_steps {
                    let st = solver.state();
                    return Err(self.budget_failure(st.t, st.y.host()));
                }
                // A derivative that is not finite at the start of a step gives a NaN step size
                // (diffsol's initial-step estimate, or our restart's), and a NaN step never
                // becomes "too small": the step would retry for ever. Fail now, naming the item.
                let h = solver.state().h;
                if !(h.is_finite() && h != 0.0) {
                    let st = solver.state();
                    let (t, y) = (st.t, st.y.host().to_vec());
                    // Diagnose at the current state, not at the last (possibly NaN) trial.
                    let mut dy = vec![0.0; y.len()];
                    let mut w = self.work.borrow_mut();
                    w.failure = None;
                    self.scene.rhs(t, &y, &mut w, &mut dy);
                    drop(w);
                    let why = format!("step size {h}: the right-hand side is not finite");
                    return Err(self.failure(t, &y, why));
                }
                let stepped = solver.step();
                if stepped.is_ok() {
                    // A non-finite trial the solver recovered from is not this run's failure.
                    self.work.borrow_mut().failure = None;
                }
                match stepped {
                    Ok(OdeSolverStopReason::TstopReached) => break,
                    Ok(OdeSolverStopReason::InternalTimestep) => {}
                    Ok(OdeSolverStopReason::RootFound(..)) => {}
                    Err(e) => {
                        let st = solver.state();
                        return Err(self.failure(st.t, st.y.host(), format!("solver error: {e}")));
                    }
                }
            }
            let st = solver.state();
            let y = st.y.host();
            if let Some(i) = y.iter().position(|v| !v.is_finite()) {
                return Err(self.failure(seg.t1, y, format!("state component {i} is not finite")));
            }
            // The row at t1 shows the inputs of the segment that starts there: switch to them now
            // (once; the next segment integrates with them).
            let row_seg = if k + 1 < total { k + 1 } else { k };
            if segs[row_seg].inputs != seg.inputs {
                self.scene
                    .set_inputs(segs[row_seg].inputs, &mut self.work.borrow_mut());
            }
            self.record(traj, seg.t1, y, row_seg);
            progress(k + 1, total);
        }
        let s = solver.get_statistics();
        traj.stats.steps = s.number_of_steps;
        traj.stats.rejected = s.number_of_error_test_failures;
        traj.stats.lu_factorisations = s.number_of_linear_solver_setups;
        traj.stats.newton_iterations = s.number_of_nonlinear_solver_iterations;
        traj.stats.newton_failures = s.number_of_nonlinear_solver_fails;
        traj.stats.restarts = restarts;
        Ok(())
    }
}

/// Energy bookkeeping of a trajectory's last state.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct EnergyBalance {
    /// Loss energy, J (sum over items).
    pub lost: f64,
    /// Heat stored in the nodes, Σ C_i (T_i(end) − T_i(0)), J.
    pub stored: f64,
    /// Heat into boundaries, J.
    pub to_boundaries: f64,
    /// |lost − stored − to_boundaries| / max(|lost|, |stored|, |to_boundaries|).
    pub relative: f64,
}

/// Energy balance between the first and last state of a trajectory.
pub fn energy_balance(scene: &Scene, traj: &Trajectory) -> EnergyBalance {
    let n = scene.nodes();
    let (y0, y1) = match (traj.states.first(), traj.states.last()) {
        (Some(a), Some(b)) => (a, b),
        _ => {
            return EnergyBalance {
                lost: 0.0,
                stored: 0.0,
                to_boundaries: 0.0,
                relative: 0.0,
            }
        }
    };
    let lost = scene.loss_energy(y1) - scene.loss_energy(y0);
    let stored: f64 = (0..n).map(|i| scene.thermal.capacity[i] * (y1[i] - y0[i])).sum();
    let b = scene.boundary_energy_index();
    let to_b = y1[b] - y0[b];
    let scale = lost
        .abs()
        .max(stored.abs())
        .max(to_b.abs())
        .max(f64::MIN_POSITIVE);
    EnergyBalance {
        lost,
        stored,
        to_boundaries: to_b,
        relative: (lost - stored - to_b).abs() / scale,
    }
}
