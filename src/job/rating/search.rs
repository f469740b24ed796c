//! The search behind a thermal rating at one input speed: the highest input torque T in
//! [T_min, T_max] whose equilibrium oil temperature T_oil,eq(T) stays at or below the limit.
//!
//! f(T) = T_oil,eq(T) − T_limit is found by a bracketing search (docs/outputs.md, "rating"):
//!
//! 1. f(T_min). Above the limit: the speed alone heats the oil past it; the rating is T_min,
//!    flagged [`Status::LimitAtMinimum`]. Without any equilibrium there: a numerical failure.
//! 2. Expansion: T_k = T_min + 10 N·m · 4^(k−1), the last one clamped to T_max, until f > 0 or
//!    the steady solver finds no equilibrium inside its valid range, taken as hotter than any
//!    limit (were it a solver failure below the limit, the narrowing would close in on it with
//!    f(a) still below −tolerance and end with an error naming the torque: a rating is only
//!    returned at a verified equilibrium). Never above the limit up to T_max: the rating is
//!    T_max, flagged [`Status::Ceiling`].
//! 3. The bracket [a, b] with f(a) ≤ 0 < f(b) is narrowed by the Illinois variant of regula
//!    falsi [recalled: M. Dowell, P. Jarratt, "A modified regula falsi method for computing the
//!    root of an equation", BIT 11 (1971) 168–174], with a bisection step whenever b has no
//!    equilibrium (no f value) or the bracket did not halve in three steps, until
//!    −[`TOLERANCE_K`] ≤ f(a) ≤ 0. The rated torque is a: its equilibrium is at or below the
//!    limit by at most the tolerance.
//!
//! The equilibrium oil temperature rises with torque in every model here (sliding and bearing
//! losses grow with load, the other losses do not depend on it), but this is not proved for
//! every model file: each new point is checked against its neighbours, and a value outside
//! [f(a), f(b)] (or below an earlier one during the expansion) by more than
//! [`MONOTONIC_SLACK_K`] marks the rating [`Search::non_monotonic`]: a higher torque may then
//! also meet the limit. Each equilibrium starts from the nearest one below it (warm start).

use crate::physics::oil::KELVIN_OFFSET;
use crate::scene::{Inputs, Scene};
use crate::solve::equilibrium::{equilibrium, Equilibrium, OIL_RANGE_C};
use crate::solve::steady::{SteadyError, SteadyOptions as NewtonOptions};

use super::super::steady::{check_equilibrium, describe};

/// The rated torque's equilibrium lies in [limit − TOLERANCE_K, limit], K.
pub const TOLERANCE_K: f64 = 1e-3;
/// A fall of the equilibrium oil temperature with rising torque by more than this, K, marks
/// the search non-monotonic (the solver's own error is far below it).
pub const MONOTONIC_SLACK_K: f64 = 1e-6;
/// First step of the expansion above T_min, N·m.
pub const FIRST_STEP_NM: f64 = 10.0;
/// Growth factor of the expansion steps.
pub const GROWTH: f64 = 4.0;
/// Most narrowing steps (the Illinois method needs about ten on smooth curves).
pub const MAX_NARROWING: usize = 200;

/// How the rated torque was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The equilibrium at the rated torque is at the limit (within [`TOLERANCE_K`]).
    Rated,
    /// The limit is not reached below the torque ceiling: the rating is the ceiling.
    Ceiling,
    /// The limit is exceeded already at the lowest torque: the rating is that torque.
    LimitAtMinimum,
}

impl Status {
    /// The name written in `rating.csv` and the JSON document.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Rated => "rated",
            Status::Ceiling => "ceiling",
            Status::LimitAtMinimum => "limit_at_minimum",
        }
    }
}

/// An equilibrium of the search with its distance to the limit.
struct Found {
    torque: f64,
    eq: Equilibrium,
    /// f = T_oil − limit, K.
    f: f64,
}

/// The upper end of the bracket: a torque above the limit (f > 0), or one without equilibrium
/// because the oil runs past the solver's valid range (`f` None).
struct Above {
    torque: f64,
    f: Option<f64>,
}

/// The result of a search at one speed.
pub struct Search {
    /// Rated input torque, N·m.
    pub torque: f64,
    /// The equilibrium at the rated torque.
    pub equilibrium: Equilibrium,
    /// How it was found.
    pub status: Status,
    /// An equilibrium oil temperature fell with rising torque somewhere in the search.
    pub non_monotonic: bool,
    /// Equilibria solved.
    pub equilibria: usize,
}

/// What a search needs besides the torques.
pub struct Point<'a> {
    /// The scene of the gear state.
    pub scene: &'a Scene,
    /// Gear-state index.
    pub state: usize,
    /// Input speed, rad/s.
    pub speed: f64,
    /// Vehicle speed for h(v) links, m/s.
    pub vehicle_speed: f64,
    /// Oil temperature limit, K.
    pub limit_k: f64,
}

