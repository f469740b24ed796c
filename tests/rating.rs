//! Thermal rating (`geartherm rating`, `job::rating`): the equilibrium at the rated torque is the
//! oil limit within 0.01 K (checked by an independent `steady` job) and a slightly higher torque
//! exceeds it; the limit exceeded at the lowest torque, the ceiling, bad options and a point
//! without equilibrium each give their documented answer; a sweep writes rating.csv, rating.json
//! and rating.png, a single point writes nothing unless asked.

use std::path::{Path, PathBuf};
use std::process::Command;

use geartherm::job::rating::{rating, RatingOptions, Status};
use geartherm::job::steady::steady;
use geartherm::job::{ErrorKind, Model, SteadyOptions};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn model(path: &str) -> Model {
    Model::load(&root().join(path), &[]).unwrap()
}

fn options(gear: &str, speeds: &[f64], limit: f64) -> RatingOptions {
    RatingOptions {
        gear: gear.into(),
        speed_rpm: speeds.to_vec(),
        oil_limit_c: limit,
        vehicle_speed_kmh: 0.0,
        ambient_c: None,
        torque_min_nm: 0.0,
        torque_max_nm: None,
    }
}

fn oil_at(m: &Model, o: &RatingOptions, rpm: f64, torque: f64) -> f64 {
    let s = SteadyOptions {
        gear: o.gear.clone(),
        speed_rpm: rpm,
        torque_nm: torque,
        vehicle_speed_kmh: o.vehicle_speed_kmh,
        ambient_c: o.ambient_c,
    };
    steady(m, &s).unwrap().temperatures_c["oil"]
}

/// Rate `path` at `speeds` and check every rated point with an independent equilibrium: at the
/// rated torque within 0.01 K of the limit and not above it; 0.5 % more torque above the limit.
fn check_rated(path: &str, gear: &str, speeds: &[f64], limit: f64, vehicle_kmh: f64) {
    let m = model(path);
    let o = RatingOptions {
        vehicle_speed_kmh: vehicle_kmh,
        ..options(gear, speeds, limit)
    };
    let r = rating(&m, &o, &|| {}).unwrap();
    assert_eq!(r.points.len(), speeds.len());
    for p in &r.points {
        assert_eq!(
            p.status,
            Status::Rated,
            "{path} at {} rpm: {:?}",
            p.speed_rpm,
            p.status
        );
        assert!(!p.non_monotonic, "{path} at {} rpm", p.speed_rpm);
        let t = oil_at(&m, &o, p.speed_rpm, p.rated_torque_nm);
        assert!(
            (t - limit).abs() <= 0.01 && t <= limit + 1e-6,
            "{path} at {} rpm: equilibrium {t} °C at the rated {} N m, limit {limit} °C",
            p.speed_rpm,
            p.rated_torque_nm
        );
        assert!((p.oil_temp_c - t).abs() < 1e-6);
        let above = oil_at(&m, &o, p.speed_rpm, 1.005 * p.rated_torque_nm);
        assert!(
            above > limit,
            "{path} at {} rpm: 0.5 % more torque gives {above} °C",
            p.speed_rpm
        );
        let power = p.rated_torque_nm * p.speed_rpm * std::f64::consts::PI / 30.0;
        assert!((p.rated_power_w - power).abs() <= 1e-9 * power.max(1.0));
    }
}

#[test]
fn fzg_c_rated_torque_puts_the_oil_at_the_limit() {
    // 90 °C: the rig's cooler starts to open there; 100 °C: fully open; 80 °C: closed.
    check_rated("models/fzg_c.toml", "1", &[1000.0, 3000.0], 90.0, 0.0);
    check_rated("models/fzg_c.toml", "1", &[1500.0, 4500.0], 100.0, 0.0);
    check_rated("models/fzg_c.toml", "1", &[2000.0], 80.0, 0.0);
}

#[test]
fn the_limit_exceeded_at_zero_torque_rates_zero_with_its_flag() {
    let m = model("models/fzg_c.toml");
    let o = options("1", &[3000.0], 40.0);
    let r = rating(&m, &o, &|| {}).unwrap();
    let p = &r.points[0];
    assert_eq!(p.status, Status::LimitAtMinimum);
    assert_eq!(p.rated_torque_nm, 0.0);
    assert!(p.oil_temp_c > 40.0);
    assert_eq!(p.flags(), "limit_at_minimum");
    assert!(r.csv().lines().nth(1).unwrap().ends_with(",limit_at_minimum"));
}

