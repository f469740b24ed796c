//! `[uncertainty]`: uncertain inputs as written — a distribution on a model key path, optional
//! rank correlations, a calibrated model's covariance, a sample count — and their checks. The
//! same table is read from a model file (`geartherm check` checks it fully, `geartherm uq`
//! samples it) and from a study file (`[sampling] plan = "qmc"` or `"saltelli"`); the Python
//! binding sends it as JSON.
//!
//! ```toml
//! [uncertainty]
//! samples = 1024               # optional: the default of `geartherm uq --samples`
//!
//! [[uncertainty.inputs]]
//! path = "lubrication.oil_level_mm"
//! dist = "normal"              # normal | lognormal | uniform | triangular
//! mean = 60.0
//! sd = 4.0
//! truncate = [45.0, 75.0]      # optional, any distribution
//! note = "dipstick tolerance"  # the assumption behind it (shown in the summary)
//!
//! [[uncertainty.inputs]]
//! path = 'thermal.links["housing-air"].h_table.h_w_per_m2k'
//! dist = "lognormal"
//! median = 1.0
//! sigma_ln = 0.25
//! relative = true              # a factor on the model's value (a number or an array)
//!
//! [[uncertainty.correlations]]
//! between = ["lubrication.oil_level_mm", 'thermal.links["housing-air"].h_table.h_w_per_m2k']
//! rank = 0.3                   # Spearman rank correlation (Iman–Conover)
//! ```
//!
//! - [`check_spec`] (run by the model's validation, every command): each input's key path
//!   parses, its distribution has exactly its family's parameters and they are in range, each
//!   key path once, the rank correlations form a positive definite matrix, the calibration's
//!   covariance is symmetric positive definite, the sample count is in range;
//! - [`against::check`] (`geartherm check`, `geartherm uq`): besides, each key path exists in
//!   the model (or its schema takes it), a log-normal is not put on a value that may be
//!   negative, and the model accepts the values each distribution reaches;
//! - [`dist`]: the distributions (check, quantile, CDF); [`matrix`]: correlation checks and
//!   the Cholesky factor.
//!
//! Every problem names its key path in the file (`uncertainty.inputs[0].sd`), the value and
//! what is allowed, with the input's model key path.

pub mod against;
pub mod dist;
pub mod matrix;
mod spec_checks;

pub use against::{check, CheckedInput, CheckedUncertainty};
pub use spec_checks::{check_samples, check_spec, CheckedCalibration};

use serde::{Deserialize, Serialize};

/// `[uncertainty]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct UncertaintySpec {
    /// The uncertain inputs.
    #[serde(default)]
    pub inputs: Vec<InputSpec>,
    /// Rank correlations between inputs (pairs not named are uncorrelated).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub correlations: Vec<CorrelationSpec>,
    /// A calibration's fitted parameters with their covariance (multivariate normal).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<CalibrationSpec>,
    /// Samples N (the default of `geartherm uq --samples`; Saltelli's design: base points).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<usize>,
}

/// Largest number of samples (N) an uncertainty study may ask for.
pub const MAX_UQ_SAMPLES: usize = 1_000_000;

/// Largest number of model runs an uncertainty study may make (N for a plain plan, N(d + 2) for
/// Saltelli's design): each keeps its band time series in memory (about 16 kB).
pub const MAX_UQ_RUNS: usize = 2_000_000;

/// The quantiles probed against the model's own range checks.
pub const PROBE_QUANTILES: [f64; 2] = [1e-6, 1.0 - 1e-6];

/// The distribution families.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DistName {
    /// `mean`, `sd`.
    Normal,
    /// `median`, `sigma_ln` (the standard deviation of ln x).
    Lognormal,
    /// `lo`, `hi`.
    Uniform,
    /// `lo`, `mode`, `hi`.
    Triangular,
}

impl DistName {
    /// The parameters of the family, by key.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            DistName::Normal => &["mean", "sd"],
            DistName::Lognormal => &["median", "sigma_ln"],
            DistName::Uniform => &["lo", "hi"],
            DistName::Triangular => &["lo", "mode", "hi"],
        }
    }

    /// Name as written.
    pub fn as_str(self) -> &'static str {
        match self {
            DistName::Normal => "normal",
            DistName::Lognormal => "lognormal",
            DistName::Uniform => "uniform",
            DistName::Triangular => "triangular",
        }
    }
}

