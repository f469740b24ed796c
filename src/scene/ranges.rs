//! Warnings: loss models used outside the range they were fitted or derived on, and loss items
//! whose value is not known. Reported in `warnings` of the JSON outputs and
//! summary.json, and one stderr line per item and range.
//!
//! Range checks depend on the operating point (speeds, oil viscosity), so they are gathered over
//! the points a command evaluates ([`RangeLog::check`]) and summarised per item and range with
//! the span of the quantity seen ([`RangeLog::warnings`]).

use crate::physics::losses::churning::ranges::above_dip_speed;
use crate::physics::losses::churning::{OilState, RangeCheck};

use super::items::OperatingPoint;
use super::losses::LossScene;

pub use super::warning::{above_oil_warning, RangeWarning};

/// Per item and range: points seen out of range and the span of the quantity.
#[derive(Debug, Clone)]
pub struct RangeLog {
    /// [item][check] → (count, min, max).
    seen: Vec<[(usize, f64, f64); RangeCheck::ALL.len()]>,
    /// Points checked.
    points: usize,
}

impl RangeLog {
    /// An empty log for `scene`.
    pub fn new(scene: &LossScene) -> RangeLog {
        RangeLog {
            seen: vec![[(0, f64::INFINITY, f64::NEG_INFINITY); RangeCheck::ALL.len()]; scene.len()],
            points: 0,
        }
    }

    /// Check every churning model of `scene` at `op`, every churning gear's pitch-line speed
    /// against the dip-lubrication range, and every windage model in air.
    pub fn check(&mut self, scene: &LossScene, op: &OperatingPoint) {
        self.points += 1;
        let oil = OilState {
            density: op.oil.rho,
            kinematic_viscosity: op.oil.nu,
        };
        let mut last = [(usize::MAX, usize::MAX); 2];
        for (item, m, w) in scene.churning_models(op.state, op.input_speed) {
            let checks = [m.out_of_range(w, &oil), m.law_disagreement(w, &oil)];
            for (slot, found) in checks.into_iter().enumerate() {
                if let Some((c, v)) = found {
                    // a planet has several orbit nodes: count the point once per item and range
                    let first = last[slot] != (item, c.index());
                    last[slot] = (item, c.index());
                    self.record(item, c, v, first);
                }
            }
        }
        for (item, speed) in scene.churning_pitch_speeds(op.state, op.input_speed) {
            if let Some((c, v)) = above_dip_speed(speed) {
                self.record(item, c, v, true);
            }
        }
        let air = crate::physics::losses::windage::AIR;
        for (item, m, w) in scene.windage_models(op.state, op.input_speed) {
            if let Some((c, v)) = m.out_of_range(w, &air) {
                self.record(item, c, v, true);
            }
        }
    }

    /// One out-of-range value `v` of check `c` for `item`; `count` adds the point.
    fn record(&mut self, item: usize, c: RangeCheck, v: f64, count: bool) {
        let e = &mut self.seen[item][c.index()];
        if count {
            e.0 += 1;
        }
        e.1 = e.1.min(v);
        e.2 = e.2.max(v);
    }

    /// The static warnings of `scene` followed by one warning per item and range met.
    pub fn warnings(&self, scene: &LossScene) -> Vec<RangeWarning> {
        let mut out = scene.warnings.clone();
        for (k, per) in self.seen.iter().enumerate() {
            for c in RangeCheck::ALL {
                let (n, lo, hi) = per[c.index()];
                if n == 0 {
                    continue;
                }
                let span = if (hi - lo).abs() <= 1e-9 * hi.abs() {
                    format!("{} {}", c.quantity(), sig(lo))
                } else {
                    format!("{} {}–{}", c.quantity(), sig(lo), sig(hi))
                };
                out.push(RangeWarning {
                    item: format!(
                        "{} of gear {}",
                        scene.items[k].source.as_str(),
                        scene.items[k].name
                    ),
                    range: c.range().into(),
                    seen: format!("{span} at {n} of {} points", self.points),
                });
            }
        }
        out
    }
}

/// A number to 4 significant digits, no exponent for the usual magnitudes.
fn sig(v: f64) -> String {
    if v.abs() >= 1e5 {
        format!("{v:.3e}")
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.3}")
    }
}
