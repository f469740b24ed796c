//! The plausibility report of `calibrate`: the calibrated model's losses per source and its
//! efficiency at the trace's highest-power rows and at a rated point, the same numbers the
//! `losses` job gives there, and a warning when a sourced figure for the gearbox kind is missed.

#[path = "common/calibrate_rig.rs"]
mod rig;

use std::path::Path;

use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use geartherm::job::Model;

const MODEL: &str = "models/helical_stage.toml";
const H: &str = "thermal.links[\"oil-housing\"].h_w_per_m2k";

/// Rig trace: an hour every 60 s in four load steps, the third (4000 rpm, 250 N m) the highest
/// power; oil and housing "measured" at a plausible warm-up.
fn trace() -> String {
    let mut s =
        String::from("time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:oil,node:housing\n");
    for k in 0..61 {
        let (w, t) = match k / 15 {
            0 => (3000.0, 200.0),
            1 => (1500.0, 100.0),
            2 => (4000.0, 250.0),
            _ => (500.0, 50.0),
        };
        let x = 30.0 + 20.0 * (1.0 - (-(k as f64) / 20.0).exp());
        s.push_str(&format!("{},{w},{t},1,20,{x},{}\n", k * 60, x - 2.0));
    }
    s
}

#[test]
fn losses_at_the_highest_power_and_at_a_rated_point() {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let m = Model::from_text(&text, Path::new(MODEL), &[]).unwrap();
    let t = Trace::parse(&trace(), "warm.csv").unwrap();
    let o = CalibrateOptions {
        fit: vec![H.into()],
        gearbox_kind: Some("wind-turbine".into()),
        rated: Some("4000:250".into()),
        ..CalibrateOptions::default()
    };
    let r = calibrate::calibrate(&m, &text, &t, &o).unwrap();
    let p = r
        .summary
        .plausibility
        .as_ref()
        .expect("a rig trace measuring the oil");
    // 1 % of 61 rows: one row, at 4000 rpm and 250 N m.
    assert_eq!(p.rows, 1);
    let hp = &p.highest_power;
    assert!((hp.input_speed_rpm - 4000.0).abs() < 1e-6 && (hp.input_torque_nm - 250.0).abs() < 1e-9);
    let sum: f64 = hp.loss_by_source_w.iter().map(|(_, v)| v).sum();
    assert!((sum - hp.loss_total_w).abs() < 1e-9 * hp.loss_total_w.abs().max(1.0));
    let eta = hp.power_w / (hp.power_w + hp.loss_total_w);
    assert!((hp.efficiency.unwrap() - eta).abs() < 1e-12);
    // The rated point: the same losses as `losses` on the calibrated model at that oil temperature.
    let rated = p.rated.as_ref().unwrap();
    rig::assert_rated_loss_is_the_losses_job(&r.calibrated_model, rated.oil_temp_c, rated.loss_total_w);
    // The reference: a share outside 1.5–6 % is warned, inside is not.
    let rf = p.reference.as_ref().unwrap();
    let share = rated.loss_total_w / rated.power_w;
    assert!((rf.loss_share - share).abs() < 1e-12);
    assert_eq!(rf.inside, (0.015..=0.06).contains(&share));
    let warned = r.summary.warnings.iter().any(|w| w.starts_with("plausibility:"));
    assert_eq!(warned, !rf.inside, "{share}: {:?}", r.summary.warnings);
}

#[test]
fn an_unknown_kind_or_a_bad_rated_point_is_refused() {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let m = Model::from_text(&text, Path::new(MODEL), &[]).unwrap();
    let t = Trace::parse(&trace(), "warm.csv").unwrap();
    for (kind, rated, want) in [
        (Some("ship"), None, "gearbox_kind = ship"),
        (None, Some("0:100"), "rated = 0:100"),
        (None, Some("4000"), "rated = 4000"),
    ] {
        let o = CalibrateOptions {
            fit: vec![H.into()],
            gearbox_kind: kind.map(String::from),
            rated: rated.map(String::from),
            ..CalibrateOptions::default()
        };
        let e = calibrate::calibrate(&m, &text, &t, &o).unwrap_err();
        assert_eq!(e.exit_code(), 1);
        assert!(e.to_string().contains(want), "{e}");
    }
}
