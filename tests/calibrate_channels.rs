//! Several measured channels in one calibration: each channel's noise is estimated and the fit
//! weights the channels by it (a quiet channel counts for more than a noisy one: the estimates
//! are closer to the truth than equal-weight least squares on the same traces); a channel or a
//! boundary column the model does not have is refused by the command, naming the file and the
//! column, and nothing is written.

#[path = "common/calibrate_rig.rs"]
mod rig;

use std::process::Command;

use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use rig::{model, Normal, Rig, H, M, MODEL};

const TRUTH: [f64; 2] = [400.0, 11.0];
/// Noise of the oil and the housing channel, K.
const NOISE: [f64; 2] = [0.2, 2.0];
/// Rig trace: four load steps over 2 h, a row every 60 s.
const RIG: Rig = Rig {
    rows: 121,
    step_s: 60,
    block: 30,
    loads: [(3000.0, 150.0), (1500.0, 100.0), (3000.0, 120.0), (500.0, 50.0)],
};

fn trace_text(values: Option<&[Vec<f64>]>) -> String {
    rig::trace_text(&RIG, values)
}

/// The two channels at the true values, every node from 30 °C.
fn exact() -> Vec<Vec<f64>> {
    rig::exact(&RIG, TRUTH)
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
