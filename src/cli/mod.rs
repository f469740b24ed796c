//! Command-line interface: argument definitions and command dispatch. Parses, calls the library,
//! prints, and maps errors to exit codes (0 ok, 1 invalid input, 2 numerical failure, 3 I/O).

use std::path::PathBuf;

use clap::{Parser, Subcommand};

mod bench;
mod run;
mod steady;
mod study;
mod validate;

use geartherm::model::{self, Gearbox, ModelError};
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::report::{info, losses};
use geartherm::scene::{LossScene, OperatingPoint};

/// Exit code: invalid input (nothing written).
pub const EXIT_INVALID: i32 = 1;
/// Exit code: numerical failure.
pub const EXIT_NUMERICAL: i32 = 2;
/// Exit code: I/O failure while writing outputs.
pub const EXIT_IO: i32 = 3;

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
    Check {
        /// Model file (TOML).
        model: PathBuf,
        #[command(flatten)]
        set: SetArgs,
    },
    /// Gear states with ratios, member speeds per unit input, meshes with contact ratios, immersion.
    Info {
        /// Model file (TOML).
        model: PathBuf,
        #[command(flatten)]
        set: SetArgs,
        /// Print one JSON document instead of tables.
        #[arg(long)]
        json: bool,
    },
    /// Every loss item (churning, pocketing, sliding) at one operating point, totals, efficiency.
    Losses {
        /// Model file (TOML).
        model: PathBuf,
        #[command(flatten)]
        set: SetArgs,
        /// Gear state name (e.g. 3, R).
        #[arg(long)]
        gear: String,
        /// Input speed, rpm (≥ 0).
        #[arg(long, allow_negative_numbers = true)]
        speed_rpm: f64,
        /// Input torque, N m (≥ 0: drive).
        #[arg(long, allow_negative_numbers = true)]
        torque_nm: f64,
        /// Oil temperature, °C.
        #[arg(long, allow_negative_numbers = true)]
        oil_temp_c: f64,
        /// Print one JSON document instead of tables.
        #[arg(long)]
        json: bool,
    },
    /// Drive-cycle transient: losses heat the thermal network; writes timeseries.csv and
    /// summary.json into the output directory.
    Run(run::RunArgs),
    /// Equilibrium temperatures, losses and efficiency at one operating point.
    Steady(steady::SteadyArgs),
    /// Equilibria over a speed × torque grid (map.csv and heat maps).
    Map(steady::MapArgs),
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
    Report {
        /// Directory with timeseries.csv + summary.json, map.csv, or bench.csv.
        dir: PathBuf,
    },
}

/// `--set PATH=VALUE`: model values overridden by key path (repeatable).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct SetArgs {
    /// Override a model value by its key path, e.g. --set lubrication.oil_level_mm=55,
    /// --set 'oil.catalogue="fva_3a"', --set 'thermal.links["housing-air"].area_m2=0.9'
    /// (the value is TOML; repeatable; checked like the file).
    #[arg(long = "set", value_name = "PATH=VALUE", value_parser = parse_set)]
    pub set: Vec<model::Override>,
}

fn parse_set(s: &str) -> Result<model::Override, String> {
    s.parse()
}

impl SetArgs {
    /// Load the model file with these overrides.
    pub fn load(&self, path: &std::path::Path) -> Result<Gearbox, ModelError> {
        model::load_with(path, &self.set)
    }
}

/// A failure with its exit code and message.
pub struct Failure {
    /// Exit code.
    pub code: i32,
    /// Message for stderr.
    pub message: String,
}

impl From<ModelError> for Failure {
    fn from(e: ModelError) -> Self {
        // A file that cannot be read (missing, no permission, a directory) is I/O; one that is
        // read but is not UTF-8 text is invalid input.
        let code = match &e {
            ModelError::Io { source, .. } if source.kind() != std::io::ErrorKind::InvalidData => EXIT_IO,
            _ => EXIT_INVALID,
        };
        Failure {
            code,
            message: e.report(),
        }
    }
}

impl From<geartherm::report::files::OutputError> for Failure {
    fn from(e: geartherm::report::files::OutputError) -> Self {
        Failure {
            code: EXIT_IO,
            message: format!("cannot write outputs: {e}"),
        }
    }
}

/// A cycle that cannot be used: I/O (exit 3) when the file exists but cannot be read, else
/// invalid input.
pub(crate) fn cycle_failure(e: geartherm::cycle::CycleError) -> Failure {
    let code = if e.kind == geartherm::cycle::CycleErrorKind::Io {
        EXIT_IO
    } else {
        EXIT_INVALID
    };
    Failure {
        code,
        message: format!("--cycle: {e}"),
    }
}

fn invalid(message: String) -> Failure {
    Failure {
        code: EXIT_INVALID,
        message,
    }
}

fn print_json<T: serde::Serialize>(value: &T) -> Result<(), Failure> {
    let text = serde_json::to_string_pretty(value).map_err(|e| Failure {
        code: EXIT_IO,
        message: format!("cannot serialise the report: {e}"),
    })?;
    println!("{text}");
    Ok(())
}

fn state_index(gb: &Gearbox, gear: &str) -> Result<usize, Failure> {
    gb.state_index(gear).ok_or_else(|| {
        let names: Vec<&str> = gb.gear_states.iter().map(|s| s.name.as_str()).collect();
        invalid(format!(
            "--gear {gear}: unknown gear state; the model has: {}",
            names.join(", ")
        ))
    })
}

