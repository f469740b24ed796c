//! Command-line interface: argument definitions, their conversion into the use-case layer's
//! options ([`crate::job`]), and dispatch. A command converts its arguments once, calls the
//! job, writes the output directory, prints; the exit code comes from the job's error kind (0
//! ok, 1 invalid input, 2 numerical failure, 3 I/O, 141 closed standard output).

use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;

use clap::{Parser, Subcommand};

mod bench;
mod calibrate;
mod check;
mod fmu;
mod output;
mod rating;
mod report;
mod run;
mod steady;
mod study;
#[cfg(test)]
mod tests;
mod uq;
mod validate;

pub use output::Failure;

/// The `geartherm` command line `args` (the program's name first), run as the binary runs it:
/// parse (a usage error exits 1 like any other bad input; clap's own 2 is this tool's code for a
/// numerical failure; `--help` and `--version` exit 0), run, print a failure's message on
/// standard error, flush standard output. Returns the exit code. The binary (`src/main.rs`) and
/// the Python package's `geartherm` console script both call it.
pub fn main<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let code = match Cli::try_parse_from(args) {
        Err(e) => {
            let _ = e.print();
            i32::from(e.use_stderr())
        }
        Ok(cli) => match run(cli) {
            Ok(()) => 0,
            Err(f) => {
                if !f.message.is_empty() {
                    let newline = if f.message.ends_with('\n') { "" } else { "\n" };
                    let _ = write!(std::io::stderr(), "{}{newline}", f.message);
                }
                f.code
            }
        },
    };
    let _ = std::io::stdout().flush();
    code
}

use crate::job;
use crate::model::Override;

/// geartherm: gearbox power losses and temperatures over drive cycles.
#[derive(Parser, Debug)]
#[command(name = "geartherm", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Commands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Validate a model file and list every problem (exit 1 if any).
    Check(check::ModelArgs),
    /// Gear states with ratios, member speeds per unit input, meshes with contact ratios, immersion.
    Info(check::InfoArgs),
    /// Every loss item (churning, pocketing, sliding, …) at one operating point, totals, efficiency.
    Losses(check::LossesArgs),
    /// Drive-cycle transient: losses heat the thermal network; writes timeseries.csv and
    /// summary.json into the output directory.
    Run(run::RunArgs),
    /// Equilibrium temperatures, losses and efficiency at one operating point.
    Steady(steady::SteadyArgs),
    /// Equilibria over a speed × torque grid (map.csv and heat maps).
    Map(steady::MapArgs),
    /// Thermal rating: the highest input torque whose equilibrium oil temperature stays at or
    /// below a limit, at one speed or over a sweep (rating.csv, rating.json, rating.png).
    Rating(rating::RatingArgs),
    /// Design study: every sample of a parameter plan on cycles or operating points, in
    /// parallel; resumable; writes study.csv, study.parquet, main_effects.png, pareto.png.
    Study(study::StudyArgs),
    /// Work-precision study: every solver over rtol 1e-3 … 1e-10 against a 1e-12 reference;
    /// writes bench.csv, bench.json and work_precision.png.
    Bench(bench::BenchArgs),
    /// Every reference case under DIR with every applicable loss model: validation.csv,
    /// per-source summary, parity and error-vs-speed plots (docs/validation.md).
    Validate(validate::ValidateArgs),
    /// PNG plots and report.md from an existing output directory (a run, a map or a bench).
    Report(report::ReportArgs),
    /// Fit model parameters (key paths with bounds) to a measured temperature trace: values with
    /// 95 % intervals, correlations, errors on fitted and held-out rows, calibrated.toml.
    Calibrate(calibrate::CalibrateArgs),
    /// Read a measured trace as `calibrate` does: rows, rows dropped for empty cells, the
    /// segments its gaps in time cut it into.
    Trace(calibrate::TraceArgs),
    /// Uncertainty study: the model's [uncertainty] inputs sampled quasi-randomly, run as a
    /// study (resumable); percentile bands over time, exceedance probabilities of limits, Sobol
    /// indices; writes uq.json, bands.csv, bands.parquet, study.csv (with --report the figures).
    Uq(uq::UqArgs),
    /// Export the model as an FMI 2.0 co-simulation FMU (Linux x86-64, self-contained).
    Fmu(fmu::FmuArgs),
}

/// The model file and `--set PATH=VALUE` overrides, shared by every command that reads a model.
#[derive(clap::Args, Debug, Clone)]
pub struct ModelSource {
    /// Model file (TOML).
    pub model: PathBuf,
    /// Override a model value by its key path, e.g. --set lubrication.oil_level_mm=55,
    /// --set 'oil.catalogue="fva_3a"', --set 'thermal.links["housing-air"].area_m2=0.9'
    /// (the value is TOML; repeatable; checked like the file).
    #[arg(long = "set", value_name = "PATH=VALUE", value_parser = parse_set)]
    pub set: Vec<Override>,
}

fn parse_set(s: &str) -> Result<Override, String> {
    s.parse()
}

impl ModelSource {
    /// Read, override and check the model.
    pub fn load(&self) -> Result<job::Model, Failure> {
        Ok(job::Model::load(&self.model, &self.set)?)
    }
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Check(a) => check::check(&a),
        Command::Info(a) => check::info(&a),
        Command::Losses(a) => check::losses(&a),
        Command::Run(a) => run::run(&a),
        Command::Steady(a) => steady::steady(&a),
        Command::Map(a) => steady::map(&a),
        Command::Rating(a) => rating::rating(&a),
        Command::Study(a) => study::study(&a),
        Command::Bench(a) => bench::bench(&a),
        Command::Validate(a) => validate::validate(&a),
        Command::Report(a) => report::report(&a),
        Command::Calibrate(a) => calibrate::calibrate(&a),
        Command::Trace(a) => calibrate::trace(&a),
        Command::Fmu(a) => fmu::fmu(&a),
        Command::Uq(a) => uq::uq(&a),
    }
}
