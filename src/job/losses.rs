//! `losses`: every loss item at one operating point and oil temperature, with the checks of its
//! inputs and of its numbers.

use serde::{Deserialize, Serialize};

use crate::report::losses::{losses as report, LossReport};
use crate::scene::{LossScene, OperatingPoint};

use super::envelope::OilRange;
use super::limits::{self, short};
use super::{JobError, Model};
use crate::physics::units::{c_to_k, rpm_to_rad_s};

/// Options of a loss evaluation (`geartherm losses`, `Model.losses`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LossesOptions {
    /// Gear-state name.
    pub gear: String,
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m (drive).
    pub torque_nm: f64,
    /// Oil temperature, °C.
    pub oil_temp_c: f64,
}

impl LossesOptions {
    /// Every range check of the options but the gear, which needs the model.
    pub fn check(&self) -> Result<(), JobError> {
        limits::SPEED_RPM.check(self.speed_rpm)?;
        limits::DRIVE_TORQUE_NM.check(self.torque_nm)?;
        limits::OIL_TEMP_C.check(self.oil_temp_c)?;
        Ok(())
    }
}

/// Evaluate every loss item at `o`; a non-finite item is a numerical failure naming it.
pub fn losses(m: &Model, o: &LossesOptions) -> Result<LossReport, JobError> {
    let state = m.state(&o.gear)?;
    o.check()?;
    OilRange::of(&m.gearbox.oil).check_option(&limits::OIL_TEMP_C, o.oil_temp_c)?;
    let scene =
        LossScene::compile(&m.gearbox).map_err(|e| JobError::invalid(format!("{}: {e}", m.label())))?;
    let op = OperatingPoint {
        state,
        input_speed: rpm_to_rad_s(o.speed_rpm),
        input_torque: o.torque_nm,
        oil: m.gearbox.oil.properties(c_to_k(o.oil_temp_c)),
    };
    if !(op.oil.nu.is_finite() && op.oil.nu > 0.0 && op.oil.rho.is_finite() && op.oil.rho > 0.0) {
        return Err(JobError::option(
            "oil_temp_c",
            short(o.oil_temp_c),
            "a temperature where the oil has a finite viscosity",
            format!(
                "oil_temp_c = {}: the oil of {} has no finite viscosity there (ν = {} m²/s)",
                short(o.oil_temp_c),
                m.label(),
                op.oil.nu
            ),
        ));
    }
    let mut r = report(&m.gearbox, &scene, &op, o.oil_temp_c);
    let bad = r
        .items
        .iter()
        .find(|it| !it.w.is_finite())
        .map(|it| format!("loss item {}:{}", it.source.as_str(), it.name))
        .or_else(|| (!r.total_w.is_finite()).then(|| "total loss".to_string()));
    if let Some(what) = bad {
        return Err(JobError::numerical(format!(
            "{}: {what} is not finite at gear {}, {} rpm, {} N m, {} °C",
            m.label(),
            o.gear,
            short(o.speed_rpm),
            short(o.torque_nm),
            short(o.oil_temp_c)
        )));
    }
    let out: Vec<f64> = r.items.iter().map(|it| it.w).collect();
    r.spread = Some(super::spread::at_point(
        &m.gearbox,
        &crate::scene::Needs::default(),
        &scene,
        &out,
        &op,
    ));
    Ok(r)
}
