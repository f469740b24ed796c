//! ROS3, a three-stage Rosenbrock method of order 3 with an embedded order-2 estimate, L-stable,
//! with **two** evaluations of f per step (its third stage reuses the second's):
//!
//! ```text
//! G = 1/(γh)·I − J,   Y_i = y + Σ_j a_ij K_j,
//! G K_i = f(t + α_i h, Y_i) + Σ_j c_ij/h K_j + γ_i h ∂f/∂t,
//! y⁺ = y + Σ m_i K_i,   error estimate Σ e_i K_i.
//! ```
//!
//! Source of the coefficients: the Rosenbrock integrator of KPP as FATODE ships it
//! (ComputationalScienceLaboratory/FATODE, `FWD/ROS/ROS_f90_Integrator.F90`, subroutine `Ros3`,
//! commit 0ccbac09; read there: "an L-stable method, 3 stages, order 3, 2 function
//! evaluations", its A, C, M, E, α and γ_i). The method belongs to the Rosenbrock family of
//! Sandu et al.'s atmospheric-chemistry benchmarks (Atmos. Environ. 31(20), 1997); that paper was
//! not read. The transformed form (G = 1/(γh) − J, stages K_i) is Hairer & Wanner's, as KPP
//! documents it. The order-3 and L-stability claims are KPP's, not re-derived here; what is
//! checked is convergence against analytic solutions (`tests/transient.rs`,
//! `tests/rosenbrock.rs`). No Newton iteration: per
//! step two right-hand sides, one Jacobian, one LU of the (small) node block and three
//! triangular solves.
//!
//! A Rosenbrock method needs the exact Jacobian for its order (measured: a Jacobian one cycle
//! sample old multiplies the WLTC error by 50, docs/numerics.md), so J is evaluated at every step.
//! Its costly part is the oil column, ∂f/∂T_oil through every loss (a forward difference costs one
//! loss evaluation). Here the losses' share of that column comes from slopes ∂q_k/∂T_oil the
//! integrator learns for free: stages 1 and 2 evaluate the losses at the same inputs and two oil
//! temperatures, and their difference quotient is the slope at this sample. At the next sample
//! each slope is carried over as a logarithmic derivative (∂ ln q_k/∂T_oil, which the viscosity
//! sets and the speed barely moves) times the new loss. An explicit forward difference is taken
//! when there is nothing to carry over: the first step, a gear change, an item whose loss was
//! zero, a rejected step. The links whose conductance follows ν(T_oil) enter with their analytic
//! derivative, which every RHS computes beside the conductance (the Jacobian at the step's start
//! takes both from the first stage).
//!
//! ∂f/∂t: only moving boundary temperatures (e.g. an engine coolant warm-up curve) make f depend
//! on t, and [`crate::scene::Scene::time_derivative`] gives it from the network alone.
//!
//! The stages and the update are linear combinations of f, and every column of J feeds the same
//! heat into the nodes as into the loss-energy and boundary-energy rows, so the energy balance
//! closes to rounding.

use diffsol::{Op, Vector};
use diffsol_la::{LinearOp, LinearSolver};

use diffsol::{FaerSparseMat, NalgebraMat, NalgebraVec};

use super::bracket::{Bracket, EVENT_MAX_ITER, EVENT_TIME_TOL};
use super::dense_lu::SmallDenseLu;
use super::driver::Driver;
use super::equations::{HostVector, JacobianMatrix, SceneEquations};
use super::sparse_lu::NetworkSparseLu;
use super::trajectory::{NumericalFailure, Trajectory};

