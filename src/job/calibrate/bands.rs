//! The 95 % prediction band of every fitted channel at every trace row: the parameters'
//! uncertainty carried through the sensitivities (sᵀ·Cov·s, s = ∂T/∂θ at that row) plus the
//! residual process's stationary variance σ_a²/(1 − φ²), the standard deviation
//! sd = √(sum) (Seber & Wild, Nonlinear Regression, 1989, §5.1, prediction intervals of a new
//! observation; with correlated errors the new observation's marginal variance); the
//! half-width is a multiplier times sd.
//!
//! The multiplier (`--band-quantile`, docs/calibration.md, "Prediction bands"):
//! - `empirical`: the ⌈(n + 1)·0.95⌉-th smallest of the n fitted rows' standardised residuals
//!   |e|/sd, the empirical 95 % quantile of the residuals' own distribution (the rank of split
//!   conformal inference, Lei, G'Sell, Rinaldo, Tibshirani & Wasserman, "Distribution-free
//!   predictive inference for regression", JASA 113, 2018, Algorithm 1), when the rows carry at
//!   least [`MIN_EFFECTIVE_ROWS`] effective independent residuals; else t(0.975, ν);
//! - `t`: Student's t(0.975, ν), exact for Gaussian residuals.

use super::problem::Simulation;
use super::residuals::Ar1;

/// Fewest effective independent residuals (see [`effective_rows`]) over which the empirical
/// quantile replaces t: then at least 5 lie beyond the 95 % quantile, and the coverage of a
/// quantile of independent rows scatters by √(0.05·0.95/n) ≤ 2.2 % about 95 %.
pub const MIN_EFFECTIVE_ROWS: f64 = 100.0;

/// How the band's multiplier is chosen (`--band-quantile`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantile {
    /// The fitted rows' empirical 95 % quantile of |e|/sd (t when they are too few).
    Empirical,
    /// Student's t(0.975, ν).
    T,
}

impl Quantile {
    /// From the option's text (`empirical` or `t`; checked by the options).
    pub fn of(s: &str) -> Quantile {
        if s == "t" {
            Quantile::T
        } else {
            Quantile::Empirical
        }
    }
}

/// One channel's band multiplier and how it was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Multiplier {
    /// The half-width over sd.
    pub value: f64,
    /// True: the empirical quantile; false: t(0.975, ν).
    pub empirical: bool,
}

impl Multiplier {
    /// Student's t quantile `t`.
    pub fn t(t: f64) -> Multiplier {
        Multiplier {
            value: t,
            empirical: false,
        }
    }

    /// `empirical` or `t`, as `calibration.json` names it.
    pub fn kind(&self) -> &'static str {
        if self.empirical {
            "empirical"
        } else {
            "t"
        }
    }
}

/// Effective number of independent rows for a quantile of |e| over n rows of an AR(1) series
/// with coefficient φ: n·(1 − φ²)/(1 + φ²). An even function of a Gaussian series has no
/// first-order Hermite component, so its lag-h autocorrelation is at most φ^(2h) (Mehler's
/// expansion of the bivariate normal density), and Σ_h φ^(2|h|) = (1 + φ²)/(1 − φ²).
pub fn effective_rows(n: usize, phi: f64) -> f64 {
    let r = phi * phi;
    n as f64 * (1.0 - r) / (1.0 + r)
}

/// The multiplier of a channel from its fitted rows' standardised residuals `z` = |e|/sd, φ its
/// residual process's coefficient, `t` Student's quantile of the fit.
pub fn multiplier(z: &[f64], phi: f64, t: f64, how: Quantile) -> Multiplier {
    let mut z: Vec<f64> = z.iter().copied().filter(|x| x.is_finite()).collect();
    if how == Quantile::T || effective_rows(z.len(), phi) < MIN_EFFECTIVE_ROWS {
        return Multiplier::t(t);
    }
    z.sort_by(f64::total_cmp);
    let n = z.len();
    // ⌈0.95·(n + 1)⌉ = ⌈19·(n + 1)/20⌉ in integers.
    let k = (19 * (n + 1)).div_ceil(20);
    Multiplier {
        value: z[k.clamp(1, n) - 1],
        empirical: true,
    }
}

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

/// The band's standard deviation, K, `[row][channel]`. `cov` is the covariance of the fitted
/// coordinates (NaN entries, of parameters left out, count as 0); `sim` holds the
/// sensitivities at every row.
pub fn sds(sim: &Simulation, cov: &[Vec<f64>], noise: &[Ar1]) -> Vec<Vec<f64>> {
    let p = cov.len();
    (0..sim.temps_c.len())
        .map(|r| {
            let row = sim.sens.get(r).map_or(&[][..], |x| &x[..]);
            noise
                .iter()
                .enumerate()
                .map(|(c, a)| {
                    let s = row.get(c * p..(c + 1) * p).unwrap_or(&[]);
                    (quadratic(s, cov) + a.marginal_sd().powi(2)).sqrt()
                })
                .collect()
        })
        .collect()
}

/// Half-widths `[row][channel]` from the standard deviations and each channel's multiplier.
pub fn scaled(sd: &[Vec<f64>], mult: &[Multiplier]) -> Vec<Vec<f64>> {
    sd.iter()
        .map(|row| row.iter().zip(mult).map(|(s, m)| s * m.value).collect())
        .collect()
}

/// |e|/sd of channel `c` over the rows `rows` (`res` and `sd` indexed `[row][channel]`).
pub fn standardised(res: &[Vec<f64>], sd: &[Vec<f64>], rows: &[usize], c: usize) -> Vec<f64> {
    rows.iter()
        .filter(|&&r| sd[r][c] > 0.0)
        .map(|&r| res[r][c].abs() / sd[r][c])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The empirical multiplier is the ⌈0.95(n + 1)⌉-th smallest value; too few effective rows
    /// (or `t` asked for) give t.
    #[test]
    fn the_rank_and_the_fallback() {
        let z: Vec<f64> = (1..=199).rev().map(f64::from).collect();
        let m = multiplier(&z, 0.0, 1.97, Quantile::Empirical);
        assert_eq!(
            m,
            Multiplier {
                value: 190.0,
                empirical: true
            }
        );
        assert_eq!(multiplier(&z, 0.0, 1.97, Quantile::T), Multiplier::t(1.97));
        // 199 rows with φ = 0.7: 199·0.51/1.49 = 68 effective rows, below 100.
        assert_eq!(
            multiplier(&z, 0.7, 1.97, Quantile::Empirical),
            Multiplier::t(1.97)
        );
        assert!((effective_rows(2016, 0.904) - 203.0).abs() < 1.0);
    }
}
