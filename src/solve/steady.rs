//! Steady-state equilibrium of the lumped thermal network (physics.md §10).
//!
//! Unknowns are the temperatures `T` (K) of the `n` non-boundary nodes. The caller describes the
//! network through [`HeatBalance`]: the residual `r(T)` (W) is the net heat flow into each node
//! (assigned losses + linear conductances + radiation + thermostat cooler), and equilibrium is
//! `r(T) = 0`, i.e. `C dT/dt = 0` (physics.md §8).
//!
//! Method ([`solve_steady`]):
//!
//! 1. **Damped Newton** with the caller's exact Jacobian `J = ∂r/∂T`: direction `δ = −J⁻¹ r`
//!    (nalgebra dense LU with partial pivoting), scaled so that `max|δ| ≤ max_step_k`, projected
//!    onto the per-node valid range, backtracking (halving) until the Armijo condition
//!    `‖r(T + λδ)‖₂ ≤ (1 − α λ)‖r(T)‖₂` holds [recalled: C. T. Kelley, *Solving Nonlinear
//!    Equations with Newton's Method*, SIAM 2003, §1.10 (Newton–Armijo)].
//! 2. **Pseudo-transient continuation** when Newton stalls (line search fails, singular `J`, or
//!    `stall_iters` consecutive damped / bound-limited steps): linearised backward-Euler steps of
//!    the pseudo-transient `C dT/dτ = r(T)`, `(C/Δτ − J) δ = r`, with switched evolution
//!    relaxation `Δτ_{k+1} = Δτ_k ‖r_{k−1}‖₂ / ‖r_k‖₂`, i.e. `Δτ_k = Δτ_0 ‖r_0‖₂/‖r_k‖₂`
//!    [recalled: C. T. Kelley & D. E. Keyes, "Convergence analysis of pseudo-transient
//!    continuation", SIAM J. Numer. Anal. 35(2) 508–523, 1998; SER: W. A. Mulder & B. van Leer,
//!    J. Comput. Phys. 59, 1985]. Returns to Newton when `‖r‖₂ ≤ ptc_return_ratio · ‖r_0‖₂`.
//! 3. **Polishing** Newton steps until the tolerance is met.
//!
//! Convergence: `max|r_i| ≤ abs_tol_w + rel_tol · scale` with `scale = heat_scale_w` or, if not
//! given, `max|r_i(T0)|`; or a full (undamped, unclipped) Newton step with `max|δ| ≤ step_tol_k`
//! (the residual has reached its round-off floor; the step is an error estimate for quadratic
//! convergence).
//!
//! Allocation: the work buffers (a few `n`-vectors, one `n×n` matrix) are created once per call;
//! inside the loop only nalgebra's LU permutation record (`n` index pairs) is allocated per
//! factorisation. The singular-value decomposition used to name the null-space nodes runs once,
//! at the end (converged point or failure).

use std::fmt;

use nalgebra::{DMatrix, DVector, LU, SVD};

/// The thermal network seen by the steady solver.
///
/// Sign convention: `residual` is the net heat flow INTO each node (W), so that
/// `C_i dT_i/dt = r_i(T)`; the Jacobian of a passive network is then negative (semi-)definite.
pub trait HeatBalance {
    /// Number of unknown temperatures.
    fn dim(&self) -> usize;
    /// Net heat flow into each node, W, at temperatures `t` (K). Must not allocate. May return
    /// Err(description) if the state is outside the model's valid range (e.g. oil above its limit).
    fn residual(&self, t: &[f64], out: &mut [f64]) -> Result<(), String>;
    /// Exact Jacobian ∂r/∂T (W/K), dense n×n, written into `jac`. The solver passes an n×n
    /// matrix filled with zeros, so the implementation may either assign or accumulate.
    fn jacobian(&self, t: &[f64], jac: &mut DMatrix<f64>) -> Result<(), String>;
    /// Heat capacities C_i (J/K) used by pseudo-transient continuation (all > 0).
    fn capacities(&self) -> &[f64];
    /// Valid temperature range (K) for node i, e.g. oil's viscosity-law range (`lo < hi`;
    /// infinite values are allowed).
    fn bounds(&self, i: usize) -> (f64, f64);
}

/// Which end of a node's valid temperature range was hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundSide {
    /// The lower limit `bounds(i).0`.
    Lower,
    /// The upper limit `bounds(i).1`.
    Upper,
}

impl fmt::Display for BoundSide {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BoundSide::Lower => f.write_str("lower"),
            BoundSide::Upper => f.write_str("upper"),
        }
    }
}

/// Tolerances and iteration limits of [`solve_steady`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyOptions {
    /// Absolute residual tolerance, W (max-norm). Default 1e-9 W.
    pub abs_tol_w: f64,
    /// Relative residual tolerance (times the heat scale). Default 1e-12.
    pub rel_tol: f64,
    /// Heat scale, W, for the relative tolerance; `None` → `max|r(T0)|` (the net heat imbalance
    /// at the start, typically the total loss when starting from ambient).
    pub heat_scale_w: Option<f64>,
    /// A full Newton step with `max|ΔT| ≤ step_tol_k` (K) also counts as converged. Default 1e-10.
    pub step_tol_k: f64,
    /// Maximum number of (accepted) Newton steps. Default 100.
    pub max_iter: usize,
    /// Maximum number of pseudo-transient steps (attempted, over all PTC phases). Default 1000.
    pub ptc_max_iter: usize,
    /// Largest temperature change of any node per step, K. Default 50 K.
    pub max_step_k: f64,
    /// Armijo sufficient-decrease constant α in (0, 1). Default 1e-4.
    pub armijo: f64,
    /// Maximum number of step halvings in the line search. Default 30.
    pub max_backtracks: usize,
    /// Consecutive damped (λ < 1) or bound-limited Newton steps before switching to PTC.
    /// Default 5.
    pub stall_iters: usize,
    /// First PTC step: Δτ₀ is chosen so that the fastest-heating node would move this much
    /// (K) in an explicit step, `Δτ₀ = ptc_initial_step_k / max_i(|r_i|/C_i)`. Default 2 K.
    pub ptc_initial_step_k: f64,
    /// Return from PTC to Newton when ‖r‖₂ has dropped by this factor since PTC started.
    /// Default 1e-3.
    pub ptc_return_ratio: f64,
    /// Consecutive PTC steps with a node held at a bound while its heat balance pushes it
    /// outward before reporting [`SteadyError::NoEquilibriumInRange`]. Default 5.
    pub bound_patience: usize,
}

impl Default for SteadyOptions {
    fn default() -> Self {
        Self {
            abs_tol_w: 1e-9,
            rel_tol: 1e-12,
            heat_scale_w: None,
            step_tol_k: 1e-10,
            max_iter: 100,
            ptc_max_iter: 1000,
            max_step_k: 50.0,
            armijo: 1e-4,
            max_backtracks: 30,
            stall_iters: 5,
            ptc_initial_step_k: 2.0,
            ptc_return_ratio: 1e-3,
            bound_patience: 5,
        }
    }
}

