//! Co-simulation stepping: a [`Stepper`] integrates a [`Scene`] from one communication point to
//! the next with inputs an importer sets in between (an FMU's `doStep`), with ROS3
//! ([`super::rosenbrock`]) continuing from one call to the next exactly as a drive-cycle run
//! continues from one segment to the next: the same starting step, the same step-size
//! proposal carried over, the same learnt loss slopes, the same f evaluated at each segment's
//! start with its inputs. A stepper fed a run's segments one per call reproduces the run's
//! states (`tests/cosim.rs`).
//!
//! The scene is the caller's: it may change the boundary temperatures between calls
//! ([`crate::scene::ThermalScene::set_boundary_ramp`]) and then calls [`Stepper::refresh`].

use std::cell::{Cell, RefCell};

use diffsol::{FaerSparseMat, NalgebraMat};

use super::dense_lu::SmallDenseLu;
use super::driver::Driver;
use super::equations::SceneEquations;
use super::rosenbrock::{self, Carry};
use super::sparse_lu::NetworkSparseLu;
use super::trajectory::NumericalFailure;
use super::transient::state_atol;
use super::transient_options::{Method, TransientOptions};
use crate::scene::{Inputs, Scene, Work};

/// One scene integrated piece by piece.
pub struct Stepper {
    opts: TransientOptions,
    atol: Vec<f64>,
    work: RefCell<Work>,
    carry: Carry,
    t: f64,
    sparse: bool,
    /// The state at `t` (the carry's, or interpolated inside a step taken past `t`).
    y_out: Vec<f64>,
    /// A step taken past `t` (see [`Stepper::step_ahead`]); the carry is at its end.
    ahead: Option<Ahead>,
}

/// A natural ROS3 step [ta, tb] taken past the communication point: what the cubic Hermite
/// interpolant needs (its end state is the carry's).
struct Ahead {
    ta: f64,
    tb: f64,
    ya: Vec<f64>,
    fa: Vec<f64>,
    fb: Vec<f64>,
}

/// The stepper steps past a communication point only when its step-size proposal is at least
/// this many times the communication step: coarser communication steps land exactly (as the
/// run's own grid does), finer ones are interpolated.
/// (After a step landed on a communication point the proposal is at most 5 times it, the
/// controller's growth bound, hence a ratio below 5.)
pub const LOOKAHEAD_RATIO: f64 = 4.0;

/// Communication steps of this length and longer land exactly, s: a drive cycle's samples
/// (1 s for WLTC data) are then the integrator's grid, and the co-simulation reproduces the run
/// (`tests/fmu.rs`); shorter ones, with unchanged inputs, are interpolated.
pub const LOOKAHEAD_MAX_STEP: f64 = 0.5;

/// Counters of a stepper.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepperStats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// LU factorisations.
    pub lu_factorisations: usize,
}

impl Stepper {
    /// A stepper at time `t0` and state `y0` (temperatures K, zero energies: see
    /// [`Scene::initial_state`]) with `inputs`. The method is ROS3 (`opts.method` must be ROS3 or
    /// Auto; the error says why not) whatever the network's size: [`ROS3_MAX_NODES`](super::transient_options::ROS3_MAX_NODES) is where
    /// `Method::Auto` prefers TR-BDF2 for a whole run's speed, not a limit of ROS3 (a larger
    /// network takes the sparse LU from `SPARSE_FROM_STATES` states on, as a run does).
    pub fn new(
        scene: &Scene,
        y0: Vec<f64>,
        inputs: Inputs,
        opts: TransientOptions,
        t0: f64,
    ) -> Result<Self, String> {
        if !matches!(opts.method, Method::Ros3 | Method::Auto) {
            return Err(format!(
                "co-simulation integrates with ros3, not {}",
                opts.method.name()
            ));
        }
        if y0.len() != scene.n_states() {
            return Err(format!(
                "initial state of {} values, the scene has {}",
                y0.len(),
                scene.n_states()
            ));
        }
        let atol = state_atol(scene, opts.atol);
        let work = RefCell::new(scene.work(inputs));
        {
            // As the transient driver starts a run.
            let mut w = work.borrow_mut();
            scene.initial_control_modes(&y0, &mut w);
            scene.settle_controls(&y0, &mut w);
            w.net.switches.iter_mut().for_each(|x| *x = 0);
            scene.settle_controls(&y0, &mut w);
        }
        let sparse = opts.linear_algebra.is_sparse(scene.n_states());
        Ok(Self {
            opts,
            atol,
            work,
            y_out: y0.clone(),
            carry: Carry::new(y0),
            t: t0,
            sparse,
            ahead: None,
        })
    }

    /// Current time, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Current state (temperatures K, then energies J).
    pub fn state(&self) -> &[f64] {
        &self.y_out
    }

    /// The inputs in force.
    pub fn inputs(&self) -> Inputs {
        self.work.borrow().inputs
    }

    /// Switch to `inputs` (the per-sample loss terms are prepared only when they change).
    pub fn set_inputs(&mut self, scene: &Scene, inputs: Inputs) {
        let mut w = self.work.borrow_mut();
        if w.inputs != inputs {
            scene.set_inputs(inputs, &mut w);
        }
    }

