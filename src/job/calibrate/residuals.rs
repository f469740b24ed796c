//! The residual model: per measured channel an AR(1) error e_t = φ·e_{t−1} + a_t, a_t
//! independent N(0, σ_a²), over the fitted rows of each stretch not interrupted by a held-out
//! window. The fit is generalised least squares by prewhitening (Prais–Winsten): each
//! channel's residuals and Jacobian rows become (r_t − φ r_{t−1})/σ_a, the first row of a
//! stretch √(1 − φ²)·r/σ_a (Seber & Wild, Nonlinear Regression, 1989, §6.2–6.4, "two-stage
//! estimation" of nonlinear models with AR(1) errors). φ and σ_a are estimated from the
//! residuals, the fit repeated with them until φ settles.

use nalgebra::{DMatrix, DVector};

use super::lm::{self, Evaluation, LmOptions, LmResult};

/// Largest |φ| estimated (a random walk has no stationary variance).
pub const MAX_PHI: f64 = 0.99;

/// One channel's AR(1) error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ar1 {
    /// Lag-1 coefficient φ.
    pub phi: f64,
    /// Innovation standard deviation σ_a, K.
    pub sigma: f64,
}

impl Ar1 {
    /// Stationary standard deviation σ_a/√(1 − φ²), K.
    pub fn marginal_sd(&self) -> f64 {
        self.sigma / (1.0 - self.phi * self.phi).sqrt()
    }

    /// Long-run standard deviation σ_a/(1 − φ), K: the noise scale of a slowly varying
    /// signal's information, Σ_t x_t²·(1 − φ)²/σ_a² (the weight of a channel's rows in a MAP
    /// fit and a profile; for φ ≤ 0 the stationary one).
    pub fn long_run_sd(&self) -> f64 {
        if self.phi > 0.0 {
            self.sigma / (1.0 - self.phi)
        } else {
            self.marginal_sd()
        }
    }
}

/// The layout of the fitted residual vector: `nc` channels per fitted row (row-major), and the
/// stretch each fitted row belongs to.
#[derive(Debug, Clone)]
pub struct Layout {
    /// Channels.
    pub nc: usize,
    /// Stretch number of each fitted row.
    pub stretch: Vec<usize>,
}

impl Layout {
    /// From the held-out flags of the trace rows: a held-out row ends a stretch.
    pub fn of(held: &[bool], nc: usize) -> Layout {
        let mut stretch = Vec::new();
        let (mut k, mut prev_held) = (0usize, false);
        for &h in held {
            if h {
                prev_held = true;
                continue;
            }
            if prev_held && !stretch.is_empty() {
                k += 1;
            }
            prev_held = false;
            stretch.push(k);
        }
        Layout { nc, stretch }
    }

    /// True when fitted row i continues the stretch of row i − 1.
    fn continues(&self, i: usize) -> bool {
        i > 0 && self.stretch[i] == self.stretch[i - 1]
    }

    /// Channel c's values of the residual vector r.
    pub fn channel(&self, r: &DVector<f64>, c: usize) -> Vec<f64> {
        (0..self.stretch.len()).map(|i| r[i * self.nc + c]).collect()
    }

    /// Autocorrelation of x (one channel, fitted rows) at `lag` rows, pairs within a stretch.
    pub fn autocorrelation(&self, x: &[f64], lag: usize) -> Option<f64> {
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        let pairs: Vec<(f64, f64)> = (lag..x.len())
            .filter(|&i| self.stretch[i] == self.stretch[i - lag])
            .map(|i| (x[i] - mean, x[i - lag] - mean))
            .collect();
        if pairs.is_empty() || var.is_nan() || var <= 0.0 {
            return None;
        }
        let cov = pairs.iter().map(|(a, b)| a * b).sum::<f64>() / pairs.len() as f64;
        Some(cov / var)
    }

    /// φ by least squares on the pairs within stretches, σ_a from the Prais–Winsten innovations.
    pub fn estimate(&self, r: &DVector<f64>) -> Vec<Ar1> {
        (0..self.nc)
            .map(|c| {
                let x = self.channel(r, c);
                let (mut sxy, mut sxx) = (0.0, 0.0);
                for i in (1..x.len()).filter(|&i| self.continues(i)) {
                    sxy += x[i] * x[i - 1];
                    sxx += x[i - 1] * x[i - 1];
                }
                // The least-squares estimate with the first-order bias of a series whose mean is
                // estimated, −(1 + 3φ)/n, added back (Marriott & Pope, Biometrika 41, 1954;
                // Kendall, Biometrika 41, 1954).
                let n = x.len() as f64;
                let phi = if sxx > 0.0 {
                    let ls = sxy / sxx;
                    (ls + (1.0 + 3.0 * ls) / n).clamp(-MAX_PHI, MAX_PHI)
                } else {
                    0.0
                };
                let ss: f64 = (0..x.len())
                    .map(|i| {
                        if self.continues(i) {
                            (x[i] - phi * x[i - 1]).powi(2)
                        } else {
                            (1.0 - phi * phi) * x[i] * x[i]
                        }
                    })
                    .sum();
                let sigma = (ss / x.len() as f64).sqrt().max(1e-12);
                Ar1 { phi, sigma }
            })
            .collect()
    }

