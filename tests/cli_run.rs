//! `geartherm run` end to end: every example model over every bundled cycle, outputs and their
//! contract, invalid input (exit 1, nothing written), numerical failure (exit 2, named).

use std::path::Path;
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("binary runs")
}

const MODELS: [&str; 4] = [
    "models/at6_lepelletier.toml",
    "models/fzg_c.toml",
    "models/helical_stage.toml",
    "models/pt6_spur_pair.toml",
];

const CYCLES: [&str; 10] = [
    "wltc",
    "nedc",
    "ftp75",
    "udds",
    "hwfet",
    "us06",
    "artemis_urban",
    "artemis_road",
    "artemis_motorway130",
    "artemis_motorway150",
];

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn every_example_model_runs_every_bundled_cycle() {
    let tmp = tempfile::tempdir().unwrap();
    let mut table = String::new();
    for m in MODELS {
        for c in CYCLES {
            let dir = tmp.path().join(format!(
                "{}_{c}",
                Path::new(m).file_stem().unwrap().to_string_lossy()
            ));
            let out = run(&["run", m, "--cycle", c, "--out", dir.to_str().unwrap(), "--quiet"]);
            assert!(
                out.status.success(),
                "{m} {c}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let s = summary(&dir);
            let bal = s["energy_balance_relative"].as_f64().unwrap();
            let total = s["energy_lost_j"]["total"].as_f64().unwrap();
            assert!(bal <= 1e-9, "{m} {c}: balance {bal}");
            assert!(total > 0.0 && total.is_finite(), "{m} {c}: {total}");
            let oil = s["oil_node"].as_str().unwrap();
            let t = &s["temperatures_c"][oil];
            assert!(
                t["final"].as_f64().unwrap() > t["min"].as_f64().unwrap(),
                "{m} {c}: oil warms"
            );
            let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
            assert!(!csv.contains("NaN") && !csv.contains("inf"), "{m} {c}");
            table.push_str(&format!(
                "{m:<32} {c:<20} loss {:>8.1} kJ  oil final {:>6.2} °C  balance {bal:.1e}  {} steps  {:.3} s\n",
                total / 1e3,
                t["final"].as_f64().unwrap(),
                s["steps"],
                s["wall_time_s"].as_f64().unwrap()
            ));
        }
    }
    println!("{table}");
}

#[test]
fn run_outputs_follow_the_contract() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("r");
    let out = run(&[
        "run",
        MODELS[0],
        "--cycle",
        "wltc",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let s: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is one JSON document");
    for key in [
        "wall_time_s",
        "steps",
        "solver",
        "rtol",
        "energy_lost_j",
        "energy_balance_relative",
        "cycle_efficiency",
        "temperatures_c",
        "skipped",
    ] {
        assert!(s.get(key).is_some(), "summary lacks {key}");
    }
    for k in ["churning", "pocketing", "sliding", "bearing", "seal", "total"] {
        assert!(s["energy_lost_j"][k].as_f64().is_some(), "{k}");
    }
    // Every source's energy adds up to the total (the AT6 has bearings and seals).
    let e = s["energy_lost_j"].as_object().unwrap();
    let sum: f64 = e
        .iter()
        .filter(|(k, _)| *k != "total")
        .map(|(_, v)| v.as_f64().unwrap())
        .sum();
    assert!((sum - e["total"].as_f64().unwrap()).abs() < 1e-6 * sum);
    assert!(e["bearing"].as_f64().unwrap() > 0.0 && e["seal"].as_f64().unwrap() > 0.0);
    let eta = s["cycle_efficiency"].as_f64().unwrap();
    assert!(eta > 0.9 && eta < 1.0, "{eta}");
    assert!(
        !s["skipped"].as_array().unwrap().is_empty(),
        "AT6 skips the suns' churning"
    );
    let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        &header[..6],
        &[
            "time_s",
            "vehicle_speed_kmh",
            "gear",
            "input_speed_rpm",
            "input_torque_nm",
            "output_power_w"
        ]
    );
    assert!(header.contains(&"temp_sump_c") && header.contains(&"temp_ambient_c"));
    assert!(header.iter().any(|h| h.starts_with("loss_sliding_")));
    assert_eq!(header[header.len() - 1], "efficiency");
    // The input shaft supplies the output power and the losses paid through it:
    // T_in·ω_in = P_out + P_loss − (converter slip + engine-driven pump), which the engine pays
    // ahead of the input shaft (docs/outputs.md).
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let engine_side: Vec<usize> = if header.contains(&"engine_speed_rpm") {
        (0..header.len())
            // The engine side's items (not their per-source sums `loss_converter_w`, `loss_pump_w`).
            .filter(|&i| {
                let h = header[i];
                (h.starts_with("loss_converter_") || h.starts_with("loss_pump_"))
                    && h != "loss_converter_w"
                    && h != "loss_pump_w"
            })
            .collect()
    } else {
        Vec::new()
    };
    let (ci, cw, cp, cl) = (
        col("input_torque_nm"),
        col("input_speed_rpm"),
        col("output_power_w"),
        col("loss_total_w"),
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.parse::<f64>().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 1801, "one row per second including t = 0");
    let mut checked = 0;
    for r in rows.iter().filter(|r| r[cw] > 0.0 && r[cp] > 0.0) {
        let p_in = r[ci] * r[cw] * std::f64::consts::PI / 30.0;
        let ahead: f64 = engine_side.iter().map(|&i| r[i]).sum();
        assert!(
            (p_in - r[cp] - (r[cl] - ahead)).abs() <= 1e-9 * p_in,
            "{p_in} vs {} + {} − {ahead}",
            r[cp],
            r[cl]
        );
        checked += 1;
    }
    assert!(checked > 500, "{checked} driving rows");
    // Nothing but the outputs in the directory (no temporary files left).
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, [".geartherm-output", "summary.json", "timeseries.csv"]);
}

