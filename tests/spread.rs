//! Model-form spread: every applicable model choice of each loss item's source in `losses`,
//! `steady` and `run --spread` (docs/uq.md, "Model-form spread").

use std::path::{Path, PathBuf};
use std::process::Command;

use geartherm::job::run::{run, RunOptions};
use geartherm::job::Model;
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `geartherm losses …` with `args`: (JSON on stdout, stderr).
fn losses(args: &[&str]) -> (Value, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .arg("losses")
        .args(args)
        .arg("--json")
        .current_dir(root())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    (
        serde_json::from_slice(&out.stdout).unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const MM82: &str = "models/mm82_wind_gearbox.toml";
const MM82_POINT: [&str; 8] = [
    "--gear",
    "run",
    "--speed-rpm",
    "1680",
    "--torque-nm",
    "5000",
    "--oil-temp-c",
    "50",
];

/// The value of item `source:name` in a `losses --json` document.
fn item_w(doc: &Value, source: &str, name: &str) -> f64 {
    doc["items"]
        .as_array()
        .unwrap()
        .iter()
        .find(|it| it["source"] == source && it["name"] == name)
        .unwrap_or_else(|| panic!("no item {source}:{name}"))["w"]
        .as_f64()
        .unwrap()
}

#[test]
fn mm82_wheel_models_disagree_and_are_warned() {
    let mut args = vec![MM82];
    args.extend(MM82_POINT);
    let (doc, stderr) = losses(&args);
    let wheel = doc["spread"]["items"]
        .as_array()
        .unwrap()
        .iter()
        .find(|it| it["source"] == "churning" && it["name"] == "wheel1")
        .expect("wheel1 in the spread block")
        .clone();
    let value = |model: &str| {
        wheel["models"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["model"] == model)
            .unwrap_or_else(|| panic!("no {model}"))["w"]
            .as_f64()
            .unwrap()
    };
    // Each alternative is what the model gives with that choice written in the file.
    for model in ["seetharaman", "stavytskyi"] {
        let set = format!("losses.churning=\"{model}\"");
        let mut a = vec![MM82, "--set", &set];
        a.extend(MM82_POINT);
        let (alone, _) = losses(&a);
        let w = item_w(&alone, "churning", "wheel1");
        assert_eq!(
            value(model),
            w,
            "{model}: spread value vs the model chosen in the file"
        );
    }
    let default = item_w(&doc, "churning", "wheel1");
    assert_eq!(value("changenet"), default);
    assert_eq!(wheel["default_w"].as_f64().unwrap(), default);
    let (lo, hi) = (wheel["min_w"].as_f64().unwrap(), wheel["max_w"].as_f64().unwrap());
    let factor = wheel["factor"].as_f64().unwrap();
    assert!(factor > 3.0, "factor {factor}");
    assert!((factor - hi / lo).abs() <= 1e-12 * factor);
    let three = [value("changenet"), value("seetharaman"), value("stavytskyi")];
    assert_eq!(lo, three.iter().cloned().fold(f64::INFINITY, f64::min));
    assert_eq!(hi, three.iter().cloned().fold(0.0, f64::max));
    let line = stderr
        .lines()
        .find(|l| l.contains("item churning:wheel1: applicable models disagree by"))
        .unwrap_or_else(|| panic!("no spread warning for the wheel in:\n{stderr}"));
    assert!(line.contains(&format!("{factor:.1}×")), "{line}");
    assert!(
        doc["spread"]["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().starts_with("item churning:wheel1:")),
        "{}",
        doc["spread"]["warnings"]
    );
    eprintln!(
        "MM82 wheel1 at 50 °C, 1680 rpm, 5000 N m: Changenet–Velex {:.1} W, Seetharaman–Kahraman {:.1} W, \
         Stavytskyi {:.1} W, factor {factor:.1}",
        three[0], three[1], three[2]
    );
}

#[test]
fn a_disagreement_of_a_few_watts_is_listed_but_not_warned() {
    // MM82 at 1500 rpm, 100 N m, 60 °C: the total loss is about 15 kW; the windage of pinion1
    // is 0.07 W or 2 W by its two models (factor ≈ 28), wheel1's churning 108 W … 12.9 kW.
    let (doc, stderr) = losses(&[
        MM82,
        "--gear",
        "run",
        "--speed-rpm",
        "1500",
        "--torque-nm",
        "100",
        "--oil-temp-c",
        "60",
    ]);
    let total: f64 = doc["items"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["w"].as_f64().unwrap())
        .sum();
    let items = doc["spread"]["items"].as_array().unwrap();
    let find = |source: &str, name: &str| {
        items
            .iter()
            .find(|it| it["source"] == source && it["name"] == name)
            .unwrap_or_else(|| panic!("no {source}:{name}"))
            .clone()
    };
    let pinion = find("windage", "pinion1");
    let (lo, hi) = (
        pinion["min_w"].as_f64().unwrap(),
        pinion["max_w"].as_f64().unwrap(),
    );
    assert!(pinion["factor"].as_f64().unwrap() > 3.0, "{pinion}");
    assert!(hi - lo < 0.01 * total, "{lo} … {hi} W of {total} W");
    let warned = |what: &str| {
        doc["spread"]["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().starts_with(what))
    };
    assert!(!warned("item windage:pinion1:"), "{}", doc["spread"]["warnings"]);
    assert!(!stderr.contains("item windage:pinion1:"), "{stderr}");
    let wheel = find("churning", "wheel1");
    assert!(wheel["max_w"].as_f64().unwrap() - wheel["min_w"].as_f64().unwrap() >= 0.01 * total);
    assert!(warned("item churning:wheel1:"), "{}", doc["spread"]["warnings"]);
}

/// The first gear state of a bundled model.
fn first_state(file: &str) -> String {
    let m = Model::load(&root().join(file), &[]).unwrap();
    m.gearbox.gear_states[0].name.clone()
}

#[test]
fn every_bundled_model_has_a_finite_spread_block() {
    for file in [
        "models/at6_lepelletier.toml",
        "models/ev_reducer.toml",
        "models/fzg_c.toml",
        "models/helical_stage.toml",
        "models/mm82_wind_gearbox.toml",
        "models/pt6_spur_pair.toml",
    ] {
        let gear = first_state(file);
        let (doc, _) = losses(&[
            file,
            "--gear",
            &gear,
            "--speed-rpm",
            "1500",
            "--torque-nm",
            "100",
            "--oil-temp-c",
            "60",
        ]);
        let items = doc["spread"]["items"]
            .as_array()
            .unwrap_or_else(|| panic!("{file}: no spread block"));
        assert_eq!(items.len(), doc["items"].as_array().unwrap().len(), "{file}");
        let mut alternatives = 0;
        for it in items {
            let what = format!("{file}: {}:{}", it["source"], it["name"]);
            let (d, lo, hi) = (
                it["default_w"].as_f64().unwrap(),
                it["min_w"].as_f64().unwrap(),
                it["max_w"].as_f64().unwrap(),
            );
            assert!(d.is_finite() && lo.is_finite() && hi.is_finite(), "{what}");
            assert!(lo <= d && d <= hi, "{what}: {lo} {d} {hi}");
            assert_eq!(
                d,
                item_w(&doc, it["source"].as_str().unwrap(), it["name"].as_str().unwrap())
            );
            let models = it["models"].as_array().unwrap();
            assert!(models.iter().any(|m| m["default"] == true), "{what}");
            for m in models {
                match m["w"].as_f64() {
                    Some(w) => assert!(w.is_finite() && lo <= w && w <= hi, "{what}: {m}"),
                    None => assert!(m["not_applicable"].is_string(), "{what}: {m}"),
                }
            }
            alternatives += models.iter().filter(|m| m["w"].is_number()).count() - 1;
        }
        assert!(alternatives > 0, "{file}: no item has an alternative model");
    }
}

#[test]
fn steady_has_the_block_at_the_equilibrium() {
    let out = Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args([
            "steady",
            "models/fzg_c.toml",
            "--gear",
            "1",
            "--speed-rpm",
            "1500",
            "--torque-nm",
            "200",
            "--json",
        ])
        .current_dir(root())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    let items = doc["spread"]["items"].as_array().unwrap();
    for it in items {
        let key = format!(
            "{}:{}",
            it["source"].as_str().unwrap(),
            it["name"].as_str().unwrap()
        );
        assert_eq!(it["default_w"], doc["losses_w"][&key], "{key}");
    }
    assert!(items
        .iter()
        .any(|it| it["source"] == "sliding" && it["models"].as_array().unwrap().len() > 1));
}

/// The summary of an AT6 WLTC run as JSON, without the wall time.
fn summary(spread: bool) -> Value {
    let m = Model::load(Path::new(&root().join("models/at6_lepelletier.toml")), &[]).unwrap();
    let o = RunOptions {
        cycle: "wltc".into(),
        summary_only: true,
        spread,
        ..RunOptions::default()
    };
    let r = run(&m, &o, &mut |_, _| {}).unwrap();
    let mut v = serde_json::to_value(&r.summary).unwrap();
    v.as_object_mut().unwrap().remove("wall_time_s");
    v
}

#[test]
fn run_spread_brackets_the_default_energy_and_leaves_the_run_unchanged() {
    let plain = summary(false);
    let mut with = summary(true);
    let spread = with
        .as_object_mut()
        .unwrap()
        .remove("spread")
        .expect("a spread block");
    assert!(plain.get("spread").is_none());
    assert_eq!(
        plain, with,
        "the run with --spread differs beyond its spread block"
    );
    let sources = spread.as_array().unwrap();
    let names: Vec<&str> = sources.iter().map(|s| s["source"].as_str().unwrap()).collect();
    for s in ["churning", "sliding", "bearing"] {
        assert!(names.contains(&s), "{s} missing from {names:?}");
    }
    for s in sources {
        let src = s["source"].as_str().unwrap();
        let (d, lo, hi) = (
            s["default_j"].as_f64().unwrap(),
            s["min_j"].as_f64().unwrap(),
            s["max_j"].as_f64().unwrap(),
        );
        assert!(lo <= d && d <= hi, "{src}: {lo} {d} {hi}");
        // The trapezoid along the output rows against the run's own quadrature.
        let run_j = plain["energy_lost_j"][src].as_f64().unwrap();
        assert!(
            (d - run_j).abs() <= 0.01 * run_j.abs().max(1.0),
            "{src}: {d} vs the run's {run_j}"
        );
        for m in s["models"].as_array().unwrap() {
            if let Some(j) = m["j"].as_f64() {
                assert!(j.is_finite() && lo <= j && j <= hi, "{src}: {m}");
            }
        }
        assert!(hi > lo, "{src}: the applicable models give the same energy");
    }
}
