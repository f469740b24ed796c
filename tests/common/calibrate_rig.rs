//! Set-up shared by the calibration tests on synthetic rig traces of the helical stage: the
//! seeded normal generator, the trace text (four load steps, ambient 20 °C, oil and housing
//! measured) and the temperatures the model gives at known values of the oil–housing h and the
//! housing mass. Included with `#[path = "common/calibrate_rig.rs"] mod rig;`.
#![allow(dead_code)]

use std::path::Path;

use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use geartherm::job::Model;

pub const MODEL: &str = "models/helical_stage.toml";
pub const H: &str = "thermal.links[\"oil-housing\"].h_w_per_m2k";
pub const M: &str = "thermal.nodes[\"housing\"].mass_kg";

/// splitmix64 → standard normal by Box–Muller.
pub struct Normal(pub u64);

impl Normal {
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn sample(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// A rig trace's shape: `rows` rows `step_s` apart, the load (speed rpm, torque N·m) changing
/// every `block` rows through `loads` (the last one held to the end).
pub struct Rig {
    pub rows: usize,
    pub step_s: usize,
    pub block: usize,
    pub loads: [(f64, f64); 4],
}

/// The trace text of `rig`: the ambient at 20 °C, oil and housing "measured" with `values`
/// (°C per row and channel; 30 °C when None).
pub fn trace_text(rig: &Rig, values: Option<&[Vec<f64>]>) -> String {
    let mut s =
        String::from("time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:oil,node:housing\n");
    for k in 0..rig.rows {
        let (w, t) = rig.loads[(k / rig.block).min(3)];
        let (a, b) = values.map_or((30.0, 30.0), |v| (v[k][0], v[k][1]));
        s.push_str(&format!("{},{w},{t},1,20,{a},{b}\n", k * rig.step_s));
    }
    s
}

/// The model text and the model with the overrides `sets`.
pub fn model(sets: &[String]) -> (String, Model) {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let ovs: Vec<_> = sets.iter().map(|s| s.parse().unwrap()).collect();
    let m = Model::from_text(&text, Path::new(MODEL), &ovs).unwrap();
    (text, m)
}

/// Oil and housing temperatures at every row of `rig` at the true values `truth` (h, mass),
/// every node from 30 °C.
pub fn exact(rig: &Rig, truth: [f64; 2]) -> Vec<Vec<f64>> {
    let (text, m) = model(&[
        "thermal.initial_temp_c = 30.0".into(),
        format!("{H} = {}", truth[0]),
        format!("{M} = {}", truth[1]),
    ]);
    let trace = Trace::parse(&trace_text(rig, None), "truth").unwrap();
    let o = CalibrateOptions {
        initial_from_trace: false,
        ..CalibrateOptions::default()
    };
    calibrate::prepare(&m, &text, &trace, &o)
        .unwrap()
        .problem
        .simulate(&[], false)
        .unwrap()
        .temps_c
}

/// The calibrated model `calibrated` (TOML text) loses `loss_total_w` in gear 1 at 4000 rpm and
/// 250 N·m with oil at `oil_temp_c`, as the `losses` job computes it (to 1e-9 relative): the
/// plausibility report's rated point is the `losses` job's answer there.
pub fn assert_rated_loss_is_the_losses_job(calibrated: &str, oil_temp_c: f64, loss_total_w: f64) {
    use geartherm::job::losses::{losses, LossesOptions};
    let cal = Model::from_text(calibrated, Path::new("calibrated.toml"), &[]).unwrap();
    let options = LossesOptions {
        gear: "1".into(),
        speed_rpm: 4000.0,
        torque_nm: 250.0,
        oil_temp_c,
    };
    let direct = losses(&cal, &options).unwrap();
    assert!(
        (direct.total_w - loss_total_w).abs() < 1e-9 * direct.total_w,
        "{} vs {loss_total_w}",
        direct.total_w
    );
}
