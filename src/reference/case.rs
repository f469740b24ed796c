//! `case.toml` and `reference.csv` of one reference case.

use std::path::{Path, PathBuf};

use super::ReferenceError;
use crate::model::Gearbox;
use crate::scene::Source;

/// Kind of reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// A peer code run on the same inputs.
    Peer,
    /// A standard's or catalogue's worked example.
    Standard,
    /// A published measurement.
    Measurement,
    /// A trend a source reports (a range the metric must fall in).
    Trend,
    /// A handbook's range of values (e.g. typical efficiencies of a kind of gearbox): neither a
    /// measurement of this gearbox nor a model's output; the value must fall in the range.
    Handbook,
    /// A self-consistency check: the project's own formula evaluated by hand, or the model's own
    /// input table. It shows the model runs its formula or table as written, not that either
    /// is right; kept apart from peers, standards and measurements in every summary.
    SelfConsistency,
}

impl Kind {
    /// Lower-case name.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Peer => "peer",
            Kind::Standard => "standard",
            Kind::Measurement => "measurement",
            Kind::Trend => "trend",
            Kind::Handbook => "handbook",
            Kind::SelfConsistency => "self_consistency",
        }
    }

    /// Rows of this kind hold a range check, not a value in watts.
    pub fn is_range(self) -> bool {
        matches!(self, Kind::Trend | Kind::Handbook)
    }
}

pub use super::choices::{Choice, Quantity};

/// A trend metric between two speeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// d ln P / d ln n between the two speeds.
    SpeedExponent,
    /// P(b)/P(a).
    Ratio,
}

impl Metric {
    /// The metric from the powers at speeds a and b.
    pub fn value(self, pa: f64, pb: f64, na: f64, nb: f64) -> f64 {
        match self {
            Metric::SpeedExponent => (pb / pa).ln() / (nb / na).ln(),
            Metric::Ratio => pb / pa,
        }
    }
}

/// One trend check.
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrendCheck {
    /// Label.
    pub point: String,
    /// Metric.
    pub metric: Metric,
    /// Gear state.
    pub gear: String,
    /// Lower input speed, rpm.
    pub speed_a_rpm: f64,
    /// Upper input speed, rpm.
    pub speed_b_rpm: f64,
    /// Input torque, N·m.
    #[serde(default)]
    pub torque_nm: f64,
    /// Oil temperature, °C.
    pub oil_temp_c: f64,
    /// Range the metric must lie in.
    pub low: f64,
    /// Upper end of the range.
    pub high: f64,
    /// Model choices this check is not run with, because for them it cannot fail (the metric
    /// is a constant of the law inside the range); `exclude_reason` says why.
    #[serde(default)]
    pub exclude: Vec<String>,
    /// Why the excluded choices are excluded.
    #[serde(default)]
    pub exclude_reason: Option<String>,
}

/// One range check at one operating point (a handbook's range of a quantity).
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangePoint {
    /// Label.
    pub point: String,
    /// Gear state.
    pub gear: String,
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m.
    pub torque_nm: f64,
    /// Oil temperature, °C.
    pub oil_temp_c: f64,
    /// Range the quantity must lie in.
    pub low: f64,
    /// Upper end of the range.
    pub high: f64,
}

/// One reference point.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Point {
    /// Label.
    pub point: String,
    /// Gear state.
    pub gear: String,
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m.
    pub torque_nm: f64,
    /// Oil temperature, °C.
    pub oil_temp_c: f64,
    /// Reference value, W.
    pub reference_w: f64,
    /// Catalogue oil of this point (the model's `[oil]` replaced by it), if given.
    #[serde(default)]
    pub oil: Option<String>,
}

#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
    kind: Kind,
    source: String,
    model: String,
    quantity: Quantity,
    item: Option<String>,
    reference: Option<String>,
    #[serde(default)]
    overrides: toml::Table,
    #[serde(default)]
    trend: Vec<TrendCheck>,
    #[serde(default)]
    range: Vec<RangePoint>,
    /// Efficiency: the loss sources counted (default: all).
    sources: Option<Vec<String>>,
    /// Only these model choices (labels; default: every applicable one).
    models: Option<Vec<String>>,
}

