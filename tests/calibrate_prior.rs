//! Priors and profile likelihoods of `calibrate`: a prior fixes what the trace does not (the
//! product h·A of a link), a wide prior leaves a determined parameter where the data put it, a
//! narrow one holds it; the influence is reported; bad priors are refused by the command with
//! the file, key path and value named and nothing written; the profile interval of a nearly
//! linear parameter agrees with the linearised one.

use std::path::Path;
use std::process::Command;

use geartherm::job::calibrate::{self, CalibrateOptions, CalibrateResult, Trace};
use geartherm::job::Model;

const MODEL: &str = "models/helical_stage.toml";
const H: &str = "thermal.links[\"oil-housing\"].h_w_per_m2k";
const A: &str = "thermal.links[\"oil-housing\"].area_m2";
const M: &str = "thermal.nodes[\"housing\"].mass_kg";

/// Rig trace over an hour every 60 s (four load steps), ambient 20 °C, oil and housing measured.
fn trace_text(values: &[Vec<f64>]) -> String {
    let mut s =
        String::from("time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:oil,node:housing\n");
    for (k, v) in values.iter().enumerate() {
        let (w, t) = match k / 15 {
            0 => (3000.0, 200.0),
            1 => (1500.0, 100.0),
            2 => (4000.0, 250.0),
            _ => (500.0, 50.0),
        };
        s.push_str(&format!("{},{w},{t},1,20,{},{}\n", k * 60, v[0], v[1]));
    }
    s
}

fn model(sets: &[&str]) -> (String, Model) {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let ovs: Vec<_> = sets.iter().map(|s| s.parse().unwrap()).collect();
    (
        text.clone(),
        Model::from_text(&text, Path::new(MODEL), &ovs).unwrap(),
    )
}