/// A Rosenbrock tableau in the transformed form (coefficients as KPP/FATODE give them).
pub struct Tableau {
    /// Stages.
    pub stages: usize,
    /// Diagonal γ.
    pub gamma: f64,
    /// a_ij (j < i).
    pub a: [[f64; 3]; 3],
    /// c_ij (j < i).
    pub c: [[f64; 3]; 3],
    /// Stage i needs a new f (else it reuses stage i−1's).
    pub new_f: [bool; 3],
    /// α_i, stage times as fractions of h.
    pub alpha: [f64; 3],
    /// γ_i = Σ_j γ_ij, weights of h·∂f/∂t.
    pub gamma_sum: [f64; 3],
    /// Solution weights.
    pub m: [f64; 3],
    /// Error-estimate weights.
    pub e: [f64; 3],
    /// Order of the error estimate's leading term (the step-size exponent is 1/elo).
    pub elo: f64,
}

/// ROS3 (FATODE `Ros3`): L-stable, order 3(2), 3 stages, 2 evaluations of f.
pub const ROS3: Tableau = Tableau {
    stages: 3,
    gamma: 0.435_866_521_508_459,
    a: [[0.0; 3], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
    c: [
        [0.0; 3],
        [-1.015_617_108_387_770_2, 0.0, 0.0],
        [4.075_995_645_253_77, 9.207_679_429_833_079, 0.0],
    ],
    new_f: [true, true, false],
    alpha: [0.0, 0.435_866_521_508_459, 0.435_866_521_508_459],
    gamma_sum: [
        0.435_866_521_508_459,
        0.242_919_964_548_168_04,
        2.185_138_002_766_406,
    ],
    m: [1.0, 6.169_794_704_382_824_6, -0.427_722_565_432_185_7],
    e: [0.5, -2.907_955_871_680_547, 0.223_540_698_978_115_7],
    elo: 3.0,
};

/// Step-size controller (Hairer & Wanner II, IV.8): safety factor and bounds per step.
const SAFETY: f64 = 0.9;
const GROW_MAX: f64 = 5.0;
const SHRINK_MIN: f64 = 0.2;

/// Oil-temperature difference between stages 1 and 2 below which their loss difference is not
/// used as a slope (rounding would dominate it), K.
const MIN_SLOPE_DT: f64 = 1e-6;

/// Carried-over loss slopes are an approximate Jacobian, whose error the embedded estimate does
/// not see (measured: the WLTC error of the FZG C stays at 4e-5 K from rtol 1e-4 to 1e-8). Below
/// this relative tolerance the slopes are differenced at every step.
pub const CARRY_SLOPES_MIN_RTOL: f64 = 1e-5;

/// The iteration matrix W = I − γhJ as the linear operator the linear solvers factorise: written
/// straight from J into the solver's matrix (one pass, no intermediate copy).
struct IterationOp<'a, M: JacobianMatrix> {
    jac: &'a M,
    gamma_h: f64,
    /// Position of each diagonal entry in the matrix values.
    diag: &'a [usize],
    sparsity: Option<M::Sparsity>,
}

impl<M: JacobianMatrix> LinearOp for IterationOp<'_, M> {
    type T = f64;
    type V = M::V;
    type M = M;
    type C = M::C;
    fn nrows(&self) -> usize {
        self.jac.nrows()
    }
    fn ncols(&self) -> usize {
        self.jac.ncols()
    }
    fn context(&self) -> &M::C {
        self.jac.context()
    }
    fn matrix_inplace(&self, y: &mut M) {
        y.copy_from(self.jac);
        let v = y.values();
        v.iter_mut().for_each(|x| *x *= -self.gamma_h);
        for &p in self.diag {
            v[p] += 1.0;
        }
    }
    fn sparsity(&self) -> Option<M::Sparsity> {
        self.sparsity.clone()
    }
}

/// How a linear solver gets the Jacobian at (t, y) and factorises W = I − γhJ for a step.
pub(crate) trait IterationLu<M: JacobianMatrix>: LinearSolver<M> {
    /// Evaluate J (losses' share of the oil column from `dq_dt`) and factorise W = I − γhJ.
    /// The default writes J into `jac` and W into the solver's matrix.
    #[allow(clippy::too_many_arguments)]
    fn factorise_w(
        &mut self,
        eqn: &SceneEquations<'_, M>,
        y: &M::V,
        t: f64,
        dq_dt: &[f64],
        jac: &mut M,
        gamma_h: f64,
        diag: &[usize],
    ) {
        eqn.jacobian_with_slopes(y, t, dq_dt, jac);
        self.set_linearisation(&IterationOp {
            jac,
            gamma_h,
            diag,
            sparsity: None,
        });
    }
}

