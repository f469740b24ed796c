//! The prediction band of a calibrated model on another trace (`--band-from calibration.json`):
//! the previous calibration's covariance of its fitted coordinates carried through the
//! sensitivities on this trace, plus each channel's residual process as that calibration
//! estimated it, and each channel's band multiplier (the same half-width formula as
//! [`super::bands`]; of a calibration over several traces the multiplier of the trace of the
//! same name, else that of every trace's rows together; a `calibration.json` without
//! multipliers gives its t quantile). The model run is the
//! calibrated one (`calibrated.toml`): the parameters are evaluated at the values it holds,
//! except a parameter of one trace in a calibration over several (`KEYPATH@X`), which a
//! prediction of trace X takes at the calibration's value for X (the model file holds one
//! trace's value).

use serde::Deserialize;

use super::bands::Multiplier;
use super::params::{FitSpec, Parameter};
use super::problem::Problem;
use super::residuals::Ar1;
use crate::job::JobError;

#[derive(Deserialize)]
struct JsonParameter {
    key_path: String,
    value: f64,
    lower_bound: f64,
    upper_bound: f64,
    scale: String,
}

#[derive(Deserialize)]
struct JsonNoise {
    phi: f64,
    innovation_sd_k: f64,
    band_multiplier: Option<f64>,
    band_quantile: Option<String>,
}

#[derive(Deserialize)]
struct JsonChannel {
    node: String,
    noise: JsonNoise,
}

#[derive(Deserialize)]
struct JsonTrace {
    name: String,
    channels: Vec<JsonChannel>,
}

#[derive(Deserialize)]
struct JsonFit {
    t975: f64,
}

#[derive(Deserialize)]
struct JsonCalibration {
    parameters: Vec<JsonParameter>,
    covariance: Vec<Vec<Option<f64>>>,
    channels: Vec<JsonChannel>,
    fit: JsonFit,
    #[serde(default)]
    traces: Vec<JsonTrace>,
}

/// A previous calibration's uncertainty, mapped onto this trace.
pub struct BandSource<'a> {
    /// The problem with the previous calibration's parameters.
    pub problem: Problem<'a>,
    /// Their covariance (NaN where the calibration had none).
    pub covariance: Vec<Vec<f64>>,
    /// Each channel's residual process.
    pub noise: Vec<Ar1>,
    /// Each channel's band multiplier.
    pub multipliers: Vec<Multiplier>,
}

/// The calibration's parameters a prediction of trace `name` takes: the shared ones and those of
/// trace `name` (`KEYPATH@name`); with parameters of other traces only, none of `name`'s, the
/// trace's own values are unknown: invalid input naming the trace.
fn parameters_of(c: &JsonCalibration, name: &str, file: &str) -> Result<Vec<usize>, JobError> {
    let owner = |q: &JsonParameter| super::params::split_owner(&q.key_path).1.map(str::to_string);
    let owned: Vec<String> = c.parameters.iter().filter_map(owner).collect();
    if !owned.is_empty() && !owned.iter().any(|o| o == name) {
        let mut traces = owned.clone();
        traces.sort();
        traces.dedup();
        let keys: Vec<&str> = c
            .parameters
            .iter()
            .filter(|q| owner(q).is_some())
            .map(|q| q.key_path.as_str())
            .collect();
        return Err(JobError::invalid(format!(
            "{file}: trace {name}: the calibration fitted parameters per trace ({}) for the traces {}, not for \
             {name}: the band of trace {name} needs its own values' uncertainty (name the trace as the \
             calibration did, or calibrate the parameters shared)",
            keys.join(", "),
            traces.join(", ")
        )));
    }
    Ok((0..c.parameters.len())
        .filter(|&k| owner(&c.parameters[k]).map_or(true, |o| o == name))
        .collect())
}

