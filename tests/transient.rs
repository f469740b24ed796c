//! Transient solver: analytic checks (one node, a linear 3-node network against its matrix
//! exponential, the maximum principle), the viscosity feedback, and one test per diffsol pitfall
//! guard (each fails when its guard is switched off).

use geartherm::model;
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{Inputs, Scene};
use geartherm::solve::drive::segments;
use geartherm::solve::transient::{
    energy_balance, integrate, Guards, Method, Restart, Segment, Trajectory, TransientOptions,
};
use nalgebra::{DMatrix, DVector};

mod common;
use common::{film_network, fzg_frozen, fzg_with, jumpy, steady_inputs};

const IMPLICIT: [Method; 4] = [Method::Bdf, Method::Esdirk34, Method::TrBdf2, Method::Ros3];

fn uniform(inputs: Inputs, n: usize, dt: f64) -> Vec<Segment> {
    (0..n)
        .map(|k| Segment {
            t0: k as f64 * dt,
            t1: (k + 1) as f64 * dt,
            inputs,
        })
        .collect()
}

fn opts(method: Method, rtol: f64) -> TransientOptions {
    TransientOptions {
        method,
        rtol,
        atol: rtol,
        ..TransientOptions::default()
    }
}

fn run(scene: &Scene, segs: &[Segment], o: &TransientOptions) -> Trajectory {
    integrate(scene, segs, o, &mut |_, _| {}).unwrap()
}

/// Total loss (W) at a frozen oil temperature.
fn frozen_loss(scene: &Scene, inputs: Inputs) -> f64 {
    let mut w = scene.work(inputs);
    let y = scene.initial_state(None);
    scene.evaluate_losses(&y, &mut w);
    w.q.iter().sum()
}

const ONE_NODE: &str = r#"
[thermal]
oil_node = "oil"
initial_temp_c = 23.0
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = 2000.0
[[thermal.boundaries]]
name = "ambient"
temp_c = 23.0
[[thermal.links]]
between = ["oil", "ambient"]
conductance_w_per_k = 5.0
"#;

#[test]
fn one_node_matches_the_exponential_approach() {
    let scene = fzg_frozen(ONE_NODE, 60.0);
    let inputs = steady_inputs(1450.0, 100.0);
    let q = frozen_loss(&scene, inputs);
    assert!(q > 50.0, "loss {q}");
    let (g, c, ta) = (5.0, 2000.0, 23.0 + KELVIN_OFFSET);
    let segs = uniform(inputs, 100, 20.0);
    for m in IMPLICIT {
        let traj = run(&scene, &segs, &opts(m, 1e-12));
        let mut worst: f64 = 0.0;
        for (t, y) in traj.times.iter().zip(&traj.states) {
            let exact = ta + q / g * (1.0 - (-g * t / c).exp());
            worst = worst.max((y[0] - exact).abs());
        }
        println!(
            "{}: max |T − T_exact| = {worst:.2e} K over 2000 s, {} steps",
            m.name(),
            traj.stats.steps
        );
        assert!(worst < 1e-6, "{}: {worst}", m.name());
        assert!(energy_balance(&scene, &traj).relative < 1e-9);
    }
}

const THREE_NODES: &str = r#"
[thermal]
oil_node = "oil"
initial_temp_c = 23.0
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = 2000.0
[[thermal.nodes]]
name = "b"
capacity_j_per_k = 500.0
initial_temp_c = 40.0
[[thermal.nodes]]
name = "c"
capacity_j_per_k = 8000.0
initial_temp_c = 10.0
[[thermal.boundaries]]
name = "ambient"
temp_c = 23.0
[[thermal.links]]
between = ["oil", "b"]
conductance_w_per_k = 3.0
[[thermal.links]]
between = ["b", "c"]
conductance_w_per_k = 10.0
[[thermal.links]]
between = ["c", "ambient"]
conductance_w_per_k = 2.0
[[thermal.links]]
between = ["oil", "ambient"]
h_w_per_m2k = 5.0
area_m2 = 0.1
"#;

