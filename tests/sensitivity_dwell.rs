//! Sensitivities across the end of a minimum on time (`solve::sensitivity`, the saltation at a
//! time event): a thermostatic heater on the oil of a two-node network (on at 40 °C, off at
//! 45 °C, at least 30 s on) heats the oil past 45 °C within its minimum on time, so every
//! switch off happens when the dwell ends, the sensor already past its set point. The
//! sensitivities of both set points, the heater's power and the minimum on time against central
//! differences of whole integrations at a tight tolerance: within 1e-5 relative (to the largest
//! sensitivity of that parameter over the trace).

use geartherm::scene::Scene;
use geartherm::solve::sensitivity::{integrate_sensitivities, Direction};
use geartherm::solve::transient::{integrate, Method, Segment, TransientOptions};

mod common;
use common::controls::{
    against_central_differences, casing_air, heater, oil_casing, sensitivity_options as opts, uniform, C1,
    G2, START_C,
};
use common::{fzg_frozen, steady_inputs};

/// on_c, off_c, heater_w, min_on_s.
const NOMINAL: [f64; 4] = [40.0, 45.0, 1500.0, 30.0];
const NAMES: [&str; 4] = ["on_c", "off_c", "heater_w", "min_on_s"];

fn network(p: &[f64; 4]) -> String {
    let dwell = format!("min_on_s = {:e}\n", p[3]);
    oil_casing(START_C, C1) + &casing_air(G2, None) + &heater(p[0], p[1], p[2], &dwell)
}

fn scene(p: &[f64; 4]) -> Scene {
    fzg_frozen(&network(p), 40.0)
}

fn segments(n: usize, dt: f64) -> Vec<Segment> {
    uniform(steady_inputs(0.0, 0.0), n, dt)
}

/// A parameter's step: 1e-3 K on a temperature, 1e-3 relative otherwise.
fn step(k: usize) -> f64 {
    if k >= 2 {
        1e-3 * NOMINAL[k]
    } else {
        1e-3
    }
}

#[test]
fn sensitivities_across_dwell_ends_match_central_differences() {
    let segs = segments(30, 50.0);
    let nominal = scene(&NOMINAL);
    // Every switch off is the end of the minimum on time (30 s after the switch on).
    let o = TransientOptions {
        method: Method::Ros3,
        rtol: 1e-12,
        atol: 1e-12,
        ..TransientOptions::default()
    };
    let traj = integrate(&nominal, &segs, &o, &mut |_, _| {}).unwrap();
    let times: Vec<f64> = traj.events.iter().map(|e| e.0).collect();
    assert!(times.len() >= 6, "the heater must cycle: {times:?}");
    // From 30 °C the heater starts on with no minimum time running (the start is not a switch):
    // its first switch off is at 45 °C; every later one ends a dwell.
    let worst = times[1..]
        .chunks_exact(2)
        .map(|w| (w[1] - w[0] - NOMINAL[3]).abs())
        .fold(0.0, f64::max);
    println!(
        "{} switches; on → off spacing vs min_on_s: worst {worst:.2e} s",
        times.len()
    );
    assert!(worst < 1e-6, "the switches off must be the dwell ends: {times:?}");
    let pairs: Vec<(Scene, Scene)> = (0..4)
        .map(|k| {
            let (mut a, mut b) = (NOMINAL, NOMINAL);
            a[k] += step(k);
            b[k] -= step(k);
            (scene(&a), scene(&b))
        })
        .collect();
    let dirs: Vec<Direction<'_>> = pairs
        .iter()
        .enumerate()
        .map(|(k, (a, b))| Direction {
            plus: a,
            minus: b,
            delta: step(k),
        })
        .collect();
    let tangent = integrate_sensitivities(&nominal, &dirs, &segs, &opts(1e-11)).unwrap();
    let np = NOMINAL.len();
    for k in 0..np {
        // The reference's step: its truncation error grows as h² and the integration's noise
        // (rtol 1e-12 on whole runs whose step sequences differ) as 1/h. Measured relative
        // errors with h = (10, 3, 1, 0.1)·step: on_c 1.9e-5, 1.7e-6, 4.4e-7, 4.0e-6; off_c
        // 4.7e-7, 1.3e-6, 5.3e-6, 2.2e-5; heater_w 2.3e-1, 3.2e-4, 3.5e-5, –; min_on_s 2.7e-1,
        // 2.9e-4, 3.2e-5, – (quadratic: truncation). Each parameter takes its step from the
        // flat part: (1, 3, 0.1, 0.1)·step.
        let factor = [1.0, 3.0, 0.1, 0.1][k];
        let h = std::env::var("CD_H")
            .ok()
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(factor)
            * step(k);
        let run = |s: f64| {
            let mut p = NOMINAL;
            p[k] += s * h;
            integrate_sensitivities(&scene(&p), &[], &segs, &opts(1e-12)).unwrap()
        };
        let (a, b) = (run(1.0), run(-1.0));
        let rel = against_central_differences(&tangent, (&a, &b), h, (k, np), NAMES[k]);
        if std::env::var("CD_H").is_err() {
            assert!(rel <= 1e-5, "{}: relative error {rel:.3e} > 1e-5", NAMES[k]);
        }
    }
}
