//! Hostile controllers (`[[thermal.controls]]`): set points reversed, equal, NaN, outside the
//! oil's range; a controller on a node that does not exist; two controllers on one cooler; keys
//! of the wrong kind. Each is refused by the release binary with exit 1, the key path and the
//! reason, and nothing is written.

use std::path::Path;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
}

/// The FZG C model with a cooler without thermostat (`fan_cooler`) and `controls` appended.
fn model_with(dir: &Path, controls: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string("models/fzg_c.toml").unwrap();
    let extra = r#"
[[thermal.coolers]]
name = "fan_cooler"
hot = "oil"
cold = "ambient"
effectiveness = 0.5
capacity_rate_w_per_k = 40.0
"#;
    let p = dir.join("m.toml");
    std::fs::write(&p, format!("{text}\n{extra}\n{controls}")).unwrap();
    p
}

const CYCLE: &str = "time_s,input_speed_rpm,input_torque_nm,gear\n0,3000,150,1\n600,3000,150,1\n";

/// `run` on the model with `controls`: exit code, stderr, whether the output exists.
fn run(controls: &str) -> (i32, String, bool) {
    let d = tempfile::tempdir().unwrap();
    let m = model_with(d.path(), controls);
    let c = d.path().join("c.csv");
    std::fs::write(&c, CYCLE).unwrap();
    let out = d.path().join("out");
    let o = bin()
        .args(["run", m.to_str().unwrap(), "--cycle", c.to_str().unwrap()])
        .args(["--out", out.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        out.exists(),
    )
}

fn two_point(on: &str, off: &str, sensor: &str, target: &str) -> String {
    format!(
        "[[thermal.controls]]\nname = \"fan\"\nkind = \"two_point\"\nsensor = \"{sensor}\"\n\
         on_c = {on}\noff_c = {off}\n{target}\n"
    )
}

fn refused(controls: &str, path: &str, reason: &str) {
    let (code, err, written) = run(controls);
    assert_eq!(code, 1, "{controls}\n{err}");
    assert!(err.contains(path), "key path {path} missing: {err}");
    assert!(err.contains(reason), "reason {reason:?} missing: {err}");
    assert!(!written, "nothing is written: {controls}");
}

const COOLER: &str = "cooler = \"fan_cooler\"";

#[test]
fn a_valid_controller_runs() {
    let (code, err, written) = run(&two_point("60.0", "55.0", "oil", COOLER));
    assert_eq!(code, 0, "{err}");
    assert!(written);
}

#[test]
fn equal_set_points_are_refused_with_the_reason() {
    refused(
        &two_point("60.0", "60.0", "oil", COOLER),
        "thermal.controls[0].off_c",
        "chatter",
    );
}

#[test]
fn nan_and_out_of_range_set_points_are_refused() {
    refused(
        &two_point("nan", "55.0", "oil", COOLER),
        "thermal.controls[0].on_c",
        "must lie in",
    );
    refused(
        &two_point("60.0", "250.0", "oil", COOLER),
        "thermal.controls[0].off_c",
        "200",
    );
    refused(
        &two_point("-80.0", "55.0", "oil", COOLER),
        "thermal.controls[0].on_c",
        "must lie in",
    );
}

#[test]
fn reversed_valve_set_points_are_refused() {
    let v = "[[thermal.controls]]\nname = \"valve\"\nkind = \"valve\"\nsensor = \"oil\"\n\
             closed_c = 80.0\nopen_c = 70.0\ncooler = \"fan_cooler\"\n";
    refused(v, "thermal.controls[0].open_c", "must be above closed_c");
    let limits = "[[thermal.controls]]\nname = \"valve\"\nkind = \"valve\"\nsensor = \"oil\"\n\
                  closed_c = 70.0\nopen_c = 80.0\nmin_share = 0.8\nmax_share = 0.2\n\
                  cooler = \"fan_cooler\"\n";
    refused(limits, "thermal.controls[0].max_share", "must be above min_share");
}

#[test]
fn an_unknown_sensor_node_is_refused() {
    refused(
        &two_point("60.0", "55.0", "sump", COOLER),
        "thermal.controls[0].sensor",
        "unknown node",
    );
    refused(
        &two_point("60.0", "55.0", "ambient", COOLER),
        "thermal.controls[0].sensor",
        "not a boundary",
    );
}

#[test]
fn two_controllers_on_one_cooler_are_refused() {
    let a = two_point("60.0", "55.0", "oil", COOLER);
    let b = a.replace("name = \"fan\"", "name = \"fan2\"");
    refused(
        &format!("{a}{b}"),
        "thermal.controls[1].cooler",
        "one controller per cooler",
    );
}

#[test]
fn targets_are_checked() {
    refused(
        &two_point("60.0", "55.0", "oil", "cooler = \"nope\""),
        "thermal.controls[0].cooler",
        "unknown cooler",
    );
    refused(
        &two_point("60.0", "55.0", "oil", "cooler = \"oil_temperature_control\""),
        "thermal.controls[0].cooler",
        "its own thermostat",
    );
    refused(
        &two_point("60.0", "55.0", "oil", "cooler = \"fan_cooler\"\nheater_w = 100.0"),
        "thermal.controls[0]",
        "exactly one target",
    );
    refused(
        &two_point("40.0", "45.0", "oil", "heater_w = -5.0"),
        "thermal.controls[0].heater_w",
        "must lie in",
    );
    refused(
        &two_point("60.0", "55.0", "oil", "cooler = \"fan_cooler\"\nclosed_c = 50.0"),
        "thermal.controls[0].closed_c",
        "not a key of a two_point controller",
    );
}

/// `steady` on a network whose fan cycles: exit 0, `method` = `limit_cycle`, the oil's band
/// between the set points, a period; the text names the controller.
#[test]
fn steady_reports_a_cycling_fan() {
    let d = tempfile::tempdir().unwrap();
    let m = model_with(d.path(), &two_point("60.0", "55.0", "oil", COOLER));
    let args = [
        m.to_str().unwrap(),
        "--gear",
        "1",
        "--speed-rpm",
        "3000",
        "--torque-nm",
        "150",
    ];
    let o = bin().arg("steady").args(args).arg("--json").output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["method"], "limit_cycle");
    let c = &v["limit_cycle"];
    let (lo, hi) = (
        c["min_c"]["oil"].as_f64().unwrap(),
        c["max_c"]["oil"].as_f64().unwrap(),
    );
    assert!((lo - 55.0).abs() < 1e-6 && (hi - 60.0).abs() < 1e-6, "{lo} {hi}");
    assert!(c["period_s"].as_f64().unwrap() > 0.0);
    let o = bin().arg("steady").args(args).output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("no equilibrium, controller fan cycles"), "{text}");
}

