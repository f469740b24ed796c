//! Drive cycles and rig cycles, the vehicle, the shift strategy, and the schedule of gearbox
//! inputs they produce (physics.md §9). Pure and SI inside; the only file access is
//! [`DriveCycle::load`].
//!
//! - [`parse`]: CSV text → [`DriveCycle`] (vehicle cycle `time_s,speed_kmh[,gear]` or rig cycle
//!   `time_s,input_speed_rpm,input_torque_nm,gear`), with line-numbered [`CycleError`]s;
//! - [`bundled`]: the cycles in `models/cycles/` compiled in; [`bundled_names`], [`resolve`];
//! - [`vehicle`]: the checked [`Vehicle`] and its longitudinal dynamics;
//! - [`gears`]: the gear table (state names and ratios) the others share;
//! - [`shift`]: gear choice with hysteresis and minimum hold time;
//! - [`launch`]: the checked [`LaunchDevice`], a torque converter with lock-up: engine-side speed
//!   and torque from the turbine (= gearbox input) demand;
//! - [`schedule()`]: cycle + vehicle + gear table → piecewise-constant [`Schedule`].

pub mod bundled;
pub mod error;
pub mod gears;
pub mod launch;
pub mod parse;
pub mod schedule;
pub mod shift;
pub mod vehicle;

pub use bundled::{bundled_names, resolve};
pub use error::{CycleError, CycleErrorKind};
pub use gears::GearTable;
pub use launch::{EngineSide, LaunchDevice};
pub use parse::{CycleKind, CycleRow, DriveCycle};
pub use schedule::{schedule, schedule_with_launch, Interval, Schedule};
pub use shift::{BoundShift, Shifter};
pub use vehicle::{Demand, Overrun, RoadLoad, ShiftStrategy, Vehicle};
