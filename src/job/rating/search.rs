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
//! every model file: each new point is checked against the bracket's ends, and a value outside
//! [f(a), f(b)] (or below an earlier one during the expansion) by more than
//! [`MONOTONIC_SLACK_K`] marks the rating [`Outcome::non_monotonic`]: a higher torque may then
//! also meet the limit. Only the sampled torques are compared: a fall between two of them is not
//! seen. Each equilibrium starts from the nearest one below it (warm start).

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

/// A probe below or at the limit: its torque, what the probe carries (an equilibrium) and its
/// distance to the limit.
struct Found<E> {
    torque: f64,
    payload: E,
    /// f = T_oil − limit, K.
    f: f64,
}

/// The upper end of the bracket: a torque above the limit (f > 0), or one without equilibrium
/// inside the valid range (`f` None).
struct Above {
    torque: f64,
    f: Option<f64>,
}

/// The result of a search: the rated torque and what its probe carries.
#[derive(Debug)]
pub struct Outcome<E> {
    /// Rated input torque, N·m.
    pub torque: f64,
    /// What the probe at the rated torque carries (the equilibrium).
    pub payload: E,
    /// How it was found.
    pub status: Status,
    /// The oil temperature fell with rising torque somewhere in the search.
    pub non_monotonic: bool,
    /// Probes made (equilibria solved).
    pub probes: usize,
}

/// A probe at a torque (N·m), warm-started from the payload of the highest torque known to be
/// at or below the limit: Ok(Some((payload, f))) with f = T_oil − limit (K), Ok(None) when there
/// is no equilibrium inside the valid range, Err(reason) for any other failure.
pub type Probe<'p, E> = dyn FnMut(f64, Option<&E>) -> Result<Option<(E, f64)>, String> + 'p;

/// The search of the module documentation on any probe, over [t_min, t_max] (t_min < t_max).
/// Err: the torque (N·m) and the reason where the search cannot give a rating.
pub fn bracket<E>(probe: &mut Probe<'_, E>, t_min: f64, t_max: f64) -> Result<Outcome<E>, (f64, String)> {
    let mut count = 1;
    let Some((payload, f)) = probe(t_min, None).map_err(|why| (t_min, why))? else {
        return Err((
            t_min,
            format!(
                "no equilibrium even at the lowest torque: none inside the valid range (oil {:.0} … {:.0} °C)",
                OIL_RANGE_C.0, OIL_RANGE_C.1
            ),
        ));
    };
    let lo = Found {
        torque: t_min,
        payload,
        f,
    };
    if lo.f > 0.0 {
        return Ok(finish(lo, Status::LimitAtMinimum, false, count));
    }
    let mut non_monotonic = false;
    let (mut a, mut step) = (lo, FIRST_STEP_NM);
    let b = loop {
        let t = (t_min + step).min(t_max);
        let next = probe(t, Some(&a.payload)).map_err(|why| (t, why))?;
        count += 1;
        match next {
            Some((payload, f)) if f <= 0.0 => {
                non_monotonic |= f < a.f - MONOTONIC_SLACK_K;
                a = Found {
                    torque: t,
                    payload,
                    f,
                };
                if t >= t_max {
                    return Ok(finish(a, Status::Ceiling, non_monotonic, count));
                }
            }
            other => {
                break Above {
                    torque: t,
                    f: other.map(|n| n.1),
                }
            }
        }
        step *= GROWTH;
    };
    narrow(probe, a, b, non_monotonic, count)
}