impl IterationLu<FaerSparseMat<f64>> for NetworkSparseLu {}

/// The small dense LU reads J's entries straight into its node block (no n × n matrix).
impl IterationLu<NalgebraMat<f64>> for SmallDenseLu {
    fn factorise_w(
        &mut self,
        eqn: &SceneEquations<'_, NalgebraMat<f64>>,
        y: &NalgebraVec<f64>,
        t: f64,
        dq_dt: &[f64],
        _jac: &mut NalgebraMat<f64>,
        gamma_h: f64,
        _diag: &[usize],
    ) {
        let n_all = y.len();
        eqn.with_jacobian_entries(y, t, dq_dt, |slots, vals| {
            self.factorise_entries(n_all, slots, vals, gamma_h)
        });
    }
}

/// What the integrator knows of ∂q_k/∂T_oil.
#[derive(Clone)]
struct Slopes {
    /// Slopes the next Jacobian uses, W/K.
    dq_dt: Vec<f64>,
    /// ∂ ln q_k/∂T_oil learnt at the last step, 1/K (None: not known).
    log: Vec<Option<f64>>,
    /// Gear state the logarithmic slopes were learnt in.
    state: Option<usize>,
    /// Losses at stage 1 (t, y) and stage 2 of the current step, W.
    q1: Vec<f64>,
    q2: Vec<f64>,
    /// Oil temperatures of stages 1 and 2, K.
    t_oil: [f64; 2],
}

/// Counters of a run.
#[derive(Default, Clone)]
pub(crate) struct RosStats {
    pub steps: usize,
    pub rejected: usize,
    pub lu: usize,
    /// Trial steps spent locating them.
    pub event_trials: usize,
}

/// The integrator's state over a run.
struct Ros<'a, 'd, M: JacobianMatrix, LS: IterationLu<M>> {
    tab: &'static Tableau,
    d: &'a Driver<'d>,
    eqn: &'a SceneEquations<'d, M>,
    y: M::V,
    /// f at (t, y).
    f: M::V,
    /// f of the latest stage.
    fs: M::V,
    /// ∂f/∂t at (t, y), when boundaries move.
    ft: Option<M::V>,
    /// `ft` is non-zero at this step (a boundary moves on the piece after t).
    ft_on: bool,
    k: Vec<M::V>,
    tmp: M::V,
    jac: M,
    diag: Vec<usize>,
    ls: LS,
    slopes: Slopes,
    stats: RosStats,
    /// Switching functions (controllers), scratch.
    g: Vec<f64>,
}

impl<'a, 'd, M: JacobianMatrix, LS: IterationLu<M>> Ros<'a, 'd, M, LS> {
    fn new(d: &'a Driver<'d>, eqn: &'a SceneEquations<'d, M>, y0: &[f64]) -> Self {
        let n = y0.len();
        let ctx = eqn.context().clone();
        let sparsity = eqn.matrix_sparsity();
        let matrix = || M::new_from_sparsity(n, n, sparsity.clone(), ctx.clone());
        let vector = || {
            let mut v = M::V::zeros(n, ctx.clone());
            v.host_mut().iter_mut().for_each(|x| *x = 0.0);
            v
        };
        let jac = matrix();
        let diag: Vec<usize> = (0..n).map(|i| M::slot(&jac, i, i)).collect();
        let mut y = vector();
        y.host_mut().copy_from_slice(y0);
        let tmp = vector();
        // Decided once: whether ∂f/∂t is needed at all.
        let ft = d.boundaries_move().then(vector);
        let mut ls = LS::default();
        ls.set_sparsity(&IterationOp {
            jac: &jac,
            gamma_h: 0.0,
            diag: &diag,
            sparsity: sparsity.clone(),
        });
        let m = d.items();
        Self {
            tab: &ROS3,
            d,
            eqn,
            y,
            f: vector(),
            fs: vector(),
            ft,
            ft_on: false,
            k: (0..ROS3.stages).map(|_| vector()).collect(),
            tmp,
            jac,
            diag,
            ls,
            slopes: Slopes {
                dq_dt: vec![0.0; m],
                log: vec![None; m],
                state: None,
                q1: vec![0.0; m],
                q2: vec![0.0; m],
                t_oil: [0.0; 2],
            },
            stats: RosStats::default(),
            g: vec![0.0; d.scene.switching_count()],
        }
    }

