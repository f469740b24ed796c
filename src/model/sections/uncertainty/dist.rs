//! Probability distributions of uncertain inputs: the five families a model or study file may
//! name, their checks, inverse CDF (sampling by quantile transform of uniform points), CDF, mean
//! and support.
//!
//! Parameterisation:
//! - `Normal { mean, sd }`: N(mean, sd²), sd > 0.
//! - `LogNormal { median, sigma_ln }`: ln X ~ N(ln median, sigma_ln²) (so `median` = e^μ and
//!   `sigma_ln` = σ of the logarithm); median > 0, sigma_ln > 0. Its support is (0, ∞).
//! - `Uniform { lo, hi }`: lo < hi.
//! - `Triangular { lo, mode, hi }`: lo ≤ mode ≤ hi, lo < hi.
//! - `Truncated { inner, lo, hi }`: `inner` restricted to [lo, hi] and renormalised; lo < hi and
//!   the inner distribution's probability mass on [lo, hi] at least [`MIN_TRUNCATED_MASS`].
//!
//! The standard normal CDF is Φ(x) = erfc(−x/√2)/2 with the FreeBSD msun `erfc` (libm crate,
//! relative error below 1 ulp over the range); the inverse is Wichura's algorithm AS 241,
//! PPND16 (M. J. Wichura, "The percentage points of the normal distribution", Applied Statistics
//! 37 (1988) 477–484), relative accuracy about 1e-16. Coefficients as printed in AS 241, read
//! from John Burkardt's C++ transcription `normal_01_cdf_inv` (GNU LGPL) and checked against
//! two further ports (R's `qnorm`, a Java `norminv`).

use std::fmt;

/// The smallest probability mass a truncation interval may keep of its inner distribution. Below
/// it the truncation is almost surely a mistake (an interval in the far tail) and the inverse CDF
/// loses digits: the quantile is found in [F(lo), F(hi)] of the inner CDF, resolved to about
/// 1e-16 absolute.
pub const MIN_TRUNCATED_MASS: f64 = 1e-6;

/// A distribution of an uncertain input (see the module docs for the parameters).
#[derive(Debug, Clone, PartialEq)]
pub enum Distribution {
    /// Normal: mean and standard deviation.
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        sd: f64,
    },
    /// Log-normal: ln X ~ N(ln median, sigma_ln²).
    LogNormal {
        /// Median (> 0), e^μ.
        median: f64,
        /// Standard deviation of ln X (> 0).
        sigma_ln: f64,
    },
    /// Uniform on [lo, hi].
    Uniform {
        /// Lower bound.
        lo: f64,
        /// Upper bound (> lo).
        hi: f64,
    },
    /// Triangular on [lo, hi] with its peak at `mode`.
    Triangular {
        /// Lower bound.
        lo: f64,
        /// Peak, lo ≤ mode ≤ hi.
        mode: f64,
        /// Upper bound (> lo).
        hi: f64,
    },
    /// `inner` restricted to [lo, hi].
    Truncated {
        /// The distribution truncated.
        inner: Box<Distribution>,
        /// Lower truncation bound.
        lo: f64,
        /// Upper truncation bound (> lo).
        hi: f64,
    },
}

/// A distribution refused by [`Distribution::check`]: the field, its value and what is allowed,
/// printed as `sd = -1: must be > 0` (to follow a key path: `oil.viscosity.sd = -1: ...`).
#[derive(Debug, Clone, PartialEq)]
pub struct DistError {
    /// The field's name (`sd`, `hi`, `inner.sd`, ...).
    pub field: String,
    /// The refused value.
    pub value: f64,
    /// What is allowed.
    pub allowed: String,
}

impl fmt::Display for DistError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}: {}", self.field, self.value, self.allowed)
    }
}

impl std::error::Error for DistError {}

fn err(field: &str, value: f64, allowed: impl Into<String>) -> DistError {
    DistError {
        field: field.to_string(),
        value,
        allowed: allowed.into(),
    }
}