    /// The prewhitened residuals and Jacobian.
    pub fn whiten(&self, e: &Evaluation, models: &[Ar1]) -> Evaluation {
        let (m, p) = e.j.shape();
        let mut r = DVector::zeros(m);
        let mut j = DMatrix::zeros(m, p);
        for i in 0..self.stretch.len() {
            for (c, a) in models.iter().enumerate() {
                let k = i * self.nc + c;
                let (w_cur, w_prev) = if self.continues(i) {
                    (1.0, -a.phi)
                } else {
                    ((1.0 - a.phi * a.phi).sqrt(), 0.0)
                };
                let prev = k.wrapping_sub(self.nc);
                let at = |v: &dyn Fn(usize) -> f64| {
                    let before = if w_prev != 0.0 { w_prev * v(prev) } else { 0.0 };
                    (w_cur * v(k) + before) / a.sigma
                };
                r[k] = at(&|q| e.r[q]);
                for col in 0..p {
                    j[(k, col)] = at(&|q| e.j[(q, col)]);
                }
            }
        }
        Evaluation { r, j }
    }

    /// Σ·x for every column x of `j`: Σ the residuals' covariance under the AR(1) models,
    /// σ_a²/(1 − φ²)·φ^|i−k| between rows i and k of one channel and stretch, 0 otherwise
    /// (forward and backward recursions, O(m) per column).
    pub fn covariance_times(&self, j: &DMatrix<f64>, models: &[Ar1]) -> DMatrix<f64> {
        let n = self.stretch.len();
        let mut out = DMatrix::zeros(j.nrows(), j.ncols());
        for col in 0..j.ncols() {
            for (c, a) in models.iter().enumerate() {
                let x: Vec<f64> = (0..n).map(|i| j[(i * self.nc + c, col)]).collect();
                let mut f = x.clone();
                for i in 1..n {
                    if self.continues(i) {
                        f[i] += a.phi * f[i - 1];
                    }
                }
                let mut b = x.clone();
                for i in (0..n.saturating_sub(1)).rev() {
                    if self.continues(i + 1) {
                        b[i] += a.phi * b[i + 1];
                    }
                }
                let v = a.marginal_sd().powi(2);
                for i in 0..n {
                    out[(i * self.nc + c, col)] = v * (f[i] + b[i] - x[i]);
                }
            }
        }
        out
    }

    /// The residuals and Jacobian from their whitened values (the inverse of [`Self::whiten`]).
    pub fn unwhiten_evaluation(&self, e: &Evaluation, models: &[Ar1]) -> Evaluation {
        let r = self.unwhiten(&e.r, models);
        let mut j = e.j.clone();
        for col in 0..j.ncols() {
            let c = self.unwhiten(&e.j.column(col).into_owned(), models);
            j.set_column(col, &c);
        }
        Evaluation { r, j }
    }

    /// The residuals r from their whitened values w (the inverse filter of [`Self::whiten`]).
    pub fn unwhiten(&self, w: &DVector<f64>, models: &[Ar1]) -> DVector<f64> {
        let mut r = DVector::zeros(w.len());
        for i in 0..self.stretch.len() {
            for (c, a) in models.iter().enumerate() {
                let k = i * self.nc + c;
                r[k] = if self.continues(i) {
                    a.sigma * w[k] + a.phi * r[k - self.nc]
                } else {
                    a.sigma * w[k] / (1.0 - a.phi * a.phi).sqrt()
                };
            }
        }
        r
    }
}

/// Effective number of independent residuals Σ_c n·(1 − φ_c)/(1 + φ_c) (n fitted rows per
/// channel; n for φ ≤ 0): the degrees of freedom of the t quantile are this less the
/// parameters, since the variance of the fit is estimated from about as much information as
/// that many independent residuals carry.
pub fn effective_rows(layout: &Layout, models: &[Ar1]) -> f64 {
    let n = layout.stretch.len() as f64;
    models
        .iter()
        .map(|a| {
            if a.phi > 0.0 {
                n * (1.0 - a.phi) / (1.0 + a.phi)
            } else {
                n
            }
        })
        .sum()
}