    /// Forget what the work area cached for the current inputs (after the caller changed the
    /// scene's boundary temperatures).
    pub fn refresh(&mut self, scene: &Scene) {
        let mut w = self.work.borrow_mut();
        let inputs = w.inputs;
        scene.set_inputs(inputs, &mut w);
    }

    /// Integrate to `t1` (> the current time) with the inputs in force, landing on it. After a
    /// step taken past the current time ([`Stepper::step_ahead`]) the integrator restarts from
    /// the interpolated state there.
    pub fn step(&mut self, scene: &Scene, t1: f64) -> Result<(), NumericalFailure> {
        self.restart();
        self.advance(scene, self.t, t1)?;
        self.t = t1;
        self.y_out.copy_from_slice(&self.carry.y);
        Ok(())
    }

    /// Drop a step taken past the current time ([`Stepper::step_ahead`]): the integrator goes on
    /// from the (interpolated) state at the current time, as after new inputs. The step-size
    /// proposal is kept.
    pub fn restart(&mut self) {
        if self.ahead.take().is_some() {
            self.carry.y.copy_from_slice(&self.y_out);
        }
    }

    /// Integrate to `t1` with the inputs in force (and boundary lines valid up to `t_max` ≥ `t1`),
    /// which the caller did not change since the last call unless it called
    /// [`Stepper::restart`]: the integrator keeps its own steps, each at most up to
    /// `t_max`, and the state at `t1` comes from the cubic Hermite interpolant of the step
    /// containing it, from the states and derivatives f at both ends (the Hermite basis and its
    /// mapping to a step [ta, tb], slopes scaled by h, as read in the notes "Cubic Hermite
    /// Splines" of github.com/uw-ipd/tmol; the same cubic as SUNDIALS ARKODE's Hermite dense
    /// output, `arkInterpEvaluate_Hermite` in `arkode_interp.c`, docs/fmu.md; Hairer, Nørsett &
    /// Wanner, Solving ODEs I, §II.6, and Shampine 1985, "Interpolation for Runge–Kutta
    /// methods", could not be read here);
    /// `hermite_is_exact_on_cubics` checks the formula. No continuous extension of ROS3's
    /// own is used (none was read with its coefficients, [`super::rosenbrock`]; a continuous
    /// extension would need its stages). The interpolant's error is O(h⁴), below the step's
    /// embedded error estimate O(h³), which the step-size control keeps under the tolerance.
    /// Being linear
    /// in the end states and their f, the interpolant keeps every linear invariant of the
    /// states, so the energy balance (loss energies against node and boundary energies) closes
    /// at the interpolated point as at the step ends.
    ///
    /// Used only for communication steps shorter than [`LOOKAHEAD_MAX_STEP`] and at most
    /// 1/[`LOOKAHEAD_RATIO`] of the step-size proposal; else this is [`Stepper::step`]. A step
    /// taken ahead in which a controller or thermostat switched (f or its slope jumps there,
    /// which the interpolant cannot follow) is undone, and the integrator lands on `t1` from the
    /// step's start.
    pub fn step_ahead(&mut self, scene: &Scene, t1: f64, t_max: f64) -> Result<(), NumericalFailure> {
        let h_comm = t1 - self.t;
        let proposal = self.carry.h.unwrap_or(0.0);
        if h_comm >= LOOKAHEAD_MAX_STEP || proposal < LOOKAHEAD_RATIO * h_comm || t_max < t1 {
            return self.step(scene, t1);
        }
        while !self.ahead.as_ref().is_some_and(|a| a.tb >= t1) {
            let (ta, fa) = match self.ahead.take() {
                Some(a) => (a.tb, a.fb),
                None => (self.t, self.f_at(scene, self.t, &self.carry.y)),
            };
            let ya = self.carry.y.clone();
            let tb = (ta + self.carry.h.unwrap_or(h_comm))
                .min(t_max)
                .max(t1.min(t_max));
            let (saved, modes) = (self.carry.clone(), self.modes());
            self.advance(scene, ta, tb)?;
            if self.modes() != modes {
                self.undo(scene, saved, &modes);
                self.advance(scene, ta, t1)?;
                self.t = t1;
                self.y_out.copy_from_slice(&self.carry.y);
                return Ok(());
            }
            let fb = self.f_at(scene, tb, &self.carry.y);
            self.ahead = Some(Ahead { ta, tb, ya, fa, fb });
        }
        if let Some(a) = &self.ahead {
            hermite(a, &self.carry.y, t1, &mut self.y_out);
        }
        self.t = t1;
        Ok(())
    }

    /// The controllers' and thermostats' modes.
    fn modes(&self) -> (Vec<u8>, Vec<u8>) {
        let w = self.work.borrow();
        (w.net.mode.clone(), w.net.kink_mode.clone())
    }