/// The model at h = 400 W/m²K and a housing of 11 kg from 30 °C, plus seeded Gaussian noise
/// of 0.1 K.
fn measured() -> String {
    let (text, m) = model(&[
        "thermal.initial_temp_c = 30.0",
        "thermal.links[\"oil-housing\"].h_w_per_m2k = 400.0",
        "thermal.nodes[\"housing\"].mass_kg = 11.0",
    ]);
    let flat = vec![vec![30.0, 30.0]; 61];
    let trace = Trace::parse(&trace_text(&flat), "truth").unwrap();
    let o = CalibrateOptions {
        initial_from_trace: false,
        ..CalibrateOptions::default()
    };
    let p = calibrate::prepare(&m, &text, &trace, &o).unwrap();
    let mut temps = p.problem.simulate(&[], false).unwrap().temps_c;
    let mut s: u64 = 11;
    let mut u = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    for row in temps.iter_mut().skip(1) {
        for v in row.iter_mut() {
            let (a, b) = (u(), u());
            *v += 0.1 * (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos();
        }
    }
    trace_text(&temps)
}

fn fit(fit: &[&str], prior: &[&str], profile: &[&str]) -> CalibrateResult {
    let (text, m) = model(&[]);
    let o = CalibrateOptions {
        fit: fit.iter().map(|s| s.to_string()).collect(),
        prior: prior.iter().map(|s| s.to_string()).collect(),
        profile: profile.iter().map(|s| s.to_string()).collect(),
        residuals: "independent".into(),
        ..CalibrateOptions::default()
    };
    let t = Trace::parse(&measured(), "measured.csv").unwrap();
    calibrate::calibrate(&m, &text, &t, &o).unwrap()
}

/// h and A enter as their product: without a prior neither has an interval; a log-normal prior
/// of 10 % on A (centred on the model's area, which the truth used) gives both one, A's is the
/// prior's own (share ≈ 1, width ratio ≈ 1) and h's contains the truth 400.
#[test]
fn a_prior_fixes_what_the_trace_does_not() {
    let r = fit(&[H, A, M], &[], &[]);
    assert!(r.summary.parameters[0].std_error.is_none());
    let area = r.summary.parameters[1].start;
    let prior = format!("{A}=lognormal:{area}:0.1");
    let r = fit(&[H, A, M], &[&prior], &[]);
    let p = &r.summary.parameters;
    let a = p[1].prior.as_ref().expect("A's prior reported");
    assert!(a.data_std_error.is_none() && a.prior_share == Some(1.0), "{a:?}");
    let ratio = a.width_ratio.unwrap();
    assert!((0.95..=1.0 + 1e-9).contains(&ratio), "{a:?}");
    let (lo, hi) = (p[0].ci95_low.unwrap(), p[0].ci95_high.unwrap());
    assert!(lo < 400.0 && 400.0 < hi && hi / lo < 1.6, "h in [{lo}, {hi}]");
    assert!(
        (p[0].value / 400.0 - 1.0).abs() < 0.05 && (p[1].value / area - 1.0).abs() < 0.01,
        "{p:?}"
    );
}

/// A wide prior on a determined parameter leaves it where the data put it (share below 1 %);
/// a narrow one holds it at the prior's mean and narrows its interval to about the prior's.
#[test]
fn a_priors_influence_is_reported() {
    let free = fit(&[H, M], &[], &[]);
    let m0 = free.summary.parameters[1].value;
    let wide = fit(&[H, M], &[&format!("{M}=normal:11:100")], &[]);
    let w = &wide.summary.parameters[1];
    let q = w.prior.as_ref().unwrap();
    assert!((w.value / m0 - 1.0).abs() < 1e-3, "{} vs {m0}", w.value);
    assert!(
        q.prior_share.unwrap() < 0.01 && q.width_ratio.unwrap() < 0.1,
        "{q:?}"
    );
    assert!((q.without_prior / m0 - 1.0).abs() < 1e-9);
    // A prior of 0.005 kg at 11.01 kg against data that fix the mass to about as much: the
    // value is the precision-weighted mean of the two (the model is nearly linear over that step).
    let narrow = fit(&[H, M], &[&format!("{M}=normal:11.01:0.005")], &[]);
    let n = &narrow.summary.parameters[1];
    let q = n.prior.as_ref().unwrap();
    let vd = (q.data_std_error.unwrap() * m0).powi(2);
    let vp = 0.005_f64.powi(2);
    let want = (m0 / vd + 11.01 / vp) / (1.0 / vd + 1.0 / vp);
    assert!((n.value - want).abs() < 5e-4, "{} vs {want}: {n:?}", n.value);
    let share = 1.0 - 1.0 / (1.0 + vd / vp);
    assert!((0.2..0.8).contains(&share), "{share}");
    assert!((q.prior_share.unwrap() - share).abs() < 0.02, "{q:?} vs {share}");
    let ratio = (1.0 / (1.0 + vp / vd)).sqrt();
    assert!((q.width_ratio.unwrap() - ratio).abs() < 0.02, "{q:?} vs {ratio}");
}

/// The housing mass is nearly linear in the temperatures: its profile interval lies within
/// 10 % of the linearised one's width of it, and the profile's minimum is at the fitted value.
#[test]
fn a_profile_agrees_with_the_linearised_interval_when_nearly_linear() {
    let r = fit(&[H, M], &[], &[M]);
    let p = &r.summary.parameters[1];
    let pr = &r.summary.profiles[0];
    assert_eq!(pr.key_path, *M);
    let (lo, hi) = (pr.ci95_low.unwrap(), pr.ci95_high.unwrap());
    let (wl, wh) = (p.ci95_low.unwrap(), p.ci95_high.unwrap());
    let width = wh - wl;
    assert!(
        (lo - wl).abs() < 0.1 * width && (hi - wh).abs() < 0.1 * width,
        "profile [{lo}, {hi}], linearised [{wl}, {wh}]"
    );
    let least = pr
        .points
        .iter()
        .min_by(|a, b| a.statistic.total_cmp(&b.statistic))
        .unwrap();
    assert!((least.value / p.value - 1.0).abs() < 1e-3, "{least:?} {p:?}");
    assert!(pr.points.len() >= 9 && pr.points.windows(2).all(|w| w[0].value < w[1].value));
}

/// Bad priors and profiles: exit 1 naming the key path (and the file), nothing written.
#[test]
fn bad_priors_are_refused_by_the_command() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("trace.csv");
    std::fs::write(&trace, measured()).unwrap();
    let priors = dir.path().join("priors.toml");
    std::fs::write(
        &priors,
        format!("[[prior]]\nkey = '{M}'\ndistribution = 'normal'\nmean = 11\nsd = 2\n\n[[prior]]\nkey = '{H}'\ndistribution = 'lognormal'\nmedian = 400\nsd_ln = -0.5\n"),
    )
    .unwrap();
    let t_fit = "thermal.nodes[\"housing\"].initial_temp_c=-10:60";
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec!["--prior".into(), format!("{M}=normal:11:-1")],
            vec![M, "-1", "> 0"],
        ),
        (
            vec!["--priors".into(), priors.display().to_string()],
            vec!["priors.toml: prior[1].sd_ln = -0.5"],
        ),
        (
            vec![
                "--fit".into(),
                t_fit.into(),
                "--prior".into(),
                "thermal.nodes[\"housing\"].initial_temp_c=lognormal:30:0.1".into(),
            ],
            vec!["initial_temp_c", "log-normal", "[-10, 60]"],
        ),
        (
            vec!["--prior".into(), format!("{A}=normal:1:0.1")],
            vec!["area_m2", "not a fitted parameter"],
        ),
        (
            vec!["--profile".into(), A.into()],
            vec!["profile", "area_m2", "not a fitted parameter"],
        ),
    ];
    for (extra, want) in cases {
        let out = dir.path().join("out");
        let o = Command::new(env!("CARGO_BIN_EXE_geartherm"))
            .args(["calibrate", MODEL, "--trace"])
            .arg(&trace)
            .args(["--fit", H, "--fit", M, "--residuals", "independent", "--out"])
            .arg(&out)
            .args(&extra)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {err}");
        for w in want {
            assert!(err.contains(w), "{extra:?}: no {w:?} in {err}");
        }
        assert!(!out.exists(), "{extra:?}: output written");
    }
}

