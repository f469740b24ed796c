//! One feasibility check: whatever the loss scene (and so `losses`, `run`, `steady`, `map`)
//! refuses, the model check refuses first. Profile shifts from −0.5 to 2.5 on every gear of
//! every bundled model: the model loads exactly when its loss scene compiles and evaluates.

use std::path::Path;

use geartherm::model;
use geartherm::physics::oil::KELVIN_OFFSET;
use geartherm::scene::{LossScene, OperatingPoint};

/// Accepted by the model check?; accepted by the loss scene (compile, one evaluation)?; messages.
fn accept(text: &str, path: &Path) -> (bool, bool, String) {
    let gb = match model::from_str(text, path) {
        Ok(gb) => gb,
        Err(e) => {
            // refused by the check: the scene is not reached
            return (false, false, e.report());
        }
    };
    let scene = match LossScene::compile(&gb) {
        Ok(s) => s,
        Err(e) => return (true, false, e.to_string()),
    };
    let mut out = vec![0.0; scene.len()];
    for state in 0..gb.gear_states.len() {
        let op = OperatingPoint {
            state,
            input_speed: 2000.0 * std::f64::consts::PI / 30.0,
            input_torque: 100.0,
            oil: gb.oil.properties(80.0 + KELVIN_OFFSET),
        };
        scene.evaluate(&op, &mut out);
        if let Some(i) = out.iter().position(|w| !w.is_finite()) {
            return (
                true,
                false,
                format!("state {state}: item {} non-finite", scene.items[i].name),
            );
        }
    }
    (true, true, String::new())
}

#[test]
fn check_and_losses_agree_on_every_bundled_model_under_a_profile_shift_sweep() {
    let mut accepted = 0;
    let mut refused = 0;
    let mut disagree = Vec::new();
    for m in ["fzg_c", "pt6_spur_pair", "helical_stage", "at6_lepelletier"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("models/{m}.toml"));
        let text = std::fs::read_to_string(&path).unwrap();
        let doc: toml::Table = text.parse().unwrap();
        let n = doc["gears"].as_array().map_or(0, |g| g.len());
        for gi in 0..n {
            for k in 0..=12 {
                let x = -0.5 + 0.25 * k as f64;
                let mut d = doc.clone();
                let g = d["gears"].as_array_mut().unwrap()[gi].as_table_mut().unwrap();
                g.insert("profile_shift".into(), toml::Value::Float(x));
                let t = toml::to_string(&d).unwrap();
                let (chk, los, msg) = accept(&t, &path);
                if chk != los {
                    disagree.push(format!(
                        "{m} gears[{gi}] x = {x}: check {chk}, losses {los}: {msg}"
                    ));
                }
                if chk {
                    accepted += 1;
                } else {
                    refused += 1;
                }
            }
        }
    }
    assert!(disagree.is_empty(), "{}", disagree.join("\n"));
    // the sweep reaches both sides of the boundary
    assert!(
        accepted > 10 && refused > 10,
        "{accepted} accepted, {refused} refused"
    );
}
