//! Levenberg–Marquardt with box bounds: minimise ½‖r(θ)‖² over lo ≤ θ ≤ hi.
//!
//! Step: (JᵀJ + μ·D)Δ = −Jᵀr with D = diag(JᵀJ) (Marquardt's scaling, Nocedal & Wright,
//! Numerical Optimization, 2nd ed., §10.3), the trial point projected onto the box. The damping
//! follows Nielsen's rule (Madsen, Nielsen & Tingleff, Methods for Non-Linear Least Squares
//! Problems, 2004, §3.2): on a gain ratio ρ > 0 the step is taken and μ ← μ·max(1/3, 1 − (2ρ − 1)³),
//! ν ← 2; else μ ← μ·ν, ν ← 2ν. Stops when the step is below `x_tol`·(‖θ‖ + x_tol), the
//! actual and the predicted relative decrease of the cost below `f_tol` (Moré's MINPACK test),
//! the scaled gradient below `g_tol`, the cost fell by less than `stall_tol` of itself over the
//! last `stall_window` accepted steps (a cost computed by an adaptive integrator is resolved only to
//! about its tolerance: below that, steps are accepted and rejected on the integrator's noise),
//! or after `max_iterations` evaluations with the Jacobian.
//!
//! Bounds: a parameter at a bound whose gradient points out of the box (the descent direction
//! −Jᵀr would leave it) is held there for the step — the active set of a projected method
//! (Nocedal & Wright §16.7, gradient projection; Kanzow, Yamashita & Fukushima, J. Comput.
//! Appl. Math. 172 (2004) 375–397, projected Levenberg–Marquardt). Without it the step is solved
//! as if that parameter could move and then clamped: the other components are those of a step
//! that was not taken, and the gain ratio of the clamped step collapses.

use nalgebra::{DMatrix, DVector};

/// Options of the fit.
#[derive(Debug, Clone)]
pub struct LmOptions {
    /// Most Jacobian evaluations.
    pub max_iterations: usize,
    /// Step tolerance (relative).
    pub x_tol: f64,
    /// Cost decrease tolerance (relative).
    pub f_tol: f64,
    /// Gradient tolerance: max |Jᵀr|_k / (‖J_k‖·‖r‖).
    pub g_tol: f64,
    /// Least relative decrease of the cost over `stall_window` accepted steps.
    pub stall_tol: f64,
    /// Accepted steps over which `stall_tol` is measured.
    pub stall_window: usize,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 50,
            x_tol: 1e-8,
            f_tol: 1e-10,
            g_tol: 1e-8,
            stall_tol: 1e-4,
            stall_window: 5,
        }
    }
}

/// Residuals and their Jacobian at a point.
pub struct Evaluation {
    /// r(θ).
    pub r: DVector<f64>,
    /// ∂r/∂θ (m × P).
    pub j: DMatrix<f64>,
}

/// Why the fit stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The step became small.
    Step,
    /// The cost stopped decreasing.
    Cost,
    /// The gradient vanished.
    Gradient,
    /// The iteration budget ran out.
    Budget,
    /// The cost fell by less than `stall_tol` of itself over the last `stall_window` accepted
    /// steps.
    Stall,
    /// Nothing to fit.
    NoParameter,
    /// The damped normal equations had no solution: a non-finite residual or Jacobian entry,
    /// or no damping made them positive definite.
    Singular,
}

/// The fit's end point.
pub struct LmResult {
    /// Fitted coordinates.
    pub theta: Vec<f64>,
    /// The evaluation there.
    pub at: Evaluation,
    /// Jacobian evaluations.
    pub evaluations: usize,
    /// Accepted steps.
    pub iterations: usize,
    /// Why it stopped.
    pub stop: Stop,
}