fn check_range(flag: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Result<(), Failure> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(invalid(format!("{flag} {v}: must lie in [{lo}, {hi}]{unit}")))
    }
}

/// `report DIR`: re-render a run, map or bench directory as one transaction (its inputs are
/// carried into the new result set, the figures and report.md replace the old ones whole).
fn report(dir: &std::path::Path) -> Result<(), Failure> {
    use geartherm::report::plots::{self, PlotError};
    let fail = |e: PlotError| Failure {
        // Unreadable or malformed inputs are invalid input; failing to write is I/O.
        code: match &e {
            PlotError::Csv { .. } | PlotError::Json { .. } | PlotError::Data { .. } => EXIT_INVALID,
            PlotError::Io { source, .. } if source.kind() == std::io::ErrorKind::InvalidData => EXIT_INVALID,
            _ => EXIT_IO,
        },
        message: format!("report: {e}"),
    };
    let kinds = [
        ("timeseries.csv", "summary.json"),
        ("map.csv", "map.json"),
        ("bench.csv", "bench.json"),
    ];
    if !dir.is_dir() || !kinds.iter().any(|(a, _)| dir.join(a).is_file()) {
        return Err(invalid(format!(
            "report: {} holds no timeseries.csv, map.csv or bench.csv",
            dir.display()
        )));
    }
    let out = geartherm::report::files::OutputDir::begin(dir)?;
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
        written.extend(plots::render_run(out.path()).map_err(fail)?);
    }
    if out.path().join("map.csv").is_file() {
        written.extend(plots::render_map(out.path()).map_err(fail)?);
    }
    if out.path().join("bench.csv").is_file() {
        written.push(plots::render_bench(out.path()).map_err(fail)?);
    }
    let target = out.commit()?;
    for p in written {
        if let Some(name) = p.file_name() {
            println!("{}", target.join(name).display());
        }
    }
    Ok(())
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Check { model, set } => {
            let gb = set.load(&model)?;
            println!(
                "{}: ok ({} gears, {} meshes, {} gear states)",
                model.display(),
                gb.gears.len(),
                gb.meshes.len(),
                gb.gear_states.len()
            );
            Ok(())
        }
        Command::Info { model, set, json } => {
            let gb = set.load(&model)?;
            let report = info::info(&gb);
            if json {
                print_json(&report)?;
            } else {
                print!("{}", info::to_text(&report, &gb));
            }
            Ok(())
        }
        Command::Losses {
            model,
            set,
            gear,
            speed_rpm,
            torque_nm,
            oil_temp_c,
            json,
        } => {
            let gb = set.load(&model)?;
            let state = state_index(&gb, &gear)?;
            check_range("--speed-rpm", speed_rpm, 0.0, 50_000.0, " rpm")?;
            check_range("--torque-nm", torque_nm, 0.0, 1e6, " N m")?;
            check_range("--oil-temp-c", oil_temp_c, -60.0, 250.0, " °C")?;
            let scene = LossScene::compile(&gb).map_err(|e| invalid(format!("{}: {e}", model.display())))?;
            let op = OperatingPoint {
                state,
                input_speed: speed_rpm * std::f64::consts::PI / 30.0,
                input_torque: torque_nm,
                oil: gb.oil.properties(oil_temp_c + KELVIN_OFFSET),
            };
            if !(op.oil.nu.is_finite() && op.oil.nu > 0.0 && op.oil.rho.is_finite() && op.oil.rho > 0.0) {
                return Err(invalid(format!(
                    "--oil-temp-c {oil_temp_c}: the oil of {} has no finite viscosity there (ν = {} m²/s)",
                    model.display(),
                    op.oil.nu
                )));
            }
            let report = losses::losses(&gb, &scene, &op, oil_temp_c);
            let bad = report
                .items
                .iter()
                .find(|it| !it.w.is_finite())
                .map(|it| format!("loss item {}:{}", it.source.as_str(), it.name))
                .or_else(|| (!report.total_w.is_finite()).then(|| "total loss".to_string()));
            if let Some(what) = bad {
                return Err(Failure {
                    code: EXIT_NUMERICAL,
                    message: format!(
                        "{}: {what} is not finite at gear {gear}, {} rpm, {} N m, {} °C",
                        model.display(),
                        short(speed_rpm),
                        short(torque_nm),
                        short(oil_temp_c)
                    ),
                });
            }
            print_warnings(&report.warnings);
            if json {
                print_json(&report)?;
            } else {
                print!("{}", losses::to_text(&report));
            }
            Ok(())
        }
        Command::Report { dir } => report(&dir),
        Command::Bench(args) => bench::bench(&args),
        Command::Study(args) => study::study(&args),
        Command::Validate(args) => validate::validate(&args),
        Command::Steady(args) => steady::steady(&args),
        Command::Map(args) => steady::map(&args),
        Command::Run(args) => {
            let outcome = run::run(&args)?;
            print_warnings(&outcome.summary.warnings);
            if args.json {
                print_json(&outcome.summary)?;
            } else {
                print!("{}", run::to_text(&outcome));
            }
            Ok(())
        }
    }
}

/// Print each out-of-range warning as one stderr line (the scene only collects them).
pub(crate) fn print_warnings(w: &[geartherm::scene::ranges::RangeWarning]) {
    for x in w {
        eprintln!("{x}");
    }
}

/// A number as a user typed it: plain in the usual range, in exponent form outside it (so that
/// 1e-300 is not printed with 300 zeros).
fn short(x: f64) -> String {
    if x == 0.0 || (1e-4..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
