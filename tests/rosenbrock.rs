//! ROS3, the default integrator (src/solve/rosenbrock.rs): its ∂f/∂t term against an analytic
//! ramp, its learnt loss slopes against the differenced ones, the tolerance it follows, and the
//! sparse path.

use geartherm::model;
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::Scene;
use geartherm::solve::drive::segments;
use geartherm::solve::transient::{
    energy_balance, integrate, LinearAlgebra, Method, Segment, Trajectory, TransientOptions,
};
use geartherm::solve::work_precision::{errors, reference};

mod common;
use common::{fzg_frozen, steady_inputs};

fn ros3(rtol: f64) -> TransientOptions {
    TransientOptions {
        method: Method::Ros3,
        rtol,
        atol: rtol,
        ..TransientOptions::default()
    }
}

fn run(scene: &Scene, segs: &[Segment], o: &TransientOptions) -> Trajectory {
    integrate(scene, segs, o, &mut |_, _| {}).unwrap()
}

/// One node coupled to a boundary whose temperature is a ramp: C dT/dt = G (a + b t − T).
const RAMP: &str = r#"
[thermal]
oil_node = "oil"
initial_temp_c = 20.0
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = 4000.0
[[thermal.boundaries]]
name = "coolant"
series = [[0.0, 20.0], [1000.0, 120.0]]
[[thermal.links]]
between = ["oil", "coolant"]
conductance_w_per_k = 20.0
"#;

#[test]
fn a_boundary_ramp_is_followed_to_its_analytic_solution() {
    // Measured without the γ_i h ∂f/∂t terms: 0.18 K at rtol 1e-4 and 2.1e-3 K at 1e-8 (25 708
    // steps); with them 1.7e-4 K and 5.4e-7 K.
    let scene = fzg_frozen(RAMP, 60.0);
    let inputs = steady_inputs(0.0, 0.0);
    let segs: Vec<Segment> = (0..40)
        .map(|k| Segment {
            t0: k as f64 * 25.0,
            t1: (k + 1) as f64 * 25.0,
            inputs,
        })
        .collect();
    let (a, b, tau) = (20.0 + KELVIN_OFFSET, 0.1, 4000.0 / 20.0);
    for (rtol, bound) in [(1e-4, 1e-3), (1e-8, 5e-6)] {
        let traj = run(&scene, &segs, &ros3(rtol));
        let mut worst: f64 = 0.0;
        for (t, y) in traj.times.iter().zip(&traj.states) {
            let exact = a + b * t - b * tau + b * tau * (-t / tau).exp();
            worst = worst.max((y[0] - exact).abs());
        }
        println!(
            "rtol {rtol:e}: max |T − exact| = {worst:.2e} K, {} steps",
            traj.stats.steps
        );
        assert!(worst < bound, "rtol {rtol}: {worst}");
        assert!(traj.stats.steps < 1000, "{} steps", traj.stats.steps);
        assert!(energy_balance(&scene, &traj).relative < 1e-9);
    }
}

fn wltc(path: &str) -> (Scene, Vec<Segment>) {
    let gb = model::load(std::path::Path::new(path)).unwrap();
    let scene = Scene::compile(&gb).unwrap();
    let cycle = geartherm::cycle::DriveCycle::resolve("wltc").unwrap();
    let (_, segs) = segments(&gb, &cycle).unwrap();
    (scene, segs)
}

#[test]
fn learnt_loss_slopes_hold_the_error_and_tighter_tolerances_difference_them() {
    let (scene, segs) = wltc("models/fzg_c.toml");
    let (refr, info) = reference(&scene, &segs, 1e-12).unwrap();
    assert!(info.agreement_k < 1e-6);
    let learnt = run(&scene, &segs, &ros3(1e-4));
    let differenced = run(&scene, &segs, &ros3(1e-6));
    let (_, e_learnt, _) = errors(&learnt, &refr, scene.nodes());
    let (_, e_diff, _) = errors(&differenced, &refr, scene.nodes());
    println!(
        "FZG C WLTC: rtol 1e-4 (learnt slopes) {e_learnt:.2e} K, {} slope differences in {} steps; \
         rtol 1e-6 (differenced) {e_diff:.2e} K, {} differences",
        learnt.stats.jac_evals, learnt.stats.steps, differenced.stats.jac_evals
    );
    // The learnt slopes replace the forward difference at most steps...
    assert!(learnt.stats.jac_evals * 10 < learnt.stats.steps);
    // ...at an error well inside the tolerance (rtol × 350 K = 0.035 K)...
    assert!(e_learnt < 1e-4, "{e_learnt}");
    // ...and a tighter tolerance differences them at every step and is more accurate.
    assert!(differenced.stats.jac_evals >= differenced.stats.steps);
    assert!(e_diff < e_learnt / 3.0, "{e_diff} vs {e_learnt}");
    for t in [&learnt, &differenced] {
        assert!(energy_balance(&scene, t).relative < 1e-9);
        // Two right-hand sides per step and one per row (the row's losses are stage 1's).
        assert!(t.stats.rhs_evals <= 2 * (t.stats.steps + t.stats.rejected) + segs.len() + 1);
    }
}

