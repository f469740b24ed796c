//! Two-point controllers with minimum on and off times (`min_on_s`, `min_off_s`): a two-node
//! network with a thermostatic heater whose solution between switches is analytic (a 2×2 linear
//! system with a constant source). A switch requested before the minimum time ends happens when
//! it ends (a time event); the switching instants of ROS3, BDF and ESDIRK34 within 1e-6 s of the analytic
//! ones, the recorded temperatures within 1e-6 K, the energy balance closed. Also a controller
//! with equal set points, accepted with a minimum time.

use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{Inputs, Scene};
use geartherm::solve::transient::Method;

mod common;
use common::controls::{
    casing_air, frozen_with_source, heater, oil_casing, run, switching_report, uniform, Linear, C1, G2,
    POWER, START_C,
};

/// The analytic solution's scan for a crossing, s.
const SCAN: f64 = 0.25;

/// The heater's law: set points (°C) and minimum times (s).
#[derive(Clone, Copy)]
struct Law {
    on_c: f64,
    off_c: f64,
    min_on: f64,
    min_off: f64,
}

/// Oil (C1) – casing (C2) – ambient, a heater of POWER W on the oil.
fn network(l: Law) -> String {
    let times = format!("min_on_s = {:e}\nmin_off_s = {:e}\n", l.min_on, l.min_off);
    oil_casing(START_C, C1) + &casing_air(G2, None) + &heater(l.on_c, l.off_c, POWER, &times)
}

/// The scene at standstill with the oil properties frozen (the losses a constant source) and
/// that source per node.
fn scene(l: Law) -> (Scene, Inputs, [f64; 2]) {
    frozen_with_source(&network(l))
}

/// The analytic switching instants (and which ended a minimum time with a switch already due),
/// and the state at every multiple of `dt` up to `t_end`.
struct Exact {
    switches: Vec<f64>,
    bound: usize,
    rows: Vec<[f64; 2]>,
}

fn analytic(l: Law, src: [f64; 2], t_end: f64, dt: f64) -> Exact {
    let sys = [Linear::new(src, 0.0), Linear::new(src, POWER)];
    let k = KELVIN_OFFSET;
    let mut y = [START_C + k, START_C + k];
    let mut heating = START_C <= l.on_c;
    let (mut t, mut last) = (0.0, f64::NEG_INFINITY);
    let mut out = Exact {
        switches: Vec::new(),
        bound: 0,
        rows: vec![y],
    };
    let mut next_row = dt;
    while t < t_end {
        let s = &sys[usize::from(heating)];
        let target = if heating { l.off_c } else { l.on_c } + k;
        let dwell_end = last + if heating { l.min_on } else { l.min_off };
        // Within the minimum time: on to its end; a switch is due there when the oil lies
        // beyond the target.
        let (ts, by_dwell) = if dwell_end > t {
            let ye = s.at(y, dwell_end - t);
            let due = if heating { ye[0] >= target } else { ye[0] <= target };
            if due {
                (Some(dwell_end), true)
            } else {
                let c = s.crossing(ye, target, t_end - dwell_end + dt, SCAN);
                (c.map(|c| dwell_end + c), false)
            }
        } else {
            (s.crossing(y, target, t_end - t + dt, SCAN).map(|c| t + c), false)
        };
        while next_row <= t_end + 1e-9 && ts.map_or(true, |ts| next_row <= ts) {
            out.rows.push(s.at(y, next_row - t));
            next_row += dt;
        }
        let Some(ts) = ts.filter(|ts| *ts < t_end) else {
            break;
        };
        y = s.at(y, ts - t);
        if !by_dwell {
            y[0] = target;
        }
        out.bound += usize::from(by_dwell);
        t = ts;
        last = ts;
        out.switches.push(ts);
        heating = !heating;
    }
    out
}

/// Every method's switching instants and rows against the analytic ones.
fn check(l: Law, t_end: f64, dt: f64) {
    let (scene, inputs, src) = scene(l);
    let exact = analytic(l, src, t_end, dt);
    println!(
        "analytic: {} switches, {} at the end of a minimum time; first {:?}",
        exact.switches.len(),
        exact.bound,
        &exact.switches[..exact.switches.len().min(6)]
    );
    assert!(
        exact.switches.len() >= 6,
        "the network must cycle: {:?}",
        exact.switches
    );
    assert!(exact.bound >= 3, "the minimum time must bind: {}", exact.bound);
    let segs = uniform(inputs, (t_end / dt) as usize, dt);
    let mut bad = Vec::new();
    for (method, rtol) in [
        (Method::Ros3, 1e-12),
        (Method::Bdf, 1e-13),
        (Method::Esdirk34, 1e-14),
    ] {
        let traj = run(&scene, &segs, method, rtol);
        let times: Vec<f64> = traj.events.iter().map(|e| e.0).collect();
        assert_eq!(
            times.len(),
            exact.switches.len(),
            "{method:?}: {times:?} vs {:?}",
            exact.switches
        );
        let dt_worst = times
            .iter()
            .zip(&exact.switches)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let t_worst = traj
            .states
            .iter()
            .zip(&exact.rows)
            .map(|(y, e)| (y[0] - e[0]).abs().max((y[1] - e[1]).abs()))
            .fold(0.0, f64::max);
        switching_report(&scene, &traj, method, times.len(), (dt_worst, t_worst), &mut bad);
        assert_eq!(traj.switches, vec![exact.switches.len()]);
    }
    assert!(bad.is_empty(), "{bad:?}");
}

/// Hysteresis 40–45 °C with minimum times longer than the free half-periods: the heater stays
/// on past 45 °C and off below 40 °C until its minimum time ends.
#[test]
fn minimum_times_that_bind_match_the_analytic_switches() {
    check(
        Law {
            on_c: 40.0,
            off_c: 45.0,
            min_on: 400.0,
            min_off: 350.0,
        },
        5000.0,
        50.0,
    );
}

/// Equal set points (42 °C) with minimum times: accepted, and the switches are the minimum
/// times apart or the crossing after them.
#[test]
fn equal_set_points_with_minimum_times_match_the_analytic_switches() {
    check(
        Law {
            on_c: 42.0,
            off_c: 42.0,
            min_on: 120.0,
            min_off: 90.0,
        },
        4000.0,
        50.0,
    );
}

/// The sensitivities carry the switching instants across the end of a minimum time (the jump
/// at the dwell's end, tests/sensitivity_dwell.rs checks it against central differences): a
/// scene with one integrates, the trace and its sensitivities finite.
#[test]
fn sensitivities_run_with_a_minimum_time() {
    use geartherm::solve::sensitivity::{integrate_sensitivities, SensitivityOptions};
    let l = Law {
        on_c: 40.0,
        off_c: 45.0,
        min_on: 400.0,
        min_off: 350.0,
    };
    let (scene, inputs, _) = scene(l);
    let opts = SensitivityOptions {
        rtol: 1e-8,
        atol: 1e-8,
        max_steps: 1_000_000,
        initial: None,
    };
    let tr = integrate_sensitivities(&scene, &[], &uniform(inputs, 40, 50.0), &opts).unwrap();
    assert_eq!(tr.times.len(), 41);
    assert!(tr.temps.iter().flatten().all(|v| v.is_finite()));
}
