//! Scene pruning and the per-sample loss cache: what the compile step leaves out and
//! caches must not change any result beyond rounding.

mod common;

use std::path::Path;
use std::process::Command;

use geartherm::model;
use geartherm::scene::{LossScene, Needs, OperatingPoint, Scene};
use geartherm::solve::transient::{integrate, Segment, TransientOptions};

const MODELS: [&str; 4] = [
    "models/at6_lepelletier.toml",
    "models/fzg_c.toml",
    "models/helical_stage.toml",
    "models/pt6_spur_pair.toml",
];

/// A model file's text with a `[losses]` table appended.
fn with_losses(path: &str, losses: &str) -> model::Gearbox {
    let text = std::fs::read_to_string(path).unwrap();
    model::from_str(&format!("{text}\n[losses]\n{losses}\n"), Path::new(path)).unwrap()
}

/// Cached evaluation (per-sample terms, then one power of η per call) against the full element
/// loops, for every state of a gearbox, driving and coasting, several speeds and oil temperatures.
fn check_cache(gb: &model::Gearbox, label: &str) -> f64 {
    let scene = LossScene::compile(gb).unwrap();
    let net = Scene::compile(gb).unwrap();
    let mut terms = scene.sample_terms();
    let (mut full, mut cached) = (vec![0.0; scene.len()], vec![0.0; scene.len()]);
    let mut worst: f64 = 0.0;
    let mut compared = 0;
    for state in 0..gb.gear_states.len() {
        for (rpm, torque) in [(800.0, 35.0), (2500.0, 180.0), (4200.0, -60.0), (1500.0, 0.0)] {
            let w = rpm * std::f64::consts::PI / 30.0;
            scene.prepare(state, w, torque, &mut terms);
            for t_c in [-20.0, 40.0, 110.0] {
                let op = OperatingPoint {
                    state,
                    input_speed: w,
                    input_torque: torque,
                    oil: net.thermal().oil_properties(t_c + 273.15),
                };
                scene.evaluate(&op, &mut full);
                scene.evaluate_cached(&op, &terms, &mut cached);
                for (k, (a, b)) in full.iter().zip(&cached).enumerate() {
                    let rel = (a - b).abs() / a.abs().max(1e-300);
                    assert!(
                        rel <= 1e-12 || a == b,
                        "{label} state {state} {rpm} rpm {torque} N·m {t_c} °C item {}: {a} vs {b}",
                        scene.items[k].name
                    );
                    if *a != 0.0 {
                        worst = worst.max(rel);
                        compared += 1;
                    }
                }
            }
        }
    }
    assert!(compared > 0, "{label}: nothing compared");
    worst
}

#[test]
fn cached_losses_equal_the_full_evaluation() {
    for m in MODELS {
        let gb = model::load(Path::new(m)).unwrap();
        let worst = check_cache(&gb, m);
        println!("{m}: cached vs full, worst relative difference {worst:.1e}");
    }
    // Every friction law and loss form: the separable ones use the cache, the others fall back.
    for losses in [
        "friction = \"schlenk\"",
        "friction = \"benedict_kelley\"",
        "friction = \"constant\"\nfriction_coefficient = 0.05\nloss_form = \"moment_balance\"",
        "loss_form = \"moment_balance\"",
        "sliding = \"iso14179\"",
    ] {
        for m in [MODELS[0], MODELS[1]] {
            let worst = check_cache(&with_losses(m, losses), &format!("{m} [{losses}]"));
            println!("{m} [{losses}]: worst relative difference {worst:.1e}");
        }
    }
}

#[test]
fn cached_terms_for_another_sample_are_not_used() {
    let gb = model::load(Path::new(MODELS[0])).unwrap();
    let scene = LossScene::compile(&gb).unwrap();
    let net = Scene::compile(&gb).unwrap();
    let mut terms = scene.sample_terms();
    scene.prepare(0, 100.0, 50.0, &mut terms);
    let op = OperatingPoint {
        state: 0,
        input_speed: 200.0,
        input_torque: 120.0,
        oil: net.thermal().oil_properties(330.0),
    };
    let (mut a, mut b) = (vec![0.0; scene.len()], vec![0.0; scene.len()]);
    scene.evaluate(&op, &mut a);
    scene.evaluate_cached(&op, &terms, &mut b);
    assert_eq!(a, b);
}

/// Gear-3 rig segments of the AT6 (the Ravigneaux set turns as one block in 3rd).
fn gear3_segments(gb: &model::Gearbox) -> Vec<Segment> {
    let state = gb.state_index("3").unwrap();
    (0..600)
        .map(|k| {
            let t = k as f64;
            let mut inputs =
                common::steady_inputs(2000.0 + 800.0 * (t / 60.0).sin(), 150.0 + 60.0 * (t / 37.0).sin());
            inputs.state = state;
            Segment {
                t0: t,
                t1: t + 1.0,
                inputs,
            }
        })
        .collect()
}

