//! The 95 % prediction band of every fitted channel at every trace row: the parameters'
//! uncertainty carried through the sensitivities (sᵀ·Cov·s, s = ∂T/∂θ at that row) plus the
//! residual process's stationary variance σ_a²/(1 − φ²), the half-width t(0.975)·√(sum)
//! (Seber & Wild, Nonlinear Regression, 1989, §5.1, prediction intervals of a new observation;
//! with correlated errors the new observation's marginal variance).

use super::problem::Simulation;
use super::residuals::Ar1;

/// sᵀ·Cov·s over the finite entries of `cov`.
fn quadratic(s: &[f64], cov: &[Vec<f64>]) -> f64 {
    let mut v = 0.0;
    for (x, cx) in s.iter().zip(cov) {
        for (y, cxy) in s.iter().zip(cx) {
            if cxy.is_finite() {
                v += x * cxy * y;
            }
        }
    }
    v.max(0.0)
}

/// Half-width of the band, K, `[row][channel]`. `cov` is the covariance of the fitted
/// coordinates (NaN entries, of parameters left out, count as 0); `sim` holds the
/// sensitivities at every row.
pub fn half_widths(sim: &Simulation, cov: &[Vec<f64>], noise: &[Ar1], t: f64) -> Vec<Vec<f64>> {
    let p = cov.len();
    (0..sim.temps_c.len())
        .map(|r| {
            let row = sim.sens.get(r).map_or(&[][..], |x| &x[..]);
            noise
                .iter()
                .enumerate()
                .map(|(c, a)| {
                    let s = row.get(c * p..(c + 1) * p).unwrap_or(&[]);
                    t * (quadratic(s, cov) + a.marginal_sd().powi(2)).sqrt()
                })
                .collect()
        })
        .collect()
}
