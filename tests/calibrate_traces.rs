//! Several traces in one fit: parameters shared by every trace or of one trace, every segment
//! of a file (a gap in time starts one) from its own measured temperatures, the AR(1) process
//! restarted at every segment; a stack of one segment is the fit of that segment; bad input
//! (a trace index out of range, `@N` with one trace, the same file twice, traces measuring
//! other nodes or with other columns, a node the model does not have, an empty segment list, a
//! parameter no trace influences) exits 1 and writes nothing.

use std::path::{Path, PathBuf};
use std::process::Command;

use geartherm::job::calibrate::{self, stack, stack_fit, trace_file, CalibrateOptions, Missing, Trace};
use geartherm::job::Model;

const MODEL: &str = "models/helical_stage.toml";
const H: &str = "thermal.links[\"oil-housing\"].h_w_per_m2k";
const M: &str = "thermal.nodes[\"housing\"].mass_kg";

/// Speed and torque steps of one hour every 60 s (`reverse`: the steps in the other order).
fn steps(reverse: bool) -> Vec<(f64, f64)> {
    let mut s = [(3000.0, 200.0), (1500.0, 100.0), (4000.0, 250.0), (500.0, 50.0)];
    if reverse {
        s.reverse();
    }
    (0..61).map(|k| s[(k / 15).min(3)]).collect()
}

fn segment_text(reverse: bool, values: Option<&[Vec<f64>]>, t0: f64, header: bool) -> String {
    let mut s = String::new();
    if header {
        s.push_str("time_s,input_speed_rpm,input_torque_nm,gear,boundary:ambient,node:oil,node:housing\n");
    }
    for (k, (w, t)) in steps(reverse).into_iter().enumerate() {
        let (a, b) = values.map_or((30.0, 30.0), |v| (v[k][0], v[k][1]));
        s.push_str(&format!("{},{w},{t},1,20,{a},{b}\n", t0 + k as f64 * 60.0));
    }
    s
}

fn model() -> (String, Model) {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let m = Model::from_text(&text, Path::new(MODEL), &[]).unwrap();
    (text, m)
}

/// Oil and housing of the model with h and the housing mass set, every node from 30 °C.
fn truth(h: f64, mass: f64, reverse: bool) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let sets = [
        "thermal.initial_temp_c = 30.0".to_string(),
        format!("{H} = {h}"),
        format!("{M} = {mass}"),
    ];
    let ovs: Vec<_> = sets.iter().map(|s| s.parse().unwrap()).collect();
    let m = Model::from_text(&text, Path::new(MODEL), &ovs).unwrap();
    let trace = Trace::parse(&segment_text(reverse, None, 0.0, true), "truth").unwrap();
    let o = CalibrateOptions {
        initial_from_trace: false,
        ..CalibrateOptions::default()
    };
    let p = calibrate::prepare(&m, &text, &trace, &o).unwrap();
    p.problem.simulate(&[], false).unwrap().temps_c
}

