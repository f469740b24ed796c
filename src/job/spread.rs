//! Model-form spread of a job: every applicable model choice of each loss item's source at an
//! operating point (`losses`, `steady`), and each source's energy per model choice along a
//! run's own trajectory (`run --spread`; the thermal network is not solved again per model).

//!
//! The disagreement warning: an item is warned when its applicable models disagree by more than
//! [`DISAGREEMENT_FACTOR`] **and** the choice among them moves the point's total loss by at
//! least [`WARN_SHARE_OF_TOTAL`] (max − min ≥ that share of the default models' total loss at
//! the point). A windage item of a few watts whose models differ tenfold is listed in the block
//! (its factor is there) but not warned: no choice among its models changes the result.

use crate::model::Gearbox;
use crate::report::spread::SpreadBlock;
use crate::scene::{Inputs, ItemSpread, LossScene, Needs, OperatingPoint, Scene, SourceSpread, SpreadScene};
use crate::solve::transient::{Segment, Trajectory};

/// Models disagreeing by more than this factor on an item are warned (when the item matters:
/// [`WARN_SHARE_OF_TOTAL`]).
pub const DISAGREEMENT_FACTOR: f64 = 3.0;

/// The share of the point's total loss that the spread of an item (max − min) must reach for
/// its disagreement to be warned.
pub const WARN_SHARE_OF_TOTAL: f64 = 0.01;

/// The spread at `op` of `scene` (compiled from `gb` for `needs`), whose values there are
/// `out`.
pub fn at_point(
    gb: &Gearbox,
    needs: &Needs,
    scene: &LossScene,
    out: &[f64],
    op: &OperatingPoint,
) -> SpreadBlock {
    let spread = SpreadScene::compile(gb, needs, scene);
    let items = spread.evaluate(scene, out, op);
    let total_w: f64 = out.iter().sum();
    let warnings = items.iter().filter_map(|it| warning(it, total_w)).collect();
    SpreadBlock::new(items, warnings)
}

/// The disagreement warning of `it` at a point whose total loss is `total_w` (see the module
/// docs): `item churning:wheel1: applicable models disagree by 27.7× (…)`.
pub fn warning(it: &ItemSpread, total_w: f64) -> Option<String> {
    if it.factor.is_some_and(|f| f <= DISAGREEMENT_FACTOR) || it.max_w <= 0.0 {
        return None;
    }
    if it.max_w - it.min_w < WARN_SHARE_OF_TOTAL * total_w.abs() {
        return None;
    }
    let at = |v: f64| it.models.iter().find(|m| m.w == Some(v)).map_or("", |m| m.label);
    let by = it
        .factor
        .map_or("an unbounded factor (one gives 0 W)".into(), |f| {
            format!("{f:.1}×")
        });
    Some(format!(
        "item {}:{}: applicable models disagree by {by} ({} {:.0} W … {} {:.0} W)",
        it.source.as_str(),
        it.name,
        at(it.max_w),
        it.max_w,
        at(it.min_w),
        it.min_w
    ))
}

/// Each source's energy per model choice of `spread` along `traj` (the rows of a run of
/// `scene` over `segs`): every interval between two output rows with its segment's inputs and
/// the oil at both ends (trapezoid rule). Non-finite energies are left out of the block.
pub fn along_run(
    spread: &SpreadScene,
    scene: &Scene,
    segs: &[Segment],
    traj: &Trajectory,
) -> Vec<SourceSpread> {
    let mut work = spread.work(scene.losses());
    let oil = |r: usize| {
        traj.states
            .get(r)
            .map(|y| scene.thermal().oil_properties(scene.oil_temp(y)))
    };
    for r in 0..traj.times.len().saturating_sub(1) {
        let dt = traj.times[r + 1] - traj.times[r];
        let Some(seg) = traj.segment.get(r).and_then(|&k| segs.get(k)) else {
            continue;
        };
        let (Some(start), Some(end)) = (oil(r), oil(r + 1)) else {
            continue;
        };
        if dt <= 0.0 {
            continue;
        }
        let inputs: Inputs = seg.inputs;
        spread.accumulate(scene.losses(), &inputs, [start, end], dt, &mut work);
    }
    let mut out = spread.source_energies(scene.losses(), &work);
    for s in &mut out {
        for m in &mut s.models {
            if m.j.is_some_and(|j| !j.is_finite()) {
                m.j = None;
                m.not_applicable.push("not finite along this trajectory".into());
            }
        }
        let js = s.models.iter().filter_map(|m| m.j);
        s.min_j = js.clone().fold(s.default_j, f64::min);
        s.max_j = js.fold(s.default_j, f64::max);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::source::Source;
    use crate::scene::ModelValue;

    fn item(lo: f64, hi: f64) -> ItemSpread {
        let m = |model, w, default| ModelValue {
            model,
            label: model,
            default,
            w: Some(w),
            not_applicable: None,
            outside: Vec::new(),
        };
        ItemSpread {
            source: Source::Windage,
            name: "pinion".into(),
            default_w: lo,
            min_w: lo,
            max_w: hi,
            factor: Some(hi / lo),
            models: vec![m("a", lo, true), m("b", hi, false)],
        }
    }

    #[test]
    fn a_disagreement_is_warned_only_when_it_moves_the_total_by_the_share() {
        // 0.2 W against 2 W (factor 10): 1.8 W of spread.
        let it = item(0.2, 2.0);
        assert!(warning(&it, 1.8 / WARN_SHARE_OF_TOTAL * 1.01).is_none());
        let w = warning(&it, 1.8 / WARN_SHARE_OF_TOTAL * 0.99).expect("warned");
        assert!(
            w.starts_with("item windage:pinion: applicable models disagree by 10.0×"),
            "{w}"
        );
        // A factor of 3 or less is never warned.
        assert!(warning(&item(1.0, 3.0), 1.0).is_none());
    }
}
