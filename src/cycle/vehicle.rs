//! The vehicle in SI units and its longitudinal dynamics: road load, mean traction force and
//! power over an interval with linear speed. The model layer reads the model file's `[vehicle]`
//! section and checks it into a [`Vehicle`] (`crate::model::sections::vehicle`).
//!
//! Physics (physics.md §9) \[std\]: wheel force F_w = m_eff·a + F_road(v), with
//! m_eff = m·(1 + rotating_mass_factor) and F_road = F0 + F1·v + F2·v² (coast-down form), or
//! F_road = m·g·c_rr·cos θ + ½·ρ_air·c_d·A·v² (physical form), plus m·g·sin θ on a grade θ.
//! Wheel torque T_w = r_w·F_w, gearbox output torque T_out = T_w / i_final.

/// Standard gravity, m/s².
pub const G: f64 = 9.806_65;

/// What the gearbox transmits when the wheels demand negative torque (braking / coasting).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Overrun {
    /// The service brakes take all negative demand; the gearbox transmits zero torque (it still
    /// spins with the wheels, so drag losses remain). Default.
    #[default]
    Zero,
    /// The negative torque passes through the gearbox (engine braking / recuperation).
    Transmit,
}

/// Road load in coast-down form (grade folded into `f0`): F = f0 + f1·v + f2·v².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoadLoad {
    /// N.
    pub f0: f64,
    /// N/(m/s).
    pub f1: f64,
    /// N/(m/s)².
    pub f2: f64,
}

impl RoadLoad {
    /// Force at speed `v` (m/s), N.
    pub fn force(&self, v: f64) -> f64 {
        self.f0 + self.f1 * v + self.f2 * v * v
    }
}

/// Checked shift strategy (SI). Gear names are bound to gear-table indices at schedule time.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftStrategy {
    /// Forward gear-state names, launch gear first.
    pub gears: Vec<String>,
    /// Upshift input speeds, rad/s (n−1).
    pub upshift: Vec<f64>,
    /// Downshift input speeds, rad/s (n−1).
    pub downshift: Vec<f64>,
    /// Minimum hold time, s.
    pub min_hold: f64,
}

/// A checked vehicle, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    /// Mass, kg.
    pub mass: f64,
    /// Effective (translational + rotating) mass, kg.
    pub effective_mass: f64,
    /// Wheel radius, m.
    pub wheel_radius: f64,
    /// Final drive ratio (−).
    pub final_drive_ratio: f64,
    /// Road load incl. grade.
    pub road_load: RoadLoad,
    /// Overrun policy.
    pub overrun: Overrun,
    /// Standstill threshold, m/s.
    pub standstill_speed: f64,
    /// Shift strategy, if configured.
    pub shift: Option<ShiftStrategy>,
}

/// Mean traction demand over an interval with linear speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Demand {
    /// Mean speed (v0+v1)/2, m/s.
    pub mean_speed: f64,
    /// Acceleration, m/s².
    pub acceleration: f64,
    /// Mean wheel force, N.
    pub mean_force: f64,
    /// Mean wheel (= loss-free gearbox output) power, W.
    pub mean_power: f64,
}

impl Vehicle {
    /// Mean demand over [t0, t0+dt] with the speed linear from `v0` to `v1` (m/s) \[derived\]:
    /// a = (v1−v0)/dt; mean(v) = (v0+v1)/2; mean(v²) = (v0²+v0·v1+v1²)/3;
    /// mean(v³) = (v0+v1)(v0²+v1²)/4 (exact integrals of the powers of a linear function).
    /// mean force = m_eff·a + f0 + f1·mean(v) + f2·mean(v²);
    /// mean power = m_eff·a·mean(v) + f0·mean(v) + f1·mean(v²) + f2·mean(v³),
    /// so that Σ mean_power·dt is the exact traction energy of the piecewise-linear trace.
    /// Precondition: dt > 0.
    pub fn demand(&self, v0: f64, v1: f64, dt: f64) -> Demand {
        let a = (v1 - v0) / dt;
        let m1 = 0.5 * (v0 + v1);
        let m2 = (v0 * v0 + v0 * v1 + v1 * v1) / 3.0;
        let m3 = 0.25 * (v0 + v1) * (v0 * v0 + v1 * v1);
        let RoadLoad { f0, f1, f2 } = self.road_load;
        let me = self.effective_mass;
        Demand {
            mean_speed: m1,
            acceleration: a,
            mean_force: me * a + f0 + f1 * m1 + f2 * m2,
            mean_power: me * a * m1 + f0 * m1 + f1 * m2 + f2 * m3,
        }
    }