#[test]
fn three_node_network_matches_its_matrix_exponential() {
    let scene = fzg_frozen(THREE_NODES, 50.0);
    let inputs = steady_inputs(2000.0, 150.0);
    let q = frozen_loss(&scene, inputs);
    // C dT/dt = A T + b.
    let c = [2000.0, 500.0, 8000.0];
    let ta = 23.0 + KELVIN_OFFSET;
    let a = DMatrix::from_row_slice(3, 3, &[-3.5, 3.0, 0.0, 3.0, -13.0, 10.0, 0.0, 10.0, -12.0]);
    let b = DVector::from_vec(vec![q + 0.5 * ta, 0.0, 2.0 * ta]);
    let cinv = DMatrix::from_diagonal(&DVector::from_vec(c.iter().map(|x| 1.0 / x).collect()));
    let m = &cinv * &a;
    let f = &cinv * &b;
    let lu = m.clone().lu();
    let y_ss = -lu.solve(&f).unwrap();
    let y0 = DVector::from_vec(vec![ta, 40.0 + KELVIN_OFFSET, 10.0 + KELVIN_OFFSET]);
    let segs = uniform(inputs, 60, 60.0);
    for meth in IMPLICIT {
        let traj = run(&scene, &segs, &opts(meth, 1e-12));
        let mut worst: f64 = 0.0;
        for (t, y) in traj.times.iter().zip(&traj.states) {
            let exact = &y_ss + (&m * *t).exp() * (&y0 - &y_ss);
            for i in 0..3 {
                worst = worst.max((y[i] - exact[i]).abs());
            }
        }
        println!("{}: max |T − expm solution| = {worst:.2e} K", meth.name());
        assert!(worst < 1e-6, "{}: {worst}", meth.name());
    }
}

#[test]
fn without_sources_temperatures_stay_within_initial_and_boundary_range() {
    // Nonlinear links included: radiation and a thermostat cooler to a time-varying boundary.
    let net = r#"
[thermal]
oil_node = "oil"
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = 1500.0
initial_temp_c = 80.0
[[thermal.nodes]]
name = "gear"
capacity_j_per_k = 0.5
initial_temp_c = -10.0
[[thermal.nodes]]
name = "housing"
capacity_j_per_k = 9000.0
initial_temp_c = 23.0
[[thermal.boundaries]]
name = "ambient"
temp_c = 30.0
[[thermal.boundaries]]
name = "coolant"
series = [[0.0, 0.0], [300.0, 60.0]]
[[thermal.links]]
between = ["oil", "gear"]
conductance_w_per_k = 50.0
[[thermal.links]]
between = ["oil", "housing"]
conductance_w_per_k = 20.0
[[thermal.links]]
between = ["housing", "ambient"]
emissivity = 0.9
area_m2 = 0.5
[[thermal.coolers]]
name = "cooler"
hot = "oil"
cold = "coolant"
effectiveness = 0.6
capacity_rate_w_per_k = 100.0
thermostat = { open_c = 40.0, full_c = 60.0 }
"#;
    let scene = fzg_with(net);
    let segs = uniform(steady_inputs(0.0, 0.0), 900, 1.0);
    let (lo, hi) = (-10.0 + KELVIN_OFFSET, 80.0 + KELVIN_OFFSET);
    for m in IMPLICIT {
        let traj = run(&scene, &segs, &opts(m, 1e-6));
        for y in &traj.states {
            for &t in &y[..3] {
                assert!(t >= lo - 1e-9 && t <= hi + 1e-9, "{}: {t}", m.name());
            }
            assert!(y[3..6].iter().all(|e| *e == 0.0), "no loss without motion");
        }
        assert!(energy_balance(&scene, &traj).to_boundaries.abs() > 0.0);
    }
}

fn at6_wltc(frozen: Option<f64>) -> (Scene, Trajectory) {
    let gb = model::load(std::path::Path::new("models/at6_lepelletier.toml")).unwrap();
    let needs = geartherm::scene::Needs {
        frozen_oil_temp_k: frozen,
        ..Default::default()
    };
    let scene = Scene::compile_for(&gb, &needs).unwrap();
    let cycle = geartherm::cycle::DriveCycle::resolve("wltc").unwrap();
    let (_, segs) = segments(&gb, &cycle).unwrap();
    let traj = run(&scene, &segs, &TransientOptions::default());
    (scene, traj)
}

