//! The options of a single-segment calibration over several traces: `--residuals ar1-gls`
//! (each channel's AR(1) process shared by every segment, each segment whitened from its own
//! first row), priors on a shared and on a per-trace parameter (`KEY@TRACE`), profiles, the
//! calibrated losses per trace (`--rated`, `--gearbox-kind`) and `--band-from` for a prediction
//! of several traces from a calibration over several; bad input through the command (exit 1,
//! nothing written).

#[path = "common/calibrate_rig.rs"]
mod rig;

use std::path::{Path, PathBuf};
use std::process::Command;

use geartherm::job::calibrate::{self, lm::Evaluation, residuals::Ar1, stack, stack_fit, trace_file};
use geartherm::job::calibrate::{CalibrateOptions, CalibrateResult, Missing, Trace};
use geartherm::job::Model;
use nalgebra::{DMatrix, DVector};
use rig::{Normal, Rig, H, M, MODEL};

fn shape(reverse: bool) -> Rig {
    let mut loads = [(3000.0, 200.0), (1500.0, 100.0), (4000.0, 250.0), (500.0, 50.0)];
    if reverse {
        loads.reverse();
    }
    Rig {
        rows: 61,
        step_s: 60,
        block: 15,
        loads,
    }
}

/// One segment measured from the model with h = 400 W/m²K and the housing `mass`, AR(1) noise
/// of coefficient `phi` and stationary standard deviation `sd` (none on the first row: it sets
/// the start), its times from `t0`.
fn segment(
    mass: f64,
    reverse: bool,
    (phi, sd): (f64, f64),
    rng: &mut Normal,
    t0: f64,
    header: bool,
) -> String {
    let r = shape(reverse);
    let mut v = rig::exact(&r, [400.0, mass]);
    let mut e = [0.0; 2];
    for (k, row) in v.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            e[c] = if k == 0 {
                sd * rng.sample()
            } else {
                phi * e[c] + sd * (1.0 - phi * phi).sqrt() * rng.sample()
            };
            if k > 0 {
                *x += e[c];
            }
        }
    }
    let text = rig::trace_text(&r, Some(&v));
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        if i == 0 {
            if header {
                out.push_str(line);
                out.push('\n');
            }
            continue;
        }
        let (t, rest) = line.split_once(',').unwrap();
        let t: f64 = t.parse().unwrap();
        out.push_str(&format!("{},{rest}\n", t + t0));
    }
    out
}

/// A trace file of two segments a day apart: the load steps, then reversed.
fn two_segments(mass: f64, noise: (f64, f64), seed: u64) -> String {
    let mut rng = Normal(seed);
    segment(mass, false, noise, &mut rng, 0.0, true) + &segment(mass, true, noise, &mut rng, 90_000.0, false)
}

fn model() -> (String, Model) {
    rig::model(&[])
}

fn files(noise: (f64, f64)) -> Vec<(String, trace_file::TraceFile)> {
    vec![
        (
            "a".to_string(),
            trace_file::read(&two_segments(11.0, noise, 3), "a.csv", Missing::Drop).unwrap(),
        ),
        (
            "b".to_string(),
            trace_file::read(&two_segments(20.0, noise, 9), "b.csv", Missing::Drop).unwrap(),
        ),
    ]
}

fn fit_stack(files: &[(String, trace_file::TraceFile)], o: &CalibrateOptions) -> CalibrateResult {
    let (text, m) = model();
    let inputs = stack::inputs(files, o).unwrap();
    stack_fit::calibrate_traces(&m, &text, &inputs, o).unwrap()
}

fn param<'a>(r: &'a CalibrateResult, key: &str) -> &'a geartherm::report::calibration::FittedParameter {
    r.summary
        .parameters
        .iter()
        .find(|p| p.key_path == key)
        .unwrap_or_else(|| panic!("{key}"))
}

