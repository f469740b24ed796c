//! The sampling plan of an uncertainty study: the uncertain inputs, checked by the model layer
//! ([`crate::model::uncertainty::check`]: key paths, distributions, correlations, the values
//! the model accepts), turned into quasi-random points (scrambled Sobol' sequence) by each
//! input's inverse CDF: rank correlations by Iman–Conover, a calibration's covariance as an
//! exact multivariate normal, or Saltelli's design for Sobol indices.
//!
//! A sample beyond the probed quantiles that the model refuses is a case with status
//! `invalid`, counted in the summary.

use std::path::Path;

use crate::job::{ErrorKind, JobError};
use crate::model::uncertainty::{self, CheckedCalibration, CheckedInput, InputSpec, UncertaintySpec};
use crate::model::Problem;
use crate::report::study::ParamValue;

use super::stats::dist::{normal_quantile, Distribution};
use super::stats::{correlation, lowdisc, sobol};
use crate::study::spec::{ParamSpec, Plan, Sampling};

pub use crate::model::uncertainty::{MAX_UQ_RUNS, MAX_UQ_SAMPLES, PROBE_QUANTILES};

/// How the samples are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Design {
    /// N quasi-random samples.
    Qmc {
        /// Samples.
        n: usize,
    },
    /// Saltelli's design: N base points, rows A, B and the d mixed matrices A_B^(i).
    Saltelli {
        /// Base points.
        n: usize,
        /// Inputs.
        d: usize,
    },
}

impl Design {
    /// Whether a sample is an independent draw of the inputs (every Qmc sample; the rows A and B
    /// of Saltelli's design, not its mixed rows): the bands and probabilities use these only.
    pub fn is_draw(self, sample: usize) -> bool {
        match self {
            Design::Qmc { .. } => true,
            Design::Saltelli { d, .. } => sample % (d + 2) < 2,
        }
    }
}

/// One sampled quantity as the summary shows it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InputInfo {
    /// Key path.
    pub path: String,
    /// Column of the study table (`path (scale)` for a factor).
    pub column: String,
    /// The distribution (`normal(mean 60, sd 4)`, `factor lognormal(...)`, `calibrated ...`).
    pub distribution: String,
    /// The assumption behind it.
    pub note: String,
    /// The sampled number's mean (a factor's, for a relative input).
    pub mean: f64,
    /// Its 5th percentile.
    pub p05: f64,
    /// Its 95th percentile.
    pub p95: f64,
}

/// The expanded plan: the study's parameters (one per sampled quantity), their values per
/// sample, the design.
#[derive(Debug, Clone)]
pub struct Expanded {
    /// Parameters in sample order.
    pub params: Vec<ParamSpec>,
    /// One value per parameter per sample.
    pub samples: Vec<Vec<ParamValue>>,
    /// Layout.
    pub design: Design,
    /// What each parameter is.
    pub inputs: Vec<InputInfo>,
}

/// Check the sample count and the design against the limits.
fn design(s: &Sampling, d: usize, correlated: bool) -> Result<Design, String> {
    let n = s.cases.ok_or("sampling.cases: the number of samples is needed")?;
    if n == 0 || n > MAX_UQ_SAMPLES {
        return Err(format!(
            "sampling.cases (samples) = {n}: must lie in [1, {MAX_UQ_SAMPLES}]"
        ));
    }
    match s.plan {
        Plan::Saltelli => {
            if correlated {
                return Err("sampling.plan = saltelli: Sobol indices need independent inputs; \
                            remove the correlations (and the calibration's covariance) or sample without Sobol indices"
                    .into());
            }
            let runs = n.checked_mul(d + 2).filter(|&r| r <= MAX_UQ_RUNS);
            runs.ok_or_else(|| {
                format!(
                    "sampling.cases (samples) = {n}: N(d + 2) = {n}·{} runs, more than {MAX_UQ_RUNS}",
                    d + 2
                )
            })?;
            Ok(Design::Saltelli { n, d })
        }
        _ => Ok(Design::Qmc { n }),
    }
}

/// The uniform points of the design, one row per run, `d` columns in (0, 1).
fn points(
    design: Design,
    d: usize,
    seed: u64,
    corr: Option<&[Vec<f64>]>,
    nu: usize,
) -> Result<Vec<Vec<f64>>, String> {
    match design {
        Design::Qmc { n } => {
            let mut u = lowdisc::sobol_points(n, d, Some(seed))?;
            if let Some(c) = corr {
                // Iman–Conover on the inputs' columns (a calibration's are jointly normal).
                let mut sub: Vec<Vec<f64>> = u.iter().map(|r| r[..nu].to_vec()).collect();
                correlation::rank_correlate(&mut sub, c)?;
                for (r, s) in u.iter_mut().zip(sub) {
                    r[..nu].copy_from_slice(&s);
                }
            }
            Ok(u)
        }
        Design::Saltelli { n, d } => {
            let base = lowdisc::sobol_points(n, 2 * d, Some(seed))?;
            Ok(sobol::saltelli_rows(&base, d))
        }
    }
}