/// Result of [`solve_steady`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteadySolution {
    /// Equilibrium temperatures of the non-boundary nodes, K.
    pub temperatures: Vec<f64>,
    /// Accepted Newton steps (including polishing steps after PTC).
    pub iterations: usize,
    /// Pseudo-transient steps (attempted, including rejected ones).
    pub ptc_iterations: usize,
    /// Final max|r_i|, W.
    pub residual_w: f64,
    /// `"newton"` or `"newton+ptc"`.
    pub method: &'static str,
    /// The residual tolerance that was applied, W.
    pub tolerance_w: f64,
    /// max|r_i| (W) at the start and after every accepted step (Newton or PTC).
    pub residual_history_w: Vec<f64>,
}

/// Failure of [`solve_steady`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SteadyError {
    /// The iterates were driven to a node's valid-range limit and stayed there with the heat
    /// balance pushing further out (e.g. losses grow faster with temperature than the cooling).
    /// `temperature_k` is where the last step wanted to take the node (beyond `bound_k`).
    #[error(
        "no equilibrium within the valid range: node {node} is driven to {temperature_k:.3} K, \
         beyond its {which} bound {bound_k:.3} K (heat balance keeps pushing it out)"
    )]
    NoEquilibriumInRange {
        /// Index of the node driven out of its range.
        node: usize,
        /// Temperature the last step wanted for that node, K.
        temperature_k: f64,
        /// The range limit it crossed, K.
        bound_k: f64,
        /// Whether that limit is the lower or the upper one.
        which: BoundSide,
    },
    /// The Jacobian is singular (typically a node or group of nodes with no thermal path to a
    /// boundary). `nodes` are the nodes carrying the null space, largest component first.
    #[error("singular heat balance: node(s) {nodes:?} have no thermal path to a boundary (the Jacobian has a null space on them)")]
    Singular {
        /// Indices of the nodes carrying the null space, largest component first.
        nodes: Vec<usize>,
    },
    /// Iteration limits reached.
    #[error(
        "steady solver did not converge after {iterations} iterations (max |residual| = {residual_w:.3e} W)"
    )]
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// Largest heat-balance residual over the nodes at the last iterate, W.
        residual_w: f64,
    },
    /// Error reported by the model ([`HeatBalance::residual`] / [`HeatBalance::jacobian`]).
    #[error("thermal model error: {0}")]
    Model(String),
    /// Inconsistent input (lengths, capacities, bounds, options).
    #[error("invalid steady-solver input: {0}")]
    InvalidInput(String),
}

/// Singular values below this fraction of the largest count as zero.
const SINGULAR_RTOL: f64 = 1e-12;
/// A node carries the null space if its component is at least this fraction of the largest.
const NULL_COMPONENT_FRAC: f64 = 0.1;
/// A PTC step is rejected (Δτ reduced) if ‖r‖₂ grows by more than this factor.
const PTC_REJECT_GROWTH: f64 = 10.0;
/// Δτ reduction after a rejected PTC step.
const PTC_SHRINK: f64 = 0.25;
/// Upper limit of Δτ, s (keeps C/Δτ from underflowing to exactly zero).
const PTC_DTAU_MAX_S: f64 = 1e30;

/// Solve `r(T) = 0` for the steady state of `sys`, starting from `t0` (K, clamped into the
/// valid ranges). See the module documentation for the method.
///
/// Errors: [`SteadyError::InvalidInput`] for inconsistent lengths / capacities / bounds /
/// options; [`SteadyError::Model`] if the model fails at the start (or keeps failing);
/// [`SteadyError::Singular`] if the Jacobian at the final (or failing) point is singular;
/// [`SteadyError::NoEquilibriumInRange`] if a node is pushed against a bound and stays there;
/// [`SteadyError::NotConverged`] otherwise.
pub fn solve_steady<H: HeatBalance>(
    sys: &H,
    t0: &[f64],
    opts: &SteadyOptions,
) -> Result<SteadySolution, SteadyError> {
    validate_options(opts)?;
    let n = sys.dim();
    if t0.len() != n {
        return Err(SteadyError::InvalidInput(format!(
            "initial temperature vector has {} entries, the model has {n} unknowns",
            t0.len()
        )));
    }
    let caps = sys.capacities();
    if caps.len() != n {
        return Err(SteadyError::InvalidInput(format!(
            "capacities have {} entries, the model has {n} unknowns",
            caps.len()
        )));
    }
    if let Some(i) = caps.iter().position(|c| !(c.is_finite() && *c > 0.0)) {
        return Err(SteadyError::InvalidInput(format!(
            "heat capacity of node {i} is {} J/K (must be finite and > 0)",
            caps[i]
        )));
    }
    let mut lo = Vec::with_capacity(n);
    let mut hi = Vec::with_capacity(n);
    for i in 0..n {
        let (l, h) = sys.bounds(i);
        if l.is_nan() || h.is_nan() || l >= h {
            return Err(SteadyError::InvalidInput(format!(
                "valid range of node {i} is [{l}, {h}] K (need lo < hi)"
            )));
        }
        lo.push(l);
        hi.push(h);
    }
    if let Some(i) = t0.iter().position(|v| !v.is_finite()) {
        return Err(SteadyError::InvalidInput(format!(
            "initial temperature of node {i} is {}",
            t0[i]
        )));
    }
    let t: Vec<f64> = (0..n).map(|i| t0[i].clamp(lo[i], hi[i])).collect();
    let mut r = vec![0.0; n];
    eval_residual(sys, &t, &mut r).map_err(SteadyError::Model)?;
    let r0 = norm_inf(&r);
    let scale = opts.heat_scale_w.unwrap_or(r0);
    let tol = opts.abs_tol_w + opts.rel_tol * scale;
    let mut history = Vec::with_capacity(opts.max_iter + opts.ptc_max_iter + 1);
    history.push(r0);
    if n == 0 {
        return Ok(SteadySolution {
            temperatures: t,
            iterations: 0,
            ptc_iterations: 0,
            residual_w: 0.0,
            method: "newton",
            tolerance_w: tol,
            residual_history_w: history,
        });
    }
    let solver = Solver {
        sys,
        opts,
        caps,
        n,
        lo,
        hi,
        tol,
        t_trial: t.clone(),
        r_trial: vec![0.0; n],
        target: t.clone(),
        t,
        r,
        delta: DVector::zeros(n),
        jac: DMatrix::zeros(n, n),
        newton_iters: 0,
        ptc_iters: 0,
        history,
        last_model_err: None,
    };
    solver.run()
}

