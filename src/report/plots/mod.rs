//! PNG reports (plotters, bitmap backend, embedded DejaVu Sans font).
//!
//! - [`render_run`]: `temperatures.png`, `losses.png`, `energy.png`, `efficiency.png` and
//!   `report.md` from a run's results in memory (its [`Summary`] and [`Timeseries`]);
//!   [`render_run_dir`] reads them from a run directory (`summary.json`, `timeseries.csv`) with
//!   the same types.
//! - [`render_map`]: `map_efficiency.png`, `map_total_loss.png`, `map_oil_temp.png` and
//!   `report.md` from a map's results in memory (its [`MapRow`]s and [`MapMeta`]);
//!   [`render_map_dir`] reads them from a map directory (`map.csv`, `map.json`) with the same
//!   types.
//! - [`render_bench`]: `work_precision.png` from a work-precision study's [`BenchResult`] in
//!   memory; [`render_bench_dir`] reads it from a bench directory (`bench.json`, `bench.csv`)
//!   with the same types.
//! - [`rating::render`]: `rating.png`, the thermal rating curve of a `rating` sweep.
//!
//! Every PNG is 1600×1000 px. Each output is rendered to a temporary file in the target
//! directory and all outputs of one call are renamed into place only after every one of them
//! rendered: a failure leaves no partial file and does not overwrite earlier results.

use std::error::Error;
use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use tempfile::NamedTempFile;

use crate::report::bench::BenchResult;
use crate::report::map::{MapMeta, MapRow};
use crate::report::run::Summary;
use crate::report::timeseries::Timeseries;

pub mod calibration;
pub mod data;
pub mod efficiency;
pub mod energy;
pub mod error;
pub mod heatmap;
pub mod index;
pub mod losses;
pub mod map_index;
pub mod panel;
pub mod quantity;
pub mod rating;
pub mod study;
pub mod style;
pub mod temperatures;
pub mod uq;
pub mod validation;
pub mod work_precision;

#[cfg(test)]
mod tests;

pub use error::PlotError;

/// The bitmap drawing area every figure draws on.
pub(crate) type Canvas<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
pub(crate) type DrawResult = Result<(), Box<dyn Error>>;

/// An output rendered to a temporary file, waiting to be renamed to `dest`.
pub(crate) struct Staged {
    tmp: NamedTempFile,
    dest: PathBuf,
}

fn io_err(path: &Path, source: std::io::Error) -> PlotError {
    PlotError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn temp_in(dir: &Path, name: &str, suffix: &str) -> Result<NamedTempFile, PlotError> {
    let prefix = format!(".{name}.");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(suffix);
    // The usual mode (0666 less the umask), not tempfile's owner-only 0600.
    #[cfg(unix)]
    b.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    b.tempfile_in(dir).map_err(|e| io_err(&dir.join(name), e))
}

/// Render a 1600×1000 PNG into a temporary file in `dir` that becomes `name` on commit.
pub(crate) fn stage_png(
    dir: &Path,
    name: &str,
    draw: impl FnOnce(&Canvas) -> DrawResult,
) -> Result<Staged, PlotError> {
    let dest = dir.join(name);
    let tmp = temp_in(dir, name, ".png")?;
    let draw_err = |e: &dyn std::fmt::Display| PlotError::Draw {
        path: dest.clone(),
        msg: e.to_string(),
    };
    {
        let root = BitMapBackend::new(tmp.path(), (style::WIDTH, style::HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(&e))?;
        draw(&root).map_err(|e| draw_err(&e))?;
        root.present().map_err(|e| draw_err(&e))?;
    }
    Ok(Staged { tmp, dest })
}

/// Write a text file into a temporary file in `dir` that becomes `name` on commit.
pub(crate) fn stage_text(dir: &Path, name: &str, content: &str) -> Result<Staged, PlotError> {
    use std::io::Write;
    let dest = dir.join(name);
    let mut tmp = temp_in(dir, name, ".tmp")?;
    tmp.write_all(content.as_bytes()).map_err(|e| io_err(&dest, e))?;
    tmp.as_file().sync_all().map_err(|e| io_err(&dest, e))?;
    Ok(Staged { tmp, dest })
}

/// Rename every staged file into place.
pub(crate) fn commit(staged: Vec<Staged>) -> Result<Vec<PathBuf>, PlotError> {
    let mut out = Vec::with_capacity(staged.len());
    for s in staged {
        s.tmp.persist(&s.dest).map_err(|e| io_err(&s.dest, e.error))?;
        out.push(s.dest);
    }
    Ok(out)
}

/// Run the stage jobs on scoped threads (figures are independent) and collect their results.
fn stage_parallel<'a>(
    jobs: Vec<Box<dyn FnOnce() -> Result<Staged, PlotError> + Send + 'a>>,
) -> Result<Vec<Staged>, PlotError> {
    let results: Vec<Result<Staged, PlotError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = jobs.into_iter().map(|job| scope.spawn(job)).collect();
        handles
            .into_iter()
            .map(|h| {
                h.join().unwrap_or_else(|_| {
                    Err(PlotError::Data {
                        path: PathBuf::new(),
                        what: "renderer panicked".into(),
                    })
                })
            })
            .collect()
    });
    results.into_iter().collect()
}