/// A prediction (no fit, every row held out) takes its band from a previous calibration: the
/// half-width is at least t·σ of the residual process it carries, and the fraction inside is
/// reported; a run that fits, or a calibration without the trace's channel, is refused.
#[test]
fn a_prediction_takes_its_band_from_a_calibration() {
    let cal = fit(&[H, M], &[], &[]);
    let json = serde_json::to_string(&cal.summary).unwrap();
    let model = Model::from_text(&cal.calibrated_model, Path::new("calibrated.toml"), &[]).unwrap();
    let t = Trace::parse(&measured(), "other.csv").unwrap();
    let predict = CalibrateOptions {
        holdout: vec!["0:1e9".into()],
        residuals: "independent".into(),
        ..CalibrateOptions::default()
    };
    let mut p = calibrate::prepare(&model, &cal.calibrated_model, &t, &predict).unwrap();
    p.band_from(&json, "cal.json").unwrap();
    let r = calibrate::fit(&model, &p, &predict).unwrap();
    let sd = cal.summary.channels[0].noise.marginal_sd_k;
    // The band's multiplier is the calibration's, channel by channel.
    for (a, b) in r.summary.channels.iter().zip(&cal.summary.channels) {
        assert_eq!(
            (a.noise.band_multiplier, a.noise.band_quantile),
            (b.noise.band_multiplier, b.noise.band_quantile)
        );
    }
    let mult = cal.summary.channels[0].noise.band_multiplier;
    let inside = r.summary.channels[0]
        .holdout
        .unwrap()
        .inside_band95
        .expect("a band");
    assert!(inside > 0.8, "{inside}");
    for line in r.fit_csv.lines().skip(1) {
        let band: f64 = line.split(',').nth(5).unwrap().parse().unwrap();
        // fit.csv writes the band to 6 decimals: the floor multiplier·sd is compared as written.
        let floor = (mult * sd * 1e6).round() / 1e6;
        assert!(band >= floor, "{band} vs {floor}");
    }
    // Without --band-from the prediction has no band.
    let p = calibrate::prepare(&model, &cal.calibrated_model, &t, &predict).unwrap();
    let r = calibrate::fit(&model, &p, &predict).unwrap();
    assert!(r.summary.channels[0].holdout.unwrap().inside_band95.is_none());
    // Refused: a run that fits; a calibration that lacks the housing channel.
    let fits = CalibrateOptions {
        fit: vec![H.into()],
        ..CalibrateOptions::default()
    };
    let mut p = calibrate::prepare(&model, &cal.calibrated_model, &t, &fits).unwrap();
    let e = p.band_from(&json, "cal.json").unwrap_err();
    assert!(e.exit_code() == 1 && e.to_string().contains("band_from"), "{e}");
    let mut v: serde_json::Value = serde_json::from_str(&json).unwrap();
    // A calibration.json without multipliers gives its t quantile; a multiplier not above 0 is
    // refused, naming the file and the channel.
    for c in v["channels"].as_array_mut().unwrap() {
        c["noise"].as_object_mut().unwrap().remove("band_multiplier");
    }
    let mut p = calibrate::prepare(&model, &cal.calibrated_model, &t, &predict).unwrap();
    p.band_from(&v.to_string(), "cal.json").unwrap();
    let r = calibrate::fit(&model, &p, &predict).unwrap();
    assert_eq!(r.summary.channels[0].noise.band_multiplier, cal.summary.fit.t975);
    assert_eq!(r.summary.channels[0].noise.band_quantile, "t");
    v["channels"][0]["noise"]["band_multiplier"] = serde_json::json!(-1.0);
    let mut p = calibrate::prepare(&model, &cal.calibrated_model, &t, &predict).unwrap();
    let e = p.band_from(&v.to_string(), "cal.json").unwrap_err();
    assert!(
        e.exit_code() == 1
            && e.to_string()
                .contains("cal.json: channels (oil): band multiplier -1"),
        "{e}"
    );
    v["channels"][0]["noise"]
        .as_object_mut()
        .unwrap()
        .remove("band_multiplier");
    v["channels"].as_array_mut().unwrap().pop();
    let mut p = calibrate::prepare(&model, &cal.calibrated_model, &t, &predict).unwrap();
    let e = p.band_from(&v.to_string(), "cal.json").unwrap_err();
    assert!(
        e.to_string()
            .contains("cal.json: channels: no channel for node housing"),
        "{e}"
    );
}
