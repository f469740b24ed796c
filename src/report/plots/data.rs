//! What the figures draw from run, map and bench outputs, read with the writers' types: a run's
//! [`Summary`] and [`Timeseries`] (`report::run`, `report::timeseries`), a map's
//! [`MapRow`]s and [`MapMeta`] (`report::map`), a bench's [`BenchResult`] (`report::bench`) and
//! [`BenchRow`]s (`solve::work_precision`). The writers draw from the same values in memory.
//!
//! Missing numeric values (empty fields) become `f64::NAN` and are skipped by the plots;
//! anything that is not a number, a wrong field count or a missing required column is an error
//! that names the file.

use std::fs;
use std::path::Path;

use serde::Deserialize;

use super::style::Source;
use super::PlotError;
pub use crate::report::bench::BenchResult;
pub use crate::report::map::{MapMeta, MapRow};
pub use crate::report::run::Summary;
use crate::report::timeseries::{parse_num, Timeseries};
use crate::scene::N_SOURCES;
pub use crate::solve::work_precision::BenchRow;

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

/// The plots' view of a `timeseries.csv` table (`path` names it in errors): the required columns
/// (`time_s`, `vehicle_speed_kmh`, `gear`, the three gear sources' `loss_<source>_w`,
/// `loss_total_w`, `efficiency`), times that increase from row to row, efficiencies in [0, 1],
/// every value drawn within ±[`MAX_AXIS_VALUE`]. Per-source columns are read under their
/// earlier names too (`<source>_w`, `total_loss_w`); a source without a column (added after the
/// file was written) is zero.
pub fn from_table(t: &Timeseries, path: &Path) -> Result<TimeSeries, PlotError> {
    let data = |what: String| PlotError::Data {
        path: path.to_path_buf(),
        what,
    };
    let require = |names: &[&str]| -> Result<&[f64], PlotError> {
        names
            .iter()
            .find_map(|n| t.num(n))
            .ok_or_else(|| data(format!("missing required column `{}`", names[0])))
    };
    let time = require(&["time_s"])?;
    let speed = require(&["vehicle_speed_kmh"])?;
    let gear = t
        .text("gear")
        .ok_or_else(|| data("missing required column `gear`".into()))?;
    // The three gear sources are required; later sources are optional (older files).
    let mut src: Vec<Option<&[f64]>> = Vec::with_capacity(N_SOURCES);
    for s in Source::ALL {
        let names = [format!("loss_{}_w", s.as_str()), format!("{}_w", s.as_str())];
        let names = [names[0].as_str(), names[1].as_str()];
        src.push(if s.index() < 3 {
            Some(require(&names)?)
        } else {
            names.iter().find_map(|n| t.num(n))
        });
    }
    let total = require(&["loss_total_w", "total_loss_w"])?;
    let eff = require(&["efficiency"])?;
    let mut ts = TimeSeries::default();
    let mut used: Vec<(&str, &[f64])> = vec![("time_s", time), ("vehicle_speed_kmh", speed)];
    for c in &t.columns {
        let crate::report::timeseries::Values::Num(v) = &c.values else {
            continue;
        };
        let h = c.name.as_str();
        if let Some(node) = h.strip_prefix("temp_").and_then(|r| r.strip_suffix("_c")) {
            if !node.is_empty() {
                ts.temps_c.push((node.to_string(), v.clone()));
                used.push((h, v));
            }
        } else if let Some(rest) = h.strip_prefix("loss_").and_then(|r| r.strip_suffix("_w")) {
            let parsed = Source::ALL.into_iter().find_map(|s| {
                rest.strip_prefix(s.as_str())
                    .and_then(|r| r.strip_prefix('_'))
                    .filter(|n| !n.is_empty())
                    .map(|n| (s, n))
            });
            if let Some((source, name)) = parsed {
                ts.items.push(LossItemSeries {
                    source,
                    name: name.to_string(),
                    power_w: v.clone(),
                });
                used.push((h, v));
            }
            // loss columns of an unknown source are ignored (forward compatibility).
        }
    }
    for (s, c) in Source::ALL.iter().zip(&src) {
        ts.source_w[s.index()] = c.map_or_else(|| vec![0.0; t.rows()], <[f64]>::to_vec);
    }
    used.extend(src.iter().flatten().map(|c| ("per-source loss", *c)));
    used.push(("loss_total_w", total));
    used.push(("efficiency", eff));
    check_values(t, path, &used)?;
    ts.time_s = time.to_vec();
    ts.vehicle_speed_kmh = speed.to_vec();
    ts.gear = gear.to_vec();
    ts.total_loss_w = total.to_vec();
    ts.efficiency = eff.to_vec();
    if ts.is_empty() {
        return Err(data("no data rows".into()));
    }
    Ok(ts)
}