    /// Switch every controller whose switch is due at (t, y), logging each that switched.
    fn log_switches(&mut self, t: f64) {
        self.d.settle_and_log(t, self.y.host());
    }

    /// The largest switching function at time `time` and state `y` in the current modes:
    /// positive once some controller's switch is due (−∞ without controllers).
    fn switch_margin(&mut self, time: f64, y_is_trial: bool) -> f64 {
        if self.g.is_empty() {
            return f64::NEG_INFINITY;
        }
        let y = if y_is_trial {
            self.tmp.host()
        } else {
            self.y.host()
        };
        self.d
            .scene
            .switching_functions_at(time, y, &self.d.work.borrow(), &mut self.g);
        self.g.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
    }

    /// After an accepted trial step of size `h` from (t, y) whose end (in `tmp`) lies past a
    /// switching surface: the step size at which the first switch is due, found by regula falsi
    /// (Illinois) on the largest switching function of the ROS3 step as a function of its size;
    /// `tmp` then holds the step to that instant (just past the surface). None when no switch is
    /// due within the step.
    fn locate_event(&mut self, t: f64, h: f64) -> Option<f64> {
        let fb0 = self.switch_margin(t + h, true);
        if fb0 <= 0.0 {
            return None;
        }
        let fa = self.switch_margin(t, false).min(0.0);
        let mut br = Bracket::new(0.0, fa, h, fb0);
        let tol = EVENT_TIME_TOL * t.abs().max(1.0);
        let mut last = h;
        for _ in 0..EVENT_MAX_ITER {
            if br.b - br.a <= tol {
                break;
            }
            let c = br.trial();
            self.factorise(t, c);
            self.step(t, c);
            self.stats.event_trials += 1;
            last = c;
            let fc = self.switch_margin(t + c, true);
            br.update(c, fc);
        }
        let b = br.b;
        if last != b {
            self.factorise(t, b);
            self.step(t, b);
            self.stats.event_trials += 1;
        }
        Some(b)
    }

    /// f at (t, y) with the current inputs, and the losses of stage 1 (they are also the output
    /// row's); a non-finite f fails the run, naming the item the RHS diagnosed.
    fn eval_f(&mut self, t: f64) -> Result<(), NumericalFailure> {
        self.d.rhs(t, self.y.host(), self.f.host_mut());
        self.d.losses_into(&mut self.slopes.q1);
        self.slopes.t_oil[0] = self.d.oil_temp(self.y.host());
        if self.f.host().iter().all(|v| v.is_finite()) {
            return Ok(());
        }
        let why = "the right-hand side is not finite at an accepted state".to_string();
        Err(self.d.failure(t, self.y.host(), why))
    }

    /// The slopes for a Jacobian at (t, y) in `state`: carried over, else differenced.
    fn prepare_slopes(&mut self, t: f64, state: usize, retry: bool) {
        let s = &mut self.slopes;
        let carried = !retry
            && self.d.opts.rtol >= CARRY_SLOPES_MIN_RTOL
            && s.state == Some(state)
            && s.q1.iter().zip(&s.log).all(|(q, l)| *q == 0.0 || l.is_some());
        if carried {
            for ((d, q), l) in s.dq_dt.iter_mut().zip(&s.q1).zip(&s.log) {
                *d = q * l.unwrap_or(0.0);
            }
            return;
        }
        // Counted in the work area's Jacobian evaluations (`Stats::jac_evals`).
        self.d.loss_slopes(t, self.y.host(), &mut s.dq_dt);
        for ((l, d), q) in s.log.iter_mut().zip(&s.dq_dt).zip(&s.q1) {
            *l = (*q != 0.0).then(|| d / q);
        }
        s.state = Some(state);
    }