/// Narrow the bracket [a, b] (f(a) ≤ 0 < f(b), or b without equilibrium) to the tolerance.
fn narrow<E>(
    probe: &mut Probe<'_, E>,
    mut a: Found<E>,
    mut b: Above,
    mut non_monotonic: bool,
    mut count: usize,
) -> Result<Outcome<E>, (f64, String)> {
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
            return Err((a.torque, jump(&a, &b)));
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
        let next = probe(t, Some(&a.payload)).map_err(|why| (t, why))?;
        count += 1;
        let f = next.as_ref().map(|n| n.1);
        if let Some(f) = f {
            let above_b = b.f.is_some_and(|fb| f > fb + MONOTONIC_SLACK_K);
            non_monotonic |= f < a.f - MONOTONIC_SLACK_K || above_b;
        }
        match next {
            Some((payload, f)) if f <= 0.0 => {
                a = Found {
                    torque: t,
                    payload,
                    f,
                };
                fa_w = f;
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
fn jump<E>(a: &Found<E>, b: &Above) -> String {
    format!(
        "the equilibrium oil temperature jumps across the limit between {} and {} N m (from {:.3} K below it): \
         no torque meets the limit within {TOLERANCE_K} K",
        a.torque, b.torque, -a.f
    )
}

fn finish<E>(p: Found<E>, status: Status, non_monotonic: bool, probes: usize) -> Outcome<E> {
    Outcome {
        torque: p.torque,
        payload: p.payload,
        status,
        non_monotonic,
        probes,
    }
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
    /// The equilibrium at `torque` from `warm` (then from the ambient) and its distance to the
    /// limit; Ok(None) when the solver finds none inside the valid temperature range (taken as
    /// hotter than any limit: a wrong guess can only end the search with an error, never with a
    /// rating, see the module documentation); Err(reason) for any other failure.
    fn probe(&self, torque: f64, warm: Option<&Equilibrium>) -> Result<Option<(Equilibrium, f64)>, String> {
        let o = NewtonOptions::default();
        let at = Inputs {
            state: self.state,
            input_speed: self.speed,
            input_torque: torque,
            vehicle_speed: self.vehicle_speed,
        };
        let solved = match warm {
            Some(w) => equilibrium(self.scene, at, Some(&w.solution.temperatures), &o)
                .or_else(|_| equilibrium(self.scene, at, None, &o)),
            None => equilibrium(self.scene, at, None, &o),
        };
        match solved {
            Ok(eq) => {
                check_equilibrium(self.scene, &eq)?;
                let f = eq.solution.temperatures[self.scene.thermal().oil] - self.limit_k;
                Ok(Some((eq, f)))
            }
            // No equilibrium inside the valid range: with positive losses the oil would run past
            // its upper end (the solver can report either end when the iterates overshoot).
            Err(SteadyError::NoEquilibriumInRange { .. }) => Ok(None),
            Err(e) => Err(describe(self.scene, &e)),
        }
    }
}

/// Search the rated torque at `p` in [t_min, t_max] (t_min < t_max), each probe an equilibrium
/// of the scene.
pub fn search(p: &Point<'_>, t_min: f64, t_max: f64) -> Result<Outcome<Equilibrium>, (f64, String)> {
    bracket(&mut |t, warm| p.probe(t, warm), t_min, t_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A probe of f(T) in K with no payload; `None` from `f`: no equilibrium there.
    fn run(f: impl Fn(f64) -> Option<f64>, t_min: f64, t_max: f64) -> Result<Outcome<()>, (f64, String)> {
        bracket(&mut |t, _| Ok(f(t).map(|v| ((), v))), t_min, t_max)
    }

    #[test]
    fn a_smooth_rising_curve_is_rated_within_the_tolerance_below_the_limit() {
        // Oil 40 °C + 0.3 K/N·m + a little curvature, limit 90 °C.
        let f = |t: f64| Some(40.0 + 0.3 * t + 1e-4 * t * t - 90.0);
        let o = run(f, 0.0, 1e6).unwrap();
        assert_eq!(o.status, Status::Rated);
        let r = f(o.torque).unwrap();
        assert!((-TOLERANCE_K..=0.0).contains(&r), "{r}");
        assert!(!o.non_monotonic);
        assert!(o.probes < 30, "{}", o.probes);
    }

    #[test]
    fn no_equilibrium_above_a_torque_is_bisected_like_a_hot_oil() {
        // Above 120 N·m no equilibrium; the limit is crossed at 100 N·m.
        let f = |t: f64| (t < 120.0).then_some(t - 100.0);
        let o = run(f, 0.0, 1e6).unwrap();
        assert_eq!(o.status, Status::Rated);
        assert!((100.0 - TOLERANCE_K..=100.0).contains(&o.torque), "{}", o.torque);
    }

    #[test]
    fn the_limit_at_the_lowest_torque_and_the_ceiling_are_flagged() {
        let o = run(|t| Some(5.0 + t), 0.0, 1e6).unwrap();
        assert_eq!((o.status, o.torque, o.probes), (Status::LimitAtMinimum, 0.0, 1));
        let o = run(|t| Some(t - 500.0), 0.0, 200.0).unwrap();
        assert_eq!((o.status, o.torque), (Status::Ceiling, 200.0));
        let e = run(|_| None, 0.0, 200.0).unwrap_err();
        assert!(
            e.1.contains("no equilibrium even at the lowest torque"),
            "{}",
            e.1
        );
    }

    #[test]
    fn a_falling_stretch_is_reported_non_monotonic() {
        // Rises to 5 N·m, falls until 100 N·m (the expansion samples 10 and 40 N·m on it), then
        // rises and crosses the limit at 192.5 N·m.
        let shape = |t: f64| {
            if t < 5.0 {
                t
            } else if t < 100.0 {
                5.0 - 0.5 * (t - 5.0)
            } else {
                -42.5 + (t - 100.0)
            }
        };
        let f = |t: f64| Some(shape(t) - 50.0);
        let o = run(f, 0.0, 1e6).unwrap();
        assert!(o.non_monotonic);
        assert_eq!(o.status, Status::Rated);
        assert!((192.5 - TOLERANCE_K..=192.5).contains(&o.torque), "{}", o.torque);
        // The same fall hidden between two sampled torques is not seen: only sampled points are
        // compared.
        let hidden = |t: f64| {
            Some(if (41.0..50.0).contains(&t) {
                -80.0
            } else {
                t - 150.0
            })
        };
        assert!(!run(hidden, 0.0, 1e6).unwrap().non_monotonic);
    }

    #[test]
    fn a_jump_across_the_limit_is_an_error_naming_the_torque() {
        let e = run(|t| Some(if t < 70.0 { -5.0 } else { 5.0 }), 0.0, 1e6).unwrap_err();
        assert!((e.0 - 70.0).abs() < 1e-6, "{}", e.0);
        assert!(e.1.contains("jumps across the limit"), "{}", e.1);
        // A failure of the probe is passed on with its torque.
        let e = bracket::<()>(
            &mut |t, _| {
                if t > 50.0 {
                    Err("singular".into())
                } else {
                    Ok(Some(((), t - 100.0)))
                }
            },
            0.0,
            1e6,
        )
        .unwrap_err();
        assert_eq!(e.1, "singular");
        assert!(e.0 > 50.0);
    }
}
