//! A cycle's schedule (gear, speeds, torques and converter state per interval) and its solver
//! segments, computed once per study job and reused by every case whose schedule inputs equal
//! those it was computed from.
//!
//! `solve::drive::segments` reads the cycle, the vehicle, the gear states' names and ratios and
//! the launch device only; the cache keeps a copy of each and hands its result to a case only
//! when all four compare equal (`PartialEq`, every field), so a case gets bitwise the schedule
//! it would compute. An uncertainty study that varies heat transfer or the oil level shares one
//! schedule; a study that varies the vehicle or a ratio computes its own per case.

use std::sync::OnceLock;

use crate::cycle::{CycleError, DriveCycle, GearTable, LaunchDevice, Schedule, Vehicle};
use crate::model::gearbox::Gearbox;
use crate::solve::drive::{gear_table, segments};
use crate::solve::transient::Segment;

/// What the schedule is computed from.
#[derive(Debug, Clone, PartialEq)]
struct Inputs {
    cycle: DriveCycle,
    vehicle: Option<Vehicle>,
    gears: GearTable,
    launch: Option<LaunchDevice>,
}

impl Inputs {
    fn of(gb: &Gearbox, cycle: &DriveCycle) -> Inputs {
        Inputs {
            cycle: cycle.clone(),
            vehicle: gb.vehicle.clone(),
            gears: gear_table(gb),
            launch: gb.launch.clone(),
        }
    }

    fn matches(&self, gb: &Gearbox, cycle: &DriveCycle) -> bool {
        self.cycle == *cycle
            && self.vehicle == gb.vehicle
            && self.launch == gb.launch
            && self.gears == gear_table(gb)
    }
}

/// The first successful schedule of a job, with what it was computed from.
#[derive(Debug, Default)]
pub struct ScheduleCache {
    first: OnceLock<(Inputs, Schedule, Vec<Segment>)>,
}

impl ScheduleCache {
    /// [`segments`] of `gb` on `cycle`: the cached result when its inputs equal these, else
    /// computed (and kept when it is the job's first).
    pub fn segments(&self, gb: &Gearbox, cycle: &DriveCycle) -> Result<(Schedule, Vec<Segment>), CycleError> {
        if let Some((inputs, sched, segs)) = self.first.get() {
            if inputs.matches(gb, cycle) {
                return Ok((sched.clone(), segs.clone()));
            }
            return segments(gb, cycle);
        }
        let (sched, segs) = segments(gb, cycle)?;
        let _ = self
            .first
            .set((Inputs::of(gb, cycle), sched.clone(), segs.clone()));
        Ok((sched, segs))
    }
}
