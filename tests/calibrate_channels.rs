//! Several measured channels in one calibration: each channel's noise is estimated and the fit
//! weights the channels by it (a quiet channel counts for more than a noisy one: the estimates
//! are closer to the truth than equal-weight least squares on the same traces); a channel or a
//! boundary column the model does not have is refused by the command, naming the file and the
//! column, and nothing is written.

use std::path::Path;
use std::process::Command;

use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use geartherm::job::Model;

const MODEL: &str = "models/helical_stage.toml";
const H: &str = "thermal.links[\"oil-housing\"].h_w_per_m2k";
const M: &str = "thermal.nodes[\"housing\"].mass_kg";
const ROWS: usize = 121;
const TRUTH: [f64; 2] = [400.0, 11.0];
/// Noise of the oil and the housing channel, K.
const NOISE: [f64; 2] = [0.2, 2.0];

/// splitmix64 → standard normal by Box–Muller.
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn sample(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// Rig trace: four load steps over 2 h, a row every 60 s, ambient 20 °C, oil and housing
/// measured (`values`, 30 °C when None).
fn trace_text(values: Option<&[Vec<f64>]>) -> String {
    let mut s =
        String::from("time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:oil,node:housing\n");
    for k in 0..ROWS {
        let (w, t) = match k / 30 {
            0 => (3000.0, 150.0),
            1 => (1500.0, 100.0),
            2 => (3000.0, 120.0),
            _ => (500.0, 50.0),
        };
        let (a, b) = values.map_or((30.0, 30.0), |v| (v[k][0], v[k][1]));
        s.push_str(&format!("{},{w},{t},1,20,{a},{b}\n", k * 60));
    }
    s
}

fn model(sets: &[String]) -> (String, Model) {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let ovs: Vec<_> = sets.iter().map(|s| s.parse().unwrap()).collect();
    (
        text.clone(),
        Model::from_text(&text, Path::new(MODEL), &ovs).unwrap(),
    )
}

/// The two channels at the true values, every node from 30 °C.
fn exact() -> Vec<Vec<f64>> {
    let (text, m) = model(&[
        "thermal.initial_temp_c = 30.0".into(),
        format!("{H} = {}", TRUTH[0]),
        format!("{M} = {}", TRUTH[1]),
    ]);
    let trace = Trace::parse(&trace_text(None), "truth").unwrap();
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

/// Fitted (h, mass) and the channels' innovation standard deviations, K.
fn fit(measured: &[Vec<f64>], residuals: &str) -> ([f64; 2], Vec<f64>) {
    let (text, m) = model(&["thermal.initial_temp_c = 30.0".into()]);
    let trace = Trace::parse(&trace_text(Some(measured)), "noisy").unwrap();
    let o = CalibrateOptions {
        fit: vec![format!("{H}=10:5000"), format!("{M}=1:200")],
        residuals: residuals.into(),
        initial_from_trace: false,
        ..CalibrateOptions::default()
    };
    let r = calibrate::calibrate(&m, &text, &trace, &o).unwrap();
    let p = &r.summary.parameters;
    let sd = r
        .summary
        .channels
        .iter()
        .map(|c| c.noise.innovation_sd_k)
        .collect();
    ([p[0].value, p[1].value], sd)
}

#[test]
fn a_quiet_channel_counts_for_more_than_a_noisy_one() {
    let exact = exact();
    let (mut weighted, mut equal) = (0.0, 0.0);
    let repeats = 12;
    for seed in 0..repeats {
        let mut g = Normal(1000 + seed);
        let noisy: Vec<Vec<f64>> = exact
            .iter()
            .enumerate()
            .map(|(k, row)| {
                (0..2)
                    .map(|c| row[c] + if k == 0 { 0.0 } else { NOISE[c] * g.sample() })
                    .collect()
            })
            .collect();
        let (w, sd) = fit(&noisy, "ar1");
        // Each channel's noise is its own (independent noise: φ near 0, σ_a near the truth).
        for c in 0..2 {
            assert!(
                (sd[c] / NOISE[c] - 1.0).abs() < 0.3,
                "seed {seed}: channel {c} noise {} against {}",
                sd[c],
                NOISE[c]
            );
        }
        let (e, _) = fit(&noisy, "independent");
        let err = |x: [f64; 2]| (0..2).map(|k| (x[k] / TRUTH[k]).ln().powi(2)).sum::<f64>();
        weighted += err(w);
        equal += err(e);
    }
    let (weighted, equal) = (
        (weighted / repeats as f64).sqrt(),
        (equal / repeats as f64).sqrt(),
    );
    println!("rms error of ln(h), ln(mass): weighted {weighted:.4}, equal weights {equal:.4}");
    assert!(
        weighted < 0.5 * equal,
        "weighted {weighted} not clearly below equal weights {equal}"
    );
}

/// A channel or a boundary the model does not have: exit 1 naming the file and the column, and
/// the nodes (boundaries) the model has; nothing written.
#[test]
fn channels_not_in_the_model_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let good = trace_text(None);
    let cases = [
        (
            good.replace(",node:housing", ",node:bearing_1"),
            vec!["node:bearing_1", "no capacity node \"bearing_1\"", "oil, housing"],
        ),
        (
            good.replace("node:oil,node:housing", "node:oil,node:inlet"),
            vec!["node:inlet", "no capacity node \"inlet\""],
        ),
        (
            good.replace("boundary:ambient", "boundary:nacelle"),
            vec!["boundary:nacelle", "no boundary \"nacelle\"", "ambient"],
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        let trace = dir.path().join(format!("trace{k}.csv"));
        std::fs::write(&trace, text).unwrap();
        let out = dir.path().join(format!("out{k}"));
        let o = Command::new(env!("CARGO_BIN_EXE_geartherm"))
            .args(["calibrate", MODEL, "--trace"])
            .arg(&trace)
            .args(["--fit", H, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "case {k}: {err}");
        assert!(
            err.contains(&format!("trace{k}.csv")),
            "case {k}: no file in {err}"
        );
        for w in want {
            assert!(err.contains(w), "case {k}: no {w:?} in {err}");
        }
        assert!(!out.exists(), "case {k}: output written");
    }
}
