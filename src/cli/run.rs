//! `geartherm run`: a drive-cycle transient, written to `timeseries.csv` and `summary.json`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use geartherm::cycle::DriveCycle;
use geartherm::cycle::Schedule;
use geartherm::model::Gearbox;
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::report::files::OutputDir;
use geartherm::report::run::{check_finite, summary, timeseries_csv, Summary};
use geartherm::scene::{Needs, Scene};
use geartherm::solve::drive::{row_inputs, segments};
use geartherm::solve::transient::{
    check_stored_values, integrate, Method, Restart, Segment, Trajectory, TransientOptions,
};

use super::{check_range, invalid, Failure, EXIT_IO, EXIT_NUMERICAL};

/// Arguments of `run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// Model file (TOML).
    pub model: PathBuf,
    #[command(flatten)]
    pub set: super::SetArgs,
    /// Bundled cycle name (wltc, nedc, ftp75, udds, hwfet, us06, artemis_urban, artemis_road,
    /// artemis_motorway130, artemis_motorway150) or a CSV file (vehicle or rig cycle).
    #[arg(long, default_value = "wltc")]
    pub cycle: String,
    /// Output directory (default: runs/<model>_<cycle>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Solver: auto (default: ros3 up to 24 nodes, tr-bdf2 above), ros3, tr-bdf2, esdirk34, bdf,
    /// tsit45.
    #[arg(long, default_value = geartherm::solve::transient::DEFAULT_METHOD.name())]
    pub solver: String,
    /// Relative tolerance.
    #[arg(long, default_value_t = geartherm::solve::transient::DEFAULT_RTOL)]
    pub rtol: f64,
    /// Absolute tolerance on temperatures, K.
    #[arg(long, default_value_t = geartherm::solve::transient::DEFAULT_ATOL)]
    pub atol: f64,
    /// Initial temperature of every node, °C (default: the model's).
    #[arg(long, allow_negative_numbers = true)]
    pub initial_temp_c: Option<f64>,
    /// Ambient temperature, °C (default: the model's ambient boundary).
    #[arg(long, allow_negative_numbers = true)]
    pub ambient_c: Option<f64>,
    /// Freeze the oil properties at this temperature, °C (switches the viscosity feedback off).
    #[arg(long, allow_negative_numbers = true)]
    pub frozen_viscosity_c: Option<f64>,
    /// Also write PNG plots and report.md.
    #[arg(long)]
    pub report: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Step budget of the solver (the run fails with exit 2 beyond it).
    #[arg(long, default_value_t = 5_000_000)]
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
}

/// Largest relative energy-balance residual a run may write (a converged integration closes
/// it to about 1e-7; a residual near 1 means the numbers are meaningless).
pub const MAX_ENERGY_RESIDUAL: f64 = 1e-2;

/// A checked, compiled run, ready to integrate.
pub struct Prepared {
    /// The model.
    pub gb: Gearbox,
    /// The scene compiled for this cycle.
    pub scene: Scene,
    /// The cycle.
    pub cycle: DriveCycle,
    /// Its schedule (gear, speeds, torques per interval).
    pub sched: Schedule,
    /// Integration segments.
    pub segs: Vec<Segment>,
    /// Solver options.
    pub opts: TransientOptions,
}

/// Everything a finished run produced.
pub struct RunOutcome {
    /// Summary.
    pub summary: Summary,
    /// Output directory.
    pub dir: PathBuf,
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned())
}

