//! What a hostile-input campaign on `calibrate` found, each case held: the physics envelope on
//! the trace and on the fit, the trace's boundary values within the model file's range, the fit
//! never evaluated or written outside the user's bounds, integer parameters kept integers, one
//! number fitted once whatever its spelling, and perfectly correlated parameters named as a
//! non-identifiable combination.

use std::path::Path;

use geartherm::job::calibrate::{self, CalibrateOptions, CalibrateResult, Trace};
use geartherm::job::{JobError, Model};

const MODEL: &str = "models/helical_stage.toml";
const H: &str = "thermal.links[\"oil-housing\"].h_w_per_m2k";
const A: &str = "thermal.links[\"oil-housing\"].area_m2";
const M: &str = "thermal.nodes[\"housing\"].mass_kg";

/// Rig trace: speed and torque steps over an hour every 60 s, the ambient at `ambient` °C, the
/// oil and the housing "measured" with `values` (°C per row and channel; 30 °C when None).
fn trace_text(values: Option<&[Vec<f64>]>, ambient: f64) -> String {
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
        s.push_str(&format!("{},{w},{t},1,{ambient},{a},{b}\n", k * 60));
    }
    s
}

fn model(sets: &[&str]) -> (String, Model) {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let ovs: Vec<_> = sets.iter().map(|s| s.parse().unwrap()).collect();
    let m = Model::from_text(&text, Path::new(MODEL), &ovs).unwrap();
    (text, m)
}

/// Oil and housing temperatures of the model with `sets` applied, every node from 30 °C.
fn truth(sets: &[&str]) -> Vec<Vec<f64>> {
    let mut all = vec![
        "thermal.initial_temp_c = 30.0",
        "thermal.links[\"oil-housing\"].h_w_per_m2k = 400.0",
        "thermal.nodes[\"housing\"].mass_kg = 11.0",
    ];
    all.extend(sets);
    let (text, m) = model(&all);
    let trace = Trace::parse(&trace_text(None, 20.0), "truth").unwrap();
    let o = CalibrateOptions {
        initial_from_trace: false,
        ..CalibrateOptions::default()
    };
    let p = calibrate::prepare(&m, &text, &trace, &o).unwrap();
    p.problem.simulate(&[], false).unwrap().temps_c
}

fn run(trace: &str, fit: &[&str]) -> Result<CalibrateResult, JobError> {
    let (text, m) = model(&[]);
    let o = CalibrateOptions {
        fit: fit.iter().map(|s| s.to_string()).collect(),
        ..CalibrateOptions::default()
    };
    let t = Trace::parse(trace, "hostile.csv").unwrap();
    calibrate::calibrate(&m, &text, &t, &o)
}

fn refused(trace: &str, fit: &[&str], code: i32) -> String {
    match run(trace, fit) {
        Ok(r) => panic!("accepted: {:?}", r.summary.parameters),
        Err(e) => {
            assert_eq!(e.exit_code(), code, "{e}");
            e.to_string()
        }
    }
}

/// A trace whose oil starts outside the oil's range (300 °C, −60 °C) is refused, naming line,
/// column, value and range.
#[test]
fn a_trace_outside_the_envelope_is_refused() {
    for bad in ["300", "-60"] {
        let t =
            trace_text(None, 20.0).replacen("0,3000,200,1,20,30,30", &format!("0,3000,200,1,20,{bad},30"), 1);
        let e = refused(&t, &[H], 1);
        assert!(
            e.contains("line 2") && e.contains("node:oil") && e.contains(bad) && e.contains("Walther"),
            "{e}"
        );
    }
}

/// Boundary values the trace reader accepts but the model file's series does not (above
/// 300 °C) are refused before the fit: calibrated.toml would fail `check`.
#[test]
fn boundary_values_are_held_to_the_model_files_range() {
    let t = trace_text(None, 20.0).replacen(",1,20,", ",1,350,", 3);
    let e = refused(&t, &[H], 1);
    assert!(
        e.contains("boundary:ambient") && e.contains("series") && e.contains("350"),
        "{e}"
    );
}

