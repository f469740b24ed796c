//! A run's states on a fixed time grid: every node's temperature (°C) and the loss energy of
//! every source since the start (J), at `points` equally spaced times from the cycle's start to
//! its end, linearly interpolated between the run's output rows (the cycle's own time steps).
//! An uncertainty study keeps these per case for its percentile bands: one grid for every case,
//! so the bands are taken across cases at equal times.

use crate::physics::units::k_to_c;
use crate::scene::{Scene, Source};
use crate::solve::transient::Trajectory;

use super::run::{prepare, solve_keeping, Prepared, RunOptions, RunResult};
use super::{JobError, Model};

/// Fewest and most grid points of a series.
pub const POINTS: (usize, usize) = (2, 100_000);

/// The series names in the order of [`RunSeries::values`]: `temp_<node>_c` for each node, then
/// `energy_<source>_j` for each source.
pub fn names(scene: &Scene) -> Vec<String> {
    let mut v: Vec<String> = scene
        .thermal()
        .names
        .iter()
        .map(|n| format!("temp_{n}_c"))
        .collect();
    v.extend(Source::ALL.iter().map(|s| format!("energy_{}_j", s.as_str())));
    v
}

/// A run's series on its grid.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSeries {
    /// Grid times, s.
    pub times_s: Vec<f64>,
    /// Series names ([`names`]).
    pub names: Vec<String>,
    /// One vector per name, one value per grid time.
    pub values: Vec<Vec<f64>>,
}

/// `points` equally spaced times over [t0, t1].
pub fn grid(t0: f64, t1: f64, points: usize) -> Vec<f64> {
    let n = points.max(2);
    (0..n)
        .map(|k| t0 + (t1 - t0) * k as f64 / (n - 1) as f64)
        .collect()
}

/// The series of a trajectory at the grid times (linear between output rows; a time outside
/// the rows takes the nearest row).
pub fn sample(scene: &Scene, traj: &Trajectory, times: &[f64]) -> Vec<Vec<f64>> {
    let nodes = scene.nodes();
    let width = nodes + Source::ALL.len();
    let mut out = vec![Vec::with_capacity(times.len()); width];
    // The values of output row k (temperatures °C, energies J), kept while the grid stays there.
    let fill = |k: usize, v: &mut Vec<f64>| {
        let y = &traj.states[k];
        let e = scene.loss_energy_by_source(y);
        v.clear();
        v.extend(y[..nodes].iter().map(|&t| k_to_c(t)));
        v.extend(Source::ALL.iter().map(|s| e[s.index()]));
    };
    let (mut a, mut b) = (Vec::with_capacity(width), Vec::with_capacity(width));
    let (mut ka, mut kb) = (usize::MAX, usize::MAX);
    let last = traj.times.len().saturating_sub(1);
    let mut k = 0;
    for &t in times {
        while k + 1 < last && traj.times[k + 1] < t {
            k += 1;
        }
        let k1 = (k + 1).min(last);
        if ka != k {
            fill(k, &mut a);
            ka = k;
        }
        if kb != k1 {
            fill(k1, &mut b);
            kb = k1;
        }
        let (ta, tb) = (traj.times[k], traj.times[k1]);
        let w = if tb > ta {
            ((t - ta) / (tb - ta)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        for (j, o) in out.iter_mut().enumerate() {
            o.push(a[j] + w * (b[j] - a[j]));
        }
    }
    out
}

/// Run a cycle as [`super::run::run`] does and sample its series on `points` grid times.
pub fn run_with_series(m: &Model, o: &RunOptions, points: usize) -> Result<(RunResult, RunSeries), JobError> {
    if !(POINTS.0..=POINTS.1).contains(&points) {
        return Err(JobError::option(
            "series_points",
            points,
            format!("[{}, {}]", POINTS.0, POINTS.1),
            format!(
                "series_points = {points}: must lie in [{}, {}]",
                POINTS.0, POINTS.1
            ),
        ));
    }
    solve_with_series(m, &prepare(m, o)?, points)
}

/// Integrate a prepared run ([`super::run::solve`]) and sample its series on `points` grid times
/// (checked by the caller: [`run_with_series`], or an uncertainty study's options).
pub fn solve_with_series(m: &Model, p: &Prepared, points: usize) -> Result<(RunResult, RunSeries), JobError> {
    let (r, traj) = solve_keeping(m, p, &mut |_, _| {})?;
    let t0 = p.segs.first().map_or(0.0, |s| s.t0);
    let t1 = p.segs.last().map_or(0.0, |s| s.t1);
    let times_s = grid(t0, t1, points);
    let values = sample(&p.scene, &traj, &times_s);
    Ok((
        r,
        RunSeries {
            times_s,
            names: names(&p.scene),
            values,
        },
    ))
}
