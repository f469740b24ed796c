//! CLI contract for `check` and `info` on the bundled models and on the invalid models of
//! `tests/invalid/` (each names the key its message must contain in a `# expect:` line).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(args: &[&str], cwd: &Path) -> Output {
    bin().args(args).current_dir(cwd).output().expect("binary runs")
}

fn example_models() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("models"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension().is_some_and(|e| e == "toml")
                && !p.ends_with("oils.toml")
                && !p.ends_with("bearings.toml")
        })
        .collect();
    v.sort();
    v
}

#[test]
fn every_example_model_passes_check() {
    let models = example_models();
    assert!(models.len() >= 4, "{models:?}");
    for m in models {
        let out = run(&["check", m.to_str().unwrap()], &root());
        assert!(
            out.status.success(),
            "{}: {}",
            m.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn every_invalid_model_fails_with_its_key_named_and_writes_nothing() {
    let dir = root().join("tests/invalid");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(
        files.len() >= 20,
        "need at least 20 invalid models, have {}",
        files.len()
    );
    let scratch = tempfile::tempdir().unwrap();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let expect = text
            .lines()
            .find_map(|l| l.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{} has no '# expect:' line", f.display()))
            .trim()
            .to_string();
        for cmd in ["check", "info"] {
            let out = run(&[cmd, f.to_str().unwrap()], scratch.path());
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{} ({cmd}): {err}", f.display());
            assert!(
                err.contains(&expect),
                "{} ({cmd}): expected '{expect}' in:\n{err}",
                f.display()
            );
            let name = f.file_name().unwrap().to_string_lossy().to_string();
            assert!(err.contains(&name), "message names the file: {err}");
            assert!(out.stdout.is_empty(), "nothing on stdout for an invalid model");
        }
    }
    assert_eq!(
        std::fs::read_dir(scratch.path()).unwrap().count(),
        0,
        "nothing written"
    );
}

#[test]
fn all_problems_are_reported_at_once() {
    let f = root().join("tests/invalid/many_problems.toml");
    let out = run(&["check", f.to_str().unwrap()], &root());
    let err = String::from_utf8_lossy(&out.stderr);
    for key in ["gears[0].teeth", "gears[1].face_width_mm", "oil.catalogue"] {
        assert!(err.contains(key), "missing {key} in:\n{err}");
    }
}

#[test]
fn syntax_error_reports_line_and_column() {
    let f = root().join("tests/invalid/syntax_error.toml");
    let out = run(&["check", f.to_str().unwrap()], &root());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line 21") && err.contains("column"), "{err}");
}

fn info_json(model: &str) -> serde_json::Value {
    let out = run(&["info", model, "--json"], &root());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON document")
}

#[test]
fn at6_lepelletier_ratios_match_the_published_values() {
    let v = info_json("models/at6_lepelletier.toml");
    let states = v["gear_states"].as_array().unwrap();
    let want = [
        ("1", 4.171),
        ("2", 2.340),
        ("3", 1.521),
        ("4", 1.143),
        ("5", 0.867),
        ("6", 0.691),
        ("R", -3.403),
    ];
    assert_eq!(states.len(), want.len());
    for ((name, ratio), s) in want.iter().zip(states) {
        assert_eq!(s["name"], *name);
        let r = s["ratio"].as_f64().unwrap();
        // The published values are given to 3 decimals (4 significant digits above 1): the
        // computed ratio must round to them.
        assert!((r - ratio).abs() <= 5e-4, "gear {name}: {r} vs {ratio}");
        assert_eq!(format!("{r:.3}"), format!("{ratio:.3}"), "gear {name}");
        eprintln!("gear {name}: ratio {r:.6} (published {ratio})");
    }
    // Exactly (108/71)(85/31) in first.
    let r1 = states[0]["ratio"].as_f64().unwrap();
    assert!((r1 - 108.0 / 71.0 * 85.0 / 31.0).abs() < 1e-10);
}

#[test]
fn info_json_has_the_contract_shape() {
    let v = info_json("models/fzg_c.toml");
    assert!(v["gear_states"][0]["ratio"].is_number());
    assert!(v["gear_states"][0]["member_speeds"].is_object());
    let mesh = &v["meshes"][0];
    assert!(mesh["name"].is_string());
    let eps = mesh["transverse_contact_ratio"].as_f64().unwrap();
    assert!((eps - 1.44).abs() <= 0.01, "FZG C eps_alpha = {eps}");
    for g in v["gears"].as_array().unwrap() {
        assert!(g["name"].is_string() && g["immersion_mm"].is_number());
    }
    // Oil at the shaft centres: each gear dips to its axis, immersion = tip radius.
    let gears = v["gears"].as_array().unwrap();
    let pin = gears.iter().find(|g| g["name"] == "pinion").unwrap();
    assert!((pin["immersion_mm"].as_f64().unwrap() - 82.46 / 2.0).abs() < 1e-9);
    // Ratio of a single external stage: negative (the output turns the other way), |i| = 24/16.
    let r = v["gear_states"][0]["ratio"].as_f64().unwrap();
    assert!((r + 1.5).abs() < 1e-12, "{r}");
}

#[test]
fn info_text_lists_states_meshes_and_gears() {
    let out = run(&["info", "models/at6_lepelletier.toml"], &root());
    assert!(out.status.success());
    let s = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "gear states",
        "meshes",
        "gears",
        "RAV:long_pinion/rav_ring",
        "4.1708",
    ] {
        assert!(s.contains(needle), "missing {needle} in\n{s}");
    }
}

#[test]
fn missing_model_file_is_an_io_error() {
    // README: exit 3 for I/O, a missing model file included.
    let out = run(&["check", "models/does_not_exist.toml"], &root());
    assert_eq!(out.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&out.stderr).contains("does_not_exist.toml"));
}
