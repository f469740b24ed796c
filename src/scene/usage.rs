//! Which gear states a run needs, and the kinematics of every state per unit input (gear
//! speeds, mesh torques) that decide whether a loss item is idle in all of them.

use crate::model::gearbox::{GearSpeed, Gearbox};

use super::items::Skipped;

/// What a run needs from the scene (scene pruning, docs/performance.md).
#[derive(Debug, Clone, Default)]
pub struct Needs {
    /// Gear states the run visits (`None`: every state of the model). Loss items idle in all of
    /// them (no relative motion, no load) are not compiled.
    pub states: Option<Vec<usize>>,
    /// Evaluate everything: keep idle items and states, and recompute every loss in full at
    /// every call instead of caching per-sample terms. Only for measuring what pruning and
    /// caching gain; results agree to rounding.
    pub evaluate_all: bool,
    /// Loss energy per source only (three quadratures) instead of per item: for runs whose
    /// outputs do not include the energy of each item (the work-precision benchmark).
    pub energy_per_source_only: bool,
    /// The ambient boundary held at this temperature, K (the scenario's ambient; the model's
    /// own boundary temperatures otherwise). The model must have an ambient boundary.
    pub ambient_k: Option<f64>,
    /// Oil properties frozen at this temperature, K (the scenario's frozen viscosity; they
    /// follow the oil node otherwise).
    pub frozen_oil_temp_k: Option<f64>,
}

/// Kinematics of every gear state and which states a run needs.
pub(super) struct Usage {
    /// Per state: gear speeds per unit input speed.
    pub(super) speeds: Vec<Vec<GearSpeed>>,
    /// Per state: mesh torques per unit input torque.
    pub(super) torques: Vec<Vec<f64>>,
    /// Needed states.
    used: Vec<usize>,
    /// Names of the needed states when they are not all of the model's.
    subset: Option<String>,
    /// Keep everything.
    all: bool,
}

impl Usage {
    /// The kinematics of `gb` and the states `needs` asks for.
    pub(super) fn of(gb: &Gearbox, needs: &Needs) -> Usage {
        // Round-off from the kinematic solve (~1e-16 per unit input) is snapped to exact zero so a
        // locked set (all members at one speed) has no relative motion at all.
        let clean = |v: f64| if v.abs() < 1e-12 { 0.0 } else { v };
        let n = gb.gear_states.len();
        let speeds = (0..n)
            .map(|si| {
                gb.gear_speeds(si)
                    .into_iter()
                    .map(|s| GearSpeed {
                        absolute: clean(s.absolute),
                        relative: clean(s.relative),
                    })
                    .collect()
            })
            .collect();
        let torques = (0..n)
            .map(|si| gb.mesh_torques(si).into_iter().map(clean).collect())
            .collect();
        let mut used: Vec<usize> = match (&needs.states, needs.evaluate_all) {
            (Some(s), false) => s.iter().copied().filter(|&i| i < n).collect(),
            _ => (0..n).collect(),
        };
        used.sort_unstable();
        used.dedup();
        let subset = (used.len() < n).then(|| {
            used.iter()
                .map(|&i| gb.gear_states[i].name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        });
        Usage {
            speeds,
            torques,
            used,
            subset,
            all: needs.evaluate_all,
        }
    }

    /// True if state `si` is needed.
    pub(super) fn needed(&self, si: usize) -> bool {
        self.all || self.used.binary_search(&si).is_ok()
    }

    /// True if `pred` holds in a needed state (always true when everything is kept).
    pub(super) fn any(&self, pred: impl Fn(&Usage, usize) -> bool) -> bool {
        self.all || self.used.iter().any(|&st| pred(self, st))
    }

    /// The reason an item idle in every needed state is left out.
    pub(super) fn idle(&self, what: String, why: &str) -> Skipped {
        Skipped {
            what,
            why: match &self.subset {
                Some(names) => format!("{why} in every gear state the run uses ({names})"),
                None => format!("{why} in every gear state"),
            },
        }
    }
}