    /// Gearbox output speed at vehicle speed `v` (m/s), rad/s: v·i_final/r_w.
    pub fn output_speed(&self, v: f64) -> f64 {
        v * self.final_drive_ratio / self.wheel_radius
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::cycle::parse::{KMH, RPM};
    use crate::cycle::GearTable;
    use approx::assert_relative_eq;

    /// The 6-speed AT sedan of the docs (ZF 6HP26 ratios).
    pub(crate) fn at6_gears() -> GearTable {
        GearTable::new(
            [
                ("1", 4.171),
                ("2", 2.340),
                ("3", 1.521),
                ("4", 1.143),
                ("5", 0.867),
                ("6", 0.691),
                ("R", -3.403),
            ]
            .iter()
            .map(|(n, r)| (n.to_string(), *r))
            .collect(),
        )
    }

    /// The 6-speed AT sedan of docs/model-file.md as checked from its `[vehicle]` section
    /// (1900 kg, rotating-mass factor 0.05, r_w 0.33 m, i_final 3.2, coast-down 160 N,
    /// 1.2 N/(m/s), 0.42 N/(m/s)², economy shift points); the model layer's tests check that
    /// its section gives exactly this.
    pub(crate) fn at6() -> Vehicle {
        let rpm = |v: [f64; 5]| v.iter().map(|x| x * RPM).collect();
        Vehicle {
            mass: 1900.0,
            effective_mass: 1900.0 * (1.0 + 0.05),
            wheel_radius: 0.33,
            final_drive_ratio: 3.2,
            road_load: RoadLoad {
                f0: 160.0,
                f1: 1.2,
                f2: 0.42,
            },
            overrun: Overrun::Zero,
            standstill_speed: 0.1 * KMH,
            shift: Some(ShiftStrategy {
                gears: ["1", "2", "3", "4", "5", "6"].map(String::from).to_vec(),
                upshift: rpm([2200.0, 2100.0, 2000.0, 1900.0, 1800.0]),
                downshift: rpm([1100.0, 1150.0, 1200.0, 1250.0, 1300.0]),
                min_hold: 2.0,
            }),
        }
    }

    #[test]
    fn demand_means_match_quadrature() {
        let v = at6();
        let (v0, v1, dt) = (3.0, 7.5, 1.0);
        let d = v.demand(v0, v1, dt);
        // midpoint rule with many points
        let n = 20_000;
        let (mut f, mut pw) = (0.0, 0.0);
        for k in 0..n {
            let s = (k as f64 + 0.5) / n as f64;
            let vs = v0 + (v1 - v0) * s;
            let force = v.effective_mass * (v1 - v0) / dt + v.road_load.force(vs);
            f += force / n as f64;
            pw += force * vs / n as f64;
        }
        assert_relative_eq!(d.mean_force, f, max_relative = 1e-8);
        assert_relative_eq!(d.mean_power, pw, max_relative = 1e-8);
        assert_relative_eq!(d.mean_speed, 5.25);
        // power-consistent force vs mean force (documented difference)
        let dv = v1 - v0;
        let diff = d.mean_power / d.mean_speed - d.mean_force;
        let want = v.road_load.f1 * dv * dv / (12.0 * d.mean_speed) + v.road_load.f2 * dv * dv / 6.0;
        assert_relative_eq!(diff, want, max_relative = 1e-9);
    }
}
