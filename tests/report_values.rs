//! `report` on a result directory whose numbers were edited: an efficiency outside [0, 1] is
//! invalid input (exit 1, the user's file and the key named, nothing written); huge finite
//! numbers are written in a form that fits (never `inf`, `NaN` or hundreds of digits).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test; `GEARTHERM_BIN` points the suite at another build (to show that
/// each test fails on a build without the fix).
fn bin() -> Command {
    match std::env::var_os("GEARTHERM_BIN") {
        Some(p) => Command::new(p),
        None => Command::new(env!("CARGO_BIN_EXE_geartherm")),
    }
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A FZG C run over the WLTC in `parent/rd` (timeseries.csv and summary.json).
fn fzg_run(parent: &Path) -> PathBuf {
    let dir = parent.join("rd");
    let o = bin()
        .args(["run", "models/fzg_c.toml", "--cycle", "wltc", "--quiet", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    dir
}

/// Set `key` (a JSON pointer) of `dir/summary.json` to the JSON number `value`.
fn edit_summary(dir: &Path, key: &str, value: &str) {
    let p = dir.join("summary.json");
    let mut json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    *json.pointer_mut(key).unwrap_or_else(|| panic!("no {key}")) = serde_json::from_str(value).unwrap();
    std::fs::write(&p, serde_json::to_string_pretty(&json).unwrap()).unwrap();
}

/// Set column `column` of `dir/name` (a CSV file) to `value` in data row `row`.
fn edit_csv(dir: &Path, name: &str, column: &str, row: usize, value: &str) {
    let p = dir.join(name);
    let text = std::fs::read_to_string(&p).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let c = lines[0].split(',').position(|h| h == column).unwrap();
    let mut cells: Vec<&str> = lines[row + 1].split(',').collect();
    cells[c] = value;
    lines[row + 1] = cells.join(",");
    std::fs::write(&p, lines.join("\n") + "\n").unwrap();
}

#[test]
fn a_cycle_efficiency_outside_0_1_is_invalid_input_naming_the_users_file_and_key() {
    for value in ["1e308", "5", "-0.5"] {
        let d = tempfile::tempdir().unwrap();
        let dir = fzg_run(d.path());
        edit_summary(&dir, "/cycle_efficiency", value);
        let before = names(&dir);
        let o = bin().arg("report").arg(&dir).output().unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "cycle_efficiency {value}: {err}");
        let file = format!("{}: ", dir.join("summary.json").display());
        assert!(err.contains(&file), "names {file}: {err}");
        assert!(err.contains("cycle_efficiency"), "names the key: {err}");
        assert!(!err.contains("geartherm-tmp"), "no temporary directory: {err}");
        assert_eq!(names(&dir), before, "nothing written");
        assert_eq!(names(d.path()), ["rd"], "no temporaries beside the directory");
    }
}

#[test]
fn a_relative_directory_is_named_as_the_user_gave_it() {
    let d = tempfile::tempdir().unwrap();
    let dir = fzg_run(d.path());
    let report = || {
        bin()
            .arg("report")
            .arg("rd")
            .current_dir(d.path())
            .output()
            .unwrap()
    };
    // Malformed JSON: refused before as now, but named by the transaction's temporary copy.
    let good = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    std::fs::write(dir.join("summary.json"), "{ not json").unwrap();
    let o = report();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("report: rd/summary.json: malformed JSON"),
        "{err}"
    );
    std::fs::write(dir.join("summary.json"), good).unwrap();
    edit_summary(&dir, "/cycle_efficiency", "5");
    let o = report();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("report: rd/summary.json: cycle_efficiency"),
        "{err}"
    );
}

#[test]
fn huge_finite_values_are_written_without_inf_or_endless_digits() {
    let d = tempfile::tempdir().unwrap();
    let dir = fzg_run(d.path());
    edit_summary(&dir, "/energy_lost_j/churning", "1e308");
    edit_summary(&dir, "/energy_lost_j/total", "1e308");
    edit_summary(&dir, "/temperatures_c/oil/max", "1e300");
    let o = bin().arg("report").arg(&dir).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for bad in ["inf", "NaN"] {
        assert!(!md.contains(bad), "report.md holds {bad}:\n{md}");
    }
    let longest = md
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(
        longest < 30,
        "a number of {longest} characters in report.md:\n{md}"
    );
    let churning = md.lines().find(|l| l.starts_with("| churning |")).unwrap();
    assert!(churning.ends_with("| 100.0 % |"), "{churning}");
}

#[test]
fn an_efficiency_over_1_in_a_time_series_or_a_map_is_invalid_input() {
    let d = tempfile::tempdir().unwrap();
    let dir = fzg_run(d.path());
    edit_csv(&dir, "timeseries.csv", "efficiency", 100, "1.5");
    let o = bin().arg("report").arg(&dir).output().unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("{}: ", dir.join("timeseries.csv").display())) && err.contains("`efficiency`"),
        "{err}"
    );

    let map = d.path().join("map");
    let o = bin()
        .args([
            "map",
            "models/fzg_c.toml",
            "--gear",
            "1",
            "--speed-rpm",
            "500:1500:2",
        ])
        .args(["--torque-nm", "50:100:2", "--no-plots", "--quiet", "--out"])
        .arg(&map)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    edit_csv(&map, "map.csv", "efficiency", 0, "5");
    let before = names(&map);
    let o = bin().arg("report").arg(&map).output().unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("{}: ", map.join("map.csv").display())) && err.contains("`efficiency`"),
        "{err}"
    );
    assert_eq!(names(&map), before, "nothing written");
}