    /// Learn ∂ ln q_k/∂T_oil from the losses of stages 1 and 2 of an accepted step.
    fn learn_slopes(&mut self) {
        let s = &mut self.slopes;
        let dt = s.t_oil[1] - s.t_oil[0];
        if dt.abs() < MIN_SLOPE_DT {
            return;
        }
        let inv_dt = 1.0 / dt;
        for ((l, q1), q2) in s.log.iter_mut().zip(&s.q1).zip(&s.q2) {
            *l = (*q1 != 0.0).then(|| (q2 - q1) * inv_dt / q1);
        }
    }

    /// Evaluate J at (t, y) and factorise W = I − γhJ (= γh·G).
    fn factorise(&mut self, t: f64, h: f64) {
        self.ls.factorise_w(
            self.eqn,
            &self.y,
            t,
            &self.slopes.dq_dt,
            &mut self.jac,
            self.tab.gamma * h,
            &self.diag,
        );
        self.stats.lu += 1;
    }

    /// Stage i's right-hand side of W K_i = γh·(f_i + Σ c_ij/h K_j + γ_i h ∂f/∂t) into K_i.
    fn stage_rhs(&mut self, i: usize, h: f64) {
        let tab = self.tab;
        let gh = tab.gamma * h;
        let (done, rest) = self.k.split_at_mut(i);
        let ki = rest[0].host_mut();
        let f = if i == 0 { self.f.host() } else { self.fs.host() };
        // One pass over the state (ROS3 has at most two earlier stages).
        let c = |j: usize| tab.c[i][j] * tab.gamma;
        match done {
            [] => ki.iter_mut().zip(f).for_each(|(x, fi)| *x = gh * fi),
            [k0] => {
                let c0 = c(0);
                for ((x, fi), a) in ki.iter_mut().zip(f).zip(k0.host()) {
                    *x = gh * fi + c0 * a;
                }
            }
            [k0, k1, ..] => {
                let (c0, c1) = (c(0), c(1));
                for (((x, fi), a), b) in ki.iter_mut().zip(f).zip(k0.host()).zip(k1.host()) {
                    *x = gh * fi + c0 * a + c1 * b;
                }
            }
        }
        if let Some(ft) = self.ft.as_ref().filter(|_| self.ft_on) {
            let g = gh * tab.gamma_sum[i] * h;
            ki.iter_mut().zip(ft.host()).for_each(|(x, v)| *x += g * v);
        }
    }

    /// f at stage i's point into `fs` (and the stage-2 losses for the slopes).
    fn stage_f(&mut self, i: usize, t: f64, h: f64) {
        let tmp = self.tmp.host_mut();
        tmp.copy_from_slice(self.y.host());
        for (j, kj) in self.k[..i].iter().enumerate() {
            let a = self.tab.a[i][j];
            if a != 0.0 {
                tmp.iter_mut().zip(kj.host()).for_each(|(x, v)| *x += a * v);
            }
        }
        self.d
            .rhs(t + self.tab.alpha[i] * h, self.tmp.host(), self.fs.host_mut());
        if i == 1 {
            self.d.losses_into(&mut self.slopes.q2);
            self.slopes.t_oil[1] = self.d.oil_temp(self.tmp.host());
        }
    }

