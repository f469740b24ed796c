//! Steady state with controllers that switch (`[[thermal.controls]]`): an equilibrium exists when
//! some combination of the two-point controllers' modes has one at which no controller would
//! switch (every switching function ≤ 0 there); the valves take the region their sensor's
//! temperature gives. When no combination has one, the network cycles between the set points:
//! the cycle is found by following the transient at the fixed inputs until a controller's last
//! two periods agree to 1e-9, and its period (between the last two such switches), the
//! time-mean of every node over that period and its band (min, max) are reported instead of an
//! equilibrium.

use super::steady::{SteadyError, SteadySolution};
use super::transient::{integrate, Method, Segment, TransientOptions};
use crate::scene::{Inputs, Scene};

/// Most two-point controllers whose mode combinations are tried (2^8 = 256 solves).
pub const MAX_TWO_POINT: usize = 8;

/// A limit cycle of the network at fixed inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitCycle {
    /// The controller whose switches mark the period.
    pub controller: String,
    /// Period, s.
    pub period_s: f64,
    /// Time-mean temperature of every node over one period, K.
    pub mean_k: Vec<f64>,
    /// Lowest temperature of every node over the period, K.
    pub min_k: Vec<f64>,
    /// Highest, K.
    pub max_k: Vec<f64>,
}

/// Samples of one period (the mean and the band are taken over them).
const SAMPLES: usize = 400;

/// True when controller `k` has switched at least 5 times and its last two periods (between
/// switches the same way) agree to 1e-9 relative: the cycle has settled.
fn periods_agree(events: &[(f64, usize)], k: usize) -> bool {
    let t: Vec<f64> = events.iter().filter(|e| e.1 == k).map(|e| e.0).collect();
    let m = t.len();
    m >= 5 && {
        let (p1, p2) = (t[m - 1] - t[m - 3], t[m - 3] - t[m - 5]);
        (p1 - p2).abs() <= 1e-9 * p1.abs()
    }
}

/// Follow the transient of `scene` at `inputs` from the node temperatures `t0` (K) until one
/// controller's period has settled ([`periods_agree`]); the last period's mean and band.
pub fn find_limit_cycle(scene: &Scene, inputs: Inputs, t0: &[f64]) -> Result<LimitCycle, SteadyError> {
    let n = scene.nodes();
    let o = TransientOptions {
        method: Method::Ros3,
        rtol: 1e-10,
        atol: 1e-10,
        ..TransientOptions::default()
    };
    let fail =
        |e: super::transient::NumericalFailure| SteadyError::Model(format!("limit-cycle search failed: {e}"));
    let start = scene.clone().with_initial(t0.to_vec());
    // Segments of growing length until some controller has switched at least 5 times.
    let (mut t, mut len) = (0.0, 60.0);
    let mut segs = Vec::new();
    let mut events = Vec::new();
    for _ in 0..30 {
        segs.push(Segment {
            t0: t,
            t1: t + len,
            inputs,
        });
        t += len;
        len *= 2.0;
        let traj = integrate(&start, &segs, &o, &mut |_, _| {}).map_err(fail)?;
        events = traj.events;
        if (0..scene.thermal().controls.len()).any(|k| periods_agree(&events, k)) {
            break;
        }
    }
    let Some((k, times)) = (0..scene.thermal().controls.len())
        .map(|k| {
            (
                k,
                events
                    .iter()
                    .filter(|e| e.1 == k)
                    .map(|e| e.0)
                    .collect::<Vec<f64>>(),
            )
        })
        .find(|(k, _)| periods_agree(&events, *k))
    else {
        return Err(SteadyError::Model(
            "no mode combination of the controllers has an equilibrium and the transient does not cycle"
                .into(),
        ));
    };
    // The same direction: every other switch. The last full period.
    let m = times.len();
    let (a, b) = (times[m - 3], times[m - 1]);
    let period = b - a;
    let fine: Vec<Segment> = segs
        .iter()
        .copied()
        .filter(|s| s.t1 <= a)
        .chain(std::iter::once(Segment {
            t0: segs.iter().map(|s| s.t1).filter(|&x| x <= a).fold(0.0, f64::max),
            t1: a,
            inputs,
        }))
        .filter(|s| s.t1 > s.t0)
        .chain(samples(a, times[m - 2], inputs))
        .chain(samples(times[m - 2], b, inputs))
        .collect();
    let traj = integrate(&start, &fine, &o, &mut |_, _| {}).map_err(fail)?;
    let rows = traj.states.len();
    let last: Vec<&[f64]> = (rows - SAMPLES - 1..rows)
        .filter_map(|r| traj.states.get(r))
        .collect();
    let mut mean = vec![0.0; n];
    let mut lo = vec![f64::INFINITY; n];
    let mut hi = vec![f64::NEG_INFINITY; n];
    // Trapezoidal mean over the period (the rows of `samples`, the switch between the halves
    // one of them, so that the band holds the switching temperatures).
    let times_of = &traj.times[rows - SAMPLES - 1..];
    for (w, tw) in last.windows(2).zip(times_of.windows(2)) {
        for i in 0..n {
            mean[i] += 0.5 * (w[0][i] + w[1][i]) * (tw[1] - tw[0]) / period;
        }
    }
    for y in &last {
        for i in 0..n {
            lo[i] = lo[i].min(y[i]);
            hi[i] = hi[i].max(y[i]);
        }
    }
    Ok(LimitCycle {
        controller: scene.thermal().controls[k].name.clone(),
        period_s: period,
        mean_k: mean,
        min_k: lo,
        max_k: hi,
    })
}

/// SAMPLES/2 equal segments from `t0` to `t1`.
fn samples(t0: f64, t1: f64, inputs: Inputs) -> impl Iterator<Item = Segment> {
    let k = SAMPLES / 2;
    let dt = (t1 - t0) / k as f64;
    (0..k).map(move |i| Segment {
        t0: t0 + i as f64 * dt,
        t1: if i + 1 == k { t1 } else { t0 + (i + 1) as f64 * dt },
        inputs,
    })
}

/// The solution a limit cycle stands for: its mean temperatures (no Newton iterations).
pub fn mean_solution(c: &LimitCycle) -> SteadySolution {
    SteadySolution {
        temperatures: c.mean_k.clone(),
        iterations: 0,
        ptc_iterations: 0,
        residual_w: 0.0,
        method: "limit_cycle",
        tolerance_w: 0.0,
        residual_history_w: Vec::new(),
    }
}
