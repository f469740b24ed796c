//! `[uncertainty]` checked against the model it belongs to: besides the model-free checks
//! ([`super::check_spec`]), each input's key path exists in the model (or the model's schema
//! takes it; a relative input needs a value to scale), a log-normal is not put on a value that
//! may be negative, and the values each distribution reaches are values the model accepts.
//!
//! Each input's distribution is probed against the model's own checks at its 10⁻⁶ and
//! 1 − 10⁻⁶ quantiles ([`PROBE_QUANTILES`]; its ends, when bounded); a calibration's parameters
//! at ±4.75 standard deviations. A value the model refuses is reported with the model's message,
//! and the remedy (a truncation inside the allowed range). Nothing is clipped silently.

use std::path::Path;

use toml::Value;

use super::dist::{normal_quantile, Distribution};
use super::spec_checks::{at, on, parts, quoted, Found};
use super::{CheckedCalibration, DistName, InputSpec, UncertaintySpec, PROBE_QUANTILES};
use crate::model::{self, overrides, KeyPath, ModelError, Override, Problem, Problems};

/// An input after its checks.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedInput {
    /// Key path in the model.
    pub path: KeyPath,
    /// Its distribution (a factor's, for a relative input).
    pub dist: Distribution,
    /// A factor on the model's value.
    pub relative: bool,
}

/// `[uncertainty]` after every check, ready to be sampled.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedUncertainty {
    /// The inputs, in order.
    pub inputs: Vec<CheckedInput>,
    /// The calibration's parameters, if any.
    pub calibration: Option<CheckedCalibration>,
    /// The inputs' rank-correlation matrix (None: independent).
    pub correlation: Option<Vec<Vec<f64>>>,
}

/// Check `u` against the model document `base` (its own `[uncertainty]` is left out of every
/// probe); `file` names the model in the model's messages. Every problem found, else the
/// checked inputs.
pub fn check(
    u: &UncertaintySpec,
    base: &toml::Table,
    file: &Path,
) -> Result<CheckedUncertainty, Vec<Problem>> {
    let mut problems = Problems::default();
    let mut base = base.clone();
    base.remove("uncertainty");
    let parts = parts(u, &mut problems);
    if u.inputs.is_empty() && u.calibration.is_none() {
        problems.push(
            "uncertainty",
            "",
            "no uncertain inputs ([[uncertainty.inputs]] or a calibration)",
        );
    }
    let mut inputs = Vec::with_capacity(u.inputs.len());
    for (k, (i, p)) in u.inputs.iter().zip(parts.inputs).enumerate() {
        let Some((path, dist)) = p else { continue };
        let c = CheckedInput {
            path,
            dist,
            relative: i.relative,
        };
        match probe_input(k, i, &c, &base, file) {
            Ok(()) => inputs.push(c),
            Err(f) => problems.push(f.0, f.1, f.2),
        }
    }
    if let Some(c) = &parts.calibration {
        if let Err(f) = probe_calibration(c, &base, file) {
            problems.push(f.0, f.1, f.2);
        }
    }
    if !problems.is_empty() {
        return Err(problems.into_vec());
    }
    Ok(CheckedUncertainty {
        inputs,
        calibration: parts.calibration,
        correlation: parts.correlation,
    })
}

/// The base model with one override, as the model checks it.
fn probe(base: &toml::Table, file: &Path, path: &KeyPath, value: Value) -> Result<(), String> {
    let ov = Override {
        path: path.clone(),
        value,
    };
    model::from_document_with(base.clone(), file, &[ov])
        .map(|_| ())
        .map_err(|e| first_line(&e))
}

fn first_line(e: &ModelError) -> String {
    match e {
        ModelError::Invalid { problems, .. } => {
            let p: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
            p.join("; ")
        }
        ModelError::Io { .. } => e.to_string(),
    }
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
fn value_at(c: &CheckedInput, base_value: Option<&Value>, x: f64) -> Result<Value, String> {
    match (c.relative, base_value) {
        (true, Some(b)) => overrides::scaled(b, x),
        (true, None) => Err("a relative input needs a value in the model to scale".into()),
        (false, Some(Value::Integer(_))) => Ok(Value::Integer(x.round() as i64)),
        (false, _) => Ok(Value::Float(x)),
    }
}

/// An absolute log-normal on a quantity the model accepts negative, or a relative one on a
/// model value that is not positive, is refused: a log-normal value is always positive.
fn check_lognormal(
    c: &CheckedInput,
    base: &toml::Table,
    file: &Path,
    bv: Option<&Value>,
) -> Result<(), String> {
    let mut xs = Vec::new();
    let non_positive = bv.is_some_and(|b| numbers(b, &mut xs)) && xs.iter().any(|&x| x <= 0.0);
    if c.relative {
        if non_positive {
            return Err(
                "a log-normal factor on a model value that is not positive (the value may be ≤ 0)".into(),
            );
        }
        return Ok(());
    }
    if non_positive {
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

/// Input `k`'s key path exists (or the schema takes it), its log-normal is on a positive
/// value, the values its distribution reaches are values the model accepts.
fn probe_input(
    k: usize,
    i: &InputSpec,
    c: &CheckedInput,
    base: &toml::Table,
    file: &Path,
) -> Result<(), Found> {
    let bv = overrides::get(base, &c.path).ok();
    if bv.is_none() {
        let not_in = |why: String| (at(k, "path"), quoted(&i.path), why);
        if i.relative {
            return Err(not_in(
                "not in the model (a relative input scales the model's value)".into(),
            ));
        }
        let ov = Override {
            path: c.path.clone(),
            value: Value::Float(c.dist.quantile(0.5)),
        };
        model::schema_takes(base.clone(), &ov).map_err(|p| {
            let p: Vec<String> = p.iter().map(|p| p.to_string()).collect();
            not_in(format!("not a key path of the model: {}", p.join("; ")))
        })?;
    }
    if i.dist == DistName::Lognormal {
        check_lognormal(c, base, file, bv.as_ref())
            .map_err(|e| (at(k, "dist"), "\"lognormal\"".into(), format!("{e} {}", on(i))))?;
    }
    for q in PROBE_QUANTILES {
        let x = c.dist.quantile(q);
        let v = value_at(c, bv.as_ref(), x).map_err(|e| (at(k, "path"), quoted(&i.path), e))?;
        probe(base, file, &c.path, v).map_err(|e| {
            (
                format!("uncertainty.inputs[{k}]"),
                x.to_string(),
                format!(
                    "the model refuses this value of {} (the distribution's {q} quantile): {e}; \
                     narrow the distribution or truncate it to the allowed range (truncate = [lo, hi])",
                    i.path
                ),
            )
        })?;
    }
    Ok(())
}

/// Every calibrated parameter at ±4.75 standard deviations (the 10⁻⁶ quantiles) accepted by
/// the model.
fn probe_calibration(c: &CheckedCalibration, base: &toml::Table, file: &Path) -> Result<(), Found> {
    let z = normal_quantile(PROBE_QUANTILES[1]);
    for i in 0..c.mean.len() {
        let sd = c.sd(i);
        for s in [-z, z] {
            let t = c.mean[i] + s * sd;
            let x = if c.log[i] { t.exp() } else { t };
            probe(base, file, &c.paths[i], Value::Float(x)).map_err(|e| {
                (
                    format!("uncertainty.calibration.parameters[{i}]"),
                    x.to_string(),
                    format!(
                        "the model refuses this value of {} (mean ± 4.75 sd): {e}",
                        c.paths[i]
                    ),
                )
            })?;
        }
    }
    Ok(())
}
