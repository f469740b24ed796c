//! The integration floor per example model: samples × (one cached RHS + one LU of
//! the iteration matrix's size), against the WLTC integration as `geartherm run` does it
//! (per-item energies, losses recorded per row) and as `run --summary-only` does it.
//!
//! `ratio_node_lu`: the same against a stricter floor whose LU is that of the node block only
//! (what the solvers factorise: the loss- and boundary-energy quadratures are eliminated), which
//! matters where per-item energies make the state large (the AT6 `run`: 37 states, 5 nodes).
//!
//! Also the per-sample preparation (`prepare_us`) and `two_rhs_bound` = (2 RHS + preparation) /
//! (RHS + LU): the ratio a method with two RHS calls per step, one step per sample and no other
//! cost would reach (ROS3, the default on these examples, makes two RHS calls per step).
//!
//! `ratio_prep_in_floor`: the same against a floor whose RHS includes building its per-sample
//! cache (speed- and load-dependent loss terms) once per sample whose inputs change, which any
//! integrator, a one-RHS-per-sample one included, has to pay. Shown beside `ratio`,
//! not instead of it. It uses `prepare_cycle_us`: the preparation per prepared sample measured
//! over the cycle's samples in order (`prepare_us` alternates between two mid-cycle samples and
//! misses e.g. the converter's open-state solve at launches).
//!
//! `cargo run --release --example floor` — CPU time of this thread (the 2-core machine is shared:
//! wall time includes waiting for a core), medians of repeats. `FLOOR_REPEATS` (default 7) and
//! `FLOOR_PROFILE=model.toml` (integrate that model 200 times, for `perf record`).

#[path = "common/cpu.rs"]
mod cpu;
use cpu::cpu_time;

use std::hint::black_box;
use std::path::Path;

use geartherm::cycle::DriveCycle;
use geartherm::model;
use geartherm::scene::{Inputs, Needs, Scene};
use geartherm::solve::drive::segments;
use geartherm::solve::transient::{integrate, Method, Segment, TransientOptions};

const MODELS: [&str; 4] = [
    "models/at6_lepelletier.toml",
    "models/fzg_c.toml",
    "models/helical_stage.toml",
    "models/pt6_spur_pair.toml",
];

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median CPU seconds per call of `f` (batches of `n` calls).
fn per_call(n: usize, repeats: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..repeats)
            .map(|_| {
                let c0 = cpu_time();
                for _ in 0..n {
                    f();
                }
                (cpu_time() - c0) / n as f64
            })
            .collect(),
    )
}

fn scene_for(gb: &model::Gearbox, segs: &[Segment], summary_only: bool) -> Scene {
    let needs = Needs {
        states: Some(segs.iter().map(|s| s.inputs.state).collect()),
        energy_per_source_only: summary_only,
        ..Needs::default()
    };
    Scene::compile_for(gb, &needs).unwrap()
}