/// Minimise ½‖r‖². `eval(θ)` gives residuals and Jacobian; `free[k]` false keeps θ_k fixed.
/// `at0` is the evaluation at `theta0`.
pub fn minimise<E>(
    mut eval: impl FnMut(&[f64]) -> Result<Evaluation, E>,
    theta0: &[f64],
    at0: Evaluation,
    bounds: &[(f64, f64)],
    free: &[bool],
    o: &LmOptions,
) -> Result<LmResult, E> {
    let p = theta0.len();
    let mut theta = theta0.to_vec();
    let mut at = at0;
    let mut evaluations = 1;
    let mut iterations = 0;
    if !free.iter().any(|&f| f) {
        return Ok(LmResult {
            theta,
            at,
            evaluations,
            iterations,
            stop: Stop::NoParameter,
        });
    }
    let cost = |e: &Evaluation| 0.5 * e.r.norm_squared();
    let mut mu: Option<f64> = None;
    let mut nu = 2.0;
    // The cost at every accepted point.
    let mut history = vec![cost(&at)];
    // After a rejected step: the longest next step, in the norm ‖D^½Δ‖.
    let mut limit: Option<f64> = None;
    loop {
        let moving = held_at_bounds(&at, &theta, bounds, free);
        let jf = masked(&at.j, &moving);
        let a = jf.transpose() * &jf;
        let g = jf.transpose() * &at.r;
        let m = *mu.get_or_insert(1e-3);
        if !a.iter().chain(g.iter()).all(|v| v.is_finite()) || m > 1e200 {
            return Ok(LmResult {
                theta,
                at,
                evaluations,
                iterations,
                stop: Stop::Singular,
            });
        }
        if gradient_small(&jf, &at.r, &g, o.g_tol) {
            return Ok(LmResult {
                theta,
                at,
                evaluations,
                iterations,
                stop: Stop::Gradient,
            });
        }
        let diag: Vec<f64> = (0..p)
            .map(|k| if moving[k] { a[(k, k)].max(1e-300) } else { 1.0 })
            .collect();
        let mut lhs = a.clone();
        for k in 0..p {
            lhs[(k, k)] += m * diag[k];
        }
        let Some(step) = lhs.clone().cholesky().map(|c| c.solve(&(-&g))) else {
            mu = Some(m * nu);
            nu *= 2.0;
            continue;
        };
        let trial: Vec<f64> = (0..p)
            .map(|k| {
                if moving[k] {
                    (theta[k] + step[k]).clamp(bounds[k].0, bounds[k].1)
                } else {
                    theta[k]
                }
            })
            .collect();
        let dx = DVector::from_fn(p, |k, _| trial[k] - theta[k]);
        if limit.is_some_and(|l| scaled_norm(&dx, &diag) > l) {
            mu = Some(m * nu);
            nu *= 2.0;
            continue;
        }
        let norm_theta = DVector::from_column_slice(&theta).norm();
        if dx.norm() <= o.x_tol * (norm_theta + o.x_tol) {
            return Ok(LmResult {
                theta,
                at,
                evaluations,
                iterations,
                stop: Stop::Step,
            });
        }
        if evaluations >= o.max_iterations {
            return Ok(LmResult {
                theta,
                at,
                evaluations,
                iterations,
                stop: Stop::Budget,
            });
        }
        let next = eval(&trial)?;
        evaluations += 1;
        limit = None;
        // Gain ratio: actual over predicted decrease of the linear model.
        let predicted = -(g.dot(&dx)) - 0.5 * (&a * &dx).dot(&dx);
        let (c0, c1) = (cost(&at), cost(&next));
        let rho = if predicted > 0.0 {
            (c0 - c1) / predicted
        } else {
            -1.0
        };
        if rho > 0.0 && c1.is_finite() {
            theta = trial;
            at = next;
            iterations += 1;
            mu = Some(m * (1.0_f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3)));
            nu = 2.0;
            history.push(c1);
            if stalled(&history, o) {
                return Ok(LmResult {
                    theta,
                    at,
                    evaluations,
                    iterations,
                    stop: Stop::Stall,
                });
            }
            // Both the actual and the predicted decrease negligible (MINPACK's ftol test): a
            // heavily damped step that gains little is not convergence.
            if (c0 - c1) <= o.f_tol * c0 && predicted <= o.f_tol * c0 && rho <= 2.0 {
                return Ok(LmResult {
                    theta,
                    at,
                    evaluations,
                    iterations,
                    stop: Stop::Cost,
                });
            }
        } else {
            mu = Some(m * nu);
            nu *= 2.0;
            limit = Some(shrink(g.dot(&dx), c0, c1) * scaled_norm(&dx, &diag));
        }
    }
}

/// ‖D^½Δ‖.
fn scaled_norm(dx: &DVector<f64>, diag: &[f64]) -> f64 {
    dx.iter().zip(diag).map(|(d, w)| d * d * w).sum::<f64>().sqrt()
}

/// The factor by which a rejected step's length is cut before the next trial: the minimiser of
/// the parabola through the cost at the start (c0, slope `slope` = gᵀΔ < 0) and at the rejected
/// point (c1), within [0.1, 0.5]; 0.1 when c1 is not finite. MINPACK's `lmder` cuts its trust
/// radius on a failed step by this factor (Moré, Garbow & Hillstrom, User Guide for MINPACK-1,
/// ANL-80-74, 1980). Raising μ alone (μ ← μ·ν) does not shorten a step taken with a damping far
/// below the smallest eigenvalue of the scaled JᵀJ: the same point would be evaluated again.
fn shrink(slope: f64, c0: f64, c1: f64) -> f64 {
    if !c1.is_finite() || slope >= 0.0 {
        return 0.1;
    }
    let curvature = c1 - c0 - slope;
    if curvature <= 0.0 {
        return 0.5;
    }
    (-slope / (2.0 * curvature)).clamp(0.1, 0.5)
}