/// Deterministic Gaussian noise of standard deviation `sd` (none on a segment's first row:
/// it sets the start).
fn noisy(mut v: Vec<Vec<f64>>, sd: f64, seed: u64) -> Vec<Vec<f64>> {
    let mut s = seed;
    let mut u = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    for row in v.iter_mut().skip(1) {
        for x in row.iter_mut() {
            let (a, b) = (u(), u());
            *x += sd * (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos();
        }
    }
    v
}

/// A trace file of two segments (a gap of a day between them): the steps, then the steps
/// reversed, measured from the model with `mass`.
fn two_segments(mass: f64, seed: u64) -> String {
    let a = noisy(truth(400.0, mass, false), 0.1, seed);
    let b = noisy(truth(400.0, mass, true), 0.1, seed + 1);
    segment_text(false, Some(&a), 0.0, true) + &segment_text(true, Some(&b), 90_000.0, false)
}

#[test]
fn shared_and_per_trace_parameters_are_recovered() {
    let (text, m) = model();
    let files = vec![
        (
            "a".to_string(),
            trace_file::read(&two_segments(11.0, 3), "a.csv", Missing::Drop).unwrap(),
        ),
        (
            "b".to_string(),
            trace_file::read(&two_segments(20.0, 9), "b.csv", Missing::Drop).unwrap(),
        ),
    ];
    let o = CalibrateOptions {
        fit: vec![H.into(), format!("{M}@*=2:60")],
        ..CalibrateOptions::default()
    };
    let inputs = stack::inputs(&files, &o).unwrap();
    let s = stack::prepare(&m, &text, &inputs, &o).unwrap();
    assert_eq!(s.segments.len(), 4);
    // No lag across a gap or between traces: four stretches of 61 rows.
    let layout = s.layout();
    assert_eq!(layout.stretch.len(), 244);
    assert_eq!(layout.stretch.iter().max(), Some(&3));
    assert_eq!(s.segments[2].map, vec![0, 2]);
    let r = stack_fit::fit(&m, &s, &o, &|th| s.evaluate(th)).unwrap();
    let p = &r.summary.parameters;
    let names: Vec<&str> = p.iter().map(|x| x.key_path.as_str()).collect();
    assert_eq!(names, [H.to_string(), format!("{M}@a"), format!("{M}@b")]);
    for (x, truth) in p.iter().zip([400.0, 11.0, 20.0]) {
        let (lo, hi) = (x.ci95_low.unwrap(), x.ci95_high.unwrap());
        assert!(lo <= truth && truth <= hi, "{x:?}");
        assert!((x.value / truth - 1.0).abs() < 0.05, "{x:?}");
    }
    let traces = &r.summary.traces;
    assert_eq!(traces.len(), 2);
    for t in traces {
        assert_eq!((t.segments.clone(), t.rows), (vec![0, 1], 122));
        let e = t.channels[0].fitted.unwrap();
        assert!(e.rmse_k > 0.05 && e.rmse_k < 0.15, "{t:?}");
        assert!(e.inside_band95.unwrap() > 0.85, "{t:?}");
    }
    // One calibrated model per trace, each with its own mass and the shared h.
    assert!(r.calibrated_model.is_empty());
    let names: Vec<&str> = r.per_trace_models.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["calibrated_a.toml", "calibrated_b.toml"]);
    for ((_, model), x) in r.per_trace_models.iter().zip(&p[1..]) {
        let doc: toml::Table = model.parse().unwrap();
        assert_eq!(doc["thermal"]["nodes"][2]["mass_kg"].as_float(), Some(x.value));
        assert_eq!(
            doc["thermal"]["links"][3]["h_w_per_m2k"].as_float(),
            Some(p[0].value)
        );
    }
    let csv = r.fit_csv.lines().collect::<Vec<_>>();
    assert!(
        csv[0].starts_with("trace,segment,time_s,holdout,oil_measured_c"),
        "{}",
        csv[0]
    );
    assert_eq!(csv.len(), 1 + 244);
    assert!(csv[62].starts_with("\"a\",1,90000,"), "{}", csv[62]);
}

/// A stack of one trace of one segment is the fit of that trace.
#[test]
fn one_segment_stacked_is_the_single_fit() {
    let (text, m) = model();
    let csv = segment_text(false, Some(&noisy(truth(400.0, 11.0, false), 0.1, 5)), 0.0, true);
    let o = CalibrateOptions {
        fit: vec![H.into(), format!("{M}=2:60")],
        ..CalibrateOptions::default()
    };
    let single = calibrate::calibrate(&m, &text, &Trace::parse(&csv, "t.csv").unwrap(), &o).unwrap();
    let files = vec![(
        "t".to_string(),
        trace_file::read(&csv, "t.csv", Missing::Drop).unwrap(),
    )];
    let inputs = stack::inputs(&files, &o).unwrap();
    let stacked = stack_fit::calibrate_traces(&m, &text, &inputs, &o).unwrap();
    for (a, b) in single.summary.parameters.iter().zip(&stacked.summary.parameters) {
        assert_eq!(a.value, b.value);
        assert_eq!(a.std_error, b.std_error);
        assert_eq!(a.ci95_low, b.ci95_low);
    }
    let (a, b) = (
        &single.summary.channels[0].noise,
        &stacked.summary.channels[0].noise,
    );
    assert_eq!((a.phi, a.innovation_sd_k), (b.phi, b.innovation_sd_k));
    for (x, y) in a
        .autocorrelation_lag_1_2_6
        .iter()
        .zip(&b.autocorrelation_lag_1_2_6)
    {
        assert!((x.unwrap() - y.unwrap()).abs() < 1e-12, "{a:?} {b:?}");
    }
    // The stacked model holds the fitted values, not one segment's boundary series.
    let doc: toml::Table = stacked.calibrated_model.parse().unwrap();
    assert_eq!(
        doc["thermal"]["links"][3]["h_w_per_m2k"].as_float(),
        Some(single.summary.parameters[0].value)
    );
}

// --- bad input through the command: exit 1 naming the option and value, nothing written -----

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "geartherm_calibrate_traces_{name}_{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run `calibrate` with `args` after the model; the exit code, stderr and whether OUT exists.
fn cli(d: &Path, args: &[&str]) -> (i32, String, bool) {
    let out = d.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_geartherm"))
        .arg("calibrate")
        .arg(MODEL)
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        out.exists(),
    )
}

fn files(d: &Path) -> (String, String) {
    let a = d.join("a.csv");
    let b = d.join("b.csv");
    std::fs::write(&a, two_segments(11.0, 3)).unwrap();
    std::fs::write(&b, two_segments(20.0, 9)).unwrap();
    (a.display().to_string(), b.display().to_string())
}