/// `ar1-gls` over a stack of one segment is the single-segment fit (to the bit); over two
/// traces of two segments each the fit recovers the truth, φ is estimated near the noise's,
/// and every segment's first row is whitened as a stationary start (no difference across a
/// boundary).
#[test]
fn ar1_gls_over_segments() {
    let (text, m) = model();
    let o = CalibrateOptions {
        fit: vec![H.into(), format!("{M}=2:60")],
        residuals: "ar1-gls".into(),
        ..CalibrateOptions::default()
    };
    let mut rng = Normal(21);
    let csv = segment(11.0, false, (0.8, 0.15), &mut rng, 0.0, true);
    let single = calibrate::calibrate(&m, &text, &Trace::parse(&csv, "t.csv").unwrap(), &o).unwrap();
    let one = vec![(
        "t".to_string(),
        trace_file::read(&csv, "t.csv", Missing::Drop).unwrap(),
    )];
    let stacked = fit_stack(&one, &o);
    for (a, b) in single.summary.parameters.iter().zip(&stacked.summary.parameters) {
        assert_eq!((a.value, a.std_error), (b.value, b.std_error));
    }
    assert_eq!(
        single.summary.channels[0].noise.phi,
        stacked.summary.channels[0].noise.phi
    );

    let fs = files((0.8, 0.15));
    let o = CalibrateOptions {
        fit: vec![H.into(), format!("{M}@*=2:60")],
        residuals: "ar1-gls".into(),
        ..CalibrateOptions::default()
    };
    let r = fit_stack(&fs, &o);
    assert_eq!(r.summary.fit.residual_model, "ar1-gls");
    for (key, truth) in [
        (H.to_string(), 400.0),
        (format!("{M}@a"), 11.0),
        (format!("{M}@b"), 20.0),
    ] {
        let p = param(&r, &key);
        let (lo, hi) = (p.ci95_low.unwrap(), p.ci95_high.unwrap());
        assert!(lo <= truth && truth <= hi, "{p:?}");
    }
    for c in &r.summary.channels {
        assert!(c.noise.phi > 0.55 && c.noise.phi < 0.97, "{c:?}");
    }
    // Whitening of the stacked rows: the first row of each of the four segments is
    // √(1 − φ²)·r/σ_a, every other row (r_t − φ r_{t−1})/σ_a.
    let inputs = stack::inputs(&fs, &o).unwrap();
    let s = stack::prepare(&m, &text, &inputs, &o).unwrap();
    let layout = s.layout();
    let n = layout.stretch.len() * 2;
    let e = Evaluation {
        r: DVector::from_element(n, 1.0),
        j: DMatrix::zeros(n, 3),
    };
    let a = Ar1 { phi: 0.5, sigma: 1.0 };
    let w = layout.whiten(&e, &[a, a]);
    for row in 0..layout.stretch.len() {
        let want = if row % 61 == 0 { 0.75_f64.sqrt() } else { 0.5 };
        assert!((w.r[2 * row] - want).abs() < 1e-12, "row {row}: {}", w.r[2 * row]);
    }
}

