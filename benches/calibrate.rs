//! Criterion bench of a calibration: six parameters of the AT6 fitted to a WLTC-length trace
//! (1800 s, the WLTC as a vehicle cycle, the sump and housing temperatures geartherm computes
//! with the parameters moved off the model's values, plus 0.2 K of seeded noise), from the
//! model's values. The whole job: trace mapping, the fit (sensitivities of every evaluation),
//! the intervals and the outputs' text.
//!
//! Run: `cargo bench --bench calibrate`. Figures are recorded in docs/performance.md
//! ("Calibration").

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use geartherm::cycle::DriveCycle;
use geartherm::job::calibrate::{self, CalibrateOptions, Trace};
use geartherm::job::Model;

const FIT: [&str; 6] = [
    "thermal.links[\"sump-housing\"].h_w_per_m2k",
    "thermal.links[\"shafts-oil\"].h_w_per_m2k",
    "thermal.nodes[\"sump\"].mass_kg",
    "thermal.nodes[\"housing\"].mass_kg",
    "thermal.links[\"housing-air\"].area_m2",
    "thermal.coolers[\"atf_cooler\"].capacity_rate_w_per_k",
];
/// The truth: each parameter times this factor.
const FACTOR: [f64; 6] = [1.3, 0.8, 1.2, 0.9, 1.25, 0.85];

fn trace_text(cycle: &DriveCycle, values: Option<&[Vec<f64>]>) -> String {
    let mut s = String::from("time_s,speed_kmh,node:sump,node:housing\n");
    for (k, r) in cycle.rows.iter().enumerate() {
        let (a, b) = values.map_or((23.0, 23.0), |v| (v[k][0], v[k][1]));
        s.push_str(&format!("{},{},{a},{b}\n", r.time, r.vehicle_speed * 3.6));
    }
    s
}

/// splitmix64 and Box–Muller.
fn noise(seed: &mut u64) -> f64 {
    let mut u = || {
        *seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let (a, b) = (u().max(1e-300), u());
    (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
}

fn benches(c: &mut Criterion) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("models/at6_lepelletier.toml");
    let text = std::fs::read_to_string(&path).expect("model text");
    let m = Model::from_text(&text, Path::new("at6_lepelletier.toml"), &[]).expect("model");
    let cycle = DriveCycle::resolve("wltc").expect("bundled cycle");
    // The synthetic measurement: the model at the truth.
    let dummy = Trace::parse(&trace_text(&cycle, None), "wltc").expect("trace");
    // The nodes start at the model's 23 °C, as the truth did (not at the noisy first row).
    let o = CalibrateOptions {
        fit: FIT.iter().map(|s| s.to_string()).collect(),
        initial_from_trace: false,
        ..CalibrateOptions::default()
    };
    let p = calibrate::prepare(&m, &text, &dummy, &o).expect("prepared");
    let truth: Vec<f64> = p
        .problem
        .params
        .iter()
        .zip(FACTOR)
        .map(|(q, f)| q.theta(q.start * f))
        .collect();
    let exact = p.problem.simulate(&truth, false).expect("simulated").temps_c;
    let mut seed = 7u64;
    let noisy: Vec<Vec<f64>> = exact
        .iter()
        .map(|r| r.iter().map(|v| v + 0.2 * noise(&mut seed)).collect())
        .collect();
    let trace = Trace::parse(&trace_text(&cycle, Some(&noisy)), "wltc_synthetic").expect("trace");
    let mut group = c.benchmark_group("calibrate");
    group.sample_size(10).measurement_time(Duration::from_secs(20));
    group.bench_function("at6_wltc_6_parameters", |b| {
        b.iter(|| calibrate::calibrate(black_box(&m), &text, &trace, &o).expect("calibrated"))
    });
    group.finish();
    let r = calibrate::calibrate(&m, &text, &trace, &o).expect("calibrated");
    println!(
        "{} evaluations, stop {}, σ = {:.3} K, wall {:.3} s",
        r.summary.fit.evaluations, r.summary.fit.stop, r.summary.fit.sigma_k, r.summary.fit.wall_time_s
    );
    for (q, f) in r.summary.parameters.iter().zip(FACTOR) {
        println!(
            "{}: truth {:.5} fitted {:.5} [{:.5}, {:.5}]",
            q.key_path,
            q.start * f,
            q.value,
            q.ci95_low.unwrap_or(f64::NAN),
            q.ci95_high.unwrap_or(f64::NAN)
        );
    }
}

criterion_group!(calibrate_benches, benches);
criterion_main!(calibrate_benches);