fn finite(field: &str, v: f64) -> Result<(), DistError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(err(field, v, "must be a finite number"))
    }
}

fn positive(field: &str, v: f64) -> Result<(), DistError> {
    finite(field, v)?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(err(field, v, "must be > 0"))
    }
}

/// `hi` above `lo` (both finite), named as `hi` with the allowed range.
fn ordered(lo: f64, hi: f64) -> Result<(), DistError> {
    finite("lo", lo)?;
    finite("hi", hi)?;
    if hi > lo {
        Ok(())
    } else if hi == lo {
        Err(err("hi", hi, format!("must be > lo = {lo} (zero width)")))
    } else {
        Err(err("hi", hi, format!("must be > lo = {lo} (bounds reversed)")))
    }
}

/// Standard normal CDF Φ(x) = erfc(−x/√2)/2 (accurate in both tails; 0 and 1 beyond ±38).
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// Horner evaluation of c[0] + c[1]·x + ... + c[7]·x⁷.
fn poly(c: &[f64; 8], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ci| acc * x + ci)
}

/// AS 241 (PPND16) coefficients, with every digit as printed (more than an f64 holds).
#[allow(clippy::excessive_precision)]
mod as241 {
    // AS 241 (PPND16) coefficients: central region |p − 0.5| ≤ 0.425 ...
    pub(super) const A: [f64; 8] = [
        3.387_132_872_796_366_608_0,
        1.331_416_678_917_843_774_5e2,
        1.971_590_950_306_551_442_7e3,
        1.373_169_376_550_946_112_5e4,
        4.592_195_393_154_987_145_7e4,
        6.726_577_092_700_870_085_3e4,
        3.343_057_558_358_812_810_5e4,
        2.509_080_928_730_122_672_7e3,
    ];
    pub(super) const B: [f64; 8] = [
        1.0,
        4.231_333_070_160_091_125_2e1,
        6.871_870_074_920_579_083_0e2,
        5.394_196_021_424_751_107_7e3,
        2.121_379_430_158_659_586_7e4,
        3.930_789_580_009_271_061_0e4,
        2.872_908_573_572_194_267_4e4,
        5.226_495_278_852_854_561_0e3,
    ];
    // ... intermediate tail r = sqrt(−ln q) ≤ 5 ...
    pub(super) const C: [f64; 8] = [
        1.423_437_110_749_683_577_34,
        4.630_337_846_156_545_295_90,
        5.769_497_221_460_691_405_50,
        3.647_848_324_763_204_605_04,
        1.270_458_252_452_368_382_58,
        2.417_807_251_774_506_117_70e-1,
        2.272_384_498_926_918_458_33e-2,
        7.745_450_142_783_414_076_40e-4,
    ];
    pub(super) const D: [f64; 8] = [
        1.0,
        2.053_191_626_637_758_821_87,
        1.676_384_830_183_803_849_40,
        6.897_673_349_851_000_045_50e-1,
        1.481_039_764_274_800_745_90e-1,
        1.519_866_656_361_645_719_66e-2,
        5.475_938_084_995_344_946_00e-4,
        1.050_750_071_644_416_843_24e-9,
    ];
    // ... far tail r > 5.
    pub(super) const E: [f64; 8] = [
        6.657_904_643_501_103_777_20,
        5.463_784_911_164_114_369_90,
        1.784_826_539_917_291_335_80,
        2.965_605_718_285_048_912_30e-1,
        2.653_218_952_657_612_309_30e-2,
        1.242_660_947_388_078_438_60e-3,
        2.711_555_568_743_487_578_15e-5,
        2.010_334_399_292_288_132_65e-7,
    ];
    pub(super) const F: [f64; 8] = [
        1.0,
        5.998_322_065_558_879_376_90e-1,
        1.369_298_809_227_358_053_10e-1,
        1.487_536_129_085_061_485_25e-2,
        7.868_691_311_456_132_591_00e-4,
        1.846_318_317_510_054_681_80e-5,
        1.421_511_758_316_445_888_70e-7,
        2.044_263_103_389_939_785_64e-15,
    ];
}
use as241::{A as AS241_A, B as AS241_B, C as AS241_C, D as AS241_D, E as AS241_E, F as AS241_F};

