//! Criterion benches of the solvers: one right-hand-side evaluation (with the per-sample loss
//! cache, and with every loss evaluated in full), one equilibrium, and a full WLTC transient per
//! example model (default solver and tolerance; for the AT6 also with everything evaluated).

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};

use geartherm::cycle::DriveCycle;
use geartherm::model;
use geartherm::scene::{Inputs, Needs, Scene};
use geartherm::solve::drive::segments;
use geartherm::solve::equilibrium::equilibrium;
use geartherm::solve::steady::SteadyOptions;
use geartherm::solve::transient::{integrate, LinearAlgebra, Method, TransientOptions};

#[path = "../tests/common/wall.rs"]
mod wall;

#[path = "../tests/common/mod.rs"]
mod common;

const MODELS: [&str; 4] = [
    "models/at6_lepelletier.toml",
    "models/fzg_c.toml",
    "models/helical_stage.toml",
    "models/pt6_spur_pair.toml",
];

fn point(gb: &model::Gearbox) -> Inputs {
    let state = gb.state_index("3").or_else(|| gb.state_index("1")).unwrap_or(0);
    Inputs {
        state,
        input_speed: 2000.0 * std::f64::consts::PI / 30.0,
        input_torque: 150.0,
        vehicle_speed: 15.0,
    }
}

fn benches(c: &mut Criterion) {
    // The floor's linear-algebra part: one dense LU of the AT6 iteration matrix size (5 nodes +
    // 15 items + 1 = 21 states), nalgebra as diffsol's NalgebraLU uses it.
    let n = 21;
    let a = nalgebra::DMatrix::<f64>::from_fn(n, n, |i, j| {
        if i == j {
            4.0 + i as f64
        } else {
            1.0 / (1.0 + (i + 2 * j) as f64)
        }
    });
    c.bench_function("lu/21x21", |b| b.iter(|| black_box(a.clone()).lu()));
    for m in MODELS {
        let gb = model::load(Path::new(m)).unwrap();
        let name = Path::new(m).file_stem().unwrap().to_string_lossy().into_owned();
        let cycle = DriveCycle::resolve("wltc").unwrap();
        let (_, segs) = segments(&gb, &cycle).unwrap();
        // As `geartherm run` compiles it: pruned to the cycle's gear states.
        let needs = Needs {
            states: Some(segs.iter().map(|s| s.inputs.state).collect()),
            ..Needs::default()
        };
        let scene = Scene::compile_for(&gb, &needs).unwrap();
        let everything = Scene::compile_for(
            &gb,
            &Needs {
                evaluate_all: true,
                ..Needs::default()
            },
        )
        .unwrap();
        let inp = point(&gb);
        for (label, sc) in [("rhs", &scene), ("rhs_full", &everything)] {
            let mut work = sc.work(inp);
            let y = sc.initial_state(None);
            let mut dy = vec![0.0; y.len()];
            c.bench_function(&format!("{label}/{name}"), |b| {
                b.iter(|| sc.rhs(black_box(0.0), black_box(&y), &mut work, &mut dy))
            });
        }
        c.bench_function(&format!("equilibrium/{name}"), |b| {
            b.iter(|| equilibrium(&scene, black_box(inp), None, &SteadyOptions::default()).unwrap())
        });
        let mut g = c.benchmark_group("wltc");
        g.sample_size(10);
        g.bench_function(&name, |b| {
            b.iter(|| integrate(&scene, &segs, &TransientOptions::default(), &mut |_, _| {}).unwrap())
        });
        if name.starts_with("at6") {
            g.bench_function(format!("{name}_evaluate_all"), |b| {
                b.iter(|| {
                    integrate(&everything, &segs, &TransientOptions::default(), &mut |_, _| {}).unwrap()
                })
            });
        }
        g.finish();
    }
}

/// The WLTC on the AT6 with its housing meshed into N patches (`[thermal.wall_mesh]`), sparse
/// and dense LU: the cost per step against N (`examples/cost_per_step.rs` divides by the steps
/// and plots it). Run alone with `cargo bench --bench solve -- wltc_network`.
fn networks(c: &mut Criterion) {
    let mut g = c.benchmark_group("wltc_network");
    g.sample_size(10);
    // Small sizes first: where the sparse LU starts to win.
    for n in wall::STUDY_SIZES {
        let (scene, segs) = wall::meshed_at6_wltc(n);
        for (label, la) in [("sparse", LinearAlgebra::Sparse), ("dense", LinearAlgebra::Dense)] {
            if la == LinearAlgebra::Dense && n > 200 {
                continue; // 1.5 s and more per run
            }
            // TR-BDF2 at every size (what `auto` uses above 24 nodes), so that the curve shows
            // how the linear algebra scales.
            let o = wall::study_options(Method::TrBdf2, la);
            g.bench_function(format!("{label}/{n}"), |b| {
                b.iter(|| integrate(&scene, &segs, &o, &mut |_, _| {}).unwrap())
            });
        }
    }
    g.finish();
}

/// An hour of a thermostatic heater on a 50 J/K oil node with a 0.5 K band (the stress run of
/// `tests/controls.rs`, about 36 000 switches), ROS3 and BDF: the run's time over its switches is
/// the cost per event (docs/performance.md, "Controllers that switch"). Run alone with
/// `cargo bench --bench solve -- switching`.
fn switching(c: &mut Criterion) {
    let net = r#"
[thermal]
oil_node = "oil"
initial_temp_c = 30.0
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = 50.0
[[thermal.nodes]]
name = "casing"
capacity_j_per_k = 5000.0
[[thermal.boundaries]]
name = "ambient"
temp_c = 20.0
[[thermal.links]]
between = ["oil", "casing"]
conductance_w_per_k = 20.0
[[thermal.links]]
between = ["casing", "ambient"]
conductance_w_per_k = 10.0
[[thermal.controls]]
name = "heater"
kind = "two_point"
sensor = "oil"
on_c = 40.0
off_c = 40.5
heater_w = 1500.0
"#;
    let scene = common::fzg_frozen(net, 40.0);
    let inputs = common::steady_inputs(0.0, 0.0);
    let segs: Vec<_> = (0..60)
        .map(|k| geartherm::solve::transient::Segment {
            t0: 60.0 * k as f64,
            t1: 60.0 * (k + 1) as f64,
            inputs,
        })
        .collect();
    let mut g = c.benchmark_group("switching");
    g.sample_size(10);
    for m in [Method::Ros3, Method::Bdf] {
        let o = TransientOptions {
            method: m,
            rtol: 1e-6,
            atol: 1e-6,
            ..TransientOptions::default()
        };
        let t = integrate(&scene, &segs, &o, &mut |_, _| {}).unwrap();
        println!(
            "switching/{}: {} switches, {} steps, {} rejected",
            m.name(),
            t.events.len(),
            t.stats.steps,
            t.stats.rejected
        );
        g.bench_function(m.name(), |b| {
            b.iter(|| integrate(&scene, &segs, &o, &mut |_, _| {}).unwrap())
        });
    }
    g.finish();
}

criterion_group!(solve, benches, networks, switching);
criterion_main!(solve);
