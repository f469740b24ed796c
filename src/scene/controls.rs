//! The controllers of a compiled network (`[[thermal.controls]]`): each has a discrete mode (a
//! two-point controller on or off; a valve below its lower limit, proportional, or at its upper
//! limit) that the integrators hold constant within a step and change only at located events,
//! so the right-hand side is smooth between events.
//!
//! Switching functions: two per controller, `g ≤ 0` while the mode holds; an event is the
//! first time some `g` turns positive. A cooling two-point controller (on above `on`, off below
//! `off`, `on > off`) has `g = T − on` while off and `g = off − T` while on; a heating one the
//! mirror; a valve has `T − lo` (below the lower limit), `T − hi` and `lo − T` (proportional),
//! `hi − T` (at the upper limit), where the share `(T − closed)/(open − closed)` meets its limits,
//! each shifted by [`EDGE_BAND`] to the far side.
//! A PI valve has the same three regions and functions on its signal
//! `v = gain·(T − set) + I` (the share before its limits, [`ControlTerm::signal`]) instead of
//! the temperature, the limits `min` and `max` in place of `lo` and `hi`.
//! An unused function is −1.
//!
//! A two-point controller with a minimum on (off) time: while that time since its last switch
//! has not ended, its first function is the time event `t − (t_last + dwell)` and the state
//! functions are not watched; at the event it switches when its state function is positive then
//! (a switch requested during the dwell), and otherwise watches its state function again. The
//! time of the last switch is kept beside the mode in the work area (`last_switch`).

use crate::model::thermal::{Control, ControlLaw, ControlTarget};

/// Half-width of the band around a valve's (or thermostat's) limit in which either region
/// holds, K: the share is continuous across the limit, and this band keeps a state that sits on
/// it (within rounding) from switching back and forth. The share's error for it is at most
/// this over the proportional band.
pub const EDGE_BAND: f64 = 1e-8;

/// Switching functions per controller.
pub const EVENTS_PER_CONTROL: usize = 2;

/// Relative tolerance of a dwell's end, s per s (of max(1, |end|)): a time this close before the
/// end counts as the end (the root finders land on it within rounding).
const DWELL_TOL: f64 = 1e-12;

/// The tolerance on a dwell ending at `end`, s.
#[inline]
fn dwell_tol(end: f64) -> f64 {
    DWELL_TOL * end.abs().max(1.0)
}

/// State rows per controller after the boundary-energy quadrature: the energy it moved (J) and
/// the time integral of its share (s; a two-point controller's time on).
pub const ROWS_PER_CONTROL: usize = 2;

/// State rows per PI valve after every controller's rows: its integral I (share; a state the
/// right-hand side depends on) and its time at the lower and at the upper limit (s,
/// quadratures).
pub const ROWS_PER_PI: usize = 3;

/// A controller's law, temperatures in K.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Law {
    /// On at `on`, off at `off`; cooling when `on > off` (with equal set points: a cooler's or
    /// link's controller cools, a heater heats).
    TwoPoint {
        /// Switch-on temperature, K.
        on: f64,
        /// Switch-off temperature, K.
        off: f64,
        /// True when it switches on as the sensor warms.
        cooling: bool,
        /// State at the start, when given.
        initial_on: Option<bool>,
        /// Shortest time on, s (0: none).
        min_on: f64,
        /// Shortest time off, s (0: none).
        min_off: f64,
    },
    /// Share `(T − closed)/(open − closed)` between `lo` and `hi` (the temperatures where it
    /// meets `min` and `max`).
    Valve {
        /// Share 0 at this temperature, K.
        closed: f64,
        /// Share 1 at this temperature, K.
        open: f64,
        /// Lowest share.
        min: f64,
        /// Highest share.
        max: f64,
        /// Temperature where the share meets `min`, K.
        lo: f64,
        /// Temperature where it meets `max`, K.
        hi: f64,
    },
    /// PI valve: share `u = clamp(v, min, max)` of the signal `v = gain·(T − set) + I`; the
    /// integral follows `dI/dt = rate·(T − set) + inv_tt·(u − v)` (back-calculation; the last
    /// term is zero within the limits).
    Pi {
        /// Set point, K.
        set: f64,
        /// Proportional gain, 1/K.
        gain: f64,
        /// gain / integral time, 1/(K·s).
        rate: f64,
        /// 1 / tracking time, 1/s.
        inv_tt: f64,
        /// Lowest share.
        min: f64,
        /// Highest share.
        max: f64,
        /// I at the start.
        initial: f64,
    },
}

/// What a controller acts on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Action {
    /// The cooler (index among the compiled coolers) whose conductance it scales.
    Cooler(usize),
    /// The links (operating-point links carrying this controller's index) it scales.
    Link,
    /// A heater of `power` W into `node` while on.
    Heater {
        /// Node heated.
        node: usize,
        /// Power while on, W.
        power: f64,
    },
}