fn assert_invalid_and_nothing_written(args: &[&str], dir: &Path, expect: &[&str]) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    for e in expect {
        assert!(err.contains(e), "{args:?}: expected '{e}' in: {err}");
    }
    assert!(out.stdout.is_empty());
    assert!(!dir.exists(), "{args:?} wrote {}", dir.display());
}

#[test]
fn malformed_cycles_are_rejected_with_their_line_and_nothing_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("never");
    let cases = [
        ("nonincreasing.csv", "time_s,speed_kmh\n0,0\n1,5\n1,6\n", "line 4"),
        ("nan.csv", "time_s,speed_kmh\n0,0\n1,NaN\n", "line 3"),
        ("negative.csv", "time_s,speed_kmh\n0,0\n1,-3\n2,0\n", "line 3"),
        (
            "unknown_gear.csv",
            "time_s,input_speed_rpm,input_torque_nm,gear\n0,1000,50,1\n1,1000,50,9\n",
            "line 3",
        ),
    ];
    for (name, text, line) in cases {
        let f = tmp.path().join(name);
        std::fs::write(&f, text).unwrap();
        assert_invalid_and_nothing_written(
            &[
                "run",
                MODELS[1],
                "--cycle",
                f.to_str().unwrap(),
                "--out",
                dir.to_str().unwrap(),
            ],
            &dir,
            &[line, name],
        );
    }
    assert_invalid_and_nothing_written(
        &[
            "run",
            MODELS[1],
            "--cycle",
            "no_such_cycle",
            "--out",
            dir.to_str().unwrap(),
        ],
        &dir,
        &["wltc"],
    );
    assert_invalid_and_nothing_written(
        &[
            "run",
            MODELS[1],
            "--solver",
            "euler",
            "--out",
            dir.to_str().unwrap(),
        ],
        &dir,
        &["--solver", "esdirk34"],
    );
    assert_invalid_and_nothing_written(
        &[
            "run",
            "tests/invalid/thermal_isolated_node.toml",
            "--out",
            dir.to_str().unwrap(),
        ],
        &dir,
        &["thermal.nodes[5]", "isolated"],
    );
}

