//! Convergence of the Sobol' index estimators on the Ishigami function (a = 7, b = 0.1, inputs
//! uniform on [−π, π]): the Saltelli design on Owen-scrambled Sobol' points, first-order indices
//! by Saltelli et al. 2010 and total indices by Jansen 1999, against their analytic values, for
//! N = 2^8 … 2^14 base points (N (d + 2) = 5N runs) and twenty scrambling seeds. Prints the table
//! of docs/uq.md, "Convergence": the largest absolute error over the six indices and the seeds,
//! the mean over seeds of each index's absolute error, the mean width of the 95 % bootstrap
//! intervals, and how many of the 120 intervals (6 indices × 20 seeds) cover the analytic value.
//!
//! `cargo run --release --example uq_convergence`
//!
//! With `-- --figure DIR`, also writes `DIR/sensitivity.png` (the Ishigami indices at the
//! recommended N, seed 1) and `DIR/bands.png` (5/25/50/75/95 % bands of a linear two-node
//! network's step response with a normal heat input and ambient, 1024 samples): the two uq
//! figures on known answers.

use std::f64::consts::PI;

use geartherm::report::plots::uq::render_uq;
use geartherm::report::uq::{BandSeries, Bands, SobolRow, UqSummary};
use geartherm::study::uq::stats::lowdisc::sobol_points;
use geartherm::study::uq::stats::quantiles::BandAccumulator;
use geartherm::study::uq::stats::sobol::{
    ishigami, ishigami_indices, saltelli_rows, sobol_indices, RECOMMENDED_BASE_SAMPLES,
};
use geartherm::study::uq::stats::Distribution;

const SEEDS: [u64; 20] = [
    1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20,
];

fn ishigami_outputs(n: usize, seed: u64) -> Vec<f64> {
    let pts = sobol_points(n, 6, Some(seed)).expect("6 dimensions");
    saltelli_rows(&pts, 3)
        .iter()
        .map(|r| {
            let x: Vec<f64> = r.iter().map(|u| -PI + 2.0 * PI * u).collect();
            ishigami(&x, 7.0, 0.1)
        })
        .collect()
}

/// Step response of the two-node network (node 1 heated by q, node 2 to the ambient), explicit
/// Euler at 1 s (a figure, not a reference: the tests use the closed form).
fn two_node(q: f64, ta: f64, times: &[f64]) -> [Vec<f64>; 2] {
    let (c1, c2, g12, g2a) = (2.0e4, 5.0e4, 20.0, 10.0);
    let (mut t1, mut t2, mut now) = (ta, ta, 0.0);
    let mut out = [Vec::new(), Vec::new()];
    for &t in times {
        while now < t {
            let f12 = g12 * (t1 - t2);
            t1 += (q - f12) / c1;
            t2 += (f12 - g2a * (t2 - ta)) / c2;
            now += 1.0;
        }
        out[0].push(t1);
        out[1].push(t2);
    }
    out
}

fn figures(dir: &std::path::Path) {
    let n = RECOMMENDED_BASE_SAMPLES;
    let r = sobol_indices(&ishigami_outputs(n, 1), n, 3, 500, 0.95, 1).expect("indices");
    let sobol: Vec<SobolRow> = (0..3)
        .map(|i| SobolRow {
            output: "Ishigami Y (a = 7, b = 0.1)".into(),
            input: format!("x{}", i + 1),
            first: r.first[i].value,
            first_lo: r.first[i].lo,
            first_hi: r.first[i].hi,
            total: r.total[i].value,
            total_lo: r.total[i].lo,
            total_hi: r.total[i].hi,
        })
        .collect();
    let times: Vec<f64> = (0..=60).map(|k| k as f64 * 240.0).collect();
    let (q, ta) = (
        Distribution::Normal {
            mean: 500.0,
            sd: 50.0,
        },
        Distribution::Normal { mean: 30.0, sd: 3.0 },
    );
    let mut acc = [
        BandAccumulator::new(times.len()),
        BandAccumulator::new(times.len()),
    ];
    for u in sobol_points(1024, 2, Some(1)).expect("2 dimensions") {
        let series = two_node(q.quantile(u[0]), ta.quantile(u[1]), &times);
        for (a, s) in acc.iter_mut().zip(&series) {
            a.push(s).expect("finite");
        }
    }
    let ps = vec![5.0, 25.0, 50.0, 75.0, 95.0];
    let bands = Bands {
        time_s: times.clone(),
        percentiles: ps.clone(),
        series: ["heated node", "outer node"]
            .iter()
            .zip(&acc)
            .map(|(name, a)| BandSeries {
                name: name.to_string(),
                unit: "°C".into(),
                values: a.bands(&ps).expect("samples"),
            })
            .collect(),
    };
    let summary = UqSummary {
        model: "test functions".into(),
        cycle_or_point: "Ishigami, two-node step".into(),
        samples: 1024,
        method: "saltelli".into(),
        seed: 1,
        inputs: vec![],
        percentiles: ps,
        exceedance: vec![],
        sobol,
        energy: vec![],
        scalars: vec![],
        failed_samples: 0,
        notes: vec![],
    };
    std::fs::create_dir_all(dir).expect("figure directory");
    for p in render_uq(dir, &summary, Some(&bands)).expect("figures") {
        println!("wrote {}", p.display());
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(k) = args.iter().position(|a| a == "--figure") {
        let dir = args.get(k + 1).expect("--figure DIR");
        figures(std::path::Path::new(dir));
    }
    let (s1, st) = ishigami_indices(7.0, 0.1);
    println!(
        "analytic: S1 = {:.4} {:.4} {:.4}, ST = {:.4} {:.4} {:.4}\n",
        s1[0], s1[1], s1[2], st[0], st[1], st[2]
    );
    println!("| N | runs | max abs error | mean abs error S1, S2, S3 | mean abs error ST1, ST2, ST3 | mean 95 % CI width | CIs covering |");
    println!("|---|---|---|---|---|---|---|");
    for k in 8..=14 {
        let n = 1usize << k;
        let mut max_err = 0.0f64;
        let mut err_f = [0.0; 3];
        let mut err_t = [0.0; 3];
        let (mut width, mut covered) = (0.0, 0);
        for &seed in &SEEDS {
            let y = ishigami_outputs(n, seed);
            let r = sobol_indices(&y, n, 3, 500, 0.95, seed).expect("indices");
            for i in 0..3 {
                for (e, truth, acc) in [
                    (r.first[i], s1[i], &mut err_f[i]),
                    (r.total[i], st[i], &mut err_t[i]),
                ] {
                    let err = (e.value - truth).abs();
                    max_err = max_err.max(err);
                    *acc += err / SEEDS.len() as f64;
                    width += (e.hi - e.lo) / (6 * SEEDS.len()) as f64;
                    covered += usize::from(e.lo <= truth && truth <= e.hi);
                }
            }
        }
        println!(
            "| 2^{k} = {n} | {} | {max_err:.4} | {:.4}, {:.4}, {:.4} | {:.4}, {:.4}, {:.4} | {width:.4} | {covered}/{} |",
            5 * n,
            err_f[0], err_f[1], err_f[2], err_t[0], err_t[1], err_t[2],
            6 * SEEDS.len()
        );
    }
}
