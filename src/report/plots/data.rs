//! Reading run, map and bench outputs (the file formats written by `report`).
//!
//! Missing numeric values (empty fields, `NaN`) become `f64::NAN` and are skipped by the plots;
//! anything that is not a number, a wrong field count or a missing required column is an error
//! that names the file.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::style::Source;
use super::PlotError;
use crate::scene::N_SOURCES;

/// One loss item's power over time.
#[derive(Clone, Debug)]
pub struct LossItemSeries {
    /// Loss source of the item (from its column name `loss_<source>_<item>_w`).
    pub source: Source,
    /// Item name (gear, mesh, bearing, … as in the model file).
    pub name: String,
    /// W per row.
    pub power_w: Vec<f64>,
}

/// The columns of `timeseries.csv` that the plots use.
#[derive(Clone, Debug, Default)]
pub struct TimeSeries {
    /// Output time per row, s.
    pub time_s: Vec<f64>,
    /// The segment's mean vehicle speed per row, km/h (0 for rig cycles).
    pub vehicle_speed_kmh: Vec<f64>,
    /// Gear-state name per row ("" where missing).
    pub gear: Vec<String>,
    /// (node name, °C per row), in column order.
    pub temps_c: Vec<(String, Vec<f64>)>,
    /// Power of every loss item, in column order.
    pub items: Vec<LossItemSeries>,
    /// Per-source total power, W, indexed by `Source::index()` (zeros for a source the file
    /// has no column of: files written before that source existed).
    pub source_w: [Vec<f64>; N_SOURCES],
    /// Sum of the items' power per row, W.
    pub total_loss_w: Vec<f64>,
    /// Efficiency as a fraction, NaN where undefined.
    pub efficiency: Vec<f64>,
}

impl TimeSeries {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// True when the file has no data rows.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// Row indices with a finite time, sorted by time (stable).
    pub fn time_order(&self) -> Vec<usize> {
        let mut idx: Vec<usize> = (0..self.len()).filter(|&i| self.time_s[i].is_finite()).collect();
        idx.sort_by(|&a, &b| self.time_s[a].total_cmp(&self.time_s[b]));
        idx
    }

    /// Weight (s) of each row in `order` by the midpoint rule: half the interval to each
    /// neighbour. A single row gets weight 1 so that distributions are still defined.
    pub fn time_weights(&self, order: &[usize]) -> Vec<f64> {
        let n = order.len();
        if n == 1 {
            return vec![1.0];
        }
        (0..n)
            .map(|k| {
                let t = |j: usize| self.time_s[order[j]];
                let left = if k > 0 { t(k) - t(k - 1) } else { 0.0 };
                let right = if k + 1 < n { t(k + 1) - t(k) } else { 0.0 };
                0.5 * (left + right)
            })
            .collect()
    }
}

