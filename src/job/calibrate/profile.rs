//! Profile likelihood of a fitted parameter: the parameter held at each point of a grid, the
//! others refitted, and the rise of the fit's objective D(p) = S(p) − S_min (Venzon & Moolgavkar,
//! Applied Statistics 37, 1988; Seber & Wild, Nonlinear Regression, 1989, §5.9). The objective
//! is that of the MAP fit: the data rows scaled by each channel's noise (the long-run standard
//! deviation σ_a/(1 − φ) of its AR(1) errors, or σ with independent errors; the prewhitened rows
//! with `ar1-gls`) plus the prior rows, so D is about χ²₁ near the optimum; the 95 % interval is
//! where D ≤ t(0.975, ν)² (F(1, ν), the linearised interval's quantile squared).

use super::lm::{self, Evaluation, LmOptions, LmResult};
use super::params::{canonical, Parameter};
use super::residuals::{Ar1, Layout};
use super::{prior, stats};
use crate::job::JobError;
use crate::model::overrides::KeyPath;
use crate::report::calibration::{Profile, ProfilePoint};

/// Grid of a profile: the fitted value ± this many standard errors…
pub const SPAN_SE: f64 = 3.0;
/// …in this many steps either side.
pub const STEPS: usize = 6;
/// Most evaluations of one profile point's refit.
pub const POINT_ITERATIONS: usize = 25;

/// The index of every `--profile` key among the fitted parameters (invalid input naming the key
/// when it is not fitted).
pub fn resolve(keys: &[String], params: &[Parameter], doc: &toml::Table) -> Result<Vec<usize>, JobError> {
    let canon: Vec<KeyPath> = params.iter().map(|p| canonical(&p.path, doc)).collect();
    let mut out = Vec::with_capacity(keys.len());
    for k in keys {
        let bad = |why: String| {
            JobError::option(
                "profile",
                k,
                "the key path of a fitted parameter",
                format!("profile = {k}: {why}"),
            )
        };
        let path: KeyPath = k.trim().parse().map_err(|e| bad(format!("bad key path: {e}")))?;
        let c = canonical(&path, doc);
        let i = canon
            .iter()
            .position(|x| *x == c)
            .ok_or_else(|| bad("not a fitted parameter (add it to fit)".into()))?;
        if !out.contains(&i) {
            out.push(i);
        }
    }
    Ok(out)
}

/// The fit's objective for the profiles.
pub struct Objective<'a> {
    /// The unweighted residuals and Jacobian of the fitted rows at θ (one segment, or every
    /// segment of several traces stacked).
    pub eval: &'a dyn Fn(&[f64]) -> Result<Evaluation, JobError>,
    /// The fitted parameters.
    pub params: &'a [Parameter],
    /// Their priors.
    pub priors: &'a prior::Priors,
    /// The error of a refit stopped on a singular point (exit 2 naming the trace).
    pub fail: &'a dyn Fn(&LmResult) -> Result<(), JobError>,
    /// The channels' residual processes.
    pub noise: &'a [Ar1],
    /// Prewhitened rows (`ar1-gls`), else rows scaled by the long-run standard deviation.
    pub whitened: bool,
    /// The fitted rows' layout.
    pub layout: &'a Layout,
}

impl Objective<'_> {
    fn eval(&self, th: &[f64]) -> Result<Evaluation, JobError> {
        let e = (self.eval)(th)?;
        let e = if self.whitened {
            self.layout.whiten(&e, self.noise)
        } else {
            let w: Vec<f64> = self.noise.iter().map(Ar1::long_run_sd).collect();
            prior::weighted(e, &w)
        };
        Ok(self.priors.augment(e, self.params, th))
    }

    /// Refit from θ with the parameters of `free`; the end point and its objective.
    fn refit(
        &self,
        th: &[f64],
        free: &[bool],
        iterations: usize,
    ) -> Result<(Vec<f64>, f64, usize), JobError> {
        let bounds: Vec<(f64, f64)> = self.params.iter().map(Parameter::theta_bounds).collect();
        let lmo = LmOptions {
            max_iterations: iterations,
            ..LmOptions::default()
        };
        let at = self.eval(th)?;
        let r = lm::minimise(|x| self.eval(x), th, at, &bounds, free, &lmo)?;
        (self.fail)(&r)?;
        Ok((r.theta.clone(), r.at.r.norm_squared(), r.evaluations))
    }
}