/// `map` over torques where the fan cycles at some points: a point is flagged as a limit cycle
/// (period and oil band in map.csv) exactly where `steady` reports one, with the band between
/// the set points.
#[test]
fn map_flags_the_points_that_cycle() {
    let d = tempfile::tempdir().unwrap();
    let m = model_with(d.path(), &two_point("60.0", "55.0", "oil", COOLER));
    let out = d.path().join("map");
    let o = bin()
        .arg("map")
        .arg(&m)
        .args(["--gear", "1", "--speed-rpm", "3000", "--torque-nm", "0,150,300"])
        .args(["--no-plots", "--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("map.csv")).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (tq, per, lo, hi) = (
        col("torque_nm"),
        col("limit_cycle_period_s"),
        col("oil_min_c"),
        col("oil_max_c"),
    );
    let mut cycles = 0;
    for line in lines {
        let c: Vec<&str> = line.split(',').collect();
        let s = bin()
            .arg("steady")
            .arg(&m)
            .args([
                "--gear",
                "1",
                "--speed-rpm",
                "3000",
                "--torque-nm",
                c[tq],
                "--json",
            ])
            .output()
            .unwrap();
        let v: serde_json::Value = serde_json::from_slice(&s.stdout).unwrap();
        let steady_cycles = v["method"] == "limit_cycle";
        assert_eq!(!c[per].is_empty(), steady_cycles, "torque {}: {line}", c[tq]);
        if steady_cycles {
            cycles += 1;
            let (a, b): (f64, f64) = (c[lo].parse().unwrap(), c[hi].parse().unwrap());
            assert!((a - 55.0).abs() < 1e-6 && (b - 60.0).abs() < 1e-6, "{line}");
            assert!(c[per].parse::<f64>().unwrap() > 0.0, "{line}");
        } else {
            assert!(c[lo].is_empty() && c[hi].is_empty(), "{line}");
        }
    }
    assert!(cycles >= 1, "no point cycles: {csv}");
}

/// `rating` at a speed where the fan already cycles at zero torque (no mode has an equilibrium:
/// oil mean 58.6 °C, band 55–60 °C) with the limit below that mean: the rating is the minimum
/// torque, and the point says that its oil temperature is a limit cycle's mean (`limit_cycle`
/// in its flags, the cycle in the JSON).
#[test]
fn rating_flags_a_rated_point_that_cycles() {
    let d = tempfile::tempdir().unwrap();
    let m = model_with(d.path(), &two_point("60.0", "55.0", "oil", COOLER));
    let out = d.path().join("rating");
    let o = bin()
        .arg("rating")
        .arg(&m)
        .args([
            "--gear",
            "1",
            "--speed-rpm",
            "3000",
            "--oil-limit-c",
            "58",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("rating.csv")).unwrap();
    let row = csv.lines().nth(1).unwrap();
    assert!(row.ends_with(",limit_at_minimum;limit_cycle"), "{csv}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("rating.json")).unwrap()).unwrap();
    let p = &v["points"][0];
    let c = &p["equilibrium"]["limit_cycle"];
    let mean = c["mean_c"]["oil"].as_f64().unwrap();
    assert!((p["oil_temp_c"].as_f64().unwrap() - mean).abs() < 1e-9, "{p}");
    assert!(mean > 58.0, "{p}");
    let (lo, hi) = (
        c["min_c"]["oil"].as_f64().unwrap(),
        c["max_c"]["oil"].as_f64().unwrap(),
    );
    assert!((lo - 55.0).abs() < 1e-6 && (hi - 60.0).abs() < 1e-6, "{p}");
}

/// Minimum on and off times: negative, NaN, infinite or beyond a year refused with the key path;
/// on a valve refused as a key of the wrong kind; equal set points accepted with one and run.
#[test]
fn hostile_minimum_times_are_refused() {
    for (key, v) in [
        ("min_on_s", "-1.0"),
        ("min_off_s", "nan"),
        ("min_on_s", "inf"),
        ("min_off_s", "1e12"),
    ] {
        let c = two_point("60.0", "55.0", "oil", &format!("{COOLER}\n{key} = {v}"));
        refused(
            &c,
            &format!("thermal.controls[0].{key}"),
            "must lie in [0, 31560000] s",
        );
    }
    let v = "[[thermal.controls]]\nname = \"valve\"\nkind = \"valve\"\nsensor = \"oil\"\n\
             closed_c = 70.0\nopen_c = 80.0\nmin_on_s = 10.0\ncooler = \"fan_cooler\"\n";
    refused(
        v,
        "thermal.controls[0].min_on_s",
        "not a key of a valve controller",
    );
    // Equal set points without a minimum time keep the refusal and its reason.
    let zero = two_point("60.0", "60.0", "oil", &format!("{COOLER}\nmin_on_s = 0.0"));
    refused(&zero, "thermal.controls[0].off_c", "chatter");
    let ok = two_point("60.0", "60.0", "oil", &format!("{COOLER}\nmin_on_s = 30.0"));
    let (code, err, written) = run(&ok);
    assert_eq!(code, 0, "{err}");
    assert!(written);
}

fn pi_valve(extra: &str) -> String {
    format!(
        "[[thermal.controls]]\nname = \"bypass\"\nkind = \"pi_valve\"\nsensor = \"oil\"\n\
         cooler = \"fan_cooler\"\n{extra}\n"
    )
}

/// PI valve: a valid one runs and writes its integral column and its time at the limits; every
/// value checked with its key path and range (set point in the oil's range, gain and integral
/// time positive, min below max within [0, 1], the initial integral within them), keys of
/// other kinds refused, the set point and gain required.
#[test]
fn pi_valve_values_are_checked() {
    let ok = pi_valve("set_c = 80.0\ngain_per_k = 0.05\nintegral_time_s = 300.0");
    let d = tempfile::tempdir().unwrap();
    let m = model_with(d.path(), &ok);
    let c = d.path().join("c.csv");
    std::fs::write(&c, CYCLE).unwrap();
    let out = d.path().join("out");
    let o = bin()
        .args(["run", m.to_str().unwrap(), "--cycle", c.to_str().unwrap()])
        .args(["--out", out.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let ts = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let header = ts.lines().next().unwrap();
    assert!(
        header.ends_with(",control_bypass,control_bypass_integral"),
        "{header}"
    );
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    for key in ["time_at_lower_limit_s", "time_at_upper_limit_s", "integral_final"] {
        assert!(summary.contains(key), "summary lacks {key}");
    }
    let base = "set_c = 80.0\ngain_per_k = 0.05\nintegral_time_s = 300.0";
    for (extra, path, reason) in [
        (
            "set_c = 250.0\ngain_per_k = 0.05\nintegral_time_s = 300.0",
            "set_c",
            "must lie in",
        ),
        (
            "set_c = nan\ngain_per_k = 0.05\nintegral_time_s = 300.0",
            "set_c",
            "",
        ),
        (
            "set_c = 80.0\ngain_per_k = 0.0\nintegral_time_s = 300.0",
            "gain_per_k",
            "must lie in (0, 100]",
        ),
        (
            "set_c = 80.0\ngain_per_k = -1.0\nintegral_time_s = 300.0",
            "gain_per_k",
            "1/K",
        ),
        (
            "set_c = 80.0\ngain_per_k = inf\nintegral_time_s = 300.0",
            "gain_per_k",
            "must lie in",
        ),
        (
            "set_c = 80.0\ngain_per_k = 0.05\nintegral_time_s = 0.0",
            "integral_time_s",
            "must lie in (0,",
        ),
        (
            "set_c = 80.0\ngain_per_k = 0.05\nintegral_time_s = nan",
            "integral_time_s",
            "must lie in",
        ),
        ("set_c = 80.0\nintegral_time_s = 300.0", "gain_per_k", "required"),
        ("gain_per_k = 0.05\nintegral_time_s = 300.0", "set_c", "required"),
        (
            &format!("{base}\nmin_share = 0.6\nmax_share = 0.4"),
            "max_share",
            "must be above min_share",
        ),
        (
            &format!("{base}\nmax_share = 1.5"),
            "max_share",
            "must lie in [0, 1]",
        ),
        (
            &format!("{base}\nmin_share = 0.2\ninitial_share = 0.1"),
            "initial_share",
            "min_share to max_share",
        ),
        (
            &format!("{base}\nopen_c = 90.0"),
            "open_c",
            "not a key of a pi_valve controller",
        ),
        (
            &format!("{base}\non_c = 90.0"),
            "on_c",
            "not a key of a pi_valve controller",
        ),
        (
            &format!("{base}\nmin_on_s = 10.0"),
            "min_on_s",
            "not a key of a pi_valve controller",
        ),
    ] {
        refused(&pi_valve(extra), &format!("thermal.controls[0].{path}"), reason);
    }
    // Without a cooler.
    let none = "[[thermal.controls]]\nname = \"bypass\"\nkind = \"pi_valve\"\nsensor = \"oil\"\n\
                set_c = 80.0\ngain_per_k = 0.05\nintegral_time_s = 300.0\n";
    refused(
        none,
        "thermal.controls[0].cooler",
        "a valve needs the cooler it bypasses",
    );
    // A valve key on a proportional valve.
    let v = "[[thermal.controls]]\nname = \"valve\"\nkind = \"valve\"\nsensor = \"oil\"\n\
             closed_c = 70.0\nopen_c = 80.0\ngain_per_k = 0.1\ncooler = \"fan_cooler\"\n";
    refused(
        v,
        "thermal.controls[0].gain_per_k",
        "not a key of a valve controller",
    );
}
