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
            // 181 fitted rows with φ near 0.9 carry about 19 effective rows for a quantile of
            // |e|, fewer than the empirical band needs: the band is t's.
            assert_eq!(c.noise.band_quantile, "t", "{model}: {:?}", c.noise);
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

/// A longer rig trace (481 rows, 15 s apart, the same four 30-minute load steps): 363 fitted
/// rows per channel, enough for the empirical band multiplier (docs/calibration.md, "Prediction
/// bands").
const LONG: Rig = Rig {
    rows: 481,
    step_s: 15,
    block: 120,
    loads: [(3000.0, 150.0), (1500.0, 100.0), (3000.0, 120.0), (500.0, 50.0)],
};

/// Held-out points inside the band (fraction of all of them) over `repeats` seeded traces with
/// AR(1) noise of coefficient `phi` and stationary standard deviation 0.3 K, its innovations
/// Gaussian or uniform (bounded): (Gaussian band, empirical band, the empirical multipliers'
/// mean and how many channels used the empirical quantile).
fn band_coverage(phi: f64, uniform: bool, repeats: u64) -> (f64, f64, f64, usize) {
    let truth = [400.0, 11.0];
    let (text, m30) = rig::model(&["thermal.initial_temp_c = 30.0".into()]);
    let exact = rig::exact(&LONG, truth);
    let marginal = 0.3;
    let sd_a = marginal * (1.0f64 - phi * phi).sqrt();
    let (mut inside, mut held, mut mults, mut empirical) = ([0.0; 2], 0usize, Vec::new(), 0);
    for seed in 0..repeats {
        let mut rng = Normal(7000 + seed);
        // A uniform innovation on ±√3·σ_a has standard deviation σ_a.
        let mut innovation = || {
            if uniform {
                sd_a * 3f64.sqrt() * (2.0 * rng.uniform() - 1.0)
            } else {
                sd_a * rng.sample()
            }
        };
        let mut e = [0.0, 0.0];
        for _ in 0..200 {
            e = [phi * e[0] + innovation(), phi * e[1] + innovation()];
        }
        let noisy: Vec<Vec<f64>> = exact
            .iter()
            .map(|row| {
                let out = vec![row[0] + e[0], row[1] + e[1]];
                e = [phi * e[0] + innovation(), phi * e[1] + innovation()];
                out
            })
            .collect();
        let trace = Trace::parse(&rig::trace_text(&LONG, Some(&noisy)), "synthetic").unwrap();
        let mut fitted = Vec::new();
        for (k, how) in ["t", "empirical"].iter().enumerate() {
            let o = CalibrateOptions {
                fit: vec![format!("{H}=50:2000"), format!("{M}=2:60")],
                holdout: vec!["5430:7200".into()],
                initial_from_trace: false,
                band_quantile: (*how).into(),
                ..CalibrateOptions::default()
            };
            let r = calibrate::calibrate(&m30, &text, &trace, &o).unwrap();
            fitted.push(r.summary.parameters.iter().map(|p| p.value).collect::<Vec<_>>());
            for c in &r.summary.channels {
                let h = c.holdout.unwrap();
                inside[k] += h.inside_band95.unwrap() * h.rows as f64;
                held += k * h.rows;
                if k == 1 {
                    mults.push(c.noise.band_multiplier);
                    empirical += usize::from(c.noise.band_quantile == "empirical");
                } else {
                    assert_eq!(c.noise.band_quantile, "t");
                    assert_eq!(c.noise.band_multiplier, r.summary.fit.t975);
                }
            }
        }
        // The band's multiplier changes the band, not the fit.
        assert_eq!(fitted[0], fitted[1]);
    }
    let mean = mults.iter().sum::<f64>() / mults.len() as f64;
    let n = held as f64;
    (inside[0] / n, inside[1] / n, mean, empirical)
}

/// Bounded residuals (AR(1), φ = 0.3, uniform innovations: a platykurtic marginal, as a cooler's
/// sawtooth leaves): the Gaussian band t·sd covers more than 98 % of the held-out points, the
/// empirical band 93–97 %; with Gaussian innovations both cover 93–97 %.
#[test]
fn the_empirical_band_holds_on_bounded_residuals() {
    let repeats = 20;
    for uniform in [true, false] {
        let (gauss, emp, mult, used) = band_coverage(0.3, uniform, repeats);
        let kind = if uniform { "uniform" } else { "Gaussian" };
        println!(
            "AR(1) φ 0.3, {kind} innovations, {repeats} repeats: held-out points inside the Gaussian band {:.1} %, \
             the empirical band {:.1} % (mean multiplier {mult:.3}, empirical on {used} of {} channels)",
            100.0 * gauss,
            100.0 * emp,
            2 * repeats
        );
        assert_eq!(
            used,
            2 * repeats as usize,
            "{kind}: the empirical quantile on every channel"
        );
        assert!(
            (0.93..=0.97).contains(&emp),
            "{kind}: empirical band coverage {emp}"
        );
        if uniform {
            assert!(gauss > 0.98, "uniform: Gaussian band coverage {gauss}");
            assert!(mult < 1.9, "uniform: multiplier {mult}");
        } else {
            assert!((0.93..=0.97).contains(&gauss), "Gaussian band coverage {gauss}");
        }
    }
}
