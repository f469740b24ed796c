//! Model-form spread of a job: every applicable model choice of each loss item's source at an
//! operating point (`losses`, `steady`), and each source's energy per model choice along a
//! run's own trajectory (`run --spread`; the thermal network is not solved again per model).

use crate::model::Gearbox;
use crate::report::spread::SpreadBlock;
use crate::scene::{Inputs, LossScene, Needs, OperatingPoint, Scene, SourceSpread, SpreadScene};
use crate::solve::transient::{Segment, Trajectory};

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
    SpreadBlock::new(spread.evaluate(scene, out, op))
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
