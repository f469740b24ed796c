//! `geartherm steady` (one equilibrium) and `geartherm map` (equilibria over a speed × torque
//! grid, in parallel with warm starts).

use std::path::PathBuf;

use crate::job::map::{self, axis, MapOptions};
use crate::job::steady::{self, SteadyOptions, SteadyResult};
use crate::job::JobError;
use crate::report::files::OutputDir;

use super::output::{emit, emit_json, io_failure, progress_bar, warnings};
use super::{Failure, ModelSource};

/// Operating-point arguments shared by `steady` and `map`.
#[derive(clap::Args, Debug)]
pub struct PointArgs {
    #[command(flatten)]
    pub source: ModelSource,
    /// Gear state name.
    #[arg(long)]
    pub gear: String,
    /// Ambient temperature, °C (−60 … 150; default: the model's ambient boundary).
    #[arg(long, allow_negative_numbers = true)]
    pub ambient_c: Option<f64>,
    /// Vehicle speed for h(v) links, km/h (0 … 400).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub vehicle_speed_kmh: f64,
}

/// Arguments of `steady`.
#[derive(clap::Args, Debug)]
pub struct SteadyArgs {
    #[command(flatten)]
    pub point: PointArgs,
    /// Input speed, rpm (0 … 50 000).
    #[arg(long, allow_negative_numbers = true)]
    pub speed_rpm: f64,
    /// Input torque, N·m (−1e6 … 1e6; negative: overrun).
    #[arg(long, allow_negative_numbers = true)]
    pub torque_nm: f64,
    /// One JSON document on stdout.
    #[arg(long)]
    pub json: bool,
}

impl SteadyArgs {
    /// The job's options.
    pub fn options(&self) -> SteadyOptions {
        SteadyOptions {
            gear: self.point.gear.clone(),
            speed_rpm: self.speed_rpm,
            torque_nm: self.torque_nm,
            vehicle_speed_kmh: self.point.vehicle_speed_kmh,
            ambient_c: self.point.ambient_c,
        }
    }
}

/// Arguments of `map`.
#[derive(clap::Args, Debug)]
pub struct MapArgs {
    #[command(flatten)]
    pub point: PointArgs,
    /// Speeds, rpm: A:B:N (N points from A to B) or a list a,b,c.
    #[arg(long, allow_hyphen_values = true)]
    pub speed_rpm: String,
    /// Torques, N·m: A:B:N or a list a,b,c.
    #[arg(long, allow_hyphen_values = true)]
    pub torque_nm: String,
    /// Output directory (default: maps/<model>_gear<G>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Skip the PNG heat maps.
    #[arg(long)]
    pub no_plots: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// A grid axis as written on the command line: `A:B:N` or a comma-separated list.
pub(super) fn values(name: &str, flag: &str, s: &str) -> Result<Vec<f64>, JobError> {
    if s.contains(':') {
        return axis(name, flag, s);
    }
    s.split(',')
        .map(|x| {
            x.trim().parse::<f64>().map_err(|_| {
                JobError::option(
                    name,
                    s,
                    "A:B:N or a list of numbers",
                    format!("{name} ({flag}) = {s}: expected A:B:N or a list a,b,c of numbers"),
                )
            })
        })
        .collect()
}

impl MapArgs {
    /// The job's options (the axes parsed, not yet checked).
    pub fn options(&self) -> Result<MapOptions, JobError> {
        Ok(MapOptions {
            gear: self.point.gear.clone(),
            speed_rpm: values("speed_rpm", "--speed-rpm", &self.speed_rpm)?,
            torque_nm: values("torque_nm", "--torque-nm", &self.torque_nm)?,
            vehicle_speed_kmh: self.point.vehicle_speed_kmh,
            ambient_c: self.point.ambient_c,
        })
    }
}

/// Run `steady`.
pub fn steady(a: &SteadyArgs) -> Result<(), Failure> {
    let m = a.point.source.load()?;
    let r = steady::steady(&m, &a.options())?;
    warnings(&r.warnings);
    super::output::spread_warnings(r.spread.as_ref());
    if a.json {
        emit_json(&r)
    } else {
        emit(&steady_text(&r))
    }
}

pub(super) fn steady_text(r: &SteadyResult) -> String {
    let mut t = match &r.limit_cycle {
        None => format!(
            "{} gear {} at {} rpm, {} N·m: equilibrium after {} Newton + {} PTC iterations ({}), residual {:.1e} W\n",
            r.model, r.gear, r.speed_rpm, r.torque_nm, r.iterations, r.ptc_iterations, r.method, r.residual_w
        ),
        Some(c) => format!(
            "{} gear {} at {} rpm, {} N·m: no equilibrium, controller {} cycles with a period of {:.3} s\n",
            r.model, r.gear, r.speed_rpm, r.torque_nm, c.controller, c.period_s
        ),
    };
    match &r.limit_cycle {
        None => {
            t.push_str("temperatures, °C\n");
            for (n, v) in &r.temperatures_c {
                t.push_str(&format!("  {n:<20} {v:>9.3}\n"));
            }
        }
        Some(c) => {
            t.push_str("temperatures over the cycle, °C: mean, min, max\n");
            for (n, v) in &c.mean_c {
                let (lo, hi) = (c.min_c[n], c.max_c[n]);
                t.push_str(&format!("  {n:<20} {v:>9.3} {lo:>9.3} {hi:>9.3}\n"));
            }
            t.push_str("losses at the mean temperatures, W\n");
        }
    }
    if r.limit_cycle.is_none() {
        t.push_str("losses, W\n");
    }
    for (n, q) in &r.losses_w {
        t.push_str(&format!("  {n:<44} {q:>10.3}\n"));
    }
    t.push_str(&format!(
        "  {}, total {:.2} W; efficiency {}\n",
        r.by_source_w.text(1.0, "W", 2),
        r.total_loss_w,
        r.efficiency.map_or("n/a".into(), |e| format!("{e:.5}"))
    ));
    if let Some(s) = &r.spread {
        t.push_str(&s.to_text());
    }
    t
}

/// Run `map`.
pub fn map(a: &MapArgs) -> Result<(), Failure> {
    let m = a.point.source.load()?;
    let o = a.options()?;
    let p = map::prepare(&m, &o)?;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("maps").join(format!("{}_gear{}", m.stem(), o.gear)));
    // Lock the output directory now: a second writer is refused before the work, not after.
    let out = OutputDir::begin(&dir)?;
    let n = o.speed_rpm.len() * o.torque_nm.len();
    let bar = progress_bar(
        n,
        "{msg} [{bar:40}] {pos}/{len} points ({eta})",
        "equilibria".into(),
        a.quiet,
    );
    let tick = || {
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    let result = map::solve(&m, &o, &p, &tick);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let r = result?;
    warnings(&r.meta.warnings);
    for (name, bytes) in r.files()? {
        out.write(name, &bytes)?;
    }
    if !a.no_plots {
        crate::report::plots::render_map(out.path(), &r.rows, &r.meta)
            .map_err(|e| io_failure(format!("plot: {e}")))?;
    }
    emit(&format!(
        "{n} points ({} converged, {:.1} iterations on average) in {:.3} s on {} threads; outputs in {}\n",
        r.meta.converged,
        r.meta.mean_iterations,
        r.meta.wall_time_s,
        r.meta.threads,
        out.target().display()
    ))?;
    out.commit()?;
    Ok(())
}