#[test]
fn at6_wltc_with_a_coolant_warm_up_stays_near_the_reference() {
    // The AT6's coolant boundary warms 23 → 90 °C: the ∂f/∂t path on a full model (without it the
    // sump error is 1.2e-2 K).
    let (scene, segs) = wltc("models/at6_lepelletier.toml");
    let (refr, _) = reference(&scene, &segs, 1e-12).unwrap();
    let traj = run(&scene, &segs, &TransientOptions::default());
    let (_, max, _) = errors(&traj, &refr, scene.nodes());
    println!(
        "AT6 WLTC, ros3 default: max error {max:.2e} K, {} steps",
        traj.stats.steps
    );
    assert!(max < 1e-3, "{max}");
}

#[test]
fn sparse_and_dense_linear_algebra_give_the_same_trajectory() {
    let (scene, segs) = wltc("models/helical_stage.toml");
    let segs = &segs[..600];
    let mut o = ros3(1e-4);
    o.linear_algebra = LinearAlgebra::Dense;
    let dense = run(&scene, segs, &o);
    o.linear_algebra = LinearAlgebra::Sparse;
    let sparse = run(&scene, segs, &o);
    assert!(sparse.stats.sparse && !dense.stats.sparse);
    let mut worst: f64 = 0.0;
    for (a, b) in dense.states.iter().zip(&sparse.states) {
        for (x, y) in a.iter().zip(b).take(scene.nodes()) {
            worst = worst.max((x - y).abs());
        }
    }
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn the_analytic_time_derivative_matches_a_central_difference_of_the_rhs() {
    // The AT6's coolant series is piecewise linear with knots at 300, 600 and 900 s: inside a
    // piece the central difference of f over ±1 ms is exact up to rounding, and at a knot the
    // derivative is the next piece's (the one a step from t integrates over).
    let (scene, segs) = wltc("models/at6_lepelletier.toml");
    let mut work = scene.work(segs[400].inputs);
    let mut y = scene.initial_state(None);
    y[scene.thermal().oil] += 30.0; // the coolant exchanger between the oil and a warmer coolant
    let n_s = scene.n_states();
    let (mut ft, mut f1, mut f0) = (vec![0.0; n_s], vec![0.0; n_s], vec![0.0; n_s]);
    let d = 1e-3;
    for t in [17.3, 450.6, 777.7, 1500.0] {
        scene.time_derivative(t, &y, &mut work, &mut ft);
        scene.rhs(t + d, &y, &mut work, &mut f1);
        scene.rhs(t - d, &y, &mut work, &mut f0);
        let scale = ft.iter().fold(1e-12_f64, |m, v| m.max(v.abs()));
        for (i, ((a, b0), b1)) in ft.iter().zip(&f0).zip(&f1).enumerate() {
            let fd = (b1 - b0) / (2.0 * d);
            assert!((a - fd).abs() <= 1e-6 * scale, "t {t}, state {i}: {a} vs {fd}");
        }
    }
    // At a knot: the slope of the piece after it.
    scene.time_derivative(300.0, &y, &mut work, &mut ft);
    scene.rhs(300.0 + d, &y, &mut work, &mut f1);
    scene.rhs(300.0, &y, &mut work, &mut f0);
    let oil = scene.thermal().oil;
    let fd = (f1[oil] - f0[oil]) / d;
    assert!(
        (ft[oil] - fd).abs() <= 1e-6 * fd.abs().max(1e-12),
        "{} vs {fd}",
        ft[oil]
    );
    assert!(ft[oil] != 0.0);
}
