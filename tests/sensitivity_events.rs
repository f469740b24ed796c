//! Sensitivities across controller switches (the saltation condition, `solve::sensitivity`):
//! a two-node network with a thermostatic heater on the oil and a fan on the casing's link to
//! the air, both cycling; the sensitivities of the switch temperatures (`on_c`, `off_c` of each),
//! the heater's power and the switched link's conductance against central differences of whole
//! integrations with error control at a tight tolerance: within 1e-5 relative (to the largest
//! sensitivity of that parameter over the trace).

use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::Scene;
use geartherm::solve::sensitivity::{integrate_sensitivities, Direction};
use geartherm::solve::transient::Segment;

mod common;
use common::controls::{
    against_central_differences, casing_air, heater, oil_casing, sensitivity_options as opts, uniform, C1,
    START_C,
};
use common::{fzg_frozen, steady_inputs};

/// The parameters: heater on, off, power; fan on, off; the switched link's conductance.
const NOMINAL: [f64; 6] = [40.0, 45.0, 1500.0, 38.0, 36.0, 10.0];
const NAMES: [&str; 6] = [
    "heater on_c",
    "heater off_c",
    "heater_w",
    "fan on_c",
    "fan off_c",
    "casing-air conductance (switched)",
];

/// Oil 2000 J/K – casing 5000 J/K (20 W/K) – air at 20 °C (`p[5]` W/K through a fan link that
/// keeps 0.3 of it while off); a heater of `p[2]` W on the oil on at `p[0]`, off at `p[1]`; the
/// fan on when the casing reaches `p[3]`, off at `p[4]`.
fn network(p: &[f64; 6]) -> String {
    oil_casing(START_C, C1)
        + &casing_air(p[5], Some("casing-air"))
        + &heater(p[0], p[1], p[2], "")
        + &format!(
            r#"[[thermal.controls]]
name = "fan"
kind = "two_point"
sensor = "casing"
on_c = {:e}
off_c = {:e}
link = "casing-air"
off_fraction = 0.3
"#,
            p[3], p[4]
        )
}

fn scene(p: &[f64; 6]) -> Scene {
    fzg_frozen(&network(p), 40.0)
}

fn segments(n: usize, dt: f64) -> Vec<Segment> {
    uniform(steady_inputs(0.0, 0.0), n, dt)
}

/// A parameter's step: 1e-3 K on a temperature, 1e-3 relative otherwise.
fn step(k: usize) -> f64 {
    if matches!(k, 2 | 5) {
        1e-3 * NOMINAL[k]
    } else {
        1e-3
    }
}

fn perturbed(k: usize, s: f64) -> [f64; 6] {
    let mut p = NOMINAL;
    p[k] += s * step(k);
    p
}

#[test]
fn sensitivities_across_switches_match_central_differences() {
    let segs = segments(30, 50.0);
    let nominal = scene(&NOMINAL);
    let pairs: Vec<(Scene, Scene)> = (0..6)
        .map(|k| (scene(&perturbed(k, 1.0)), scene(&perturbed(k, -1.0))))
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
    // Both controllers must cycle in the window.
    let plain = integrate_sensitivities(&nominal, &[], &segs, &opts(1e-11)).unwrap();
    let (oil, casing): (Vec<f64>, Vec<f64>) = plain
        .temps
        .iter()
        .map(|r| (r[0] - KELVIN_OFFSET, r[1] - KELVIN_OFFSET))
        .unzip();
    let rises = |v: &[f64]| v.windows(2).filter(|w| w[1] > w[0]).count();
    let falls = |v: &[f64]| v.windows(2).filter(|w| w[1] < w[0]).count();
    assert!(
        rises(&oil) > 3 && falls(&oil) > 3,
        "the heater must cycle: {oil:?}"
    );
    assert!(
        rises(&casing) > 3 && falls(&casing) > 3,
        "the fan must cycle: {casing:?}"
    );
    let np = NOMINAL.len();
    for k in 0..np {
        let h = 1e-2 * step(k) * 10.0;
        let run = |s: f64| {
            let mut p = NOMINAL;
            p[k] += s * h;
            integrate_sensitivities(&scene(&p), &[], &segs, &opts(1e-12)).unwrap()
        };
        let (a, b) = (run(1.0), run(-1.0));
        let rel = against_central_differences(&tangent, (&a, &b), h, (k, np), NAMES[k]);
        assert!(rel <= 1e-5, "{}: relative error {rel:.3e} > 1e-5", NAMES[k]);
    }
}