    /// Back to the carry `saved` and the `modes` before a step (the counters keep the work).
    fn undo(&mut self, scene: &Scene, saved: Carry, modes: &(Vec<u8>, Vec<u8>)) {
        let stats = std::mem::take(&mut self.carry.stats);
        self.carry = saved;
        self.carry.stats = stats;
        let mut w = self.work.borrow_mut();
        for (k, &m) in modes.0.iter().enumerate() {
            scene.set_control_mode(k, m, &mut w);
        }
        w.net.kink_mode.copy_from_slice(&modes.1);
    }

    /// f at (t, y) with the inputs in force.
    fn f_at(&self, scene: &Scene, t: f64, y: &[f64]) -> Vec<f64> {
        let mut f = vec![0.0; y.len()];
        self.driver(scene).rhs(t, y, &mut f);
        f
    }

    fn driver<'a>(&'a self, scene: &'a Scene) -> Driver<'a> {
        Driver {
            scene,
            work: &self.work,
            segments: &[],
            opts: &self.opts,
            atol: &self.atol,
            events: Cell::new(0),
            event_log: RefCell::new(Vec::new()),
        }
    }

    /// ROS3 from the carry at `t0` to `t1`, landing on it.
    fn advance(&mut self, scene: &Scene, t0: f64, t1: f64) -> Result<(), NumericalFailure> {
        let d = Driver {
            scene,
            work: &self.work,
            segments: &[],
            opts: &self.opts,
            atol: &self.atol,
            events: Cell::new(0),
            event_log: RefCell::new(Vec::new()),
        };
        macro_rules! advance_with {
            ($m:ty, $ls:ty) => {{
                let mut eqn = SceneEquations::<$m>::new(scene, &self.work, self.carry.y.clone());
                eqn.assembled = self.opts.assembled_jacobian;
                rosenbrock::advance::<$m, $ls>(&d, &eqn, &mut self.carry, t0, t1)
            }};
        }
        let r = if self.sparse {
            advance_with!(FaerSparseMat<f64>, NetworkSparseLu)
        } else {
            advance_with!(NalgebraMat<f64>, SmallDenseLu)
        };
        r
    }

    /// The losses (W per item) at the current state with the inputs in force.
    pub fn losses(&self, scene: &Scene) -> Vec<f64> {
        let mut q = vec![0.0; scene.items()];
        self.losses_into(scene, &mut q);
        q
    }

    /// [`Stepper::losses`] into `q` (one per item).
    pub fn losses_into(&self, scene: &Scene, q: &mut [f64]) {
        let mut w = self.work.borrow_mut();
        scene.evaluate_losses(&self.y_out, &mut w);
        q.copy_from_slice(&w.q);
    }

    /// Counters so far.
    pub fn stats(&self) -> StepperStats {
        StepperStats {
            steps: self.carry.stats.steps,
            rejected: self.carry.stats.rejected,
            lu_factorisations: self.carry.stats.lu,
        }
    }
}

/// The cubic Hermite interpolant of step `a` (end state `yb`) at `t` into `out`: the basis
/// 2s³ − 3s² + 1, (s³ − 2s² + s)h, −2s³ + 3s², (s³ − s²)h of the values and slopes at both ends
/// (s = (t − ta)/h).
fn hermite(a: &Ahead, yb: &[f64], t: f64, out: &mut [f64]) {
    let h = a.tb - a.ta;
    let s = ((t - a.ta) / h).clamp(0.0, 1.0);
    let (s2, s3) = (s * s, s * s * s);
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = (s3 - 2.0 * s2 + s) * h;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = (s3 - s2) * h;
    for (i, o) in out.iter_mut().enumerate() {
        *o = h00 * a.ya[i] + h10 * a.fa[i] + h01 * yb[i] + h11 * a.fb[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cubic Hermite interpolant reproduces a cubic exactly (from its values and slopes at
    /// both ends), and its ends are the step's ends.
    #[test]
    fn hermite_is_exact_on_cubics() {
        let p = |t: f64| 2.0 - 3.0 * t + 0.5 * t * t - 0.25 * t * t * t;
        let dp = |t: f64| -3.0 + t - 0.75 * t * t;
        let (ta, tb) = (1.5, 4.0);
        let a = Ahead {
            ta,
            tb,
            ya: vec![p(ta)],
            fa: vec![dp(ta)],
            fb: vec![dp(tb)],
        };
        let mut out = [0.0];
        for t in [ta, 2.0, 2.75, 3.9, tb] {
            hermite(&a, &[p(tb)], t, &mut out);
            assert!(
                (out[0] - p(t)).abs() <= 1e-12 * p(t).abs().max(1.0),
                "{t}: {}",
                out[0]
            );
        }
        // Not exact on a quartic: the test could fail.
        let q = |t: f64| t.powi(4);
        let a = Ahead {
            ta,
            tb,
            ya: vec![q(ta)],
            fa: vec![4.0 * ta.powi(3)],
            fb: vec![4.0 * tb.powi(3)],
        };
        hermite(&a, &[q(tb)], 2.75, &mut out);
        assert!((out[0] - q(2.75)).abs() > 1e-3);
    }
}