fn info(i: &InputSpec, dist: &Distribution) -> InputInfo {
    InputInfo {
        path: i.path.clone(),
        column: if i.relative {
            format!("{} (scale)", i.path)
        } else {
            i.path.clone()
        },
        distribution: if i.relative {
            format!("factor {}", dist.describe())
        } else {
            dist.describe()
        },
        note: i.note.clone().unwrap_or_default(),
        mean: dist.mean(),
        p05: dist.quantile(0.05),
        p95: dist.quantile(0.95),
    }
}

fn param(path: &str, factors: bool) -> ParamSpec {
    ParamSpec {
        path: path.to_string(),
        values: None,
        range: None,
        scale: None,
        levels: None,
        factors,
    }
}

/// The problems of `[uncertainty]` as one invalid-input error: one line per problem, each
/// naming its key path, value and what is allowed.
fn uncertainty_error(problems: Vec<Problem>) -> JobError {
    let lines: Vec<String> = problems.iter().map(Problem::to_string).collect();
    JobError {
        kind: ErrorKind::Model,
        message: lines.join("\n"),
        problems,
        io_kind: None,
        file: None,
    }
}

/// What the summary shows of a calibration's parameters.
fn calibration_info(names: &[String], k: &CheckedCalibration) -> Vec<InputInfo> {
    let z = normal_quantile(0.95);
    names
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let sd = k.sd(i);
            let coord = if k.log[i] { "ln p" } else { "p" };
            let at = |t: f64| if k.log[i] { t.exp() } else { t };
            let mean = if k.log[i] {
                (k.mean[i] + 0.5 * sd * sd).exp()
            } else {
                k.mean[i]
            };
            InputInfo {
                path: p.clone(),
                column: p.clone(),
                distribution: format!(
                    "calibrated: {coord} ~ normal(mean {}, sd {sd:.4}), jointly with the covariance",
                    k.mean[i]
                ),
                note: "calibration covariance".into(),
                mean,
                p05: at(k.mean[i] - z * sd),
                p95: at(k.mean[i] + z * sd),
            }
        })
        .collect()
}

/// Check `[uncertainty]` against the base model and draw the plan's samples.
pub fn expand(
    u: &UncertaintySpec,
    s: &Sampling,
    base: &toml::Table,
    file: &Path,
) -> Result<Expanded, JobError> {
    let checked = uncertainty::check(u, base, file).map_err(uncertainty_error)?;
    let mut inputs: Vec<InputInfo> = u
        .inputs
        .iter()
        .zip(&checked.inputs)
        .map(|(i, c)| info(i, &c.dist))
        .collect();
    let mut params: Vec<ParamSpec> = u.inputs.iter().map(|i| param(&i.path, i.relative)).collect();
    if let (Some(spec), Some(k)) = (&u.calibration, &checked.calibration) {
        inputs.extend(calibration_info(&spec.parameters, k));
        params.extend(spec.parameters.iter().map(|p| param(p, false)));
    }
    let d = params.len();
    let cal = checked.calibration.as_ref();
    let correlated = checked.correlation.is_some() || cal.is_some_and(|c| c.mean.len() > 1);
    let design = design(s, d, correlated).map_err(JobError::invalid)?;
    let nu = checked.inputs.len();
    let u_rows = points(design, d, s.seed, checked.correlation.as_deref(), nu).map_err(JobError::invalid)?;
    let samples = values(&checked.inputs, cal, &u_rows).map_err(JobError::invalid)?;
    Ok(Expanded {
        params,
        samples,
        design,
        inputs,
    })
}

/// The sampled numbers (a relative input's factor, every other input's value).
fn values(
    checked: &[CheckedInput],
    cal: Option<&CheckedCalibration>,
    u: &[Vec<f64>],
) -> Result<Vec<Vec<ParamValue>>, String> {
    let nu = checked.len();
    u.iter()
        .map(|row| {
            let mut out: Vec<ParamValue> = checked
                .iter()
                .zip(row)
                .map(|(c, &x)| ParamValue::Number(c.dist.quantile(x)))
                .collect();
            if let Some(c) = cal {
                let z: Vec<f64> = row[nu..].iter().map(|&x| normal_quantile(x)).collect();
                out.extend(c.values(&z).into_iter().map(ParamValue::Number));
            }
            if out
                .iter()
                .any(|v| matches!(v, ParamValue::Number(x) if !x.is_finite()))
            {
                return Err("a sampled value is not finite".to_string());
            }
            Ok(out)
        })
        .collect()
}