/// A CSV number: empty is "no value" (NaN inside, a break in the curve); `NaN`, `inf` and
/// anything else that is not a finite number is rejected (geartherm never writes them).
fn parse_num(field: &str) -> Option<f64> {
    let f = field.trim();
    if f.is_empty() {
        return Some(f64::NAN);
    }
    f.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// What is wrong with an efficiency outside [0, 1].
const NOT_AN_EFFICIENCY: &str = "is not an efficiency (a fraction in [0, 1])";

/// A number for a message: as written for the usual magnitudes, in exponent form outside them
/// (1e308, not 309 digits).
fn number(v: f64) -> String {
    if v == 0.0 || (1e-6..1e9).contains(&v.abs()) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

/// True for an efficiency geartherm can have written: a fraction in [0, 1], or no value (NaN:
/// undefined where there is no output power).
fn is_efficiency(v: f64) -> bool {
    v.is_nan() || (0.0..=1.0).contains(&v)
}

fn csv_err(path: &Path, e: csv::Error) -> PlotError {
    PlotError::Csv {
        path: path.to_path_buf(),
        msg: e.to_string(),
    }
}

fn open_csv(path: &Path) -> Result<csv::Reader<fs::File>, PlotError> {
    let file = fs::File::open(path).map_err(|e| PlotError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    Ok(csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(file))
}

/// Read `timeseries.csv`.
pub fn read_timeseries(path: &Path) -> Result<TimeSeries, PlotError> {
    let mut rdr = open_csv(path)?;
    let headers = rdr.headers().map_err(|e| csv_err(path, e))?.clone();
    let find = |name: &str| headers.iter().position(|h| h == name);
    let require = |name: &str| {
        find(name).ok_or_else(|| PlotError::Data {
            path: path.to_path_buf(),
            what: format!("missing required column `{name}`"),
        })
    };
    let c_time = require("time_s")?;
    let c_speed = require("vehicle_speed_kmh")?;
    let c_gear = require("gear")?;
    // The three gear sources are required; later sources are optional (older files).
    let mut c_src = [None; N_SOURCES];
    for s in Source::ALL {
        let col = format!("loss_{}_w", s.as_str());
        c_src[s.index()] = if s.index() < 3 {
            Some(require(&col)?)
        } else {
            find(&col)
        };
    }
    let c_total = require("loss_total_w")?;
    let c_eff = require("efficiency")?;

    let mut ts = TimeSeries::default();
    let mut temp_cols = Vec::new();
    let mut item_cols = Vec::new();
    for (i, h) in headers.iter().enumerate() {
        if let Some(node) = h.strip_prefix("temp_").and_then(|r| r.strip_suffix("_c")) {
            if !node.is_empty() {
                temp_cols.push(i);
                ts.temps_c.push((node.to_string(), Vec::new()));
            }
        } else if let Some(rest) = h.strip_prefix("loss_").and_then(|r| r.strip_suffix("_w")) {
            let parsed = Source::ALL.into_iter().find_map(|s| {
                rest.strip_prefix(s.as_str())
                    .and_then(|r| r.strip_prefix('_'))
                    .filter(|n| !n.is_empty())
                    .map(|n| (s, n))
            });
            if let Some((source, name)) = parsed {
                item_cols.push(i);
                ts.items.push(LossItemSeries {
                    source,
                    name: name.to_string(),
                    power_w: Vec::new(),
                });
            }
            // loss columns of an unknown source are ignored (forward compatibility).
        }
    }

    let mut record = csv::StringRecord::new();
    let mut line = 1u64;
    loop {
        match rdr.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_err(path, e)),
        }
        line = record.position().map(|p| p.line()).unwrap_or(line + 1);
        // Every value is drawn on an axis: finite and within ±MAX_AXIS_VALUE (an axis spanning
        // ±1e308 has an infinite width, on which the tick search never ends).
        let num = |c: usize| -> Result<f64, PlotError> {
            let field = record.get(c).unwrap_or("");
            parse_num(field)
                .filter(|v| v.is_nan() || v.abs() <= MAX_AXIS_VALUE)
                .ok_or_else(|| PlotError::Csv {
                    path: path.to_path_buf(),
                    msg: format!(
                        "line {line}, column `{}`: `{field}` is not a finite number within \
                         ±{MAX_AXIS_VALUE:e}",
                        &headers[c]
                    ),
                })
        };
        let t = num(c_time)?;
        let speed = num(c_speed)?;
        let prev = ts.time_s.last().copied().unwrap_or(f64::NEG_INFINITY);
        // A run writes one row per sample, at increasing times (the axis and the energy weights
        // rest on it).
        {
            let increases = t.partial_cmp(&prev) == Some(std::cmp::Ordering::Greater);
            if !increases || t.abs() > MAX_AXIS_VALUE {
                return Err(PlotError::Csv {
                    path: path.to_path_buf(),
                    msg: format!(
                        "line {line}, column `time_s`: {} does not follow {} (times increase \
                         from row to row, |time| ≤ {MAX_AXIS_VALUE:e} s)",
                        number(t),
                        number(prev)
                    ),
                });
            }
        }
        ts.time_s.push(t);
        ts.vehicle_speed_kmh.push(speed);
        ts.gear.push(record.get(c_gear).unwrap_or("").to_string());
        for (k, &c) in temp_cols.iter().enumerate() {
            let v = num(c)?;
            ts.temps_c[k].1.push(v);
        }
        for (k, &c) in item_cols.iter().enumerate() {
            let v = num(c)?;
            ts.items[k].power_w.push(v);
        }
        for (k, c) in c_src.iter().enumerate() {
            let v = match c {
                Some(c) => num(*c)?,
                None => 0.0,
            };
            ts.source_w[k].push(v);
        }
        ts.total_loss_w.push(num(c_total)?);
        let eff = num(c_eff)?;
        if !is_efficiency(eff) {
            return Err(PlotError::Csv {
                path: path.to_path_buf(),
                msg: format!(
                    "line {line}, column `efficiency`: {} {NOT_AN_EFFICIENCY}",
                    number(eff)
                ),
            });
        }
        ts.efficiency.push(eff);
    }
    if ts.is_empty() {
        return Err(PlotError::Data {
            path: path.to_path_buf(),
            what: "no data rows".into(),
        });
    }
    Ok(ts)
}

/// `energy_lost_j`: one key per source and `total` (missing or null values are `None`).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(transparent)]
pub struct EnergyBySource(BTreeMap<String, Option<f64>>);

impl EnergyBySource {
    /// Energy lost by source `s` over the run, J.
    pub fn get(&self, s: Source) -> Option<f64> {
        self.0.get(s.as_str()).copied().flatten()
    }

    /// Energy lost by all sources over the run, J.
    pub fn total(&self) -> Option<f64> {
        self.0.get("total").copied().flatten()
    }
}

/// One entry of `energy_by_item_j`: the energy one loss item dissipated over the run.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct ItemEnergy {
    /// Loss source of the item (`churning`, `bearing`, …).
    pub source: String,
    /// Item name.
    pub name: String,
    /// Energy, J.
    pub j: Option<f64>,
}

