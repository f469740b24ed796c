//! Controllers that switch (`[[thermal.controls]]`): a two-node network with a thermostatic
//! heater, whose solution between switches is analytic (a 2×2 linear system with a constant
//! source), against ROS3 and diffsol: every switching instant within 1e-6 s of the analytic one,
//! every recorded temperature within 1e-6 K; the energy balance closed across the switches; a
//! stress run with more than 10 000 switches.

use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{Inputs, Scene};
use geartherm::solve::transient::{energy_balance, Method};

mod common;
use common::controls::{
    casing_air, frozen_with_source, heater, oil_casing, run, switching_report, uniform, Linear, C1, G2,
    POWER, START_C,
};
use common::{fzg_frozen, steady_inputs};

const ON_C: f64 = 40.0;
const OFF_C: f64 = 45.0;

/// Oil (`c1`) – casing (C2) – ambient, conductances G1 and G2, a heater of `power` W on the oil
/// switching on when the oil falls to `on_c` and off when it reaches `off_c`.
fn heater_network(on_c: f64, off_c: f64, power: f64, c1: f64) -> String {
    oil_casing(START_C, c1) + &casing_air(G2, None) + &heater(on_c, off_c, power, "")
}

/// The scene at standstill with the oil properties frozen: the losses are a constant source.
fn scene() -> (Scene, Inputs, [f64; 2]) {
    frozen_with_source(&heater_network(ON_C, OFF_C, POWER, C1))
}

/// The analytic switching instants and the state at every multiple of `dt` up to `t_end`.
fn analytic(src: [f64; 2], t_end: f64, dt: f64) -> (Vec<f64>, Vec<[f64; 2]>) {
    let on = Linear::new(src, POWER);
    let off = Linear::new(src, 0.0);
    let k = KELVIN_OFFSET;
    let mut y = [START_C + k, START_C + k];
    let mut heating = START_C <= ON_C;
    let (mut t, mut switches) = (0.0, Vec::new());
    let mut rows = vec![y];
    let mut next_row = dt;
    while t < t_end {
        let sys = if heating { &on } else { &off };
        let target = if heating { OFF_C } else { ON_C } + k;
        let ts = sys.crossing(y, target, t_end - t + dt, 0.5).map(|s| t + s);
        while next_row <= t_end + 1e-9 && ts.map_or(true, |ts| next_row <= ts) {
            rows.push(sys.at(y, next_row - t));
            next_row += dt;
        }
        let Some(ts) = ts.filter(|ts| *ts < t_end) else {
            break;
        };
        y = sys.at(y, ts - t);
        y[0] = target;
        t = ts;
        switches.push(ts);
        heating = !heating;
    }
    (switches, rows)
}

#[test]
fn switching_instants_and_temperatures_match_the_analytic_solution() {
    let (scene, inputs, src) = scene();
    let (t_end, dt) = (4000.0, 50.0);
    let (switches, rows) = analytic(src, t_end, dt);
    assert!(switches.len() >= 8, "the test network must cycle: {switches:?}");
    let segs = uniform(inputs, (t_end / dt) as usize, dt);
    let mut bad = Vec::new();
    // Tolerances at which each method's own error is below the 1e-6 s / 1e-6 K asked (the
    // switching time is off by the temperature error over the rate, 0.1 K/s while cooling).
    for (method, rtol) in [
        (Method::Ros3, 1e-12),
        (Method::Bdf, 1e-13),
        (Method::Esdirk34, 1e-14),
    ] {
        let traj = run(&scene, &segs, method, rtol);
        let times: Vec<f64> = traj.events.iter().map(|e| e.0).collect();
        assert_eq!(
            times.len(),
            switches.len(),
            "{method:?}: {times:?} vs {switches:?}"
        );
        let dt_worst = times
            .iter()
            .zip(&switches)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let mut t_worst: f64 = 0.0;
        for (k, (y, exact)) in traj.states.iter().zip(&rows).enumerate() {
            t_worst = t_worst.max((y[0] - exact[0]).abs()).max((y[1] - exact[1]).abs());
            if std::env::var("DEBUG_ROWS").is_ok() {
                println!("{k} {:e} {:e}", y[0] - exact[0], y[1] - exact[1]);
            }
        }
        if std::env::var("DEBUG_ROWS").is_ok() {
            for (a, b) in times.iter().zip(&switches).take(10) {
                println!("switch {a} {b} {:e}", a - b);
            }
        }
        switching_report(&scene, &traj, method, times.len(), (dt_worst, t_worst), &mut bad);
        assert_eq!(traj.switches, vec![switches.len()]);
    }
    assert!(bad.is_empty(), "{bad:?}");
}

/// The controller's rows: the heat it moved equals the heater's power times its time on, and
/// the time on equals the sum of the analytic on-intervals.
#[test]
fn the_heater_rows_hold_its_energy_and_time_on() {
    let (scene, inputs, src) = scene();
    let (t_end, dt) = (4000.0, 50.0);
    let (switches, _) = analytic(src, t_end, dt);
    let segs = uniform(inputs, (t_end / dt) as usize, dt);
    let traj = run(&scene, &segs, Method::Ros3, 1e-10);
    let r = scene.control_row_index();
    let last = traj.states.last().unwrap();
    // On from 0 (the start lies below on_c) to the first switch, then every other interval.
    let mut edges = vec![0.0];
    edges.extend(&switches);
    if edges.len() % 2 == 1 {
        edges.push(t_end);
    }
    let on: f64 = edges.chunks(2).map(|p| p[1] - p[0]).sum();
    assert!((last[r + 1] - on).abs() < 1e-6, "time on {} vs {on}", last[r + 1]);
    assert!(
        (last[r] - POWER * on).abs() < 1e-6 * POWER,
        "energy {} vs {}",
        last[r],
        POWER * on
    );
    // The recorded state column: 1 while on.
    let first = traj.controls.first().unwrap();
    assert_eq!(first, &[1.0]);
}

