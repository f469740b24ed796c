//! The checks of `[uncertainty]` that need no model: each input's key path parses, its
//! distribution has exactly its family's parameters and they are in range (sd, sigma_ln > 0,
//! lo < hi, mode in [lo, hi], a truncation keeping at least 1e-6 of the distribution), each key
//! path once, the rank correlations in (−1, 1) forming a positive definite matrix, the
//! calibration's covariance symmetric positive definite, the sample count in
//! [1, [`MAX_UQ_SAMPLES`]].

use super::dist::{DistError, Distribution};
use super::matrix;
use super::{CalibrationSpec, DistName, InputSpec, UncertaintySpec, MAX_UQ_SAMPLES};
use crate::model::{KeyPath, Problems};

/// A problem before it is recorded: key path in the file, value, what is allowed.
pub(super) type Found = (String, String, String);

/// A calibration's block checked: the fitted coordinates' mean and Cholesky factor.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedCalibration {
    /// Key paths of the parameters.
    pub paths: Vec<KeyPath>,
    /// Per parameter: fitted on a log scale (ln p) rather than a linear one (p).
    pub log: Vec<bool>,
    /// The fitted values in their coordinates (ln p or p).
    pub mean: Vec<f64>,
    /// The covariance's lower Cholesky factor.
    pub chol: Vec<Vec<f64>>,
}