    /// One step of size h from (t, y): y⁺ into `tmp`; returns the weighted RMS error estimate
    /// (infinite when a solve fails or a value is not finite).
    fn step(&mut self, t: f64, h: f64) -> f64 {
        // Boundary series are piecewise linear: on a still piece (e.g. the coolant at its
        // thermostat) ∂f/∂t is zero and neither computed nor added.
        self.ft_on = self.ft.is_some() && !self.d.time_rate_vanishes(t);
        if let Some(ft) = self.ft.as_mut().filter(|_| self.ft_on) {
            self.d.time_derivative(t, self.y.host(), ft.host_mut());
        }
        for i in 0..self.tab.stages {
            if i > 0 && self.tab.new_f[i] {
                self.stage_f(i, t, h);
            }
            self.stage_rhs(i, h);
            if self.ls.solve_in_place(&mut self.k[i]).is_err() {
                return f64::INFINITY;
            }
        }
        self.update_and_error()
    }

    /// y⁺ = y + Σ m_i K_i into `tmp` and the weighted RMS norm of Σ e_i K_i.
    fn update_and_error(&mut self) -> f64 {
        let (rtol, atol) = (self.d.opts.rtol, self.d.atol);
        let (m, e) = (self.tab.m, self.tab.e);
        let (tmp, y) = (self.tmp.host_mut(), self.y.host());
        let [k0, k1, k2] = [self.k[0].host(), self.k[1].host(), self.k[2].host()];
        let mut sum = 0.0;
        for i in 0..y.len() {
            let (a, b, c) = (k0[i], k1[i], k2[i]);
            let y1 = y[i] + m[0] * a + m[1] * b + m[2] * c;
            let err = e[0] * a + e[1] * b + e[2] * c;
            tmp[i] = y1;
            let r = err / (atol[i] + rtol * y[i].abs().max(y1.abs()));
            sum += r * r;
        }
        let err = (sum / y.len() as f64).sqrt();
        if err.is_finite() {
            err
        } else {
            f64::INFINITY
        }
    }
}

/// Integrate the driver's segments with ROS3 on matrix type `M` and linear solver `LS`.
pub(crate) fn run<M, LS>(
    d: &Driver<'_>,
    eqn: &SceneEquations<'_, M>,
    y0: &[f64],
    traj: &mut Trajectory,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RosStats, NumericalFailure>
where
    M: JacobianMatrix,
    LS: IterationLu<M>,
{
    let mut r = Ros::<M, LS>::new(d, eqn, y0);
    let segs = d.segments;
    let mut t = segs[0].t0;
    d.settle_controls(t, r.y.host());
    r.eval_f(t)?;
    d.record_evaluated(traj, t, r.y.host(), 0);
    let len0 = segs[0].t1 - segs[0].t0;
    let mut h = d.restart_step(r.y.host(), r.f.host(), len0, len0);
    for (k, seg) in segs.iter().enumerate() {
        h = integrate_segment(&mut r, &mut t, h, seg.t1, seg.inputs.state)?;
        let y = r.y.host();
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(d.failure(seg.t1, y, format!("state component {i} is not finite")));
        }
        let row_seg = if k + 1 < segs.len() { k + 1 } else { k };
        if segs[row_seg].inputs != seg.inputs {
            d.switch_inputs(row_seg);
        }
        // The next step's first stage is f at the new inputs; its losses are the row's.
        r.eval_f(seg.t1)?;
        d.record_evaluated(traj, seg.t1, r.y.host(), row_seg);
        progress(k + 1, segs.len());
    }
    Ok(r.stats)
}

/// What ROS3 carries from one call of [`advance`] to the next, for a caller that integrates
/// piece by piece (co-simulation, [`super::cosim`]): the state, the step-size proposal, the
/// learnt loss slopes and the counters. Between calls the integrator is exactly where
/// [`run`] is between two segments.
#[derive(Clone)]
pub(crate) struct Carry {
    /// State (temperatures K, energies J).
    pub y: Vec<f64>,
    /// Next step-size proposal (None before the first step).
    pub h: Option<f64>,
    slopes: Option<Slopes>,
    /// Counters.
    pub stats: RosStats,
}