/// A compiled controller.
#[derive(Debug, Clone)]
pub struct ControlTerm {
    /// Name.
    pub name: String,
    /// Sensor node.
    pub sensor: usize,
    /// Law.
    pub law: Law,
    /// Target.
    pub action: Action,
    /// Share of the target's conductance while a two-point controller is off.
    pub off_fraction: f64,
}

impl ControlTerm {
    /// Compile a checked controller; `cooler_index` maps a model cooler to its compiled index.
    pub fn compile(c: &Control, cooler_index: impl Fn(usize) -> usize) -> ControlTerm {
        let heater = matches!(c.target, ControlTarget::Heater { .. });
        let law = match c.law {
            ControlLaw::TwoPoint {
                on,
                off,
                initial_on,
                min_on,
                min_off,
            } => Law::TwoPoint {
                on,
                off,
                cooling: on > off || (on == off && !heater),
                initial_on,
                min_on,
                min_off,
            },
            ControlLaw::Valve {
                closed,
                open,
                min,
                max,
            } => Law::Valve {
                closed,
                open,
                min,
                max,
                lo: closed + min * (open - closed),
                hi: closed + max * (open - closed),
            },
            ControlLaw::Pi {
                set,
                gain,
                ti,
                min,
                max,
                initial,
            } => Law::Pi {
                set,
                gain,
                rate: gain / ti,
                inv_tt: 1.0 / ti,
                min,
                max,
                initial,
            },
        };
        let (action, off_fraction) = match &c.target {
            ControlTarget::Cooler { cooler, off_fraction } => {
                (Action::Cooler(cooler_index(*cooler)), *off_fraction)
            }
            ControlTarget::Link { off_fraction, .. } => (Action::Link, *off_fraction),
            ControlTarget::Heater { node, power } => (
                Action::Heater {
                    node: *node,
                    power: *power,
                },
                0.0,
            ),
        };
        ControlTerm {
            name: c.name.clone(),
            sensor: c.sensor,
            law,
            action,
            off_fraction,
        }
    }

    /// True for a two-point controller (its mode is on/off).
    pub fn is_two_point(&self) -> bool {
        matches!(self.law, Law::TwoPoint { .. })
    }

    /// True for a PI valve (it has an integral in the state).
    pub fn is_pi(&self) -> bool {
        matches!(self.law, Law::Pi { .. })
    }

    /// The signal the switching functions watch at sensor temperature `t` (K) and integral `i`:
    /// a PI valve's `gain·(t − set) + i`, else the temperature.
    #[inline]
    pub fn signal(&self, t: f64, i: f64) -> f64 {
        match self.law {
            Law::Pi { set, gain, .. } => gain * (t - set) + i,
            _ => t,
        }
    }

    /// The share x the controller applies in `mode` at sensor temperature `t` (K) and integral
    /// `i` (PI valves), with dx/dT and dx/dI: a two-point controller 1 on, `off_fraction` off; a
    /// valve its limited share.
    #[inline]
    pub fn share(&self, mode: u8, t: f64, i: f64) -> (f64, f64, f64) {
        match self.law {
            Law::TwoPoint { .. } => (if mode == 1 { 1.0 } else { self.off_fraction }, 0.0, 0.0),
            Law::Valve {
                closed,
                open,
                min,
                max,
                ..
            } => match mode {
                0 => (min, 0.0, 0.0),
                2 => (max, 0.0, 0.0),
                _ => {
                    let w = 1.0 / (open - closed);
                    ((t - closed) * w, w, 0.0)
                }
            },
            Law::Pi { min, max, gain, .. } => match mode {
                0 => (min, 0.0, 0.0),
                2 => (max, 0.0, 0.0),
                _ => (self.signal(t, i), gain, 1.0),
            },
        }
    }

    /// A PI valve's dI/dt at sensor temperature `t` (K) and integral `i` in `mode`, and its
    /// derivatives in T and I: `rate·(t − set)` between the limits, plus `inv_tt·(u − v)` at a
    /// limit u (back-calculation: with the tracking time equal to the integral time this is
    /// `(u − i)/ti`, the integral relaxing to the limit); 0 for the other kinds.
    #[inline]
    pub fn integral_rate(&self, mode: u8, t: f64, i: f64) -> (f64, f64, f64) {
        let Law::Pi {
            set,
            gain,
            rate,
            inv_tt,
            min,
            max,
            ..
        } = self.law
        else {
            return (0.0, 0.0, 0.0);
        };
        let e = rate * (t - set);
        match mode {
            1 => (e, rate, 0.0),
            _ => {
                let u = if mode == 0 { min } else { max };
                let v = self.signal(t, i);
                (e + inv_tt * (u - v), rate - inv_tt * gain, -inv_tt)
            }
        }
    }

    /// A PI valve's integral at the start (0 for the other kinds).
    pub fn initial_integral(&self) -> f64 {
        match self.law {
            Law::Pi { initial, .. } => initial,
            _ => 0.0,
        }
    }