/// A loaded case.
#[derive(Debug, Clone)]
pub struct Case {
    /// Directory name.
    pub name: String,
    /// Directory.
    pub dir: PathBuf,
    /// Kind of reference.
    pub kind: Kind,
    /// Source (repository + commit + function, or publication, table/figure).
    pub source: String,
    /// Model file.
    pub model_path: PathBuf,
    /// Quantity compared.
    pub quantity: Quantity,
    /// One item only (gear or mesh name).
    pub item: Option<String>,
    /// Fixed `[losses]` keys (same inputs as the reference, e.g. its lubricant factor).
    pub overrides: Vec<(String, toml::Value)>,
    /// Reference points.
    pub points: Vec<Point>,
    /// Trend checks.
    pub trends: Vec<TrendCheck>,
    /// Range checks at operating points.
    pub ranges: Vec<RangePoint>,
    /// Loss sources an efficiency counts.
    pub sources: Vec<Source>,
    /// Model choices the case is evaluated with.
    pub choices: Vec<Choice>,
}

impl Case {
    /// Read `dir/case.toml` and its reference CSV.
    pub fn load(dir: &Path) -> Result<Case, ReferenceError> {
        let path = dir.join("case.toml");
        let bad = |msg: String| ReferenceError::Case {
            path: path.clone(),
            msg,
        };
        let text = std::fs::read_to_string(&path).map_err(|e| bad(e.to_string()))?;
        let f: CaseFile = toml::from_str(&text).map_err(|e| bad(e.to_string()))?;
        let mut points = Vec::new();
        if let Some(r) = &f.reference {
            let rp = dir.join(r);
            let mut rd = csv::ReaderBuilder::new()
                .comment(Some(b'#'))
                .trim(csv::Trim::All)
                .from_path(&rp)
                .map_err(|e| ReferenceError::Case {
                    path: rp.clone(),
                    msg: e.to_string(),
                })?;
            for rec in rd.deserialize::<Point>() {
                let p = rec.map_err(|e| ReferenceError::Case {
                    path: rp.clone(),
                    msg: e.to_string(),
                })?;
                if !(p.reference_w.is_finite() && p.reference_w > 0.0) {
                    return Err(ReferenceError::Case {
                        path: rp.clone(),
                        msg: format!("point {}: reference_w must be > 0", p.point),
                    });
                }
                points.push(p);
            }
        }
        if points.is_empty() && f.trend.is_empty() && f.range.is_empty() {
            return Err(bad("no reference points, trend or range checks".into()));
        }
        if let Some(t) = f
            .trend
            .iter()
            .find(|t| !t.exclude.is_empty() && t.exclude_reason.is_none())
        {
            return Err(bad(format!("trend {}: exclude needs exclude_reason", t.point)));
        }
        if let Some(r) = f
            .range
            .iter()
            .find(|r| !(r.low.is_finite() && r.high.is_finite() && r.low <= r.high))
        {
            return Err(bad(format!("range {}: needs finite low <= high", r.point)));
        }
        let sources = match &f.sources {
            None => Source::ALL.to_vec(),
            Some(v) => v
                .iter()
                .map(|n| {
                    Source::parse(n)
                        .ok_or_else(|| bad(format!("sources: \"{n}\" (allowed: {})", Source::names())))
                })
                .collect::<Result<Vec<_>, _>>()?,
        };
        let choices = super::choices::select(f.quantity, f.models.as_deref()).map_err(bad)?;
        Ok(Case {
            name: dir
                .file_name()
                .map_or_else(|| "case".into(), |n| n.to_string_lossy().into_owned()),
            dir: dir.to_path_buf(),
            kind: f.kind,
            source: f.source,
            model_path: dir.join(&f.model),
            quantity: f.quantity,
            item: f.item,
            overrides: f.overrides.into_iter().collect(),
            points,
            trends: f.trend,
            ranges: f.range,
            sources,
            choices,
        })
    }

    /// The gearbox with the case's overrides and then `keys` written over `[losses]`, and its
    /// `[oil]` replaced by the catalogue oil `oil` when given.
    pub fn gearbox(&self, keys: &[(&str, toml::Value)], oil: Option<&str>) -> Result<Gearbox, String> {
        let mut all: Vec<(&str, toml::Value)> = self
            .overrides
            .iter()
            .map(|(k, v)| (k.as_str(), v.clone()))
            .collect();
        all.extend(keys.iter().cloned());
        super::load_with(&self.model_path, &all, oil)
    }

    /// The distinct oils of the points (`None`: the model's own), in first-seen order.
    pub fn oils(&self) -> Vec<Option<String>> {
        let mut v: Vec<Option<String>> = Vec::new();
        for p in &self.points {
            if !v.contains(&p.oil) {
                v.push(p.oil.clone());
            }
        }
        if v.is_empty() {
            v.push(None);
        }
        v
    }
}