/// One node's entry of `temperatures_c`, °C.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct TempStats {
    /// Lowest temperature over the output rows, °C.
    pub min: Option<f64>,
    /// Highest temperature over the output rows, °C.
    pub max: Option<f64>,
    /// Temperature at the end of the run, °C (key `final`).
    #[serde(rename = "final")]
    pub last: Option<f64>,
}

/// One entry of `nodes`: a thermal network node.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct NodeInfo {
    /// Node name from the model file.
    pub name: String,
    /// True for a boundary (prescribed temperature), false for a capacity node.
    pub boundary: bool,
}

/// One entry of `skipped`: something the scene left out of the run.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct Skipped {
    /// The item or table left out.
    pub what: String,
    /// Why (idle in every gear state the run uses, above the oil, …).
    pub why: String,
}

/// `summary.json`. Every field is optional so that a partial summary still renders; unknown
/// keys are ignored.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct Summary {
    /// Model name.
    pub model: Option<String>,
    /// Cycle name.
    pub cycle: Option<String>,
    /// Solver as asked (`auto` by default).
    pub solver: Option<serde_json::Value>,
    /// Relative tolerance of the integration.
    pub rtol: Option<serde_json::Value>,
    /// Absolute tolerance of the integration, K on temperatures.
    pub atol: Option<serde_json::Value>,
    /// Wall time of the integration, s.
    pub wall_time_s: Option<f64>,
    /// Accepted integration steps.
    pub steps: Option<f64>,
    /// Energy lost per source and in total, J.
    pub energy_lost_j: Option<EnergyBySource>,
    /// Energy lost per loss item, J.
    pub energy_by_item_j: Vec<ItemEnergy>,
    /// |lost − stored − to boundaries| over the largest of the three energies.
    pub energy_balance_relative: Option<f64>,
    /// `cycle_efficiency` (∫P_out/∫P_in); `mean_efficiency` in directories of earlier versions.
    #[serde(alias = "mean_efficiency")]
    pub cycle_efficiency: Option<f64>,
    /// Min, max and final temperature per node, °C.
    pub temperatures_c: BTreeMap<String, TempStats>,
    /// The network's nodes, capacity nodes first.
    pub nodes: Vec<NodeInfo>,
    /// Name of the node whose temperature sets the oil properties.
    pub oil_node: Option<String>,
    /// What the scene left out of the run.
    pub skipped: Vec<Skipped>,
}

impl Summary {
    /// True when `node` is a boundary node of the run.
    pub fn is_boundary(&self, node: &str) -> bool {
        self.nodes.iter().any(|n| n.name == node && n.boundary)
    }

