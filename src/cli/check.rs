//! `check`, `info` and `losses`: the commands that read a model and print, writing no files.

use crate::job::{self, LossesOptions};
use crate::report::{info, losses};

use super::output::{emit, emit_json, warnings};
use super::{Failure, ModelSource};

/// Arguments of `check`.
#[derive(clap::Args, Debug)]
pub struct ModelArgs {
    #[command(flatten)]
    pub source: ModelSource,
}

/// Arguments of `info`.
#[derive(clap::Args, Debug)]
pub struct InfoArgs {
    #[command(flatten)]
    pub source: ModelSource,
    /// Print one JSON document instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `losses`.
#[derive(clap::Args, Debug)]
pub struct LossesArgs {
    #[command(flatten)]
    pub source: ModelSource,
    /// Gear state name (e.g. 3, R).
    #[arg(long)]
    pub gear: String,
    /// Input speed, rpm (0 … 50 000).
    #[arg(long, allow_negative_numbers = true)]
    pub speed_rpm: f64,
    /// Input torque, N m (0 … 1e6: drive).
    #[arg(long, allow_negative_numbers = true)]
    pub torque_nm: f64,
    /// Oil temperature, °C (within the oil's range, at most −60 … 200).
    #[arg(long, allow_negative_numbers = true)]
    pub oil_temp_c: f64,
    /// Print one JSON document instead of tables.
    #[arg(long)]
    pub json: bool,
}

impl LossesArgs {
    /// The job's options.
    pub fn options(&self) -> LossesOptions {
        LossesOptions {
            gear: self.gear.clone(),
            speed_rpm: self.speed_rpm,
            torque_nm: self.torque_nm,
            oil_temp_c: self.oil_temp_c,
        }
    }
}

/// Run `check`.
pub fn check(a: &ModelArgs) -> Result<(), Failure> {
    let m = job::Model::check_file(&a.source.model, &a.source.set)?;
    let r = m.check_report();
    emit(&format!(
        "{}: ok ({} gears, {} meshes, {} gear states)\n",
        m.label(),
        r.gears,
        r.meshes,
        r.gear_states.len()
    ))
}

/// Run `info`.
pub fn info(a: &InfoArgs) -> Result<(), Failure> {
    let m = a.source.load()?;
    let report = info::info(&m.gearbox);
    if a.json {
        emit_json(&report)
    } else {
        emit(&info::to_text(&report, &m.gearbox))
    }
}

/// Run `losses`.
pub fn losses(a: &LossesArgs) -> Result<(), Failure> {
    let m = a.source.load()?;
    let report = job::losses::losses(&m, &a.options())?;
    warnings(&report.warnings);
    super::output::spread_warnings(report.spread.as_ref());
    if a.json {
        emit_json(&report)
    } else {
        emit(&losses::to_text(&report))
    }
}