fn check_dir(dir: &Path) -> Result<(), PlotError> {
    if dir.is_dir() {
        Ok(())
    } else {
        Err(PlotError::Data {
            path: dir.to_path_buf(),
            what: "not a directory".into(),
        })
    }
}

/// Render the run report of `summary` and `table` (the run's results) into `dir`. Returns the
/// paths written: the four PNGs and `report.md`.
pub fn render_run(dir: &Path, summary: &Summary, table: &Timeseries) -> Result<Vec<PathBuf>, PlotError> {
    check_dir(dir)?;
    style::ensure_fonts()?;
    let run = data::RunData::new(dir, summary, table)?;
    let run = &run;
    let jobs: Vec<Box<dyn FnOnce() -> Result<Staged, PlotError> + Send + '_>> = vec![
        Box::new(move || stage_png(dir, "temperatures.png", |root| temperatures::draw(root, run))),
        Box::new(move || stage_png(dir, "losses.png", |root| losses::draw(root, run))),
        Box::new(move || stage_png(dir, "energy.png", |root| energy::draw(root, run))),
        Box::new(move || stage_png(dir, "efficiency.png", |root| efficiency::draw(root, run))),
        Box::new(move || stage_text(dir, "report.md", &index::markdown(run))),
    ];
    commit(stage_parallel(jobs)?)
}

/// Read the run directory `dir` (`summary.json`, `timeseries.csv`, with the writer's types) and
/// render its report into it ([`render_run`]).
pub fn render_run_dir(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    check_dir(dir)?;
    let (summary, table) = data::read_run(dir)?;
    render_run(dir, &summary, &table)
}

/// Render the three heat maps and `report.md` of a map's results (`rows` of `map.csv`, `meta`
/// of `map.json`) into `dir`. Returns the paths written.
pub fn render_map(dir: &Path, rows: &[MapRow], meta: &MapMeta) -> Result<Vec<PathBuf>, PlotError> {
    check_dir(dir)?;
    let grid = data::MapGrid::new(rows.to_vec(), meta.clone(), &dir.join("map.csv"))?;
    render_grid(dir, &grid)
}

/// Read the map directory `dir` (`map.csv`, `map.json`, with the writer's types) and render its
/// report into it ([`render_map`]).
pub fn render_map_dir(dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    check_dir(dir)?;
    let grid = data::read_map(dir)?;
    render_grid(dir, &grid)
}

