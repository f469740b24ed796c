//! The importer's side of a WLTC co-simulation of an exported model, computed before a clock
//! starts (shared by `examples/fmu_timing.rs` and `benches/fmu.rs`): per segment of a run (one
//! 1 s cycle sample, inputs held) its inputs and communication points, the boundary values
//! (ambient, coolant) read from the run's series and their slopes over each point's step.

use geartherm::job::run;
use geartherm::scene::Inputs;

/// One communication point: start, end, value and derivative of each boundary.
pub type Point = (f64, f64, Vec<f64>, Vec<f64>);

/// Per segment of `p`, its inputs and its communication points at communication step `step`.
pub fn plan(p: &run::Prepared, step: f64) -> Vec<(Inputs, Vec<Point>)> {
    let nb = p.scene.thermal().boundary_names.len();
    let at = |k, t| p.scene.thermal().boundary_temperature_at(k, t).unwrap();
    p.segs
        .iter()
        .map(|seg| {
            let n = ((seg.t1 - seg.t0) / step).round().max(1.0) as usize;
            let points = (0..n)
                .map(|j| {
                    let a = seg.t0 + (seg.t1 - seg.t0) * j as f64 / n as f64;
                    let b = seg.t0 + (seg.t1 - seg.t0) * (j + 1) as f64 / n as f64;
                    let x = (0..nb).map(|k| at(k, a)).collect();
                    let d = (0..nb).map(|k| (at(k, b) - at(k, a)) / (b - a)).collect();
                    (a, b, x, d)
                })
                .collect();
            (seg.inputs, points)
        })
        .collect()
}
