//! From a gearbox and a drive (or rig) cycle to the solver's input segments and the per-row
//! inputs of the outputs: the glue between `cycle` and the transient driver.

use crate::cycle::{schedule_with_launch, CycleError, DriveCycle, GearTable, Schedule};
use crate::model::Gearbox;
use crate::physics::units::m_s_to_kmh;
use crate::scene::Inputs;

use super::trajectory::{Segment, Trajectory};

/// The gear table of a gearbox: every gear state with its ratio, in model order (the table index
/// is the gear-state index).
pub fn gear_table(gb: &Gearbox) -> GearTable {
    GearTable::new(
        gb.gear_states
            .iter()
            .map(|g| (g.name.clone(), g.ratio()))
            .collect(),
    )
}

/// Schedule a cycle on a gearbox and turn it into solver segments.
pub fn segments(gb: &Gearbox, cycle: &DriveCycle) -> Result<(Schedule, Vec<Segment>), CycleError> {
    let sched = schedule_with_launch(cycle, gb.vehicle.as_ref(), &gear_table(gb), gb.launch.as_ref())?;
    let segs = sched
        .intervals
        .iter()
        .map(|iv| Segment {
            t0: iv.t0,
            t1: iv.t1,
            inputs: Inputs {
                state: iv.gear,
                input_speed: iv.input_speed,
                input_torque: iv.input_torque,
                vehicle_speed: iv.vehicle_speed,
            },
        })
        .collect();
    Ok((sched, segs))
}

/// Per-row context the solver does not know: vehicle speed, gear name, input speed and torque,
/// output power.
#[derive(Debug, Clone)]
pub struct RowInputs {
    /// Vehicle speed, km/h.
    pub vehicle_speed_kmh: f64,
    /// Gear-state name (shared by the rows of one state).
    pub gear: std::sync::Arc<str>,
    /// Input speed, rpm.
    pub input_speed_rpm: f64,
    /// Loss-free input torque T_out/i, N·m (`timeseries.csv` adds the losses: P_loss/ω_in).
    pub input_torque_nm: f64,
    /// Output power, W.
    pub output_power_w: f64,
    /// With a launch device: engine-side (converter impeller) speed, rpm, torque into the
    /// launch device, N·m, and the lock-up clutch state (`None` without one).
    pub engine: Option<EngineRow>,
}

/// Engine side of a row of a run with a launch device (`cycle::Interval`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EngineRow {
    /// Impeller (engine) speed, rpm.
    pub speed_rpm: f64,
    /// Impeller torque for the loss-free turbine demand, N·m.
    pub torque_nm: f64,
    /// The lock-up clutch is closed.
    pub lockup: bool,
    /// Converter slip loss, W.
    pub converter_loss_w: f64,
}

/// Row inputs of a trajectory's output rows (each row shows the inputs of its segment).
pub fn row_inputs(gb: &Gearbox, sched: &Schedule, traj: &Trajectory) -> Vec<RowInputs> {
    let names: Vec<std::sync::Arc<str>> = gb.gear_states.iter().map(|g| g.name.as_str().into()).collect();
    traj.segment
        .iter()
        .map(|&k| {
            let iv = &sched.intervals[k];
            RowInputs {
                vehicle_speed_kmh: m_s_to_kmh(iv.vehicle_speed),
                gear: names[iv.gear].clone(),
                input_speed_rpm: iv.input_speed * 30.0 / std::f64::consts::PI,
                input_torque_nm: iv.input_torque,
                output_power_w: iv.output_power,
                engine: gb.launch.as_ref().map(|_| EngineRow {
                    speed_rpm: iv.engine_speed * 30.0 / std::f64::consts::PI,
                    torque_nm: iv.engine_torque,
                    lockup: iv.lockup,
                    converter_loss_w: iv.converter_loss,
                }),
            }
        })
        .collect()
}