fn validate_options(o: &SteadyOptions) -> Result<(), SteadyError> {
    let bad = |what: &str| Err(SteadyError::InvalidInput(format!("option {what}")));
    if !(o.abs_tol_w.is_finite() && o.abs_tol_w >= 0.0) {
        return bad("abs_tol_w must be finite and >= 0");
    }
    if !(o.rel_tol.is_finite() && o.rel_tol >= 0.0) {
        return bad("rel_tol must be finite and >= 0");
    }
    if let Some(s) = o.heat_scale_w {
        if !(s.is_finite() && s >= 0.0) {
            return bad("heat_scale_w must be finite and >= 0");
        }
    }
    if !(o.step_tol_k.is_finite() && o.step_tol_k >= 0.0) {
        return bad("step_tol_k must be finite and >= 0");
    }
    if o.max_step_k.is_nan() || o.max_step_k <= 0.0 {
        return bad("max_step_k must be > 0");
    }
    if !(o.armijo > 0.0 && o.armijo < 1.0) {
        return bad("armijo must be in (0, 1)");
    }
    if !(o.ptc_initial_step_k.is_finite() && o.ptc_initial_step_k > 0.0) {
        return bad("ptc_initial_step_k must be finite and > 0");
    }
    if !(o.ptc_return_ratio > 0.0 && o.ptc_return_ratio < 1.0) {
        return bad("ptc_return_ratio must be in (0, 1)");
    }
    if o.stall_iters == 0 || o.bound_patience == 0 {
        return bad("stall_iters and bound_patience must be >= 1");
    }
    Ok(())
}

fn eval_residual<H: HeatBalance>(sys: &H, t: &[f64], out: &mut [f64]) -> Result<(), String> {
    sys.residual(t, out)?;
    if out.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err("heat balance is not finite".to_string())
    }
}

fn norm_inf(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

enum NewtonOutcome {
    /// Step accepted; `tiny`: full step below `step_tol_k` (converged); `damped`: λ < 1 or a
    /// bound was active.
    Accepted { tiny: bool, damped: bool },
    /// Singular Jacobian or line search failure.
    Failed,
}

enum PtcOutcome {
    Converged,
    BackToNewton,
    /// Bound patience exhausted or PTC budget used up.
    Stuck,
}

struct Solver<'a, H: HeatBalance> {
    sys: &'a H,
    opts: &'a SteadyOptions,
    caps: &'a [f64],
    n: usize,
    lo: Vec<f64>,
    hi: Vec<f64>,
    tol: f64,
    t: Vec<f64>,
    r: Vec<f64>,
    t_trial: Vec<f64>,
    r_trial: Vec<f64>,
    /// Last unclipped target `T + s·δ` (for the NoEquilibriumInRange report).
    target: Vec<f64>,
    delta: DVector<f64>,
    jac: DMatrix<f64>,
    newton_iters: usize,
    ptc_iters: usize,
    history: Vec<f64>,
    last_model_err: Option<String>,
}