/// A wide prior on the shared h leaves it where the data put it; a narrow prior on trace b's
/// own mass holds it at the prior's mean; trace a's mass, without a prior, is the data's.
#[test]
fn priors_on_shared_and_per_trace_parameters() {
    let fs = files((0.0, 0.1));
    let wide = CalibrateOptions {
        fit: vec![H.into(), format!("{M}@*=2:60")],
        prior: vec![format!("{H}=lognormal:400:5")],
        ..CalibrateOptions::default()
    };
    let r = fit_stack(&fs, &wide);
    let h = param(&r, H);
    let hp = h.prior.as_ref().expect("h's prior");
    assert!(hp.prior_share.unwrap() < 0.01, "{hp:?}");
    assert!((h.value / hp.without_prior - 1.0).abs() < 1e-3, "{h:?}");
    let o = CalibrateOptions {
        prior: vec![format!("{M}@b=normal:19:0.0005")],
        ..wide
    };
    let r = fit_stack(&fs, &o);
    let mb = param(&r, &format!("{M}@b"));
    let q = mb.prior.as_ref().expect("b's prior");
    assert!((mb.value - 19.0).abs() < 0.05, "{mb:?}");
    assert!((q.without_prior - 20.0).abs() < 1.0, "{q:?}");
    assert!(q.prior_share.unwrap() > 0.9, "{q:?}");
    let ma = param(&r, &format!("{M}@a"));
    assert!(ma.prior.is_none());
    assert!((ma.value / 11.0 - 1.0).abs() < 0.05, "{ma:?}");
    let text = geartherm::report::calibration::to_text(&r.summary);
    assert!(
        text.contains(&format!("prior {M}@b normal(19, 0.0005)")),
        "{text}"
    );
    // A prior on a trace that does not exist, or on a key fitted per trace named as shared.
    let (mtext, m) = model();
    for (prior, want) in [
        (format!("{M}@c=normal:15:1"), "no trace is named \"c\""),
        (
            format!("{M}=normal:15:1"),
            "not fitted as a parameter shared by every trace",
        ),
    ] {
        let o = CalibrateOptions {
            prior: vec![prior.clone()],
            ..o.clone()
        };
        let inputs = stack::inputs(&fs, &o).unwrap();
        let e = stack::prepare(&m, &mtext, &inputs, &o).err().expect("refused");
        assert_eq!(e.exit_code(), 1);
        assert!(
            e.to_string().contains(want) && e.to_string().contains(&prior),
            "{e}"
        );
    }
}

/// The profile likelihoods of a shared and of a per-trace parameter over the stack: their 95 %
/// intervals contain the fitted value and agree with the linearised ones within 25 % of the
/// width (the parameters are nearly linear on these traces).
#[test]
fn profiles_of_shared_and_per_trace_parameters() {
    let fs = files((0.0, 0.1));
    let o = CalibrateOptions {
        fit: vec![H.into(), format!("{M}@*=2:60")],
        profile: vec![H.into(), format!("{M}@a")],
        residuals: "independent".into(),
        ..CalibrateOptions::default()
    };
    let r = fit_stack(&fs, &o);
    assert_eq!(r.summary.profiles.len(), 2);
    for pr in &r.summary.profiles {
        let p = param(&r, &pr.key_path);
        let (lo, hi) = (pr.ci95_low.unwrap(), pr.ci95_high.unwrap());
        assert!(lo < p.value && p.value < hi, "{pr:?}");
        let (a, b) = (p.ci95_low.unwrap(), p.ci95_high.unwrap());
        let w = b - a;
        assert!(
            (lo - a).abs() < 0.25 * w && (hi - b).abs() < 0.25 * w,
            "{pr:?} vs [{a}, {b}]"
        );
    }
    assert!(r.files().unwrap().iter().any(|(n, _)| n == "profile.csv"));
}