#[test]
fn a_limit_not_reached_below_the_ceiling_rates_the_ceiling() {
    let m = model("models/fzg_c.toml");
    let o = RatingOptions {
        torque_max_nm: Some(20.0),
        ..options("1", &[1000.0], 100.0)
    };
    let r = rating(&m, &o, &|| {}).unwrap();
    let p = &r.points[0];
    assert_eq!(p.status, Status::Ceiling);
    assert_eq!(p.rated_torque_nm, 20.0);
    assert!(p.oil_temp_c < 100.0);
    // At rest nothing heats the oil: every torque is below the limit.
    let r = rating(&m, &options("1", &[0.0], 100.0), &|| {}).unwrap();
    assert_eq!(r.points[0].status, Status::Ceiling);
    assert_eq!(r.points[0].rated_torque_nm, 1e6);
}

#[test]
fn bad_options_are_refused_with_their_range() {
    let m = model("models/fzg_c.toml");
    let bad = [
        (
            options("1", &[3000.0], 250.0),
            "oil_limit_c = 250 °C: must lie in [-60, 200] °C",
        ),
        (options("1", &[], 90.0), "a rating takes 1 to 2000 speeds"),
        (options("1", &[-5.0], 90.0), "speed_rpm = -5 rpm"),
        (
            RatingOptions {
                torque_min_nm: 50.0,
                torque_max_nm: Some(50.0),
                ..options("1", &[3000.0], 90.0)
            },
            "must lie above torque_min_nm",
        ),
        (options("9", &[3000.0], 90.0), "unknown gear state"),
    ];
    for (o, msg) in bad {
        let e = rating(&m, &o, &|| {}).unwrap_err();
        assert!(e.is_invalid(), "{o:?}: {e}");
        assert!(e.message.contains(msg), "{o:?}: {}", e.message);
    }
}

#[test]
fn no_equilibrium_at_the_lowest_torque_is_a_numerical_failure_naming_the_point() {
    let m = model("models/fzg_c.toml");
    let o = RatingOptions {
        torque_min_nm: 5e5,
        ..options("1", &[6000.0], 100.0)
    };
    let e = rating(&m, &o, &|| {}).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Numerical);
    assert!(
        e.message.contains("at 6000 rpm failed at 500000 N m"),
        "{}",
        e.message
    );
}

fn cli(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .current_dir(root())
        .args(args)
        .output()
        .unwrap()
}

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|d| {
            d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    // The output directory's own marker is not a result.
    v.retain(|f| !f.starts_with('.'));
    v.sort();
    v
}

#[test]
fn the_cli_writes_the_curve_for_a_sweep_and_nothing_for_a_point() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("curve");
    let o = out.to_str().unwrap();
    let r = cli(&[
        "rating",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "1000:4000:4",
        "--oil-limit-c",
        "100",
        "--out",
        o,
        "--quiet",
    ]);
    assert_eq!(r.status.code(), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
    assert_eq!(files(&out), ["rating.csv", "rating.json", "rating.png"]);
    let csv = std::fs::read_to_string(out.join("rating.csv")).unwrap();
    assert_eq!(
        csv.lines().next().unwrap(),
        "speed_rpm,rated_torque_nm,rated_power_kw,oil_temp_c,loss_total_w,efficiency,flags"
    );
    assert_eq!(csv.lines().count(), 5);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("rating.json")).unwrap()).unwrap();
    assert_eq!(json["points"].as_array().unwrap().len(), 4);
    assert!(json["points"][0]["equilibrium"]["losses_w"].is_object());

    // One speed: printed, nothing written.
    let r = cli(&[
        "rating",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "3000",
        "--oil-limit-c",
        "100",
    ]);
    assert_eq!(r.status.code(), Some(0));
    let text = String::from_utf8_lossy(&r.stdout);
    assert!(
        text.contains("rated input torque") && text.contains("losses, W"),
        "{text}"
    );
    assert!(!root().join("ratings").join("fzg_c_gear1").exists());

    // Bad option: exit 1, nothing written; no equilibrium: exit 2 naming the point, nothing written.
    let bad = tmp.path().join("bad");
    let r = cli(&[
        "rating",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "0:3000:4",
        "--oil-limit-c",
        "300",
        "--out",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("oil_limit_c (--oil-limit-c) = 300"));
    assert!(!bad.exists());
    let r = cli(&[
        "rating",
        "models/fzg_c.toml",
        "--gear",
        "1",
        "--speed-rpm",
        "0:6000:4",
        "--oil-limit-c",
        "100",
        "--torque-min-nm",
        "500000",
        "--out",
        bad.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(r.status.code(), Some(2));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("rpm failed at 500000 N m: no equilibrium even at the lowest torque"),
        "{err}"
    );
    assert!(files(&bad).is_empty());
}
