//! The two-node network of the controller tests (`controls*.rs`, `sensitivity_*.rs`): oil and
//! casing, the casing linked to the ambient air, the FZG C's losses at standstill with the oil
//! properties frozen as a constant source; its closed-form solution between switches; uniform
//! segments and the integrations the tests compare.

use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{Inputs, Scene};
use geartherm::solve::sensitivity::{SensitivityOptions, SensitivityTrajectory};
use geartherm::solve::transient::{energy_balance, integrate, Method, Segment, Trajectory, TransientOptions};

use super::{fzg_frozen, steady_inputs};

/// Heat capacity of the oil node, J/K.
pub const C1: f64 = 2000.0;
/// Heat capacity of the casing node, J/K.
pub const C2: f64 = 5000.0;
/// Conductance oil–casing, W/K.
pub const G1: f64 = 20.0;
/// Conductance casing–ambient, W/K.
pub const G2: f64 = 10.0;
/// The heater's power, W.
pub const POWER: f64 = 1500.0;
/// The ambient air, °C.
pub const AMBIENT_C: f64 = 20.0;
/// The initial temperature of both nodes, °C.
pub const START_C: f64 = 30.0;

/// `[thermal]` with the oil (`c_oil` J/K) and casing (C2) nodes starting at `initial_c` (°C), the
/// ambient boundary at AMBIENT_C and the oil–casing link (G1).
pub fn oil_casing(initial_c: f64, c_oil: f64) -> String {
    format!(
        r#"
[thermal]
oil_node = "oil"
initial_temp_c = {initial_c:e}
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = {c_oil:e}
[[thermal.nodes]]
name = "casing"
capacity_j_per_k = {C2:e}
[[thermal.boundaries]]
name = "ambient"
temp_c = {AMBIENT_C:e}
[[thermal.links]]
between = ["oil", "casing"]
conductance_w_per_k = {G1:e}
"#
    )
}

/// The casing–ambient link of `g` W/K, named `name` when given (a fan's link).
pub fn casing_air(g: f64, name: Option<&str>) -> String {
    let name = name.map_or(String::new(), |n| format!("name = \"{n}\"\n"));
    format!(
        r#"[[thermal.links]]
{name}between = ["casing", "ambient"]
conductance_w_per_k = {g:e}
"#
    )
}

/// A two-point heater of `power` W on the oil, on at `on_c`, off at `off_c` (°C), with the
/// lines `more` (minimum times).
pub fn heater(on_c: f64, off_c: f64, power: f64, more: &str) -> String {
    format!(
        r#"[[thermal.controls]]
name = "heater"
kind = "two_point"
sensor = "oil"
on_c = {on_c:e}
off_c = {off_c:e}
heater_w = {power:e}
{more}"#
    )
}

/// The scene of `thermal` at standstill with the oil properties frozen at 40 °C (the losses a
/// constant source), its inputs, and that source per node (W).
pub fn frozen_with_source(thermal: &str) -> (Scene, Inputs, [f64; 2]) {
    let scene = fzg_frozen(thermal, 40.0);
    let inputs = steady_inputs(0.0, 0.0);
    let mut w = scene.work(inputs);
    let y = scene.initial_state(None);
    scene.evaluate_losses(&y, &mut w);
    let mut src = [0.0; 2];
    for (q, dest) in w.q.iter().zip(&scene.thermal().heat) {
        for &(node, f) in dest {
            src[node] += f * q;
        }
    }
    (scene, inputs, src)
}

/// The exact solution of y' = A y + b of the network (C1, C2, G1, G2, ambient) with the source
/// `src` and a heater of `heater` W on the oil (A 2×2 with real distinct eigenvalues).
pub struct Linear {
    a: [[f64; 2]; 2],
    b: [f64; 2],
}

impl Linear {
    pub fn new(src: [f64; 2], heater: f64) -> Linear {
        let ta = AMBIENT_C + KELVIN_OFFSET;
        Linear {
            a: [[-G1 / C1, G1 / C1], [G1 / C2, -(G1 + G2) / C2]],
            b: [(src[0] + heater) / C1, (src[1] + G2 * ta) / C2],
        }
    }

