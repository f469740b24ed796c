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
//! 3. Samples and shifts are known times (stop times); roots are the controllers' switching
//!    functions only. A root found in the step that lands on the stop time hides `TstopReached`:
//!    after the switch the state is set back to the root's time and the stop time set again.
//! 4. After a restart the step size is re-estimated (Hairer–Nørsett–Wanner II.4 starting step with
//!    the new derivative), not kept from before the jump.
//! 5. Restarts only where the inputs jump ([`Restart::AtJumps`], default); `EveryInterval` exists
//!    for the benchmark.
//! 6. After changing the inputs the state's `dy` is set to `f(t⁺, y)`.

use std::cell::{Cell, RefCell};
use std::time::Instant;

use diffsol::{FaerSparseMat, NalgebraMat, OdeBuilder, OdeEquations, OdeSolverMethod, OdeSolverStopReason};

use super::dense_lu::SmallDenseLu;
use super::driver::Driver;
use super::equations::{HostVector, SceneEquations};
use super::events::Events;
use super::rosenbrock;
use super::rows::Rows;
use super::sparse_lu::NetworkSparseLu;
use crate::scene::Scene;

pub use super::trajectory::{
    check_stored_values, energy_balance, stored_values, EnergyBalance, NumericalFailure, Segment, Stats,
    Trajectory, MAX_STORED_VALUES,
};
pub use super::transient_options::{
    Guards, LinearAlgebra, Method, Restart, TransientOptions, DEFAULT_ATOL, DEFAULT_METHOD, DEFAULT_RTOL,
    ROS3_MAX_NODES, SPARSE_FROM_STATES,
};

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
        node: scene.thermal().names[scene.thermal().oil].clone(),
        item: None,
        message: "empty input: no segment to integrate".into(),
    })?;
    let n = scene.nodes();
    let method = opts.method.resolve(n);
    let ns = scene.n_states();
    let y0 = scene.initial_state(opts.initial_temp);
    let atol = state_atol(scene, opts.atol);
    let work = RefCell::new(scene.work(first.inputs));
    {
        let mut w = work.borrow_mut();
        scene.initial_control_modes(&y0, &mut w);
        scene.settle_controls(&y0, &mut w);
        w.net.switches.iter_mut().for_each(|x| *x = 0);
    }
    let fail_build = |e: diffsol::error::DiffsolError| NumericalFailure {
        time: first.t0,
        node: scene.thermal().names[scene.thermal().oil].clone(),
        item: None,
        message: format!("could not set up the solver: {e}"),
    };
    let ctx = Driver {
        scene,
        work: &work,
        segments,
        opts,
        atol: &atol,
        events: Cell::new(0),
        event_log: RefCell::new(Vec::new()),
    };
    let mut traj = Trajectory {
        times: Vec::with_capacity(segments.len() + 1),
        states: Rows::with_capacity(scene.n_states(), segments.len() + 1),
        losses: Rows::with_capacity(
            scene.items(),
            if opts.record_losses { segments.len() + 1 } else { 0 },
        ),
        segment: Vec::with_capacity(segments.len() + 1),
        controls: Rows::with_capacity(
            scene.thermal().controls.len() + scene.thermal().pi_rows() / crate::scene::controls::ROWS_PER_PI,
            segments.len() + 1,
        ),
        switches: Vec::new(),
        events: Vec::new(),
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
    traj.stats.events = ctx.events.get();
    traj.events = ctx.event_log.take();
    traj.switches = w.net.switches.clone();
    traj.wall_time_s = start.elapsed().as_secs_f64();
    Ok(traj)
}

/// The absolute tolerance of every state: `atol` (K) on temperatures, `atol` × the mean node
/// capacity (J) on energies, `atol` × the gain (share) on a PI valve's integral.
pub(crate) fn state_atol(scene: &Scene, atol: f64) -> Vec<f64> {
    let n = scene.nodes();
    let mean_c = scene.thermal().capacity.iter().sum::<f64>() / n as f64;
    let mut out = vec![atol; scene.n_states()];
    for a in out.iter_mut().skip(n) {
        *a = atol * mean_c;
    }
    // A PI valve's integral (a share): the share `atol` K of its sensor moves.
    let th = scene.thermal();
    for (k, c) in th.controls.iter().enumerate() {
        if let Some(r) = th.integral_row(k) {
            out[r] = atol * c.gain();
        }
    }
    out
}

impl Driver<'_> {
    /// Integrate the segments with a diffsol solver, recording a row at every segment end.
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
        let mut events = Events::new(self.scene);
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
                events.step_start(solver);
                let stepped = solver.step();
                if stepped.is_ok() {
                    // A non-finite trial the solver recovered from is not this run's failure.
                    self.work.borrow_mut().failure = None;
                }
                match stepped {
                    Ok(OdeSolverStopReason::TstopReached) => {
                        if events.at_stop(self, solver, seg.t1)? {
                            break;
                        }
                    }
                    Ok(OdeSolverStopReason::InternalTimestep) => {}
                    Ok(OdeSolverStopReason::RootFound(tr, idx)) => {
                        if events.at_root(self, solver, tr, idx, seg.t1)? {
                            break;
                        }
                    }
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