#[test]
fn rig_cycle_runs_a_model_without_vehicle_semantics() {
    let tmp = tempfile::tempdir().unwrap();
    let f = tmp.path().join("rig.csv");
    std::fs::write(
        &f,
        "time_s,input_speed_rpm,input_torque_nm,gear\n0,1450,35.3,1\n600,1450,94.1,1\n1200,1450,135.3,1\n1800,0,0,1\n",
    )
    .unwrap();
    let dir = tmp.path().join("rig");
    let out = run(&[
        "run",
        MODELS[1],
        "--cycle",
        f.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let s = summary(&dir);
    assert!(s["energy_balance_relative"].as_f64().unwrap() <= 1e-9);
    assert_eq!(s["duration_s"].as_f64().unwrap(), 1800.0);
}

#[test]
fn numerical_failure_exits_2_naming_time_node_and_item() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("fail");
    let out = run(&[
        "run",
        MODELS[1],
        "--cycle",
        "wltc",
        "--solver",
        "tsit45",
        "--max-steps",
        "200",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("t = ") && err.contains("node ") && err.contains("loss item "),
        "{err}"
    );
    assert!(!dir.exists());
}

fn png_stats(path: &Path) -> (u32, u32, f64) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let px = &buf[..info.buffer_size()];
    let mean = px.iter().map(|&v| f64::from(v)).sum::<f64>() / px.len() as f64;
    let var = px.iter().map(|&v| (f64::from(v) - mean).powi(2)).sum::<f64>() / px.len() as f64;
    (info.width, info.height, var)
}

#[test]
fn run_with_report_writes_decodable_non_blank_pngs() {
    let tmp = tempfile::tempdir().unwrap();
    let f = tmp.path().join("short.csv");
    // A short vehicle cycle: launch, cruise, stop.
    let mut text = String::from("time_s,speed_kmh\n");
    for t in 0..=120 {
        let v = if t < 30 {
            2.0 * t as f64
        } else if t < 90 {
            60.0
        } else {
            2.0 * (120 - t) as f64
        };
        text.push_str(&format!("{t},{v}\n"));
    }
    std::fs::write(&f, text).unwrap();
    let dir = tmp.path().join("rep");
    let out = run(&[
        "run",
        MODELS[0],
        "--cycle",
        f.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--report",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for name in ["temperatures.png", "losses.png", "energy.png", "efficiency.png"] {
        let (w, h, var) = png_stats(&dir.join(name));
        assert_eq!((w, h), (1600, 1000), "{name}");
        assert!(var > 100.0, "{name} looks blank (pixel variance {var})");
    }
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for name in ["temperatures.png", "losses.png", "energy.png", "efficiency.png"] {
        assert!(md.contains(name), "report.md does not show {name}");
    }
}

#[test]
fn committed_plots_match_what_the_documented_commands_produce() {
    // plots/regenerate.sh: the run and the map; their data files must be what the binary
    // produces today (PNGs are rendered from them).
    let tmp = tempfile::tempdir().unwrap();
    let r = tmp.path().join("at6_wltc");
    let out = run(&[
        "run",
        MODELS[0],
        "--cycle",
        "wltc",
        "--out",
        r.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(out.status.success());
    // (a plain comparison: the files are too long for assert_eq!'s message)
    assert!(
        std::fs::read_to_string(r.join("timeseries.csv")).unwrap()
            == std::fs::read_to_string("plots/at6_wltc/timeseries.csv").unwrap(),
        "plots/at6_wltc is stale: run plots/regenerate.sh"
    );
    let m = tmp.path().join("map");
    let out = run(&[
        "map",
        MODELS[1],
        "--gear",
        "1",
        "--speed-rpm",
        "300:3000:28",
        "--torque-nm",
        "0:300:31",
        "--out",
        m.to_str().unwrap(),
        "--no-plots",
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        std::fs::read_to_string(m.join("map.csv")).unwrap()
            == std::fs::read_to_string("plots/fzg_c_map/map.csv").unwrap(),
        "plots/fzg_c_map is stale: run plots/regenerate.sh"
    );
    for p in [
        "plots/at6_wltc/temperatures.png",
        "plots/at6_wltc/losses.png",
        "plots/at6_wltc/energy.png",
        "plots/at6_wltc/efficiency.png",
        "plots/fzg_c_map/map_efficiency.png",
        "plots/fzg_c_map/map_total_loss.png",
        "plots/fzg_c_map/map_oil_temp.png",
    ] {
        let (w, h, var) = png_stats(Path::new(p));
        assert_eq!((w, h), (1600, 1000), "{p}");
        assert!(var > 100.0, "{p}");
    }
}