/// A fit whose oil leaves the oil's range (a link that cannot carry the heat away) exits 2
/// naming the node, and returns no calibrated model.
#[test]
fn a_fit_leaving_the_envelope_fails() {
    let t = trace_text(Some(&truth(&[])), 20.0);
    let e = refused(&t, &[H, "losses.multiplier.churning=50:100"], 2);
    assert!(
        e.contains("node oil") && e.contains("outside") && e.contains("no calibrated"),
        "{e}"
    );
}

/// With the optimum at the upper bound 1 of the emissivity, the fit never evaluates 1.0001 and
/// writes the bound itself.
#[test]
fn the_fit_stays_within_the_users_bounds() {
    let e = "thermal.links[\"housing-air radiation\"].emissivity";
    let t = trace_text(Some(&truth(&[&format!("{e} = 1.0")])), 20.0);
    let r = run(&t, &[H, M, &format!("{e}=0.05:1")]).unwrap();
    let p = &r.summary.parameters[2];
    assert!(p.value <= 1.0 && p.value > 0.95, "{p:?}");
    // A bound of 14 kg above the truth of 11 kg: written as 14, not one bit below (exp(ln 14) is below 14).
    let t = trace_text(Some(&truth(&[])), 20.0);
    let r = run(&t, &[H, &format!("{M}=14:60")]).unwrap();
    let p = &r.summary.parameters[1];
    assert_eq!(p.value, 14.0, "{p:?}");
    let doc: toml::Table = r.calibrated_model.parse().unwrap();
    assert_eq!(doc["thermal"]["nodes"][2]["mass_kg"].as_float(), Some(14.0));
}

/// A parameter the trace does not influence is written as its start, to the bit.
#[test]
fn an_uninfluenced_parameter_keeps_its_start() {
    let t = trace_text(Some(&truth(&[])), 20.0);
    let r = run(&t, &[H, "losses.stavytskyi_ks=0.2:0.9"]).unwrap();
    let p = &r.summary.parameters[1];
    assert_eq!(p.value, p.start, "{p:?}");
    assert!(r
        .calibrated_model
        .contains(&format!("stavytskyi_ks = {}", p.start)));
}

/// An integer of the model (a gear's teeth) starts and is written as an integer.
#[test]
fn an_integer_parameter_stays_an_integer() {
    let t = trace_text(Some(&truth(&[])), 20.0);
    let r = run(&t, &[H, "gears[0].teeth=20:40"]).unwrap();
    let p = &r.summary.parameters[1];
    assert_eq!(p.value, p.value.round(), "{p:?}");
    let doc: toml::Table = r.calibrated_model.parse().unwrap();
    assert!(
        doc["gears"][0]["teeth"].as_integer().is_some(),
        "{}",
        doc["gears"][0]["teeth"]
    );
}

/// One number fitted under two spellings is refused, naming both.
#[test]
fn one_number_under_two_spellings_is_refused() {
    let t = trace_text(Some(&truth(&[])), 20.0);
    let e = refused(&t, &["thermal.nodes[2].mass_kg", M], 1);
    assert!(
        e.contains("thermal.nodes[2].mass_kg") && e.contains("housing") && e.contains("once"),
        "{e}"
    );
}

/// A link's h and area enter only as their product: the pair is named as not identifiable,
/// without a standard error or an interval (no zero-width intervals).
#[test]
fn perfectly_correlated_parameters_are_named() {
    let t = trace_text(Some(&truth(&[])), 20.0);
    let r = run(&t, &[H, A, M]).unwrap();
    let w = r.summary.warnings.join("\n");
    assert!(
        w.contains("h_w_per_m2k") && w.contains("area_m2") && w.contains("not identifiable"),
        "{w}"
    );
    for p in &r.summary.parameters[..2] {
        assert!(p.std_error.is_none() && p.ci95_low.is_none(), "{p:?}");
    }
    let mass = &r.summary.parameters[2];
    let (lo, hi) = (mass.ci95_low.unwrap(), mass.ci95_high.unwrap());
    assert!(lo < hi && (lo..=hi).contains(&(mass.value)), "{mass:?}");
    assert!((mass.value / 11.0 - 1.0).abs() < 1e-6, "{mass:?}");
}