/// Load, check, schedule the cycle, compile the scene for it: everything that can fail with
/// exit 1.
pub fn prepare(args: &RunArgs) -> Result<Prepared, Failure> {
    let gb = args.set.load(&args.model)?;
    let method = Method::parse(&args.solver).ok_or_else(|| {
        invalid(format!(
            "--solver {}: unknown; allowed: {}",
            args.solver,
            Method::ALL.map(|m| m.name()).join(", ")
        ))
    })?;
    check_range("--rtol", args.rtol, 1e-14, 1e-1, "")?;
    check_range("--atol", args.atol, 1e-14, 1.0, " K")?;
    for (flag, v) in [
        ("--initial-temp-c", args.initial_temp_c),
        ("--ambient-c", args.ambient_c),
        ("--frozen-viscosity-c", args.frozen_viscosity_c),
    ] {
        if let Some(v) = v {
            check_range(flag, v, -60.0, 250.0, " °C")?;
        }
    }
    let cycle = DriveCycle::resolve(&args.cycle).map_err(super::cycle_failure)?;
    let (sched, segs) =
        segments(&gb, &cycle).map_err(|e| invalid(format!("{}: {e}", args.model.display())))?;
    // Scene pruning: only the gear states this cycle visits, only the outputs asked for.
    let needs = Needs {
        states: Some(segs.iter().map(|s| s.inputs.state).collect()),
        evaluate_all: args.evaluate_all,
        energy_per_source_only: args.summary_only,
    };
    let mut scene =
        Scene::compile_for(&gb, &needs).map_err(|e| invalid(format!("{}: {e}", args.model.display())))?;
    if let Some(a) = args.ambient_c {
        let idx = scene.thermal.ambient.ok_or_else(|| {
            invalid(format!(
                "--ambient-c: {} has no ambient boundary (name one `ambient` or set ambient = true)",
                args.model.display()
            ))
        })?;
        scene.thermal.set_boundary_fixed(idx, a + KELVIN_OFFSET);
    }
    scene.frozen_oil_temp = args.frozen_viscosity_c.map(|c| c + KELVIN_OFFSET);
    let opts = TransientOptions {
        method,
        rtol: args.rtol,
        atol: args.atol,
        restart: Restart::AtJumps,
        max_steps: args.max_steps,
        initial_temp: args.initial_temp_c.map(|c| c + KELVIN_OFFSET),
        record_losses: !args.summary_only,
        ..TransientOptions::default()
    };
    check_stored_values(&scene, &segs, &opts)
        .map_err(|e| invalid(format!("{}: {e}", args.model.display())))?;
    Ok(Prepared {
        gb,
        scene,
        cycle,
        sched,
        segs,
        opts,
    })
}

/// The whole command.
pub fn run(args: &RunArgs) -> Result<RunOutcome, Failure> {
    let Prepared {
        gb,
        scene,
        cycle,
        sched,
        segs,
        opts,
    } = prepare(args)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{}_{}", stem(&args.model), cycle.name)));
    // The output directory is locked (a second writer is refused now, not after the run) and
    // written as one transaction: the previous result stays whole until the commit.
    let out = OutputDir::begin(&dir)?;

    let bar = (!args.quiet && std::io::stderr().is_terminal()).then(|| {
        let b = indicatif::ProgressBar::new(segs.len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{spinner} {msg} [{bar:40}] {pos}/{len} s of cycle ({eta})",
        ) {
            b.set_style(style.progress_chars("=> "));
        }
        b.set_message(format!("{} on {}", gb.name, cycle.name));
        b
    });
    let mut progress = |k: usize, _n: usize| {
        if let Some(b) = &bar {
            if k % 20 == 0 {
                b.set_position(k as u64);
            }
        }
    };
    let result = integrate(&scene, &segs, &opts, &mut progress);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let traj: Trajectory = result.map_err(|e| Failure {
        code: EXIT_NUMERICAL,
        message: format!("{}: {e}", args.model.display()),
    })?;
    let rows = row_inputs(&gb, &sched, &traj);
    let sum = summary(
        &scene,
        &traj,
        &rows,
        &gb.name,
        &cycle.name,
        opts.method.name(),
        opts.rtol,
        opts.atol,
    );
    let work = std::cell::RefCell::new(scene.thermal.work());
    let bt = |t: f64| {
        let mut w = work.borrow_mut();
        scene.thermal.boundary_temperatures(t, &mut w);
        w.boundary_t.clone()
    };
    let numerical = |what: String| Failure {
        code: EXIT_NUMERICAL,
        message: format!("{}: {what}", args.model.display()),
    };
    check_finite(&scene, &traj, &rows, &sum).map_err(numerical)?;
    if sum.energy_balance_relative > MAX_ENERGY_RESIDUAL {
        return Err(numerical(format!(
            "energy balance residual {:.2e} exceeds {MAX_ENERGY_RESIDUAL:e}: the integration is not trustworthy \
             (tighten --rtol or check the cycle's time steps)",
            sum.energy_balance_relative
        )));
    }
    let csv = (!args.summary_only).then(|| timeseries_csv(&scene, &traj, &rows, &bt));
    let json = serde_json::to_string_pretty(&sum).map_err(|e| Failure {
        code: EXIT_IO,
        message: format!("cannot serialise the summary: {e}"),
    })?;
    if let Some(csv) = &csv {
        out.write("timeseries.csv", csv.as_bytes())?;
    }
    out.write("summary.json", json.as_bytes())?;
    if args.report {
        geartherm::report::plots::render_run(out.path()).map_err(|e| Failure {
            code: EXIT_IO,
            message: format!("report: {e}"),
        })?;
    }
    let dir = out.commit()?;
    Ok(RunOutcome { summary: sum, dir })
}

/// Human-readable summary for stdout.
pub fn to_text(o: &RunOutcome) -> String {
    let s = &o.summary;
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
    t.push_str(&format!("outputs in {}\n", o.dir.display()));
    t
}