    /// The values the report writes as they must be: `cycle_efficiency` a fraction in [0, 1]
    /// (an efficiency is never drawn or written over 100 %). Err: the key and what is wrong.
    pub fn check(&self) -> Result<(), String> {
        match self.cycle_efficiency {
            Some(e) if !is_efficiency(e) => {
                Err(format!("cycle_efficiency: {} {NOT_AN_EFFICIENCY}", number(e)))
            }
            _ => Ok(()),
        }
    }
}

/// A JSON scalar as display text (strings without quotes).
pub fn value_text(v: &Option<serde_json::Value>) -> String {
    match v {
        None | Some(serde_json::Value::Null) => "–".into(),
        Some(serde_json::Value::String(s)) => s.clone(),
        Some(serde_json::Value::Number(n)) => match n.as_f64() {
            Some(x) if n.is_f64() => super::style::fmt_sig(x, 3),
            _ => n.to_string(),
        },
        Some(other) => other.to_string(),
    }
}

/// Read and deserialise a JSON file; errors name the file.
pub fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T, PlotError> {
    let text = fs::read_to_string(path).map_err(|e| PlotError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    serde_json::from_str(&text).map_err(|e| PlotError::Json {
        path: path.to_path_buf(),
        source: e,
    })
}

/// Everything a run report needs.
pub struct RunData {
    /// The run's output directory.
    pub dir: PathBuf,
    /// Its `timeseries.csv`.
    pub ts: TimeSeries,
    /// Its `summary.json`.
    pub summary: Summary,
}

/// Read `timeseries.csv` and `summary.json` of the run output directory `dir`.
pub fn read_run(dir: &Path) -> Result<RunData, PlotError> {
    let ts = read_timeseries(&dir.join("timeseries.csv"))?;
    let path = dir.join("summary.json");
    let summary: Summary = read_json(&path)?;
    summary.check().map_err(|what| PlotError::Data { path, what })?;
    Ok(RunData {
        dir: dir.to_path_buf(),
        ts,
        summary,
    })
}

/// One row of `map.csv`.
#[derive(Clone, Debug, Deserialize)]
pub struct MapRow {
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m.
    pub torque_nm: f64,
    /// Efficiency P_out/(P_out + P_loss) at the equilibrium, fraction (empty without one).
    pub efficiency: Option<f64>,
    /// Total loss at the equilibrium, W.
    #[serde(rename = "loss_total_w")]
    pub total_loss_w: Option<f64>,
    /// Churning loss at the equilibrium, W.
    #[serde(rename = "loss_churning_w")]
    pub churning_w: Option<f64>,
    /// Pocketing loss at the equilibrium, W.
    #[serde(rename = "loss_pocketing_w")]
    pub pocketing_w: Option<f64>,
    /// Sliding (mesh friction) loss at the equilibrium, W.
    #[serde(rename = "loss_sliding_w")]
    pub sliding_w: Option<f64>,
    /// Equilibrium temperature of the oil node, °C.
    pub oil_temp_c: Option<f64>,
    /// Iterations the steady solver took (Newton and pseudo-transient together).
    pub iterations: Option<f64>,
    /// True when the steady solver converged at this point.
    pub converged: bool,
}

/// `map.json`: what the map was computed for.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct MapMeta {
    /// Model name.
    pub model: Option<String>,
    /// Gear state of the map.
    pub gear: Option<serde_json::Value>,
}

/// A map on its (speed × torque) grid. Cell (i, j) = speed i, torque j; `None` = no point.
pub struct MapGrid {
    /// The map's `map.json`.
    pub meta: MapMeta,
    /// Input speeds of the grid, rpm, ascending.
    pub speeds_rpm: Vec<f64>,
    /// Input torques of the grid, N·m, ascending.
    pub torques_nm: Vec<f64>,
    /// Rows by cell, torque-major: cell (i, j) at `j * speeds_rpm.len() + i`.
    pub cells: Vec<Option<MapRow>>,
}

impl MapGrid {
    /// The row at speed index `i` and torque index `j`, if the map has that point.
    pub fn cell(&self, i: usize, j: usize) -> Option<&MapRow> {
        self.cells[j * self.speeds_rpm.len() + i].as_ref()
    }
}

fn unique_sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.retain(|x| x.is_finite());
    v.sort_by(f64::total_cmp);
    let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    v.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * scale);
    v
}

