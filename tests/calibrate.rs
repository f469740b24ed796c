//! Calibration against synthetic traces made by geartherm itself: recovery of known parameters
//! (coverage of the 95 % intervals over 100 seeded noise draws), the calibrated model file
//! reproducing the fit under `run`, and the refusals and warnings of bad input.

use std::path::Path;

use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use geartherm::job::run::RunOptions;
use geartherm::job::{self, Model};

const MODEL: &str = "models/helical_stage.toml";
const H: &str = "thermal.links[\"oil-housing\"].h_w_per_m2k";
const M: &str = "thermal.nodes[\"housing\"].mass_kg";

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

/// Rig trace text: speed and torque steps over an hour every 60 s, the ambient at 20 °C, the
/// oil and the housing "measured" with `values` (°C per row and channel; 30 °C when None).
fn trace_text(values: Option<&[Vec<f64>]>) -> String {
    let mut s =
        String::from("time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:oil,node:housing\n");
    for k in 0..61 {
        let (w, t) = match k / 15 {
            0 => (3000.0, 200.0),
            1 => (1500.0, 100.0),
            2 => (4000.0, 250.0),
            _ => (500.0, 50.0),
        };
        let (a, b) = values.map_or((30.0, 30.0), |v| (v[k][0], v[k][1]));
        s.push_str(&format!("{},{w},{t},1,20,{a},{b}\n", k * 60));
    }
    s
}

fn model() -> (String, Model) {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let m = Model::from_text(&text, Path::new(MODEL), &[]).unwrap();
    (text, m)
}

/// The oil and housing temperatures geartherm computes with h and mass at `truth`, every node
/// starting at 30 °C.
fn synthetic(text: &str, m: &Model, truth: [f64; 2], rtol: f64) -> Vec<Vec<f64>> {
    let trace = Trace::parse(&trace_text(None), "truth").unwrap();
    let o = CalibrateOptions {
        fit: vec![H.into(), M.into()],
        rtol,
        ..CalibrateOptions::default()
    };
    let p = calibrate::prepare(m, text, &trace, &o).unwrap();
    let theta: Vec<f64> = truth.iter().map(|v| v.ln()).collect();
    p.problem.simulate(&theta, false).unwrap().temps_c
}

#[test]
fn recovers_known_parameters_within_their_intervals() {
    let (text, m) = model();
    let truth = [400.0, 11.0];
    let exact = synthetic(&text, &m, truth, 1e-4);
    let sigma = 0.3;
    let m30 = Model::from_text(
        &text,
        Path::new(MODEL),
        &["thermal.initial_temp_c = 30.0".parse().unwrap()],
    )
    .unwrap();
    let (mut covered, mut fits) = ([0usize; 2], 0);
    for seed in 0..100u64 {
        let mut rng = Normal(seed);
        let noisy: Vec<Vec<f64>> = exact
            .iter()
            .map(|row| row.iter().map(|v| v + sigma * rng.sample()).collect())
            .collect();
        let trace = Trace::parse(&trace_text(Some(&noisy)), "synthetic").unwrap();
        // The nodes start where the truth started (30 °C, written as an override): the noisy
        // first row does not set them.
        let o = CalibrateOptions {
            fit: vec![format!("{H}=50:2000"), format!("{M}=2:60")],
            initial_from_trace: false,
            ..CalibrateOptions::default()
        };
        let r = calibrate::calibrate(&m30, &text, &trace, &o).unwrap();
        fits += 1;
        for (k, p) in r.summary.parameters.iter().enumerate() {
            let (lo, hi) = (p.ci95_low.unwrap(), p.ci95_high.unwrap());
            if (lo..=hi).contains(&truth[k]) {
                covered[k] += 1;
            }
        }
        let s = r.summary.fit.sigma_k;
        assert!(
            (0.2..0.4).contains(&s),
            "seed {seed}: σ = {s} K for noise of {sigma} K"
        );
    }
    println!(
        "coverage of the 95 % intervals over {fits} fits: h {} / mass {}",
        covered[0], covered[1]
    );
    assert!(covered.iter().all(|&c| c >= 90), "coverage {covered:?} of 100");
}

#[test]
fn calibrated_model_reproduces_the_fit_under_run() {
    let (text, m) = model();
    let exact = synthetic(&text, &m, [400.0, 11.0], 1e-7);
    let trace = Trace::parse(&trace_text(Some(&exact)), "synthetic").unwrap();
    let o = CalibrateOptions {
        fit: vec![H.into(), M.into()],
        holdout: vec!["2400:3600".into()],
        rtol: 1e-7,
        ..CalibrateOptions::default()
    };
    let r = calibrate::calibrate(&m, &text, &trace, &o).unwrap();
    let p = &r.summary.parameters;
    assert!(
        (p[0].value / 400.0 - 1.0).abs() < 1e-4 && (p[1].value / 11.0 - 1.0).abs() < 1e-4,
        "{p:?}"
    );
    let e = r.summary.channels[0].holdout.unwrap();
    assert!(e.rmse_k < 1e-3 && e.rows == 21, "{e:?}");
    // `run` on calibrated.toml with cycle.csv: the same oil temperatures.
    let dir = tempfile::tempdir().unwrap();
    let cycle = dir.path().join("cycle.csv");
    std::fs::write(&cycle, &r.cycle_csv).unwrap();
    let cal = Model::from_text(&r.calibrated_model, Path::new("calibrated.toml"), &[]).unwrap();
    let ro = RunOptions {
        cycle: cycle.display().to_string(),
        rtol: 1e-7,
        ..RunOptions::default()
    };
    let run = job::run::run(&cal, &ro, &mut |_, _| {}).unwrap();
    let csv = run.timeseries_csv.unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = head
        .iter()
        .position(|h| *h == "temp_oil_c")
        .expect("an oil column");
    let fit: Vec<Vec<&str>> = r
        .fit_csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    for (row, l) in lines.enumerate() {
        let v: f64 = l.split(',').nth(col).unwrap().parse().unwrap();
        let sim: f64 = fit[row][3].parse().unwrap();
        assert!((v - sim).abs() < 2e-3, "row {row}: run {v} °C, fit {sim} °C");
    }
}