/// Read a `calibration.json` (`file` names it) and map it onto `base` (this trace's problem
/// without parameters; `name` the trace's name, `KEYPATH@name` its own parameters in a
/// calibration over several traces): every parameter resolved in the model at hand, every
/// measured node of the trace among the calibration's channels; else invalid input naming the
/// file and what is missing.
pub fn band_source<'a>(
    base: &Problem<'a>,
    doc: &toml::Table,
    json: &str,
    file: &str,
    name: &str,
) -> Result<BandSource<'a>, JobError> {
    let bad = |m: String| JobError::invalid(format!("{file}: {m}"));
    let c: JsonCalibration =
        serde_json::from_str(json).map_err(|e| bad(format!("not a calibration.json: {e}")))?;
    let np = c.parameters.len();
    if c.covariance.len() != np || c.covariance.iter().any(|r| r.len() != np) {
        return Err(bad(format!("covariance: must be {np} × {np}")));
    }
    let kept = parameters_of(&c, name, file)?;
    let mut params = Vec::with_capacity(kept.len());
    for &k in &kept {
        let q = &c.parameters[k];
        let key = super::params::split_owner(&q.key_path).0;
        let spec: FitSpec = format!("{key}={}:{}", q.lower_bound, q.upper_bound)
            .parse()
            .map_err(|e: String| bad(format!("parameters[{k}]: {e}")))?;
        let mut p = Parameter::resolve(&spec, doc)
            .map_err(|e| bad(format!("parameters[{k}] ({}): {e}", q.key_path)))?;
        if super::params::split_owner(&q.key_path).1.is_some() {
            // The model file holds one trace's value; trace `name`'s is the calibration's.
            if !(q.value.is_finite() && (q.lower_bound..=q.upper_bound).contains(&q.value)) {
                return Err(bad(format!(
                    "parameters[{k}] ({}): value {} must lie in its bounds [{}, {}]",
                    q.key_path, q.value, q.lower_bound, q.upper_bound
                )));
            }
            p.start = q.value;
        }
        if (q.scale == "log") != p.log {
            return Err(bad(format!(
                "parameters[{k}] ({}): scale {} does not match the model's value {}",
                q.key_path, q.scale, p.start
            )));
        }
        params.push(p);
    }
    let mut noise = Vec::with_capacity(base.trace.measured.len());
    let mut multipliers = Vec::with_capacity(base.trace.measured.len());
    for m in &base.trace.measured {
        let ch = c.channels.iter().find(|x| x.node == m.name).ok_or_else(|| {
            bad(format!(
                "channels: no channel for node {} (column {} of {}): its residual process is unknown",
                m.name, m.column, base.trace.source
            ))
        })?;
        noise.push(Ar1 {
            phi: ch.noise.phi,
            sigma: ch.noise.innovation_sd_k,
        });
        multipliers.push(multiplier_of(&c, ch, name, file)?);
    }
    let covariance = kept
        .iter()
        .map(|&a| {
            kept.iter()
                .map(|&b| c.covariance[a][b].unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let problem = base.with_params(params);
    Ok(BandSource {
        problem,
        covariance,
        noise,
        multipliers,
    })
}

/// Channel `ch`'s band multiplier for trace `name`: that of the calibration's trace of that
/// name, else the channel's, else the calibration's t quantile; invalid input (naming the file)
/// when not a finite number above 0.
fn multiplier_of(
    c: &JsonCalibration,
    ch: &JsonChannel,
    name: &str,
    file: &str,
) -> Result<Multiplier, JobError> {
    let own = c
        .traces
        .iter()
        .filter(|t| t.name == name)
        .flat_map(|t| t.channels.iter())
        .find(|x| x.node == ch.node);
    let noise = &own.unwrap_or(ch).noise;
    let m = match noise.band_multiplier {
        Some(v) => Multiplier {
            value: v,
            empirical: noise.band_quantile.as_deref() == Some("empirical"),
        },
        None => Multiplier::t(c.fit.t975),
    };
    if m.value.is_finite() && m.value > 0.0 {
        Ok(m)
    } else {
        Err(JobError::invalid(format!(
            "{file}: channels ({}): band multiplier {} must be a finite number above 0",
            ch.node, m.value
        )))
    }
}

/// A trace's name from its source: the file's stem (as `calibrate --trace` names it).
pub fn trace_name(source: &str) -> String {
    std::path::Path::new(source)
        .file_stem()
        .map_or_else(|| source.to_string(), |s| s.to_string_lossy().into_owned())
}
