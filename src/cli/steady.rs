//! `geartherm steady` (one equilibrium) and `geartherm map` (equilibria over a speed × torque
//! grid, in parallel with warm starts).

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::PathBuf;

use geartherm::model::Gearbox;
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::report::sources::SourceValues;
use geartherm::scene::{Inputs, Needs, Scene};
use geartherm::solve::equilibrium::equilibrium;
use geartherm::solve::steady::SteadyOptions;
use geartherm::solve::sweep;

use super::{check_range, invalid, print_json, state_index, Failure, EXIT_IO, EXIT_NUMERICAL};

/// Operating-point arguments shared by `steady` and `map`.
#[derive(clap::Args, Debug)]
pub struct PointArgs {
    /// Model file (TOML).
    pub model: PathBuf,
    #[command(flatten)]
    pub set: super::SetArgs,
    /// Gear state name.
    #[arg(long)]
    pub gear: String,
    /// Ambient temperature, °C (default: the model's ambient boundary).
    #[arg(long, allow_negative_numbers = true)]
    pub ambient_c: Option<f64>,
    /// Vehicle speed for h(v) links, km/h.
    #[arg(long, default_value_t = 0.0)]
    pub vehicle_speed_kmh: f64,
}

/// Arguments of `steady`.
#[derive(clap::Args, Debug)]
pub struct SteadyArgs {
    #[command(flatten)]
    pub point: PointArgs,
    /// Input speed, rpm.
    #[arg(long)]
    pub speed_rpm: f64,
    /// Input torque, N·m.
    #[arg(long, allow_negative_numbers = true)]
    pub torque_nm: f64,
    /// One JSON document on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `map`.
#[derive(clap::Args, Debug)]
pub struct MapArgs {
    #[command(flatten)]
    pub point: PointArgs,
    /// Speeds A:B:N (rpm, N points from A to B).
    #[arg(long)]
    pub speed_rpm: String,
    /// Torques A:B:N (N·m).
    #[arg(long)]
    pub torque_nm: String,
    /// Output directory (default: maps/<model>_gear<G>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Skip the PNG heat maps.
    #[arg(long)]
    pub no_plots: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

fn prepare(p: &PointArgs) -> Result<(Gearbox, Scene, usize), Failure> {
    let gb = p.set.load(&p.model)?;
    let state = state_index(&gb, &p.gear)?;
    check_range("--vehicle-speed-kmh", p.vehicle_speed_kmh, 0.0, 400.0, " km/h")?;
    // Scene pruning: only this gear state's active items are compiled.
    let needs = Needs {
        states: Some(vec![state]),
        ..Needs::default()
    };
    let mut scene =
        Scene::compile_for(&gb, &needs).map_err(|e| invalid(format!("{}: {e}", p.model.display())))?;
    if let Some(a) = p.ambient_c {
        check_range("--ambient-c", a, -60.0, 80.0, " °C")?;
        let idx = scene.thermal.ambient.ok_or_else(|| {
            invalid(format!(
                "--ambient-c: {} has no ambient boundary",
                p.model.display()
            ))
        })?;
        scene.thermal.set_boundary_fixed(idx, a + KELVIN_OFFSET);
    }
    Ok((gb, scene, state))
}

fn inputs(p: &PointArgs, state: usize, speed_rpm: f64, torque: f64) -> Inputs {
    Inputs {
        state,
        input_speed: speed_rpm * std::f64::consts::PI / 30.0,
        input_torque: torque,
        vehicle_speed: p.vehicle_speed_kmh / 3.6,
    }
}

/// `steady` report.
#[derive(serde::Serialize)]
struct SteadyReport {
    model: String,
    gear: String,
    speed_rpm: f64,
    torque_nm: f64,
    temperatures_c: BTreeMap<String, f64>,
    losses_w: BTreeMap<String, f64>,
    by_source_w: SourceValues,
    total_loss_w: f64,
    efficiency: Option<f64>,
    iterations: usize,
    ptc_iterations: usize,
    method: &'static str,
    residual_w: f64,
    warnings: Vec<geartherm::scene::RangeWarning>,
}

/// Run `steady`.
pub fn steady(a: &SteadyArgs) -> Result<(), Failure> {
    let (gb, scene, state) = prepare(&a.point)?;
    check_range("--speed-rpm", a.speed_rpm, 0.0, 50_000.0, " rpm")?;
    check_range("--torque-nm", a.torque_nm, -1e6, 1e6, " N m")?;
    let eq = equilibrium(
        &scene,
        inputs(&a.point, state, a.speed_rpm, a.torque_nm),
        None,
        &SteadyOptions::default(),
    )
    .map_err(|e| Failure {
        code: EXIT_NUMERICAL,
        message: format!(
            "{}: no equilibrium in gear {} at --speed-rpm {} --torque-nm {}{}: {}",
            a.point.model.display(),
            a.point.gear,
            a.speed_rpm,
            a.torque_nm,
            a.point
                .ambient_c
                .map_or(String::new(), |c| format!(" --ambient-c {c}")),
            describe(&scene, &e)
        ),
    })?;
    let numerical = |what: String| Failure {
        code: EXIT_NUMERICAL,
        message: format!(
            "{}: gear {} at {} rpm, {} N m: {what}",
            a.point.model.display(),
            a.point.gear,
            a.speed_rpm,
            a.torque_nm
        ),
    };
    check_equilibrium(&scene, &eq).map_err(numerical)?;
    let mut temps = BTreeMap::new();
    for (n, t) in scene.thermal.names.iter().zip(&eq.solution.temperatures) {
        temps.insert(n.clone(), t - KELVIN_OFFSET);
    }
    let mut losses = BTreeMap::new();
    for (it, q) in scene.losses.items.iter().zip(&eq.losses) {
        losses.insert(format!("{}:{}", it.source.as_str(), it.name), *q);
    }
    let total: f64 = eq.by_source.iter().sum();
    let r = SteadyReport {
        model: gb.name.clone(),
        gear: a.point.gear.clone(),
        speed_rpm: a.speed_rpm,
        torque_nm: a.torque_nm,
        temperatures_c: temps,
        losses_w: losses,
        by_source_w: SourceValues::new(eq.by_source, "", false),
        total_loss_w: total,
        efficiency: eq.efficiency,
        iterations: eq.solution.iterations,
        ptc_iterations: eq.solution.ptc_iterations,
        method: eq.solution.method,
        residual_w: eq.solution.residual_w,
        warnings: {
            let mut log = geartherm::scene::RangeLog::new(&scene.losses);
            let t_oil = eq.solution.temperatures[scene.thermal.oil];
            log.check(
                &scene.losses,
                &geartherm::scene::OperatingPoint {
                    state,
                    input_speed: a.speed_rpm * std::f64::consts::PI / 30.0,
                    input_torque: a.torque_nm,
                    oil: scene.thermal.oil_properties(t_oil),
                },
            );
            log.warnings(&scene.losses)
        },
    };
    super::print_warnings(&r.warnings);
    if a.json {
        return print_json(&r);
    }
    println!(
        "{} gear {} at {} rpm, {} N·m: equilibrium after {} Newton + {} PTC iterations ({}), residual {:.1e} W",
        r.model, r.gear, r.speed_rpm, r.torque_nm, r.iterations, r.ptc_iterations, r.method, r.residual_w
    );
    println!("temperatures, °C");
    for (n, t) in &r.temperatures_c {
        println!("  {n:<20} {t:>9.3}");
    }
    println!("losses, W");
    for (n, q) in &r.losses_w {
        println!("  {n:<44} {q:>10.3}");
    }
    println!(
        "  {}, total {:.2} W; efficiency {}",
        r.by_source_w.text(1.0, "W", 2),
        total,
        r.efficiency.map_or("n/a".into(), |e| format!("{e:.5}"))
    );
    Ok(())
}

/// Largest residual of an equilibrium relative to its total loss (the solver converges to about
/// 1e-12; a larger residual is not an equilibrium, whatever the step criterion said).
const MAX_RELATIVE_RESIDUAL: f64 = 1e-6;

/// Every number of an equilibrium finite and its residual small, else the first failure named.
fn check_equilibrium(scene: &Scene, eq: &geartherm::solve::equilibrium::Equilibrium) -> Result<(), String> {
    for (n, t) in scene.thermal.names.iter().zip(&eq.solution.temperatures) {
        if !t.is_finite() {
            return Err(format!("temperature of node {n} is not finite"));
        }
    }
    for (it, q) in scene.losses.items.iter().zip(&eq.losses) {
        if !q.is_finite() {
            return Err(format!(
                "loss item {}:{} is not finite",
                it.source.as_str(),
                it.name
            ));
        }
    }
    let total: f64 = eq.by_source.iter().sum();
    let r = eq.solution.residual_w;
    if !r.is_finite() || r > MAX_RELATIVE_RESIDUAL * total.abs().max(1.0) {
        return Err(format!(
            "no equilibrium: residual {r:.3e} W exceeds {MAX_RELATIVE_RESIDUAL:e} of the total loss {total:.3e} W"
        ));
    }
    Ok(())
}

fn describe(scene: &Scene, e: &geartherm::solve::steady::SteadyError) -> String {
    use geartherm::solve::steady::SteadyError as E;
    let name = |i: usize| scene.thermal.names.get(i).cloned().unwrap_or_default();
    match e {
        E::NoEquilibriumInRange {
            node,
            temperature_k,
            bound_k,
            which,
        } => format!(
            "node {} is driven past its {which} limit {:.1} °C (toward {:.1} °C): the losses grow faster with \
             temperature than the cooling removes heat",
            name(*node),
            bound_k - KELVIN_OFFSET,
            temperature_k - KELVIN_OFFSET
        ),
        E::Singular { nodes } => format!(
            "node(s) {} have no thermal path to a boundary",
            nodes.iter().map(|&i| name(i)).collect::<Vec<_>>().join(", ")
        ),
        other => other.to_string(),
    }
}

/// Most points per map axis.
pub const MAX_AXIS_POINTS: usize = 2000;
/// Most points of a map (N_speed × N_torque): each equilibrium keeps its losses and solver
/// state (about 5 kB), and a 2-core machine solves about 1000 points per second; beyond this a
/// map is a study (`geartherm study`), not a map.
pub const MAX_MAP_POINTS: usize = 40_000;

fn range(flag: &str, s: &str) -> Result<Vec<f64>, Failure> {
    let parts: Vec<&str> = s.split(':').collect();
    let bad = || {
        invalid(format!(
            "{flag} {s}: expected A:B:N (from A to B in N points, A ≤ B finite, 1 ≤ N ≤ {MAX_AXIS_POINTS})"
        ))
    };
    if parts.len() != 3 {
        return Err(bad());
    }
    let a: f64 = parts[0].trim().parse().map_err(|_| bad())?;
    let b: f64 = parts[1].trim().parse().map_err(|_| bad())?;
    let n: usize = parts[2].trim().parse().map_err(|_| bad())?;
    if n == 0 || n > MAX_AXIS_POINTS || !a.is_finite() || !b.is_finite() || (n > 1 && b < a) {
        return Err(bad());
    }
    Ok((0..n)
        .map(|k| {
            if n == 1 {
                a
            } else {
                a + (b - a) * k as f64 / (n - 1) as f64
            }
        })
        .collect())
}

/// Run `map`.
pub fn map(a: &MapArgs) -> Result<(), Failure> {
    let (gb, scene, state) = prepare(&a.point)?;
    let speeds = range("--speed-rpm", &a.speed_rpm)?;
    let torques = range("--torque-nm", &a.torque_nm)?;
    let n = speeds.len() * torques.len();
    if n > MAX_MAP_POINTS {
        return Err(invalid(format!(
            "--speed-rpm {} --torque-nm {}: {} × {} = {n} points; a map may have at most {MAX_MAP_POINTS} points",
            a.speed_rpm,
            a.torque_nm,
            speeds.len(),
            torques.len()
        )));
    }
    for &s in &speeds {
        check_range("--speed-rpm", s, 0.0, 50_000.0, " rpm")?;
    }
    for &t in &torques {
        check_range("--torque-nm", t, -1e6, 1e6, " N m")?;
    }
    let dir = a.out.clone().unwrap_or_else(|| {
        PathBuf::from("maps").join(format!(
            "{}_gear{}",
            a.point
                .model
                .file_stem()
                .map_or("model".into(), |s| s.to_string_lossy()),
            a.point.gear
        ))
    });
    // Lock the output directory now: a second writer is refused before the work, not after.
    let out = geartherm::report::files::OutputDir::begin(&dir)?;
    let bar = (!a.quiet && std::io::stderr().is_terminal()).then(|| {
        let b = indicatif::ProgressBar::new((speeds.len() * torques.len()) as u64);
        if let Ok(st) = indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} points ({eta})")
        {
            b.set_style(st.progress_chars("=> "));
        }
        b.set_message("equilibria");
        b
    });
    let start = std::time::Instant::now();
    let tick = || {
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    let points = sweep::map(
        &scene,
        state,
        &speeds,
        &torques,
        a.point.vehicle_speed_kmh / 3.6,
        &SteadyOptions::default(),
        &tick,
    );
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let wall = start.elapsed().as_secs_f64();
    let csv = geartherm::report::map::map_csv(&points, scene.thermal.oil);
    let converged = points.iter().filter_map(|p| p.equilibrium.as_ref());
    let (ok, iters) = converged.fold((0usize, 0usize), |(k, i), e| {
        (k + 1, i + e.solution.iterations + e.solution.ptc_iterations)
    });
    // A map is written whole or not at all: points without an equilibrium are a failure
    // (exit 2, nothing written) that names them, not a map with holes.
    let failed: Vec<String> = points
        .iter()
        .filter_map(|p| {
            let why = match &p.equilibrium {
                None => "no equilibrium".to_string(),
                Some(e) => check_equilibrium(&scene, e).err()?,
            };
            Some(format!("{} rpm, {} N m: {why}", p.speed_rpm, p.torque_nm))
        })
        .collect();
    if !failed.is_empty() {
        return Err(Failure {
            code: EXIT_NUMERICAL,
            message: format!(
                "{}: {} of {n} points failed, nothing written (narrow the grid); first: {}",
                a.point.model.display(),
                failed.len(),
                failed.iter().take(5).cloned().collect::<Vec<_>>().join("; ")
            ),
        });
    }
    let json = serde_json::json!({
        "model": gb.name,
        "gear": a.point.gear,
        "points": n,
        "converged": ok,
        "mean_iterations": iters as f64 / ok.max(1) as f64,
        "wall_time_s": wall,
        "threads": rayon::current_num_threads(),
    });
    let text = serde_json::to_string_pretty(&json).map_err(|e| Failure {
        code: EXIT_IO,
        message: e.to_string(),
    })?;
    out.write("map.csv", csv.as_bytes())?;
    out.write("map.json", text.as_bytes())?;
    if !a.no_plots {
        geartherm::report::plots::render_map(out.path()).map_err(|e| Failure {
            code: EXIT_IO,
            message: format!("plot: {e}"),
        })?;
    }
    let dir = out.commit()?;
    println!(
        "{n} points ({ok} converged, {:.1} iterations on average) in {wall:.3} s on {} threads; outputs in {}",
        iters as f64 / ok.max(1) as f64,
        rayon::current_num_threads(),
        dir.display()
    );
    Ok(())
}
