//! `geartherm rating`: the thermal rating — the highest input torque whose equilibrium oil
//! temperature stays at or below a limit, at one speed (printed) or over a speed sweep (the
//! rating curve: `rating.csv`, `rating.json`, `rating.png`).

use std::path::PathBuf;

use crate::job::rating::{self, RatingOptions, RatingPoint, RatingResult, Status};
use crate::job::JobError;
use crate::report::files::OutputDir;

use super::output::{emit, emit_json, io_failure, progress_bar, warn, warnings};
use super::steady::{steady_text, values, PointArgs};
use super::Failure;

/// Arguments of `rating`.
#[derive(clap::Args, Debug)]
pub struct RatingArgs {
    #[command(flatten)]
    pub point: PointArgs,
    /// Input speed, rpm: one value, A:B:N (N speeds from A to B: the rating curve) or a list a,b,c.
    #[arg(long, allow_hyphen_values = true)]
    pub speed_rpm: String,
    /// Oil temperature limit, °C (−60 … 200).
    #[arg(long, allow_negative_numbers = true)]
    pub oil_limit_c: f64,
    /// Lowest input torque searched, N·m (0 … 1e6).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub torque_min_nm: f64,
    /// Highest input torque searched (the ceiling), N·m (default 1e6).
    #[arg(long, allow_negative_numbers = true)]
    pub torque_max_nm: Option<f64>,
    /// Output directory (written for a sweep or when given; default: ratings/<model>_gear<G>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// One JSON document (rating.json's) on stdout.
    #[arg(long)]
    pub json: bool,
    /// Skip rating.png.
    #[arg(long)]
    pub no_plots: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

impl RatingArgs {
    /// The job's options (the speeds parsed, not yet checked).
    pub fn options(&self) -> Result<RatingOptions, JobError> {
        Ok(RatingOptions {
            gear: self.point.gear.clone(),
            speed_rpm: values("speed_rpm", "--speed-rpm", &self.speed_rpm)?,
            oil_limit_c: self.oil_limit_c,
            vehicle_speed_kmh: self.point.vehicle_speed_kmh,
            ambient_c: self.point.ambient_c,
            torque_min_nm: self.torque_min_nm,
            torque_max_nm: self.torque_max_nm,
        })
    }
}

/// Run `rating`.
pub fn rating(a: &RatingArgs) -> Result<(), Failure> {
    let m = a.point.source.load()?;
    let o = a.options()?;
    let p = rating::prepare(&m, &o)?;
    let sweep = o.speed_rpm.len() > 1;
    let out = if sweep || a.out.is_some() {
        let dir = a
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from("ratings").join(format!("{}_gear{}", m.stem(), o.gear)));
        // Lock the output directory now: a second writer is refused before the work.
        Some(OutputDir::begin(&dir)?)
    } else {
        None
    };
    let bar = progress_bar(
        o.speed_rpm.len(),
        "{msg} [{bar:40}] {pos}/{len} speeds ({eta})",
        "rating".into(),
        a.quiet || !sweep,
    );
    let tick = || {
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    let result = rating::solve(&m, &o, &p, &tick);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let r = result?;
    warnings(&r.warnings);
    for pt in &r.points {
        flag_warning(&r, pt);
    }
    if let Some(out) = &out {
        for (name, bytes) in r.files()? {
            out.write(name, &bytes)?;
        }
        if !a.no_plots {
            crate::report::plots::rating::render(out.path(), &r.curve())
                .map_err(|e| io_failure(format!("plot: {e}")))?;
        }
    }
    let mut text = if a.json {
        String::new()
    } else if sweep {
        table(&r)
    } else {
        r.points.first().map_or_else(String::new, |p| point_text(&r, p))
    };
    if let Some(out) = &out {
        if !a.json {
            text.push_str(&format!("outputs in {}\n", out.target().display()));
        }
    }
    if a.json {
        emit_json(&r)?;
    } else {
        emit(&text)?;
    }
    if let Some(out) = out {
        out.commit()?;
    }
    Ok(())
}

/// The stderr line of a point that is not rated at the limit.
fn flag_warning(r: &RatingResult, p: &RatingPoint) {
    let at = format!("rating at {} rpm", p.speed_rpm);
    match p.status {
        Status::Rated => {}
        Status::Ceiling => warn(&format!(
            "warning: {at}: the oil stays below {} °C up to the torque ceiling {} N·m (equilibrium {:.2} °C): rated torque = the ceiling",
            r.oil_limit_c, r.torque_max_nm, p.oil_temp_c
        )),
        Status::LimitAtMinimum => warn(&format!(
            "warning: {at}: the speed alone heats the oil above {} °C (equilibrium {:.2} °C at {} N·m): rated torque = the lowest torque",
            r.oil_limit_c, p.oil_temp_c, r.torque_min_nm
        )),
    }
    if p.non_monotonic {
        warn(&format!(
            "warning: {at}: the equilibrium oil temperature fell with rising torque during the search: a higher torque may also meet the limit"
        ));
    }
}

fn point_text(r: &RatingResult, p: &RatingPoint) -> String {
    let mut t = format!(
        "{} gear {} at {} rpm, oil limit {} °C: rated input torque {:.3} N·m ({:.3} kW) [{}], equilibrium oil {:.4} °C, \
         {} equilibria\n",
        r.model,
        r.gear,
        p.speed_rpm,
        r.oil_limit_c,
        p.rated_torque_nm,
        p.rated_power_w / 1e3,
        p.flags(),
        p.oil_temp_c,
        p.equilibria
    );
    t.push_str(&steady_text(&p.equilibrium));
    t
}

fn table(r: &RatingResult) -> String {
    let mut t = format!(
        "{} gear {}, oil limit {} °C: thermal rating over {} speeds in {:.2} s\n{:>10} {:>14} {:>12} {:>10} {:>12} {:>10}  flags\n",
        r.model,
        r.gear,
        r.oil_limit_c,
        r.points.len(),
        r.wall_time_s,
        "rpm",
        "torque N·m",
        "power kW",
        "oil °C",
        "loss W",
        "eff."
    );
    for p in &r.points {
        t.push_str(&format!(
            "{:>10} {:>14.3} {:>12.3} {:>10.3} {:>12.2} {:>10}  {}\n",
            p.speed_rpm,
            p.rated_torque_nm,
            p.rated_power_w / 1e3,
            p.oil_temp_c,
            p.total_loss_w,
            p.efficiency.map_or("n/a".into(), |e| format!("{e:.5}")),
            p.flags()
        ));
    }
    t
}
