//! The envelope: the range of states where a job's models hold, checked once here for `run`,
//! `steady`, `map` and `losses` (docs/robustness.md "Physics envelope", docs/physics.md §1).
//!
//! - **Oil** (the oil node, and every temperature at which the oil's properties are evaluated:
//!   `--oil-temp-c`, `--frozen-viscosity-c`, `--initial-temp-c`): from the temperature at which
//!   the oil's Walther fit reaches a dynamic viscosity of [`MAX_OIL_VISCOSITY_PA_S`] (but not
//!   below [`OIL_RANGE_C`]`.0`) up to [`OIL_RANGE_C`]`.1`.
//! - **Every other node**: [`NODE_RANGE_C`].
//!
//! An option outside the oil's range is refused before anything runs (exit 1, with the range);
//! a state that leaves the envelope fails the job (exit 2), naming the time, the node, its
//! temperature and the model whose range it left.

use crate::physics::oil::Oil;
use crate::scene::Scene;
use crate::solve::transient::{Segment, Trajectory};

use super::limits::{short, Limit};
use super::JobError;
use crate::physics::units::{c_to_k, k_to_c};

pub use crate::solve::equilibrium::{NODE_RANGE_C, OIL_RANGE_C};

/// Highest dynamic viscosity of the oil's range, Pa·s: 150 000 mPa·s, the Brookfield viscosity
/// (ASTM D2983) that defines the low-temperature end of every winter grade of SAE J306
/// (automotive gear lubricant viscosity classification: 70W at −55 °C, 75W at −40 °C, 80W at
/// −26 °C, 85W at −12 °C). ASTM D341 §3.1 holds the Walther charts to the range in which the oil
/// is a homogeneous liquid, from its cloud point up; the catalogue states no cloud or pour point,
/// so the classification's limit stands in for it.
pub const MAX_OIL_VISCOSITY_PA_S: f64 = 150.0;

/// The temperature range, °C, in which an oil's Walther fit is used.
#[derive(Debug, Clone, PartialEq)]
pub struct OilRange {
    /// Oil name.
    pub oil: String,
    /// Lowest temperature, °C (rounded up to 0.1 °C: the value checked is the value printed).
    pub lo_c: f64,
    /// Highest temperature, °C.
    pub hi_c: f64,
}

impl OilRange {
    /// The range of `oil`: its cold end where μ reaches [`MAX_OIL_VISCOSITY_PA_S`] (by bisection;
    /// μ = ρ ν falls monotonically with temperature), within [`OIL_RANGE_C`].
    pub fn of(oil: &Oil) -> OilRange {
        let (floor, top) = OIL_RANGE_C;
        let mu = |c: f64| oil.dynamic_viscosity(c_to_k(c));
        let at_floor = mu(floor);
        let lo_c = if at_floor.is_finite() && at_floor <= MAX_OIL_VISCOSITY_PA_S {
            floor
        } else if !(mu(top).is_finite() && mu(top) < MAX_OIL_VISCOSITY_PA_S) {
            top
        } else {
            let (mut cold, mut warm) = (floor, top);
            for _ in 0..60 {
                let mid = 0.5 * (cold + warm);
                if mu(mid) > MAX_OIL_VISCOSITY_PA_S {
                    cold = mid;
                } else {
                    warm = mid;
                }
            }
            ((warm * 10.0).ceil() / 10.0).min(top)
        };
        OilRange {
            oil: oil.name.clone(),
            lo_c,
            hi_c: top,
        }
    }

    /// True when `t_c` (°C) lies in the range.
    pub fn contains(&self, t_c: f64) -> bool {
        t_c.is_finite() && (self.lo_c..=self.hi_c).contains(&t_c)
    }

    /// `[lo, hi] °C`.
    pub fn allowed(&self) -> String {
        format!("[{}, {}] °C", short(self.lo_c), short(self.hi_c))
    }

    /// The range and whose it is, for messages.
    pub fn describe(&self) -> String {
        format!(
            "{}, where the Walther fit of oil {} holds (its cold end is where the viscosity reaches {} mPa s, \
             the SAE J306 low-temperature limit)",
            self.allowed(),
            self.oil,
            short(MAX_OIL_VISCOSITY_PA_S * 1e3)
        )
    }

    /// Refuse option `limit` = `v` (°C) outside the range, with the range in the message.
    pub fn check_option(&self, limit: &Limit, v: f64) -> Result<f64, JobError> {
        limit.check(v)?;
        if self.contains(v) {
            return Ok(v);
        }
        Err(JobError::option(
            limit.name,
            short(v),
            self.allowed(),
            format!(
                "{} = {} °C: must lie in {}",
                limit.name,
                short(v),
                self.describe()
            ),
        ))
    }

    /// [`Self::check_option`] for an optional value.
    pub fn check_option_opt(&self, limit: &Limit, v: Option<f64>) -> Result<(), JobError> {
        v.map(|x| self.check_option(limit, x)).transpose().map(|_| ())
    }
}

/// A node outside the envelope: which, where, and whose range it left.
#[derive(Debug, Clone, PartialEq)]
pub struct Breach {
    /// Node name.
    pub node: String,
    /// Its temperature, °C.
    pub temp_c: f64,
    /// The range it left and the model that range belongs to.
    pub range: String,
}