impl Carry {
    /// At state `y0`, before any step.
    pub fn new(y0: Vec<f64>) -> Self {
        Self {
            y: y0,
            h: None,
            slopes: None,
            stats: RosStats::default(),
        }
    }
}

/// Integrate from `t0` to `t1` with the driver's current inputs, continuing from `carry` as
/// [`run`] continues from one segment to the next: f at (t0, y) with the current inputs, the
/// carried step-size proposal (a starting step on the first call), the carried slopes.
pub(crate) fn advance<M, LS>(
    d: &Driver<'_>,
    eqn: &SceneEquations<'_, M>,
    carry: &mut Carry,
    t0: f64,
    t1: f64,
) -> Result<(), NumericalFailure>
where
    M: JacobianMatrix,
    LS: IterationLu<M>,
{
    let mut r = Ros::<M, LS>::new(d, eqn, &carry.y);
    if let Some(s) = carry.slopes.take() {
        r.slopes = s;
    }
    r.stats = std::mem::take(&mut carry.stats);
    let mut t = t0;
    r.eval_f(t)?;
    let h = carry
        .h
        .unwrap_or_else(|| d.restart_step(r.y.host(), r.f.host(), t1 - t0, t1 - t0));
    let state = d.work.borrow().inputs.state;
    let result = integrate_segment(&mut r, &mut t, h, t1, state);
    carry.stats = std::mem::take(&mut r.stats);
    let h = result?;
    let y = r.y.host();
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(d.failure(t1, y, format!("state component {i} is not finite")));
    }
    carry.y.copy_from_slice(y);
    carry.h = Some(h);
    carry.slopes = Some(r.slopes);
    Ok(())
}

/// Steps from t to `t1` (f at (t, y) already evaluated); returns the next step-size proposal.
fn integrate_segment<M: JacobianMatrix, LS: IterationLu<M>>(
    r: &mut Ros<'_, '_, M, LS>,
    t: &mut f64,
    mut h: f64,
    t1: f64,
    state: usize,
) -> Result<f64, NumericalFailure> {
    let d = r.d;
    let mut retry = false;
    while *t < t1 {
        if r.stats.steps + r.stats.rejected >= d.opts.max_steps {
            return Err(d.budget_failure(*t, r.y.host()));
        }
        let rest = t1 - *t;
        // Land exactly on the segment end, leaving no sliver.
        let h_try = if h >= rest * (1.0 - 1e-9) { rest } else { h };
        r.prepare_slopes(*t, state, retry);
        r.factorise(*t, h_try);
        let err = r.step(*t, h_try);
        let expo = -1.0 / r.tab.elo;
        if err <= 1.0 {
            r.stats.steps += 1;
            h = h_try * (SAFETY * err.max(1e-10).powf(expo)).min(GROW_MAX);
            let event = r.locate_event(*t, h_try);
            r.learn_slopes();
            *t = match event {
                Some(he) if he < rest => *t + he,
                _ if h_try == rest => t1,
                _ => *t + h_try,
            };
            std::mem::swap(&mut r.y, &mut r.tmp);
            d.clear_failure();
            if event.is_some() {
                // The switch: the modes after it, and f with them at the next step's start.
                r.log_switches(*t);
            }
            retry = false;
            if *t < t1 {
                r.eval_f(*t)?;
                if event.is_some() {
                    // f has jumped: a starting step for the new mode, at most the proposal.
                    h = d.restart_step(r.y.host(), r.f.host(), h, t1 - *t);
                }
            }
        } else {
            r.stats.rejected += 1;
            let fac = if err.is_finite() {
                (SAFETY * err.powf(expo)).clamp(SHRINK_MIN, 1.0)
            } else {
                0.25
            };
            h = h_try * fac;
            retry = true;
            if h < 1e-10 * t.abs().max(1.0) {
                let why = format!("step size {h:.3e} s too small: the error test keeps failing");
                return Err(d.failure(*t, r.y.host(), why));
            }
        }
    }
    Ok(h)
}
