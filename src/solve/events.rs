//! The controllers' switches on the diffsol path: diffsol locates the root of a switching
//! function (`RootFound(t_r, i)`) by interpolating inside the step it has taken, and its state
//! is then at the step's end. The interpolant's error is outside the error control, so the state
//! at the switch is not taken from it: the step is taken again from its start with `t_r` as the
//! stop time, and the controller switches at the state the solver reaches there. If the root
//! lies on the step's end, the switch is made there directly.
//!
//! Pitfall 3 of docs/numerics.md (a root in the step that lands on the stop time hides
//! `TstopReached`) is met by setting the segment's stop time again after every switch; a switch
//! at the segment's end ends the segment.

use diffsol::{OdeEquations, OdeSolverMethod};

use super::driver::Driver;
use super::equations::HostVector;
use super::trajectory::NumericalFailure;
use crate::scene::Scene;

/// Times closer than this (relative to max(1, |t|)) are the same instant.
const SAME_TIME: f64 = 1e-12;

/// A switching function this close below zero at the root's time counts as turned, K: the
/// state reached again differs from the interpolant by the solver's error; waiting for the sign
/// would restart the step over and over next to the root.
const SWITCH_SLACK: f64 = 1e-9;

/// What the diffsol loop keeps to restart a step at a root.
pub(crate) struct Events {
    /// Start of the step being taken: time and state.
    t: f64,
    y: Vec<f64>,
    /// The switching function whose root is the current stop time (the step was restarted).
    approach: Option<usize>,
    /// Switching functions, scratch.
    g: Vec<f64>,
    on: bool,
}

impl Events {
    pub(crate) fn new(scene: &Scene) -> Events {
        let on = scene.switching_count() > 0;
        Events {
            t: 0.0,
            y: if on {
                vec![0.0; scene.n_states()]
            } else {
                Vec::new()
            },
            approach: None,
            g: vec![0.0; scene.switching_count()],
            on,
        }
    }

    /// Remember the start of the step about to be taken.
    pub(crate) fn step_start<'a, Eqn, S>(&mut self, solver: &S)
    where
        Eqn: OdeEquations<T = f64, V: HostVector> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        if self.on {
            let st = solver.state();
            self.t = st.t;
            self.y.copy_from_slice(st.y.host());
        }
    }

    /// The stop time was reached: the segment's end (true), or the root being approached (the
    /// switch is made there when its function has turned; the segment goes on: false).
    pub(crate) fn at_stop<'a, Eqn, S>(
        &mut self,
        d: &Driver<'_>,
        solver: &mut S,
        t1: f64,
    ) -> Result<bool, NumericalFailure>
    where
        Eqn: OdeEquations<T = f64, V: HostVector> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let Some(idx) = self.approach.take() else {
            return Ok(true);
        };
        let turned = {
            let st = solver.state();
            d.scene
                .switching_functions_at(st.t, st.y.host(), &d.work.borrow(), &mut self.g);
            self.g[idx] >= -SWITCH_SLACK
        };
        if turned {
            return self.switch_here(d, solver, idx, t1);
        }
        // Not yet turned on the step taken again: go on to the segment's end (the root comes in
        // the next step, from a start next to it).
        self.resume(d, solver, t1)
    }

    /// Root of switching function `idx` at `tr` in the step just taken.
    pub(crate) fn at_root<'a, Eqn, S>(
        &mut self,
        d: &Driver<'_>,
        solver: &mut S,
        tr: f64,
        idx: usize,
        t1: f64,
    ) -> Result<bool, NumericalFailure>
    where
        Eqn: OdeEquations<T = f64, V: HostVector> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let t_end = solver.state().t;
        let same = |a: f64, b: f64| (a - b).abs() <= SAME_TIME * a.abs().max(1.0);
        if same(t_end, tr) {
            self.approach = None;
            return self.switch_here(d, solver, idx, t1);
        }
        // Take the step again from its start, to the root (or switch at the start).
        {
            let st = solver.state_mut();
            *st.t = self.t;
            st.y.host_mut().copy_from_slice(&self.y);
            d.scene
                .rhs(self.t, st.y.host(), &mut d.work.borrow_mut(), st.dy.host_mut());
            *st.h = d.restart_step(st.y.host(), st.dy.host(), *st.h, tr - self.t);
        }
        if same(self.t, tr) {
            self.approach = None;
            return self.switch_here(d, solver, idx, t1);
        }
        solver.set_stop_time(tr).map_err(|e| Self::fail(d, solver, e))?;
        self.approach = Some(idx);
        Ok(false)
    }

    /// Switch the controller of function `idx` at the solver's state (and any other whose switch
    /// is due there), renew the derivative and the step size, set the stop time `t1` again.
    /// True when the state is at `t1` (the segment is done).
    fn switch_here<'a, Eqn, S>(
        &mut self,
        d: &Driver<'_>,
        solver: &mut S,
        idx: usize,
        t1: f64,
    ) -> Result<bool, NumericalFailure>
    where
        Eqn: OdeEquations<T = f64, V: HostVector> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let t = solver.state().t;
        let before = d.work.borrow().net.switches.clone();
        {
            let y = solver.state().y.host().to_vec();
            let mut w = d.work.borrow_mut();
            // The end of a minimum on or off time switches only when a switch is due then.
            if !d.scene.is_dwell_event(t, idx, &w) {
                d.scene.switch_control(t, idx, &mut w);
            }
            d.scene.settle_controls_at(t, &y, &mut w);
        }
        d.log_changed(t, &before);
        self.resume(d, solver, t1)
    }

    /// Restart at the solver's state with the current modes and set the stop time `t1` again;
    /// true when the state is at `t1`.
    fn resume<'a, Eqn, S>(
        &mut self,
        d: &Driver<'_>,
        solver: &mut S,
        t1: f64,
    ) -> Result<bool, NumericalFailure>
    where
        Eqn: OdeEquations<T = f64, V: HostVector> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let st = solver.state_mut();
        let t = *st.t;
        let done = t1 - t <= SAME_TIME * t.abs().max(1.0);
        if done {
            *st.t = t1;
        }
        d.scene
            .rhs(*st.t, st.y.host(), &mut d.work.borrow_mut(), st.dy.host_mut());
        *st.h = d.restart_step(st.y.host(), st.dy.host(), *st.h, (t1 - t).max(0.0));
        if !done {
            solver.set_stop_time(t1).map_err(|e| Self::fail(d, solver, e))?;
        }
        Ok(done)
    }

    fn fail<'a, Eqn, S>(d: &Driver<'_>, solver: &S, e: diffsol::error::DiffsolError) -> NumericalFailure
    where
        Eqn: OdeEquations<T = f64, V: HostVector> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let st = solver.state();
        d.failure(st.t, st.y.host(), format!("at a controller's switch: {e}"))
    }
}