fn main() {
    let repeats: usize = std::env::var("FLOOR_REPEATS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(7);
    let cycle = DriveCycle::resolve("wltc").unwrap();
    if let Ok(m) = std::env::var("FLOOR_PROFILE") {
        let gb = model::load(Path::new(&m)).unwrap();
        let (_, segs) = segments(&gb, &cycle).unwrap();
        let scene = scene_for(&gb, &segs, true);
        let mut o = TransientOptions {
            record_losses: false,
            ..TransientOptions::default()
        };
        if let Some(m) = std::env::var("FLOOR_METHOD").ok().and_then(|m| Method::parse(&m)) {
            o.method = m;
        }
        for _ in 0..200 {
            black_box(integrate(&scene, &segs, &o, &mut |_, _| {}).unwrap());
        }
        return;
    }
    println!(
        "model,mode,states,samples,steps,rhs_evals,lu,rhs_us,lu_us,prepare_us,floor_ms,wltc_ms,ratio,two_rhs_bound,node_lu_us,ratio_node_lu,ratio_prep_in_floor,prepare_cycle_us"
    );
    for m in MODELS {
        let gb = model::load(Path::new(m)).unwrap();
        let name = Path::new(m).file_stem().unwrap().to_string_lossy().into_owned();
        let (_, segs) = segments(&gb, &cycle).unwrap();
        for (mode, summary, assembled) in [
            ("run", false, true),
            ("summary-only", true, true),
            ("summary-only, Jacobian from products", true, false),
        ] {
            let scene = scene_for(&gb, &segs, summary);
            let mut o = TransientOptions {
                record_losses: !summary,
                assembled_jacobian: assembled,
                ..TransientOptions::default()
            };
            if let Some(m) = std::env::var("FLOOR_METHOD").ok().and_then(|m| Method::parse(&m)) {
                o.method = m;
            }
            // One cached RHS at a mid-cycle sample (the per-sample terms prepared once).
            let mid = segs[segs.len() / 2].inputs;
            let inp = Inputs { ..mid };
            let mut work = scene.work(inp);
            let y = scene.initial_state(None);
            let mut dy = vec![0.0; y.len()];
            let n = scene.n_states();
            if std::env::var_os("FLOOR_NODES").is_some() {
                eprintln!("{name} {mode}: {} nodes, {} states", scene.nodes(), n);
            }
            let test_matrix = |n: usize| {
                nalgebra::DMatrix::<f64>::from_fn(n, n, |i, j| {
                    if i == j {
                        4.0 + i as f64
                    } else {
                        1.0 / (1.0 + (i + 2 * j) as f64)
                    }
                })
            };
            let (a, a_nodes) = (test_matrix(n), test_matrix(scene.nodes()));
            // The per-sample preparation (speed- and load-dependent loss terms, conductances),
            // alternating between two samples so that nothing is reused.
            let other = segs[segs.len() / 2 + 1].inputs;
            let mut flip = false;
            // Each repeat measures the floor's parts and the integration back to back, and the
            // ratio is taken per repeat: the shared machine's speed drifts over seconds, which
            // separately taken medians would mix into the ratio.
            let (mut rhs_v, mut lu_v, mut prep_v, mut wltc_v, mut ratio_v) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
            let (mut node_lu_v, mut node_ratio_v, mut prep_ratio_v) = (Vec::new(), Vec::new(), Vec::new());
            let mut prep_cycle_v = Vec::new();
            let mut last = None;
            for _ in 0..repeats {
                let rhs = per_call(20_000, 1, || {
                    scene.rhs(black_box(0.0), black_box(&y), &mut work, &mut dy)
                });
                let lu = per_call(2_000, 1, || {
                    black_box(black_box(a.clone()).lu());
                });
                let node_lu = per_call(2_000, 1, || {
                    black_box(black_box(a_nodes.clone()).lu());
                });
                let prepare = per_call(20_000, 1, || {
                    flip = !flip;
                    scene.set_inputs(if flip { other } else { mid }, &mut work);
                });
                // The preparation as the integration pays it: every sample of the cycle in order,
                // prepared when its inputs differ from the last one's (converter open at launches,
                // every gear, every load).
                let (mut changed, c0) = (0usize, cpu_time());
                for w in segs.windows(2) {
                    if w[1].inputs != w[0].inputs {
                        scene.set_inputs(w[1].inputs, &mut work);
                        changed += 1;
                    }
                }
                prep_cycle_v.push((cpu_time() - c0) / changed.max(1) as f64);
                scene.set_inputs(mid, &mut work);
                let c0 = cpu_time();
                let t = integrate(&scene, &segs, &o, &mut |_, _| {}).unwrap();
                let wltc = cpu_time() - c0;
                ratio_v.push(wltc / (segs.len() as f64 * (rhs + lu)));
                // The floor with its RHS's per-sample cache built once per prepared sample.
                let prepared = t.stats.samples_prepared as f64;
                let prep_cycle = *prep_cycle_v.last().unwrap_or(&prepare);
                prep_ratio_v.push(wltc / (segs.len() as f64 * (rhs + lu) + prepared * prep_cycle));
                node_ratio_v.push(wltc / (segs.len() as f64 * (rhs + node_lu)));
                node_lu_v.push(node_lu);
                rhs_v.push(rhs);
                lu_v.push(lu);
                prep_v.push(prepare);
                wltc_v.push(wltc);
                last = Some(t);
            }
            let (rhs, lu, prepare, wltc) = (median(rhs_v), median(lu_v), median(prep_v), median(wltc_v));
            let t = last.unwrap();
            let samples = segs.len();
            let floor = samples as f64 * (rhs + lu);
            // What a method with two RHS calls per step and one preparation per sample would
            // cost at one step per sample and nothing else, against the floor.
            let bound = (2.0 * rhs + prepare) / (rhs + lu);
            let ratio = median(ratio_v);
            let (node_lu, node_ratio) = (median(node_lu_v), median(node_ratio_v));
            let prep_ratio = median(prep_ratio_v);
            let prep_cycle = median(prep_cycle_v);
            println!(
                "{name},{mode},{n},{samples},{},{},{},{:.3},{:.3},{:.3},{:.3},{:.3},{:.2},{bound:.2},{:.3},{node_ratio:.2},{prep_ratio:.2},{:.3}",
                t.stats.steps,
                t.stats.rhs_evals,
                t.stats.lu_factorisations,
                rhs * 1e6,
                lu * 1e6,
                prepare * 1e6,
                floor * 1e3,
                wltc * 1e3,
                ratio,
                node_lu * 1e6,
                prep_cycle * 1e6
            );
        }
    }
}
