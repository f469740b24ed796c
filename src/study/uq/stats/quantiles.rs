//! Percentiles, exceedance probabilities and percentile bands over time.
//!
//! Percentiles are Hyndman & Fan's type 7 (R. J. Hyndman, Y. Fan, "Sample quantiles in
//! statistical packages", Am. Stat. 50 (1996) 361–365; the default of R and NumPy): for sorted
//! values x_0 ≤ … ≤ x_{n−1} and p in [0, 100], h = (n − 1) p/100 and
//! Q(p) = x_⌊h⌋ + (h − ⌊h⌋)(x_⌊h⌋+1 − x_⌊h⌋).
//!
//! Exceedance probability: the fraction k/n of samples above a limit, with the Wilson score
//! interval (E. B. Wilson, "Probable inference, the law of succession, and statistical
//! inference", J. Am. Stat. Assoc. 22 (1927) 209–212):
//! (p̂ + z²/2n ± z √(p̂(1−p̂)/n + z²/4n²)) / (1 + z²/n), z = Φ⁻¹((1 + confidence)/2).
//! Chosen over the Wald interval, which collapses to zero width at k = 0 or k = n (the case of a
//! rare exceedance, the one that matters), and over Clopper–Pearson, which is exact only in the
//! sense of never under-covering and is wider than needed on average (Brown, Cai & DasGupta,
//! "Interval estimation for a binomial proportion", Stat. Sci. 16 (2001) 101–133, recommend
//! Wilson). The binomial model assumes independent samples; for quasi-random (Sobol') samples
//! the count's variance is smaller than binomial, so the interval is conservative there.

use super::dist::normal_quantile;
use super::estimate::Estimate;

/// Type-7 percentiles `ps` (in percent, 0–100) of `values`, which are sorted in place. NaN for
/// every p when `values` is empty or holds a non-finite value, or for a p outside [0, 100]
/// (callers check: no NaN reaches a file).
pub fn percentiles(values: &mut [f64], ps: &[f64]) -> Vec<f64> {
    if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
        return vec![f64::NAN; ps.len()];
    }
    values.sort_by(f64::total_cmp);
    ps.iter().map(|&p| sorted_percentile(values, p)).collect()
}

/// Type-7 percentile p (percent) of sorted finite values.
fn sorted_percentile(x: &[f64], p: f64) -> f64 {
    if !(0.0..=100.0).contains(&p) {
        return f64::NAN;
    }
    let h = (x.len() - 1) as f64 * p / 100.0;
    let lo = h.floor() as usize;
    let hi = (lo + 1).min(x.len() - 1);
    x[lo] + (h - lo as f64) * (x[hi] - x[lo])
}

/// Check a list of percentiles: each in (0, 100), finite, strictly increasing.
pub fn check_percentiles(ps: &[f64]) -> Result<(), String> {
    if ps.is_empty() {
        return Err("no percentiles asked".into());
    }
    for (k, &p) in ps.iter().enumerate() {
        if !(p > 0.0 && p < 100.0) {
            return Err(format!("[{k}] = {p}: a percentile must be in (0, 100)"));
        }
        if k > 0 && p <= ps[k - 1] {
            return Err(format!(
                "[{k}] = {p}: percentiles must increase ({} before it)",
                ps[k - 1]
            ));
        }
    }
    Ok(())
}

/// Exceedance probability k/n with its Wilson score interval at `confidence` (module docs).
/// For n = 0 the estimate is 0 with the interval [0, 1].
pub fn exceedance(count: usize, n: usize, confidence: f64) -> Estimate {
    if n == 0 {
        return Estimate {
            value: 0.0,
            lo: 0.0,
            hi: 1.0,
        };
    }
    let (k, nf) = (count.min(n) as f64, n as f64);
    let p = k / nf;
    let z = normal_quantile(0.5 * (1.0 + confidence));
    let z2 = z * z;
    let centre = (p + z2 / (2.0 * nf)) / (1.0 + z2 / nf);
    let half = z * (p * (1.0 - p) / nf + z2 / (4.0 * nf * nf)).sqrt() / (1.0 + z2 / nf);
    Estimate {
        value: p,
        lo: (centre - half).max(0.0),
        hi: (centre + half).min(1.0),
    }
}

/// Percentile bands of one time series over samples: each sample's series is pushed (stored as
/// f32, 4 bytes per value: 1000 samples × 1800 times = 7 MB per series; a temperature keeps
/// about 1e-5 K), then [`BandAccumulator::bands`] gives the percentiles at every time.
#[derive(Debug, Clone)]
pub struct BandAccumulator {
    n_times: usize,
    values: Vec<f32>,
}

impl BandAccumulator {
    /// An empty accumulator for series of `n_times` values.
    pub fn new(n_times: usize) -> Self {
        BandAccumulator {
            n_times,
            values: Vec::new(),
        }
    }

