//! `geartherm bench`: the work-precision study of one model over one cycle.

use std::path::PathBuf;

use crate::job::bench::BenchRow;
use crate::job::bench::{bench as run_bench, BenchOptions};
use crate::report::files::OutputDir;

use super::output::{emit, io_failure, warn};
use super::{Failure, ModelSource};

/// Arguments of `bench`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub source: ModelSource,
    /// Cycle (bundled name or CSV).
    #[arg(long, default_value = "wltc")]
    pub cycle: String,
    /// Output directory (default: bench/<model>_<cycle>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Repeats per point (median wall time; 1 … 1000).
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// Tightest tolerance of the sweep (1e-13 … 1e-3; the sweep goes 1e-3 … this, one per decade).
    #[arg(long, default_value_t = 1e-10)]
    pub min_rtol: f64,
    /// Solvers (comma-separated).
    #[arg(long, default_value = "bdf,esdirk34,tr-bdf2,ros3,tsit45")]
    pub solvers: String,
    /// Step budget per run (an explicit solver on a stiff network stops there and is reported).
    #[arg(long, default_value_t = 2_000_000)]
    pub max_steps: usize,
}

impl BenchArgs {
    /// The job's options.
    pub fn options(&self) -> BenchOptions {
        BenchOptions {
            cycle: self.cycle.clone(),
            repeats: self.repeats,
            min_rtol: self.min_rtol,
            solvers: self.solvers.split(',').map(|s| s.trim().to_string()).collect(),
            max_steps: self.max_steps,
        }
    }
}

fn row_line(row: &BenchRow) -> String {
    if let Some(f) = &row.failure {
        // A failed row has no time or error: said in words, never as NaN.
        return format!(
            "{:<9} rtol {:>7.0e} atol {:>7.0e}: FAILED: {f}",
            row.solver, row.rtol, row.atol
        );
    }
    format!(
        "{:<9} rtol {:>7.0e} atol {:>7.0e}: {:>9.4} ms, err max {:>9.2e} K final {:>9.2e} K, {:>6} steps, {:>5} rejected, {:>7} RHS, {:>5} LU{}",
        row.solver,
        row.rtol,
        row.atol,
        row.wall_time_s * 1e3,
        row.err_max_k,
        row.err_final_k,
        row.steps,
        row.rejected,
        row.rhs_evals,
        row.lu_count,
        row.failure.as_ref().map(|f| format!("  FAILED: {f}")).unwrap_or_default()
    )
}

/// Run the study, write bench.csv, bench.json and work_precision.png; print where.
pub fn bench(args: &BenchArgs) -> Result<(), Failure> {
    let m = args.source.load()?;
    let o = args.options();
    let r = run_bench(
        &m,
        &o,
        &mut |info| {
            warn(&format!(
                "reference: {} and {} at rtol = atol = 1e-12 agree to {:.2e} K (max over nodes and the 1 Hz grid)",
                info.methods[0], info.methods[1], info.agreement_k
            ))
        },
        &mut |row| warn(&row_line(row)),
    )?;
    warn(&format!(
        "default ({} rtol {:.0e}) on the Pareto front of (wall time, max error): {} among all solvers, {} among the implicit solvers",
        r.default.solver, r.default.rtol, r.default.on_pareto_front, r.default.on_implicit_pareto_front
    ));
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("bench").join(format!("{}_{}", m.stem(), r.cycle)));
    let out = OutputDir::begin(&dir)?;
    for (name, bytes) in r.files()? {
        out.write(name, &bytes)?;
    }
    crate::report::plots::render_bench(out.path(), &r).map_err(|e| io_failure(format!("plot: {e}")))?;
    emit(&format!(
        "{}\n{}\n",
        out.target().join("bench.csv").display(),
        out.target().join("work_precision.png").display()
    ))?;
    out.commit()?;
    Ok(())
}