/// Where D crosses `q` between grid points `a` (inside) and `b` (outside), by linear
/// interpolation in the fitted coordinate.
fn crossing(a: (f64, f64), b: (f64, f64), q: f64) -> f64 {
    let (ta, da) = a;
    let (tb, db) = b;
    if db == da {
        return tb;
    }
    ta + (q - da) / (db - da) * (tb - ta)
}

/// One side of the profile from the optimum outward: the points (coordinate, objective S),
/// each refit started from the previous point's.
fn side(
    obj: &Objective<'_>,
    k: usize,
    theta: &[f64],
    free: &[bool],
    step: f64,
    evaluations: &mut usize,
) -> Result<Vec<(f64, f64)>, JobError> {
    let (lo, hi) = obj.params[k].theta_bounds();
    let mut at = theta.to_vec();
    let mut prev = theta[k];
    let mut points = Vec::with_capacity(STEPS);
    for i in 1..=STEPS {
        let t = (theta[k] + step * i as f64).clamp(lo, hi);
        if (t - prev).abs() <= 1e-12 * (1.0 + t.abs()) {
            break;
        }
        at[k] = t;
        let (next, s, n) = obj.refit(&at, free, POINT_ITERATIONS)?;
        *evaluations += n;
        at = next;
        points.push((t, s));
        prev = t;
    }
    Ok(points)
}

/// The first crossing of `q` by D going from index `from` through `order`.
fn first_crossing(
    pts: &[(f64, f64)],
    from: usize,
    order: impl Iterator<Item = usize>,
    q: f64,
) -> Option<f64> {
    let mut prev = pts[from];
    for i in order {
        if pts[i].1 >= q {
            return Some(crossing(prev, pts[i], q));
        }
        prev = pts[i];
    }
    None
}

/// The profile of parameter `k` from the fitted point `theta`; `se` its standard error in the
/// fitted coordinate (None: the grid spans the bounds), `dof` the t quantile's degrees of freedom,
/// `free` the parameters the fit moved. S_min is the least objective met (the refit from the
/// fitted point or a grid point, when the fit stopped short of the optimum along a flat valley).
pub fn profile(
    obj: &Objective<'_>,
    k: usize,
    theta: &[f64],
    se: Option<f64>,
    dof: usize,
    free: &[bool],
) -> Result<Profile, JobError> {
    let par = &obj.params[k];
    let mut evaluations = 0;
    let (best, s0, n) = obj.refit(theta, free, POINT_ITERATIONS)?;
    evaluations += n;
    let q = stats::t975(dof).powi(2);
    let (lo, hi) = par.theta_bounds();
    let step = match se {
        Some(s) if s > 0.0 => SPAN_SE * s / STEPS as f64,
        _ => (hi - lo) / (2 * STEPS) as f64,
    };
    let mut fixed = free.to_vec();
    fixed[k] = false;
    let down = side(obj, k, &best, &fixed, -step, &mut evaluations)?;
    let up = side(obj, k, &best, &fixed, step, &mut evaluations)?;
    let mut pts: Vec<(f64, f64)> = down.into_iter().rev().collect();
    pts.push((best[k], s0));
    pts.extend(up);
    let s_min = pts.iter().fold(f64::INFINITY, |a, p| a.min(p.1));
    for x in &mut pts {
        x.1 -= s_min;
    }
    let at = pts.iter().position(|x| x.1 == 0.0).unwrap_or(0);
    let below = s0 - s_min;
    let below_fit = (pts[at].0 != best[k] && below > 1e-6 * s0.max(1e-300)).then_some(below);
    let low = first_crossing(&pts, at, (0..at).rev(), q);
    let high = first_crossing(&pts, at, at + 1..pts.len(), q);
    Ok(Profile {
        key_path: par.name(),
        threshold: q,
        points: pts
            .iter()
            .map(|&(t, d)| ProfilePoint {
                value: par.written(t),
                statistic: d,
            })
            .collect(),
        ci95_low: low.map(|t| par.value(t)),
        ci95_high: high.map(|t| par.value(t)),
        evaluations,
        below_fit,
    })
}
