//! The sensitivities of the MM82 wind-turbine gearbox (bearings, inlet node, the cooler's
//! thermostat on the inlet) on the first 12.4 days of the La Haute Borne trace of R80711, at a
//! point a sump-only fit passes through: the cooler's capacity rate at 30 000 W/K holds the
//! inlet node at the edge of its thermostat's band for hours. The sensitivities there stay
//! finite and bounded, and agree with central differences of plain simulations.
//!
//! The trace is converted from `../shared/data/engie_la_haute_borne/R80711_2017-spring.csv` as
//! `scripts/engie_traces.py` converts it (rows 10 minutes apart, no gap in these rows).

use std::path::Path;

use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use geartherm::job::Model;

const MODEL: &str = "models/mm82_wind_gearbox.toml";
const DATA: &str = "../shared/data/engie_la_haute_borne/R80711_2017-spring.csv";
/// Rows of the trace used: past the hours the inlet spends at the band's edge (rows 1760–1775).
const ROWS: usize = 1790;

/// The parameters fitted by `scripts/engie_channels.py` (case B) and the point: sliding and the
/// nacelle h at their lower bounds, the capacity rate at its upper one.
const POINT: [(&str, &str, f64); 5] = [
    ("losses.multiplier.sliding", "0.05:50", 0.05),
    ("losses.multiplier.churning", "0.01:100", 0.7304127382406455),
    (
        "thermal.coolers[\"oil_cooler\"].capacity_rate_w_per_k",
        "100:30000",
        30000.0,
    ),
    (
        "thermal.coolers[\"oil_cooler\"].thermostat.open_c",
        "45:61",
        55.565038120033606,
    ),
    ("thermal.links[\"gearbox-nacelle\"].h_w_per_m2k", "0.5:100", 0.5),
];

/// The trace text: generator speed as the input speed, −P/ω as the torque (0 below 50 rpm),
/// nacelle and outdoor temperatures as boundaries, the sump temperature measured.
fn trace_text() -> String {
    let src = std::fs::read_to_string(DATA).expect("the La Haute Borne extract in ../shared/data");
    let mut lines = src.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (p, ds, sump, nacelle, outdoor) = (
        col("P_avg"),
        col("Ds_avg"),
        col("Gost_avg"),
        col("Yt_avg"),
        col("Ot_avg"),
    );
    let mut s = String::from(
        "time_s,input_speed_rpm,input_torque_nm,gear,boundary:nacelle,boundary:outdoor,node:sump\n",
    );
    for (k, line) in lines.take(ROWS).enumerate() {
        let c: Vec<f64> = line.split(',').skip(1).map(|x| x.parse().unwrap()).collect();
        let at = |i: usize| c[i - 1];
        let n = at(ds).max(0.0);
        let w = n * std::f64::consts::PI / 30.0;
        let torque = if n > 50.0 { -at(p) * 1e3 / w } else { 0.0 };
        s.push_str(&format!(
            "{},{n},{torque:.1},run,{},{},{}\n",
            600 * k,
            at(nacelle),
            at(outdoor),
            at(sump)
        ));
    }
    s
}

#[test]
fn sensitivities_stay_finite_at_the_thermostats_edge() {
    let text = std::fs::read_to_string(MODEL).unwrap();
    let sets: Vec<geartherm::model::Override> = POINT
        .iter()
        .map(|(k, _, v)| format!("{k} = {v:?}").parse().unwrap())
        .collect();
    let m = Model::from_text(&text, Path::new(MODEL), &sets).unwrap();
    let trace = Trace::parse(&trace_text(), "R80711 spring 2017").unwrap();
    let o = CalibrateOptions {
        fit: POINT.iter().map(|(k, b, _)| format!("{k}={b}")).collect(),
        ..CalibrateOptions::default()
    };
    let prepared = calibrate::prepare(&m, &text, &trace, &o).unwrap();
    let pr = &prepared.problem;
    let theta = pr.start();
    let sim = pr.simulate(&theta, true).unwrap();
    let largest =
        sim.sens.iter().flatten().fold(
            0.0f64,
            |a, &x| if x.is_finite() { a.max(x.abs()) } else { f64::NAN },
        );
    println!("largest |∂T_sump/∂θ| over {ROWS} rows: {largest:.3} K");
    // A factor e on any of these parameters (or 1 K on open_c) moves the sump by less than its
    // whole range in the data (36–63 °C).
    assert!(
        largest.is_finite() && largest < 30.0,
        "largest sensitivity {largest}"
    );
    // The churning multiplier and open_c are inside their bounds: their sensitivities at the
    // last rows against central differences of plain simulations (δ = 0.05 in ln p, 0.05 K;
    // their own step sequences make the differences uncertain by a few 0.01 K per unit).
    for (k, d) in [(1usize, 0.05), (3, 0.05)] {
        let (mut up, mut down) = (theta.clone(), theta.clone());
        up[k] += d;
        down[k] -= d;
        let (a, b) = (
            pr.simulate(&up, false).unwrap(),
            pr.simulate(&down, false).unwrap(),
        );
        for row in ROWS - 20..ROWS {
            let fd = (a.temps_c[row][0] - b.temps_c[row][0]) / (2.0 * d);
            let s = sim.sens[row][k];
            assert!(
                (s - fd).abs() <= 0.1 * fd.abs() + 0.05,
                "parameter {k}, row {row}: sensitivity {s} against central difference {fd}"
            );
        }
    }
}
