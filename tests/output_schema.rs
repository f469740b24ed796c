//! One schema per output file: the directories the commands write are read back by `report DIR`
//! and `read_run` with the writers' types, and so are directories written by earlier versions
//! (tests/fixtures/README.md).
//!
//! - run: `summary.json` read as `report::run::Summary` and written again gives the same JSON
//!   value; `timeseries.csv` read as `report::timeseries::Timeseries` and written again gives
//!   the same bytes; `report DIR` draws the same PNGs and `report.md` as `run --report` drew from
//!   the results in memory.
//! - map: `map.json` read as `report::map::MapMeta` gives the same JSON value; `report DIR` draws the
//!   same heat maps and `report.md` as `map` did.
//! - map: `map.csv` read as `report::map::MapRow`s and written again gives the same bytes.
//! - bench: `bench.json` read as `report::bench::BenchResult`, `bench.csv` into its
//!   `solve::work_precision::BenchRow`s; `report DIR` draws the same `work_precision.png` as
//!   `bench` did.
//! - map and bench directories written by the previous binary read back, and `report DIR` draws
//!   the figures that binary drew; a map of the oldest format (`total_loss_w`, `<source>_w`)
//!   reads with today's names.
//! - rating, study, calibrate and validate directories hold none of these files: `report`
//!   refuses them (exit 1) and writes nothing.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use geartherm::report::map::{map_csv, MapMeta};
use geartherm::report::plots::data::{read_bench, read_json, read_map, read_run};
use geartherm::report::run::Summary;
use geartherm::scene::Source;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("binary runs")
}

fn ok(args: &[&str]) {
    let o = bin(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&fs::read(path).unwrap()).unwrap()
}

/// A copy of `files` of `from` in a new directory `to` (the inputs of `report`, without the
/// figures).
fn inputs(from: &Path, to: &Path, files: &[&str]) {
    fs::create_dir_all(to).unwrap();
    for f in files {
        fs::copy(from.join(f), to.join(f)).unwrap();
    }
}

/// `report DIR` on a copy of the inputs of `dir`: the figures and `report.md` it writes are the
/// bytes of those in `dir`.
fn report_redraws(dir: &Path, copy: &Path, files: &[&str], drawn: &[&str]) {
    inputs(dir, copy, files);
    ok(&["report", copy.to_str().unwrap()]);
    for f in drawn {
        assert!(
            fs::read(dir.join(f)).unwrap() == fs::read(copy.join(f)).unwrap(),
            "{f}: report DIR drew other bytes than the command that wrote {}",
            dir.display()
        );
    }
}