/// Standard normal quantile Φ⁻¹(p) by AS 241 (PPND16); −∞ at p ≤ 0, +∞ at p ≥ 1, NaN for NaN.
pub fn normal_quantile(p: f64) -> f64 {
    if p.is_nan() {
        return f64::NAN;
    }
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    let q = p - 0.5;
    if q.abs() <= 0.425 {
        let r = 0.180_625 - q * q;
        return q * poly(&AS241_A, r) / poly(&AS241_B, r);
    }
    let tail = if q < 0.0 { p } else { 1.0 - p };
    let r = (-tail.ln()).sqrt();
    let z = if r <= 5.0 {
        let r = r - 1.6;
        poly(&AS241_C, r) / poly(&AS241_D, r)
    } else {
        let r = r - 5.0;
        poly(&AS241_E, r) / poly(&AS241_F, r)
    };
    if q < 0.0 {
        -z
    } else {
        z
    }
}

impl Distribution {
    /// Check the parameters; the error names the field, its value and the allowed range.
    pub fn check(&self) -> Result<(), DistError> {
        match self {
            Distribution::Normal { mean, sd } => {
                finite("mean", *mean)?;
                positive("sd", *sd)
            }
            Distribution::LogNormal { median, sigma_ln } => {
                positive("median", *median)?;
                positive("sigma_ln", *sigma_ln)
            }
            Distribution::Uniform { lo, hi } => ordered(*lo, *hi),
            Distribution::Triangular { lo, mode, hi } => {
                ordered(*lo, *hi)?;
                finite("mode", *mode)?;
                if *mode < *lo || *mode > *hi {
                    return Err(err("mode", *mode, format!("must be in [lo, hi] = [{lo}, {hi}]")));
                }
                Ok(())
            }
            Distribution::Truncated { inner, lo, hi } => {
                if matches!(**inner, Distribution::Truncated { .. }) {
                    return Err(err(
                        "inner",
                        f64::NAN,
                        "a truncated distribution cannot be truncated again",
                    ));
                }
                inner.check().map_err(|e| DistError {
                    field: format!("inner.{}", e.field),
                    ..e
                })?;
                ordered(*lo, *hi)?;
                let mass = inner.cdf(*hi) - inner.cdf(*lo);
                if mass < MIN_TRUNCATED_MASS {
                    return Err(err(
                        "hi",
                        *hi,
                        format!(
                            "the interval [{lo}, {hi}] holds a probability of {mass:.3e} of the inner \
                             distribution (at least {MIN_TRUNCATED_MASS:e} needed)"
                        ),
                    ));
                }
                Ok(())
            }
        }
    }

    /// Inverse CDF at u ∈ (0, 1) (u outside is clamped to the support's ends, which may be
    /// infinite for the unbounded families at u = 0 or 1).
    pub fn quantile(&self, u: f64) -> f64 {
        match self {
            Distribution::Normal { mean, sd } => mean + sd * normal_quantile(u),
            Distribution::LogNormal { median, sigma_ln } => median * (sigma_ln * normal_quantile(u)).exp(),
            Distribution::Uniform { lo, hi } => lo + (hi - lo) * u.clamp(0.0, 1.0),
            Distribution::Triangular { lo, mode, hi } => {
                let u = u.clamp(0.0, 1.0);
                let fc = (mode - lo) / (hi - lo);
                if u < fc {
                    lo + (u * (hi - lo) * (mode - lo)).sqrt()
                } else {
                    hi - ((1.0 - u) * (hi - lo) * (hi - mode)).sqrt()
                }
            }
            Distribution::Truncated { inner, lo, hi } => {
                let (flo, fhi) = (inner.cdf(*lo), inner.cdf(*hi));
                let x = inner.quantile(flo + u.clamp(0.0, 1.0) * (fhi - flo));
                x.clamp(*lo, *hi)
            }
        }
    }