/// The heat maps and `report.md` of `grid` into `dir`.
fn render_grid(dir: &Path, grid: &data::MapGrid) -> Result<Vec<PathBuf>, PlotError> {
    style::ensure_fonts()?;
    let mut jobs: Vec<Box<dyn FnOnce() -> Result<Staged, PlotError> + Send + '_>> = heatmap::Quantity::ALL
        .into_iter()
        .map(|q| {
            Box::new(move || stage_png(dir, q.file_name(), |root| heatmap::draw(root, grid, q)))
                as Box<dyn FnOnce() -> Result<Staged, PlotError> + Send>
        })
        .collect();
    jobs.push(Box::new(move || {
        stage_text(dir, "report.md", &map_index::markdown(grid))
    }));
    commit(stage_parallel(jobs)?)
}

/// Write the validation outputs into `dir` at once (all or nothing): `validation.csv`,
/// `validation_summary.csv`, `validation.md`, `parity_sliding.png`, `parity_churning.png`,
/// `error_vs_speed_sliding.png`, `error_vs_speed_churning.png`.
pub fn render_validation(
    dir: &Path,
    rows: &[crate::reference::Row],
    texts: &[(&str, String)],
) -> Result<Vec<PathBuf>, PlotError> {
    std::fs::create_dir_all(dir).map_err(|e| io_err(dir, e))?;
    style::ensure_fonts()?;
    let pick = |q: &str| -> Vec<&crate::reference::Row> { rows.iter().filter(|r| r.quantity == q).collect() };
    let (sl, ch) = (pick("sliding"), pick("churning"));
    let el: Vec<&crate::reference::Row> = rows
        .iter()
        .filter(|r| !matches!(r.quantity, "sliding" | "churning" | "efficiency"))
        .collect();
    let eff = pick("efficiency");
    let (sl, ch, el, eff) = (&sl, &ch, &el, &eff);
    let mut jobs: Vec<Box<dyn FnOnce() -> Result<Staged, PlotError> + Send + '_>> = vec![
        Box::new(move || {
            stage_png(dir, "parity_sliding.png", |r| {
                validation::draw_parity(r, sl, "Sliding loss: geartherm vs references")
            })
        }),
        Box::new(move || {
            stage_png(dir, "parity_churning.png", |r| {
                validation::draw_parity(r, ch, "Churning loss: geartherm vs references")
            })
        }),
        Box::new(move || {
            stage_png(dir, "error_vs_speed_sliding.png", |r| {
                validation::draw_error_vs_speed(r, sl, "Sliding loss: relative error vs input speed")
            })
        }),
        Box::new(move || {
            stage_png(dir, "error_vs_speed_churning.png", |r| {
                validation::draw_error_vs_speed(r, ch, "Churning loss: relative error vs input speed")
            })
        }),
        Box::new(move || {
            stage_png(dir, "parity_elements.png", |r| {
                validation::draw_parity(
                    r,
                    el,
                    "Bearings, seals and the automatic's losses: geartherm vs references",
                )
            })
        }),
        Box::new(move || {
            stage_png(dir, "range_distance_efficiency.png", |r| {
                validation::draw_range_distance(
                    r,
                    eff,
                    "Efficiency: distance to the handbook ranges vs input speed",
                )
            })
        }),
    ];
    for (name, text) in texts {
        jobs.push(Box::new(move || stage_text(dir, name, text)));
    }
    commit(stage_parallel(jobs)?)
}

/// Render `work_precision.png` of a work-precision study's results into `dir`. Returns the
/// path written.
pub fn render_bench(dir: &Path, result: &BenchResult) -> Result<PathBuf, PlotError> {
    check_dir(dir)?;
    style::ensure_fonts()?;
    let staged = stage_png(dir, "work_precision.png", |root| {
        work_precision::draw(root, &result.rows, &result.model, &result.cycle)
    })?;
    let mut paths = commit(vec![staged])?;
    paths.pop().ok_or_else(|| PlotError::Data {
        path: dir.to_path_buf(),
        what: "nothing written".into(),
    })
}

/// Read the bench directory `dir` (`bench.json`, `bench.csv`, with the writer's types) and
/// render `work_precision.png` into it ([`render_bench`]).
pub fn render_bench_dir(dir: &Path) -> Result<PathBuf, PlotError> {
    check_dir(dir)?;
    let result = data::read_bench(dir)?;
    render_bench(dir, &result)
}
