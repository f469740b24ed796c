//! `case.toml` and `reference.csv` of one reference case.

use std::path::{Path, PathBuf};

use super::ValidationError;
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
}

impl Kind {
    /// Lower-case name.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Peer => "peer",
            Kind::Standard => "standard",
            Kind::Measurement => "measurement",
            Kind::Trend => "trend",
        }
    }
}

/// The loss quantity a case compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Mesh friction.
    Sliding,
    /// Churning.
    Churning,
}

/// `[losses]` keys of one model choice.
pub type Choice = (&'static str, Vec<(&'static str, toml::Value)>);

fn s(v: &str) -> toml::Value {
    toml::Value::String(v.into())
}

impl Quantity {
    /// Source of the loss items compared.
    pub fn source(self) -> Source {
        match self {
            Quantity::Sliding => Source::Sliding,
            Quantity::Churning => Source::Churning,
        }
    }

    /// Name.
    pub fn as_str(self) -> &'static str {
        match self {
            Quantity::Sliding => "sliding",
            Quantity::Churning => "churning",
        }
    }

    /// Every applicable model choice (label, `[losses]` keys); the other sources are off.
    pub fn choices(self) -> Vec<Choice> {
        let off = |k: &'static str| (k, s("off"));
        match self {
            Quantity::Sliding => {
                // Every key explicit, so a label means the same whatever the defaults are.
                let det = |f: &'static str, ls: &'static str, hd: &'static str| {
                    vec![
                        off("churning"),
                        off("pocketing"),
                        ("sliding", s("detailed")),
                        ("friction", s(f)),
                        ("load_sharing", s(ls)),
                        ("helical_distribution", s(hd)),
                    ]
                };
                vec![
                    ("iso_tc60", det("iso_tc60", "uniform", "uniform")),
                    ("benedict_kelley", det("benedict_kelley", "uniform", "uniform")),
                    ("schlenk", det("schlenk", "uniform", "uniform")),
                    ("schlenk 33:67", det("schlenk", "33:67", "uniform")),
                    ("schlenk ramp", det("schlenk", "ramp", "uniform")),
                    (
                        "schlenk niemann_richer",
                        det("schlenk", "uniform", "niemann_richer"),
                    ),
                    (
                        "iso14179",
                        vec![off("churning"), off("pocketing"), ("sliding", s("iso14179"))],
                    ),
                ]
            }
            Quantity::Churning => ["changenet", "seetharaman", "stavytskyi"]
                .into_iter()
                .map(|m| (m, vec![off("sliding"), off("pocketing"), ("churning", s(m))]))
                .collect(),
        }
    }
}

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
}

impl Case {
    /// Read `dir/case.toml` and its reference CSV.
    pub fn load(dir: &Path) -> Result<Case, ValidationError> {
        let path = dir.join("case.toml");
        let bad = |msg: String| ValidationError::Case {
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
                .map_err(|e| ValidationError::Case {
                    path: rp.clone(),
                    msg: e.to_string(),
                })?;
            for rec in rd.deserialize::<Point>() {
                let p = rec.map_err(|e| ValidationError::Case {
                    path: rp.clone(),
                    msg: e.to_string(),
                })?;
                if !(p.reference_w.is_finite() && p.reference_w > 0.0) {
                    return Err(ValidationError::Case {
                        path: rp.clone(),
                        msg: format!("point {}: reference_w must be > 0", p.point),
                    });
                }
                points.push(p);
            }
        }
        if points.is_empty() && f.trend.is_empty() {
            return Err(bad("no reference points and no trend checks".into()));
        }
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
        })
    }

    /// The gearbox with the case's overrides and then `keys` written over `[losses]`.
    pub fn gearbox(&self, keys: &[(&str, toml::Value)]) -> Result<Gearbox, String> {
        let mut all: Vec<(&str, toml::Value)> = self
            .overrides
            .iter()
            .map(|(k, v)| (k.as_str(), v.clone()))
            .collect();
        all.extend(keys.iter().cloned());
        super::load_with(&self.model_path, &all)
    }
}
