//! `geartherm run`: a drive-cycle transient, written to `timeseries.csv` and `summary.json`.

use std::path::PathBuf;

use crate::job::run::{prepare, solve, RunOptions, DEFAULT_ATOL, DEFAULT_METHOD, DEFAULT_RTOL};
use crate::job::{self, RunResult};
use crate::report::files::OutputDir;
use crate::report::timeseries::Timeseries;

use super::output::{emit, emit_json, io_failure, progress_bar, warnings};
use super::{Failure, ModelSource};

/// Arguments of `run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    #[command(flatten)]
    pub source: ModelSource,
    /// Bundled cycle name (wltc, nedc, ftp75, udds, hwfet, us06, artemis_urban, artemis_road,
    /// artemis_motorway130, artemis_motorway150) or a CSV file (vehicle or rig cycle).
    #[arg(long, default_value = "wltc")]
    pub cycle: String,
    /// Output directory (default: runs/<model>_<cycle>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Solver: auto (default: ros3 up to 24 nodes, tr-bdf2 above), ros3, tr-bdf2, esdirk34, bdf,
    /// tsit45.
    #[arg(long, default_value = DEFAULT_METHOD.name())]
    pub solver: String,
    /// Relative tolerance (1e-14 … 0.1).
    #[arg(long, default_value_t = DEFAULT_RTOL)]
    pub rtol: f64,
    /// Absolute tolerance on temperatures, K (1e-14 … 1).
    #[arg(long, default_value_t = DEFAULT_ATOL)]
    pub atol: f64,
    /// Initial temperature of every node, °C (within the oil's range, at most −60 … 200;
    /// default: the model's).
    #[arg(long, allow_negative_numbers = true)]
    pub initial_temp_c: Option<f64>,
    /// Ambient temperature, °C (−60 … 150; default: the model's ambient boundary).
    #[arg(long, allow_negative_numbers = true)]
    pub ambient_c: Option<f64>,
    /// Freeze the oil properties at this temperature, °C (within the oil's range, at most
    /// −60 … 200; switches the viscosity feedback off).
    #[arg(long, allow_negative_numbers = true)]
    pub frozen_viscosity_c: Option<f64>,
    /// Also write PNG plots and report.md.
    #[arg(long)]
    pub report: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Step budget of the solver (the run fails with exit 2 beyond it).
    #[arg(long, default_value_t = job::run::DEFAULT_MAX_STEPS)]
    pub max_steps: usize,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write summary.json only: no timeseries.csv, and loss energy per source instead of per
    /// item (the scene leaves out what these outputs would need). Not with --report.
    #[arg(long, conflicts_with = "report")]
    pub summary_only: bool,
    /// Evaluate everything: no scene pruning of unused gear states and idle items, no
    /// per-sample loss cache (for measuring what they save; results agree to rounding).
    #[arg(long)]
    pub evaluate_all: bool,
    /// Model-form spread: the energy each applicable model choice of every loss source would
    /// give along this run's trajectory, in summary.json (docs/uq.md).
    #[arg(long)]
    pub spread: bool,
}

impl RunArgs {
    /// The job's options.
    pub fn options(&self) -> RunOptions {
        RunOptions {
            cycle: self.cycle.clone(),
            cycle_text: None,
            solver: self.solver.clone(),
            rtol: self.rtol,
            atol: self.atol,
            initial_temp_c: self.initial_temp_c,
            ambient_c: self.ambient_c,
            frozen_viscosity_c: self.frozen_viscosity_c,
            max_steps: self.max_steps,
            summary_only: self.summary_only,
            evaluate_all: self.evaluate_all,
            spread: self.spread,
        }
    }
}

/// The whole command: check and compile (exit 1 before anything is touched), lock the output
/// directory, integrate, check, write, print, commit.
pub fn run(args: &RunArgs) -> Result<(), Failure> {
    let m = args.source.load()?;
    let o = args.options();
    let p = prepare(&m, &o)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{}_{}", m.stem(), p.cycle.name)));
    // The output directory is locked (a second writer is refused now, not after the run) and
    // written as one transaction: the previous result stays whole until the commit.
    let out = OutputDir::begin(&dir)?;
    let bar = progress_bar(
        p.segs.len(),
        "{spinner} {msg} [{bar:40}] {pos}/{len} s of cycle ({eta})",
        format!("{} on {}", m.gearbox.name, p.cycle.name),
        args.quiet,
    );
    let result = solve(&m, &p, &mut |k, _| {
        if let Some(b) = &bar {
            if k % 20 == 0 {
                b.set_position(k as u64);
            }
        }
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let result = result?;
    for (name, bytes) in result.files()? {
        out.write(name, &bytes)?;
    }
    if args.report {
        // The figures from the results in memory (the table parsed from the run's own text, not
        // re-read from the file just written).
        let fail = |e: crate::report::plots::PlotError| io_failure(format!("report: {e}"));
        let csv = result.timeseries_csv.as_deref().unwrap_or_default();
        let table = Timeseries::parse(csv.as_bytes(), &out.path().join("timeseries.csv")).map_err(fail)?;
        crate::report::plots::render_run(out.path(), &result.summary, &table).map_err(fail)?;
    }
    warnings(&result.summary.warnings);
    if args.json {
        emit_json(&result.summary)?;
    } else {
        emit(&to_text(&result, out.target()))?;
    }
    out.commit()?;
    Ok(())
}

/// Human-readable summary for stdout.
pub fn to_text(r: &RunResult, dir: &std::path::Path) -> String {
    let s = &r.summary;
    let mut t = String::new();
    t.push_str(&format!(
        "{} over {} ({:.0} s): {} in {:.3} s wall, {} steps, {} rejected, {} RHS evaluations\n",
        s.model, s.cycle, s.duration_s, s.solver, s.wall_time_s, s.steps, s.stats.rejected, s.stats.rhs_evals
    ));
    let e = &s.energy_lost_j;
    t.push_str(&format!(
        "energy lost: {}, total {:.1} kJ\n",
        e.text(1e-3, "kJ", 2),
        e.sum() / 1e3
    ));
    t.push_str(&format!(
        "energy balance residual {:.2e} (relative); cycle efficiency (energy-weighted) {}\n",
        s.energy_balance_relative,
        s.cycle_efficiency.map_or("n/a".into(), |x| format!("{x:.4}"))
    ));
    t.push_str("temperatures, °C        min      max    final\n");
    for (name, ts) in &s.temperatures_c {
        t.push_str(&format!(
            "  {name:<18} {:>8.2} {:>8.2} {:>8.2}\n",
            ts.min, ts.max, ts.r#final
        ));
    }
    t.push_str(&format!("outputs in {}\n", dir.display()));
    t
}
