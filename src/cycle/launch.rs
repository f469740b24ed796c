//! The launch device: the model file's `[launch]` section, a hydrodynamic torque converter with
//! a lock-up clutch between the engine and the gearbox input (the turbine).
//!
//! With it, the engine side follows from the vehicle demand: the cycle gives the turbine speed
//! and torque (= gearbox input), the converter characteristic gives the impeller (engine) speed
//! and torque and the slip loss (physics in [`crate::physics::losses::converter`]). Lock-up by
//! gear and vehicle speed: the clutch is closed in the listed gears above their vehicle speed,
//! when the turbine turns at least at idle speed; closed, it runs with a constant controlled slip
//! (`slip_rpm`, 0 = rigid). At standstill in gear the engine idles against the stalled turbine.
//! Without the section the gearbox input is driven directly (today's behaviour).

use serde::{Deserialize, Serialize};

use super::gears::GearTable;
use super::parse::{KMH, RPM};
use super::vehicle::VehicleProblem;
pub use crate::physics::losses::converter::ConverterPoint as EngineSide;
use crate::physics::losses::converter::{locked, Converter};

/// Kind of launch device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LaunchKind {
    /// Hydrodynamic torque converter (with optional lock-up clutch).
    TorqueConverter,
}

/// `[launch.lockup]`: where the lock-up clutch is closed.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LockupSpec {
    /// Gear states in which the clutch may close.
    pub gears: Vec<String>,
    /// Vehicle speed above which it closes, per listed gear, km/h.
    pub above_kmh: Vec<f64>,
    /// Controlled slip while closed, rpm (default 0: rigid).
    #[serde(default)]
    pub slip_rpm: f64,
}

/// The `[launch]` section as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LaunchSpec {
    /// `"torque_converter"`.
    pub kind: LaunchKind,
    /// Engine idle speed, rpm.
    pub idle_speed_rpm: f64,
    /// Speed ratios turbine/impeller of the characteristic, from 0, increasing, below 1.
    pub speed_ratio: Vec<f64>,
    /// Capacity factor K = n_impeller/√T_impeller per speed ratio, rpm/√(N·m).
    pub k_factor_rpm_per_sqrt_nm: Vec<f64>,
    /// Torque ratio T_turbine/T_impeller per speed ratio.
    pub torque_ratio: Vec<f64>,
    /// Lock-up clutch (none: always open).
    #[serde(default)]
    pub lockup: Option<LockupSpec>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

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

