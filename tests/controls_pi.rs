//! The PI bypass valve (`kind = "pi_valve"`): a two-node network (oil – casing – ambient) with a
//! constant source in the oil (the FZG C's losses with the oil properties frozen) and a cooler on the oil whose share a PI valve sets on the oil's
//! temperature. With the share within its limits the equilibrium has the oil exactly at the set
//! point, the casing and the share given by the heat balance in closed form; the steady solver
//! and long transients (ROS3 and BDF) must find it. A step response from cold stays within its
//! limits and settles; at saturation the integral relaxes to the limit (back-calculation
//! anti-windup) and the valve leaves the limit when the load falls. The Jacobian (with the integral's column) against
//! products, the energy balance, and the refusals of bad values.

use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{Inputs, Scene};
use geartherm::solve::equilibrium::equilibrium;
use geartherm::solve::steady::SteadyOptions;
use geartherm::solve::transient::{energy_balance, Method, Segment};

mod common;
use common::controls::{casing_air, oil_casing, run, uniform, AMBIENT_C, C1, G1, G2};
use common::{fzg_frozen, steady_inputs};

/// The cooler's ε·C_min, W/K, and its coolant, °C.
const COOLANT_C: f64 = 30.0;
const SET_C: f64 = 60.0;
const GAIN: f64 = 0.05;
const TI: f64 = 200.0;

fn network(gc: f64, min: f64, max: f64) -> String {
    oil_casing(AMBIENT_C, C1)
        + &format!(
            r#"[[thermal.boundaries]]
name = "coolant"
temp_c = {COOLANT_C:e}
"#
        )
        + &casing_air(G2, None)
        + &format!(
            r#"[[thermal.coolers]]
name = "cooler"
hot = "oil"
cold = "coolant"
effectiveness = 1.0
capacity_rate_w_per_k = {gc:e}
[[thermal.controls]]
name = "bypass"
kind = "pi_valve"
sensor = "oil"
cooler = "cooler"
set_c = {SET_C:e}
gain_per_k = {GAIN:e}
integral_time_s = {TI:e}
min_share = {min:e}
max_share = {max:e}
"#
        )
}

/// Input torque of the nominal load and of the lighter one, N·m (at 3000 rpm).
const TORQUE: f64 = 150.0;
const LIGHT: f64 = 100.0;

/// The source into the oil at `torque` (frozen oil properties: constant), W.
fn source(scene: &Scene, torque: f64) -> f64 {
    let inputs = steady_inputs(3000.0, torque);
    let mut w = scene.work(inputs);
    let y = scene.initial_state(None);
    scene.evaluate_losses(&y, &mut w);
    let mut src = vec![0.0; scene.nodes()];
    for (q, dest) in w.q.iter().zip(&scene.thermal().heat) {
        for &(node, f) in dest {
            src[node] += f * q;
        }
    }
    assert!(
        src[1..].iter().all(|x| *x == 0.0),
        "the losses heat the oil alone"
    );
    src[0]
}

/// The cooler's ε·C_min, W/K: the share 0.5 holds the oil at the set point under the nominal
/// load.
fn cooler_g() -> f64 {
    let q = source(&fzg_frozen(&network(100.0, 0.0, 1.0), 40.0), TORQUE);
    let (tc, _) = analytic_with(q, 1.0);
    let through = q - G1 * (SET_C - tc);
    through / (0.5 * (SET_C - COOLANT_C))
}

/// The scene with the oil properties frozen, the nominal inputs and their source (W) and the
/// cooler's ε·C_min.
fn pi_scene(min: f64, max: f64) -> (Scene, Inputs, f64, f64) {
    let gc = cooler_g();
    let scene = fzg_frozen(&network(gc, min, max), 40.0);
    let q = source(&scene, TORQUE);
    (scene, steady_inputs(3000.0, TORQUE), q, gc)
}

/// The equilibrium with the oil at the set point: (casing °C, share) for cooler `gc`.
fn analytic_with(q: f64, gc: f64) -> (f64, f64) {
    let tc = (G1 * SET_C + G2 * AMBIENT_C) / (G1 + G2);
    let u = (q - G1 * (SET_C - tc)) / (gc * (SET_C - COOLANT_C));
    (tc, u)
}

/// The equilibrium with the share held at `u`: the oil, K.
fn oil_at_share(q: f64, gc: f64, u: f64) -> f64 {
    let ta = AMBIENT_C + KELVIN_OFFSET;
    let tk = COOLANT_C + KELVIN_OFFSET;
    // Oil: q = G1 (T1 − T2) + u gc (T1 − Tk); casing: G1 (T1 − T2) = G2 (T2 − Ta).
    let g12 = G1 * G2 / (G1 + G2);
    (q + g12 * ta + u * gc * tk) / (g12 + u * gc)
}

