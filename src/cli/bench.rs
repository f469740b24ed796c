//! `geartherm bench`: the work-precision study of one model over one cycle.

use std::path::PathBuf;

use geartherm::solve::transient::{Method, DEFAULT_ATOL, DEFAULT_METHOD, DEFAULT_RTOL};
use geartherm::solve::work_precision::{pareto, reference, sweep, to_csv};

use super::run::{prepare, RunArgs};
use super::{invalid, Failure, EXIT_IO, EXIT_NUMERICAL};

/// Arguments of `bench`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Model file (TOML).
    pub model: PathBuf,
    /// Cycle (bundled name or CSV).
    #[arg(long, default_value = "wltc")]
    pub cycle: String,
    /// Output directory (default: bench/<model>_<cycle>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Repeats per point (median wall time).
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
    /// Tightest tolerance of the sweep (the sweep goes 1e-3 … this, one per decade).
    #[arg(long, default_value_t = 1e-10)]
    pub min_rtol: f64,
    /// Solvers (comma-separated).
    #[arg(long, default_value = "bdf,esdirk34,tr-bdf2,ros3,tsit45")]
    pub solvers: String,
    /// Step budget per run (an explicit solver on a stiff network stops there and is reported).
    #[arg(long, default_value_t = 2_000_000)]
    pub max_steps: usize,
}

/// Run the study, write bench.csv, bench.json and work_precision.png; print the table.
pub fn bench(args: &BenchArgs) -> Result<(), Failure> {
    let run_args = RunArgs {
        model: args.model.clone(),
        set: Default::default(),
        cycle: args.cycle.clone(),
        out: None,
        solver: DEFAULT_METHOD.name().into(),
        rtol: DEFAULT_RTOL,
        atol: DEFAULT_ATOL,
        initial_temp_c: None,
        ambient_c: None,
        frozen_viscosity_c: None,
        report: false,
        quiet: true,
        max_steps: args.max_steps,
        json: false,
        summary_only: false,
        evaluate_all: false,
    };
    // The study measures the problem `run` solves by default (same scene pruning and outputs).
    let super::run::Prepared {
        gb,
        scene,
        cycle,
        segs,
        ..
    } = prepare(&run_args)?;
    let methods: Vec<Method> = args
        .solvers
        .split(',')
        .map(|s| Method::parse(s.trim()).ok_or_else(|| invalid(format!("--solvers: unknown solver {s}"))))
        .collect::<Result<_, _>>()?;
    if !(1e-13..=1e-3).contains(&args.min_rtol) {
        return Err(invalid(format!(
            "--min-rtol {}: must lie in [1e-13, 1e-3]",
            args.min_rtol
        )));
    }
    let (refr, info) = reference(&scene, &segs, 1e-12).map_err(|e| Failure {
        code: EXIT_NUMERICAL,
        message: format!("reference solution failed: {e}"),
    })?;
    eprintln!(
        "reference: {} and {} at rtol = atol = 1e-12 agree to {:.2e} K (max over nodes and the 1 Hz grid)",
        info.methods[0], info.methods[1], info.agreement_k
    );
    let mut rtols = Vec::new();
    let mut r = 1e-3;
    while r >= args.min_rtol * 0.999 {
        rtols.push(r);
        r /= 10.0;
    }
    let rows = sweep(
        &scene,
        &segs,
        &refr,
        &methods,
        &rtols,
        args.repeats,
        args.max_steps,
        &mut |row| {
            eprintln!(
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
        },
    );
    let front = pareto(&rows);
    let default_on_front = rows.iter().zip(&front).any(|(r, f)| r.default && *f);
    // The default must also handle stiff networks (an explicit method cannot: tests/stress.rs),
    // so its front among the implicit solvers is reported too.
    let implicit: Vec<bool> = rows
        .iter()
        .map(|r| Method::parse(&r.solver).is_some_and(|m| m.is_implicit()))
        .collect();
    let implicit_rows: Vec<_> = rows
        .iter()
        .zip(&implicit)
        .filter(|(_, i)| **i)
        .map(|(r, _)| r.clone())
        .collect();
    let default_on_implicit_front = implicit_rows
        .iter()
        .zip(pareto(&implicit_rows))
        .any(|(r, f)| r.default && f);
    eprintln!(
        "default ({} rtol {:.0e}) on the Pareto front of (wall time, max error): {} among all solvers, {} among the implicit solvers",
        DEFAULT_METHOD.name(),
        DEFAULT_RTOL,
        default_on_front,
        default_on_implicit_front
    );
    let dir = args.out.clone().unwrap_or_else(|| {
        PathBuf::from("bench").join(format!(
            "{}_{}",
            args.model
                .file_stem()
                .map_or("model".into(), |s| s.to_string_lossy()),
            cycle.name
        ))
    });
    let json = serde_json::json!({
        "model": gb.name,
        "cycle": cycle.name,
        "reference": info,
        "default": { "solver": DEFAULT_METHOD.name(), "rtol": DEFAULT_RTOL, "atol": DEFAULT_ATOL, "on_pareto_front": default_on_front, "on_implicit_pareto_front": default_on_implicit_front },
        "rows": rows,
        "pareto": front,
        "nodes": scene.nodes(),
        "items": scene.items(),
        "samples": segs.len(),
    });
    let text = serde_json::to_string_pretty(&json).map_err(|e| Failure {
        code: EXIT_IO,
        message: e.to_string(),
    })?;
    let out = geartherm::report::files::OutputDir::begin(&dir)?;
    out.write("bench.csv", to_csv(&rows).as_bytes())?;
    out.write("bench.json", text.as_bytes())?;
    geartherm::report::plots::render_bench(out.path()).map_err(|e| Failure {
        code: EXIT_IO,
        message: format!("plot: {e}"),
    })?;
    let dir = out.commit()?;
    println!("{}", dir.join("bench.csv").display());
    println!("{}", dir.join("work_precision.png").display());
    Ok(())
}
