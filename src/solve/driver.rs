//! What the integrators share ([`super::transient`]'s diffsol loop and [`super::rosenbrock`]):
//! the scene and its work area, the segments, the tolerances, the rows a run records and the
//! diagnosis of a failure.

use std::cell::RefCell;

use super::trajectory::{NumericalFailure, Segment, Trajectory};
use super::transient_options::TransientOptions;
use crate::scene::{Scene, Work};

/// What the integrators share: the scene, its work area, the segments and the tolerances.
pub(crate) struct Driver<'s> {
    pub(super) scene: &'s Scene,
    pub(super) work: &'s RefCell<Work>,
    pub(crate) segments: &'s [Segment],
    pub(crate) opts: &'s TransientOptions,
    pub(crate) atol: &'s [f64],
    /// Controller events located so far (diffsol path).
    pub(crate) events: std::cell::Cell<usize>,
    /// Every switch located: (time, controller).
    pub(crate) event_log: RefCell<Vec<(f64, usize)>>,
}

impl Driver<'_> {
    /// `dy = f(t, y)` with the current inputs (the losses stay in the work area).
    pub(crate) fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        self.scene.rhs(t, y, &mut self.work.borrow_mut(), dy);
    }

    /// True when some boundary temperature moves (then f depends on t).
    pub(crate) fn boundaries_move(&self) -> bool {
        self.scene.thermal().boundaries_move()
    }

    /// True when ∂f/∂t = 0 on the step from `t` (no boundary temperature moves there).
    pub(crate) fn time_rate_vanishes(&self, t: f64) -> bool {
        self.scene.thermal().boundaries_still_at(t)
    }

    /// ∂f/∂t at (t, y).
    pub(crate) fn time_derivative(&self, t: f64, y: &[f64], out: &mut [f64]) {
        self.scene.time_derivative(t, y, &mut self.work.borrow_mut(), out);
    }

    /// The losses (W per item) of the last right-hand side, into `out`.
    pub(crate) fn losses_into(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.work.borrow().q);
    }

    /// ∂q_k/∂T_oil of every item at (t, y) by a forward difference.
    pub(crate) fn loss_slopes(&self, t: f64, y: &[f64], out: &mut [f64]) {
        self.scene.loss_slopes(t, y, &mut self.work.borrow_mut(), out);
    }

    /// Number of loss items.
    pub(crate) fn items(&self) -> usize {
        self.scene.items()
    }

    /// Oil temperature that sets the oil properties at state `y`, K.
    pub(crate) fn oil_temp(&self, y: &[f64]) -> f64 {
        self.scene.oil_temp(y)
    }

    /// Switch to the inputs of segment `k`.
    pub(crate) fn switch_inputs(&self, k: usize) {
        self.scene
            .set_inputs(self.segments[k].inputs, &mut self.work.borrow_mut());
    }

    /// Count a switch of switching function `idx` at time `t`.
    pub(crate) fn log_event(&self, t: f64, idx: usize) {
        let k = idx / crate::scene::controls::EVENTS_PER_CONTROL;
        if k < self.scene.thermal().controls.len() {
            self.events.set(self.events.get() + 1);
            self.event_log.borrow_mut().push((t, k));
        }
    }

    /// Settle the controllers at time `t` and state `y` (the switches due there); true when one
    /// switched.
    pub(crate) fn settle_controls(&self, t: f64, y: &[f64]) -> bool {
        self.scene.settle_controls_at(t, y, &mut self.work.borrow_mut())
    }

    /// Settle the controllers at time `t` and state `y`, logging each controller that switched.
    pub(crate) fn settle_and_log(&self, t: f64, y: &[f64]) {
        let before = self.work.borrow().net.switches.clone();
        self.settle_controls(t, y);
        self.log_changed(t, &before);
    }

    /// Log a switch at `t` of every controller whose switch count differs from `before`.
    pub(crate) fn log_changed(&self, t: f64, before: &[usize]) {
        let after = self.work.borrow().net.switches.clone();
        for (k, (a, b)) in after.iter().zip(before).enumerate() {
            if a != b {
                self.log_event(t, k * crate::scene::controls::EVENTS_PER_CONTROL);
            }
        }
    }

    /// Forget a non-finite trial the integrator recovered from.
    pub(crate) fn clear_failure(&self) {
        self.work.borrow_mut().failure = None;
    }

    /// Record the row at time `t` whose losses [`Self::rhs`] has just evaluated at `y`.
    pub(crate) fn record_evaluated(&self, traj: &mut Trajectory, t: f64, y: &[f64], seg: usize) {
        if self.opts.record_losses {
            traj.losses.push(&self.work.borrow().q);
        }
        traj.times.push(t);
        traj.states.push(y);
        traj.segment.push(seg);
        self.record_controls(traj, y);
    }

    /// The controllers' shares at state `y` into the row.
    fn record_controls(&self, traj: &mut Trajectory, y: &[f64]) {
        let th = self.scene.thermal();
        if th.controls.is_empty() {
            return;
        }
        let w = self.work.borrow();
        // The shares, then every PI valve's integral.
        let row: Vec<f64> = th
            .controls
            .iter()
            .zip(&w.net.mode)
            .enumerate()
            .map(|(k, (c, &m))| c.share(m, y[c.sensor], th.integral_in(k, y)).0)
            .chain((0..th.controls.len()).filter_map(|k| th.integral_row(k).map(|r| y[r])))
            .collect();
        traj.controls.push(&row);
    }

    /// The step budget is spent.
    pub(crate) fn budget_failure(&self, t: f64, y: &[f64]) -> NumericalFailure {
        self.failure(
            t,
            y,
            format!(
                "step budget of {} exceeded (the network is too stiff for {} at this tolerance, or oscillates)",
                self.opts.max_steps,
                self.opts.method.resolve(self.scene.nodes()).name()
            ),
        )
    }

    /// Record the row at time `t`: the state and the losses with the current inputs (those of
    /// segment `seg`, which the caller has already switched to).
    pub(super) fn record(&self, traj: &mut Trajectory, t: f64, y: &[f64], seg: usize) {
        if self.opts.record_losses {
            let mut w = self.work.borrow_mut();
            self.scene.evaluate_losses(y, &mut w);
            traj.losses.push(&w.q);
        }
        traj.times.push(t);
        traj.states.push(y);
        traj.segment.push(seg);
        self.record_controls(traj, y);
    }

    /// Failure at the solver's current state: names the node with the largest weighted rate and
    /// the item (non-finite, else the largest loss).
    pub(crate) fn failure(&self, t: f64, y: &[f64], message: String) -> NumericalFailure {
        let mut w = self.work.borrow_mut();
        if let Some(f) = w.failure.take() {
            return NumericalFailure {
                time: f.time,
                node: f.node,
                item: f.item,
                message: format!("{} ({message})", f.what),
            };
        }
        let n = self.scene.nodes();
        let mut dy = vec![0.0; y.len()];
        self.scene.rhs(t, y, &mut w, &mut dy);
        let node = (0..n)
            .max_by(|&a, &b| {
                let ra = dy[a].abs() / (self.atol[a] + self.opts.rtol * y[a].abs());
                let rb = dy[b].abs() / (self.atol[b] + self.opts.rtol * y[b].abs());
                ra.total_cmp(&rb)
            })
            .unwrap_or(self.scene.thermal().oil);
        let item =
            w.q.iter()
                .enumerate()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .map(|(k, _)| {
                    let it = &self.scene.losses().items[k];
                    format!("{}:{}", it.source.as_str(), it.name)
                });
        NumericalFailure {
            time: t,
            node: self.scene.thermal().names[node].clone(),
            item,
            message,
        }
    }

    /// Starting step after a restart (Hairer, Nørsett & Wanner I, II.4), capped by the previous
    /// step and the segment length.
    pub(crate) fn restart_step(&self, y: &[f64], f: &[f64], h_prev: f64, len: f64) -> f64 {
        let (mut d0, mut d1) = (0.0, 0.0);
        for ((yi, fi), ai) in y.iter().zip(f).zip(self.atol) {
            let w = ai + self.opts.rtol * yi.abs();
            d0 += (yi / w).powi(2);
            d1 += (fi / w).powi(2);
        }
        let k = y.len() as f64;
        let (d0, d1) = ((d0 / k).sqrt(), (d1 / k).sqrt());
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        h0.min(h_prev.abs().max(1e-6)).min(len).max(1e-10)
    }
}
