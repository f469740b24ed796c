//! `geartherm uq MODEL.toml --cycle C | --gear G --speed-rpm N --torque-nm T [options]`:
//! converts the arguments into the uncertainty study's options, runs its cases with the study
//! runner under a progress bar (journal, resume, shards, Ctrl-C as `geartherm study`), writes
//! the outputs and prints the exceedance probabilities and the largest Sobol indices.

use std::path::PathBuf;

use crate::job::{RunOptions, SteadyOptions};
use crate::study::uq::output::{compact, UqOutcome};
use crate::study::uq::run::{read_calibration, Limit, Uq, UqJob, UqOptions, DEFAULT_SERIES_POINTS};
use crate::study::Selection;

use super::output::{emit, warn, Failure};
use super::study::solve_journaled;

/// Arguments of `uq`.
#[derive(clap::Args, Debug)]
pub struct UqArgs {
    /// Model file (TOML) with its `[uncertainty]` inputs, or a study file with `[uncertainty]`
    /// (its model, first job and sampling are used where no option is given).
    pub model: PathBuf,
    /// Drive cycle (bundled name or CSV file); without --gear, `wltc`.
    #[arg(long, conflicts_with = "gear")]
    pub cycle: Option<String>,
    /// A steady operating point instead of a cycle: gear state.
    #[arg(long, requires_all = ["speed_rpm", "torque_nm"])]
    pub gear: Option<String>,
    /// Steady point: input speed, rpm.
    #[arg(long, allow_negative_numbers = true)]
    pub speed_rpm: Option<f64>,
    /// Steady point: input torque, N·m.
    #[arg(long, allow_negative_numbers = true)]
    pub torque_nm: Option<f64>,
    /// Steady point: vehicle speed for h(v) links, km/h.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub vehicle_speed_kmh: f64,
    /// Relative tolerance of the cycle's integration (with --cycle).
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Samples N (with --sobol: base points, N(d + 2) runs).
    /// [default: 1000, or a study file's sampling.cases]
    #[arg(long)]
    pub samples: Option<usize>,
    /// Seed of the scrambled Sobol' points and of the bootstrap [default: 1, or a study file's].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Saltelli's design: first-order and total Sobol indices of every input.
    #[arg(long)]
    pub sobol: bool,
    /// Percentiles of the bands, %, comma-separated.
    #[arg(
        long,
        default_value = "5,50,95",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub percentiles: Vec<f64>,
    /// A limit NODE=T (°C): probability that the node's highest temperature over the cycle
    /// exceeds T, with its interval (repeatable).
    #[arg(long = "limit", value_name = "NODE=T", value_parser = parse_limit)]
    pub limits: Vec<Limit>,
    /// Sample a calibration's fitted parameters from their covariance (calibrated.toml, whose
    /// `# [calibration]` block `geartherm calibrate` writes, or a file with a [calibration] table).
    #[arg(long, value_name = "FILE")]
    pub from_calibration: Option<PathBuf>,
    /// Grid points of the band time series over the cycle.
    #[arg(long, default_value_t = DEFAULT_SERIES_POINTS)]
    pub series_points: usize,
    /// Bootstrap resamples of the Sobol indices' intervals.
    #[arg(long, default_value_t = 200)]
    pub bootstrap: usize,
    /// Confidence level of the intervals.
    #[arg(long, default_value_t = 0.95)]
    pub confidence: f64,
    /// Output directory (journal, uq.json, bands.csv, bands.parquet, study.csv, study.parquet).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run only shard I of N (a later run without --shard merges the journals).
    #[arg(long, value_name = "I/N", allow_hyphen_values = true)]
    pub shard: Option<String>,
    /// Figures: bands.png and (with --sobol) sensitivity.png.
    #[arg(long)]
    pub report: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

fn parse_limit(s: &str) -> Result<Limit, String> {
    let (node, t) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected NODE=T (°C)"))?;
    let temp_c: f64 = t
        .trim()
        .parse()
        .map_err(|_| format!("`{s}`: T = `{t}` is not a number"))?;
    Ok(Limit {
        node: node.trim().to_string(),
        temp_c,
    })
}

impl UqArgs {
    /// The use case's options (the calibration file is read by the use-case layer).
    fn options(&self) -> Result<UqOptions, Failure> {
        let job = match (&self.gear, &self.cycle) {
            (Some(g), _) => Some(UqJob::Steady(SteadyOptions {
                gear: g.clone(),
                speed_rpm: self.speed_rpm.unwrap_or_default(),
                torque_nm: self.torque_nm.unwrap_or_default(),
                vehicle_speed_kmh: self.vehicle_speed_kmh,
                ambient_c: None,
            })),
            (None, Some(c)) => Some(UqJob::Run(RunOptions {
                cycle: c.clone(),
                rtol: self.rtol.unwrap_or(crate::job::run::DEFAULT_RTOL),
                summary_only: true,
                ..RunOptions::default()
            })),
            (None, None) => None,
        };
        let calibration = match &self.from_calibration {
            Some(f) => Some(read_calibration(f)?),
            None => None,
        };
        Ok(UqOptions {
            job,
            samples: self.samples,
            seed: self.seed,
            sobol: self.sobol,
            percentiles: self.percentiles.clone(),
            limits: self.limits.clone(),
            series_points: self.series_points,
            confidence: self.confidence,
            bootstrap: self.bootstrap,
            inputs: None,
            calibration,
        })
    }
}

fn print(o: &UqOutcome, dir: &std::path::Path) -> Result<(), Failure> {
    let mut s = String::new();
    for e in &o.summary.exceedance {
        s.push_str(&format!(
            "P({} {} > {} °C) = {:.4}  [{:.4}, {:.4}] ({:.0} % {}; {} of {})\n",
            e.quantity,
            e.node,
            e.limit_c,
            e.probability,
            e.lo,
            e.hi,
            e.confidence * 100.0,
            e.interval,
            e.count,
            e.n
        ));
    }
    for x in &o.summary.scalars {
        let p: Vec<String> = x.p.iter().map(|(p, v)| format!("p{p} {v:.4}")).collect();
        s.push_str(&format!("{}: mean {:.4}, {}\n", x.name, x.mean, p.join(", ")));
    }
    for r in &o.summary.sobol {
        s.push_str(&format!(
            "Sobol {} ← {}: S1 {:.3} [{:.3}, {:.3}], ST {:.3} [{:.3}, {:.3}]\n",
            r.output, r.input, r.first, r.first_lo, r.first_hi, r.total, r.total_lo, r.total_hi
        ));
    }
    for n in o
        .summary
        .notes
        .iter()
        .filter(|n| n.starts_with("Sobol indices not") || n.contains("left out"))
    {
        warn(n);
    }
    s.push_str(&format!("{}: {}\n", dir.display(), o.files.join(", ")));
    emit(&s)
}

/// Run `uq`.
pub fn uq(a: &UqArgs) -> Result<(), Failure> {
    let uq = Uq::from_file(&a.model, a.options()?)?;
    let selection = Selection::parse(None, a.shard.as_deref())?;
    let cases = uq.study.select(&selection)?;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("uq").join(&uq.study.spec.study.name));
    solve_journaled(&uq.study, &selection, cases.len(), &dir, a.quiet, "samples")?;
    if let Some((i, n)) = selection.journal_shard() {
        return emit(&format!(
            "shard {i}/{n} done; run the same command without --shard once every shard finished to merge them\n"
        ));
    }
    let o = compact(&uq, &dir, a.report)?;
    print(&o, &dir)
}