fn refusal(trace: &str, fit: &[&str]) -> String {
    let (text, m) = model();
    let o = CalibrateOptions {
        fit: fit.iter().map(|s| s.to_string()).collect(),
        ..CalibrateOptions::default()
    };
    match Trace::parse(trace, "bad.csv") {
        Err(e) => e.to_string(),
        Ok(t) => {
            let e = calibrate::calibrate(&m, &text, &t, &o).unwrap_err();
            assert_eq!(e.exit_code(), 1, "{e}");
            e.to_string()
        }
    }
}

#[test]
fn bad_input_is_refused_naming_what() {
    let ok = trace_text(None);
    let e = refusal(&ok.replace("node:housing", "node:case"), &[H]);
    assert!(
        e.contains("node:case") && e.contains("no capacity node \"case\"") && e.contains("housing"),
        "{e}"
    );
    let e = refusal(&ok.replace("boundary:ambient", "boundary:water"), &[H]);
    assert!(e.contains("boundary:water") && e.contains("no boundary"), "{e}");
    let e = refusal(&ok, &["thermal.links[\"nope\"].h_w_per_m2k"]);
    assert!(e.contains("nope"), "{e}");
    let e = refusal(&ok, &[H, H]);
    assert!(e.contains("twice"), "{e}");
    let e = refusal(
        &ok.replace("120,3000,200,1,20,30,30", "120,3000,200,1,20,NaN,30"),
        &[H],
    );
    assert!(e.contains("line 4") && e.contains("node:oil"), "{e}");
}

#[test]
fn a_parameter_the_trace_does_not_influence_is_warned_about() {
    let (text, m) = model();
    let exact = synthetic(&text, &m, [400.0, 11.0], 1e-4);
    let trace = Trace::parse(&trace_text(Some(&exact)), "synthetic").unwrap();
    let o = CalibrateOptions {
        fit: vec![H.into(), "losses.stavytskyi_ks=0.2:0.9".into()],
        ..CalibrateOptions::default()
    };
    let r = calibrate::calibrate(&m, &text, &trace, &o).unwrap();
    let w = r.summary.warnings.join("\n");
    assert!(
        w.contains("stavytskyi_ks") && w.contains("does not influence"),
        "{w}"
    );
    assert!(r.summary.parameters[1].ci95_low.is_none());
    assert!(r.summary.parameters[0].ci95_low.is_some());
}

#[test]
fn loss_multipliers_scale_their_items() {
    use geartherm::scene::{Inputs, Scene};
    let (text, base) = model();
    let ovs: Vec<geartherm::model::Override> = [
        "losses.multiplier.churning = 2.0",
        "losses.multiplier.\"bearing:input_a\" = 0.5",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect();
    let scaled = Model::from_text(&text, Path::new(MODEL), &ovs).unwrap();
    let inputs = Inputs {
        state: 0,
        input_speed: 300.0,
        input_torque: 150.0,
        vehicle_speed: 0.0,
    };
    let q = |m: &Model| {
        let s = Scene::compile(&m.gearbox).unwrap();
        let mut w = s.work(inputs);
        let y = s.initial_state(Some(330.0));
        s.evaluate_losses(&y, &mut w);
        (s.losses().items.clone(), w.q)
    };
    let (items, q0) = q(&base);
    let (_, q1) = q(&scaled);
    for ((it, a), b) in items.iter().zip(&q0).zip(&q1) {
        let f = match (it.source.as_str(), it.name.as_str()) {
            ("churning", _) => 2.0,
            ("bearing", "input_a") => 0.5,
            _ => 1.0,
        };
        assert!(
            *a > 0.0 && (b - f * a).abs() <= 1e-12 * a.abs(),
            "{}:{} {a} {b}",
            it.source.as_str(),
            it.name
        );
    }
    let bad = |o: &str| {
        let ov: geartherm::model::Override = o.parse().unwrap();
        match Model::from_text(&text, Path::new(MODEL), &[ov]) {
            Err(e) => e.to_string(),
            Ok(m) => Scene::compile(&m.gearbox).unwrap_err().to_string(),
        }
    };
    assert!(bad("losses.multiplier.foo = 1.0").contains("must name a source"));
    assert!(bad("losses.multiplier.churning = 0.0").contains("(0, 100]"));
    let e = bad("losses.multiplier.\"churning:nope\" = 1.0");
    assert!(
        e.contains("no churning item named nope") && e.contains("wheel"),
        "{e}"
    );
}