/// The checks of [`from_table`] on the values it draws: within ±[`MAX_AXIS_VALUE`], times
/// increasing, efficiencies in [0, 1]; errors name the line and column.
fn check_values(t: &Timeseries, path: &Path, used: &[(&str, &[f64])]) -> Result<(), PlotError> {
    let csv = |line: usize, msg: String| PlotError::Csv {
        path: path.to_path_buf(),
        msg: format!("line {line}, {msg}"),
    };
    for k in 0..t.rows() {
        let line = k + 2;
        for (name, v) in used {
            // An axis spanning ±1e308 has an infinite width, on which the tick search never ends.
            if v[k].abs() > MAX_AXIS_VALUE {
                return Err(csv(
                    line,
                    format!(
                        "column `{name}`: `{}` is not a finite number within ±{MAX_AXIS_VALUE:e}",
                        number(v[k])
                    ),
                ));
            }
        }
        // A run writes one row per sample, at increasing times (the axis and the energy weights
        // rest on it).
        let time = used[0].1;
        let prev = if k > 0 { time[k - 1] } else { f64::NEG_INFINITY };
        if time[k].partial_cmp(&prev) != Some(std::cmp::Ordering::Greater) {
            return Err(csv(
                line,
                format!(
                    "column `time_s`: {} does not follow {} (times increase from row to row, |time| ≤ \
                     {MAX_AXIS_VALUE:e} s)",
                    number(time[k]),
                    number(prev)
                ),
            ));
        }
        let eff = used[used.len() - 1].1[k];
        if !is_efficiency(eff) {
            return Err(csv(
                line,
                format!("column `efficiency`: {} {NOT_AN_EFFICIENCY}", number(eff)),
            ));
        }
    }
    Ok(())
}

