//! Loss items that are not gears or meshes: rolling bearings and shaft seals. Compiled once per
//! scene with their speed per unit input speed and their loads per unit input torque in every
//! gear state ([`super::bearing_loads`]); a cycle sample fixes the load terms of each bearing
//! ([`ElementLosses::prepare`]), a right-hand-side call only the viscosity-dependent part.

use crate::model::bearings::BearingMount;
use crate::model::gearbox::{GearMount, Gearbox};
use crate::physics::losses::bearings::skf::speed_exponent_powers;
use crate::physics::losses::bearings::{BearingFriction, BearingLoad, BearingOil, LoadTerms};
use crate::physics::losses::seals::LipSeal;
use crate::physics::oil::OilProperties;

use super::bearing_loads::{magnitudes, state_loads};
use super::items::{DefaultHeat, LossItem, Skipped, Source};

/// Round-off of the kinematic solve snapped to zero (as for the gear items).
fn clean(v: f64) -> f64 {
    if v.abs() < 1e-12 {
        0.0
    } else {
        v
    }
}

#[derive(Debug, Clone, PartialEq)]
struct BearingEntry {
    item: usize,
    model: BearingFriction,
    /// Planets of the set for planet bearings (one bearing per planet), else 1.
    multiplicity: f64,
    /// Relative ring speed per unit input speed, per state.
    speed: Vec<f64>,
    /// (radial, axial) load per unit |input torque|, per state, N/(N·m).
    load: Vec<[f64; 2]>,
    /// Constant (radial, axial) loads, N.
    preload: [f64; 2],
    /// SKF speed powers per unit input speed, per state (`None`: Palmgren).
    speed_unit: Vec<Option<[f64; 4]>>,
}

#[derive(Debug, Clone, PartialEq)]
struct SealEntry {
    item: usize,
    seal: LipSeal,
    speed: Vec<f64>,
}

/// Compiled bearings and seals.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ElementLosses {
    bearings: Vec<BearingEntry>,
    seals: Vec<SealEntry>,
}

/// Member speeds per unit input speed of state `si`.
fn member_speeds(gb: &Gearbox, si: usize) -> &[f64] {
    &gb.gear_states[si].solution.speeds
}

impl ElementLosses {
    /// Compile the bearings and seals of `gb`, appending their items; `needed(si)` tells which
    /// states the run visits (an element still in all of them is skipped).
    pub fn compile(
        gb: &Gearbox,
        needed: &dyn Fn(usize) -> bool,
        idle: &dyn Fn(String, &str) -> Skipped,
        keep_idle: bool,
        items: &mut Vec<LossItem>,
        skipped: &mut Vec<Skipped>,
    ) -> ElementLosses {
        let n = gb.gear_states.len();
        let loads: Vec<_> = (0..n).map(|si| state_loads(gb, si)).collect();
        let mut out = ElementLosses::default();
        for (k, b) in gb.bearings.iter().enumerate() {
            let speed: Vec<f64> = (0..n)
                .map(|si| {
                    let w = member_speeds(gb, si);
                    clean(match b.mount {
                        BearingMount::Member { member, outer } => w[member] - outer.map_or(0.0, |o| w[o]),
                        BearingMount::Planet { gear } => gb.gear_speeds(si)[gear].relative,
                    })
                })
                .collect();
            if !keep_idle && !(0..n).any(|si| needed(si) && speed[si] != 0.0) {
                skipped.push(idle(
                    format!("bearing {}", b.name),
                    "its rings do not turn relative to each other",
                ));
                continue;
            }
            let (multiplicity, heat_gear) = match b.mount {
                BearingMount::Member { member, .. } => (
                    1.0,
                    gb.gears
                        .iter()
                        .position(|g| g.member == member && g.mount == GearMount::OnMember),
                ),
                BearingMount::Planet { gear } => {
                    let set = match gb.gears[gear].mount {
                        GearMount::Planet { set, .. } => set,
                        GearMount::OnMember => 0,
                    };
                    (f64::from(gb.planetary_sets[set].planets), Some(gear))
                }
            };
            let load = loads
                .iter()
                .map(|l| {
                    let (r, a) = magnitudes(&l.reactions[k]);
                    [r, a]
                })
                .collect();
            out.bearings.push(BearingEntry {
                item: items.len(),
                model: b.friction.clone(),
                multiplicity,
                speed_unit: speed
                    .iter()
                    .map(|&r| b.friction.speed_powers_per_unit(r))
                    .collect(),
                speed,
                load,
                preload: [b.preload.0, b.preload.1],
            });
            items.push(LossItem {
                source: Source::Bearing,
                name: b.name.clone(),
                gears: Vec::new(),
                heat: default_heat(&b.heat_to, heat_gear),
                engine_side: false,
            });
        }
        for s in &gb.seals {
            let speed: Vec<f64> = (0..n)
                .map(|si| {
                    let w = member_speeds(gb, si);
                    clean(w[s.member] - s.outer.map_or(0.0, |o| w[o]))
                })
                .collect();
            if !keep_idle && !(0..n).any(|si| needed(si) && speed[si] != 0.0) {
                skipped.push(idle(
                    format!("seal {}", s.name),
                    "its shaft does not turn relative to the seal",
                ));
                continue;
            }
            let heat_gear = gb
                .gears
                .iter()
                .position(|g| g.member == s.member && g.mount == GearMount::OnMember);
            out.seals.push(SealEntry {
                item: items.len(),
                seal: s.seal,
                speed,
            });
            items.push(LossItem {
                source: Source::Seal,
                name: s.name.clone(),
                gears: Vec::new(),
                heat: default_heat(&s.heat_to, heat_gear),
                engine_side: false,
            });
        }
        out
    }

