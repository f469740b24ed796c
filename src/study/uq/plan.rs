//! The sampling plan of an uncertainty study: every uncertain input checked against its
//! distribution's rules and against the model (the key path exists, the values the distribution
//! reaches are values the model accepts), then quasi-random points (scrambled Sobol' sequence)
//! turned into values by each input's inverse CDF: rank correlations by Iman–Conover, a
//! calibration's covariance as an exact multivariate normal, or Saltelli's design for Sobol
//! indices.
//!
//! A distribution whose 10⁻⁶ or 1 − 10⁻⁶ quantile (its ends, when bounded) the model refuses is
//! refused before any case runs: the message names the key path and the value, and asks for a
//! truncation. A sample beyond those quantiles that the model refuses is a case with status
//! `invalid`, counted in the summary.

use std::path::Path;

use toml::Value;

use crate::job::{self, JobError};
use crate::model::{overrides, KeyPath, Override};
use crate::report::study::ParamValue;

use super::spec::{CalibrationSpec, DistName, InputSpec, UncertaintySpec};
use super::stats::dist::{normal_quantile, Distribution};
use super::stats::{correlation, lowdisc, sobol};
use crate::study::spec::{ParamSpec, Plan, Sampling};

/// Largest number of samples (N) an uncertainty study may ask for.
pub const MAX_UQ_SAMPLES: usize = 1_000_000;

/// Largest number of model runs an uncertainty study may make (N for a plain plan, N(d + 2) for
/// Saltelli's design): each keeps its band time series in memory (about 16 kB).
pub const MAX_UQ_RUNS: usize = 2_000_000;

/// The quantiles probed against the model's own range checks.
pub const PROBE_QUANTILES: [f64; 2] = [1e-6, 1.0 - 1e-6];

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

/// An input after its checks.
struct Checked {
    path: KeyPath,
    dist: Distribution,
    relative: bool,
}

/// The base model with one override, as the model checks it.
fn probe(base: &toml::Table, file: &Path, path: &KeyPath, value: Value) -> Result<(), JobError> {
    let ov = Override {
        path: path.clone(),
        value,
    };
    job::Model::from_document(base.clone(), file, &[ov]).map(|_| ())
}

fn first_line(e: &JobError) -> String {
    let problems: Vec<String> = e.problems.iter().map(|p| p.to_string()).collect();
    if problems.is_empty() {
        e.message.lines().last().unwrap_or("").trim().to_string()
    } else {
        problems.join("; ")
    }
}

/// The distribution an input names, with exactly its family's parameters given.
fn distribution(i: &InputSpec) -> Result<Distribution, String> {
    let keys = i.dist.keys();
    let mut vals = Vec::new();
    for (key, v) in i.given() {
        match (keys.contains(&key), v) {
            (true, Some(x)) => vals.push(x),
            (true, None) => return Err(format!("{} needs `{key}` ({})", i.dist.as_str(), keys.join(", "))),
            (false, Some(_)) => {
                return Err(format!(
                    "`{key}` is not a parameter of {} ({})",
                    i.dist.as_str(),
                    keys.join(", ")
                ))
            }
            (false, None) => {}
        }
    }
    let d = match i.dist {
        DistName::Normal => Distribution::Normal {
            mean: vals[0],
            sd: vals[1],
        },
        DistName::Lognormal => Distribution::LogNormal {
            median: vals[0],
            sigma_ln: vals[1],
        },
        DistName::Uniform => Distribution::Uniform {
            lo: vals[0],
            hi: vals[1],
        },
        DistName::Triangular => Distribution::Triangular {
            lo: vals[0],
            mode: vals[1],
            hi: vals[2],
        },
    };
    d.check().map_err(|e| e.to_string())?;
    let Some([lo, hi]) = i.truncate else { return Ok(d) };
    let t = Distribution::Truncated {
        inner: Box::new(d),
        lo,
        hi,
    };
    t.check().map_err(|e| format!("truncate: {e}"))?;
    Ok(t)
}

/// Every number of a value (a number or a nested array of numbers).
fn numbers(v: &Value, out: &mut Vec<f64>) -> bool {
    match v {
        Value::Integer(i) => out.push(*i as f64),
        Value::Float(x) => out.push(*x),
        Value::Array(a) => return a.iter().all(|x| numbers(x, out)),
        _ => return false,
    }
    true
}

/// The model value an input sets at the sampled number `x`.
fn value_at(c: &Checked, base_value: Option<&Value>, x: f64) -> Result<Value, String> {
    match (c.relative, base_value) {
        (true, Some(b)) => super::super::scaled(b, x),
        (true, None) => Err("a relative input needs a value in the model to scale".into()),
        (false, Some(Value::Integer(_))) => Ok(Value::Integer(x.round() as i64)),
        (false, _) => Ok(Value::Float(x)),
    }
}

