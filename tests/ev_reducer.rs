//! The bundled EV reducer (models/ev_reducer.toml): its ratio from "160 km/h at 16 000 rpm",
//! a single-gear vehicle with no engine over the WLTC with regenerative braking through the
//! reducer, the thermal rating at the oil limit within 0.01 K, and the range warnings at the
//! motor's top speed (a dipping gear above the dip-lubrication speed says so).

use std::path::PathBuf;

use geartherm::job::rating::{rating, RatingOptions, Status};
use geartherm::job::run::run;
use geartherm::job::steady::steady;
use geartherm::job::{Model, RunOptions, SteadyOptions};
use geartherm::model::Override;

const MODEL: &str = "models/ev_reducer.toml";

fn model(overrides: &[&str]) -> Model {
    let o: Vec<Override> = overrides.iter().map(|s| s.parse().unwrap()).collect();
    Model::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(MODEL), &o).unwrap()
}

#[test]
fn the_ratio_gives_160_kmh_at_16000_rpm() {
    let m = model(&[]);
    let ratio = m.gearbox.gear_states[0].ratio();
    assert!((ratio - (61.0 / 19.0) * (67.0 / 17.0)).abs() < 1e-9, "{ratio}");
    let r_w = m.gearbox.vehicle.as_ref().unwrap().wheel_radius;
    let kmh = 16000.0 * std::f64::consts::PI / 30.0 / ratio * r_w * 3.6;
    assert!((kmh - 160.0).abs() < 1.0, "{kmh} km/h at 16 000 rpm");
}

#[test]
fn wltc_runs_with_regenerative_braking_through_the_reducer() {
    let m = model(&[]);
    let o = RunOptions {
        cycle: "wltc".into(),
        ..RunOptions::default()
    };
    let r = run(&m, &o, &mut |_, _| {}).unwrap();
    let s = &r.summary;
    assert!(s.energy_balance_relative.abs() < 1e-9);
    let csv = r.timeseries_csv.as_deref().unwrap();
    let mut rows = csv.lines();
    let head: Vec<&str> = rows.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (tq, sp) = (col("input_torque_nm"), col("input_speed_rpm"));
    let (mut overrun, mut max_rpm) = (0, 0.0f64);
    for line in rows {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap_or(f64::NAN)).collect();
        if f[tq] < -1.0 {
            overrun += 1;
        }
        max_rpm = max_rpm.max(f[sp]);
    }
    // Braking is recuperation: a quarter of the WLTC's seconds carry negative torque.
    assert!(overrun > 300, "{overrun} overrun rows");
    // 131.3 km/h, the WLTC's top speed, with the ratio 12.65 and r_w 0.3364 m: about 13 100 rpm.
    assert!((12_900.0..13_300.0).contains(&max_rpm), "{max_rpm}");
    let eff = s.cycle_efficiency.unwrap();
    assert!((0.9..1.0).contains(&eff), "{eff}");
}

#[test]
fn ev_reducer_rated_torque_puts_the_oil_at_the_limit() {
    let m = model(&[]);
    let o = RatingOptions {
        gear: "D".into(),
        speed_rpm: vec![2000.0, 8000.0, 16000.0],
        oil_limit_c: 110.0,
        vehicle_speed_kmh: 0.0,
        ambient_c: None,
        torque_min_nm: 0.0,
        torque_max_nm: None,
    };
    let r = rating(&m, &o, &|| {}).unwrap();
    for p in &r.points {
        assert_eq!(p.status, Status::Rated, "{} rpm", p.speed_rpm);
        let s = SteadyOptions {
            gear: "D".into(),
            speed_rpm: p.speed_rpm,
            torque_nm: p.rated_torque_nm,
            vehicle_speed_kmh: 0.0,
            ambient_c: None,
        };
        let t = steady(&m, &s).unwrap().temperatures_c["oil"];
        assert!(
            (t - 110.0).abs() <= 0.01 && t <= 110.0 + 1e-6,
            "{} rpm: {t} °C",
            p.speed_rpm
        );
        let above = steady(
            &m,
            &SteadyOptions {
                torque_nm: 1.005 * p.rated_torque_nm,
                ..s
            },
        )
        .unwrap()
        .temperatures_c["oil"];
        assert!(above > 110.0, "{} rpm: {above} °C", p.speed_rpm);
    }
    // The motor's 310 N·m as the ceiling: at low speed the gearbox is not the limit.
    let r = rating(
        &m,
        &RatingOptions {
            speed_rpm: vec![1000.0],
            torque_max_nm: Some(310.0),
            ..o
        },
        &|| {},
    )
    .unwrap();
    assert_eq!(r.points[0].status, Status::Ceiling);
    assert_eq!(r.points[0].rated_torque_nm, 310.0);
}

fn dip_speed_warnings(m: &Model, rpm: f64) -> Vec<String> {
    let s = SteadyOptions {
        gear: "D".into(),
        speed_rpm: rpm,
        torque_nm: 20.0,
        vehicle_speed_kmh: 100.0,
        ambient_c: None,
    };
    steady(m, &s)
        .unwrap()
        .warnings
        .iter()
        .filter(|w| w.range.contains("dip lubrication"))
        .map(|w| format!("{}: {}", w.item, w.seen))
        .collect()
}

#[test]
fn churning_above_the_dip_lubrication_speed_says_so() {
    let m = model(&[]);
    // The output gear (pitch radius 108.4 mm) at 16 000 / 12.65 rpm: 14.4 m/s.
    let w = dip_speed_warnings(&m, 16000.0);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("churning of gear output_gear: pitch-line speed m/s 14.35"),
        "{w:?}"
    );
    // At 8000 rpm (7.2 m/s) it is inside.
    assert!(dip_speed_warnings(&m, 8000.0).is_empty());
    // Oil raised so that the intermediate wheel dips: at 16 000 rpm it turns at 4984 rpm,
    // 35 m/s at its pitch circle, far above dip lubrication.
    let m = model(&[
        "lubrication.oil_level_mm = 130.0",
        "lubrication.sump_volume_l = 2.5",
    ]);
    let w = dip_speed_warnings(&m, 16000.0);
    assert!(
        w.iter()
            .any(|x| x.starts_with("churning of gear intermediate_wheel: pitch-line speed m/s 35.1")),
        "{w:?}"
    );
}
