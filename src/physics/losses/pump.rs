//! The transmission's oil pump: a fixed-displacement pump delivering the line pressure.
//!
//! Model \[std, positive-displacement pump relations as in the pump makers' data sheets and
//! e.g. MathWorks Simscape "Fixed-Displacement Pump": ideal flow V·n, drive torque V·Δp/(2π)
//! divided by the hydraulic-mechanical efficiency]:
//! - delivered flow `Q = η_v · V · ω/(2π)` (V displacement per revolution);
//! - drive torque `T = V · Δp / (2π · η_hm)`, drive power `P = T·ω`;
//! - Δp is the line pressure, a table over the gearbox input torque (the pressure control raises
//!   the line pressure with the torque the clutches must hold).
//!
//! Where the power goes: all of the drive power ends as heat in the ATF — the pump's own
//! mechanical and leakage losses, and the hydraulic power Q·Δp, throttled in the pressure
//! regulator, the valve body, the lubrication and cooler circuit. So the loss item is `P`.
//!
//! Units: SI (m³ per revolution, Pa, rad/s, N·m, W, m³/s).

use super::curve::Curve;
use std::f64::consts::PI;

/// A fixed-displacement pump with its line-pressure schedule.
#[derive(Debug, Clone, PartialEq)]
pub struct Pump {
    /// Displacement per revolution, m³.
    pub displacement: f64,
    /// Line pressure (Pa, gauge) over the gearbox input torque (N·m).
    pub line_pressure: Curve,
    /// Volumetric efficiency η_v (0..1].
    pub volumetric_efficiency: f64,
    /// Hydraulic-mechanical efficiency η_hm (0..1].
    pub mechanical_efficiency: f64,
}

/// Pump operating point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PumpPoint {
    /// Line pressure, Pa.
    pub pressure: f64,
    /// Delivered flow, m³/s.
    pub flow: f64,
    /// Drive torque, N·m.
    pub torque: f64,
    /// Drive power = heat into the ATF, W.
    pub power: f64,
}

impl Pump {
    /// Operating point at pump speed `speed` (rad/s, magnitude used) and gearbox input torque
    /// `input_torque` (N·m). No allocation.
    pub fn point(&self, speed: f64, input_torque: f64) -> PumpPoint {
        let w = speed.abs();
        let dp = self.line_pressure.at(input_torque);
        let torque = self.displacement * dp / (2.0 * PI * self.mechanical_efficiency);
        PumpPoint {
            pressure: dp,
            flow: self.volumetric_efficiency * self.displacement * w / (2.0 * PI),
            torque,
            power: torque * w,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    use crate::physics::units::RAD_S_PER_RPM;
    const CC: f64 = 1e-6;
    const BAR: f64 = 1e5;

    fn pump(v_cc: f64, bar: f64, ev: f64, ehm: f64) -> Pump {
        Pump {
            displacement: v_cc * CC,
            line_pressure: Curve::new(vec![0.0], vec![bar * BAR]).unwrap(),
            volumetric_efficiency: ev,
            mechanical_efficiency: ehm,
        }
    }

    #[test]
    fn reproduces_the_published_flow_example() {
        // hydraulic-calculator (npm, README "pumpFlow"): 20 cc/rev at 1500 rpm with efficiency
        // 0.95 → 28.5 L/min.
        let p = pump(20.0, 10.0, 0.95, 1.0).point(1500.0 * RAD_S_PER_RPM, 0.0);
        assert_relative_eq!(p.flow * 60_000.0, 28.5, max_relative = 1e-12);
    }

    #[test]
    fn drive_torque_and_power_by_the_data_sheet_formula() {
        // Data-sheet form T[N·m] = V[cm³]·Δp[bar]/(20·π·η_hm): 16 cm³, 15 bar, η_hm 0.85.
        let p = pump(16.0, 15.0, 0.9, 0.85).point(2000.0 * RAD_S_PER_RPM, 0.0);
        assert_relative_eq!(p.torque, 16.0 * 15.0 / (20.0 * PI * 0.85), max_relative = 1e-12);
        // P[kW] = T·n/9549
        assert_relative_eq!(
            p.power / 1e3,
            p.torque * 2000.0 / 9_549.296_585_513_72,
            max_relative = 1e-9
        );
    }

    #[test]
    fn units_and_scaling() {
        let base = pump(16.0, 10.0, 0.9, 0.8);
        let a = base.point(1000.0 * RAD_S_PER_RPM, 50.0);
        // power ∝ speed, ∝ pressure, ∝ displacement, ∝ 1/η_hm; flow ∝ η_v·speed
        assert_relative_eq!(
            base.point(2000.0 * RAD_S_PER_RPM, 50.0).power,
            2.0 * a.power,
            max_relative = 1e-12
        );
        assert_relative_eq!(
            pump(16.0, 20.0, 0.9, 0.8)
                .point(1000.0 * RAD_S_PER_RPM, 50.0)
                .power,
            2.0 * a.power,
            max_relative = 1e-12
        );
        assert_relative_eq!(
            pump(32.0, 10.0, 0.9, 0.8)
                .point(1000.0 * RAD_S_PER_RPM, 50.0)
                .power,
            2.0 * a.power,
            max_relative = 1e-12
        );
        assert_relative_eq!(
            pump(16.0, 10.0, 0.9, 0.4)
                .point(1000.0 * RAD_S_PER_RPM, 50.0)
                .power,
            2.0 * a.power,
            max_relative = 1e-12
        );
        assert_relative_eq!(
            pump(16.0, 10.0, 0.45, 0.8)
                .point(1000.0 * RAD_S_PER_RPM, 50.0)
                .flow,
            0.5 * a.flow,
            max_relative = 1e-12
        );
        assert_eq!(base.point(0.0, 50.0).power, 0.0);
        assert_eq!(base.point(-1000.0 * RAD_S_PER_RPM, 50.0), a);
        // the line pressure follows the torque table
        let mut p = base.clone();
        p.line_pressure = Curve::new(vec![0.0, 400.0], vec![5.0 * BAR, 17.0 * BAR]).unwrap();
        assert_relative_eq!(p.point(1.0, 200.0).pressure, 11.0 * BAR, max_relative = 1e-12);
        assert_relative_eq!(p.point(1.0, -50.0).pressure, 5.0 * BAR, max_relative = 1e-12);
    }
}