/// A small oil capacity and a narrow band: more than 10 000 switches in an hour, without the
/// step size collapsing (the run ends within its step budget), energy balance within 1e-9.
#[test]
fn ten_thousand_switches_keep_the_energy_balance() {
    let scene = fzg_frozen(&heater_network(40.0, 40.5, 1500.0, 50.0), 40.0);
    let segs = uniform(steady_inputs(0.0, 0.0), 60, 60.0);
    for method in [Method::Ros3, Method::Bdf] {
        let traj = run(&scene, &segs, method, 1e-6);
        let eb = energy_balance(&scene, &traj);
        let events = traj.events.len();
        println!(
            "{method:?}: {events} switches, {} steps, {} rejected, energy balance {:.2e}, {:.3} s",
            traj.stats.steps, traj.stats.rejected, eb.relative, traj.wall_time_s
        );
        assert!(events >= 10_000, "{method:?}: only {events} switches");
        // No step-size collapse: a bounded number of attempts per switch (measured: ROS3 1.5,
        // BDF 29, which restarts at order 1 at every switch).
        let per = (traj.stats.steps + traj.stats.rejected) as f64 / events as f64;
        let bound = if method == Method::Ros3 { 3.0 } else { 40.0 };
        assert!(per < bound, "{method:?}: {per} steps per switch");
        assert!(
            eb.relative <= 1e-9,
            "{method:?}: energy balance {:e}",
            eb.relative
        );
        // The oil stays inside the band (tolerance: the solver's).
        for y in traj.states.iter().skip(2) {
            let t = y[0] - KELVIN_OFFSET;
            assert!((39.99..=40.51).contains(&t), "{method:?}: oil at {t} °C");
        }
    }
}

/// Steady state with a switching heater: no mode has an equilibrium (on, the oil would settle
/// above 45 °C; off, below 40 °C), so the steady job reports the limit cycle: its period against
/// the analytic one (the switching instants of the exact solution once they repeat), the oil's
/// band between the set points.
#[test]
fn steady_state_reports_the_limit_cycle() {
    use geartherm::solve::equilibrium::equilibrium;
    use geartherm::solve::steady::SteadyOptions;
    let (scene, inputs, src) = scene();
    let eq = equilibrium(&scene, inputs, None, &SteadyOptions::default()).unwrap();
    let c = eq.limit_cycle.expect("a limit cycle");
    let (switches, _) = analytic(src, 30_000.0, 1000.0);
    let m = switches.len();
    let exact = switches[m - 1] - switches[m - 3];
    let k = KELVIN_OFFSET;
    println!(
        "period {} s (analytic {exact} s), oil mean {:.4} °C, band {:.6}–{:.6} °C",
        c.period_s,
        c.mean_k[0] - k,
        c.min_k[0] - k,
        c.max_k[0] - k
    );
    assert!(
        (c.period_s - exact).abs() < 1e-5,
        "period {} vs {exact}",
        c.period_s
    );
    assert!(
        (c.min_k[0] - (ON_C + k)).abs() < 1e-4,
        "oil min {}",
        c.min_k[0] - k
    );
    assert!(
        (c.max_k[0] - (OFF_C + k)).abs() < 1e-4,
        "oil max {}",
        c.max_k[0] - k
    );
    assert!(c.mean_k[0] > ON_C + k && c.mean_k[0] < OFF_C + k);
    assert_eq!(eq.solution.temperatures, c.mean_k);
}

/// A heater whose set points lie below the temperature the network settles at without it: the
/// equilibrium with the heater off, no cycle.
#[test]
fn steady_state_with_a_consistent_mode_is_an_equilibrium() {
    use geartherm::solve::equilibrium::equilibrium;
    use geartherm::solve::steady::SteadyOptions;
    let scene = fzg_frozen(&heater_network(5.0, 10.0, POWER, C1), 40.0);
    let inputs = steady_inputs(0.0, 0.0);
    let eq = equilibrium(&scene, inputs, None, &SteadyOptions::default()).unwrap();
    assert!(eq.limit_cycle.is_none());
    // Off: no source but the (standstill) losses; the oil above the heater's off point.
    assert!(eq.solution.temperatures[0] > 10.0 + KELVIN_OFFSET);
    assert!(eq.solution.method.contains("newton"));
}

/// A fan that never switches on: its link runs at `off_fraction` of its conductance, which
/// moves heat, but its time on (and so its duty cycle) stays 0.
#[test]
fn a_fan_that_stays_off_has_no_time_on() {
    let text = oil_casing(START_C, C1)
        + &casing_air(G2, Some("casing-air"))
        + &heater(ON_C, OFF_C, POWER, "")
        + r#"
[[thermal.controls]]
name = "fan"
kind = "two_point"
sensor = "casing"
on_c = 150.0
off_c = 140.0
link = "casing-air"
off_fraction = 0.4
"#;
    let scene = fzg_frozen(&text, 40.0);
    let segs = uniform(steady_inputs(0.0, 0.0), 40, 50.0);
    let traj = run(&scene, &segs, Method::Ros3, 1e-8);
    let fan = scene.control_row_index() + geartherm::scene::controls::ROWS_PER_CONTROL;
    let last = traj.states.last().unwrap();
    assert_eq!(last[fan + 1], 0.0, "time on of a fan that never switched on");
    assert!(
        last[fan] > 0.0,
        "the link at its off share still moves heat: {}",
        last[fan]
    );
}