impl Point<'_> {
    fn inputs(&self, torque: f64) -> Inputs {
        Inputs {
            state: self.state,
            input_speed: self.speed,
            input_torque: torque,
            vehicle_speed: self.vehicle_speed,
        }
    }

    /// The equilibrium at `torque` from `warm` (then from the ambient); Ok(None) when the solver
    /// finds none inside the valid temperature range (taken as hotter than any limit: a wrong
    /// guess can only end the search with an error, never with a rating, see [`search`]);
    /// Err(reason) when there is no equilibrium for another reason.
    fn probe(&self, torque: f64, warm: Option<&Found>) -> Result<Option<Found>, (f64, String)> {
        let o = NewtonOptions::default();
        let at = self.inputs(torque);
        let solved = match warm {
            Some(w) => equilibrium(self.scene, at, Some(&w.eq.solution.temperatures), &o)
                .or_else(|_| equilibrium(self.scene, at, None, &o)),
            None => equilibrium(self.scene, at, None, &o),
        };
        match solved {
            Ok(eq) => {
                check_equilibrium(self.scene, &eq).map_err(|why| (torque, why))?;
                let f = eq.solution.temperatures[self.scene.thermal.oil] - self.limit_k;
                Ok(Some(Found { torque, eq, f }))
            }
            // No equilibrium inside the valid range: with positive losses the oil would run past
            // its upper end (the solver can report either end when the iterates overshoot).
            Err(SteadyError::NoEquilibriumInRange { .. }) => Ok(None),
            Err(e) => Err((torque, describe(self.scene, &e))),
        }
    }
}

/// Search the rated torque in [t_min, t_max] (t_min < t_max). Err: the torque (N·m) and the
/// reason where an equilibrium could not be found for another reason than a hot oil.
pub fn search(p: &Point<'_>, t_min: f64, t_max: f64) -> Result<Search, (f64, String)> {
    let Some(lo) = p.probe(t_min, None)? else {
        return Err((
            t_min,
            format!(
                "no equilibrium even at the lowest torque: none inside the valid range (oil {:.0} … {:.0} °C)",
                OIL_RANGE_C.0, OIL_RANGE_C.1
            ),
        ));
    };
    let mut count = 1;
    if lo.f > 0.0 {
        return Ok(finish(lo, Status::LimitAtMinimum, false, count));
    }
    let mut non_monotonic = false;
    let (mut a, mut step) = (lo, FIRST_STEP_NM);
    let b = loop {
        let t = (t_min + step).min(t_max);
        let next = p.probe(t, Some(&a))?;
        count += 1;
        match next {
            Some(n) if n.f <= 0.0 => {
                non_monotonic |= n.f < a.f - MONOTONIC_SLACK_K;
                if t >= t_max {
                    return Ok(finish(n, Status::Ceiling, non_monotonic, count));
                }
                a = n;
            }
            other => {
                break Above {
                    torque: t,
                    f: other.map(|n| n.f),
                }
            }
        }
        step *= GROWTH;
    };
    narrow(p, a, b, non_monotonic, count)
}

/// Narrow the bracket [a, b] (f(a) ≤ 0 < f(b), or b without equilibrium) to the tolerance.
fn narrow(
    p: &Point<'_>,
    mut a: Found,
    mut b: Above,
    mut non_monotonic: bool,
    mut count: usize,
) -> Result<Search, (f64, String)> {
    // Illinois: the f value kept at an end that stays twice in a row is halved.
    let (mut fa_w, mut fb_w) = (a.f, b.f);
    let mut last_side = 0i8;
    let mut widths = [f64::INFINITY; 3];
    for k in 0..MAX_NARROWING {
        if a.f >= -TOLERANCE_K {
            return Ok(finish(a, Status::Rated, non_monotonic, count));
        }
        let width = b.torque - a.torque;
        if width <= 1e-12 * b.torque.abs().max(1.0) {
            return Err((a.torque, jump(p, &a, &b)));
        }
        // Bisect when b has no f value or the bracket did not halve in three steps.
        let bisect = width > 0.5 * widths[k % 3];
        widths[k % 3] = width;
        let t = match fb_w {
            Some(fb) if !bisect => {
                let t = a.torque - fa_w * width / (fb - fa_w);
                t.clamp(a.torque + 1e-3 * width, b.torque - 1e-3 * width)
            }
            _ => 0.5 * (a.torque + b.torque),
        };
        let next = p.probe(t, Some(&a))?;
        count += 1;
        let f = next.as_ref().map(|n| n.f);
        if let Some(f) = f {
            let above_b = b.f.is_some_and(|fb| f > fb + MONOTONIC_SLACK_K);
            non_monotonic |= f < a.f - MONOTONIC_SLACK_K || above_b;
        }
        match next {
            Some(n) if n.f <= 0.0 => {
                fa_w = n.f;
                a = n;
                if last_side == -1 {
                    fb_w = fb_w.map(|x| 0.5 * x);
                }
                last_side = -1;
            }
            _ => {
                b = Above { torque: t, f };
                fb_w = f;
                if last_side == 1 {
                    fa_w *= 0.5;
                }
                last_side = 1;
            }
        }
    }
    Err((
        a.torque,
        format!("the rating search did not meet the limit within {TOLERANCE_K} K in {MAX_NARROWING} steps"),
    ))
}

/// The message for an equilibrium oil temperature that jumps across the limit.
fn jump(p: &Point<'_>, a: &Found, b: &Above) -> String {
    format!(
        "the equilibrium oil temperature jumps across the limit between {} and {} N m (from {:.3} °C): \
         no torque meets the limit within {TOLERANCE_K} K",
        a.torque,
        b.torque,
        a.f + p.limit_k - KELVIN_OFFSET
    )
}

fn finish(p: Found, status: Status, non_monotonic: bool, equilibria: usize) -> Search {
    Search {
        torque: p.torque,
        equilibrium: p.eq,
        status,
        non_monotonic,
        equilibria,
    }
}