/// An absolute log-normal on a quantity the model accepts negative, or a relative one on a
/// model value that is not positive, is refused: a log-normal value is always positive.
fn check_lognormal(c: &Checked, base: &toml::Table, file: &Path, bv: Option<&Value>) -> Result<(), String> {
    let mut xs = Vec::new();
    if c.relative {
        if bv.is_some_and(|b| numbers(b, &mut xs)) && xs.iter().any(|&x| x <= 0.0) {
            return Err(
                "a log-normal factor on a model value that is not positive (the value may be ≤ 0)".into(),
            );
        }
        return Ok(());
    }
    if bv.is_some_and(|b| numbers(b, &mut xs)) && xs.iter().any(|&x| x <= 0.0) {
        return Err(format!("a log-normal on a value the model has ≤ 0 ({})", xs[0]));
    }
    if probe(base, file, &c.path, Value::Float(-1.0)).is_ok() {
        return Err(
            "a log-normal on a value that may be negative (the model accepts -1 here); \
                    use a normal, uniform or triangular distribution, or a truncated one"
                .into(),
        );
    }
    Ok(())
}

/// One input checked: its key path parses and exists (or the model's schema takes it), its
/// distribution is well formed, the values it reaches are values the model accepts.
fn check_input(i: &InputSpec, base: &toml::Table, file: &Path) -> Result<Checked, String> {
    let path: KeyPath = i.path.parse().map_err(|e| format!("key path: {e}"))?;
    let dist = distribution(i)?;
    let bv = overrides::get(base, &path).ok();
    if bv.is_none() && i.relative {
        return Err("not in the model (a relative input scales the model's value)".into());
    }
    let c = Checked {
        path,
        dist,
        relative: i.relative,
    };
    if i.dist == DistName::Lognormal {
        check_lognormal(&c, base, file, bv.as_ref())?;
    }
    for q in PROBE_QUANTILES {
        let x = c.dist.quantile(q);
        let v = value_at(&c, bv.as_ref(), x)?;
        probe(base, file, &c.path, v).map_err(|e| {
            let what = if bv.is_none() {
                "the key path is not in the model or "
            } else {
                ""
            };
            format!(
                "{what}the model refuses the value {x} (the distribution's {q} quantile): {}; \
                 narrow the distribution or truncate it to the allowed range (truncate = [lo, hi])",
                first_line(&e)
            )
        })?;
    }
    Ok(c)
}

/// A calibration's block checked: the fitted coordinates' mean and Cholesky factor.
struct Calibrated {
    paths: Vec<KeyPath>,
    log: Vec<bool>,
    mean: Vec<f64>,
    chol: Vec<Vec<f64>>,
}

fn check_calibration(c: &CalibrationSpec) -> Result<Calibrated, String> {
    let d = c.parameters.len();
    if d == 0 || c.scale.len() != d || c.value.len() != d || c.covariance.len() != d {
        return Err(format!(
            "parameters, scale, value and covariance need one entry per parameter ({d} parameters)"
        ));
    }
    let mut paths = Vec::with_capacity(d);
    let mut log = Vec::with_capacity(d);
    let mut mean = Vec::with_capacity(d);
    for k in 0..d {
        let p: KeyPath = c.parameters[k]
            .parse()
            .map_err(|e| format!("parameters[{k}]: {e}"))?;
        let is_log = match c.scale[k].as_str() {
            "log" => true,
            "linear" => false,
            s => return Err(format!("scale[{k}] = {s:?}: must be \"log\" or \"linear\"")),
        };
        let v = c.value[k];
        if !v.is_finite() || (is_log && v <= 0.0) {
            return Err(format!("value[{k}] = {v}: must be finite (> 0 on a log scale)"));
        }
        if c.covariance[k].len() != d || c.covariance[k].iter().any(|x| !x.is_finite()) {
            return Err(format!(
                "covariance row {k} ({}): {d} finite numbers needed (nan: the fit could not identify the parameter; \
                 fix it or leave it out)",
                c.parameters[k]
            ));
        }
        paths.push(p);
        log.push(is_log);
        mean.push(if is_log { v.ln() } else { v });
    }
    let symmetric = (0..d).all(|i| {
        (0..d).all(|j| {
            let (a, b) = (c.covariance[i][j], c.covariance[j][i]);
            (a - b).abs() <= 1e-9 * (a.abs() + b.abs()).max(f64::MIN_POSITIVE)
        })
    });
    if !symmetric {
        return Err("covariance: not symmetric".into());
    }
    let chol = correlation::cholesky(&c.covariance)
        .map_err(|e| format!("covariance: not positive definite ({e})"))?;
    Ok(Calibrated {
        paths,
        log,
        mean,
        chol,
    })
}

impl Calibrated {
    /// Model values of the parameters at standard-normal scores z.
    fn values(&self, z: &[f64]) -> Vec<f64> {
        (0..self.mean.len())
            .map(|i| {
                let t = self.mean[i] + (0..=i).map(|k| self.chol[i][k] * z[k]).sum::<f64>();
                if self.log[i] {
                    t.exp()
                } else {
                    t
                }
            })
            .collect()
    }