    /// The state at time `t` from `y0`.
    pub fn at(&self, y0: [f64; 2], t: f64) -> [f64; 2] {
        let [[a, b], [c, d]] = self.a;
        let det = a * d - b * c;
        // Equilibrium y* = −A⁻¹ b.
        let ys = [
            -(d * self.b[0] - b * self.b[1]) / det,
            -(-c * self.b[0] + a * self.b[1]) / det,
        ];
        let tr = a + d;
        let disc = (tr * tr / 4.0 - det).sqrt();
        let (l1, l2) = (tr / 2.0 + disc, tr / 2.0 - disc);
        // exp(At) = (e1 (A − l2 I) − e2 (A − l1 I)) / (l1 − l2).
        let (e1, e2) = ((l1 * t).exp(), (l2 * t).exp());
        let m = |i: usize, j: usize| {
            let id = if i == j { 1.0 } else { 0.0 };
            (e1 * (self.a[i][j] - l2 * id) - e2 * (self.a[i][j] - l1 * id)) / (l1 - l2)
        };
        let z = [y0[0] - ys[0], y0[1] - ys[1]];
        [
            ys[0] + m(0, 0) * z[0] + m(0, 1) * z[1],
            ys[1] + m(1, 0) * z[0] + m(1, 1) * z[1],
        ]
    }

    /// First time in (0, horizon] at which the oil reaches `target` from the side it starts on
    /// (bisection on a bracket found by scanning in steps of `scan` s), if any.
    pub fn crossing(&self, y0: [f64; 2], target: f64, horizon: f64, scan: f64) -> Option<f64> {
        let f = |t: f64| self.at(y0, t)[0] - target;
        let s0 = f(0.0).signum();
        let mut lo = 0.0;
        while lo < horizon {
            let hi = lo + scan;
            if f(hi).signum() != s0 {
                let (mut a, mut b) = (lo, hi);
                for _ in 0..200 {
                    let m = 0.5 * (a + b);
                    if f(m).signum() == s0 {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                return Some(0.5 * (a + b));
            }
            lo = hi;
        }
        None
    }
}

/// `n` segments of `dt` s from 0 with `inputs`.
pub fn uniform(inputs: Inputs, n: usize, dt: f64) -> Vec<Segment> {
    (0..n)
        .map(|k| Segment {
            t0: k as f64 * dt,
            t1: (k + 1) as f64 * dt,
            inputs,
        })
        .collect()
}

/// An integration of `segs` with `method` at rtol = atol = `rtol`.
pub fn run(scene: &Scene, segs: &[Segment], method: Method, rtol: f64) -> Trajectory {
    let o = TransientOptions {
        method,
        rtol,
        atol: rtol,
        ..TransientOptions::default()
    };
    integrate(scene, segs, &o, &mut |_, _| {}).unwrap()
}

/// Sensitivity options at rtol = atol = `rtol`.
pub fn sensitivity_options(rtol: f64) -> SensitivityOptions {
    SensitivityOptions {
        rtol,
        atol: rtol,
        max_steps: 10_000_000,
        initial: None,
    }
}

/// Print a trajectory's switching comparison (switches, worst switching time and temperature
/// against the analytic ones, energy balance, steps), note a miss over 1e-6 s or 1e-6 K in
/// `bad`, and assert the energy balance within 1e-9.
pub fn switching_report(
    scene: &Scene,
    traj: &Trajectory,
    method: Method,
    switches: usize,
    (dt_worst, t_worst): (f64, f64),
    bad: &mut Vec<String>,
) {
    let eb = energy_balance(scene, traj);
    println!(
        "{method:?}: {} switches, worst switching time {dt_worst:.3e} s, worst temperature \
         {t_worst:.3e} K, energy balance {:.2e}, steps {}",
        switches, eb.relative, traj.stats.steps
    );
    if !(dt_worst < 1e-6 && t_worst < 1e-6) {
        bad.push(format!(
            "{method:?}: switching time off by {dt_worst:e} s, temperature by {t_worst:e} K"
        ));
    }
    assert!(eb.relative < 1e-9, "{method:?}: energy balance {:e}", eb.relative);
}

/// The sensitivities of parameter `k` (of `np`) in `tangent` against the central differences
/// of the integrations `a` (parameter + `h`) and `b` (− `h`) over both nodes and every row:
/// the largest |S| and the largest difference relative to it, printed with `name`; asserts
/// that there is a sensitivity.
pub fn against_central_differences(
    tangent: &SensitivityTrajectory,
    (a, b): (&SensitivityTrajectory, &SensitivityTrajectory),
    h: f64,
    (k, np): (usize, usize),
    name: &str,
) -> f64 {
    let (mut err, mut scale) = (0.0_f64, 0.0_f64);
    for r in 0..tangent.times.len() {
        for i in 0..2 {
            let cd = (a.temps[r][i] - b.temps[r][i]) / (2.0 * h);
            let s = tangent.sens_at(r, i, k, np);
            err = err.max((s - cd).abs());
            scale = scale.max(s.abs());
        }
    }
    let rel = err / scale;
    println!("{name}: max |S| {scale:.4e} K per unit, relative error {rel:.2e}");
    assert!(scale > 0.0, "{name}: no sensitivity");
    rel
}