/// The free parameters that move in this step: not those at a bound whose gradient component
/// points out of the box.
fn held_at_bounds(at: &Evaluation, theta: &[f64], bounds: &[(f64, f64)], free: &[bool]) -> Vec<bool> {
    let g = masked(&at.j, free).transpose() * &at.r;
    (0..theta.len())
        .map(|k| {
            let (lo, hi) = bounds[k];
            let out = (theta[k] <= lo && g[k] > 0.0) || (theta[k] >= hi && g[k] < 0.0);
            free[k] && !out
        })
        .collect()
}

/// The cost fell by less than `stall_tol` of itself over the last `stall_window` accepted
/// steps.
fn stalled(history: &[f64], o: &LmOptions) -> bool {
    let n = history.len();
    if o.stall_window == 0 || n <= o.stall_window {
        return false;
    }
    let (before, now) = (history[n - 1 - o.stall_window], history[n - 1]);
    before - now <= o.stall_tol * before
}

/// J with the fixed parameters' columns zeroed.
fn masked(j: &DMatrix<f64>, free: &[bool]) -> DMatrix<f64> {
    let mut out = j.clone();
    for (k, &f) in free.iter().enumerate() {
        if !f {
            out.column_mut(k).fill(0.0);
        }
    }
    out
}

fn gradient_small(j: &DMatrix<f64>, r: &DVector<f64>, g: &DVector<f64>, tol: f64) -> bool {
    let rn = r.norm();
    if rn == 0.0 {
        return true;
    }
    (0..j.ncols()).all(|k| {
        let cn = j.column(k).norm();
        cn == 0.0 || g[k].abs() / (cn * rn) <= tol
    })
}

