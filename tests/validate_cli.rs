//! `geartherm validate` on a reduced set of the bundled reference cases (the full set runs in
//! docs/validation.md): a peer case and a trend case, every applicable model choice.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn copy_case(name: &str, to: &Path) {
    let src = root().join("validation").join(name);
    let dst = to.join(name);
    std::fs::create_dir_all(&dst).unwrap();
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, dst.join(p.file_name().unwrap())).unwrap();
    }
}

#[test]
fn validate_runs_every_model_choice_and_writes_table_and_plots() {
    let d = tempfile::tempdir().unwrap();
    let cases = d.path().join("cases");
    copy_case("gearpie_c14_sliding", &cases);
    copy_case("seed000_table2_trend", &cases);
    let out = d.path().join("out");
    let r = validate(&cases, &out, &["--json"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    // 6 GEARpie points × 8 sliding choices + 2 trends × 3 churning models, less Changenet's
    // 40 °C trend (excluded: it cannot fail there)
    assert_eq!(rows.len(), 6 * 8 + 2 * 3 - 1);
    for f in [
        "validation.csv",
        "validation_summary.csv",
        "validation.md",
        "parity_sliding.png",
        "parity_churning.png",
        "error_vs_speed_sliding.png",
        "error_vs_speed_churning.png",
        "parity_elements.png",
        "range_distance_efficiency.png",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let csv = std::fs::read_to_string(out.join("validation.csv")).unwrap();
    assert!(csv.starts_with("case,point,model,quantity,speed_rpm,predicted,reference,kind,relative_error"));
    let summary = v["summary"].as_array().unwrap();
    let get = |case: &str, model: &str| {
        summary
            .iter()
            .find(|s| s["case"] == case && s["model"] == model)
            .unwrap_or_else(|| panic!("{case} {model}"))
            .clone()
    };
    // The default sliding model (Schlenk, uniform) is within 5 % of GEARpie at K5/K7/K9 and two
    // speeds; ISO TC60 is far above it (the finding that moved the default).
    assert!(
        get("gearpie_c14_sliding", "schlenk")["max_abs_error"]
            .as_f64()
            .unwrap()
            < 0.05
    );
    assert!(get("gearpie_c14_sliding", "iso_tc60")["bias"].as_f64().unwrap() > 0.4);
    // Changenet–Velex's low-Re_c law gives ω^1.59: inside seed 000's 1.4–1.7 at 40 °C.
    let cv = rows
        .iter()
        .find(|r| r["case"] == "seed000_table2_trend" && r["model"] == "changenet")
        .unwrap();
    assert_eq!(cv["relative_error"].as_f64().unwrap(), 0.0, "{cv}");
}

#[test]
fn validate_on_a_directory_without_cases_fails_and_writes_nothing() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    let r = validate(d.path(), &out, &[]);
    assert_eq!(r.status.code(), Some(1));
    assert!(!out.exists());
}

/// `geartherm validate CASES --out OUT [extra...]`.
fn validate(cases: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args([
            "validate",
            cases.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .args(extra)
        .output()
        .unwrap()
}

fn run_validate(cases: &Path, out: &Path) -> serde_json::Value {
    let r = validate(cases, out, &["--json"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    serde_json::from_slice(&r.stdout).unwrap()
}

/// A handbook case on the bundled FZG model (absolute model path, so it runs from a temporary
/// directory): gear-pair efficiency at K9, 2175 rpm, against a range.
fn write_handbook_case(cases: &Path, low: f64, high: f64) {
    let d = cases.join("handbook_fzg");
    std::fs::create_dir_all(&d).unwrap();
    let model = root().join("models").join("fzg_c.toml");
    std::fs::write(
        d.join("case.toml"),
        format!(
            "kind = \"handbook\"\nsource = \"test\"\nmodel = {:?}\nquantity = \"efficiency\"\n\
             sources = [\"churning\", \"pocketing\", \"sliding\"]\nmodels = [\"default\"]\n\
             [[range]]\npoint = \"K9\"\ngear = \"1\"\nspeed_rpm = 2175.0\ntorque_nm = 215.513\n\
             oil_temp_c = 90.0\nlow = {low}\nhigh = {high}\n",
            model.to_str().unwrap()
        ),
    )
    .unwrap();
}

#[test]
fn validate_covers_bearing_seal_converter_pump_and_handbook_ranges() {
    let d = tempfile::tempdir().unwrap();
    let cases = d.path().join("cases");
    for c in [
        "fernandes_nj406_1000n_bearing",
        "iso14179_seal_standard",
        "advisor_jdm_converter",
        "pump_datasheet_standard",
    ] {
        copy_case(c, &cases);
    }
    write_handbook_case(&cases, 0.990, 0.998);
    let v = run_validate(&cases, &d.path().join("out"));
    let rows = v["rows"].as_array().unwrap();
    let of = |case: &str| -> Vec<&serde_json::Value> { rows.iter().filter(|r| r["case"] == case).collect() };
    // Three kinds of reference in one run.
    let mut kinds: Vec<&str> = rows.iter().map(|r| r["kind"].as_str().unwrap()).collect();
    kinds.sort_unstable();
    kinds.dedup();
    assert_eq!(kinds, ["handbook", "peer", "self_consistency"]);
    // Bearing: the Palmgren and SKF choices (NJ 406 has an SKF row), one row per peer point each.
    let b = of("fernandes_nj406_1000n_bearing");
    assert_eq!(b.len(), 12);
    assert!(b.iter().all(|r| r["quantity"] == "bearing"));
    for m in ["palmgren", "skf"] {
        assert_eq!(b.iter().filter(|r| r["model"] == m).count(), 6, "{m}");
    }
    // Seal law, converter table and pump formula are reproduced (a wrong item, speed or source
    // would miss by far more).
    for c in [
        "iso14179_seal_standard",
        "advisor_jdm_converter",
        "pump_datasheet_standard",
    ] {
        for r in of(c) {
            assert!(r["relative_error"].as_f64().unwrap().abs() < 1e-6, "{r}");
        }
    }
    // Efficiency of the FZG pair at K9: a fraction just below 1 (about 1 % of the input power
    // lost in the mesh), its error the distance to the spur-pair range.
    let h = of("handbook_fzg");
    assert_eq!(h.len(), 1);
    let eta = h[0]["predicted"].as_f64().unwrap();
    assert!(eta > 0.98 && eta < 1.0, "{eta}");
    let inside = eta.clamp(0.990, 0.998);
    let e = h[0]["relative_error"].as_f64().unwrap();
    assert!((e - (eta - inside) / inside).abs() < 1e-12, "{e}");
}

#[test]
fn a_handbook_range_the_value_misses_gives_the_distance_to_it() {
    let d = tempfile::tempdir().unwrap();
    let cases = d.path().join("cases");
    // A range above any gear-pair efficiency: the error is (η − 0.9999)/0.9999 < 0.
    write_handbook_case(&cases, 0.9999, 1.0);
    let v = run_validate(&cases, &d.path().join("out"));
    let r = &v["rows"][0];
    let eta = r["predicted"].as_f64().unwrap();
    assert_eq!(r["reference"].as_f64().unwrap(), 0.9999);
    let e = r["relative_error"].as_f64().unwrap();
    assert!((e - (eta - 0.9999) / 0.9999).abs() < 1e-12 && e < 0.0, "{e}");
}

#[test]
fn a_range_with_low_above_high_is_rejected_naming_the_point() {
    let d = tempfile::tempdir().unwrap();
    let cases = d.path().join("cases");
    write_handbook_case(&cases, 0.998, 0.990);
    let out = d.path().join("out");
    let r = validate(&cases, &out, &[]);
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("range K9") && err.contains("case.toml"), "{err}");
    assert!(!out.exists());
}