#[test]
fn pruned_scene_gives_the_full_scenes_temperatures_and_energies() {
    let gb = model::load(Path::new(MODELS[0])).unwrap();
    let segs = gear3_segments(&gb);
    let pruned = Scene::compile_for(
        &gb,
        &Needs {
            states: Some(segs.iter().map(|s| s.inputs.state).collect()),
            ..Needs::default()
        },
    )
    .unwrap();
    let all = Scene::compile_for(
        &gb,
        &Needs {
            evaluate_all: true,
            ..Needs::default()
        },
    )
    .unwrap();
    // What gear 3 leaves idle: all four RAV sliding meshes, the three external RAV pockets (fed by
    // the circuit, above the ATF), the two Ravigneaux planet-pin bearings (the locked set's
    // pinions do not spin) and the drag of the engaged clutches A and B.
    assert_eq!(all.items() - pruned.items(), 11, "{:?}", pruned.skipped());
    for mesh in ["RAV:large_sun/long_pinion", "RAV:short_pinion/long_pinion"] {
        let what = format!("sliding of mesh {mesh}");
        let s = pruned.skipped().iter().find(|s| s.what == what);
        assert!(
            s.is_some_and(|s| s.why.contains("gear state the run uses (3)")),
            "{what}: {:?}",
            pruned.skipped()
        );
    }
    let opts = TransientOptions {
        rtol: 1e-10,
        atol: 1e-10,
        ..TransientOptions::default()
    };
    let a = integrate(&pruned, &segs, &opts, &mut |_, _| {}).unwrap();
    let b = integrate(&all, &segs, &opts, &mut |_, _| {}).unwrap();
    let n = pruned.nodes();
    // Same state, same inputs: the temperature derivatives agree to rounding (the idle items are
    // exact zeros in the full scene).
    let (mut wa, mut wb) = (pruned.work(segs[0].inputs), all.work(segs[0].inputs));
    let (mut da, mut db) = (vec![0.0; pruned.n_states()], vec![0.0; all.n_states()]);
    let mut yb = all.initial_state(None);
    let mut worst: f64 = 0.0;
    for (k, ya) in a.states.iter().enumerate().take(segs.len()) {
        pruned.set_inputs(segs[k].inputs, &mut wa);
        all.set_inputs(segs[k].inputs, &mut wb);
        yb[..n].copy_from_slice(&ya[..n]);
        pruned.rhs(k as f64, ya, &mut wa, &mut da);
        all.rhs(k as f64, &yb, &mut wb, &mut db);
        // norm-wise relative difference (a single component may sit near a cancellation)
        let scale = db[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..n {
            worst = worst.max((da[i] - db[i]).abs() / scale);
        }
    }
    assert!(worst < 1e-12, "dT/dt differs by {worst:e} (relative)");
    let mut dt: f64 = 0.0;
    for (ya, yb) in a.states.iter().zip(&b.states) {
        for i in 0..n {
            dt = dt.max((ya[i] - yb[i]).abs());
        }
    }
    let (ea, eb) = (
        pruned.loss_energy_by_source(a.states.last().unwrap()),
        all.loss_energy_by_source(b.states.last().unwrap()),
    );
    println!(
        "pruned vs everything evaluated: dT/dt {worst:.1e} (relative), max ΔT {dt:.2e} K, energies {ea:?} vs {eb:?}"
    );
    // Integrated at rtol 1e-10 the two differ only through their step sequences (the full scene's
    // error norm also weighs its 7 zero energies): a few µK over 600 restarts.
    assert!(dt < 1e-5, "{dt}");
    for (x, y) in ea.iter().zip(&eb) {
        assert!((x - y).abs() <= 1e-7 * y.abs().max(1.0), "{ea:?} {eb:?}");
    }
    // One preparation per distinct sample (600 here), not per call or per output row.
    assert_eq!(a.stats.samples_prepared, segs.len(), "{:?}", a.stats);
    assert!(a.stats.rhs_evals > 2 * segs.len());
}

#[test]
fn per_source_energies_equal_the_sum_of_item_energies() {
    let gb = model::load(Path::new(MODELS[0])).unwrap();
    let segs = gear3_segments(&gb);
    let lean = Scene::compile_for(
        &gb,
        &Needs {
            energy_per_source_only: true,
            ..Needs::default()
        },
    )
    .unwrap();
    let full = Scene::compile(&gb).unwrap();
    assert_eq!(lean.n_states(), lean.nodes() + geartherm::scene::N_SOURCES + 1);
    assert_eq!(full.n_states(), full.nodes() + full.items() + 1);
    assert!(lean
        .skipped()
        .iter()
        .any(|s| s.what == "energy of each loss item"));
    let opts = TransientOptions {
        rtol: 1e-10,
        atol: 1e-10,
        ..TransientOptions::default()
    };
    let lean_opts = TransientOptions {
        record_losses: false,
        ..opts.clone()
    };
    let a = integrate(&lean, &segs, &lean_opts, &mut |_, _| {}).unwrap();
    let b = integrate(&full, &segs, &opts, &mut |_, _| {}).unwrap();
    assert!(a.losses.is_empty() && b.losses.len() == b.times.len());
    let (ya, yb) = (a.states.last().unwrap(), b.states.last().unwrap());
    let (ea, eb) = (lean.loss_energy_by_source(ya), full.loss_energy_by_source(yb));
    assert!(lean.item_energy(ya, 0).is_none() && full.item_energy(yb, 0).is_some());
    for (x, y) in ea.iter().zip(&eb) {
        assert!((x - y).abs() <= 1e-7 * y.abs().max(1.0), "{ea:?} {eb:?}");
    }
    let bal = geartherm::solve::transient::energy_balance(&lean, &a);
    assert!(bal.relative < 1e-9, "{bal:?}");
}

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn summary_only_and_evaluate_all_runs_agree_with_the_default_run() {
    let tmp = tempfile::tempdir().unwrap();
    let go = |name: &str, extra: &[&str]| {
        let dir = tmp.path().join(name);
        let mut args = vec![
            "run",
            MODELS[0],
            "--cycle",
            "artemis_urban",
            // 1e-11: with the automatic's clutch drag and converter the RHS has kinks, and at
            // 1e-9 the three integration paths differ by 1e-6 K from integration error alone.
            "--rtol",
            "1e-11",
            "--atol",
            "1e-11",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = run(&args);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        dir
    };
    let d = go("default", &[]);
    let s = go("summary_only", &["--summary-only"]);
    let e = go("evaluate_all", &["--evaluate-all"]);
    assert!(d.join("timeseries.csv").exists());
    assert!(!s.join("timeseries.csv").exists() && s.join("summary.json").exists());
    let (sd, ss, se) = (summary(&d), summary(&s), summary(&e));
    assert_eq!(ss["energy_by_item_j"].as_array().unwrap().len(), 0);
    assert!(ss["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .any(|x| x["what"] == "energy of each loss item"));
    assert!(!sd["energy_by_item_j"].as_array().unwrap().is_empty());
    for other in [&ss, &se] {
        for src in ["churning", "pocketing", "sliding", "total"] {
            let (a, b) = (
                sd["energy_lost_j"][src].as_f64().unwrap(),
                other["energy_lost_j"][src].as_f64().unwrap(),
            );
            assert!((a - b).abs() <= 1e-6 * a.abs(), "{src}: {a} vs {b}");
        }
        let (a, b) = (
            sd["temperatures_c"]["sump"]["final"].as_f64().unwrap(),
            other["temperatures_c"]["sump"]["final"].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-6, "{a} vs {b}");
    }
}

#[test]
fn usage_errors_exit_1_and_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("x");
    for args in [
        vec!["run", MODELS[1], "--summary-only", "--report"],
        vec!["run", MODELS[1], "--no-such-flag"],
        vec!["run"],
    ] {
        let mut a = args.clone();
        a.extend_from_slice(&["--out", dir.to_str().unwrap()]);
        let out = run(&a);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(!dir.exists());
    }
    assert_eq!(run(&["--help"]).status.code(), Some(0));
}

#[test]
fn per_state_idle_items_of_the_at6() {
    // What each gear state alone leaves idle (docs/physics.md §8): 3rd locks the Ravigneaux set.
    let gb = model::load(Path::new(MODELS[0])).unwrap();
    let all_states = LossScene::compile(&gb).unwrap();
    let full = all_states.len();
    // all states together need every item
    assert!(!all_states
        .skipped
        .iter()
        .any(|s| s.why.contains("every gear state")));
    let mut idle_by_state = Vec::new();
    for (i, st) in gb.gear_states.iter().enumerate() {
        let sc = LossScene::compile_for(
            &gb,
            &Needs {
                states: Some(vec![i]),
                ..Needs::default()
            },
        )
        .unwrap();
        let idle: Vec<_> = sc
            .skipped
            .iter()
            .filter(|s| s.why.contains("every gear state the run uses"))
            .map(|s| s.what.clone())
            .collect();
        assert_eq!(sc.len() + idle.len(), full, "state {}", st.name);
        println!("state {}: {} of {full} items, idle {idle:?}", st.name, sc.len());
        idle_by_state.push((st.name.clone(), idle.len()));
    }
    let count = |n: &str| idle_by_state.iter().find(|(s, _)| s == n).map(|x| x.1);
    // 3rd: the 4 Ravigneaux sliding meshes, its 3 external pockets (fed by the circuit), the 2
    // Ravigneaux planet bearings and the drag of the engaged clutches A and B.
    assert_eq!(count("3"), Some(11));
    // 2nd holds the large sun: its bearing and its windage stand still, and the engaged A and C
    // have no drag.
    assert_eq!(count("2"), Some(4));
    // every other state leaves one to four meshes unloaded, and in 1st, 6th and R one held
    // member's bearing still (in 6th also the held large sun's windage), plus the drag of its two
    // engaged shift elements
    for s in ["1", "4", "5", "6", "R"] {
        assert!(
            count(s).is_some_and(|c| (3..=8).contains(&c)),
            "{s}: {idle_by_state:?}"
        );
    }
}