#[test]
fn at6_wltc_cold_start_warms_up_with_viscosity_feedback() {
    let (scene, coupled) = at6_wltc(None);
    let (_, frozen) = at6_wltc(Some(23.0 + KELVIN_OFFSET));
    let bal = energy_balance(&scene, &coupled);
    let oil = scene.thermal().oil;
    let t0 = coupled.states[0][oil] - KELVIN_OFFSET;
    let t1 = coupled.states.last().unwrap()[oil] - KELVIN_OFFSET;
    let fb = energy_balance(&scene, &frozen);
    println!(
        "AT6 WLTC: oil {t0:.2} → {t1:.2} °C; loss energy coupled {:.1} J, viscosity frozen at 23 °C {:.1} J \
         (difference {:+.3} %); balance {:.2e}",
        bal.lost,
        fb.lost,
        100.0 * (bal.lost / fb.lost - 1.0),
        bal.relative
    );
    assert!(bal.relative <= 1e-9);
    assert!(t1 > t0 + 1.0, "oil must warm up");
    // Direction: the warmer oil has the lower viscosity. The ISO TC60 mesh friction rises as the
    // viscosity falls (μ_mz ∝ η^−0.05 Schlenk, the default; ISO TC60 ∝ η^−0.25), but the bearings' rolling friction falls with it
    // (SKF M_rr ∝ (ν n)^0.6, Palmgren M0 ∝ (ν n)^(2/3)) and, with the AT6's eleven bearings,
    // dominates (docs/physics.md §Bearings): the coupled run loses less energy than the frozen
    // one (−1.5 % over the WLTC).
    assert!(
        bal.lost < fb.lost * 0.999,
        "coupled {} vs frozen {}",
        bal.lost,
        fb.lost
    );
}

