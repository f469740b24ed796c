//! Cost of co-simulation through an exported FMU's instance (`job::fmu::instance`, what every
//! `fmi2DoStep` calls; no importer overhead) on the AT6 over the WLTC, inputs from the run's
//! segments (held), boundaries as lines, at communication steps of 1 s and 0.01 s, against the
//! run itself (`job::run::solve`: the integration and its outputs, as `geartherm run` does it
//! after reading the model). The importer's values (inputs, boundary values and derivatives at
//! each communication point) are computed before the clock starts.
//!
//! `cargo run --release --example fmu_timing` — CPU time of this thread (the 2-core machine is
//! shared), median of `FMU_REPEATS` (default 3) repeats. Prints µs per doStep and the ratio of the
//! co-simulation to the run, without reading outputs between the steps (one read per 1 s sample)
//! and reading some at every 0.01 s communication point ([`READS`]; `FMU_READS=name,…` runs
//! only those).

#[path = "common/cpu.rs"]
mod cpu;
use cpu::cpu_time;
#[path = "common/fmu_plan.rs"]
mod fmu_plan;
use fmu_plan::plan;

use std::path::Path;
use std::sync::Arc;

use geartherm::job::fmu::instance::Instance;
use geartherm::job::fmu::{FmuModel, Payload, Role};
use geartherm::job::{run, Model, RunOptions};

const AT6: &str = "models/at6_lepelletier.toml";

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The outputs read at every communication point: none, the node temperatures and loss
/// energies (`temperatures_energies`), the node temperatures and total loss (`temperatures_loss`),
/// every output variable (`all_outputs`, what FMPy's `simulate_fmu` records).
const READS: [&str; 4] = [
    "none",
    "temperatures_energies",
    "temperatures_loss",
    "all_outputs",
];

/// The value references `read` names.
fn read_refs(fm: &FmuModel, read: &str) -> Vec<u32> {
    let wanted = |r: Role| match read {
        "temperatures_energies" => {
            matches!(r, Role::NodeTemp(_) | Role::SourceEnergy(_) | Role::TotalEnergy)
        }
        "temperatures_loss" => matches!(r, Role::NodeTemp(_) | Role::TotalLoss),
        "all_outputs" => part_of_outputs(r),
        _ => false,
    };
    fm.vars.iter().filter(|v| wanted(v.role)).map(|v| v.vr).collect()
}

fn part_of_outputs(r: Role) -> bool {
    !matches!(
        r,
        Role::InputSpeed
            | Role::InputTorque
            | Role::VehicleSpeed
            | Role::Gear
            | Role::Boundary(_)
            | Role::InitialTemp(_)
            | Role::Rtol
            | Role::Atol
            | Role::Param(_)
    )
}

/// One WLTC co-simulation at communication step `step`, the outputs `every` read after each
/// doStep: (CPU seconds, doSteps).
fn cosim(fm: &Arc<FmuModel>, p: &run::Prepared, step: f64, every: &[u32]) -> (f64, usize) {
    let vr = |role: Role| fm.vars.iter().find(|v| v.role == role).map(|v| v.vr).unwrap_or(0);
    let (speed, torque, vehicle, gear) = (
        vr(Role::InputSpeed),
        vr(Role::InputTorque),
        vr(Role::VehicleSpeed),
        vr(Role::Gear),
    );
    let boundaries: Vec<u32> = (0..p.scene.thermal().boundary_names.len())
        .map(|b| vr(Role::Boundary(b)))
        .collect();
    let plan = plan(p, step);
    let t0 = cpu_time();
    let mut inst = Instance::new(fm.clone());
    inst.enter_initialization().unwrap();
    inst.exit_initialization().unwrap();
    let mut steps = 0;
    let mut out = vec![0.0; every.len()];
    for (i, points) in &plan {
        inst.set(speed, i.input_speed).unwrap();
        inst.set(torque, i.input_torque).unwrap();
        inst.set(vehicle, i.vehicle_speed).unwrap();
        inst.set(gear, i.state as f64).unwrap();
        for (a, b, x, d) in points {
            for ((&r, &x), &d) in boundaries.iter().zip(x).zip(d) {
                inst.set(r, x).unwrap();
                inst.set_derivative(r, 1, d).unwrap();
            }
            inst.do_step(*a, b - a).unwrap();
            steps += 1;
            // As an importer reads them: one `fmi2GetReal` of every variable wanted.
            inst.get_many(every, &mut out).unwrap();
            std::hint::black_box(&out);
        }
        // An importer reads the outputs at every communication point; here once per sample.
        inst.get(vr(Role::TotalLoss)).unwrap();
    }
    (cpu_time() - t0, steps)
}