impl<H: HeatBalance> Solver<'_, H> {
    fn run(mut self) -> Result<SteadySolution, SteadyError> {
        let mut stall = 0usize;
        let mut use_ptc = false;
        loop {
            if norm_inf(&self.r) <= self.tol {
                return self.finish();
            }
            if use_ptc {
                match self.ptc_phase()? {
                    PtcOutcome::Converged => return self.finish(),
                    PtcOutcome::BackToNewton => {
                        use_ptc = false;
                        stall = 0;
                    }
                    PtcOutcome::Stuck => return Err(self.failure()?),
                }
            } else {
                if self.newton_iters >= self.opts.max_iter {
                    return Err(self.failure()?);
                }
                match self.newton_step()? {
                    NewtonOutcome::Accepted { tiny: true, .. } => return self.finish(),
                    NewtonOutcome::Accepted { damped, .. } => {
                        stall = if damped { stall + 1 } else { 0 };
                        if stall >= self.opts.stall_iters {
                            use_ptc = self.ptc_iters < self.opts.ptc_max_iter;
                            stall = 0;
                        }
                    }
                    NewtonOutcome::Failed => {
                        if self.ptc_iters >= self.opts.ptc_max_iter {
                            return Err(self.failure()?);
                        }
                        use_ptc = true;
                    }
                }
            }
        }
    }

    /// Evaluate the Jacobian at `self.t` into `self.jac` (zeroed first), checking its shape.
    fn eval_jacobian(&mut self) -> Result<(), SteadyError> {
        self.jac.fill(0.0);
        self.sys
            .jacobian(&self.t, &mut self.jac)
            .map_err(SteadyError::Model)?;
        if self.jac.shape() != (self.n, self.n) {
            return Err(SteadyError::Model(format!(
                "Jacobian has shape {:?}, expected ({n}, {n})",
                self.jac.shape(),
                n = self.n
            )));
        }
        Ok(())
    }

    /// Solve `jac · δ = −r` in place (LU with partial pivoting). Returns false if the matrix is
    /// singular or the step is not finite. `jac` is overwritten (its storage is reused).
    fn direction(&mut self) -> bool {
        for (d, r) in self.delta.iter_mut().zip(&self.r) {
            *d = -r;
        }
        let m = std::mem::replace(&mut self.jac, DMatrix::zeros(0, 0));
        if !m.iter().all(|v| v.is_finite()) {
            self.jac = m;
            return false;
        }
        let lu = LU::new(m);
        let ok = lu.solve_mut(&mut self.delta);
        // Reclaim the n×n storage (same shape, no reallocation).
        self.jac = lu.l_unpack();
        ok && self.delta.iter().all(|v| v.is_finite())
    }

    /// Step scale so that max|s·δ| ≤ max_step_k; also returns max|δ|.
    fn step_scale(&self) -> (f64, f64) {
        let dmax = norm_inf(self.delta.as_slice());
        let s = if dmax > self.opts.max_step_k {
            self.opts.max_step_k / dmax
        } else {
            1.0
        };
        (s, dmax)
    }

    /// t_trial = clamp(t + f·δ); target = t + f·δ. Returns whether a bound was active.
    fn trial_point(&mut self, f: f64) -> bool {
        let mut hit = false;
        for i in 0..self.n {
            let x = self.t[i] + f * self.delta[i];
            self.target[i] = x;
            let c = x.clamp(self.lo[i], self.hi[i]);
            hit |= c != x;
            self.t_trial[i] = c;
        }
        hit
    }

    fn accept_trial(&mut self) {
        std::mem::swap(&mut self.t, &mut self.t_trial);
        std::mem::swap(&mut self.r, &mut self.r_trial);
        self.history.push(norm_inf(&self.r));
        self.last_model_err = None;
    }

    fn newton_step(&mut self) -> Result<NewtonOutcome, SteadyError> {
        self.eval_jacobian()?;
        if !self.direction() {
            return Ok(NewtonOutcome::Failed);
        }
        let (s, dmax) = self.step_scale();
        let r_norm = norm2(&self.r);
        if s == 1.0 && dmax <= self.opts.step_tol_k {
            self.trial_point(1.0);
            match eval_residual(self.sys, &self.t_trial, &mut self.r_trial) {
                Ok(()) => {
                    self.accept_trial();
                    self.newton_iters += 1;
                    return Ok(NewtonOutcome::Accepted {
                        tiny: true,
                        damped: false,
                    });
                }
                Err(e) => {
                    self.last_model_err = Some(e);
                    return Ok(NewtonOutcome::Failed);
                }
            }
        }
        let mut lambda = 1.0;
        for _ in 0..=self.opts.max_backtracks {
            let hit = self.trial_point(lambda * s);
            match eval_residual(self.sys, &self.t_trial, &mut self.r_trial) {
                Ok(()) => {
                    if norm2(&self.r_trial) <= (1.0 - self.opts.armijo * lambda * s) * r_norm {
                        self.accept_trial();
                        self.newton_iters += 1;
                        return Ok(NewtonOutcome::Accepted {
                            tiny: false,
                            damped: lambda < 1.0 || hit,
                        });
                    }
                }
                Err(e) => self.last_model_err = Some(e),
            }
            lambda *= 0.5;
        }
        Ok(NewtonOutcome::Failed)
    }

    fn ptc_phase(&mut self) -> Result<PtcOutcome, SteadyError> {
        let r_start = norm2(&self.r);
        let rate = self
            .r
            .iter()
            .zip(self.caps)
            .fold(0.0, |m: f64, (r, c)| m.max(r.abs() / c));
        let mut dtau = if rate > 0.0 {
            (self.opts.ptc_initial_step_k / rate).min(PTC_DTAU_MAX_S)
        } else {
            1.0
        };
        let mut r_prev = r_start;
        let mut stuck = 0usize;
        while self.ptc_iters < self.opts.ptc_max_iter {
            self.ptc_iters += 1;

            self.eval_jacobian()?;
            for i in 0..self.n {
                self.jac[(i, i)] -= self.caps[i] / dtau;
            }
            if !self.direction() {
                dtau *= PTC_SHRINK;
                continue;
            }
            let (s, _) = self.step_scale();
            self.trial_point(s);
            if let Err(e) = eval_residual(self.sys, &self.t_trial, &mut self.r_trial) {
                self.last_model_err = Some(e);
                dtau *= PTC_SHRINK;
                continue;
            }
            let rn = norm2(&self.r_trial);
            if rn > PTC_REJECT_GROWTH * r_prev {
                // A rejected step while a node sits at its limit with its heat balance pushing out
                // also counts toward `bound_patience`: with that node clipped the others keep
                // heating and every further step grows the residual (runaway with no equilibrium
                // in range), which would otherwise only shrink Δτ until the budget runs out.
                if self.pushing_node().is_some() {
                    stuck += 1;
                    if stuck >= self.opts.bound_patience {
                        return Ok(PtcOutcome::Stuck);
                    }
                }
                dtau *= PTC_SHRINK;
                continue;
            }
            self.accept_trial();
            if norm_inf(&self.r) <= self.tol {
                return Ok(PtcOutcome::Converged);
            }
            if self.pushing_node().is_some() {
                stuck += 1;
                if stuck >= self.opts.bound_patience {
                    return Ok(PtcOutcome::Stuck);
                }
            } else {
                stuck = 0;
            }
            // Switched evolution relaxation.
            dtau = (dtau * r_prev / rn).min(PTC_DTAU_MAX_S);
            r_prev = rn;
            if rn <= self.opts.ptc_return_ratio * r_start {
                return Ok(PtcOutcome::BackToNewton);
            }
        }
        Ok(PtcOutcome::Stuck)
    }

    /// The node held at a bound whose heat balance pushes it further out (largest |r_i|).
    fn pushing_node(&self) -> Option<(usize, BoundSide)> {
        let mut best: Option<(usize, BoundSide)> = None;
        let mut best_r = 0.0;
        for i in 0..self.n {
            let side = if self.t[i] >= self.hi[i] && self.r[i] > self.tol {
                BoundSide::Upper
            } else if self.t[i] <= self.lo[i] && self.r[i] < -self.tol {
                BoundSide::Lower
            } else {
                continue;
            };
            if self.r[i].abs() > best_r {
                best_r = self.r[i].abs();
                best = Some((i, side));
            }
        }
        best
    }

    /// Nodes carrying the null space of J at the current point, or None if J is regular.
    fn null_space_nodes(&mut self) -> Result<Option<Vec<usize>>, SteadyError> {
        self.eval_jacobian()?;
        if !self.jac.iter().all(|v| v.is_finite()) {
            return Err(SteadyError::Model(
                "Jacobian is not finite at the current temperatures".to_string(),
            ));
        }
        let Some(svd) = SVD::try_new(self.jac.clone(), false, true, f64::EPSILON, 10_000) else {
            return Ok(None);
        };
        let sv = &svd.singular_values;
        let smax = sv.max();
        let threshold = SINGULAR_RTOL * smax;
        if smax > 0.0 && sv.iter().all(|&s| s > threshold) {
            return Ok(None);
        }
        let Some(v_t) = svd.v_t.as_ref() else {
            return Ok(None);
        };
        // Largest null-space component of each node over all (near-)null right singular vectors.
        let mut weight = vec![0.0_f64; self.n];
        for (k, &s) in sv.iter().enumerate() {
            if s <= threshold {
                let row = v_t.row(k);
                for (w, v) in weight.iter_mut().zip(row.iter()) {
                    *w = w.max(v.abs());
                }
            }
        }
        let wmax = weight.iter().fold(0.0_f64, |m, w| m.max(*w));
        let mut nodes: Vec<usize> = (0..self.n)
            .filter(|&i| weight[i] >= NULL_COMPONENT_FRAC * wmax)
            .collect();
        nodes.sort_by(|&a, &b| weight[b].total_cmp(&weight[a]));
        Ok(Some(nodes))
    }

    fn finish(mut self) -> Result<SteadySolution, SteadyError> {
        if let Some(nodes) = self.null_space_nodes()? {
            return Err(SteadyError::Singular { nodes });
        }
        Ok(SteadySolution {
            residual_w: norm_inf(&self.r),
            method: if self.ptc_iters > 0 {
                "newton+ptc"
            } else {
                "newton"
            },
            iterations: self.newton_iters,
            ptc_iterations: self.ptc_iters,
            tolerance_w: self.tol,
            temperatures: self.t,
            residual_history_w: self.history,
        })
    }

    /// Classify a failure: singular Jacobian, node stuck at a bound, model error, or plain
    /// non-convergence (in that order).
    fn failure(&mut self) -> Result<SteadyError, SteadyError> {
        if let Some(nodes) = self.null_space_nodes()? {
            return Ok(SteadyError::Singular { nodes });
        }
        if let Some((i, which)) = self.pushing_node() {
            let bound_k = match which {
                BoundSide::Upper => self.hi[i],
                BoundSide::Lower => self.lo[i],
            };
            let beyond = match which {
                BoundSide::Upper => self.target[i] > bound_k,
                BoundSide::Lower => self.target[i] < bound_k,
            };
            return Ok(SteadyError::NoEquilibriumInRange {
                node: i,
                temperature_k: if beyond { self.target[i] } else { self.t[i] },
                bound_k,
                which,
            });
        }
        if let Some(e) = self.last_model_err.take() {
            return Ok(SteadyError::Model(e));
        }
        Ok(SteadyError::NotConverged {
            iterations: self.newton_iters + self.ptc_iters,
            residual_w: norm_inf(&self.r),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIGMA: f64 = 5.670_374_419e-8;
    const T_AMB: f64 = 293.15;

    /// Check a model's analytic Jacobian against central differences.
    fn check_jacobian<H: HeatBalance>(sys: &H, t: &[f64]) {
        let n = sys.dim();
        let mut jac = DMatrix::zeros(n, n);
        sys.jacobian(t, &mut jac).unwrap();
        let mut tp = t.to_vec();
        let mut rp = vec![0.0; n];
        let mut rm = vec![0.0; n];
        for j in 0..n {
            let h = 1e-4;
            tp[j] = t[j] + h;
            sys.residual(&tp, &mut rp).unwrap();
            tp[j] = t[j] - h;
            sys.residual(&tp, &mut rm).unwrap();
            tp[j] = t[j];
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                assert!(
                    (fd - jac[(i, j)]).abs() <= 1e-5 * (1.0 + fd.abs()),
                    "J[{i},{j}] analytic {} vs fd {fd}",
                    jac[(i, j)]
                );
            }
        }
    }

    /// Linear network: internal conductances `g` (symmetric), ambient conductances `ga`,
    /// constant sources `q`.
    struct Linear {
        g: DMatrix<f64>,
        ga: Vec<f64>,
        q: Vec<f64>,
        c: Vec<f64>,
    }

    impl HeatBalance for Linear {
        fn dim(&self) -> usize {
            self.q.len()
        }
        fn residual(&self, t: &[f64], out: &mut [f64]) -> Result<(), String> {
            for i in 0..t.len() {
                let mut s = self.q[i] + self.ga[i] * (T_AMB - t[i]);
                for j in 0..t.len() {
                    s += self.g[(i, j)] * (t[j] - t[i]);
                }
                out[i] = s;
            }
            Ok(())
        }
        fn jacobian(&self, t: &[f64], jac: &mut DMatrix<f64>) -> Result<(), String> {
            let n = t.len();
            for i in 0..n {
                let mut d = -self.ga[i];
                for j in 0..n {
                    if j != i {
                        jac[(i, j)] = self.g[(i, j)];
                        d -= self.g[(i, j)];
                    }
                }
                jac[(i, i)] = d;
            }
            Ok(())
        }
        fn capacities(&self) -> &[f64] {
            &self.c
        }
        fn bounds(&self, _i: usize) -> (f64, f64) {
            (200.0, 600.0)
        }
    }

    fn linear3(q: [f64; 3], ga: [f64; 3]) -> Linear {
        let g = DMatrix::from_row_slice(3, 3, &[0.0, 40.0, 10.0, 40.0, 0.0, 5.0, 10.0, 5.0, 0.0]);
        Linear {
            g,
            ga: ga.to_vec(),
            q: q.to_vec(),
            c: vec![5e3, 2e4, 4e4],
        }
    }

    #[test]
    fn linear_network_matches_direct_solve_in_one_newton_step() {
        let sys = linear3([250.0, 150.0, 0.0], [0.0, 2.0, 25.0]);
        check_jacobian(&sys, &[300.0, 310.0, 320.0]);
        let sol = solve_steady(&sys, &[T_AMB; 3], &SteadyOptions::default()).unwrap();
        // Direct solve: (−J) T = q + ga·Ta.
        let mut a = DMatrix::zeros(3, 3);
        sys.jacobian(&[0.0; 3], &mut a).unwrap();
        let a = -a;
        let b = DVector::from_iterator(3, (0..3).map(|i| sys.q[i] + sys.ga[i] * T_AMB));
        let x = a.lu().solve(&b).unwrap();
        // The test is only meaningful if no step limit was active.
        assert!(x.iter().all(|v| v - T_AMB < 50.0 && *v > T_AMB));
        for i in 0..3 {
            assert!((sol.temperatures[i] - x[i]).abs() < 1e-9, "node {i}");
        }
        assert_eq!(sol.iterations, 1);
        assert_eq!(sol.ptc_iterations, 0);
        assert_eq!(sol.method, "newton");
        assert!(sol.residual_w <= sol.tolerance_w);
        // Energy: total source = heat to ambient.
        let to_amb: f64 = (0..3).map(|i| sys.ga[i] * (x[i] - T_AMB)).sum();
        assert!((to_amb - 400.0).abs() < 1e-9);
    }

    #[test]
    fn linear_network_far_from_start_uses_step_limit_but_stays_newton() {
        // Rise ≈ 140 K: three 50 K-limited steps along the Newton direction, then exact.
        let sys = linear3([1500.0, 300.0, 0.0], [0.0, 2.0, 25.0]);
        let sol = solve_steady(&sys, &[T_AMB; 3], &SteadyOptions::default()).unwrap();
        let mut r = [0.0; 3];
        sys.residual(&sol.temperatures, &mut r).unwrap();
        assert!(norm_inf(&r) <= sol.tolerance_w);
        assert_eq!(sol.ptc_iterations, 0);
        assert!(sol.iterations >= 2 && sol.iterations <= 6, "{}", sol.iterations);
    }

    /// One node: viscous-type source falling with temperature, convection and radiation.
    struct RadNode {
        a: f64,
        b: f64,
        t_ref: f64,
        ha: f64,
        eps_a: f64,
    }

    impl RadNode {
        fn r(&self, t: f64) -> f64 {
            self.a * (-self.b * (t - self.t_ref)).exp()
                - self.ha * (t - T_AMB)
                - SIGMA * self.eps_a * (t.powi(4) - T_AMB.powi(4))
        }
        fn dr(&self, t: f64) -> f64 {
            -self.a * self.b * (-self.b * (t - self.t_ref)).exp()
                - self.ha
                - 4.0 * SIGMA * self.eps_a * t.powi(3)
        }
    }

    impl HeatBalance for RadNode {
        fn dim(&self) -> usize {
            1
        }
        fn residual(&self, t: &[f64], out: &mut [f64]) -> Result<(), String> {
            out[0] = self.r(t[0]);
            Ok(())
        }
        fn jacobian(&self, t: &[f64], jac: &mut DMatrix<f64>) -> Result<(), String> {
            jac[(0, 0)] = self.dr(t[0]);
            Ok(())
        }
        fn capacities(&self) -> &[f64] {
            &[8e3]
        }
        fn bounds(&self, _i: usize) -> (f64, f64) {
            (233.15, 473.15)
        }
    }

    fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
        let flo = f(lo);
        assert!(flo * f(hi) < 0.0, "no sign change");
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if (f(mid) > 0.0) == (flo > 0.0) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn radiation_convection_and_falling_source_match_bisection() {
        let sys = RadNode {
            a: 1500.0,
            b: 0.02,
            t_ref: 313.15,
            ha: 6.0,
            eps_a: 0.9 * 0.6,
        };
        check_jacobian(&sys, &[350.0]);
        let sol = solve_steady(&sys, &[T_AMB], &SteadyOptions::default()).unwrap();
        let tb = bisect(|t| sys.r(t), T_AMB, 473.15);
        assert!(
            (sol.temperatures[0] - tb).abs() < 1e-10,
            "{} vs {tb}",
            sol.temperatures[0]
        );
        assert_eq!(sol.ptc_iterations, 0);
    }

    #[test]
    fn pure_newton_converges_quadratically() {
        let sys = RadNode {
            a: 1500.0,
            b: 0.02,
            t_ref: 313.15,
            ha: 6.0,
            eps_a: 0.9 * 0.6,
        };
        let opts = SteadyOptions {
            abs_tol_w: 1e-12,
            rel_tol: 0.0,
            ..SteadyOptions::default()
        };
        let sol = solve_steady(&sys, &[T_AMB], &opts).unwrap();
        let h = &sol.residual_history_w;
        // All steps were full Newton steps (no damping, no PTC): residual strictly falling.
        assert_eq!(sol.ptc_iterations, 0);
        assert!(h.windows(2).all(|w| w[1] < w[0]), "{h:?}");
        // Order estimate p_k = ln(e_{k+1}/e_k) / ln(e_k/e_{k-1}) over the asymptotic range
        // (residuals well above round-off, ~1e-12 W here).
        let mut orders = Vec::new();
        for k in 1..h.len() - 1 {
            if h[k + 1] > 1e-9 && h[k] < 0.5 * h[k - 1] {
                orders.push((h[k + 1] / h[k]).ln() / (h[k] / h[k - 1]).ln());
            }
        }
        assert!(!orders.is_empty(), "{h:?}");
        let last = *orders.last().unwrap();
        assert!(last > 1.8 && last < 2.2, "orders {orders:?}, history {h:?}");
        // Quadratic-rate constant e_{k+1}/e_k² roughly constant in the last iterations.
        let n = h.len();
        let q1 = h[n - 2] / (h[n - 3] * h[n - 3]);
        let q2 = h[n - 3] / (h[n - 4] * h[n - 4]);
        if h[n - 2] > 1e-9 {
            assert!(q1 / q2 < 3.0 && q2 / q1 < 3.0, "{q1} {q2} {h:?}");
        }
    }

    /// One node: a source that GROWS with temperature, convection to ambient, and an optional
    /// thermostat cooler (tanh ramp). Without the cooler there is no equilibrium.
    struct GrowingSource {
        q0: f64,
        c: f64,
        g: f64,
        cooler_g: f64,
        t_open: f64,
        width: f64,
        t_coolant: f64,
    }

    impl GrowingSource {
        fn rescue() -> Self {
            Self {
                q0: 300.0,
                c: 0.02,
                g: 10.0,
                cooler_g: 100.0,
                t_open: 380.0,
                width: 3.0,
                t_coolant: 340.0,
            }
        }
        fn ramp(&self, t: f64) -> (f64, f64) {
            let th = ((t - self.t_open) / self.width).tanh();
            (0.5 * (1.0 + th), 0.5 * (1.0 - th * th) / self.width)
        }
        fn r(&self, t: f64) -> f64 {
            let (s, _) = self.ramp(t);
            self.q0 * (self.c * (t - T_AMB)).exp()
                - self.g * (t - T_AMB)
                - self.cooler_g * s * (t - self.t_coolant)
        }
        fn dr(&self, t: f64) -> f64 {
            let (s, ds) = self.ramp(t);
            self.q0 * self.c * (self.c * (t - T_AMB)).exp()
                - self.g
                - self.cooler_g * (ds * (t - self.t_coolant) + s)
        }
    }

    impl HeatBalance for GrowingSource {
        fn dim(&self) -> usize {
            1
        }
        fn residual(&self, t: &[f64], out: &mut [f64]) -> Result<(), String> {
            out[0] = self.r(t[0]);
            Ok(())
        }
        fn jacobian(&self, t: &[f64], jac: &mut DMatrix<f64>) -> Result<(), String> {
            jac[(0, 0)] = self.dr(t[0]);
            Ok(())
        }
        fn capacities(&self) -> &[f64] {
            &[1e4]
        }
        fn bounds(&self, _i: usize) -> (f64, f64) {
            (233.15, 423.15)
        }
    }

    #[test]
    fn ptc_rescues_newton_stuck_at_a_residual_minimum() {
        let sys = GrowingSource::rescue();
        check_jacobian(&sys, &[330.0]);
        check_jacobian(&sys, &[381.0]);
        // Plain (undamped, unclipped) Newton from ambient does not find the root: it wanders
        // around the positive local minimum of r(T) near T_amb + 25 K.
        let mut t = T_AMB;
        for _ in 0..200 {
            t -= sys.r(t) / sys.dr(t);
            if !t.is_finite() {
                break;
            }
        }
        assert!(
            sys.r(t).is_nan() || sys.r(t).abs() >= 1e-6,
            "plain Newton unexpectedly converged to {t}"
        );

        let sol = solve_steady(&sys, &[T_AMB], &SteadyOptions::default()).unwrap();
        assert_eq!(sol.method, "newton+ptc");
        assert!(sol.ptc_iterations > 0);
        assert!(sol.residual_w <= sol.tolerance_w);
        // The only root in range lies on the cooler ramp.
        let tb = bisect(|t| sys.r(t), 353.15, 423.15);
        assert!(
            (sol.temperatures[0] - tb).abs() < 1e-9,
            "{} vs {tb}",
            sol.temperatures[0]
        );
        assert!((sol.temperatures[0] - sys.t_open).abs() < 3.0 * sys.width);
    }

    /// Two nodes: housing (0) to ambient, oil (1) to housing, oil source growing with T.
    struct Runaway {
        q0: f64,
    }

    impl HeatBalance for Runaway {
        fn dim(&self) -> usize {
            2
        }
        fn residual(&self, t: &[f64], out: &mut [f64]) -> Result<(), String> {
            let q = self.q0 * (0.02 * (t[1] - T_AMB)).exp();
            out[0] = 20.0 * (T_AMB - t[0]) + 50.0 * (t[1] - t[0]);
            out[1] = q + 50.0 * (t[0] - t[1]);
            Ok(())
        }
        fn jacobian(&self, t: &[f64], jac: &mut DMatrix<f64>) -> Result<(), String> {
            let dq = 0.02 * self.q0 * (0.02 * (t[1] - T_AMB)).exp();
            jac[(0, 0)] = -70.0;
            jac[(0, 1)] = 50.0;
            jac[(1, 0)] = 50.0;
            jac[(1, 1)] = dq - 50.0;
            Ok(())
        }
        fn capacities(&self) -> &[f64] {
            &[3e4, 1e4]
        }
        fn bounds(&self, i: usize) -> (f64, f64) {
            if i == 1 {
                (233.15, 423.15)
            } else {
                (200.0, 700.0)
            }
        }
    }

    #[test]
    fn runaway_losses_give_no_equilibrium_naming_the_node() {
        // Series conductance oil→ambient G = 1/(1/20 + 1/50) ≈ 14.3 W/K; q0·e^{cΔT} > GΔT for
        // all ΔT iff q0 > G/(c·e) ≈ 263 W.
        let sys = Runaway { q0: 400.0 };
        check_jacobian(&sys, &[320.0, 340.0]);
        let err = solve_steady(&sys, &[T_AMB; 2], &SteadyOptions::default()).unwrap_err();
        match err {
            SteadyError::NoEquilibriumInRange {
                node,
                temperature_k,
                bound_k,
                which,
            } => {
                assert_eq!(node, 1);
                assert_eq!(which, BoundSide::Upper);
                assert_eq!(bound_k, 423.15);
                assert!(temperature_k > bound_k);
            }
            e => panic!("unexpected {e:?}"),
        }
        // Just below the critical source the same model has an equilibrium.
        let sol = solve_steady(&Runaway { q0: 200.0 }, &[T_AMB; 2], &SteadyOptions::default()).unwrap();
        assert!(sol.temperatures[1] < 423.15 && sol.temperatures[1] > sol.temperatures[0]);
    }

    #[test]
    fn heat_sink_below_lower_bound_reports_lower_side() {
        // Constant extraction of 1000 W against 5 W/K to ambient: equilibrium 200 K below
        // ambient, below the 250 K limit.
        struct Sink;
        impl HeatBalance for Sink {
            fn dim(&self) -> usize {
                1
            }
            fn residual(&self, t: &[f64], out: &mut [f64]) -> Result<(), String> {
                out[0] = -1000.0 + 5.0 * (T_AMB - t[0]);
                Ok(())
            }
            fn jacobian(&self, _t: &[f64], jac: &mut DMatrix<f64>) -> Result<(), String> {
                jac[(0, 0)] = -5.0;
                Ok(())
            }
            fn capacities(&self) -> &[f64] {
                &[1e3]
            }
            fn bounds(&self, _i: usize) -> (f64, f64) {
                (250.0, 500.0)
            }
        }
        let err = solve_steady(&Sink, &[T_AMB], &SteadyOptions::default()).unwrap_err();
        assert!(
            matches!(
                err,
                SteadyError::NoEquilibriumInRange { node: 0, which: BoundSide::Lower, bound_k, .. }
                    if bound_k == 250.0
            ),
            "{err:?}"
        );
        assert!(err.to_string().contains("lower bound"));
    }

    #[test]
    fn isolated_node_is_singular_and_named() {
        // Node 2 has no conductance at all (zero row and column).
        let mut sys = linear3([100.0, 50.0, 10.0], [0.0, 2.0, 25.0]);
        for k in 0..3 {
            sys.g[(2, k)] = 0.0;
            sys.g[(k, 2)] = 0.0;
        }
        sys.ga[2] = 0.0;
        sys.ga[1] = 25.0;
        let err = solve_steady(&sys, &[T_AMB; 3], &SteadyOptions::default()).unwrap_err();
        assert_eq!(err, SteadyError::Singular { nodes: vec![2] });
        // Without a source the residual is zero at any temperature of node 2: still singular
        // (the equilibrium is not unique).
        sys.q[2] = 0.0;
        let err = solve_steady(&sys, &[T_AMB; 3], &SteadyOptions::default()).unwrap_err();
        assert_eq!(err, SteadyError::Singular { nodes: vec![2] });
    }

    #[test]
    fn floating_group_is_singular_and_names_both_nodes() {
        // Nodes 1 and 2 are linked to each other only.
        let mut sys = linear3([100.0, 50.0, 10.0], [25.0, 0.0, 0.0]);
        sys.g[(0, 1)] = 0.0;
        sys.g[(1, 0)] = 0.0;
        sys.g[(0, 2)] = 0.0;
        sys.g[(2, 0)] = 0.0;
        let err = solve_steady(&sys, &[T_AMB; 3], &SteadyOptions::default()).unwrap_err();
        match err {
            SteadyError::Singular { mut nodes } => {
                nodes.sort_unstable();
                assert_eq!(nodes, vec![1, 2]);
            }
            e => panic!("unexpected {e:?}"),
        }
    }

    /// Gearbox-like network: oil (0), gear body (1), housing (2), ambient boundary.
    /// Churning falls with oil temperature (viscosity), sliding grows slowly with it, housing
    /// has convection + radiation, oil has a thermostat cooler.
    struct Gearbox {
        churn_w: f64,
        slide_w: f64,
    }

    impl Gearbox {
        const G_OG: f64 = 100.0;
        const G_OH: f64 = 30.0;
        const G_GH: f64 = 5.0;
        const G_HA: f64 = 8.0;
        const EPS_A: f64 = 0.9;
        const COOLER: f64 = 150.0;
        const T_OPEN: f64 = 363.15;
        const WIDTH: f64 = 4.0;
        const T_COOL: f64 = 343.15;

        fn losses(&self, t_oil: f64) -> (f64, f64, f64, f64) {
            let e = (-0.02 * (t_oil - 313.15)).exp();
            let qc = self.churn_w * e;
            let dqc = -0.02 * qc;
            let qs = self.slide_w * (1.0 + 1e-3 * (t_oil - 313.15));
            let dqs = self.slide_w * 1e-3;
            (qc, dqc, qs, dqs)
        }
        fn ramp(t: f64) -> (f64, f64) {
            let th = ((t - Self::T_OPEN) / Self::WIDTH).tanh();
            (0.5 * (1.0 + th), 0.5 * (1.0 - th * th) / Self::WIDTH)
        }
    }

    impl HeatBalance for Gearbox {
        fn dim(&self) -> usize {
            3
        }
        fn residual(&self, t: &[f64], out: &mut [f64]) -> Result<(), String> {
            if t[0] > 430.0 {
                return Err(format!("oil at {} K above its limit", t[0]));
            }
            let (qc, _, qs, _) = self.losses(t[0]);
            let (s, _) = Self::ramp(t[0]);
            out[0] = qc + Self::G_OG * (t[1] - t[0]) + Self::G_OH * (t[2] - t[0])
                - Self::COOLER * s * (t[0] - Self::T_COOL);
            out[1] = qs + Self::G_OG * (t[0] - t[1]) + Self::G_GH * (t[2] - t[1]);
            out[2] = Self::G_OH * (t[0] - t[2]) + Self::G_GH * (t[1] - t[2]) + Self::G_HA * (T_AMB - t[2])
                - SIGMA * Self::EPS_A * (t[2].powi(4) - T_AMB.powi(4));
            Ok(())
        }
        fn jacobian(&self, t: &[f64], jac: &mut DMatrix<f64>) -> Result<(), String> {
            let (_, dqc, _, dqs) = self.losses(t[0]);
            let (s, ds) = Self::ramp(t[0]);
            jac[(0, 0)] = dqc - Self::G_OG - Self::G_OH - Self::COOLER * (ds * (t[0] - Self::T_COOL) + s);
            jac[(0, 1)] = Self::G_OG;
            jac[(0, 2)] = Self::G_OH;
            jac[(1, 0)] = Self::G_OG + dqs;
            jac[(1, 1)] = -Self::G_OG - Self::G_GH;
            jac[(1, 2)] = Self::G_GH;
            jac[(2, 0)] = Self::G_OH;
            jac[(2, 1)] = Self::G_GH;
            jac[(2, 2)] = -Self::G_OH - Self::G_GH - Self::G_HA - 4.0 * SIGMA * Self::EPS_A * t[2].powi(3);
            Ok(())
        }
        fn capacities(&self) -> &[f64] {
            &[8e3, 1.5e4, 6e4]
        }
        fn bounds(&self, i: usize) -> (f64, f64) {
            if i == 0 {
                (233.15, 423.15)
            } else {
                (200.0, 600.0)
            }
        }
    }

    #[test]
    fn grid_of_source_scalings_all_converge_from_ambient() {
        check_jacobian(
            &Gearbox {
                churn_w: 600.0,
                slide_w: 800.0,
            },
            &[360.0, 365.0, 330.0],
        );
        let opts = SteadyOptions::default();
        let mut ptc_used = 0;
        for i in 0..10 {
            let speed = 0.1 + 2.9 * i as f64 / 9.0;
            let mut prev_oil = 0.0;
            for j in 0..10 {
                let torque = 0.1 + 2.9 * j as f64 / 9.0;
                let sys = Gearbox {
                    churn_w: 600.0 * speed,
                    slide_w: 800.0 * torque * speed.sqrt(),
                };
                let sol = solve_steady(&sys, &[T_AMB; 3], &opts)
                    .unwrap_or_else(|e| panic!("speed {speed} torque {torque}: {e}"));
                let mut r = [0.0; 3];
                sys.residual(&sol.temperatures, &mut r).unwrap();
                assert!(norm_inf(&r) <= sol.tolerance_w.max(1e-8));
                // Energy balance: all losses leave through housing and cooler.
                let t = &sol.temperatures;
                let (qc, _, qs, _) = sys.losses(t[0]);
                let out = Gearbox::G_HA * (t[2] - T_AMB)
                    + SIGMA * Gearbox::EPS_A * (t[2].powi(4) - T_AMB.powi(4))
                    + Gearbox::COOLER * Gearbox::ramp(t[0]).0 * (t[0] - Gearbox::T_COOL);
                assert!((qc + qs - out).abs() < 1e-6 * (qc + qs));
                // More torque → hotter oil.
                assert!(t[0] > prev_oil, "speed {speed} torque {torque}");
                prev_oil = t[0];
                if sol.ptc_iterations > 0 {
                    ptc_used += 1;
                }
            }
        }
        // Most points are plain Newton.
        assert!(ptc_used < 50, "{ptc_used} of 100 needed PTC");
    }

    #[test]
    fn agrees_with_long_transient_run() {
        // physics.md §10: the equilibrium must agree with a long transient to 1e-6 K.
        // Classical RK4 on C dT/dt = r(T) from ambient (time constants 60–2000 s, dt = 2 s).
        let sys = Gearbox {
            churn_w: 900.0,
            slide_w: 1500.0,
        };
        let sol = solve_steady(&sys, &[T_AMB; 3], &SteadyOptions::default()).unwrap();
        let c = sys.capacities().to_vec();
        let f = |t: &[f64; 3]| {
            let mut r = [0.0; 3];
            sys.residual(t, &mut r).unwrap();
            [r[0] / c[0], r[1] / c[1], r[2] / c[2]]
        };
        let dt = 2.0;
        let mut t = [T_AMB; 3];
        let add = |a: &[f64; 3], k: &[f64; 3], h: f64| [a[0] + h * k[0], a[1] + h * k[1], a[2] + h * k[2]];
        for _ in 0..(200_000.0 / dt) as usize {
            let k1 = f(&t);
            let k2 = f(&add(&t, &k1, 0.5 * dt));
            let k3 = f(&add(&t, &k2, 0.5 * dt));
            let k4 = f(&add(&t, &k3, dt));
            for i in 0..3 {
                t[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        for (i, (tt, ts)) in t.iter().zip(&sol.temperatures).enumerate() {
            assert!((tt - ts).abs() < 1e-6, "node {i}: transient {tt} vs steady {ts}");
        }
    }

    #[test]
    fn model_error_and_invalid_input_are_reported() {
        struct Broken;
        impl HeatBalance for Broken {
            fn dim(&self) -> usize {
                1
            }
            fn residual(&self, _t: &[f64], _out: &mut [f64]) -> Result<(), String> {
                Err("oil above limit".to_string())
            }
            fn jacobian(&self, _t: &[f64], _jac: &mut DMatrix<f64>) -> Result<(), String> {
                Err("oil above limit".to_string())
            }
            fn capacities(&self) -> &[f64] {
                &[1.0]
            }
            fn bounds(&self, _i: usize) -> (f64, f64) {
                (0.0, 1000.0)
            }
        }
        let err = solve_steady(&Broken, &[300.0], &SteadyOptions::default()).unwrap_err();
        assert_eq!(err, SteadyError::Model("oil above limit".to_string()));

        let sys = linear3([1.0, 1.0, 1.0], [1.0, 1.0, 1.0]);
        let err = solve_steady(&sys, &[T_AMB; 2], &SteadyOptions::default()).unwrap_err();
        assert!(matches!(err, SteadyError::InvalidInput(_)));
        let bad = SteadyOptions {
            armijo: 1.5,
            ..SteadyOptions::default()
        };
        let err = solve_steady(&sys, &[T_AMB; 3], &bad).unwrap_err();
        assert!(matches!(err, SteadyError::InvalidInput(_)));
    }

    #[test]
    fn start_outside_bounds_is_clamped_and_converges() {
        let sys = linear3([250.0, 150.0, 0.0], [0.0, 2.0, 25.0]);
        let sol = solve_steady(&sys, &[100.0, 900.0, T_AMB], &SteadyOptions::default()).unwrap();
        let mut r = [0.0; 3];
        sys.residual(&sol.temperatures, &mut r).unwrap();
        assert!(norm_inf(&r) <= sol.tolerance_w);
    }

    #[test]
    fn already_converged_start_takes_no_iteration() {
        let sys = linear3([250.0, 150.0, 0.0], [0.0, 2.0, 25.0]);
        let sol = solve_steady(&sys, &[T_AMB; 3], &SteadyOptions::default()).unwrap();
        let again = solve_steady(&sys, &sol.temperatures, &SteadyOptions::default()).unwrap();
        assert_eq!(again.iterations, 0);
        assert_eq!(again.temperatures, sol.temperatures);
    }
}