    /// Add one sample's series (length `n_times`, finite values).
    pub fn push(&mut self, series: &[f64]) -> Result<(), String> {
        if series.len() != self.n_times {
            return Err(format!(
                "a series of {} values, expected {}",
                series.len(),
                self.n_times
            ));
        }
        if let Some(k) = series.iter().position(|v| !v.is_finite()) {
            return Err(format!("value {k} of the series is {}", series[k]));
        }
        self.values.extend(series.iter().map(|&v| v as f32));
        Ok(())
    }

    /// Samples pushed so far.
    pub fn samples(&self) -> usize {
        self.values.len().checked_div(self.n_times).unwrap_or(0)
    }

    /// Percentiles `ps` (percent) at every time: `[percentile][time]`; an error without samples.
    pub fn bands(&self, ps: &[f64]) -> Result<Vec<Vec<f64>>, String> {
        let n = self.samples();
        if n == 0 {
            return Err("no sample finished: no band".into());
        }
        let mut out = vec![vec![0.0; self.n_times]; ps.len()];
        let mut col = vec![0.0f64; n];
        for t in 0..self.n_times {
            for (s, c) in col.iter_mut().enumerate() {
                *c = f64::from(self.values[s * self.n_times + t]);
            }
            let q = percentiles(&mut col, ps);
            for (row, v) in out.iter_mut().zip(q) {
                row[t] = v;
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::super::dist::{normal_cdf, Distribution};
    use super::super::lowdisc::sobol_points;
    use super::*;

    #[test]
    fn type_7_on_a_small_sample() {
        // NumPy's default (linear) percentiles of [1, 2, 3, 4]: 25 % → 1.75, 50 % → 2.5.
        let q = percentiles(&mut [4.0, 1.0, 3.0, 2.0], &[0.0, 25.0, 50.0, 100.0]);
        assert_eq!(q, vec![1.0, 1.75, 2.5, 4.0]);
        assert!(percentiles(&mut [], &[50.0])[0].is_nan());
        assert!(percentiles(&mut [1.0, f64::NAN], &[50.0])[0].is_nan());
    }

    #[test]
    fn percentiles_of_a_normal_sample_match_the_analytic_quantiles() {
        let d = Distribution::Normal { mean: 80.0, sd: 5.0 };
        let mut x: Vec<f64> = sobol_points(4096, 1, Some(4))
            .unwrap()
            .iter()
            .map(|p| d.quantile(p[0]))
            .collect();
        let ps = [5.0, 50.0, 95.0];
        let q = percentiles(&mut x, &ps);
        for (k, p) in ps.iter().enumerate() {
            let exact = d.quantile(p / 100.0);
            assert!((q[k] - exact).abs() < 0.01, "p{p}: {} vs {exact}", q[k]);
        }
    }

    #[test]
    fn exceedance_of_a_sum_of_uniforms_matches_the_closed_form() {
        // X = U1 + U2 on [0, 2] (triangular): P(X > 1.5) = (2 − 1.5)²/2 = 0.125.
        let pts = sobol_points(1 << 14, 2, Some(8)).unwrap();
        let k = pts.iter().filter(|p| p[0] + p[1] > 1.5).count();
        let e = exceedance(k, pts.len(), 0.95);
        assert!((e.value - 0.125).abs() < 0.002, "{e:?}");
        assert!(e.lo < 0.125 && 0.125 < e.hi, "{e:?}");
        // A normal: P(X > μ + 2σ) = 1 − Φ(2).
        let d = Distribution::Normal { mean: 100.0, sd: 8.0 };
        let pts = sobol_points(1 << 14, 1, Some(2)).unwrap();
        let k = pts.iter().filter(|p| d.quantile(p[0]) > 116.0).count();
        let e = exceedance(k, pts.len(), 0.95);
        let exact = 1.0 - normal_cdf(2.0);
        assert!(e.lo < exact && exact < e.hi, "{e:?} vs {exact}");
    }

    #[test]
    fn wilson_interval_at_zero_and_full_counts() {
        let e = exceedance(0, 100, 0.95);
        assert_eq!((e.value, e.lo), (0.0, 0.0));
        // Upper end z²/(n + z²) at k = 0.
        let z2 = 1.959_963_984_540_054_f64.powi(2);
        assert!((e.hi - z2 / (100.0 + z2)).abs() < 1e-12, "{e:?}");
        let e = exceedance(100, 100, 0.95);
        assert_eq!((e.value, e.hi), (1.0, 1.0));
        assert!(e.lo < 1.0);
    }

    #[test]
    fn band_accumulator_gives_per_time_percentiles() {
        let mut b = BandAccumulator::new(2);
        for s in 0..101 {
            b.push(&[s as f64, 2.0 * s as f64]).unwrap();
        }
        let q = b.bands(&[5.0, 50.0, 95.0]).unwrap();
        assert_eq!(q[1], vec![50.0, 100.0]);
        assert_eq!(q[0][0], 5.0);
        assert_eq!(q[2][1], 190.0);
        assert!(b.push(&[1.0]).is_err());
        assert!(b.push(&[1.0, f64::INFINITY]).is_err());
        assert!(BandAccumulator::new(3).bands(&[50.0]).is_err());
    }

    /// The step response of a linear two-node network (C1 dT1/dt = Q − G12 (T1 − T2),
    /// C2 dT2/dt = G12 (T1 − T2) − G2a (T2 − Ta), both nodes starting at Ta) is
    /// T_i(t) = Ta + Q g_i(t) with g(t) = M⁻¹ (e^{Mt} − I) b (M the 2×2 system matrix,
    /// b = (1/C1, 0)); with Q ~ N(μ_Q, σ_Q²) and Ta ~ N(μ_a, σ_a²) independent, T_i(t) is normal
    /// with mean μ_a + μ_Q g_i and variance σ_a² + σ_Q² g_i². The bands of the accumulator over
    /// 2^14 scrambled Sobol' samples must match those normal quantiles at every time, within one
    /// Monte-Carlo standard error of a quantile.
    #[test]
    fn bands_of_a_linear_two_node_network_match_the_analytic_distribution() {
        let (c1, c2, g12, g2a): (f64, f64, f64, f64) = (2.0e4, 5.0e4, 20.0, 10.0);
        let m = [[-g12 / c1, g12 / c1], [g12 / c2, -(g12 + g2a) / c2]];
        let (tr, det) = (m[0][0] + m[1][1], m[0][0] * m[1][1] - m[0][1] * m[1][0]);
        let disc = (tr * tr / 4.0 - det).sqrt();
        let (l1, l2) = (tr / 2.0 + disc, tr / 2.0 - disc);
        // g(t) = M⁻¹ (e^{Mt} − I) b, e^{Mt} by Sylvester's formula for distinct eigenvalues.
        let g = |t: f64| -> [f64; 2] {
            let (e1, e2) = ((l1 * t).exp(), (l2 * t).exp());
            let ex = |i: usize, j: usize| {
                let id = if i == j { 1.0 } else { 0.0 };
                (e1 * (m[i][j] - l2 * id) - e2 * (m[i][j] - l1 * id)) / (l1 - l2)
            };
            let v = [(ex(0, 0) - 1.0) / c1, ex(1, 0) / c1];
            let inv = [[m[1][1] / det, -m[0][1] / det], [-m[1][0] / det, m[0][0] / det]];
            [
                inv[0][0] * v[0] + inv[0][1] * v[1],
                inv[1][0] * v[0] + inv[1][1] * v[1],
            ]
        };
        let times: Vec<f64> = (0..=40).map(|k| k as f64 * 300.0).collect();
        let q = Distribution::Normal {
            mean: 500.0,
            sd: 50.0,
        };
        let ta = Distribution::Normal { mean: 30.0, sd: 3.0 };
        let mut acc = [
            BandAccumulator::new(times.len()),
            BandAccumulator::new(times.len()),
        ];
        let n = 1usize << 14;
        for u in sobol_points(n, 2, Some(21)).unwrap() {
            let (qv, tv) = (q.quantile(u[0]), ta.quantile(u[1]));
            for (node, a) in acc.iter_mut().enumerate() {
                let series: Vec<f64> = times.iter().map(|&t| tv + qv * g(t)[node]).collect();
                a.push(&series).unwrap();
            }
        }
        let ps = [5.0, 50.0, 95.0];
        for (node, a) in acc.iter().enumerate() {
            let bands = a.bands(&ps).unwrap();
            for (k, &t) in times.iter().enumerate() {
                let gi = g(t)[node];
                let exact = Distribution::Normal {
                    mean: 30.0 + 500.0 * gi,
                    sd: (9.0 + 2500.0 * gi * gi).sqrt(),
                };
                let sd = (9.0 + 2500.0 * gi * gi).sqrt();
                for (j, p) in ps.iter().enumerate() {
                    let want = exact.quantile(p / 100.0);
                    let err = (bands[j][k] - want).abs();
                    // One standard error of a Monte-Carlo quantile of n independent samples,
                    // σ √(p(1−p)/n) / φ(z_p): the scrambled points must do at least as well
                    // (a wrong band is off by kelvins).
                    let pf = p / 100.0;
                    let z = normal_quantile(pf);
                    let phi = (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
                    let tol = sd * (pf * (1.0 - pf) / n as f64).sqrt() / phi;
                    assert!(
                        err < tol,
                        "node {node}, t = {t} s, p{p}: {} vs {want} (tolerance {tol})",
                        bands[j][k]
                    );
                }
            }
        }
        // The network has warmed: node 1 at 12 000 s is well above the ambient's spread.
        assert!(g(12_000.0)[0] > 0.1);
    }

    #[test]
    fn bad_percentile_lists_are_refused() {
        assert!(check_percentiles(&[5.0, 50.0, 95.0]).is_ok());
        assert!(check_percentiles(&[50.0, 5.0])
            .unwrap_err()
            .contains("must increase"));
        assert!(check_percentiles(&[0.0]).unwrap_err().contains("(0, 100)"));
    }
}