fn nearest(axis: &[f64], x: f64) -> usize {
    let k = axis.partition_point(|&a| a < x);
    if k == 0 {
        0
    } else if k >= axis.len() {
        axis.len() - 1
    } else if (axis[k] - x).abs() < (x - axis[k - 1]).abs() {
        k
    } else {
        k - 1
    }
}

/// Most cells of a map grid: as many points as `geartherm map` writes at most
/// (`job::limits::MAX_MAP_POINTS`; a test holds the two equal). A crafted `map.csv` of n rows
/// with n distinct speeds and torques would otherwise ask for n² cells.
pub const MAX_MAP_CELLS: usize = 40_000;

/// Largest magnitude of a grid value: the heat map's cell edges and axis ticks (ten times the
/// axis span) must stay finite.
pub const MAX_AXIS_VALUE: f64 = 1e300;

/// A grid the heat maps can draw: at most [`MAX_MAP_CELLS`] cells, values within
/// ±[`MAX_AXIS_VALUE`].
fn check_grid(path: &Path, speeds: &[f64], torques: &[f64]) -> Result<(), PlotError> {
    let data = |what: String| PlotError::Data {
        path: path.to_path_buf(),
        what,
    };
    if speeds.len().saturating_mul(torques.len()) > MAX_MAP_CELLS {
        return Err(data(format!(
            "{} speeds × {} torques: more than {MAX_MAP_CELLS} grid cells (the most `geartherm map` writes)",
            speeds.len(),
            torques.len()
        )));
    }
    for (name, axis) in [("speed_rpm", speeds), ("torque_nm", torques)] {
        if let Some(v) = axis.iter().find(|v| v.abs() > MAX_AXIS_VALUE) {
            return Err(data(format!(
                "column `{name}`: {v:e} is too large to draw (|value| ≤ {MAX_AXIS_VALUE:e})"
            )));
        }
    }
    Ok(())
}

/// Read `map.csv` and `map.json` of the map output directory `dir` onto their grid.
pub fn read_map(dir: &Path) -> Result<MapGrid, PlotError> {
    let path = dir.join("map.csv");
    let mut rdr = open_csv(&path)?;
    let mut rows = Vec::new();
    for r in rdr.deserialize::<MapRow>() {
        let r = r.map_err(|e| csv_err(&path, e))?;
        let cells = [
            Some(r.speed_rpm),
            Some(r.torque_nm),
            r.efficiency,
            r.total_loss_w,
            r.churning_w,
            r.pocketing_w,
            r.sliding_w,
            r.oil_temp_c,
            r.iterations,
        ];
        if cells.iter().flatten().any(|v| !v.is_finite()) {
            return Err(PlotError::Csv {
                path,
                msg: format!(
                    "row {} ({} rpm, {} N m) holds a value that is not a finite number",
                    rows.len() + 2,
                    r.speed_rpm,
                    r.torque_nm
                ),
            });
        }
        if let Some(e) = r.efficiency.filter(|e| !is_efficiency(*e)) {
            return Err(PlotError::Csv {
                path,
                msg: format!(
                    "row {}, column `efficiency`: {} {NOT_AN_EFFICIENCY}",
                    rows.len() + 2,
                    number(e)
                ),
            });
        }
        rows.push(r);
    }
    if rows.is_empty() {
        return Err(PlotError::Data {
            path,
            what: "no data rows".into(),
        });
    }
    let meta: MapMeta = read_json(&dir.join("map.json"))?;
    let speeds = unique_sorted(rows.iter().map(|r| r.speed_rpm).collect());
    let torques = unique_sorted(rows.iter().map(|r| r.torque_nm).collect());
    if speeds.is_empty() || torques.is_empty() {
        return Err(PlotError::Data {
            path,
            what: "no finite speed/torque values".into(),
        });
    }
    check_grid(&path, &speeds, &torques)?;
    let mut cells = vec![None; speeds.len() * torques.len()];
    for r in rows {
        if !(r.speed_rpm.is_finite() && r.torque_nm.is_finite()) {
            continue;
        }
        let (i, j) = (nearest(&speeds, r.speed_rpm), nearest(&torques, r.torque_nm));
        cells[j * speeds.len() + i] = Some(r);
    }
    Ok(MapGrid {
        meta,
        speeds_rpm: speeds,
        torques_nm: torques,
        cells,
    })
}