#[test]
fn steady_state_holds_the_set_point_exactly_within_the_limits() {
    let (scene, inputs, q, gc) = pi_scene(0.0, 1.0);
    let (tc, u) = analytic_with(q, gc);
    assert!(u > 0.05 && u < 0.95, "the share must lie within its limits: {u}");
    let eq = equilibrium(&scene, inputs, None, &SteadyOptions::default()).unwrap();
    let t = &eq.solution.temperatures;
    let (oil, casing) = (t[0] - KELVIN_OFFSET, t[1] - KELVIN_OFFSET);
    println!("steady: oil {oil:.12} °C (set {SET_C}), casing {casing:.12} (analytic {tc:.12}); share {u:.9}");
    assert!(eq.limit_cycle.is_none());
    assert!((oil - SET_C).abs() < 1e-8, "oil {oil} vs set point {SET_C}");
    assert!((casing - tc).abs() < 1e-8, "casing {casing} vs {tc}");
}

#[test]
fn steady_state_at_a_limit_when_the_cooler_cannot_hold_the_set_point() {
    // The share needed is 0.5: at most 0.3, the valve rests at its upper limit with the oil
    // above the set point; at least 0.7, at its lower limit with the oil below it.
    for (min, max, share) in [(0.0, 0.3, 0.3), (0.7, 1.0, 0.7)] {
        let (scene, inputs, q, gc) = pi_scene(min, max);
        let eq = equilibrium(&scene, inputs, None, &SteadyOptions::default()).unwrap();
        let t = &eq.solution.temperatures;
        let t1 = oil_at_share(q, gc, share);
        println!(
            "steady with shares {min}..{max}: oil {:.9} °C, analytic at share {share}: {:.9}",
            t[0] - KELVIN_OFFSET,
            t1 - KELVIN_OFFSET
        );
        assert_eq!(t[0] - KELVIN_OFFSET > SET_C, share < 0.5);
        assert!((t[0] - t1).abs() < 1e-8);
    }
}

#[test]
fn step_response_from_cold_settles_on_the_set_point_on_ros3_and_bdf() {
    let (scene, inputs, q, gc) = pi_scene(0.0, 1.0);
    let (tc, u) = analytic_with(q, gc);
    let segs = uniform(inputs, 400, 100.0);
    for (method, rtol) in [(Method::Ros3, 1e-10), (Method::Bdf, 1e-10)] {
        let traj = run(&scene, &segs, method, rtol);
        let last = traj.states.last().unwrap();
        let share_col = 0;
        let integ_col = scene.thermal().controls.len();
        let (mut peak, mut share_lo, mut share_hi) = (f64::MIN, f64::MAX, f64::MIN);
        for (y, c) in traj.states.iter().zip(&traj.controls) {
            peak = peak.max(y[0] - KELVIN_OFFSET);
            share_lo = share_lo.min(c[share_col]);
            share_hi = share_hi.max(c[share_col]);
        }
        let oil = last[0] - KELVIN_OFFSET;
        let casing = last[1] - KELVIN_OFFSET;
        let c = traj.controls.last().unwrap();
        let bal = energy_balance(&scene, &traj);
        println!(
            "{method:?}: after 40 000 s oil {oil:.9} °C, casing {casing:.9} (analytic {tc:.9}), share {:.9} \
             (analytic {u:.9}), integral {:.9}, peak {peak:.4} °C, switches {:?}, balance {:.2e}",
            c[share_col], c[integ_col], traj.switches, bal.relative
        );
        assert!((oil - SET_C).abs() < 1e-6, "{method:?}: oil {oil}");
        assert!((casing - tc).abs() < 1e-6, "{method:?}: casing {casing}");
        assert!(
            (c[share_col] - u).abs() < 1e-6,
            "{method:?}: share {}",
            c[share_col]
        );
        assert!(
            (c[integ_col] - u).abs() < 1e-6,
            "at rest the share is the integral"
        );
        assert!(
            share_lo >= 0.0 && share_hi <= 1.0,
            "share left its limits: {share_lo}..{share_hi}"
        );
        // From cold the valve sits at its lower limit until the oil reaches the set point; the
        // proportional part then opens it, and the integral takes over: the overshoot is small.
        assert!(traj.switches[0] >= 1);
        // A sanity bound, not a tuned figure: 10 K is half the proportional band (1/gain).
        assert!(peak > SET_C && peak < SET_C + 10.0, "peak {peak}");
        assert!(bal.relative < 1e-9, "balance {}", bal.relative);
    }
}