    /// CDF at x.
    pub fn cdf(&self, x: f64) -> f64 {
        match self {
            Distribution::Normal { mean, sd } => normal_cdf((x - mean) / sd),
            Distribution::LogNormal { median, sigma_ln } => {
                if x <= 0.0 {
                    0.0
                } else {
                    normal_cdf((x / median).ln() / sigma_ln)
                }
            }
            Distribution::Uniform { lo, hi } => ((x - lo) / (hi - lo)).clamp(0.0, 1.0),
            Distribution::Triangular { lo, mode, hi } => {
                if x <= *lo {
                    0.0
                } else if x >= *hi {
                    1.0
                } else if x <= *mode {
                    (x - lo).powi(2) / ((hi - lo) * (mode - lo))
                } else {
                    1.0 - (hi - x).powi(2) / ((hi - lo) * (hi - mode))
                }
            }
            Distribution::Truncated { inner, lo, hi } => {
                if x <= *lo {
                    0.0
                } else if x >= *hi {
                    1.0
                } else {
                    let flo = inner.cdf(*lo);
                    (inner.cdf(x) - flo) / (inner.cdf(*hi) - flo)
                }
            }
        }
    }

    /// Mean. Closed forms; a truncated distribution's mean is ∫₀¹ Q(u) du by the midpoint rule on
    /// 2¹⁴ points (Q bounded on a finite truncation; relative error ≲ 1e-6 for the families here).
    pub fn mean(&self) -> f64 {
        match self {
            Distribution::Normal { mean, .. } => *mean,
            Distribution::LogNormal { median, sigma_ln } => median * (0.5 * sigma_ln * sigma_ln).exp(),
            Distribution::Uniform { lo, hi } => 0.5 * (lo + hi),
            Distribution::Triangular { lo, mode, hi } => (lo + mode + hi) / 3.0,
            Distribution::Truncated { .. } => {
                const M: usize = 1 << 14;
                (0..M)
                    .map(|k| self.quantile((k as f64 + 0.5) / M as f64))
                    .sum::<f64>()
                    / M as f64
            }
        }
    }

    /// Support (lo, hi); infinite ends for the normal (both) and log-normal (upper).
    pub fn support(&self) -> (f64, f64) {
        match self {
            Distribution::Normal { .. } => (f64::NEG_INFINITY, f64::INFINITY),
            Distribution::LogNormal { .. } => (0.0, f64::INFINITY),
            Distribution::Uniform { lo, hi }
            | Distribution::Triangular { lo, hi, .. }
            | Distribution::Truncated { lo, hi, .. } => (*lo, *hi),
        }
    }