/// Most passes of the two-stage fit (estimate φ, σ_a; fit the whitened residuals).
pub const MAX_PASSES: usize = 4;
/// The passes stop when no channel's φ moves by more than this.
pub const PHI_SETTLED: f64 = 0.01;

/// The generalised least-squares fit: from the ordinary fit `ols` (raw residuals), estimate the
/// channels' AR(1) errors, fit the whitened residuals (with the rows `augment` appends: the
/// priors'; `strip` removes them), re-estimate, until φ settles. Returns the last fit (its
/// evaluation whitened, without the appended rows, evaluations and steps summed over the
/// passes) and the models that whitened it.
#[allow(clippy::too_many_arguments)]
pub fn refit<E>(
    mut eval: impl FnMut(&[f64]) -> Result<Evaluation, E>,
    augment: impl Fn(Evaluation, &[f64]) -> Evaluation,
    strip: impl Fn(Evaluation) -> Evaluation,
    ols: LmResult,
    layout: &Layout,
    bounds: &[(f64, f64)],
    free: &[bool],
    o: &LmOptions,
) -> Result<(LmResult, Vec<Ar1>), E> {
    let (mut evaluations, mut iterations) = (ols.evaluations, ols.iterations);
    let mut models = layout.estimate(&ols.at.r);
    let (mut theta, mut raw) = (ols.theta, ols.at);
    let mut pass = 0;
    loop {
        pass += 1;
        let at = augment(layout.whiten(&raw, &models), &theta);
        let m = models.clone();
        let mut res = lm::minimise(
            |th| eval(th).map(|e| augment(layout.whiten(&e, &m), th)),
            &theta,
            at,
            bounds,
            free,
            o,
        )?;
        res.at = strip(res.at);
        evaluations += res.evaluations - 1;
        iterations += res.iterations;
        raw = layout.unwhiten_evaluation(&res.at, &models);
        let next = layout.estimate(&raw.r);
        let moved = next
            .iter()
            .zip(&models)
            .fold(0.0_f64, |a, (x, y)| a.max((x.phi - y.phi).abs()));
        theta.clone_from(&res.theta);
        if moved <= PHI_SETTLED || pass == MAX_PASSES {
            return Ok((
                LmResult {
                    evaluations,
                    iterations,
                    ..res
                },
                models,
            ));
        }
        models = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An AR(1) series with φ = 0.9 is estimated near 0.9; whitening then unwhitening returns it.
    #[test]
    fn estimates_and_inverts() {
        let mut s: u64 = 7;
        let mut normal = || {
            let mut u = || {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
            };
            let (a, b) = (u(), u());
            (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
        };
        let n = 20_000;
        let mut x = vec![0.0; n];
        for i in 1..n {
            x[i] = 0.9 * x[i - 1] + 0.5 * normal();
        }
        let held: Vec<bool> = (0..n).map(|i| (5000..5100).contains(&i)).collect();
        let kept: Vec<f64> = (0..n).filter(|&i| !held[i]).map(|i| x[i]).collect();
        let lay = Layout::of(&held, 1);
        assert_eq!(lay.stretch[4999], 0);
        assert_eq!(lay.stretch[5000], 1);
        let r = DVector::from_vec(kept);
        let a = lay.estimate(&r)[0];
        assert!(
            (a.phi - 0.9).abs() < 0.01 && (a.sigma - 0.5).abs() < 0.01,
            "{a:?}"
        );
        let e = Evaluation {
            r: r.clone(),
            j: DMatrix::from_element(r.len(), 1, 1.0),
        };
        let w = lay.whiten(&e, &[a]);
        let back = lay.unwhiten(&w.r, &[a]);
        assert!((back - &r).amax() < 1e-9);
        let acf = lay.autocorrelation(r.as_slice(), 1).unwrap();
        assert!((acf - 0.9).abs() < 0.02, "{acf}");
        // Σ·e_k is column k of Σ: σ_a²/(1 − φ²)·φ^|i−k| within the stretch.
        let small = Layout::of(&[false, false, false, true, false], 1);
        let m = Ar1 { phi: 0.5, sigma: 1.0 };
        let unit = DMatrix::from_fn(4, 1, |i, _| f64::from(u8::from(i == 1)));
        let col = small.covariance_times(&unit, &[m]);
        let v = 1.0 / 0.75;
        let want = [0.5 * v, v, 0.5 * v, 0.0];
        assert!((0..4).all(|i| (col[(i, 0)] - want[i]).abs() < 1e-12), "{col}");
    }
}
