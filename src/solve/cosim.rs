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
use super::transient_options::{Method, TransientOptions, ROS3_MAX_NODES};
use crate::scene::{Inputs, Scene, Work};

/// One scene integrated piece by piece.
pub struct Stepper {
    opts: TransientOptions,
    atol: Vec<f64>,
    work: RefCell<Work>,
    carry: Carry,
    t: f64,
    sparse: bool,
}

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
    /// Auto, and the scene at most [`ROS3_MAX_NODES`] nodes): the error says why not.
    pub fn new(
        scene: &Scene,
        y0: Vec<f64>,
        inputs: Inputs,
        opts: TransientOptions,
        t0: f64,
    ) -> Result<Self, String> {
        let n = scene.nodes();
        if !matches!(opts.method, Method::Ros3 | Method::Auto) {
            return Err(format!(
                "co-simulation integrates with ros3, not {}",
                opts.method.name()
            ));
        }
        if n > ROS3_MAX_NODES {
            return Err(format!(
                "co-simulation integrates with ros3, for networks of at most {ROS3_MAX_NODES} nodes; this one has {n}"
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
            carry: Carry::new(y0),
            t: t0,
            sparse,
        })
    }

    /// Current time, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Current state (temperatures K, then energies J).
    pub fn state(&self) -> &[f64] {
        &self.carry.y
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

    /// Integrate to `t1` (> the current time) with the inputs in force.
    pub fn step(&mut self, scene: &Scene, t1: f64) -> Result<(), NumericalFailure> {
        let t0 = self.t;
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
        r?;
        self.t = t1;
        Ok(())
    }

    /// The losses (W per item) at the current state with the inputs in force.
    pub fn losses(&self, scene: &Scene) -> Vec<f64> {
        let mut w = self.work.borrow_mut();
        scene.evaluate_losses(&self.carry.y, &mut w);
        w.q.clone()
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
