//! Forward sensitivities (the tangent linear of ROS3, `solve::sensitivity`) against central
//! differences of whole integrations, on every bundled model: within 1e-5 relative (to the
//! largest sensitivity of that parameter over the trajectory) for a conductance-type link
//! coefficient, a node mass, the oil level and an initial temperature.
//!
//! The whole integrations at θ ± h replay the step sizes of the nominal one
//! (`integrate_fixed`): the discrete solution as a smooth function of θ, whose derivative the
//! tangent linear is. A second check runs both at a tight tolerance with error control, where
//! the discrete and the exact derivative agree.

use std::path::Path;

use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use geartherm::job::Model;
use geartherm::solve::sensitivity::{
    integrate_fixed, integrate_sensitivities, Direction, SensitivityOptions,
};

const MODELS: [&str; 6] = [
    "models/at6_lepelletier.toml",
    "models/ev_reducer.toml",
    "models/fzg_c.toml",
    "models/helical_stage.toml",
    "models/mm82_wind_gearbox.toml",
    "models/pt6_spur_pair.toml",
];

/// A rig trace of `rows` samples every `dt` s in the first gear state with a speed and torque
/// step, every node "measured" (values unused here), every boundary at 25 °C.
fn trace_for(m: &Model, rows: usize, dt: f64) -> String {
    let gear = &m.gearbox.gear_states[0].name;
    let net = m.gearbox.thermal.as_ref().unwrap();
    let mut s = String::from("time_s,input_speed_rpm,input_torque_nm,gear");
    for n in &net.nodes {
        s.push_str(&format!(",node:{}", n.name));
    }
    for b in &net.boundaries {
        s.push_str(&format!(",boundary:{}", b.name));
    }
    s.push('\n');
    for k in 0..rows {
        let (w, t) = if k < rows / 2 {
            (1500.0, 80.0)
        } else {
            (2500.0, 150.0)
        };
        s.push_str(&format!("{},{w},{t},{gear}", k as f64 * dt));
        for _ in &net.nodes {
            s.push_str(",40");
        }
        // Boundaries held below the nodes: a two-way cooler never switches to heating (a kink
        // of the right-hand side that no derivative of a fixed step sequence follows).
        for _ in &net.boundaries {
            s.push_str(",25");
        }
        s.push('\n');
    }
    s
}

/// Parameters of each kind the model has.
fn fit_specs(text: &str) -> Vec<String> {
    let doc: toml::Table = text.parse().unwrap();
    let th = doc["thermal"].as_table().unwrap();
    let mut out = Vec::new();
    let links = th["links"].as_array().unwrap();
    for key in ["h_w_per_m2k", "conductance_w_per_k"] {
        if let Some(l) = links.iter().find(|l| l.get(key).is_some()) {
            out.push(format!(
                "thermal.links[\"{}\"].{key}",
                l["name"].as_str().unwrap()
            ));
        }
    }
    let nodes = th["nodes"].as_array().unwrap();
    let n = nodes.iter().find(|n| n.get("mass_kg").is_some()).unwrap();
    out.push(format!(
        "thermal.nodes[\"{}\"].mass_kg",
        n["name"].as_str().unwrap()
    ));
    out.push("lubrication.oil_level_mm".into());
    let oil = th["oil_node"].as_str().unwrap();
    out.push(format!("thermal.nodes[\"{oil}\"].initial_temp_c"));
    out
}

/// max |S − CD| / max |S| over every row and node, for each parameter.
fn check_model(path: &str, rows: usize, dt: f64, rtol: f64, replay: bool) -> Vec<(String, f64, f64)> {
    let text = std::fs::read_to_string(path).unwrap();
    let m = Model::from_text(&text, Path::new(path), &[]).unwrap();
    let trace = Trace::parse(&trace_for(&m, rows, dt), "synthetic").unwrap();
    let o = CalibrateOptions {
        fit: fit_specs(&text),
        rtol,
        ..CalibrateOptions::default()
    };
    let p = calibrate::prepare(&m, &text, &trace, &o).unwrap();
    let pr = &p.problem;
    let theta: Vec<f64> = pr.params.iter().map(|q| q.theta(q.start)).collect();
    let scene = pr.scene_at(&theta).unwrap();
    let pairs: Vec<_> = pr
        .params
        .iter()
        .enumerate()
        .map(|(k, q)| {
            let mut th = theta.clone();
            th[k] += q.delta();
            let plus = pr.scene_at(&th).unwrap();
            th[k] -= 2.0 * q.delta();
            (plus, pr.scene_at(&th).unwrap(), q.delta())
        })
        .collect();
    let dirs: Vec<Direction<'_>> = pairs
        .iter()
        .map(|(a, b, d)| Direction {
            plus: a,
            minus: b,
            delta: *d,
        })
        .collect();
    let opts = SensitivityOptions {
        rtol,
        atol: 1e-9,
        max_steps: 10_000_000,
        initial: None,
    };
    let nominal = integrate_sensitivities(&scene, &dirs, &pr.segs, &opts).unwrap();
    let np = pr.params.len();
    let n = scene.nodes();
    let mut out = Vec::new();
    for (k, q) in pr.params.iter().enumerate() {
        // Replayed: twice the tangent's own difference step (a loss law with a kink, such as a
        // regime bridge, stays out of reach); adaptive: large enough that the step choices'
        // rounding-level changes stay below the difference.
        let h = if replay {
            2.0 * q.delta()
        } else if q.log {
            1e-2
        } else {
            1e-1
        };
        let run = |s: f64| {
            let mut th = theta.clone();
            th[k] += s * h;
            let sc = pr.scene_at(&th).unwrap();
            if replay {
                integrate_fixed(&sc, &[], &pr.segs, &opts, &nominal.steps).unwrap()
            } else {
                integrate_sensitivities(&sc, &[], &pr.segs, &opts).unwrap()
            }
        };
        let (a, b) = (run(1.0), run(-1.0));
        let (mut err, mut scale) = (0.0_f64, 0.0_f64);
        for r in 0..nominal.times.len() {
            for i in 0..n {
                let cd = (a.temps[r][i] - b.temps[r][i]) / (2.0 * h);
                let s = nominal.sens_at(r, i, k, np);
                err = err.max((s - cd).abs());
                scale = scale.max(s.abs());
            }
        }
        out.push((q.name(), err / scale.max(1e-300), scale));
    }
    out
}

#[test]
fn sensitivities_match_central_differences_of_replayed_integrations() {
    for path in MODELS {
        for (name, rel, scale) in check_model(path, 31, 60.0, 1e-6, true) {
            println!("{path} {name}: max |S| {scale:.4e} K, relative error {rel:.2e}");
            assert!(scale > 0.0, "{path} {name}: no sensitivity at all");
            assert!(rel <= 1e-5, "{path} {name}: relative error {rel:.3e} > 1e-5");
        }
    }
}

#[test]
fn sensitivities_converge_to_the_exact_derivative() {
    // Error control on both sides at a tight tolerance: the adaptive integrations at θ ± h
    // choose their own steps, and still agree with the tangent.
    for path in MODELS {
        for (name, rel, _) in check_model(path, 11, 60.0, 1e-9, false) {
            println!("{path} {name}: relative error {rel:.2e} (adaptive, rtol 1e-9)");
            assert!(rel <= 1e-3, "{path} {name}: relative error {rel:.3e}");
        }
    }
}