/// The warning a fit's stop deserves: a budget run out before converging, or a cost that stalled
/// below what the integration's tolerance resolves (`None` for a converged stop).
pub(crate) fn stop_warning(res: &LmResult) -> Option<String> {
    match res.stop {
        Stop::Budget => Some(format!(
            "the fit stopped after {} evaluations (max_iterations) before converging",
            res.evaluations
        )),
        Stop::Stall => Some(format!(
            "the fit stopped after {} evaluations: the cost fell by less than 1e-4 of itself over the \
             last 5 accepted steps, below what the integration's tolerance resolves",
            res.evaluations
        )),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exponential decay y = a·exp(−b·t): recovers (a, b) from exact data, and respects bounds.
    #[test]
    fn fits_exponential_decay() {
        let t: Vec<f64> = (0..20).map(|k| k as f64 * 0.25).collect();
        let y: Vec<f64> = t.iter().map(|x| 3.0 * (-0.7 * x).exp()).collect();
        let eval = |th: &[f64]| -> Result<Evaluation, ()> {
            let r = DVector::from_fn(t.len(), |i, _| th[0] * (-th[1] * t[i]).exp() - y[i]);
            let j = DMatrix::from_fn(t.len(), 2, |i, c| {
                let e = (-th[1] * t[i]).exp();
                if c == 0 {
                    e
                } else {
                    -th[0] * t[i] * e
                }
            });
            Ok(Evaluation { r, j })
        };
        let fit = |th: &[f64], b: &[(f64, f64)], free: &[bool]| {
            minimise(eval, th, eval(th).unwrap(), b, free, &LmOptions::default()).unwrap()
        };
        let res = fit(&[1.0, 0.1], &[(0.0, 10.0), (0.0, 5.0)], &[true, true]);
        assert!(
            (res.theta[0] - 3.0).abs() < 1e-7 && (res.theta[1] - 0.7).abs() < 1e-7,
            "{:?}",
            res.theta
        );
        let res = fit(&[1.0, 0.1], &[(0.0, 2.0), (0.0, 5.0)], &[true, true]);
        assert!((res.theta[0] - 2.0).abs() < 1e-12, "{:?}", res.theta);
        let res = fit(&[1.0, 0.7], &[(0.0, 10.0), (0.0, 5.0)], &[true, false]);
        assert!((res.theta[0] - 3.0).abs() < 1e-7 && res.theta[1] == 0.7);
    }

    /// A parameter at its bound with the gradient pointing out of the box is held there: the
    /// other, coupled to it, reaches the bounded optimum at once (r = (10(a − b), a − 4), a ≤ 1:
    /// the optimum a = b = 1), instead of steps solved as if a could move and then clamped.
    #[test]
    fn a_parameter_held_at_its_bound_lets_the_others_move() {
        let eval = |th: &[f64]| -> Result<Evaluation, ()> {
            let r = DVector::from_vec(vec![10.0 * (th[0] - th[1]), th[0] - 4.0]);
            let j = DMatrix::from_row_slice(2, 2, &[10.0, -10.0, 1.0, 0.0]);
            Ok(Evaluation { r, j })
        };
        let b = [(-10.0, 1.0), (-10.0, 10.0)];
        let res = minimise(
            eval,
            &[1.0, -3.0],
            eval(&[1.0, -3.0]).unwrap(),
            &b,
            &[true, true],
            &LmOptions::default(),
        )
        .unwrap();
        println!(
            "{:?} in {} evaluations, stop {:?}",
            res.theta, res.evaluations, res.stop
        );
        assert!(
            (res.theta[0] - 1.0).abs() < 1e-12 && (res.theta[1] - 1.0).abs() < 1e-6,
            "{:?}",
            res.theta
        );
        assert!(res.evaluations <= 8, "{} evaluations", res.evaluations);
    }

    /// A cost resolved only to about 10⁻³ (noise of an adaptive integrator) stops on the stall
    /// test, not on the budget.
    #[test]
    fn a_noisy_cost_stops_on_the_stall_test() {
        let eval = |th: &[f64]| -> Result<Evaluation, ()> {
            let noise = 1e-3 * (1e4 * th[0]).sin();
            let r = DVector::from_vec(vec![th[0] - 2.0 + noise, 0.5 * (th[0] - 2.0) + 1.0]);
            let j = DMatrix::from_vec(2, 1, vec![1.0, 0.5]);
            Ok(Evaluation { r, j })
        };
        let o = LmOptions {
            max_iterations: 200,
            ..LmOptions::default()
        };
        let res = minimise(eval, &[0.0], eval(&[0.0]).unwrap(), &[(-10.0, 10.0)], &[true], &o).unwrap();
        println!(
            "{:?} in {} evaluations, stop {:?}",
            res.theta, res.evaluations, res.stop
        );
        assert!(
            res.stop != Stop::Budget,
            "{:?} after {}",
            res.stop,
            res.evaluations
        );
        assert!((res.theta[0] - 1.6).abs() < 0.01, "{:?}", res.theta);
    }

    /// A Jacobian with a NaN entry stops the fit as singular instead of raising the damping for
    /// ever (the Cholesky factorisation of a matrix with NaN never succeeds).
    #[test]
    fn nan_jacobian_stops_as_singular() {
        let eval = |th: &[f64]| -> Result<Evaluation, ()> {
            let r = DVector::from_vec(vec![th[0] - 1.0, th[0] + 1.0]);
            let j = DMatrix::from_vec(2, 1, vec![1.0, f64::NAN]);
            Ok(Evaluation { r, j })
        };
        let res = minimise(
            eval,
            &[0.5],
            eval(&[0.5]).unwrap(),
            &[(-10.0, 10.0)],
            &[true],
            &LmOptions::default(),
        )
        .unwrap();
        assert_eq!(res.stop, Stop::Singular);
        assert_eq!(res.evaluations, 1);
    }

    /// A step rejected under a damping far below the scaled JᵀJ's eigenvalues (here: the first
    /// Gauss–Newton step of r = 10·tanh θ from θ = 3, 100 long) is not tried again nearly
    /// unchanged: every trial after a rejection is at most half as far from the current point as
    /// the rejected one, and the fit reaches θ = 0.
    #[test]
    fn a_rejected_step_is_shortened_before_the_next_evaluation() {
        let mut trials: Vec<f64> = Vec::new();
        let eval = |th: &[f64]| -> Result<Evaluation, ()> {
            let t = th[0].tanh();
            Ok(Evaluation {
                r: DVector::from_vec(vec![10.0 * t]),
                j: DMatrix::from_vec(1, 1, vec![10.0 * (1.0 - t * t)]),
            })
        };
        let at0 = eval(&[3.0]).unwrap();
        let res = minimise(
            |th: &[f64]| {
                trials.push(th[0]);
                eval(th)
            },
            &[3.0],
            at0,
            &[(-200.0, 200.0)],
            &[true],
            &LmOptions::default(),
        )
        .unwrap();
        println!("{trials:?}: {:?}, stop {:?}", res.theta, res.stop);
        assert!(res.theta[0].abs() < 1e-6, "{:?}", res.theta);
        // Rejected trials (cost above the current point's) and the one after each.
        let mut current = 3.0_f64;
        for w in trials.windows(2) {
            let (a, b) = (w[0], w[1]);
            if a.tanh().abs() >= current.tanh().abs() {
                assert!(
                    (b - current).abs() <= 0.5 * (a - current).abs() + 1e-12,
                    "{trials:?}"
                );
            } else {
                current = a;
            }
        }
        assert!(res.evaluations <= 20, "{} evaluations", res.evaluations);
    }
}
