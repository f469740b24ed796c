//! `[pump]`: the transmission's fixed-displacement oil pump and what drives it.

use serde::{Deserialize, Serialize};

use crate::model::problems::Problems;
use crate::physics::losses::curve::Curve;
use crate::physics::losses::pump::Pump;

fn engine() -> String {
    "engine".into()
}

/// Line pressure over gearbox input torque.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LinePressureSpec {
    /// Input torques, N·m (increasing).
    pub torque_nm: Vec<f64>,
    /// Line pressure (gauge), bar.
    pub bar: Vec<f64>,
}

/// `[pump]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PumpSpec {
    /// Displacement, cm³ per revolution.
    pub displacement_cm3: f64,
    /// `"engine"` (the launch device's engine side; the input member without one) or a member.
    #[serde(default = "engine")]
    pub drive: String,
    /// Line pressure table.
    pub line_pressure: LinePressureSpec,
    /// Volumetric efficiency (0..1].
    pub volumetric_efficiency: f64,
    /// Hydraulic-mechanical efficiency (0..1].
    pub mechanical_efficiency: f64,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// What drives the pump.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PumpDrive {
    /// The engine side of the launch device (the input member without one).
    Engine,
    /// A member of the gear train (index).
    Member(usize),
}

/// A checked pump.
#[derive(Debug, Clone, PartialEq)]
pub struct PumpModel {
    /// The pump (SI).
    pub pump: Pump,
    /// Its drive.
    pub drive: PumpDrive,
}

/// Check `[pump]` against the member names.
pub(crate) fn validate_pump(s: &PumpSpec, members: &[&str], problems: &mut Problems) -> Option<PumpModel> {
    let before = problems.len();
    problems.in_range("pump.displacement_cm3", s.displacement_cm3, 0.1, 500.0, " cm3");
    for (key, v) in [
        ("volumetric_efficiency", s.volumetric_efficiency),
        ("mechanical_efficiency", s.mechanical_efficiency),
    ] {
        if !(v.is_finite() && v > 0.05 && v <= 1.0) {
            problems.push(format!("pump.{key}"), v, "must lie in (0.05, 1]");
        }
    }
    let drive = if s.drive == "engine" {
        Some(PumpDrive::Engine)
    } else {
        let m = members.iter().position(|m| *m == s.drive).map(PumpDrive::Member);
        if m.is_none() {
            problems.push(
                "pump.drive",
                format!("\"{}\"", s.drive),
                format!("must be \"engine\" or a member ({})", members.join(", ")),
            );
        }
        m
    };
    let lp = &s.line_pressure;
    for (k, v) in lp.bar.iter().enumerate() {
        problems.in_range(&format!("pump.line_pressure.bar[{k}]"), *v, 0.0, 100.0, " bar");
    }
    let curve = Curve::new(lp.torque_nm.clone(), lp.bar.iter().map(|b| b * 1e5).collect());
    if let Err(e) = &curve {
        problems.push(
            "pump.line_pressure.torque_nm",
            format!("{:?}", lp.torque_nm),
            e.to_string(),
        );
    }
    if problems.len() > before {
        return None;
    }
    Some(PumpModel {
        pump: Pump {
            displacement: s.displacement_cm3 * 1e-6,
            line_pressure: curve.ok()?,
            volumetric_efficiency: s.volumetric_efficiency,
            mechanical_efficiency: s.mechanical_efficiency,
        },
        drive: drive?,
    })
}
