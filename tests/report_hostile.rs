//! Crafted result directories from the hostile campaign (family `report`): a grid value of 1e308
//! (an infinite heat-map axis, on which plotters' tick search never ends), n rows of n distinct
//! speeds and torques (an n² grid), a time column that does not increase. Each is invalid input
//! (exit 1), the directory left byte for byte.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

const HEADER: &str =
    "speed_rpm,torque_nm,efficiency,total_loss_w,churning_w,pocketing_w,sliding_w,bearing_w,\
seal_w,clutch_drag_w,pump_w,converter_w,oil_temp_c,iterations,converged";

fn row(speed: f64, torque: &str) -> String {
    format!("{speed},{torque},0.9,50,10,2,5,30,3,0,0,0,60,10,true")
}

fn map_dir(d: &Path, rows: &[String]) {
    std::fs::create_dir_all(d).unwrap();
    std::fs::write(d.join("map.csv"), format!("{HEADER}\n{}\n", rows.join("\n"))).unwrap();
    std::fs::write(d.join("map.json"), r#"{"model": "m", "gear": "1"}"#).unwrap();
}

fn report_refuses(d: &Path, what: &str) {
    let before: Vec<(String, Vec<u8>)> = files(d);
    let start = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .arg("report")
        .arg(d)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "took {:?}",
        start.elapsed()
    );
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains(what), "{err}");
    assert_eq!(files(d), before, "the directory changed");
}

fn files(d: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn a_map_value_too_large_to_draw_is_invalid_input() {
    let d = tempfile::tempdir().unwrap();
    let m = d.path().join("m");
    let rows = [
        row(1000.0, "10"),
        row(1000.0, "1e308"),
        row(2000.0, "10"),
        row(2000.0, "1e308"),
    ];
    map_dir(&m, &rows);
    report_refuses(&m, "column `torque_nm`: 1e308 is too large to draw");
}

#[test]
fn a_map_whose_grid_would_be_too_large_is_invalid_input() {
    let d = tempfile::tempdir().unwrap();
    let m = d.path().join("m");
    let rows: Vec<String> = (0..70_000)
        .map(|k| row(1000.0 + k as f64, &format!("{}", 10 + k)))
        .collect();
    map_dir(&m, &rows);
    report_refuses(&m, "70000 speeds × 70000 torques: more than 40000 grid cells");
}

/// The grid bound of `report` is the point bound of `map`.
#[test]
fn the_report_grid_bound_is_the_map_point_bound() {
    assert_eq!(
        geartherm::report::plots::data::MAX_MAP_CELLS,
        geartherm::job::limits::MAX_MAP_POINTS
    );
}

/// A complete run directory of the FZG C over the short rig cycle under `parent`, and its
/// `timeseries.csv` text.
fn fzg_run(parent: &Path) -> (std::path::PathBuf, String) {
    let run = parent.join("r");
    let o = Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .args([
            "run",
            "models/fzg_c.toml",
            "--cycle",
            "tests/data/rig_short.csv",
            "--quiet",
            "--out",
        ])
        .arg(&run)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(run.join("timeseries.csv")).unwrap();
    (run, text)
}

/// A run directory whose `time_s` jumps back to -1e308 (a time axis spanning 1e308 is never
/// drawn): times must increase from row to row and stay within ±1e300 s.
#[test]
fn a_time_column_that_does_not_increase_is_invalid_input() {
    let d = tempfile::tempdir().unwrap();
    let (run, text) = fzg_run(d.path());
    for (row, time) in [(3, "-1e+308"), (1, "1e308"), (2, "0")] {
        let edited: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(k, l)| match (k == row, l.split_once(',')) {
                (true, Some((_, rest))) => format!("{time},{rest}"),
                _ => l.to_string(),
            })
            .collect();
        std::fs::write(run.join("timeseries.csv"), edited.join("\n") + "\n").unwrap();
        report_refuses(&run, "column `time_s`");
    }
}

/// A temperature of ±1e308 in `timeseries.csv`: the temperature axis would span 2e308 (infinite)
/// and its tick search never end; every value read for a figure lies within ±1e300.
#[test]
fn a_value_too_large_to_draw_in_a_time_series_is_invalid_input() {
    let d = tempfile::tempdir().unwrap();
    let (run, text) = fzg_run(d.path());
    let head: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = head.iter().position(|h| *h == "temp_housing_c").unwrap();
    let edited: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(k, l)| {
            let mut f: Vec<String> = l.split(',').map(str::to_string).collect();
            if k == 2 {
                f[col] = "-1e+308".into();
            }
            f.join(",")
        })
        .collect();
    std::fs::write(run.join("timeseries.csv"), edited.join("\n") + "\n").unwrap();
    report_refuses(&run, "column `temp_housing_c`");
}
