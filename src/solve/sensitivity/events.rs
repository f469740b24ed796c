//! Switches of the controllers inside the tangent integrator, and the jump of the
//! sensitivities there (the saltation condition).
//!
//! A controller switches when its switching function g(T, θ) (affine in its sensor's
//! temperature, its set points depending on θ) reaches zero at τ. Before the switch the
//! right-hand side is f⁻, after it f⁺. Differentiating x(τ(θ), θ) and g(x(τ), θ) = 0
//! (Filippov 1988, §2.11; the sensitivity form in Hiskens & Pai, "Trajectory sensitivity
//! analysis of hybrid systems", IEEE Trans. Circuits Syst. I 47 (2000) 204–220, eq. 20–22):
//!
//! ```text
//! dτ/dθ_j = −(∇g·S_j + ∂g/∂θ_j) / (∇g·f⁻),
//! S_j⁺ = S_j⁻ + (f⁻ − f⁺)·dτ/dθ_j.
//! ```
//!
//! ∇g·S_j + ∂g/∂θ_j is the central difference of g along (δ·S_j, ±δ_j), the scenes at θ ± δ
//! evaluated at x ± δ·S_j (exact up to rounding: g is affine in T and in the set points);
//! ∇g·f⁻ the difference of g along f⁻ (exact for the same reason).
//!
//! The switch is located as in [`crate::solve::rosenbrock`]: regula falsi (Illinois) on the
//! largest switching function at the end of the ROS3 step as a function of the step size; the
//! step is cut just past the surface.
//!
//! The end of a minimum on or off time is a time event, τ_e = τ_s + d, with τ_s the switch that
//! started the dwell and d the minimum time. When the sensor lies past its set point then, the
//! controller switches at τ_e, and the same jump applies with the time event's switching-time
//! derivative (Hiskens & Pai 2000, the event's triggering time entering the jump through
//! dτ/dθ alone; the time event's function t − τ_s − d gives it by the implicit function theorem
//! with ∂g/∂t = 1):
//!
//! ```text
//! dτ_e/dθ_j = dτ_s/dθ_j + ∂d/∂θ_j,
//! S_j⁺ = S_j⁻ + (f⁻ − f⁺)·dτ_e/dθ_j,
//! ```
//!
//! where dτ_s/dθ_j is kept from the switch at τ_s (per controller) and ∂d/∂θ_j is the central
//! difference of the minimum time over the scenes at θ ± δ (zero unless the minimum time is a
//! parameter). A dwell that ends with no switch due moves nothing: no jump.

use nalgebra::DVector;

use super::{start_step, NumericalFailure, SensitivityOptions, StepStages, Tangent, ROS3};
use crate::scene::controls::EVENTS_PER_CONTROL;
use crate::scene::Scene;
use crate::solve::bracket::{Bracket, EVENT_MAX_ITER, EVENT_TIME_TOL};

/// |∇g·f⁻| below this (K/s) is a grazing switch: the surface is touched, not crossed, and
/// dτ/dθ is unbounded.
const GRAZING: f64 = 1e-14;

/// Scratch for the switching functions.
pub(super) struct EventScratch {
    /// Switching functions of the controllers (not the thermostats' band edges).
    count: usize,
    g: Vec<f64>,
    gp: Vec<f64>,
    gm: Vec<f64>,
    /// A switch is due at the state just accepted.
    pub(super) due: bool,
    /// Per controller: dτ/dθ_j of its last switch (empty before the first), the start of its
    /// minimum on or off time.
    dtau: Vec<Vec<f64>>,
    /// Switches made.
    pub(super) switches: usize,
}

impl EventScratch {
    pub(super) fn new(scene: &Scene) -> Self {
        let all = scene.switching_count();
        EventScratch {
            count: scene.thermal().controls.len() * EVENTS_PER_CONTROL,
            g: vec![0.0; all],
            gp: vec![0.0; all],
            gm: vec![0.0; all],
            due: false,
            switches: 0,
            dtau: vec![Vec::new(); scene.thermal().controls.len()],
        }
    }
}