    /// Number of compiled bearings (size of the per-sample terms).
    pub fn bearings(&self) -> usize {
        self.bearings.len()
    }

    /// Load terms of every bearing for `state`, input speed `w_in` (rad/s) and torque `t_in`
    /// (N·m) into `terms`. No allocation.
    ///
    /// The SKF speed powers of every bearing are its per-state powers per unit input speed times
    /// the powers of the input speed, computed once (one logarithm, four exponentials per sample
    /// instead of per bearing).
    pub fn prepare(&self, state: usize, w_in: f64, t_in: f64, terms: &mut [LoadTerms]) {
        if self.bearings.is_empty() {
            return;
        }
        let w_pow = speed_exponent_powers(w_in);
        for (e, t) in self.bearings.iter().zip(terms) {
            let speed = e.speed_unit[state].map(|u| [0, 1, 2, 3].map(|i| u[i] * w_pow[i]));
            *t = load_terms_with_speed(e, state, w_in, t_in, speed);
        }
    }

    /// Losses (W) of every bearing and seal at `state`, `w_in`, `t_in` and `oil` into `out`;
    /// `terms`: load terms prepared for this sample, or `None` to compute them here. No
    /// allocation.
    pub fn evaluate(
        &self,
        state: usize,
        w_in: f64,
        t_in: f64,
        oil: &OilProperties,
        terms: Option<&[LoadTerms]>,
        out: &mut [f64],
    ) {
        if !self.bearings.is_empty() {
            self.evaluate_bearings(state, w_in, t_in, BearingOil::new(oil.nu), terms, out);
        }
        for e in &self.seals {
            out[e.item] = e.seal.power(e.speed[state] * w_in);
        }
    }

    fn evaluate_bearings(
        &self,
        state: usize,
        w_in: f64,
        t_in: f64,
        bo: BearingOil,
        terms: Option<&[LoadTerms]>,
        out: &mut [f64],
    ) {
        for (k, e) in self.bearings.iter().enumerate() {
            let w = e.speed[state] * w_in;
            out[e.item] = if w == 0.0 {
                0.0
            } else {
                let t = match terms {
                    Some(ts) => ts[k],
                    None => load_terms(e, state, w_in, t_in),
                };
                e.multiplicity * e.model.moment(&t, bo).total() * w.abs()
            };
        }
    }
}

fn load_terms(e: &BearingEntry, state: usize, w_in: f64, t_in: f64) -> LoadTerms {
    load_terms_with_speed(e, state, w_in, t_in, None)
}

/// Load terms of `e`, with its SKF speed powers `speed` when known
/// ([`BearingFriction::load_terms_with_speed`]).
fn load_terms_with_speed(
    e: &BearingEntry,
    state: usize,
    w_in: f64,
    t_in: f64,
    speed: Option<[f64; 4]>,
) -> LoadTerms {
    let [r, a] = e.load[state];
    let t = t_in.abs();
    let load = BearingLoad {
        radial: r * t + e.preload[0],
        axial: a * t + e.preload[1],
    };
    e.model.load_terms_with_speed(e.speed[state] * w_in, load, speed)
}

fn default_heat(heat_to: &Option<Vec<(String, f64)>>, gear: Option<usize>) -> DefaultHeat {
    match (heat_to, gear) {
        (Some(list), _) => DefaultHeat::Nodes(list.clone()),
        (None, Some(g)) => DefaultHeat::Member(vec![(g, 1.0)]),
        (None, None) => DefaultHeat::Oil,
    }
}
