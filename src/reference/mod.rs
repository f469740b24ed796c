//! Reference cases and their comparison: each case of `validation/<case>/case.toml` evaluated
//! with every applicable model choice and compared with its reference (docs/validation.md). This
//! layer reads case files and loads models; it calls no solver (it evaluates the loss scene at
//! fixed operating points). Checking a model file's input is `model`'s job, not this one's.
//!
//! A case names a model file, a quantity (any loss source, optionally one item, or the
//! efficiency over chosen sources), the kind of reference (peer, standard, measurement, trend,
//! handbook) and its source, and a reference CSV (`point,gear,speed_rpm,torque_nm,oil_temp_c,
//! reference_w`; speed and torque at the model's input), trend checks (a speed exponent or a
//! power ratio that must lie in a range) or range checks at operating points (`[[range]]`).
//! Each model choice is a set of keys written over the model file's own (`choices`).

pub mod case;
pub mod choices;
pub mod stats;

use std::path::{Path, PathBuf};

pub use case::{Case, Kind, Quantity, RangePoint, TrendCheck};
pub use stats::{summarise, SummaryRow};

use crate::model::{self, Gearbox};
use crate::physics::units::{c_to_k, rpm_to_rad_s};
use crate::scene::{LossScene, OperatingPoint, RangeLog, RangeWarning, Source};

/// One row of `validation.csv`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Case name (its directory).
    pub case: String,
    /// Point label.
    pub point: String,
    /// Model choice label.
    pub model: String,
    /// Quantity compared (a loss source's name, or `efficiency`).
    pub quantity: &'static str,
    /// Input speed, rpm (for the error-vs-speed plot).
    pub speed_rpm: f64,
    /// geartherm's value (W, or the trend metric).
    pub predicted: f64,
    /// Reference value (W; trends: the nearest bound when outside the range, else the value).
    pub reference: f64,
    /// Kind of reference.
    pub kind: Kind,
    /// Source of the reference.
    pub source: String,
    /// (predicted − reference)/reference.
    pub relative_error: f64,
}

/// A reference case that could not be evaluated.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    /// Unreadable or malformed case or reference file.
    #[error("{}: {msg}", path.display())]
    Case {
        /// The case or reference file.
        path: PathBuf,
        /// What is wrong with it.
        msg: String,
    },
    /// The model file (with a choice applied) does not load or compile.
    #[error("{}: model choice {choice}: {msg}", path.display())]
    Model {
        /// The model file the case names.
        path: PathBuf,
        /// The model choice applied (keys written over the model file).
        choice: String,
        /// Why it does not load or compile.
        msg: String,
    },
}

/// Every case directory under `dir` (those holding a `case.toml`), sorted.
pub fn case_dirs(dir: &Path) -> Result<Vec<PathBuf>, ReferenceError> {
    let rd = std::fs::read_dir(dir).map_err(|e| ReferenceError::Case {
        path: dir.to_path_buf(),
        msg: e.to_string(),
    })?;
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("case.toml").is_file())
        .collect();
    v.sort();
    Ok(v)
}

/// A loss model used outside its range (or an item not counted) in one case and model choice,
/// over the points that choice evaluated.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CaseWarning {
    /// Case name.
    pub case: String,
    /// Model choice label.
    pub model: String,
    /// The warning (item, range, what was seen).
    #[serde(flatten)]
    pub warning: RangeWarning,
}

/// Evaluate every case under `dir` with every model choice of its family.
pub fn run_all(dir: &Path) -> Result<Vec<Row>, ReferenceError> {
    Ok(run_all_with_warnings(dir)?.0)
}

/// [`run_all`] with the range warnings of every case and model choice.
pub fn run_all_with_warnings(dir: &Path) -> Result<(Vec<Row>, Vec<CaseWarning>), ReferenceError> {
    let mut rows = Vec::new();
    let mut warnings = Vec::new();
    for d in case_dirs(dir)? {
        let (r, w) = run_case_with_warnings(&Case::load(&d)?)?;
        rows.extend(r);
        warnings.extend(w);
    }
    Ok((rows, warnings))
}

/// Evaluate one case.
pub fn run_case(c: &Case) -> Result<Vec<Row>, ReferenceError> {
    Ok(run_case_with_warnings(c)?.0)
}

/// [`run_case`] with its range warnings per model choice.
pub fn run_case_with_warnings(c: &Case) -> Result<(Vec<Row>, Vec<CaseWarning>), ReferenceError> {
    let mut rows = Vec::new();
    let mut warnings = Vec::new();
    for (label, keys) in &c.choices {
        for oil in c.oils() {
            let (r, w) = run_choice(c, label, keys, oil.as_deref())?;
            rows.extend(r);
            warnings.extend(w.into_iter().map(|warning| CaseWarning {
                case: c.name.clone(),
                model: label.to_string(),
                warning,
            }));
        }
    }
    Ok((rows, warnings))
}

