//! The input and the output of a transient run: the segments with constant inputs, the
//! trajectory with its counters, the failure that ends a run, the memory check before a run
//! and the energy balance after it.

use super::rows::Rows;
use super::transient_options::TransientOptions;
use crate::scene::{Inputs, Scene};

/// One interval with constant inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Start, s.
    pub t0: f64,
    /// End, s.
    pub t1: f64,
    /// Inputs during the interval.
    pub inputs: Inputs,
}

/// Solver work counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps (error test failures).
    pub rejected: usize,
    /// Right-hand-side evaluations.
    pub rhs_evals: usize,
    /// Jacobian evaluations (loss derivative columns).
    pub jac_evals: usize,
    /// LU factorisations (linear solver setups).
    pub lu_factorisations: usize,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Newton convergence failures.
    pub newton_failures: usize,
    /// Restarts at input jumps.
    pub restarts: usize,
    /// Cycle samples whose loss terms were prepared (once per distinct input sample).
    pub samples_prepared: usize,
    /// Controller switches located as events (switching-function roots).
    pub events: usize,
    /// True when the Newton iterations used the sparse LU.
    pub sparse: bool,
    /// The method that integrated (`auto` resolved).
    pub method: &'static str,
}

/// The result: the state at every segment boundary, and the losses there.
#[derive(Debug, Clone)]
pub struct Trajectory {
    /// Output times, s (segment boundaries).
    pub times: Vec<f64>,
    /// State at each time (temperatures K, energies J).
    pub states: Rows,
    /// Loss of each item at each time (W), with the inputs of the segment that starts there (the
    /// last row: of the last segment). Empty when `TransientOptions::record_losses` is off.
    pub losses: Rows,
    /// Segment index whose inputs each row shows.
    pub segment: Vec<usize>,
    /// Each controller's share at each row (a two-point controller: 1 on, its off fraction off;
    /// a valve: the cooler's share), after the switches due at that instant; then each PI
    /// valve's integral.
    pub controls: Rows,
    /// Switches of each controller over the run.
    pub switches: Vec<usize>,
    /// Every located switch: (time, s; controller index).
    pub events: Vec<(f64, usize)>,
    /// Counters.
    pub stats: Stats,
    /// Wall time of the integration, s.
    pub wall_time_s: f64,
}

/// The solver could not continue.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("numerical failure at t = {time:.6} s, node {node}{}: {message}", item.as_ref().map(|i| format!(", loss item {i}")).unwrap_or_default())]
pub struct NumericalFailure {
    /// Time, s.
    pub time: f64,
    /// Node concerned (the one changing fastest relative to its tolerance, or the one that became
    /// non-finite).
    pub node: String,
    /// Loss item concerned (non-finite, or the largest at that time).
    pub item: Option<String>,
    /// What happened.
    pub message: String,
}

/// Values a run keeps in memory for its output rows: one row per segment end (and the start),
/// each holding the state and, when recorded, every loss item.
pub fn stored_values(scene: &Scene, segments: &[Segment], opts: &TransientOptions) -> usize {
    let per_row = scene.n_states()
        + if opts.record_losses {
            scene.losses().items.len()
        } else {
            0
        };
    (segments.len() + 1).saturating_mul(per_row)
}

/// At most this many stored values (8 bytes each: 400 MB) per run: a larger run (a long cycle on
/// a finely meshed housing) is refused up front with the figures, not found out by the allocator.
pub const MAX_STORED_VALUES: usize = 50_000_000;

/// Refuse a run above [`MAX_STORED_VALUES`], saying what would help.
pub fn check_stored_values(
    scene: &Scene,
    segments: &[Segment],
    opts: &TransientOptions,
) -> Result<(), String> {
    let stored = stored_values(scene, segments, opts);
    if stored <= MAX_STORED_VALUES {
        return Ok(());
    }
    let rows = segments.len() + 1;
    let states_only = rows.saturating_mul(scene.n_states());
    let help = if opts.record_losses && states_only <= MAX_STORED_VALUES {
        "run with --summary-only (no per-row losses), shorten the cycle or use fewer wall patches"
    } else {
        "shorten the cycle or use fewer wall patches"
    };
    Err(format!(
        "this run would keep {rows} rows × {} values = {stored} values in memory, more than the \
         limit of {MAX_STORED_VALUES} (400 MB): {help}",
        stored / rows
    ))
}

/// Energy bookkeeping of a trajectory's last state.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct EnergyBalance {
    /// Loss energy, J (sum over items).
    pub lost: f64,
    /// Heat stored in the nodes, Σ C_i (T_i(end) − T_i(0)), J.
    pub stored: f64,
    /// Heat into boundaries, J.
    pub to_boundaries: f64,
    /// |lost − stored − to_boundaries| / max(|lost|, |stored|, |to_boundaries|).
    pub relative: f64,
}

/// Energy balance between the first and last state of a trajectory.
pub fn energy_balance(scene: &Scene, traj: &Trajectory) -> EnergyBalance {
    let n = scene.nodes();
    let (y0, y1) = match (traj.states.first(), traj.states.last()) {
        (Some(a), Some(b)) => (a, b),
        _ => {
            return EnergyBalance {
                lost: 0.0,
                stored: 0.0,
                to_boundaries: 0.0,
                relative: 0.0,
            }
        }
    };
    let lost = scene.loss_energy(y1) - scene.loss_energy(y0);
    let stored: f64 = (0..n)
        .map(|i| scene.thermal().capacity[i] * (y1[i] - y0[i]))
        .sum();
    let b = scene.boundary_energy_index();
    let to_b = y1[b] - y0[b];
    let scale = lost
        .abs()
        .max(stored.abs())
        .max(to_b.abs())
        .max(f64::MIN_POSITIVE);
    EnergyBalance {
        lost,
        stored,
        to_boundaries: to_b,
        relative: (lost - stored - to_b).abs() / scale,
    }
}
