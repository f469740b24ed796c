//! The AR(1) residual model on synthetic traces with autocorrelated noise (φ = 0.9 per row):
//! the 95 % intervals contain the true values in at least 90 of 100 seeded repeats (the
//! intervals of independent errors on the same traces are printed beside), and the 95 %
//! prediction band contains 90–98 % of the held-out points.

#[path = "common/calibrate_rig.rs"]
mod rig;

use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use geartherm::job::Model;
use rig::{Normal, Rig, H, M};

/// Rig trace: speed and torque steps every 30 min over 2 h, a row every 30 s.
const RIG: Rig = Rig {
    rows: 241,
    step_s: 30,
    block: 60,
    loads: [(3000.0, 150.0), (1500.0, 100.0), (3000.0, 120.0), (500.0, 50.0)],
};

fn trace_text(values: Option<&[Vec<f64>]>) -> String {
    rig::trace_text(&RIG, values)
}

/// The model text, the model with every node from 30 °C, and the oil and housing temperatures
/// at the true values `truth` (h, mass).
fn exact(truth: [f64; 2]) -> (String, Model, Vec<Vec<f64>>) {
    let (text, m30) = rig::model(&["thermal.initial_temp_c = 30.0".into()]);
    (text, m30, rig::exact(&RIG, truth))
}

#[test]
fn ar1_intervals_and_bands_cover() {
    for model in ["ar1", "ar1-gls"] {
        coverage(model);
    }
}

fn coverage(model: &str) {
    let truth = [400.0, 11.0];
    let (text, m30, exact) = exact(truth);
    let (phi, marginal) = (0.9, 0.3);
    let innovation = marginal * (1.0f64 - phi * phi).sqrt();
    let (mut ar1, mut ind) = ([0usize; 2], [0usize; 2]);
    let (mut inside, mut held, mut phis) = (0.0, 0usize, Vec::new());
    for seed in 0..100u64 {
        let mut rng = Normal(1000 + seed);
        let mut e = [marginal * rng.sample(), marginal * rng.sample()];
        let noisy: Vec<Vec<f64>> = exact
            .iter()
            .map(|row| {
                let out = vec![row[0] + e[0], row[1] + e[1]];
                for x in e.iter_mut() {
                    *x = phi * *x + innovation * rng.sample();
                }
                out
            })
            .collect();
        let trace = Trace::parse(&trace_text(Some(&noisy)), "synthetic").unwrap();
        let o = CalibrateOptions {
            fit: vec![format!("{H}=50:2000"), format!("{M}=2:60")],
            holdout: vec!["5430:7200".into()],
            initial_from_trace: false,
            residuals: model.into(),
            ..CalibrateOptions::default()
        };
        let r = calibrate::calibrate(&m30, &text, &trace, &o).unwrap();
        for (k, p) in r.summary.parameters.iter().enumerate() {
            let within = |lo: Option<f64>, hi: Option<f64>| (lo.unwrap()..=hi.unwrap()).contains(&truth[k]);
            ar1[k] += usize::from(within(p.ci95_low, p.ci95_high));
            ind[k] += usize::from(within(p.ci95_independent_low, p.ci95_independent_high));
        }
        for c in &r.summary.channels {
            let h = c.holdout.unwrap();
            inside += h.inside_band95.unwrap() * h.rows as f64;
            held += h.rows;
            phis.push(c.noise.phi);
        }
    }
    let band = inside / held as f64;
    let mean_phi = phis.iter().sum::<f64>() / phis.len() as f64;
    println!(
        "--residuals {model}: 95 % intervals containing the truth in 100 repeats: AR(1) model h {} / mass {}; \
         independent errors h {} / mass {}; held-out points inside the 95 % band: {:.1} % of {held}; mean \
         estimated φ {mean_phi:.3}",
        ar1[0],
        ar1[1],
        ind[0],
        ind[1],
        100.0 * band
    );
    assert!(ar1.iter().all(|&c| c >= 90), "{model}: coverage {ar1:?} of 100");
    assert!((0.90..=0.98).contains(&band), "{model}: band coverage {band}");
}

/// calibrated.toml carries the fitted parameters' covariance (a TOML table behind `# `), equal
/// to calibration.json's; an unknown residual model is refused.
#[test]
fn the_covariance_is_written_and_bad_options_refused() {
    let (text, m, exact) = exact([400.0, 11.0]);
    let mut rng = Normal(5);
    let values: Vec<Vec<f64>> = exact
        .iter()
        .map(|row| row.iter().map(|v| v + 0.2 * rng.sample()).collect())
        .collect();
    let trace = Trace::parse(&trace_text(Some(&values)), "synthetic").unwrap();
    let mut o = CalibrateOptions {
        fit: vec![format!("{H}=50:2000"), format!("{M}=2:60")],
        initial_from_trace: false,
        ..CalibrateOptions::default()
    };
    let r = calibrate::calibrate(&m, &text, &trace, &o).unwrap();
    let block: String = r
        .calibrated_model
        .lines()
        .skip_while(|l| *l != "# [calibration]")
        .map(|l| format!("{}\n", l.trim_start_matches("# ")))
        .collect();
    let doc: toml::Table = block.parse().unwrap();
    let cov = doc["calibration"]["covariance"].as_array().unwrap();
    let want = r.summary.covariance[0][1].unwrap();
    let got = cov[0].as_array().unwrap()[1].as_float().unwrap();
    assert!((got - want).abs() <= 1e-12 * want.abs(), "{got} {want}");
    o.residuals = "ar2".into();
    let e = calibrate::calibrate(&m, &text, &trace, &o).unwrap_err();
    assert!(
        e.exit_code() == 1 && e.to_string().contains("residuals = ar2"),
        "{e}"
    );
}
