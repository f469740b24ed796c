//! `geartherm calibrate` end to end: a bad trace exits 1 naming file, line and column and writes
//! nothing; a good one writes the five outputs in one transaction.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn calibrate(trace: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .arg("calibrate")
        .arg(root().join("models/helical_stage.toml"))
        .arg("--trace")
        .arg(trace)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("binary runs")
}

fn trace(rows: &[&str]) -> String {
    let mut s = String::from("time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:oil\n");
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s
}

const GOOD: [&str; 6] = [
    "0,3000,200,1,20,30",
    "600,3000,200,1,20,52",
    "1200,3000,200,1,20,68",
    "1800,1500,100,1,20,70",
    "2400,1500,100,1,20,66",
    "3000,1500,100,1,20,62",
];

#[test]
fn bad_traces_exit_1_and_write_nothing() {
    let d = tempfile::tempdir().unwrap();
    let fit = [
        "--fit",
        "thermal.links[\"oil-housing\"].h_w_per_m2k",
        "--refuse-missing",
    ];
    let cases: [(String, &[&str]); 5] = [
        (
            trace(&GOOD).replace("1200,3000,200,1,20,68", "1200,3000,200,1,20,nan"),
            &["line 4", "node:oil"],
        ),
        (trace(&GOOD).replace("600,3000", "0,3000"), &["line 3", "time"]),
        (
            trace(&GOOD).replace("node:oil", "node:gearbox"),
            &["node:gearbox", "no capacity node"],
        ),
        (
            trace(&GOOD).replace(",node:oil", ",node:oil,node:oil"),
            &["line 1", "twice"],
        ),
        (
            trace(&GOOD).replace("1800,1500,100,1,20,70", "1800,1500,100,1,,70"),
            &["line 5", "boundary:ambient", "empty", "refused"],
        ),
    ];
    for (k, (text, wanted)) in cases.iter().enumerate() {
        let t = d.path().join(format!("bad{k}.csv"));
        std::fs::write(&t, text).unwrap();
        let out = d.path().join(format!("out{k}"));
        let o = calibrate(&t, &out, &fit);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "case {k}: {err}");
        for w in wanted.iter() {
            assert!(err.contains(w), "case {k}: {err} lacks {w}");
        }
        assert!(!out.exists(), "case {k}: {} was written", out.display());
    }
}

#[test]
fn empty_cells_are_dropped_and_counted_and_gaps_cut_segments() {
    let d = tempfile::tempdir().unwrap();
    let fit = ["--fit", "thermal.links[\"oil-housing\"].h_w_per_m2k", "--json"];
    // Row 3 has an empty cell; a gap of 30 000 s starts a second segment.
    let mut rows: Vec<String> = GOOD.iter().map(|r| r.to_string()).collect();
    rows[2] = "1200,3000,200,1,20,".into();
    rows.extend(
        [
            "33000,1500,100,1,20,50",
            "33600,1500,100,1,20,49",
            "34200,1500,100,1,20,48",
        ]
        .map(String::from),
    );
    let refs: Vec<&str> = rows.iter().map(String::as_str).collect();
    let t = d.path().join("scada.csv");
    std::fs::write(&t, trace(&refs)).unwrap();
    let o = calibrate(&t, &d.path().join("none"), &fit);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("2 segments") && err.contains("--segment"), "{err}");
    let mut args = fit.to_vec();
    args.extend(["--segment", "0"]);
    let o = calibrate(&t, &d.path().join("seg0"), &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(s["rows"], 5, "{s}");
    let warnings = s["warnings"].to_string();
    assert!(
        warnings.contains("1 row(s) with empty cells dropped") && warnings.contains("node:oil 1"),
        "{warnings}"
    );
    assert!(warnings.contains("segment 0 of 2"), "{warnings}");
    let listed = Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args(["trace", "--json"])
        .arg(&t)
        .output()
        .unwrap();
    let l: serde_json::Value = serde_json::from_slice(&listed.stdout).unwrap();
    assert_eq!(
        (l["rows"].as_u64(), l["dropped_rows"].as_u64()),
        (Some(9), Some(1))
    );
    assert_eq!(l["segments"][1]["start_s"], 33000.0);
    assert_eq!(l["segments"][1]["first_line"], 8);
}

#[test]
fn a_calibration_writes_its_outputs() {
    let d = tempfile::tempdir().unwrap();
    let t = d.path().join("trace.csv");
    std::fs::write(&t, trace(&GOOD)).unwrap();
    let out = d.path().join("cal");
    let o = calibrate(
        &t,
        &out,
        &[
            "--fit",
            "thermal.links[\"oil-housing\"].h_w_per_m2k",
            "--holdout",
            "2000:4000",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "calibration.json",
        "fit.csv",
        "calibrated.toml",
        "cycle.csv",
        "calibration.png",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("calibration.json")).unwrap()).unwrap();
    assert_eq!(json["channels"][0]["holdout"]["rows"], 2);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("95 % interval")
            && stdout.contains("oil-housing")
            && stdout.contains("acf lag 1, 2, 6"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(out.join("fit.csv")).unwrap();
    assert!(csv.starts_with("time_s,holdout,oil_measured_c,oil_simulated_c,oil_residual_k,oil_band95_k\n"));
    let cal = std::fs::read_to_string(out.join("calibrated.toml")).unwrap();
    assert!(
        cal.contains("# [calibration]") && cal.contains("# covariance = [["),
        "{cal}"
    );
    // An unknown residual model: exit 1 naming the option, nothing written.
    let bad = d.path().join("bad");
    let o = calibrate(&t, &bad, &["--residuals", "ar2"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(1) && err.contains("--residuals"), "{err}");
    assert!(!bad.exists());
}
