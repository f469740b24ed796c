//! Convergence of the Sobol' index estimators on the Ishigami function (a = 7, b = 0.1, inputs
//! uniform on [−π, π]): the Saltelli design on Owen-scrambled Sobol' points, first-order indices
//! by Saltelli et al. 2010 and total indices by Jansen 1999, against their analytic values, for
//! N = 2^8 … 2^14 base points (N (d + 2) = 5N runs) and five scrambling seeds. Prints the table
//! of docs/uq.md, "Convergence": the largest absolute error over the six indices and the seeds,
//! the mean over seeds of each index's absolute error, the mean width of the 95 % bootstrap
//! intervals, and how many of the 30 intervals (6 indices × 5 seeds) cover the analytic value.
//!
//! `cargo run --release --example uq_convergence`

use std::f64::consts::PI;

use geartherm::study::uq::stats::lowdisc::sobol_points;
use geartherm::study::uq::stats::sobol::{ishigami, ishigami_indices, saltelli_rows, sobol_indices};

const SEEDS: [u64; 5] = [1, 2, 3, 4, 5];

fn main() {
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
            let pts = sobol_points(n, 6, Some(seed)).expect("6 dimensions");
            let y: Vec<f64> = saltelli_rows(&pts, 3)
                .iter()
                .map(|r| {
                    let x: Vec<f64> = r.iter().map(|u| -PI + 2.0 * PI * u).collect();
                    ishigami(&x, 7.0, 0.1)
                })
                .collect();
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
            "| 2^{k} = {n} | {} | {max_err:.4} | {:.4}, {:.4}, {:.4} | {:.4}, {:.4}, {:.4} | {width:.4} | {covered}/30 |",
            5 * n,
            err_f[0], err_f[1], err_f[2], err_t[0], err_t[1], err_t[2]
        );
    }
}