impl CheckedCalibration {
    /// Model values of the parameters at standard-normal scores z.
    pub fn values(&self, z: &[f64]) -> Vec<f64> {
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

    /// The standard deviation of parameter i in its coordinate.
    pub fn sd(&self, i: usize) -> f64 {
        self.chol[i][..=i].iter().map(|x| x * x).sum::<f64>().sqrt()
    }
}

/// What the model-free checks found: each input's key path and distribution (None where a
/// check failed), the calibration, the rank-correlation matrix (None: uncorrelated).
pub(super) struct Parts {
    pub inputs: Vec<Option<(KeyPath, Distribution)>>,
    pub calibration: Option<CheckedCalibration>,
    pub correlation: Option<Vec<Vec<f64>>>,
}

/// Every model-free check of `u`; each problem is recorded in `problems`.
pub fn check_spec(u: &UncertaintySpec, problems: &mut Problems) {
    let _ = parts(u, problems);
}

/// A sample count in [1, [`MAX_UQ_SAMPLES`]], named `path` in the problem.
pub fn check_samples(path: &str, n: usize, problems: &mut Problems) -> bool {
    if n == 0 || n > MAX_UQ_SAMPLES {
        problems.push(path, n, format!("must lie in [1, {MAX_UQ_SAMPLES}]"));
        return false;
    }
    true
}

pub(super) fn parts(u: &UncertaintySpec, problems: &mut Problems) -> Parts {
    let mut push = |f: Found| problems.push(f.0, f.1, f.2);
    let inputs = u
        .inputs
        .iter()
        .enumerate()
        .map(|(k, i)| {
            let path = i
                .path
                .parse::<KeyPath>()
                .map_err(|e| push((at(k, "path"), quoted(&i.path), format!("not a key path: {e}"))))
                .ok();
            let dist = distribution(k, i).map_err(&mut push).ok();
            path.zip(dist)
        })
        .collect();
    let calibration = u
        .calibration
        .as_ref()
        .and_then(|c| calibration(c).map_err(&mut push).ok());
    if let Some(f) = duplicate(u) {
        push(f);
    }
    let correlation = correlation_matrix(u).map_err(&mut push).ok().flatten();
    if let Some(n) = u.samples {
        check_samples("uncertainty.samples", n, problems);
    }
    Parts {
        inputs,
        calibration,
        correlation,
    }
}

/// `uncertainty.inputs[k].key`.
pub(super) fn at(k: usize, key: &str) -> String {
    format!("uncertainty.inputs[{k}].{key}")
}

/// A key path as a value: in single quotes (it may hold double quotes).
pub(super) fn quoted(path: &str) -> String {
    format!("'{path}'")
}

/// `(normal on lubrication.oil_level_mm)`: the input a problem is about.
pub(super) fn on(i: &InputSpec) -> String {
    format!("({} on {})", i.dist.as_str(), i.path)
}

/// A distribution's problem at `uncertainty.inputs[k]`: a parameter by its key, a truncation's
/// end as `truncate[0]` / `truncate[1]`.
fn dist_problem(k: usize, i: &InputSpec, e: DistError, truncation: bool) -> Found {
    let key = match (truncation, e.field.as_str()) {
        (true, "lo") => "truncate[0]".to_string(),
        (true, "hi") => "truncate[1]".to_string(),
        (true, _) => "truncate".to_string(),
        (false, f) => f.to_string(),
    };
    (
        at(k, &key),
        e.value.to_string(),
        format!("{} {}", e.allowed, on(i)),
    )
}

/// The distribution input `k` names, with exactly its family's parameters given.
fn distribution(k: usize, i: &InputSpec) -> Result<Distribution, Found> {
    let keys = i.dist.keys();
    let mut vals = Vec::new();
    for (key, v) in i.given() {
        match (keys.contains(&key), v) {
            (true, Some(x)) => vals.push(x),
            (true, None) => {
                return Err((
                    format!("uncertainty.inputs[{k}]"),
                    String::new(),
                    format!(
                        "`{key}` missing: {} needs {} {}",
                        i.dist.as_str(),
                        keys.join(", "),
                        on(i)
                    ),
                ))
            }
            (false, Some(x)) => {
                return Err((
                    at(k, key),
                    x.to_string(),
                    format!(
                        "not a parameter of {} ({}) {}",
                        i.dist.as_str(),
                        keys.join(", "),
                        on(i)
                    ),
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
    d.check().map_err(|e| dist_problem(k, i, e, false))?;
    let Some([lo, hi]) = i.truncate else { return Ok(d) };
    let t = Distribution::Truncated {
        inner: Box::new(d),
        lo,
        hi,
    };
    t.check().map_err(|e| dist_problem(k, i, e, true))?;
    Ok(t)
}

/// A calibration block's shape, values and covariance.
fn calibration(c: &CalibrationSpec) -> Result<CheckedCalibration, Found> {
    let at = |key: &str| format!("uncertainty.calibration.{key}");
    let d = c.parameters.len();
    if d == 0 || c.scale.len() != d || c.value.len() != d || c.covariance.len() != d {
        return Err((
            at("parameters"),
            String::new(),
            format!("parameters, scale, value and covariance need one entry per parameter ({d} parameters)"),
        ));
    }
    let mut out = CheckedCalibration {
        paths: Vec::with_capacity(d),
        log: Vec::with_capacity(d),
        mean: Vec::with_capacity(d),
        chol: Vec::new(),
    };
    for k in 0..d {
        let p: KeyPath = c.parameters[k].parse().map_err(|e| {
            (
                at(&format!("parameters[{k}]")),
                quoted(&c.parameters[k]),
                format!("not a key path: {e}"),
            )
        })?;
        let is_log = match c.scale[k].as_str() {
            "log" => true,
            "linear" => false,
            s => {
                return Err((
                    at(&format!("scale[{k}]")),
                    format!("{s:?}"),
                    "must be \"log\" or \"linear\"".into(),
                ))
            }
        };
        let v = c.value[k];
        if !v.is_finite() || (is_log && v <= 0.0) {
            return Err((
                at(&format!("value[{k}]")),
                v.to_string(),
                "must be finite (> 0 on a log scale)".into(),
            ));
        }
        if c.covariance[k].len() != d || c.covariance[k].iter().any(|x| !x.is_finite()) {
            return Err((
                at(&format!("covariance[{k}]")),
                String::new(),
                format!(
                    "{d} finite numbers needed for {} (nan: the fit could not identify the parameter; \
                     fix it or leave it out)",
                    c.parameters[k]
                ),
            ));
        }
        out.paths.push(p);
        out.log.push(is_log);
        out.mean.push(if is_log { v.ln() } else { v });
    }
    out.chol = covariance_factor(&c.covariance).map_err(|e| (at("covariance"), String::new(), e))?;
    Ok(out)
}

/// The Cholesky factor of a covariance that is symmetric and positive definite.
fn covariance_factor(cov: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, String> {
    let d = cov.len();
    let symmetric = (0..d).all(|i| {
        (0..d).all(|j| {
            let (a, b) = (cov[i][j], cov[j][i]);
            (a - b).abs() <= 1e-9 * (a.abs() + b.abs()).max(f64::MIN_POSITIVE)
        })
    });
    if !symmetric {
        return Err("not symmetric".into());
    }
    matrix::cholesky(cov).map_err(|e| format!("not positive definite ({e})"))
}

/// The first key path sampled twice (inputs, then the calibration's parameters).
fn duplicate(u: &UncertaintySpec) -> Option<Found> {
    let mut named: Vec<(String, &str)> = u
        .inputs
        .iter()
        .enumerate()
        .map(|(k, i)| (at(k, "path"), i.path.as_str()))
        .collect();
    if let Some(c) = &u.calibration {
        named.extend(
            c.parameters
                .iter()
                .enumerate()
                .map(|(k, p)| (format!("uncertainty.calibration.parameters[{k}]"), p.as_str())),
        );
    }
    let paths: Vec<Option<KeyPath>> = named.iter().map(|(_, p)| p.parse().ok()).collect();
    (0..paths.len()).find_map(|b| {
        (0..b)
            .find(|&a| paths[a].is_some() && paths[a] == paths[b])
            .map(|a| {
                (
                    named[b].0.clone(),
                    quoted(named[b].1),
                    format!("sampled twice (also {}); each key path once", named[a].0),
                )
            })
    })
}

/// The rank-correlation matrix of the inputs from `[[uncertainty.correlations]]`, checked.
fn correlation_matrix(u: &UncertaintySpec) -> Result<Option<Vec<Vec<f64>>>, Found> {
    if u.correlations.is_empty() {
        return Ok(None);
    }
    let d = u.inputs.len();
    let mut m: Vec<Vec<f64>> = (0..d)
        .map(|i| (0..d).map(|j| f64::from(u8::from(i == j))).collect())
        .collect();
    let index = |p: &str, k: usize, j: usize| {
        u.inputs.iter().position(|i| i.path == p).ok_or_else(|| {
            (
                format!("uncertainty.correlations[{k}].between[{j}]"),
                quoted(p),
                "not the path of an uncertain input ([[uncertainty.inputs]])".to_string(),
            )
        })
    };
    for (k, c) in u.correlations.iter().enumerate() {
        let (a, b) = (index(&c.between[0], k, 0)?, index(&c.between[1], k, 1)?);
        if a == b || !(c.rank > -1.0 && c.rank < 1.0) {
            return Err((
                format!("uncertainty.correlations[{k}].rank"),
                c.rank.to_string(),
                format!(
                    "must lie in (-1, 1) between two different inputs ({} ~ {})",
                    c.between[0], c.between[1]
                ),
            ));
        }
        m[a][b] = c.rank;
        m[b][a] = c.rank;
    }
    matrix::check_correlation(&m).map_err(|e| {
        (
            "uncertainty.correlations".to_string(),
            String::new(),
            format!("the rank correlation matrix is not a correlation matrix: {e}"),
        )
    })?;
    Ok(Some(m))
}