    /// A PI valve's proportional gain, 1/K (0 for the other kinds).
    pub fn gain(&self) -> f64 {
        match self.law {
            Law::Pi { gain, .. } => gain,
            _ => 0.0,
        }
    }

    /// True when the controller has a minimum on or off time.
    pub fn has_min_time(&self) -> bool {
        matches!(self.law, Law::TwoPoint { min_on, min_off, .. } if min_on > 0.0 || min_off > 0.0)
    }

    /// The end of the minimum time in `mode` after a switch at `last` (s), when there is one.
    #[inline]
    pub fn dwell_end(&self, mode: u8, last: f64) -> Option<f64> {
        let Law::TwoPoint { min_on, min_off, .. } = self.law else {
            return None;
        };
        let d = if mode == 1 { min_on } else { min_off };
        (d > 0.0 && last.is_finite()).then_some(last + d)
    }

    /// True when at time `time` (s) the minimum time in `mode` after a switch at `last` has
    /// not ended (within its tolerance).
    #[inline]
    pub fn in_dwell(&self, mode: u8, time: f64, last: f64) -> bool {
        self.dwell_end(mode, last)
            .is_some_and(|end| time < end - 2.0 * dwell_tol(end))
    }

    /// The switching functions in `mode` at time `time` (s) and signal `t` ([`Self::signal`]:
    /// the sensor temperature, K, or a PI valve's signal), the last switch at `last` (s), into
    /// `g`: within a minimum time its end as a time event.
    #[inline]
    pub fn events_at(&self, mode: u8, time: f64, last: f64, t: f64, g: &mut [f64]) {
        if let Some(end) = self.dwell_end(mode, last) {
            let end = end - dwell_tol(end);
            if time < end {
                g[0] = time - end;
                g[1] = -1.0;
                return;
            }
        }
        self.events(mode, t, g);
    }

    /// The switching functions in `mode` at signal `t` ([`Self::signal`]) into `g`, minimum
    /// times aside.
    #[inline]
    pub fn events(&self, mode: u8, t: f64, g: &mut [f64]) {
        let (a, b) = match self.law {
            Law::TwoPoint { on, off, cooling, .. } => {
                let g = match (cooling, mode == 1) {
                    (true, false) => t - on,
                    (true, true) => off - t,
                    (false, false) => on - t,
                    (false, true) => t - off,
                };
                (g, -1.0)
            }
            Law::Valve { lo, hi, .. } | Law::Pi { min: lo, max: hi, .. } => match mode {
                0 => (t - (lo + EDGE_BAND), -1.0),
                1 => (t - (hi + EDGE_BAND), (lo - EDGE_BAND) - t),
                _ => (-1.0, (hi - EDGE_BAND) - t),
            },
        };
        g[0] = a;
        g[1] = b;
    }

    /// The mode after switching function `slot` fired in `mode`.
    pub fn flip(&self, mode: u8, slot: usize) -> u8 {
        match self.law {
            Law::TwoPoint { .. } => 1 - mode.min(1),
            Law::Valve { .. } | Law::Pi { .. } => {
                if slot == 0 {
                    (mode + 1).min(2)
                } else {
                    mode.saturating_sub(1)
                }
            }
        }
    }

    /// The mode at the start at signal `t` ([`Self::signal`]): a two-point controller as given,
    /// else on when `t` lies beyond the switch-on temperature; a valve by where `t` lies.
    pub fn initial_mode(&self, t: f64) -> u8 {
        match self.law {
            Law::TwoPoint {
                on,
                cooling,
                initial_on,
                ..
            } => {
                let beyond = if cooling { t >= on } else { t <= on };
                u8::from(initial_on.unwrap_or(beyond))
            }
            Law::Valve { lo, hi, .. } | Law::Pi { min: lo, max: hi, .. } => {
                if t < lo {
                    0
                } else if t > hi {
                    2
                } else {
                    1
                }
            }
        }
    }

    /// A mode in which no switching function is positive at signal `t` (the mode after the events
    /// that are due at this point; unchanged when none is): flips while one is, minimum times
    /// aside.
    pub fn settle(&self, mode: u8, t: f64) -> u8 {
        self.settle_at(mode, f64::INFINITY, f64::NEG_INFINITY, t)
    }

    /// [`Self::settle`] at time `time` (s) after a switch at `last` (s): no switch within a
    /// minimum time, and at most one when the new mode has one.
    pub fn settle_at(&self, mut mode: u8, time: f64, last: f64, t: f64) -> u8 {
        if self.in_dwell(mode, time, last) {
            return mode;
        }
        let mut g = [0.0; EVENTS_PER_CONTROL];
        for _ in 0..3 {
            self.events(mode, t, &mut g);
            match g.iter().position(|v| *v > 0.0) {
                Some(slot) => {
                    mode = self.flip(mode, slot);
                    if self.dwell_end(mode, time).is_some() {
                        break;
                    }
                }
                None => break,
            }
        }
        mode
    }
}