/// With a parameter per trace each trace's calibrated model has its own losses: at its
/// highest-power rows and at the rated point, the rated losses those of the `losses` job on
/// its `calibrated_<trace>.toml`; with every parameter shared one report over every trace.
#[test]
fn losses_per_trace_at_the_rated_point() {
    let fs = files((0.0, 0.1));
    let o = CalibrateOptions {
        fit: vec![H.into(), format!("{M}@*=2:60")],
        rated: Some("4000:250".into()),
        gearbox_kind: Some("wind-turbine".into()),
        ..CalibrateOptions::default()
    };
    let r = fit_stack(&fs, &o);
    assert!(r.summary.plausibility.is_none());
    for (t, (_, model)) in r.summary.traces.iter().zip(&r.per_trace_models) {
        let p = t.plausibility.as_ref().expect("a trace's losses");
        // 1 % of 122 rows: two rows, both at 4000 rpm and 250 N m.
        assert_eq!(p.rows, 2);
        assert!((p.highest_power.input_speed_rpm - 4000.0).abs() < 1e-6);
        let rated = p.rated.as_ref().unwrap();
        rig::assert_rated_loss_is_the_losses_job(model, rated.oil_temp_c, rated.loss_total_w);
        let rf = p.reference.as_ref().unwrap();
        let warned = r
            .summary
            .warnings
            .iter()
            .any(|w| w.starts_with(&format!("trace {}: plausibility:", t.name)));
        assert_eq!(warned, !rf.inside, "{:?}", r.summary.warnings);
    }
    let (a, b) = (
        r.summary.traces[0].plausibility.as_ref().unwrap(),
        r.summary.traces[1].plausibility.as_ref().unwrap(),
    );
    assert_ne!(a.highest_power.oil_temp_c, b.highest_power.oil_temp_c);
    let text = geartherm::report::calibration::to_text(&r.summary);
    assert!(
        text.contains("trace a: rated point") && text.contains("trace b: rated point"),
        "{text}"
    );
    // Every parameter shared: one report over the rows of every trace.
    let o = CalibrateOptions {
        fit: vec![H.into()],
        ..o
    };
    let r = fit_stack(&fs, &o);
    let p = r.summary.plausibility.as_ref().expect("one report");
    assert_eq!(p.rows, 3);
    assert!(r.summary.traces.iter().all(|t| t.plausibility.is_none()));
}

// --- through the command -------------------------------------------------------------------

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "geartherm_calibrate_traces_options_{name}_{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `calibrate MODEL ARGS --out OUT`: exit code, stdout, stderr, whether OUT exists.
fn cli(model: &str, args: &[&str], out: &Path) -> (i32, String, String, bool) {
    let o = Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .arg("calibrate")
        .arg(model)
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        out.exists(),
    )
}