/// `name`, or `default` when it is empty (a summary without the key).
pub fn name_or<'a>(name: &'a str, default: &'a str) -> &'a str {
    if name.is_empty() {
        default
    } else {
        name
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

/// Everything a run report needs: the run's summary and its time series as the plots see it.
pub struct RunData<'a> {
    /// The run's `timeseries.csv`, as the figures draw it.
    pub ts: TimeSeries,
    /// Its `summary.json`.
    pub summary: &'a Summary,
}

impl<'a> RunData<'a> {
    /// The figures' view of a run's results (`dir` names the files in errors): the summary's
    /// `cycle_efficiency` must be a fraction in [0, 1] (an efficiency is never drawn or written
    /// over 100 %).
    pub fn new(dir: &Path, summary: &'a Summary, table: &Timeseries) -> Result<RunData<'a>, PlotError> {
        let ts = from_table(table, &dir.join("timeseries.csv"))?;
        if let Some(e) = summary.cycle_efficiency.filter(|e| !is_efficiency(*e)) {
            return Err(PlotError::Data {
                path: dir.join("summary.json"),
                what: format!("cycle_efficiency: {} {NOT_AN_EFFICIENCY}", number(e)),
            });
        }
        Ok(RunData { ts, summary })
    }
}

/// Read `summary.json` and `timeseries.csv` of the run output directory `dir` with the writer's
/// types.
pub fn read_run(dir: &Path) -> Result<(Summary, Timeseries), PlotError> {
    let table = Timeseries::read(&dir.join("timeseries.csv"))?;
    let summary: Summary = read_json(&dir.join("summary.json"))?;
    Ok((summary, table))
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

    /// The grid of a map's rows and `map.json` (`path` names `map.csv` in errors): every value
    /// finite, efficiencies in [0, 1], at least one row, a grid the heat maps can draw
    /// ([`check_grid`]).
    pub fn new(rows: Vec<MapRow>, meta: MapMeta, path: &Path) -> Result<MapGrid, PlotError> {
        check_rows(&rows, path)?;
        grid(rows, meta, path)
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

/// Every value of `rows` finite, every efficiency in [0, 1], at least one row.
fn check_rows(rows: &[MapRow], path: &Path) -> Result<(), PlotError> {
    for (k, r) in rows.iter().enumerate() {
        if r.numbers().any(|v| !v.is_finite()) {
            return Err(PlotError::Csv {
                path: path.to_path_buf(),
                msg: format!(
                    "row {} ({} rpm, {} N m) holds a value that is not a finite number",
                    k + 2,
                    r.speed_rpm,
                    r.torque_nm
                ),
            });
        }
        if let Some(e) = r.efficiency.filter(|e| !is_efficiency(*e)) {
            return Err(PlotError::Csv {
                path: path.to_path_buf(),
                msg: format!(
                    "row {}, column `efficiency`: {} {NOT_AN_EFFICIENCY}",
                    k + 2,
                    number(e)
                ),
            });
        }
    }
    if rows.is_empty() {
        return Err(PlotError::Data {
            path: path.to_path_buf(),
            what: "no data rows".into(),
        });
    }
    Ok(())
}

/// The checked `rows` on their (speed × torque) grid.
fn grid(rows: Vec<MapRow>, meta: MapMeta, path: &Path) -> Result<MapGrid, PlotError> {
    let speeds = unique_sorted(rows.iter().map(|r| r.speed_rpm).collect());
    let torques = unique_sorted(rows.iter().map(|r| r.torque_nm).collect());
    if speeds.is_empty() || torques.is_empty() {
        return Err(PlotError::Data {
            path: path.to_path_buf(),
            what: "no finite speed/torque values".into(),
        });
    }
    check_grid(path, &speeds, &torques)?;
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

/// Read `map.csv` ([`MapRow`]) and `map.json` ([`MapMeta`]) of the map output directory `dir`
/// with the writer's types, onto their grid.
pub fn read_map(dir: &Path) -> Result<MapGrid, PlotError> {
    let path = dir.join("map.csv");
    let mut rdr = open_csv(&path)?;
    let rows: Vec<MapRow> = rdr
        .deserialize::<MapRow>()
        .collect::<Result<_, _>>()
        .map_err(|e| csv_err(&path, e))?;
    check_rows(&rows, &path)?;
    let meta: MapMeta = read_json(&dir.join("map.json"))?;
    grid(rows, meta, &path)
}

/// Read a bench output directory `dir` with the writer's types: `bench.json` into
/// [`BenchResult`] (a key an earlier version did not write reads as its default) and its rows
/// from `bench.csv` into [`BenchRow`] (an empty number is NaN, a failed row's reason is not in
/// the file).
pub fn read_bench(dir: &Path) -> Result<BenchResult, PlotError> {
    let path = dir.join("bench.csv");
    let mut rdr = open_csv(&path)?;
    let headers = rdr.headers().map_err(|e| csv_err(&path, e))?.clone();
    let mut rows = Vec::new();
    for (k, rec) in rdr.records().enumerate() {
        let rec = rec.map_err(|e| csv_err(&path, e))?;
        let bad = |name: &str, field: &str| PlotError::Csv {
            path: path.clone(),
            msg: format!("line {}, column `{name}`: `{field}` is not a valid value", k + 2),
        };
        let field = |name: &str| -> Result<&str, PlotError> {
            let i = headers
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| PlotError::Data {
                    path: path.clone(),
                    what: format!("missing required column `{name}`"),
                })?;
            Ok(rec.get(i).unwrap_or(""))
        };
        let num = |name: &str| -> Result<f64, PlotError> {
            let f = field(name)?;
            parse_num(f).ok_or_else(|| bad(name, f))
        };
        let count = |name: &str| -> Result<usize, PlotError> {
            let f = field(name)?;
            f.parse::<usize>().map_err(|_| bad(name, f))
        };
        let default = field("default")?;
        rows.push(BenchRow {
            solver: field("solver")?.to_string(),
            rtol: num("rtol")?,
            atol: num("atol")?,
            wall_time_s: num("wall_time_s")?,
            steps: count("steps")?,
            rejected: count("rejected")?,
            rhs_evals: count("rhs_evals")?,
            jac_evals: count("jac_evals")?,
            lu_count: count("lu_count")?,
            err_final_k: num("err_final_k")?,
            err_max_k: num("err_max_k")?,
            err_rms_k: num("err_rms_k")?,
            energy_balance_relative: num("energy_balance_relative")?,
            default: default.parse::<bool>().map_err(|_| bad("default", default))?,
            failure: None,
        });
    }
    if rows.is_empty() {
        return Err(PlotError::Data {
            path,
            what: "no data rows".into(),
        });
    }
    let meta: BenchResult = read_json(&dir.join("bench.json"))?;
    Ok(BenchResult { rows, ..meta })
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
