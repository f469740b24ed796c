//! Steady state: equals a long transient at the same constant point (every example model);
//! Newton converges from ambient over a 10 × 10 grid of each example's range; a model whose oil
//! cannot reach equilibrium gets a named error.

use geartherm::model;
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{Inputs, Scene};
use geartherm::solve::equilibrium::equilibrium;
use geartherm::solve::steady::SteadyOptions;
use geartherm::solve::transient::{integrate, Method, Segment, TransientOptions};

/// (model, gear, max input speed rpm, max input torque N·m): each example's operating range (the
/// helical stage: up to seed 003's test point, 2000 rpm and 201 N·m; beyond it the oil of this
/// small, uncooled box passes 200 °C).
const CASES: [(&str, &str, f64, f64); 4] = [
    ("models/at6_lepelletier.toml", "3", 4000.0, 300.0),
    ("models/fzg_c.toml", "1", 3000.0, 300.0),
    ("models/helical_stage.toml", "1", 2000.0, 201.0),
    ("models/pt6_spur_pair.toml", "1", 4000.0, 100.0),
];

fn scene(path: &str) -> Scene {
    Scene::compile(&model::load(std::path::Path::new(path)).unwrap()).unwrap()
}

fn inputs(rpm: f64, torque: f64) -> Inputs {
    Inputs {
        state: 0,
        input_speed: rpm * std::f64::consts::PI / 30.0,
        input_torque: torque,
        vehicle_speed: 15.0,
    }
}

#[test]
fn steady_state_equals_a_long_transient() {
    for (path, gear, wmax, tmax) in CASES {
        let sc = scene(path);
        let gb = model::load(std::path::Path::new(path)).unwrap();
        let state = gb.state_index(gear).unwrap();
        let inp = Inputs {
            state,
            ..inputs(0.6 * wmax, 0.6 * tmax)
        };
        let eq = equilibrium(&sc, inp, None, &SteadyOptions::default()).unwrap();
        // Transient from the equilibrium's neighbourhood, long enough for the slowest mode to die
        // out (the time constants are ≤ a few hours; 60 h with a 1 h segment).
        let segs: Vec<Segment> = (0..60)
            .map(|k| Segment {
                t0: k as f64 * 3600.0,
                t1: (k + 1) as f64 * 3600.0,
                inputs: inp,
            })
            .collect();
        let o = TransientOptions {
            method: Method::Bdf,
            rtol: 1e-12,
            atol: 1e-12,
            ..TransientOptions::default()
        };
        let traj = integrate(&sc, &segs, &o, &mut |_, _| {}).unwrap();
        let last = traj.states.last().unwrap();
        // The transient starts at the model's initial temperatures, far from the equilibrium, so
        // agreement is not the start value echoed back.
        let start_gap = (traj.states[0][sc.thermal().oil] - eq.solution.temperatures[sc.thermal().oil]).abs();
        assert!(
            start_gap > 1.0,
            "{path}: transient starts only {start_gap} K away"
        );
        let worst = eq
            .solution
            .temperatures
            .iter()
            .zip(last)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "{path}: oil {:.4} °C steady (transient starts {start_gap:.1} K away), |steady − transient(60 h)| max {worst:.2e} K, {} Newton iterations",
            eq.solution.temperatures[sc.thermal().oil] - KELVIN_OFFSET,
            eq.solution.iterations
        );
        assert!(worst < 1e-6, "{path}: {worst}");
    }
}

#[test]
fn newton_converges_from_ambient_on_a_10_by_10_grid() {
    for (path, gear, wmax, tmax) in CASES {
        // Without the AT6's torque converter: at low turbine speed and high torque the open
        // converter slips kilowatts into the oil (a stalled converter has no equilibrium below
        // 200 °C), which is physics, not a Newton failure; the grid tests the solver.
        let mut gb = model::load(std::path::Path::new(path)).unwrap();
        gb.launch = None;
        let sc = Scene::compile(&gb).unwrap();
        let state = gb.state_index(gear).unwrap();
        let (mut iters, mut ptc, mut worst_res) = (0, 0, 0.0f64);
        for i in 0..10 {
            for j in 0..10 {
                let rpm = wmax * (i as f64 + 1.0) / 10.0;
                let tq = tmax * j as f64 / 9.0;
                let inp = Inputs {
                    state,
                    ..inputs(rpm, tq)
                };
                let eq = equilibrium(&sc, inp, None, &SteadyOptions::default())
                    .unwrap_or_else(|e| panic!("{path} {rpm} rpm {tq} N·m: {e}"));
                iters += eq.solution.iterations;
                ptc += eq.solution.ptc_iterations;
                worst_res = worst_res.max(eq.solution.residual_w);
                let oil = eq.solution.temperatures[sc.thermal().oil] - KELVIN_OFFSET;
                assert!(oil > 20.0 && oil < 200.0, "{path}: oil {oil}");
            }
        }
        println!(
            "{path}: 100 points from ambient, {:.1} Newton + {:.1} PTC iterations on average, worst residual {worst_res:.1e} W",
            iters as f64 / 100.0,
            ptc as f64 / 100.0
        );
    }
}

#[test]
fn no_equilibrium_is_a_named_error() {
    // FZG gears with a tiny path to ambient and no cooling coil: at full load the oil would pass
    // 200 °C.
    let text = std::fs::read_to_string("models/fzg_c.toml").unwrap();
    let text = text
        .replace(
            "h_w_per_m2k = 10.0            # natural convection",
            "h_w_per_m2k = 0.05 # ",
        )
        .replace(
            "emissivity = 0.85             # painted steel",
            "emissivity = 0.001",
        )
        .replace("capacity_rate_w_per_k = 60.0", "capacity_rate_w_per_k = 0.0");
    let gb = model::from_str(&text, std::path::Path::new("weak.toml")).unwrap();
    let sc = Scene::compile(&gb).unwrap();
    let e = equilibrium(&sc, inputs(3000.0, 300.0), None, &SteadyOptions::default()).unwrap_err();
    let msg = e.to_string();
    println!("{msg}");
    assert!(
        matches!(
            e,
            geartherm::solve::steady::SteadyError::NoEquilibriumInRange { .. }
        ),
        "{msg}"
    );
}