/// Read a run directory with the writer's types; the summary written again is the same JSON
/// value and the time series the same bytes.
fn run_reads_back(dir: &Path) -> Summary {
    let (summary, table) = read_run(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    assert_eq!(
        serde_json::to_value(&summary).unwrap(),
        json(&dir.join("summary.json")),
        "{}",
        dir.display()
    );
    assert_eq!(
        table.to_csv(),
        fs::read_to_string(dir.join("timeseries.csv")).unwrap(),
        "{}",
        dir.display()
    );
    summary
}

const RUN_FILES: [&str; 2] = ["summary.json", "timeseries.csv"];
const RUN_DRAWN: [&str; 5] = [
    "temperatures.png",
    "losses.png",
    "energy.png",
    "efficiency.png",
    "report.md",
];

#[test]
fn run_directories_read_back_with_the_writers_types() {
    let d = tempfile::tempdir().unwrap();
    for (model, cycle) in [
        ("models/at6_lepelletier.toml", "hwfet"),
        ("models/fzg_c.toml", "tests/data/rig_short.csv"),
    ] {
        let dir = d.path().join(Path::new(model).file_stem().unwrap());
        let s = dir.to_str().unwrap();
        ok(&["run", model, "--cycle", cycle, "--out", s, "--report", "--quiet"]);
        let summary = run_reads_back(&dir);
        assert!(summary.stats.steps > 0 && !summary.stats.method.is_empty());
        report_redraws(
            &dir,
            &d.path().join(format!("{}_again", summary.cycle)),
            &RUN_FILES,
            &RUN_DRAWN,
        );
    }
}

#[test]
fn map_and_bench_directories_read_back_with_the_writers_types() {
    let d = tempfile::tempdir().unwrap();
    let map = d.path().join("map");
    let m = map.to_str().unwrap();
    ok(&[
        "map",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "500:1500:3",
        "--torque-nm",
        "0:100:3",
        "--out",
        m,
        "--quiet",
    ]);
    let meta: MapMeta = read_json(&map.join("map.json")).unwrap();
    assert_eq!(serde_json::to_value(&meta).unwrap(), json(&map.join("map.json")));
    assert_eq!(meta.points, 9);
    map_csv_reads_back(&map);
    report_redraws(
        &map,
        &d.path().join("map_again"),
        &["map.csv", "map.json"],
        &[
            "map_efficiency.png",
            "map_total_loss.png",
            "map_oil_temp.png",
            "report.md",
        ],
    );

    let bench = d.path().join("bench");
    let b = bench.to_str().unwrap();
    ok(&[
        "bench",
        "models/fzg_c.toml",
        "--cycle",
        "tests/data/rig_short.csv",
        "--repeats",
        "1",
        "--min-rtol",
        "1e-4",
        "--solvers",
        "ros3,bdf",
        "--out",
        b,
    ]);
    let result = read_bench(&bench).unwrap();
    let file = json(&bench.join("bench.json"));
    assert_eq!(result.model, file["model"].as_str().unwrap());
    assert_eq!(result.cycle, file["cycle"].as_str().unwrap());
    assert_eq!(result.default.solver, file["default"]["solver"].as_str().unwrap());
    let rows = result.rows;
    let lines = fs::read_to_string(bench.join("bench.csv"))
        .unwrap()
        .lines()
        .count();
    assert_eq!(rows.len(), lines - 1);
    assert!(rows.iter().any(|r| r.solver == "ros3") && rows.iter().any(|r| r.default));
    report_redraws(
        &bench,
        &d.path().join("bench_again"),
        &["bench.csv", "bench.json"],
        &["work_precision.png"],
    );
}

#[test]
fn directories_report_does_not_draw_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let rating = d.path().join("rating");
    let r = rating.to_str().unwrap();
    ok(&[
        "rating",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "1500",
        "--oil-limit-c",
        "90",
        "--out",
        r,
        "--quiet",
    ]);
    let before = fs::read_dir(&rating).unwrap().count();
    let o = bin(&["report", r]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("holds no timeseries.csv, map.csv or bench.csv"));
    assert_eq!(fs::read_dir(&rating).unwrap().count(), before);
}

#[test]
fn a_run_directory_of_the_previous_binary_reads_back() {
    let fixture = root().join("tests/fixtures/run_main_9d79de0");
    let summary = run_reads_back(&fixture);
    assert_eq!(summary.model, "FZG C-type test gearbox");
    let d = tempfile::tempdir().unwrap();
    inputs(&fixture, d.path(), &RUN_FILES);
    ok(&["report", d.path().to_str().unwrap()]);
    for f in RUN_DRAWN {
        assert!(d.path().join(f).is_file(), "{f}");
    }
}

#[test]
fn a_run_directory_of_an_earlier_format_reads_with_todays_names() {
    let fixture = root().join("tests/fixtures/run_d379aa5");
    let file = json(&fixture.join("summary.json"));
    let (summary, table) = read_run(&fixture).unwrap();
    // Renamed key: mean_efficiency is read as cycle_efficiency.
    assert_eq!(summary.cycle_efficiency, file["mean_efficiency"].as_f64());
    assert!(summary.cycle_efficiency.is_some());
    // Keys the version did not write read as their defaults.
    assert!(summary.warnings.is_empty() && summary.controls.is_empty() && summary.launch.is_none());
    assert_eq!(summary.energy_efficiency, None);
    assert_eq!(summary.stats.method, "");
    assert_eq!(
        summary.stats.steps as u64,
        file["stats"]["steps"].as_u64().unwrap()
    );
    // Keys it wrote keep their values.
    let e = &file["energy_lost_j"];
    assert_eq!(Some(summary.energy_lost_j.sum()), e["total"].as_f64());
    assert_eq!(
        summary.temperatures_c["sump"].max,
        file["temperatures_c"]["sump"]["max"].as_f64().unwrap()
    );
    assert_eq!(summary.oil_node, "sump");
    // Its per-source columns under their earlier names.
    assert!(table.num("churning_w").is_some() && table.num("total_loss_w").is_some());
    assert_eq!(
        table.to_csv(),
        fs::read_to_string(fixture.join("timeseries.csv")).unwrap()
    );
    let d = tempfile::tempdir().unwrap();
    inputs(&fixture, d.path(), &RUN_FILES);
    ok(&["report", d.path().to_str().unwrap()]);
    let md = fs::read_to_string(d.path().join("report.md")).unwrap();
    let pct = format!("{:.2} %", 100.0 * file["mean_efficiency"].as_f64().unwrap());
    assert!(md.contains(&pct), "{pct} not in report.md:\n{md}");
    assert!(
        md.contains(&format!(
            "| churning | {} |",
            geartherm::report::plots::style::fmt_sig(e["churning"].as_f64().unwrap() / 1e3, 4)
        )),
        "{md}"
    );
}