impl std::fmt::Display for Breach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "node {} at {:.1} °C is outside {}",
            self.node, self.temp_c, self.range
        )
    }
}

/// The envelope of one compiled scene.
#[derive(Debug, Clone)]
pub struct Envelope {
    /// The oil's range.
    pub oil: OilRange,
    oil_node: usize,
    names: Vec<String>,
}

impl Envelope {
    /// The envelope of `scene` (its oil and its nodes).
    pub fn of(scene: &Scene) -> Envelope {
        Envelope {
            oil: OilRange::of(scene.thermal().oil_model()),
            oil_node: scene.thermal().oil,
            names: scene.thermal().names.clone(),
        }
    }

    /// The first node of `temps_k` (K, the network's nodes in order) outside the envelope.
    pub fn check(&self, temps_k: &[f64]) -> Result<(), Breach> {
        let (lo, hi) = NODE_RANGE_C;
        for (i, (name, t_k)) in self.names.iter().zip(temps_k).enumerate() {
            let t = k_to_c(*t_k);
            let breach = |range: String| Breach {
                node: name.clone(),
                temp_c: t,
                range,
            };
            if i == self.oil_node {
                if !self.oil.contains(t) {
                    return Err(breach(self.oil.describe()));
                }
            } else if !(t.is_finite() && (lo..=hi).contains(&t)) {
                return Err(breach(format!(
                    "[{}, {}] °C, the range of the thermal network's solid nodes",
                    short(lo),
                    short(hi)
                )));
            }
        }
        Ok(())
    }

    /// The first output row of a run outside the envelope, named by time, node and the largest
    /// loss item there (evaluated at that row's state with its segment's inputs).
    pub fn check_run(&self, scene: &Scene, segs: &[Segment], traj: &Trajectory) -> Result<(), String> {
        let n = scene.nodes();
        for (k, y) in traj.states.iter().enumerate() {
            let Err(b) = self.check(&y[..n]) else {
                continue;
            };
            let t = traj.times[k];
            let since = match k.checked_sub(1) {
                Some(p) => format!("between t = {} s and t = {t} s", traj.times[p]),
                None => format!("at t = {t} s (the initial state)"),
            };
            let item = traj
                .segment
                .get(k)
                .and_then(|&s| segs.get(s))
                .and_then(|s| largest_item(scene, s, y))
                .map_or(String::new(), |i| format!("; largest loss there: {i}"));
            return Err(format!(
                "the state left the range where its models hold {since}: {b}{item}"
            ));
        }
        Ok(())
    }
}

/// `source:name (P W)` of the largest loss item at state `y` with the inputs of `seg`.
fn largest_item(scene: &Scene, seg: &Segment, y: &[f64]) -> Option<String> {
    let mut w = scene.work(seg.inputs);
    scene.evaluate_losses(y, &mut w);
    let (k, q) =
        w.q.iter()
            .enumerate()
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))?;
    let it = &scene.losses().items[k];
    Some(format!("{}:{} ({q:.3e} W)", it.source.as_str(), it.name))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::oil::{WaltherVariant, ALPHA_T_MINERAL, CST};

    fn fva3a() -> Oil {
        Oil::new(
            "FVA 3A",
            WaltherVariant::AstmD341,
            90.02 * CST,
            10.41 * CST,
            884.1,
            ALPHA_T_MINERAL,
        )
        .unwrap()
    }

    /// The cold end is where μ crosses 150 Pa·s: thicker just below it, thinner at it.
    #[test]
    fn the_cold_end_is_where_the_viscosity_reaches_the_j306_limit() {
        let oil = fva3a();
        let r = OilRange::of(&oil);
        let mu = |c: f64| oil.dynamic_viscosity(c_to_k(c));
        assert!(r.lo_c > OIL_RANGE_C.0 && r.lo_c < 0.0, "{r:?}");
        assert!(mu(r.lo_c) <= MAX_OIL_VISCOSITY_PA_S, "{}", mu(r.lo_c));
        assert!(mu(r.lo_c - 0.1) > MAX_OIL_VISCOSITY_PA_S, "{}", mu(r.lo_c - 0.1));
        assert_eq!(r.hi_c, OIL_RANGE_C.1);
        assert!(r.contains(r.lo_c) && !r.contains(r.lo_c - 0.05) && !r.contains(f64::NAN));
    }

    /// A thin oil that never reaches the limit above the floor keeps the floor.
    #[test]
    fn a_thin_oil_keeps_the_floor() {
        let oil = Oil::new(
            "thin",
            WaltherVariant::AstmD341,
            4.0 * CST,
            1.5 * CST,
            800.0,
            -7e-4,
        )
        .unwrap();
        assert_eq!(OilRange::of(&oil).lo_c, OIL_RANGE_C.0);
    }

    /// An option outside the oil's range is refused with the range in the message.
    #[test]
    fn an_option_outside_the_oil_range_is_refused_with_the_range() {
        let r = OilRange::of(&fva3a());
        let lim = super::super::limits::FROZEN_VISCOSITY_C;
        let e = r.check_option(&lim, -60.0).unwrap_err();
        assert_eq!(e.exit_code(), 1);
        assert!(e.message.starts_with("frozen_viscosity_c = "), "{}", e.message);
        assert!(e.message.contains(&r.allowed()), "{}", e.message);
        assert!(r.check_option(&lim, 40.0).is_ok());
    }
}