    /// Every parameter at ±4.75 standard deviations (the 10⁻⁶ quantiles) accepted by the model.
    fn probe(&self, base: &toml::Table, file: &Path) -> Result<(), String> {
        let z = normal_quantile(PROBE_QUANTILES[1]);
        for i in 0..self.mean.len() {
            let sd = self.chol[i][..=i].iter().map(|x| x * x).sum::<f64>().sqrt();
            for s in [-z, z] {
                let t = self.mean[i] + s * sd;
                let x = if self.log[i] { t.exp() } else { t };
                probe(base, file, &self.paths[i], Value::Float(x)).map_err(|e| {
                    format!(
                        "parameters[{i}]: the model refuses the value {x} (mean ± 4.75 sd): {}",
                        first_line(&e)
                    )
                })?;
            }
        }
        Ok(())
    }
}

/// The rank-correlation matrix of the inputs from `[[uncertainty.correlations]]`, checked.
fn correlation_matrix(u: &UncertaintySpec) -> Result<Option<Vec<Vec<f64>>>, String> {
    if u.correlations.is_empty() {
        return Ok(None);
    }
    let d = u.inputs.len();
    let mut m: Vec<Vec<f64>> = (0..d)
        .map(|i| (0..d).map(|j| f64::from(u8::from(i == j))).collect())
        .collect();
    let index = |p: &str, k: usize| {
        u.inputs
            .iter()
            .position(|i| i.path == p)
            .ok_or_else(|| format!("uncertainty.correlations[{k}]: `{p}` is not an uncertain input"))
    };
    for (k, c) in u.correlations.iter().enumerate() {
        let (a, b) = (index(&c.between[0], k)?, index(&c.between[1], k)?);
        if a == b || !(c.rank > -1.0 && c.rank < 1.0) {
            return Err(format!(
                "uncertainty.correlations[{k}] ({} ~ {}): rank = {}: must lie in (-1, 1) between two different inputs",
                c.between[0], c.between[1], c.rank
            ));
        }
        m[a][b] = c.rank;
        m[b][a] = c.rank;
    }
    correlation::check_correlation(&m).map_err(|e| {
        format!("uncertainty.correlations: the rank correlation matrix is not a correlation matrix: {e}")
    })?;
    Ok(Some(m))
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

/// Check `[uncertainty]` against the base model and draw the plan's samples.
pub fn expand(
    u: &UncertaintySpec,
    s: &Sampling,
    base: &toml::Table,
    file: &Path,
) -> Result<Expanded, JobError> {
    let invalid = JobError::invalid;
    let mut checked = Vec::new();
    let mut inputs = Vec::new();
    let mut params = Vec::new();
    for (k, i) in u.inputs.iter().enumerate() {
        let c = check_input(i, base, file)
            .map_err(|e| invalid(format!("uncertainty.inputs[{k}] ({}): {e}", i.path)))?;
        inputs.push(info(i, &c.dist));
        params.push(param(&i.path, i.relative));
        checked.push(c);
    }
    let cal = match &u.calibration {
        Some(c) => {
            let k = check_calibration(c).map_err(|e| invalid(format!("uncertainty.calibration: {e}")))?;
            k.probe(base, file)
                .map_err(|e| invalid(format!("uncertainty.calibration: {e}")))?;
            for (i, p) in c.parameters.iter().enumerate() {
                let sd = c.covariance[i][i].sqrt();
                let coord = if k.log[i] { "ln p" } else { "p" };
                let z = normal_quantile(0.95);
                let at = |t: f64| if k.log[i] { t.exp() } else { t };
                let mean = if k.log[i] {
                    (k.mean[i] + 0.5 * sd * sd).exp()
                } else {
                    k.mean[i]
                };
                inputs.push(InputInfo {
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
                });
                params.push(param(p, false));
            }
            Some(k)
        }
        None => None,
    };
    let d = params.len();
    if d == 0 {
        return Err(JobError::invalid(
            "uncertainty: no uncertain inputs ([[uncertainty.inputs]] or a calibration)",
        ));
    }
    if let Some((a, b)) = first_duplicate(&params) {
        return Err(invalid(format!(
            "uncertainty: `{}` is sampled twice (inputs and calibration parameters {a} and {b}); each key path once",
            params[b].path
        )));
    }
    let corr = correlation_matrix(u).map_err(invalid)?;
    let design = design(
        s,
        d,
        corr.is_some() || cal.as_ref().is_some_and(|c| c.mean.len() > 1),
    )
    .map_err(invalid)?;
    let nu = checked.len();
    let u_rows = points(design, d, s.seed, corr.as_deref(), nu).map_err(invalid)?;
    let samples = values(&checked, cal.as_ref(), &u_rows, base);
    let samples = samples.map_err(invalid)?;
    Ok(Expanded {
        params,
        samples,
        design,
        inputs,
    })
}

fn first_duplicate(params: &[ParamSpec]) -> Option<(usize, usize)> {
    let paths: Vec<Option<KeyPath>> = params.iter().map(|p| p.path.parse().ok()).collect();
    (0..paths.len()).find_map(|b| {
        (0..b)
            .find(|&a| paths[a].is_some() && paths[a] == paths[b])
            .map(|a| (a, b))
    })
}

/// The sampled numbers (a relative input's factor, every other input's value).
fn values(
    checked: &[Checked],
    cal: Option<&Calibrated>,
    u: &[Vec<f64>],
    _base: &toml::Table,
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