/// `map.csv` of `dir` read with the writer's type and written again: the same bytes.
fn map_csv_reads_back(dir: &Path) {
    let grid = read_map(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let rows: Vec<_> = grid.cells.into_iter().flatten().collect();
    let mut by_file_order = rows.clone();
    let text = fs::read_to_string(dir.join("map.csv")).unwrap();
    // The grid holds the rows torque-major; the file is speed-major.
    by_file_order.sort_by(|a, b| {
        a.speed_rpm
            .total_cmp(&b.speed_rpm)
            .then(a.torque_nm.total_cmp(&b.torque_nm))
    });
    assert_eq!(by_file_order.len(), text.lines().count() - 1);
    assert_eq!(map_csv(&by_file_order), text, "{}", dir.display());
}

#[test]
fn map_and_bench_directories_of_the_previous_binary_read_back() {
    let map = root().join("tests/fixtures/map_main_c9b66ad");
    map_csv_reads_back(&map);
    let meta: MapMeta = read_json(&map.join("map.json")).unwrap();
    assert_eq!(serde_json::to_value(&meta).unwrap(), json(&map.join("map.json")));
    let d = tempfile::tempdir().unwrap();
    report_redraws(
        &map,
        &d.path().join("map"),
        &["map.csv", "map.json"],
        &["map_efficiency.png", "report.md"],
    );
    let bench = root().join("tests/fixtures/bench_main_c9b66ad");
    let result = read_bench(&bench).unwrap();
    assert_eq!(result.model, "FZG C-type test gearbox");
    assert_eq!(result.rows.len(), 4);
    assert_eq!(result.pareto.len(), 4);
    assert!(result.reference.agreement_k > 0.0 && result.reference.methods[1] == "bdf");
    report_redraws(
        &bench,
        &d.path().join("bench"),
        &["bench.csv", "bench.json"],
        &["work_precision.png"],
    );
}

#[test]
fn a_map_directory_of_the_oldest_format_reads_with_todays_names() {
    let fixture = root().join("tests/fixtures/map_d379aa5");
    let grid = read_map(&fixture).unwrap();
    let text = fs::read_to_string(fixture.join("map.csv")).unwrap();
    let first: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
    let cell = grid.cell(0, 0).unwrap();
    assert_eq!((cell.speed_rpm, cell.torque_nm), (300.0, 0.0));
    // `total_loss_w` and `<source>_w` read as `loss_total_w` and `loss_<source>_w`.
    assert_eq!(cell.loss_total_w, Some(first[3].parse().unwrap()));
    assert_eq!(
        cell.loss_w[Source::Churning.index()],
        Some(first[4].parse().unwrap())
    );
    assert_eq!(cell.loss_w[Source::Sliding.index()], Some(0.0));
    // A source the version did not write has no value; a column it did not write is empty.
    assert_eq!(cell.loss_w[Source::Bearing.index()], None);
    assert_eq!(cell.limit_cycle_period_s, None);
    assert_eq!(grid.cells.iter().flatten().count(), 9);
    let d = tempfile::tempdir().unwrap();
    inputs(&fixture, d.path(), &["map.csv", "map.json"]);
    ok(&["report", d.path().to_str().unwrap()]);
    let md = fs::read_to_string(d.path().join("report.md")).unwrap();
    assert!(md.contains("| Total loss | 2.9 … 12.7 W |"), "{md}");
}
