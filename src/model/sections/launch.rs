//! `[launch]` and `[launch.lockup]`: the torque converter between the engine and the gearbox
//! input as written, and its checks into a [`LaunchDevice`] (SI), the form the cycle layer turns
//! the gearbox input demand into the engine side with ([`crate::cycle::launch`]).

use serde::{Deserialize, Serialize};

use crate::cycle::parse::{KMH, RPM};
use crate::cycle::{GearTable, LaunchDevice};
use crate::model::choice::choice;
use crate::model::problems::Problems;
use crate::physics::losses::converter::{Converter, ConverterError};

/// Kind of launch device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LaunchKind {
    /// Hydrodynamic torque converter (with optional lock-up clutch).
    TorqueConverter,
}
choice!(LaunchKind {
    TorqueConverter = "torque_converter",
});

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

/// `[launch]` as written.
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

/// Check every value of `[launch]` against the gear table and build the device, or record
/// every problem.
pub fn validate_launch(spec: &LaunchSpec, gears: &GearTable, p: &mut Problems) -> Option<LaunchDevice> {
    let start = p.len();
    p.in_range(
        "launch.idle_speed_rpm",
        spec.idle_speed_rpm,
        300.0,
        3000.0,
        " rpm",
    );
    let converter = characteristic(spec, p);
    if let Err(e) = &converter {
        // Reported only when no other launch value was: a bad value also breaks the table.
        if p.len() == start {
            p.push(
                "launch.speed_ratio",
                format!("{:?}", spec.speed_ratio),
                e.to_string(),
            );
        }
    }
    let (lockup_above, slip) = match &spec.lockup {
        Some(l) => lockup(l, gears, p),
        None => (vec![f64::INFINITY; gears.states.len()], 0.0),
    };
    if p.len() > start {
        return None;
    }
    Some(LaunchDevice {
        converter: converter.ok()?,
        idle_speed: spec.idle_speed_rpm * RPM,
        lockup_above,
        lockup_slip: slip,
    })
}

/// The converter characteristic: K factor and torque ratio per speed ratio.
fn characteristic(spec: &LaunchSpec, p: &mut Problems) -> Result<Converter, ConverterError> {
    let n = spec.speed_ratio.len();
    for (key, len) in [
        ("k_factor_rpm_per_sqrt_nm", spec.k_factor_rpm_per_sqrt_nm.len()),
        ("torque_ratio", spec.torque_ratio.len()),
    ] {
        if len != n {
            p.push(
                format!("launch.{key}"),
                format!("{len} values"),
                format!("needs one value per speed ratio ({n})"),
            );
        }
    }
    for (k, &v) in spec.k_factor_rpm_per_sqrt_nm.iter().enumerate() {
        p.in_range(
            &format!("launch.k_factor_rpm_per_sqrt_nm[{k}]"),
            v,
            10.0,
            1000.0,
            " rpm/sqrt(N m)",
        );
    }
    for (k, &v) in spec.torque_ratio.iter().enumerate() {
        p.in_range(&format!("launch.torque_ratio[{k}]"), v, 0.5, 5.0, "");
    }
    Converter::new(
        spec.speed_ratio.clone(),
        spec.k_factor_rpm_per_sqrt_nm.iter().map(|k| k * RPM).collect(),
        spec.torque_ratio.clone(),
    )
}

/// `[launch.lockup]`: per gear-table index the vehicle speed above which the clutch closes
/// (m/s; +∞ never), and the controlled slip (rad/s).
fn lockup(l: &LockupSpec, gears: &GearTable, p: &mut Problems) -> (Vec<f64>, f64) {
    let mut above = vec![f64::INFINITY; gears.states.len()];
    if l.above_kmh.len() != l.gears.len() {
        p.push(
            "launch.lockup.above_kmh",
            format!("{} values", l.above_kmh.len()),
            format!("needs one value per lock-up gear ({})", l.gears.len()),
        );
    }
    for (k, g) in l.gears.iter().enumerate() {
        let Some(i) = gears.index_of(g) else {
            p.push(
                format!("launch.lockup.gears[{k}]"),
                format!("\"{g}\""),
                format!("not a gear state of the model ({})", gears.names().join(", ")),
            );
            continue;
        };
        if let Some(&v) = l.above_kmh.get(k) {
            if p.in_range(&format!("launch.lockup.above_kmh[{k}]"), v, 0.0, 300.0, " km/h") {
                above[i] = v * KMH;
            }
        }
    }
    let slip = if p.in_range("launch.lockup.slip_rpm", l.slip_rpm, 0.0, 300.0, " rpm") {
        l.slip_rpm * RPM
    } else {
        0.0
    };
    (above, slip)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycle::launch::tests::launch;
    use crate::cycle::vehicle::tests::at6_gears;

    const LAUNCH_TOML: &str = r#"
kind = "torque_converter"
idle_speed_rpm = 750.0
speed_ratio = [0.0, 0.5, 0.8, 0.9]
k_factor_rpm_per_sqrt_nm = [144.4, 163.7, 197.3, 227.2]
torque_ratio = [2.0, 1.43, 1.10, 1.0]
lockup = { gears = ["3", "4", "5", "6"], above_kmh = [40.0, 45.0, 50.0, 55.0], slip_rpm = 20.0 }
"#;

    #[test]
    fn example_gives_the_cycle_layers_converter_exactly() {
        let s: LaunchSpec = toml::from_str(LAUNCH_TOML).unwrap();
        let mut p = Problems::default();
        assert_eq!(validate_launch(&s, &at6_gears(), &mut p), Some(launch()));
        assert!(p.is_empty());
    }

    #[test]
    fn problems_are_listed_with_paths() {
        let mut s: LaunchSpec = toml::from_str(LAUNCH_TOML).unwrap();
        s.idle_speed_rpm = 50.0;
        s.torque_ratio = vec![2.0, 1.0];
        s.lockup.as_mut().unwrap().gears[1] = "9".into();
        let mut p = Problems::default();
        assert!(validate_launch(&s, &at6_gears(), &mut p).is_none());
        let paths: Vec<&str> = p.as_slice().iter().map(|p| p.path.as_str()).collect();
        for want in [
            "launch.idle_speed_rpm",
            "launch.torque_ratio",
            "launch.lockup.gears[1]",
        ] {
            assert!(paths.contains(&want), "{want}: {paths:?}");
        }
        assert!(
            !paths.contains(&"launch.speed_ratio"),
            "a table already reported value by value is not reported whole: {paths:?}"
        );
    }
}