/// `[[uncertainty.inputs]]`: one uncertain value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputSpec {
    /// Key path in the model (as `--set` and study files write it).
    pub path: String,
    /// Distribution family.
    pub dist: DistName,
    /// Normal: mean.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean: Option<f64>,
    /// Normal: standard deviation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sd: Option<f64>,
    /// Log-normal: median (e^μ).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub median: Option<f64>,
    /// Log-normal: standard deviation of ln x.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_ln: Option<f64>,
    /// Uniform, triangular: lower end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lo: Option<f64>,
    /// Triangular: mode.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode: Option<f64>,
    /// Uniform, triangular: upper end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hi: Option<f64>,
    /// Truncation to [lo, hi] (any family).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truncate: Option<[f64; 2]>,
    /// The distribution is of a factor multiplying the model's value (a number or an array of
    /// numbers, all scaled together).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub relative: bool,
    /// The assumption behind the distribution (free text).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl InputSpec {
    /// The parameters given, by key (for the check that exactly the family's are given).
    pub fn given(&self) -> [(&'static str, Option<f64>); 7] {
        [
            ("mean", self.mean),
            ("sd", self.sd),
            ("median", self.median),
            ("sigma_ln", self.sigma_ln),
            ("lo", self.lo),
            ("mode", self.mode),
            ("hi", self.hi),
        ]
    }
}

/// `[[uncertainty.correlations]]`: the rank correlation of two inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CorrelationSpec {
    /// The two inputs' key paths.
    pub between: [String; 2],
    /// Spearman rank correlation in (-1, 1).
    pub rank: f64,
}

/// `[uncertainty.calibration]`: fitted parameters with their covariance, as `geartherm
/// calibrate` writes them at the end of `calibrated.toml`. The parameters are sampled from the
/// multivariate normal N(value, covariance) in their fitted coordinates (ln p for scale `log`,
/// p for `linear`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationSpec {
    /// Key paths.
    pub parameters: Vec<String>,
    /// `log` or `linear`, per parameter.
    pub scale: Vec<String>,
    /// Fitted values (in the model's units, not the coordinate).
    pub value: Vec<f64>,
    /// Covariance in the fitted coordinates.
    pub covariance: Vec<Vec<f64>>,
}

/// The `[calibration]` block `geartherm calibrate` writes as comment lines at the end of
/// `calibrated.toml` (`# [calibration]` and the `# key = value` lines after it), or a
/// `[calibration]` table of a TOML file. None when the text has neither.
pub fn calibration_block(text: &str) -> Result<Option<CalibrationSpec>, String> {
    let doc: Option<toml::Table> = text.parse().ok();
    if let Some(t) = doc.as_ref().and_then(|d| d.get("calibration")) {
        return t
            .clone()
            .try_into()
            .map(Some)
            .map_err(|e: toml::de::Error| e.message().to_string());
    }
    let mut lines = text.lines().skip_while(|l| l.trim() != "# [calibration]");
    if lines.next().is_none() {
        return Ok(None);
    }
    let body: String = lines
        .map_while(|l| l.strip_prefix("# "))
        .map(|l| format!("{l}\n"))
        .collect();
    // Not identifiable entries are written `nan` (a TOML float): refused when checked.
    let table: toml::Table = body
        .parse()
        .map_err(|e: toml::de::Error| format!("the `# [calibration]` block: {}", e.message()))?;
    toml::Value::Table(table)
        .try_into()
        .map(Some)
        .map_err(|e: toml::de::Error| format!("the `# [calibration]` block: {}", e.message()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_comment_block_of_calibrated_toml_reads_back() {
        let text = "[model]\nname = \"x\"\n\n# The fitted parameters' covariance ...\n# nan where not\n\
                    # [calibration]\n# parameters = [\"a.b\", \"c\"]\n# scale = [\"log\", \"linear\"]\n\
                    # value = [2.0, 3.5]\n# covariance = [[0.01, 0.002], [0.002, 0.04]]\n";
        let c = calibration_block(text).unwrap().unwrap();
        assert_eq!(c.parameters, ["a.b", "c"]);
        assert_eq!(c.scale, ["log", "linear"]);
        assert_eq!(c.value, [2.0, 3.5]);
        assert_eq!(c.covariance[1], [0.002, 0.04]);
        assert!(calibration_block("[model]\nname = \"x\"\n").unwrap().is_none());
    }
}
