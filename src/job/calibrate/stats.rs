//! What the fit's Jacobian says about the fitted values: covariance (JᵀJ)⁻¹·σ², 95 % intervals
//! through Student's t quantile, the correlation matrix (Seber & Wild, Nonlinear Regression,
//! 1989, §2.1: the linearised intervals of a least-squares fit).

use nalgebra::DMatrix;

/// Student's t density's normalising constant Γ((ν+1)/2) / (√(νπ)·Γ(ν/2)), from the
/// recurrence r(ν+1) = (ν/2)/r(ν) of r(ν) = Γ((ν+1)/2)/Γ(ν/2), r(1) = 1/√π.
fn t_norm(nu: usize) -> f64 {
    let mut r = 1.0 / std::f64::consts::PI.sqrt();
    for k in 1..nu {
        r = (k as f64 / 2.0) / r;
    }
    r / (nu as f64 * std::f64::consts::PI).sqrt()
}

/// P(|T| < x) for Student's t with ν degrees of freedom: twice the density's integral over
/// [0, x] (composite Simpson rule, 4000 intervals).
fn t_central(x: f64, nu: usize) -> f64 {
    let c = t_norm(nu);
    let n = 4000;
    let h = x / n as f64;
    let pdf = |u: f64| c * (1.0 + u * u / nu as f64).powf(-(nu as f64 + 1.0) / 2.0);
    let mut s = pdf(0.0) + pdf(x);
    for k in 1..n {
        s += pdf(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    2.0 * s * h / 3.0
}

/// The two-sided 95 % quantile t(0.975, ν) (bisection on [`t_central`]); above 10⁵ degrees of
/// freedom the normal quantile's value at that ν is used.
pub fn t975(dof: usize) -> f64 {
    let nu = dof.clamp(1, 100_000);
    let (mut lo, mut hi) = (0.0, 50.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if t_central(mid, nu) < 0.95 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Covariance, correlation and standard errors of the fitted coordinates.
#[derive(Debug, Clone)]
pub struct Linearised {
    /// σ² = SSR / (m − P), K².
    pub sigma2: f64,
    /// Degrees of freedom m − P.
    pub dof: usize,
    /// Standard error of each coordinate (None: not identifiable).
    pub std_err: Vec<Option<f64>>,
    /// Correlation matrix (NaN where undefined).
    pub correlation: Vec<Vec<f64>>,
}

/// Linearised statistics from the residuals' Jacobian `j` (m × P) and sum of squares `ssr`.
/// A column that is zero (no influence) gets no standard error and is left out of the inverse.
pub fn linearised(j: &DMatrix<f64>, ssr: f64, identifiable: &[bool]) -> Linearised {
    let (m, p) = j.shape();
    let keep: Vec<usize> = (0..p).filter(|&k| identifiable[k]).collect();
    let dof = m.saturating_sub(keep.len()).max(1);
    let sigma2 = ssr / dof as f64;
    let jk = DMatrix::from_fn(m, keep.len(), |r, c| j[(r, keep[c])]);
    let a = jk.transpose() * &jk;
    let inv = a.clone().try_inverse();
    let mut std_err = vec![None; p];
    let mut correlation = vec![vec![f64::NAN; p]; p];
    if let Some(inv) = inv {
        for (a_, &ka) in keep.iter().enumerate() {
            std_err[ka] = Some((inv[(a_, a_)] * sigma2).max(0.0).sqrt());
            for (b_, &kb) in keep.iter().enumerate() {
                let d = (inv[(a_, a_)] * inv[(b_, b_)]).sqrt();
                correlation[ka][kb] = if d > 0.0 { inv[(a_, b_)] / d } else { f64::NAN };
            }
        }
    }
    Linearised {
        sigma2,
        dof,
        std_err,
        correlation,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles() {
        // P(|T| < t975) = 0.95 by construction; check the density integrates to 1 and the
        // limits: ν = 1 is the Cauchy distribution, t = tan(0.475π); ν large → 1.95996.
        assert!((t975(1) - (0.475 * std::f64::consts::PI).tan()).abs() < 1e-3);
        assert!((t975(100_000) - 1.959_964).abs() < 1e-3);
        assert!(t975(5) > t975(30) && t975(30) > t975(1000));
        // ν = 2 has the closed form t = q·√(2/(1 − q²)) with q = 0.95.
        let q: f64 = 0.95;
        assert!((t975(2) - q * (2.0 / (1.0 - q * q)).sqrt()).abs() < 1e-6);
    }

    #[test]
    fn straight_line_intervals() {
        // y = a + b·x: Cov = σ²(XᵀX)⁻¹, checked against the closed form of simple regression.
        let x: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let j = DMatrix::from_fn(10, 2, |r, c| if c == 0 { 1.0 } else { x[r] });
        let l = linearised(&j, 8.0, &[true, true]);
        let sxx: f64 = x.iter().map(|v| (v - 4.5).powi(2)).sum();
        assert!((l.sigma2 - 1.0).abs() < 1e-12);
        assert!((l.std_err[1].unwrap() - (1.0 / sxx).sqrt()).abs() < 1e-12);
        let r = l.correlation[0][1];
        assert!((r - (-4.5 / (sxx / 10.0 + 20.25).sqrt())).abs() < 1e-9, "{r}");
        let l = linearised(&j, 8.0, &[true, false]);
        assert!(l.std_err[1].is_none() && l.std_err[0].is_some());
    }
}