/// One model choice of a case with one oil (`None`: the model's): its points, and with the
/// model's own oil its range and trend checks; and the range warnings over those points.
fn run_choice(
    c: &Case,
    label: &str,
    keys: &[(&str, toml::Value)],
    oil: Option<&str>,
) -> Result<(Vec<Row>, Vec<RangeWarning>), ReferenceError> {
    let mut rows = Vec::new();
    let gb = c.gearbox(keys, oil).map_err(|msg| ReferenceError::Model {
        path: c.model_path.clone(),
        choice: label.to_string(),
        msg,
    })?;
    let scene = LossScene::compile(&gb).map_err(|e| ReferenceError::Model {
        path: c.model_path.clone(),
        choice: label.to_string(),
        msg: e.to_string(),
    })?;
    let log = std::cell::RefCell::new(RangeLog::new(&scene));
    let eval = |gear: &str, rpm: f64, torque: f64, temp: f64| -> Result<f64, ReferenceError> {
        value(&gb, &scene, c, (gear, rpm, torque, temp), &log).map_err(|msg| ReferenceError::Case {
            path: c.dir.join("case.toml"),
            msg,
        })
    };
    let row = |point: &str, speed_rpm: f64, predicted: f64, reference: f64, kind: Kind| Row {
        case: c.name.clone(),
        point: point.to_string(),
        model: label.to_string(),
        quantity: c.quantity.as_str(),
        speed_rpm,
        predicted,
        reference,
        kind,
        source: c.source.clone(),
        relative_error: (predicted - reference) / reference,
    };
    for p in c.points.iter().filter(|p| p.oil.as_deref() == oil) {
        let predicted = eval(&p.gear, p.speed_rpm, p.torque_nm, p.oil_temp_c)?;
        let name = match &p.oil {
            Some(o) => format!("{} {o}", p.point),
            None => p.point.clone(),
        };
        rows.push(row(&name, p.speed_rpm, predicted, p.reference_w, c.kind));
    }
    if oil.is_some() {
        return Ok((rows, log.borrow().warnings(&scene)));
    }
    for r in &c.ranges {
        let predicted = eval(&r.gear, r.speed_rpm, r.torque_nm, r.oil_temp_c)?;
        rows.push(row(
            &r.point,
            r.speed_rpm,
            predicted,
            predicted.clamp(r.low, r.high),
            c.kind,
        ));
    }
    for t in c.trends.iter().filter(|t| !t.exclude.iter().any(|e| e == label)) {
        let pa = eval(&t.gear, t.speed_a_rpm, t.torque_nm, t.oil_temp_c)?;
        let pb = eval(&t.gear, t.speed_b_rpm, t.torque_nm, t.oil_temp_c)?;
        let predicted = t.metric.value(pa, pb, t.speed_a_rpm, t.speed_b_rpm);
        rows.push(row(
            &t.point,
            t.speed_b_rpm,
            predicted,
            predicted.clamp(t.low, t.high),
            Kind::Trend,
        ));
    }
    let warnings = log.borrow().warnings(&scene);
    Ok((rows, warnings))
}

/// The case's quantity at one point (gear state, rpm, N·m, °C): W, or the efficiency (–); the
/// point's range checks go into `log`.
fn value(
    gb: &Gearbox,
    scene: &LossScene,
    c: &Case,
    (gear, rpm, torque, temp_c): (&str, f64, f64, f64),
    log: &std::cell::RefCell<RangeLog>,
) -> Result<f64, String> {
    let state = gb
        .state_index(gear)
        .ok_or_else(|| format!("gear state \"{gear}\" not in the model"))?;
    let op = OperatingPoint {
        state,
        input_speed: rpm_to_rad_s(rpm),
        input_torque: torque,
        oil: gb.oil.properties(c_to_k(temp_c)),
    };
    let mut out = vec![0.0; scene.len()];
    scene.evaluate(&op, &mut out);
    log.borrow_mut().check(scene, &op);
    let counts = |src: Source| match c.quantity.source() {
        Some(want) => src == want,
        None => c.sources.contains(&src),
    };
    let loss: f64 = scene
        .items
        .iter()
        .zip(&out)
        .filter(|(it, _)| counts(it.source) && c.item.as_ref().map_or(true, |n| *n == it.name))
        .map(|(_, w)| *w)
        .sum();
    let v = match c.quantity {
        Quantity::Efficiency => {
            let p_in = op.input_speed * op.input_torque;
            if p_in <= 0.0 {
                return Err(format!(
                    "efficiency needs input power > 0 ({rpm} rpm, {torque} N·m)"
                ));
            }
            1.0 - loss / p_in
        }
        _ => loss,
    };
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("non-finite {} at {rpm} rpm", c.quantity.as_str()))
    }
}

/// Load a model file with `[losses]` keys written over its own (and its `[oil]` replaced by the
/// catalogue oil `oil` when given); a key `bearings.<k>` is written
/// into every `[[bearings]]` entry instead.
pub fn load_with(path: &Path, keys: &[(&str, toml::Value)], oil: Option<&str>) -> Result<Gearbox, String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let mut doc: toml::Table = text.parse().map_err(|e: toml::de::Error| e.to_string())?;
    if let Some(o) = oil {
        let mut t = toml::Table::new();
        t.insert("catalogue".into(), toml::Value::String(o.into()));
        doc.insert("oil".into(), toml::Value::Table(t));
    }
    for (k, v) in keys {
        if let Some(bk) = k.strip_prefix("bearings.") {
            let Some(list) = doc.get_mut("bearings").and_then(|b| b.as_array_mut()) else {
                return Err(format!("{k}: the model has no [[bearings]]"));
            };
            for b in list.iter_mut().filter_map(|b| b.as_table_mut()) {
                b.insert(bk.to_string(), v.clone());
            }
            continue;
        }
        let losses = doc
            .entry("losses")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let Some(t) = losses.as_table_mut() else {
            return Err("[losses] is not a table".into());
        };
        t.insert((*k).to_string(), v.clone());
    }
    let text = toml::to_string(&doc).map_err(|e| e.to_string())?;
    model::from_str(&text, path).map_err(|e| e.report())
}