fn write_traces(d: &Path) -> (String, String) {
    let (a, b) = (d.join("a.csv"), d.join("b.csv"));
    std::fs::write(&a, two_segments(11.0, (0.0, 0.1), 3)).unwrap();
    std::fs::write(&b, two_segments(20.0, (0.0, 0.1), 9)).unwrap();
    (a.display().to_string(), b.display().to_string())
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A prediction of several traces takes each trace's band from a calibration over several
/// (trace X's own parameters and the shared ones): the fraction inside the band per trace,
/// printed; a trace the calibration has no parameters of is refused naming it.
#[test]
fn bands_of_several_traces_from_a_calibration_over_several() {
    let d = dir("bands");
    let (a, b) = write_traces(&d);
    let cal = d.join("cal");
    let m_each = format!("--fit={M}@*=2:60");
    let (code, _, err, _) = cli(
        MODEL,
        &["--trace", &a, "--trace", &b, &format!("--fit={H}"), &m_each],
        &cal,
    );
    assert_eq!(code, 0, "{err}");
    let band = cal.join("calibration.json");
    let band = band.to_str().unwrap();
    let model_a = cal.join("calibrated_a.toml");
    let model_a = model_a.to_str().unwrap();
    let out = d.join("predict");
    let hold = "--holdout=0:1e9";
    let (code, stdout, err, _) = cli(
        model_a,
        &["--trace", &a, "--trace", &b, hold, "--band-from", band],
        &out,
    );
    assert_eq!(code, 0, "{err}");
    let j = json(&out.join("calibration.json"));
    let fitted = json(&cal.join("calibration.json"));
    // Each trace's band multiplier is that of the calibration's trace of the same name.
    let mut least = f64::INFINITY;
    for t in j["traces"].as_array().unwrap() {
        let own = fitted["traces"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["name"] == t["name"])
            .unwrap();
        for (c, o) in t["channels"]
            .as_array()
            .unwrap()
            .iter()
            .zip(own["channels"].as_array().unwrap())
        {
            let inside = c["holdout"]["inside_band95"].as_f64().expect("a band");
            assert!(inside > 0.7, "{t}");
            assert_eq!(
                c["noise"]["band_multiplier"], o["noise"]["band_multiplier"],
                "{t}"
            );
            least = least.min(o["noise"]["band_multiplier"].as_f64().unwrap());
        }
    }
    assert!(
        stdout.contains("0 a: oil") && stdout.contains("1 b: oil"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(out.join("fit.csv")).unwrap();
    let sd = json(&cal.join("calibration.json"))["channels"][0]["noise"]["marginal_sd_k"]
        .as_f64()
        .unwrap();
    for line in csv.lines().skip(1) {
        let band: f64 = line.split(',').nth(7).unwrap().parse().unwrap();
        assert!(band >= least * sd * (1.0 - 1e-5), "{line}: {least} {sd}");
    }
    // One segment of trace a, predicted alone: a's parameters.
    let (code, _, err, _) = cli(
        model_a,
        &["--trace", &a, "--segment", "1", hold, "--band-from", band],
        &d.join("one"),
    );
    assert_eq!(code, 0, "{err}");
    // A trace the calibration has no parameters of: refused naming it, nothing written.
    let c = d.join("c.csv");
    std::fs::copy(&a, &c).unwrap();
    let out = d.join("refused");
    let (code, _, err, written) = cli(
        model_a,
        &[
            "--trace",
            &a,
            "--trace",
            c.to_str().unwrap(),
            hold,
            "--band-from",
            band,
        ],
        &out,
    );
    assert_eq!((code, written), (1, false), "{err}");
    assert!(
        err.contains("trace c") && err.contains("calibration.json"),
        "{err}"
    );
    // A run that fits is refused too.
    let (code, _, err, written) = cli(
        model_a,
        &[
            "--trace",
            &a,
            "--trace",
            &b,
            &format!("--fit={H}"),
            "--band-from",
            band,
        ],
        &out,
    );
    assert_eq!((code, written), (1, false), "{err}");
    assert!(err.contains("band_from") || err.contains("band-from"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Bad options over several traces through the command: a priors file with a negative width
/// (the file and key path named), a profile of a trace that does not exist, a prior on a
/// parameter not fitted for that trace, a bad rated point; exit 1, nothing written.
#[test]
fn bad_options_over_several_traces_are_refused() {
    let d = dir("bad");
    let (a, b) = write_traces(&d);
    let priors = d.join("priors.toml");
    std::fs::write(
        &priors,
        format!("[[prior]]\nkey = '{M}@b'\ndistribution = 'normal'\nmean = 15.0\nsd = -1.0\n"),
    )
    .unwrap();
    let p = priors.to_str().unwrap();
    let base = [
        "--trace",
        &a,
        "--trace",
        &b,
        &format!("--fit={H}"),
        &format!("--fit={M}@*=2:60"),
    ];
    let out = d.join("out");
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec!["--priors".into(), p.into()],
            vec!["priors.toml", "prior[0].sd = -1"],
        ),
        (vec![format!("--prior={M}@a=normal:15:-2")], vec!["prior", "> 0"]),
        (
            vec![format!("--profile={M}@c")],
            vec!["profile", "no trace is named \"c\""],
        ),
        (
            vec![
                format!("--prior={M}@0=lognormal:10:0.5"),
                format!("--prior={M}@a=normal:10:1"),
            ],
            vec!["two priors"],
        ),
        (vec!["--rated=0:100".into()], vec!["rated", "= 0:100"]),
        (vec!["--gearbox-kind=ship".into()], vec!["gearbox_kind", "ship"]),
    ];
    for (extra, words) in cases {
        let mut args: Vec<&str> = base.to_vec();
        args.extend(extra.iter().map(String::as_str));
        let (code, _, err, written) = cli(MODEL, &args, &out);
        assert_eq!((code, written), (1, false), "{extra:?}: {err}");
        for w in words {
            assert!(err.contains(w), "{w} not in {err}");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}