impl LaunchSpec {
    /// Deserialize the `[launch]` table.
    pub fn from_table(table: &toml::Table) -> Result<LaunchSpec, Vec<VehicleProblem>> {
        toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| {
                vec![VehicleProblem {
                    path: "launch".into(),
                    value: String::new(),
                    allowed: e.message().to_string(),
                }]
            })
    }

    /// Check every value against the gear table and build the device, or list every problem.
    pub fn validate(&self, gears: &GearTable) -> Result<LaunchDevice, Vec<VehicleProblem>> {
        let mut p = Vec::new();
        if !(self.idle_speed_rpm.is_finite() && (300.0..=3000.0).contains(&self.idle_speed_rpm)) {
            push(
                &mut p,
                "launch.idle_speed_rpm".into(),
                self.idle_speed_rpm.to_string(),
                "must lie in [300, 3000] rpm".into(),
            );
        }
        let n = self.speed_ratio.len();
        for (key, len) in [
            ("k_factor_rpm_per_sqrt_nm", self.k_factor_rpm_per_sqrt_nm.len()),
            ("torque_ratio", self.torque_ratio.len()),
        ] {
            if len != n {
                push(
                    &mut p,
                    format!("launch.{key}"),
                    format!("{len} values"),
                    format!("needs one value per speed ratio ({n})"),
                );
            }
        }
        for (k, &v) in self.k_factor_rpm_per_sqrt_nm.iter().enumerate() {
            if !(v.is_finite() && (10.0..=1000.0).contains(&v)) {
                push(
                    &mut p,
                    format!("launch.k_factor_rpm_per_sqrt_nm[{k}]"),
                    v.to_string(),
                    "must lie in [10, 1000] rpm/sqrt(N m)".into(),
                );
            }
        }
        for (k, &v) in self.torque_ratio.iter().enumerate() {
            if !(v.is_finite() && (0.5..=5.0).contains(&v)) {
                push(
                    &mut p,
                    format!("launch.torque_ratio[{k}]"),
                    v.to_string(),
                    "must lie in [0.5, 5]".into(),
                );
            }
        }
        let converter = Converter::new(
            self.speed_ratio.clone(),
            self.k_factor_rpm_per_sqrt_nm.iter().map(|k| k * RPM).collect(),
            self.torque_ratio.clone(),
        );
        if let Err(e) = &converter {
            if p.is_empty() {
                push(
                    &mut p,
                    "launch.speed_ratio".into(),
                    format!("{:?}", self.speed_ratio),
                    e.to_string(),
                );
            }
        }
        let mut lockup_above = vec![f64::INFINITY; gears.states.len()];
        let mut slip = 0.0;
        if let Some(l) = &self.lockup {
            if l.above_kmh.len() != l.gears.len() {
                push(
                    &mut p,
                    "launch.lockup.above_kmh".into(),
                    format!("{} values", l.above_kmh.len()),
                    format!("needs one value per lock-up gear ({})", l.gears.len()),
                );
            }
            for (k, g) in l.gears.iter().enumerate() {
                match gears.index_of(g) {
                    None => push(
                        &mut p,
                        format!("launch.lockup.gears[{k}]"),
                        format!("\"{g}\""),
                        format!("not a gear state of the model ({})", gears.names().join(", ")),
                    ),
                    Some(i) => {
                        if let Some(&v) = l.above_kmh.get(k) {
                            if v.is_finite() && (0.0..=300.0).contains(&v) {
                                lockup_above[i] = v * KMH;
                            } else {
                                push(
                                    &mut p,
                                    format!("launch.lockup.above_kmh[{k}]"),
                                    v.to_string(),
                                    "must lie in [0, 300] km/h".into(),
                                );
                            }
                        }
                    }
                }
            }
            if l.slip_rpm.is_finite() && (0.0..=300.0).contains(&l.slip_rpm) {
                slip = l.slip_rpm * RPM;
            } else {
                push(
                    &mut p,
                    "launch.lockup.slip_rpm".into(),
                    l.slip_rpm.to_string(),
                    "must lie in [0, 300] rpm".into(),
                );
            }
        }
        match converter {
            Ok(converter) if p.is_empty() => Ok(LaunchDevice {
                converter,
                idle_speed: self.idle_speed_rpm * RPM,
                lockup_above,
                lockup_slip: slip,
            }),
            _ => Err(p),
        }
    }
}

fn push(p: &mut Vec<VehicleProblem>, path: String, value: String, allowed: String) {
    p.push(VehicleProblem { path, value, allowed });
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::cycle::vehicle::tests::at6_gears;

    pub(crate) const LAUNCH_TOML: &str = r#"
kind = "torque_converter"
idle_speed_rpm = 750.0
speed_ratio = [0.0, 0.5, 0.8, 0.9]
k_factor_rpm_per_sqrt_nm = [144.4, 163.7, 197.3, 227.2]
torque_ratio = [2.0, 1.43, 1.10, 1.0]
lockup = { gears = ["3", "4", "5", "6"], above_kmh = [40.0, 45.0, 50.0, 55.0], slip_rpm = 20.0 }
"#;

    pub(crate) fn launch() -> LaunchDevice {
        let t: toml::Table = toml::from_str(LAUNCH_TOML).unwrap();
        LaunchSpec::from_table(&t)
            .unwrap()
            .validate(&at6_gears())
            .unwrap()
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

    #[test]
    fn problems_are_listed_with_paths() {
        let mut t: toml::Table = toml::from_str(LAUNCH_TOML).unwrap();
        t.insert("idle_speed_rpm".into(), toml::Value::Float(50.0));
        t.insert(
            "torque_ratio".into(),
            toml::Value::try_from(vec![2.0, 1.0]).unwrap(),
        );
        let mut s = LaunchSpec::from_table(&t).unwrap();
        s.lockup.as_mut().unwrap().gears[1] = "9".into();
        let e = s.validate(&at6_gears()).unwrap_err();
        let paths: Vec<&str> = e.iter().map(|p| p.path.as_str()).collect();
        for want in [
            "launch.idle_speed_rpm",
            "launch.torque_ratio",
            "launch.lockup.gears[1]",
        ] {
            assert!(paths.contains(&want), "{want}: {paths:?}");
        }
        t.insert("kindx".into(), toml::Value::Float(1.0));
        assert!(LaunchSpec::from_table(&t).is_err());
    }
}