/// The loss model alone, evaluated as a loss output read at every 0.01 s point evaluates it:
/// per segment of the run its per-sample terms prepared once, then 100 evaluations at oil
/// temperatures along the segment (the run's initial state with the oil node moved from 40 to
/// 100 °C over the cycle). CPU seconds and evaluations.
fn loss_evaluations(fm: &FmuModel, p: &run::Prepared) -> (f64, usize) {
    let scene = &fm.scene;
    let oil = scene.thermal().oil;
    let mut y = scene.initial_state(None);
    let mut w = scene.work(p.segs[0].inputs);
    let n = p.segs.len() * 100;
    let mut k = 0;
    let t0 = cpu_time();
    for seg in &p.segs {
        scene.set_inputs(seg.inputs, &mut w);
        for _ in 0..100 {
            y[oil] = 313.15 + 60.0 * k as f64 / n as f64;
            scene.evaluate_losses(&y, &mut w);
            std::hint::black_box(&w.q);
            k += 1;
        }
    }
    (cpu_time() - t0, n)
}

fn main() {
    let repeats: usize = std::env::var("FMU_REPEATS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let m = Model::load(Path::new(AT6), &[]).unwrap();
    let p = run::prepare(&m, &RunOptions::default()).unwrap();
    let fm = Arc::new(
        FmuModel::build(Payload {
            file: AT6.into(),
            text: std::fs::read_to_string(AT6).unwrap(),
            overrides: vec![],
            params: vec![],
        })
        .unwrap(),
    );
    let run_s = median(
        (0..repeats)
            .map(|_| {
                let t0 = cpu_time();
                run::solve(&m, &p, &mut |_, _| {}).unwrap();
                cpu_time() - t0
            })
            .collect(),
    );
    println!(
        "AT6 WLTC, CPU time, median of {repeats}; {} nodes, {} loss items, {} states, {} outputs",
        p.scene.nodes(),
        p.scene.items(),
        fm.scene.n_states(),
        read_refs(&fm, "all_outputs").len()
    );
    println!("run (job::run::solve): {:.2} ms", run_s * 1e3);
    let (s, n) = loss_evaluations(&fm, &p);
    println!(
        "loss model alone: {n} evaluations at 0.01 s points, {:.2} ms, {:.2} us each, {:.2} x the run",
        s * 1e3,
        s * 1e6 / n as f64,
        s / run_s
    );
    println!("step_s,read_every_point,do_steps,cosim_ms,us_per_do_step,ratio_to_run");
    // `FMU_READS=a,b`: only these cases at 0.01 s (and not the 1 s one).
    let only = std::env::var("FMU_READS").ok();
    let cases = [(1.0, "none")].into_iter().chain(READS.map(|r| (0.01, r)));
    let cases = cases.filter(|(step, r)| {
        only.as_deref()
            .map_or(true, |o| *step < 1.0 && o.split(',').any(|x| x == *r))
    });
    for (step, read) in cases {
        let every = read_refs(&fm, read);
        let mut n = 0;
        let s = median(
            (0..repeats)
                .map(|_| {
                    let (s, k) = cosim(&fm, &p, step, &every);
                    n = k;
                    s
                })
                .collect(),
        );
        println!(
            "{step},{read},{n},{:.2},{:.2},{:.2}",
            s * 1e3,
            s * 1e6 / n as f64,
            s / run_s
        );
    }
}