#[test]
fn the_integral_stands_still_at_saturation_and_the_valve_recovers() {
    // Share at most 0.3 under the nominal load (0.5 needed): saturated at the upper limit for
    // 20 000 s; then the lighter load, under which the valve leaves the limit and the oil
    // returns to the set point.
    let (scene, inputs, q, gc) = pi_scene(0.0, 0.3);
    let light = steady_inputs(3000.0, LIGHT);
    let q_light = source(&scene, LIGHT);
    let (_, u_light) = analytic_with(q_light, gc);
    assert!(
        u_light > 0.02 && u_light < 0.28,
        "the light load needs a share within the limits: {u_light}"
    );
    let mut segs = uniform(inputs, 200, 100.0);
    segs.extend(uniform(light, 300, 100.0).into_iter().map(|s| Segment {
        t0: s.t0 + 20_000.0,
        t1: s.t1 + 20_000.0,
        inputs: light,
    }));
    let traj = run(&scene, &segs, Method::Ros3, 1e-10);
    let integ_col = scene.thermal().controls.len();
    let mut at_max = Vec::new();
    for ((c, y), t) in traj.controls.iter().zip(&traj.states).zip(&traj.times) {
        if (c[0] - 0.3).abs() < 1e-12 && *t <= 20_000.0 {
            at_max.push((*t, c[integ_col], y[0] - KELVIN_OFFSET));
        }
    }
    assert!(
        at_max.len() > 100,
        "the valve must saturate: {} rows at the limit",
        at_max.len()
    );
    // Back-calculation with the tracking time Ti: at the limit dI/dt = (0.3 − I)/Ti, so the
    // integral relaxes to the limit (it never winds up past it).
    let (t0, i0, _) = at_max[0];
    let worst = at_max
        .iter()
        .map(|(t, i, _)| {
            let expect = 0.3 + (i0 - 0.3) * (-(t - t0) / TI).exp();
            (i - expect).abs()
        })
        .fold(0.0, f64::max);
    let highest = traj
        .controls
        .iter()
        .map(|c| c[integ_col])
        .fold(f64::MIN, f64::max);
    let (_, i_end, hot) = *at_max.last().unwrap();
    let k20 = traj.times.iter().position(|t| *t == 20_000.0).unwrap();
    let ks = scene.control_row_index() + scene.thermal().control_rows();
    let (y20, end) = (&traj.states[k20], traj.states.last().unwrap());
    let (t_lo, t_hi) = (y20[ks + 1], y20[ks + 2]);
    println!(
        "saturated: {} rows at the upper limit from {t0:.1} s, integral {i0:.9} → {i_end:.12} \
         (worst vs 0.3 + (I0 − 0.3)·exp(−t/Ti): {worst:.2e}), highest integral {highest:.12}, oil \
         {hot:.6} °C (analytic at share 0.3: {:.6}), time at lower/upper limit {t_lo:.3}/{t_hi:.3} s by 20 000 s",
        at_max.len(),
        oil_at_share(q, gc, 0.3) - KELVIN_OFFSET
    );
    assert!(worst < 1e-6, "integral at the limit vs its relaxation: {worst}");
    assert!(
        highest <= 0.3 + 1e-9,
        "the integral winds up past the limit: {highest}"
    );
    assert!((hot - (oil_at_share(q, gc, 0.3) - KELVIN_OFFSET)).abs() < 1e-6);
    assert!(t_hi > 15_000.0 && t_lo + t_hi <= 20_000.0 + 1e-6);
    let share_end = traj.controls.last().unwrap()[0];
    println!(
        "after the load drop: oil {:.9} °C, share {share_end:.9} (analytic {u_light:.9}), switches {:?}",
        end[0] - KELVIN_OFFSET,
        traj.switches
    );
    assert!((end[0] - KELVIN_OFFSET - SET_C).abs() < 1e-6);
    assert!((share_end - u_light).abs() < 1e-6);
    // No chattering on the limits: the valve enters and leaves each a handful of times.
    assert!(traj.switches[0] <= 6, "switches {:?}", traj.switches);
    assert!(energy_balance(&scene, &traj).relative < 1e-9);
}

#[test]
fn jacobian_with_the_integral_column_matches_products_and_differences() {
    let (scene, inputs, _, gc) = pi_scene(0.0, 1.0);
    let mut work = scene.work(inputs);
    let mut y = scene.initial_state(None);
    y[0] = SET_C + 1.0 + KELVIN_OFFSET;
    y[1] = 45.0 + KELVIN_OFFSET;
    let row = scene.thermal().integral_row(0).unwrap();
    y[row] = 0.3;
    scene.initial_control_modes(&y, &mut work);
    assert_eq!(work.net.mode[0], 1, "the valve between its limits");
    let n = scene.n_states();
    let dense = common::jacobian::checked_dense_jacobian(&scene, &y, &mut work);
    // The integral's column: the oil loses GC·(T − Tk) per unit share.
    let expect = -gc * (y[0] - COOLANT_C - KELVIN_OFFSET) / C1;
    assert!((dense[row * n] - expect).abs() < 1e-9 * expect.abs());
    // Its row: dI/dt = gain/Ti·(T − set) between the limits.
    assert!((dense[row] - GAIN / TI).abs() < 1e-15);
}

/// The sensitivity integrator carries the node temperatures alone: a scene with a PI valve is
/// refused, naming the controller, rather than return a Jacobian without its integral.
#[test]
fn sensitivities_refuse_a_pi_valve() {
    use geartherm::solve::sensitivity::{integrate_sensitivities, SensitivityOptions};
    let (scene, inputs, _, _) = pi_scene(0.0, 1.0);
    let opts = SensitivityOptions {
        rtol: 1e-8,
        atol: 1e-8,
        max_steps: 1_000_000,
        initial: None,
    };
    let err = integrate_sensitivities(&scene, &[], &uniform(inputs, 4, 50.0), &opts).unwrap_err();
    assert!(
        err.message.contains("controller bypass is a PI valve"),
        "{}",
        err.message
    );
    assert!(err.message.contains("cannot fit through it"), "{}", err.message);
}