/// One row of `bench.csv`.
#[derive(Clone, Debug, Deserialize)]
pub struct BenchRow {
    /// Solver (method) name.
    pub solver: String,
    /// Relative tolerance.
    pub rtol: Option<f64>,
    /// Absolute tolerance, K on temperatures.
    pub atol: Option<f64>,
    /// Wall time of the integration, s.
    pub wall_time_s: Option<f64>,
    /// Accepted steps.
    pub steps: Option<f64>,
    /// Rejected steps.
    pub rejected: Option<f64>,
    /// Right-hand-side evaluations.
    pub rhs_evals: Option<f64>,
    /// Jacobian oil-column evaluations (ROS3: explicit loss-slope differences).
    pub jac_evals: Option<f64>,
    /// LU factorisations.
    pub lu_count: Option<f64>,
    /// Largest |T − T_ref| over the nodes at the end of the run, K.
    pub err_final_k: Option<f64>,
    /// Largest |T − T_ref| over the nodes and the output grid, K.
    pub err_max_k: Option<f64>,
    /// RMS of T − T_ref over the nodes and the output grid, K.
    pub err_rms_k: Option<f64>,
    /// |lost − stored − to boundaries| over the largest of the three energies.
    pub energy_balance_relative: Option<f64>,
    /// True for the default solver and tolerance.
    pub default: bool,
}

/// `bench.json`: what the work-precision study was run on.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct BenchMeta {
    /// Model name.
    pub model: Option<String>,
    /// Cycle name.
    pub cycle: Option<String>,
}

/// Read `bench.csv` and `bench.json` of the bench output directory `dir`.
pub fn read_bench(dir: &Path) -> Result<(Vec<BenchRow>, BenchMeta), PlotError> {
    let path = dir.join("bench.csv");
    let mut rdr = open_csv(&path)?;
    let mut rows = Vec::new();
    for r in rdr.deserialize::<BenchRow>() {
        rows.push(r.map_err(|e| csv_err(&path, e))?);
    }
    if rows.is_empty() {
        return Err(PlotError::Data {
            path,
            what: "no data rows".into(),
        });
    }
    let meta: BenchMeta = read_json(&dir.join("bench.json"))?;
    Ok((rows, meta))
}

/// Split the rows in `order` into runs of consecutive finite (x, y) points, so that missing
/// values break a line instead of being bridged or drawn as zero.
pub fn finite_segments(order: &[usize], x: &[f64], y: &[f64], x_scale: f64) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for &i in order {
        let (xi, yi) = (x[i] * x_scale, y[i]);
        if xi.is_finite() && yi.is_finite() {
            cur.push((xi, yi));
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Reduce a polyline (x increasing) to at most ~4 points per bucket (first, min, max, last)
/// over `buckets` equal x intervals; the drawn line is visually identical at that resolution.
pub fn decimate(points: &[(f64, f64)], buckets: usize) -> Vec<(f64, f64)> {
    if points.len() <= 4 * buckets || points.len() < 2 {
        return points.to_vec();
    }
    let x0 = points[0].0;
    let x1 = points[points.len() - 1].0;
    let w = (x1 - x0) / buckets as f64;
    if w.is_nan() || w <= 0.0 {
        return points.to_vec();
    }
    let mut out = Vec::with_capacity(4 * buckets + 2);
    let mut start = 0;
    while start < points.len() {
        let b = ((points[start].0 - x0) / w).floor();
        let mut end = start + 1;
        while end < points.len() && ((points[end].0 - x0) / w).floor() <= b {
            end += 1;
        }
        let chunk = &points[start..end];
        let (mut kmin, mut kmax) = (0, 0);
        for (k, p) in chunk.iter().enumerate() {
            if p.1 < chunk[kmin].1 {
                kmin = k;
            }
            if p.1 > chunk[kmax].1 {
                kmax = k;
            }
        }
        let mut ks = [0, kmin, kmax, chunk.len() - 1];
        ks.sort_unstable();
        let mut last = usize::MAX;
        for k in ks {
            if k != last {
                out.push(chunk[k]);
                last = k;
            }
        }
        start = end;
    }
    out
}