fn refused(d: &Path, args: &[&str], words: &[&str]) {
    let (code, err, written) = cli(d, args);
    assert_eq!(code, 1, "{err}");
    assert!(!written, "{err}");
    for w in words {
        assert!(err.contains(w), "{w} not in {err}");
    }
}

#[test]
fn bad_trace_lists_are_refused() {
    let d = dir("bad");
    let (a, b) = files(&d);
    let h = &format!("--fit={H}");
    // A trace index out of range, an unknown trace name.
    refused(
        &d,
        &["--trace", &a, "--trace", &b, h, &format!("--fit={M}@2=2:60")],
        &["fit", "@2", "trace 2 does not exist"],
    );
    refused(
        &d,
        &["--trace", &a, "--trace", &b, &format!("--fit={M}@c=2:60")],
        &["no trace is named \"c\""],
    );
    // @N with one trace (one segment or several).
    refused(
        &d,
        &["--trace", &a, "--segment", "all", &format!("--fit={M}@0")],
        &["fit", "one trace is fitted"],
    );
    // The same file twice (also under another spelling).
    let other = format!("{}/./a.csv", d.display());
    refused(
        &d,
        &["--trace", &a, "--trace", &other, h],
        &["trace", "a.csv", "given twice"],
    );
    // A key shared and of one trace, or of one trace twice.
    refused(
        &d,
        &["--trace", &a, "--trace", &b, h, &format!("--fit={H}@0")],
        &["fit", "already fitted"],
    );
    // Traces measuring other nodes.
    let c = d.join("c.csv");
    let text = two_segments(11.0, 3).replace(",node:housing", ",node:gears");
    std::fs::write(&c, text).unwrap();
    refused(
        &d,
        &["--trace", &a, "--trace", c.to_str().unwrap(), h],
        &["trace", "c.csv", "same nodes"],
    );
    // An empty segment list, a segment out of range, a segment named twice, --segment with
    // several traces.
    refused(
        &d,
        &["--trace", &a, "--segment", ",", h],
        &["segment", "empty segment list"],
    );
    refused(
        &d,
        &["--trace", &a, "--segment", "0,2", h],
        &["segment", "2 must lie in [0, 1]"],
    );
    refused(
        &d,
        &["--trace", &a, "--segment", "1,1", h],
        &["segment", "named twice"],
    );
    refused(
        &d,
        &["--trace", &a, "--trace", &b, "--segment", "0", h],
        &["segment", "several traces"],
    );
    // A shared parameter no trace influences.
    refused(
        &d,
        &[
            "--trace",
            &a,
            "--trace",
            &b,
            h,
            "--fit=losses.stavytskyi_ks=0.2:0.9",
        ],
        &["fit", "stavytskyi_ks", "none of the traces"],
    );
    // Traces with different columns: a boundary column one has and the other lacks.
    let e = d.join("e.csv");
    let text = two_segments(11.0, 3)
        .replace(",boundary:ambient", "")
        .lines()
        .map(|l| {
            let mut cells: Vec<&str> = l.split(',').collect();
            if cells.len() == 7 {
                cells.remove(4);
            }
            cells.join(",")
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&e, text + "\n").unwrap();
    refused(
        &d,
        &["--trace", &a, "--trace", e.to_str().unwrap(), h],
        &["trace", "e.csv", "boundary:ambient", "same columns"],
    );
    // A measured column the model does not have.
    let f = d.join("f.csv");
    std::fs::write(
        &f,
        two_segments(11.0, 3).replace(",node:housing", ",node:bearing_x"),
    )
    .unwrap();
    refused(
        &d,
        &["--trace", &a, "--trace", f.to_str().unwrap(), h],
        &["f.csv", "node:bearing_x"],
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Two segments of one file in one fit through the command: the files written.
#[test]
fn segments_of_one_file_fit_together() {
    let d = dir("segments");
    let (a, b) = files(&d);
    let (code, err, written) = cli(&d, &["--trace", &a, "--segment", "all", &format!("--fit={H}")]);
    assert_eq!((code, written), (0, true), "{err}");
    for f in ["calibration.json", "fit.csv", "calibrated.toml"] {
        assert!(d.join("out").join(f).exists(), "{f}");
    }
    let (code, err, _) = cli(
        &d,
        &[
            "--trace",
            &a,
            "--trace",
            &b,
            &format!("--fit={H}"),
            &format!("--fit={M}@b=2:60"),
        ],
    );
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("out/calibration.json")).unwrap()).unwrap();
    assert_eq!(json["traces"].as_array().map(Vec::len), Some(2));
    assert_eq!(json["parameters"][1]["key_path"], format!("{M}@b"));
    assert!(d.join("out/calibrated_a.toml").exists() && d.join("out/calibrated_b.toml").exists());
    let _ = std::fs::remove_dir_all(&d);
}
