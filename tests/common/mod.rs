//! Helpers shared by the solver tests: scenes built from the FZG C gears with a test network, and
//! input segments.
#![allow(dead_code)]

pub mod controls;
pub mod jacobian;

use geartherm::model;
use geartherm::physics::units::c_to_k;
use geartherm::scene::{Inputs, Needs, Scene};
use geartherm::solve::transient::Segment;

/// The FZG C gear data without its thermal network and vehicle, plus `thermal`.
pub fn fzg_with(thermal: &str) -> Scene {
    let text = std::fs::read_to_string("models/fzg_c.toml").unwrap();
    let cut = text.find("# ------").unwrap();
    let full = format!("{}\n{thermal}", &text[..cut]);
    let gb = model::from_str(&full, std::path::Path::new("test.toml")).unwrap();
    Scene::compile(&gb).unwrap()
}

/// [`fzg_with`] compiled with the oil properties frozen at `oil_c` (°C).
pub fn fzg_frozen(thermal: &str, oil_c: f64) -> Scene {
    let text = std::fs::read_to_string("models/fzg_c.toml").unwrap();
    let cut = text.find("# ------").unwrap();
    let full = format!("{}\n{thermal}", &text[..cut]);
    let gb = model::from_str(&full, std::path::Path::new("test.toml")).unwrap();
    let needs = Needs {
        frozen_oil_temp_k: Some(c_to_k(oil_c)),
        ..Needs::default()
    };
    Scene::compile_for(&gb, &needs).unwrap()
}

/// A scene from a model file.
pub fn scene_of(path: &str) -> (model::Gearbox, Scene) {
    let gb = model::load(std::path::Path::new(path)).unwrap();
    let scene = Scene::compile(&gb).unwrap();
    (gb, scene)
}

/// Constant inputs in gear state 0.
pub fn steady_inputs(speed_rpm: f64, torque: f64) -> Inputs {
    Inputs {
        state: 0,
        input_speed: speed_rpm * std::f64::consts::PI / 30.0,
        input_torque: torque,
        vehicle_speed: 0.0,
    }
}

/// Oil node plus a small "film" node holding both gears' bodies (capacity `cap` J/K, conductance
/// `g` W/K to the oil), the oil linked to ambient by 4 W/K: a stiff two-node network.
pub fn film_network(cap: f64, g: f64) -> String {
    format!(
        r#"
[thermal]
oil_node = "oil"
[[thermal.nodes]]
name = "oil"
capacity_j_per_k = 2000.0
[[thermal.nodes]]
name = "film"
capacity_j_per_k = {cap:e}
gears = ["pinion", "wheel"]
[[thermal.boundaries]]
name = "ambient"
temp_c = 23.0
[[thermal.links]]
between = ["film", "oil"]
conductance_w_per_k = {g:e}
[[thermal.links]]
between = ["oil", "ambient"]
conductance_w_per_k = 4.0
"#
    )
}

/// 1 s segments whose speed (500–3000 rpm), torque (20–320 N·m) and vehicle speed jump every
/// second in a fixed pseudo-random pattern; `state_of(k)` gives the gear state of segment k.
pub fn jumpy(n: usize, state_of: impl Fn(usize) -> usize) -> Vec<Segment> {
    (0..n)
        .map(|k| {
            let x = ((k * 7919) % 101) as f64 / 100.0;
            Segment {
                t0: k as f64,
                t1: k as f64 + 1.0,
                inputs: Inputs {
                    state: state_of(k),
                    input_speed: (500.0 + 2500.0 * x) * std::f64::consts::PI / 30.0,
                    input_torque: 20.0 + 300.0 * (1.0 - x),
                    vehicle_speed: 20.0 * x,
                },
            }
        })
        .collect()
}