    /// Human-readable text, e.g. `normal(mean 40, sd 2)`, for summaries and messages.
    pub fn describe(&self) -> String {
        match self {
            Distribution::Normal { mean, sd } => format!("normal(mean {mean}, sd {sd})"),
            Distribution::LogNormal { median, sigma_ln } => {
                format!("lognormal(median {median}, sigma_ln {sigma_ln})")
            }
            Distribution::Uniform { lo, hi } => format!("uniform({lo}, {hi})"),
            Distribution::Triangular { lo, mode, hi } => format!("triangular({lo}, {mode}, {hi})"),
            Distribution::Truncated { inner, lo, hi } => {
                format!("{} truncated to [{lo}, {hi}]", inner.describe())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_quantile_matches_tabulated_points() {
        // Φ⁻¹(0.975) = 1.959963984540054, Φ⁻¹(0.95) = 1.6448536269514722,
        // Φ⁻¹(1e-10) = -6.361340902404056 (values of the standard normal table, to 16 digits).
        assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-14);
        assert!((normal_quantile(0.95) - 1.644_853_626_951_472_2).abs() < 1e-14);
        assert!((normal_quantile(1e-10) + 6.361_340_902_404_056).abs() < 1e-12);
        assert_eq!(normal_quantile(0.5), 0.0);
    }

    #[test]
    fn quantile_and_cdf_round_trip_for_every_family() {
        let dists = [
            Distribution::Normal { mean: 40.0, sd: 2.0 },
            Distribution::LogNormal {
                median: 300.0,
                sigma_ln: 0.3,
            },
            Distribution::Uniform { lo: 0.7, hi: 1.3 },
            Distribution::Triangular {
                lo: 0.5,
                mode: 0.8,
                hi: 1.0,
            },
            Distribution::Truncated {
                inner: Box::new(Distribution::Normal { mean: 1.0, sd: 0.5 }),
                lo: 0.2,
                hi: 1.1,
            },
        ];
        for d in &dists {
            d.check().unwrap();
            for k in 1..200 {
                let u = k as f64 / 200.0;
                let x = d.quantile(u);
                let (lo, hi) = d.support();
                assert!(x > lo && x < hi, "{d:?}: {x}");
                assert!((d.cdf(x) - u).abs() < 1e-12, "{d:?} at u = {u}: {}", d.cdf(x));
            }
        }
    }

    #[test]
    fn truncated_normal_mean_matches_the_closed_form() {
        // E[X | a ≤ X ≤ b] = μ + σ (φ(α) − φ(β)) / (Φ(β) − Φ(α)), α = (a−μ)/σ, β = (b−μ)/σ.
        let (mu, sd, a, b) = (1.0_f64, 0.5_f64, 0.2_f64, 1.1_f64);
        let phi = |z: f64| (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let (al, be) = ((a - mu) / sd, (b - mu) / sd);
        let exact = mu + sd * (phi(al) - phi(be)) / (normal_cdf(be) - normal_cdf(al));
        let d = Distribution::Truncated {
            inner: Box::new(Distribution::Normal { mean: mu, sd }),
            lo: a,
            hi: b,
        };
        assert!((d.mean() - exact).abs() < 1e-7, "{} vs {exact}", d.mean());
    }

    #[test]
    fn bad_distributions_are_refused_naming_the_field() {
        let cases: [(Distribution, &str); 7] = [
            (
                Distribution::Normal { mean: 1.0, sd: -1.0 },
                "sd = -1: must be > 0",
            ),
            (
                Distribution::LogNormal {
                    median: -2.0,
                    sigma_ln: 0.1,
                },
                "median = -2: must be > 0",
            ),
            (
                Distribution::Uniform { lo: 2.0, hi: 1.0 },
                "hi = 1: must be > lo = 2 (bounds reversed)",
            ),
            (Distribution::Uniform { lo: 1.0, hi: 1.0 }, "(zero width)"),
            (
                Distribution::Triangular {
                    lo: 0.0,
                    mode: 2.0,
                    hi: 1.0,
                },
                "mode = 2: must be in [lo, hi]",
            ),
            (
                Distribution::Truncated {
                    inner: Box::new(Distribution::Normal { mean: 0.0, sd: 1.0 }),
                    lo: 8.0,
                    hi: 9.0,
                },
                "holds a probability of",
            ),
            (
                Distribution::Truncated {
                    inner: Box::new(Distribution::Normal { mean: 0.0, sd: 0.0 }),
                    lo: 0.0,
                    hi: 1.0,
                },
                "inner.sd = 0: must be > 0",
            ),
        ];
        for (d, want) in cases {
            let e = d.check().unwrap_err().to_string();
            assert!(e.contains(want), "{d:?}: {e}");
        }
    }
}
