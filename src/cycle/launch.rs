//! The launch device: a hydrodynamic torque converter with a lock-up clutch between the engine
//! and the gearbox input (the turbine). The model layer reads the model file's `[launch]` section
//! and checks it into a [`LaunchDevice`] (`crate::model::sections::launch`).
//!
//! With it, the engine side follows from the vehicle demand: the cycle gives the turbine speed
//! and torque (= gearbox input), the converter characteristic gives the impeller (engine) speed
//! and torque and the slip loss (physics in [`crate::physics::losses::converter`]). Lock-up by
//! gear and vehicle speed: the clutch is closed in the listed gears above their vehicle speed,
//! when the turbine turns at least at idle speed; closed, it runs with a constant controlled slip
//! (`slip_rpm`, 0 = rigid). At standstill in gear the engine idles against the stalled turbine.
//! Without the section the gearbox input is driven directly.

pub use crate::physics::losses::converter::ConverterPoint as EngineSide;
use crate::physics::losses::converter::{locked, Converter};

/// A checked launch device (SI).
#[derive(Debug, Clone, PartialEq)]
pub struct LaunchDevice {
    /// Converter characteristic.
    pub converter: Converter,
    /// Idle speed, rad/s.
    pub idle_speed: f64,
    /// Per gear-table index: vehicle speed above which the lock-up clutch closes (m/s; +∞ never).
    pub lockup_above: Vec<f64>,
    /// Controlled slip while locked, rad/s.
    pub lockup_slip: f64,
}

impl LaunchDevice {
    /// Engine side for gear-table index `gear`, vehicle speed `vehicle_speed` (m/s), turbine speed
    /// (rad/s, ≥ 0) and turbine torque demand (N·m). No allocation.
    pub fn engine_side(
        &self,
        gear: usize,
        vehicle_speed: f64,
        turbine_speed: f64,
        turbine_torque: f64,
    ) -> EngineSide {
        let above = self.lockup_above.get(gear).copied().unwrap_or(f64::INFINITY);
        if vehicle_speed > above && turbine_speed >= self.idle_speed {
            locked(turbine_speed, turbine_torque, self.lockup_slip)
        } else {
            self.converter
                .open(turbine_speed, turbine_torque, self.idle_speed)
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::cycle::parse::{KMH, RPM};
    use crate::cycle::vehicle::tests::at6_gears;

    /// A converter with lock-up on the AT6 gear table as checked from its `[launch]` section
    /// (idle 750 rpm; SR 0, 0.5, 0.8, 0.9; K 144.4, 163.7, 197.3, 227.2 rpm/√(N·m); TR 2, 1.43,
    /// 1.10, 1; lock-up in 3rd–6th above 40, 45, 50, 55 km/h with 20 rpm slip); the model layer's
    /// tests check that the section gives exactly this.
    pub(crate) fn launch() -> LaunchDevice {
        let k = [144.4, 163.7, 197.3, 227.2];
        let converter = Converter::new(
            vec![0.0, 0.5, 0.8, 0.9],
            k.iter().map(|k| k * RPM).collect(),
            vec![2.0, 1.43, 1.10, 1.0],
        )
        .unwrap();
        let mut lockup_above = vec![f64::INFINITY; at6_gears().states.len()];
        for (gear, kmh) in [("3", 40.0), ("4", 45.0), ("5", 50.0), ("6", 55.0)] {
            lockup_above[at6_gears().index_of(gear).unwrap()] = kmh * KMH;
        }
        LaunchDevice {
            converter,
            idle_speed: 750.0 * RPM,
            lockup_above,
            lockup_slip: 20.0 * RPM,
        }
    }

    #[test]
    fn lockup_by_gear_and_speed_and_idle_at_standstill() {
        let l = launch();
        // 4th (index 3) at 60 km/h with 2000 rpm turbine: locked with 20 rpm slip
        let e = l.engine_side(3, 60.0 * KMH, 2000.0 * RPM, 100.0);
        assert!(e.locked);
        assert!((e.impeller_speed - 2020.0 * RPM).abs() < 1e-9);
        assert!((e.loss - 100.0 * 20.0 * RPM).abs() < 1e-9);
        // same in 2nd: open, slips
        let e = l.engine_side(1, 60.0 * KMH, 2000.0 * RPM, 100.0);
        assert!(!e.locked && e.impeller_speed > 2000.0 * RPM && e.loss > 0.0);
        // standstill in first: engine idles, stall loss
        let e = l.engine_side(0, 0.0, 0.0, 0.0);
        assert!((e.impeller_speed - 750.0 * RPM).abs() < 1e-12);
        let tp = (750.0f64 / 144.4).powi(2);
        assert!((e.loss - tp * 750.0 * RPM).abs() < 1e-9 * e.loss);
    }
}
