//! `geartherm report DIR`: re-render a run, map or bench directory as one transaction (its
//! inputs are carried into the new result set, the figures and report.md replace the old ones
//! whole).

use std::path::PathBuf;

use crate::job::JobError;
use crate::report::files::OutputDir;
use crate::report::plots;

use super::output::{emit, invalid};
use super::Failure;

/// Arguments of `report`.
#[derive(clap::Args, Debug)]
pub struct ReportArgs {
    /// Directory with timeseries.csv + summary.json, map.csv, or bench.csv.
    pub dir: PathBuf,
}

/// A figure's failure with the exit code of its kind ([`JobError`]'s conversion).
fn failure(e: plots::PlotError) -> Failure {
    JobError::from(e).into()
}

/// Run `report`.
pub fn report(a: &ReportArgs) -> Result<(), Failure> {
    let dir = &a.dir;
    let kinds = ["timeseries.csv", "map.csv", "bench.csv"];
    if !dir.is_dir() || !kinds.iter().any(|k| dir.join(k).is_file()) {
        return Err(invalid(format!(
            "report: {} holds no timeseries.csv, map.csv or bench.csv",
            dir.display()
        )));
    }
    let out = OutputDir::begin(dir)?;
    out.carry_over(&[
        "timeseries.csv",
        "summary.json",
        "map.csv",
        "map.json",
        "bench.csv",
        "bench.json",
    ])?;
    let mut written = Vec::new();
    if out.path().join("timeseries.csv").is_file() {
        written.extend(plots::render_run_dir(out.path()).map_err(failure)?);
    }
    if out.path().join("map.csv").is_file() {
        written.extend(plots::render_map_dir(out.path()).map_err(failure)?);
    }
    if out.path().join("bench.csv").is_file() {
        written.push(plots::render_bench_dir(out.path()).map_err(failure)?);
    }
    let text: String = written
        .iter()
        .filter_map(|p| p.file_name())
        .map(|name| format!("{}\n", out.target().join(name).display()))
        .collect();
    emit(&text)?;
    out.commit()?;
    Ok(())
}