/// The largest controller switching function and its index.
fn largest(g: &[f64], count: usize) -> (usize, f64) {
    g[..count].iter().enumerate().fold(
        (0, f64::NEG_INFINITY),
        |(i, a), (k, &b)| if b > a { (k, b) } else { (i, a) },
    )
}

impl Tangent<'_> {
    /// The controllers' modes at the start state (the nominal scene's law), copied to the
    /// scenes at θ ± δ: every direction follows the nominal sequence of modes.
    pub(super) fn start_modes(&mut self) {
        if self.ev.count == 0 {
            return;
        }
        self.nominal.set_state(self.y.as_slice(), 0.0, self.y.as_slice());
        let e = &mut self.nominal;
        e.scene.initial_control_modes(&e.y, &mut e.work);
        self.sync_modes();
    }

    /// The nominal modes into the scenes at θ ± δ.
    fn sync_modes(&mut self) {
        let modes = self.nominal.work.net.mode.clone();
        for e in self.plus.iter_mut().chain(self.minus.iter_mut()) {
            for (k, &m) in modes.iter().enumerate() {
                e.scene.set_control_mode(k, m, &mut e.work);
            }
        }
    }

    /// The largest controller switching function at time `t` (s; a dwell's end is a time
    /// event) and node temperatures `x` (nominal scene).
    fn margin(&mut self, t: f64, x: &DVector<f64>) -> (usize, f64) {
        let e = &mut self.nominal;
        e.set_state(x.as_slice(), 0.0, x.as_slice());
        e.scene.switching_functions_at(t, &e.y, &e.work, &mut self.ev.g);
        largest(&self.ev.g, self.ev.count)
    }

    /// The end of a step's stages from the current state.
    fn step_end(&self, st: &StepStages) -> DVector<f64> {
        let m = &ROS3.m;
        &self.y + &st.k[0] * m[0] + &st.k[1] * m[1] + &st.k[2] * m[2]
    }

    /// After an accepted step `st` from t whose end lies past a controller's switching surface:
    /// the step cut at the first switch (its stages and size; `ev.due` set). None when no switch
    /// is due within the step.
    pub(super) fn locate_event(
        &mut self,
        t: f64,
        st: &StepStages,
        opts: &SensitivityOptions,
    ) -> Option<(StepStages, f64)> {
        self.ev.due = false;
        if self.ev.count == 0 {
            return None;
        }
        let end = self.step_end(st);
        let (_, fb0) = self.margin(t + st.h, &end);
        if fb0 <= 0.0 {
            return None;
        }
        let y0 = self.y.clone();
        let fa = self.margin(t, &y0).1.min(0.0);
        let mut br = Bracket::new(0.0, fa, st.h, fb0);
        let tol = EVENT_TIME_TOL * t.abs().max(1.0);
        for _ in 0..EVENT_MAX_ITER {
            if br.b - br.a <= tol {
                break;
            }
            let c = br.trial();
            let (trial, _) = self.step(t, c, opts.rtol, opts.atol);
            let fc = self.margin(t + c, &self.step_end(&trial)).1;
            br.update(c, fc);
        }
        let b = br.b;
        // The stages (and the LU of W) of the step of size b, just past the surface.
        let stages = self.step(t, b, opts.rtol, opts.atol).0;
        self.ev.due = true;
        Some((stages, b))
    }

    /// At the accepted state (time t) past a switching surface: switch every controller whose
    /// switch is due, one at a time, each with its jump of the sensitivities; returns the next
    /// step-size proposal (a starting step for the new right-hand side, at most `h`).
    pub(super) fn switch_with_saltation(
        &mut self,
        t: f64,
        h: f64,
        opts: &SensitivityOptions,
        rest: f64,
    ) -> Result<f64, NumericalFailure> {
        self.ev.due = false;
        let y = self.y.clone();
        for _ in 0..=self.ev.count {
            let (idx, g) = self.margin(t, &y);
            if g <= 0.0 {
                break;
            }
            self.saltation(t, &y, idx)?;
            self.ev.switches += 1;
        }
        if rest <= 0.0 {
            return Ok(h);
        }
        let f = self.nominal_f(t, &y);
        Ok(start_step(&y, &f, opts, rest).min(h))
    }

    /// Switch the controller of switching function `idx` at (t, y) and jump S.
    fn saltation(&mut self, t: f64, y: &DVector<f64>, idx: usize) -> Result<(), NumericalFailure> {
        let k = idx / EVENTS_PER_CONTROL;
        let f_before = self.nominal_f(t, y);
        let dwell = {
            let e = &self.nominal;
            e.scene.is_dwell_event(t, idx, &e.work)
        };
        let dtau = if dwell {
            self.dwell_end_derivatives(k)
        } else {
            // ∇g·f⁻ (g affine in T: the central difference with unit step is exact).
            self.margin(t, &(y + &f_before));
            let up = self.ev.g[idx];
            self.margin(t, &(y - &f_before));
            let rate = 0.5 * (up - self.ev.g[idx]);
            if rate.is_nan() || rate.abs() <= GRAZING {
                let why = format!(
                    "a controller's switching surface is touched, not crossed (rate {rate:.3e} K/s): \
                     the sensitivities of the switching instant are unbounded"
                );
                return Err(self.failure(t, why));
            }
            self.switch_time_derivatives(y, idx, rate)
        };
        {
            let e = &mut self.nominal;
            e.scene.switch_control(t, idx, &mut e.work);
        }
        self.sync_modes();
        let jump = &f_before - self.nominal_f(t, y);
        for (j, d) in dtau.iter().enumerate() {
            let mut col = self.s.column_mut(j);
            col += &jump * *d;
        }
        self.ev.dtau[k] = dtau;
        if self.s.iter().all(|v| v.is_finite()) {
            return Ok(());
        }
        let why = "the sensitivities are not finite after a controller's switch".to_string();
        Err(self.failure(t, why))
    }

    /// dτ_e/dθ_j of the end of controller `k`'s minimum time: its last switch's dτ/dθ_j plus
    /// the minimum time's own derivative (central difference over the scenes at θ ± δ).
    fn dwell_end_derivatives(&self, k: usize) -> Vec<f64> {
        let (mode, last) = {
            let w = &self.nominal.work.net;
            (w.mode[k], w.last_switch[k])
        };
        (0..self.delta.len())
            .map(|j| {
                let start = self.ev.dtau[k].get(j).copied().unwrap_or(0.0);
                let end = |e: &super::Eval<'_>| e.scene.thermal().controls[k].dwell_end(mode, last);
                let dd = match (end(&self.plus[j]), end(&self.minus[j])) {
                    (Some(a), Some(b)) => (a - b) / (2.0 * self.delta[j]),
                    _ => 0.0,
                };
                start + dd
            })
            .collect()
    }

    /// dτ/dθ_j of every direction for switching function `idx` at the state y, with
    /// ∇g·f⁻ = `rate`.
    fn switch_time_derivatives(&mut self, y: &DVector<f64>, idx: usize, rate: f64) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.delta.len());
        for j in 0..self.delta.len() {
            let dl = self.delta[j];
            let sj = self.s.column(j).into_owned();
            let (p, m) = (&mut self.plus[j], &mut self.minus[j]);
            p.set_state(y.as_slice(), dl, sj.as_slice());
            m.set_state(y.as_slice(), -dl, sj.as_slice());
            p.scene.switching_functions(&p.y, &p.work, &mut self.ev.gp);
            m.scene.switching_functions(&m.y, &m.work, &mut self.ev.gm);
            let dg = (self.ev.gp[idx] - self.ev.gm[idx]) / (2.0 * dl);
            out.push(-dg / rate);
        }
        out
    }
}