fn max_err(a: &Trajectory, b: &Trajectory, n: usize) -> f64 {
    a.states
        .iter()
        .zip(&b.states)
        .map(|(x, y)| (0..n).map(|i| (x[i] - y[i]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max)
}

fn fzg_model_scene() -> Scene {
    Scene::compile(&model::load(std::path::Path::new("models/fzg_c.toml")).unwrap()).unwrap()
}

#[test]
fn pitfall_2_rows_sit_exactly_on_segment_ends() {
    // Segment ends that are not representable (0.1 s steps): rows must still be at the exact ends
    // with their own segment's inputs, whatever t the solver stopped at.
    let scene = fzg_model_scene();
    let segs: Vec<Segment> = (0..50)
        .map(|k| Segment {
            t0: k as f64 * 0.1,
            t1: (k + 1) as f64 * 0.1,
            inputs: steady_inputs(1000.0 + 10.0 * k as f64, 50.0),
        })
        .collect();
    let traj = run(&scene, &segs, &TransientOptions::default());
    assert_eq!(traj.times.len(), 51);
    for (k, t) in traj.times.iter().enumerate().skip(1) {
        assert_eq!(*t, segs[k - 1].t1);
        assert_eq!(traj.segment[k], k.min(49));
    }
}

#[test]
fn pitfall_5_restarting_bdf_only_at_jumps_keeps_its_order() {
    // Constant inputs cut into 1 s segments: restarting every segment pins BDF at order 1.
    let scene = fzg_model_scene();
    let segs = uniform(steady_inputs(1450.0, 135.0), 1200, 1.0);
    let reference = run(&scene, &segs, &opts(Method::Esdirk34, 1e-11));
    let mut o = opts(Method::Bdf, 1e-6);
    let jumps = run(&scene, &segs, &o);
    o.restart = Restart::EveryInterval;
    let every = run(&scene, &segs, &o);
    let (ej, ee) = (max_err(&jumps, &reference, 5), max_err(&every, &reference, 5));
    println!(
        "BDF rtol 1e-6: restart at jumps {ej:.2e} K ({} steps), every second {ee:.2e} K ({} steps)",
        jumps.stats.steps, every.stats.steps
    );
    assert!(ej * 10.0 < ee, "at jumps {ej}, every second {ee}");
}

#[test]
fn pitfall_6_derivative_refreshed_after_an_input_jump() {
    // ESDIRK34 starts each step from the stored derivative (first stage explicit): a stale dy
    // after a jump puts the pre-jump heat into the first stage of the new interval.
    // The gear-only FZG scene this pitfall was calibrated on (bearings and seals add smooth
    // load-dependent heat; with them the stale/refreshed error ratio is 4.2 instead of 5.8).
    // 600 one-second jumps: the stale-derivative error accumulates with the number of jumps
    // (stale/refreshed ratio at rtol 1e-6: 4.97 over 300 jumps, 7.45 over 600; at rtol 1e-5
    // 31.7 / 53.5).
    let mut gb = model::load(std::path::Path::new("models/fzg_c.toml")).unwrap();
    gb.bearings.clear();
    gb.seals.clear();
    let scene = Scene::compile(&gb).unwrap();
    let segs = jumpy(600, |_| 0);
    let reference = run(&scene, &segs, &opts(Method::Esdirk34, 1e-11));
    let mut o = opts(Method::Esdirk34, 1e-6);
    let good = run(&scene, &segs, &o);
    o.guards = Guards {
        refresh_derivative: false,
        ..Guards::default()
    };
    let stale = run(&scene, &segs, &o);
    let (eg, es) = (max_err(&good, &reference, 5), max_err(&stale, &reference, 5));
    println!("ESDIRK34 rtol 1e-6, jumps every second: dy refreshed {eg:.2e} K, stale {es:.2e} K");
    assert!(eg * 5.0 < es, "refreshed {eg}, stale {es}");
}

#[test]
fn pitfall_4_step_size_reset_at_stiff_jumps() {
    // A near-massless node (0.01 J/K) next to the oil: after a jump the old (large) step makes
    // BDF fail its error test repeatedly; the re-estimated step avoids the rejections.
    let net = film_network(0.01, 20.0);
    let scene = fzg_with(&net);
    // Long quiet stretches (large steps) between load jumps.
    let segs: Vec<Segment> = (0..600)
        .map(|k| Segment {
            t0: k as f64,
            t1: k as f64 + 1.0,
            inputs: if (k / 60) % 2 == 0 {
                steady_inputs(1450.0, 20.0)
            } else {
                steady_inputs(2900.0, 300.0)
            },
        })
        .collect();
    let mut o = opts(Method::Bdf, 1e-6);
    let good = run(&scene, &segs, &o);
    o.guards = Guards {
        reset_step: false,
        ..Guards::default()
    };
    let kept = integrate(&scene, &segs, &o, &mut |_, _| {});
    let kept_rejected = kept.as_ref().map_or(usize::MAX, |t| t.stats.rejected);
    println!(
        "BDF with a 0.01 J/K node: step re-estimated: {} rejected of {} steps; old step kept: {}",
        good.stats.rejected,
        good.stats.steps,
        kept.as_ref().map_or_else(
            |e| format!("failed: {e}"),
            |t| format!("{} rejected", t.stats.rejected)
        )
    );
    assert!(
        good.stats.rejected < kept_rejected,
        "{} vs {kept_rejected}",
        good.stats.rejected
    );
}

#[test]
fn pitfall_1_long_runs_survive_the_lifetime_newton_failure_count() {
    // Ten WLTCs of random jumps on a stiff network accumulate more than diffsol's default of 50
    // Newton failures over the solver's life; with the limit raised the run completes.
    let net = film_network(0.001, 50.0);
    let scene = fzg_with(&net);
    let segs = jumpy(18000, |_| 0);
    let mut o = opts(Method::Bdf, 1e-6);
    o.guards = Guards {
        reset_step: false,
        ..Guards::default()
    };
    let t = run(&scene, &segs, &o);
    println!(
        "10 × 1800 s of jumps: {} Newton failures over the run, completed",
        t.stats.newton_failures
    );
    assert!(
        t.stats.newton_failures > 50,
        "scenario must exceed the default limit"
    );
    o.guards.raise_failure_limit = false;
    assert!(integrate(&scene, &segs, &o, &mut |_, _| {}).is_err());
}

#[test]
fn default_settings_on_at6_wltc_are_within_a_millikelvin_of_the_reference() {
    let gb = model::load(std::path::Path::new("models/at6_lepelletier.toml")).unwrap();
    let scene = Scene::compile(&gb).unwrap();
    let cycle = geartherm::cycle::DriveCycle::resolve("wltc").unwrap();
    let (_, segs) = segments(&gb, &cycle).unwrap();
    let (reference, info) = geartherm::solve::work_precision::reference(&scene, &segs, 1e-12).unwrap();
    let default = run(&scene, &segs, &TransientOptions::default());
    let (fin, max, rms) = geartherm::solve::work_precision::errors(&default, &reference, scene.nodes());
    let bal = energy_balance(&scene, &default).relative;
    println!(
        "AT6 WLTC, default {} rtol {:e}: error vs reference max {max:.2e} K, final {fin:.2e} K, rms {rms:.2e} K; \
         balance {bal:.1e}; reference pair agrees to {:.1e} K",
        TransientOptions::default().method.name(),
        TransientOptions::default().rtol,
        info.agreement_k
    );
    assert!(info.agreement_k < 1e-6);
    assert!(max <= 1e-3, "{max}");
    assert!(bal <= 1e-9, "{bal}");
}
