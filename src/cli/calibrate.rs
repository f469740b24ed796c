//! `geartherm calibrate`: fit model parameters to a measured temperature trace; writes
//! `calibration.json`, `fit.csv`, `calibrated.toml`, `cycle.csv` and `calibration.png`.

use std::path::PathBuf;

use crate::job::calibrate::{self, CalibrateOptions, CalibrateResult, Missing, TraceFile};
use crate::report::calibration::to_text;
use crate::report::files::OutputDir;

use super::output::{emit, emit_json, invalid, io_failure, warn};
use super::{Failure, ModelSource};

/// Arguments of `calibrate`.
#[derive(clap::Args, Debug)]
pub struct CalibrateArgs {
    #[command(flatten)]
    pub source: ModelSource,
    /// Trace CSV: a cycle's columns (time_s and speed_kmh[,gear], or input_speed_rpm,
    /// input_torque_nm,gear), boundary:NAME and node:NAME temperature columns in °C.
    /// Repeatable: several traces are fitted together, every segment of each (trace N, 0-based,
    /// named by its file's stem).
    #[arg(long, required = true)]
    pub trace: Vec<PathBuf>,
    /// A parameter to fit, by key path, with optional bounds: KEYPATH[=LO:HI] (repeatable;
    /// positive values are fitted on a log scale). Without --fit the model is only compared.
    /// With several traces KEYPATH@TRACE[=LO:HI] is trace TRACE's own value (its 0-based index
    /// or its name; @* one value per trace); without @ the value is shared by every trace.
    #[arg(long, value_name = "KEYPATH[@TRACE][=LO:HI]")]
    pub fit: Vec<String>,
    /// A time window T0:T1 (s) whose rows are predicted, not fitted (repeatable).
    #[arg(long, value_name = "T0:T1")]
    pub holdout: Vec<String>,
    /// Output directory (default: runs/<model>_calibration).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Relative tolerance of the integrations (1e-14 … 0.1).
    #[arg(long, default_value_t = calibrate::DEFAULT_RTOL)]
    pub rtol: f64,
    /// Absolute tolerance, K (1e-14 … 1).
    #[arg(long, default_value_t = crate::job::run::DEFAULT_ATOL)]
    pub atol: f64,
    /// Step budget of one integration.
    #[arg(long, default_value_t = crate::job::run::DEFAULT_MAX_STEPS)]
    pub max_steps: usize,
    /// Most evaluations with sensitivities (1 … 1000).
    #[arg(long, default_value_t = calibrate::DEFAULT_MAX_ITERATIONS)]
    pub max_iterations: usize,
    /// Start from the model's initial temperatures instead of the trace's first row.
    #[arg(long)]
    pub keep_initial: bool,
    /// The segment of the trace fitted, 0-based (gaps in time cut a trace file into
    /// segments; `geartherm trace FILE` lists them); K1,K2,… or all: several segments of the
    /// trace fitted together.
    #[arg(long, value_name = "K|K1,K2,…|all")]
    pub segment: Option<String>,
    /// Refuse a trace with empty cells (by default their rows are dropped and counted).
    #[arg(long)]
    pub refuse_missing: bool,
    /// Residual model: ar1 (least squares, intervals and bands from per channel AR(1) errors;
    /// those of independent errors reported beside), ar1-gls (generalised least squares under
    /// AR(1) errors) or independent.
    #[arg(long, default_value = "ar1", value_name = "ar1|ar1-gls|independent")]
    pub residuals: String,
    /// The 95 % prediction band's multiplier of its standard deviation: empirical (the fitted
    /// rows' own 95 % quantile of |residual|/sd, per channel and trace; Student's t when they
    /// carry fewer than 100 effective independent rows) or t (Student's t(0.975, dof), for
    /// Gaussian residuals).
    #[arg(long, default_value = "empirical", value_name = "empirical|t")]
    pub band_quantile: String,
    /// A prior on a fitted parameter (a MAP fit): KEYPATH=normal:MEAN:SD or
    /// KEYPATH=lognormal:MEDIAN:SD_LN (SD_LN the standard deviation of ln p; repeatable).
    #[arg(long, value_name = "KEYPATH=DIST:LOC:WIDTH")]
    pub prior: Vec<String>,
    /// A TOML file of priors: [[prior]] tables with key, distribution ("normal": mean, sd;
    /// "lognormal": median, sd_ln).
    #[arg(long, value_name = "FILE")]
    pub priors: Option<PathBuf>,
    /// Compute the profile likelihood of a fitted parameter (repeatable): profile.csv and its
    /// 95 % interval.
    #[arg(long, value_name = "KEYPATH")]
    pub profile: Vec<String>,
    /// Compare the calibrated losses with the sourced figure for this kind of gearbox
    /// (wind-turbine) and warn when outside.
    #[arg(long, value_name = "KIND")]
    pub gearbox_kind: Option<String>,
    /// A rated point at which the calibrated losses and efficiency are reported: RPM:NM (input
    /// speed and torque).
    #[arg(long, value_name = "RPM:NM", allow_hyphen_values = true)]
    pub rated: Option<String>,
    /// For a prediction (no --fit, every row held out): the 95 % band from a previous
    /// calibration's calibration.json (its covariance and residual process). With several
    /// traces each trace's band, from the calibration's shared parameters and those of the
    /// trace of the same name.
    #[arg(long, value_name = "calibration.json")]
    pub band_from: Option<PathBuf>,
    /// Print calibration.json on stdout.
    #[arg(long)]
    pub json: bool,
}

impl CalibrateArgs {
    /// The job's options.
    pub fn options(&self) -> CalibrateOptions {
        let (segment, segments) = match self.segment.as_deref().map(str::trim) {
            Some(k) => match k.parse::<usize>() {
                Ok(k) => (Some(k), None),
                Err(_) => (None, Some(k.to_string())),
            },
            None => (None, None),
        };
        let shown: Vec<String> = self.trace.iter().map(|p| p.display().to_string()).collect();
        CalibrateOptions {
            trace: shown.first().cloned().unwrap_or_default(),
            traces: shown.iter().skip(1).cloned().collect(),
            fit: self.fit.clone(),
            holdout: self.holdout.clone(),
            rtol: self.rtol,
            atol: self.atol,
            max_steps: self.max_steps,
            max_iterations: self.max_iterations,
            initial_from_trace: !self.keep_initial,
            segment,
            segments,
            refuse_missing: self.refuse_missing,
            residuals: self.residuals.clone(),
            band_quantile: self.band_quantile.clone(),
            prior: self.prior.clone(),
            profile: self.profile.clone(),
            gearbox_kind: self.gearbox_kind.clone(),
            rated: self.rated.clone(),
        }
    }
}

/// Check the model, the trace and the options (exit 1 before anything is touched), lock the
/// output directory, fit, write, render, print, commit.
pub fn calibrate(args: &CalibrateArgs) -> Result<(), Failure> {
    let m = args.source.load()?;
    let text = std::fs::read_to_string(&args.source.model)
        .map_err(|e| io_failure(format!("{}: {e}", args.source.model.display())))?;
    let mut o = args.options();
    if let Some(path) = &args.priors {
        let text = crate::job::read_text(path)?;
        let mut from_file = calibrate::prior::from_file(&text, &path.display().to_string())?;
        from_file.append(&mut o.prior);
        o.prior = from_file;
    }
    if args.trace.len() > 1 || o.segments.is_some() {
        return calibrate_traces(args, &m, &text, &o);
    }
    let file = TraceFile::load(&args.trace[0], o.missing())?;
    let trace = file.select(o.segment).map_err(|e| invalid(e.to_string()))?;
    let mut prepared = calibrate::prepare(&m, &text, trace, &o)?;
    if let Some(path) = &args.band_from {
        let json = crate::job::read_text(path)?;
        prepared.band_from(&json, &path.display().to_string())?;
    }
    let out = OutputDir::begin(&out_dir(args, &m))?;
    let result = calibrate::fit(&m, &prepared, &o)?;
    finish(args, out, &result, true)
}

/// Write the result's files (and the figure), print, commit.
fn finish(
    args: &CalibrateArgs,
    out: OutputDir,
    result: &CalibrateResult,
    figure: bool,
) -> Result<(), Failure> {
    for (name, bytes) in result.files()? {
        out.write(&name, &bytes)?;
    }
    if figure {
        crate::report::plots::calibration::render_calibration(out.path())
            .map_err(|e| io_failure(format!("calibration.png: {e}")))?;
    }
    for w in &result.summary.warnings {
        warn(w);
    }
    if args.json {
        emit_json(&result.summary)?;
    } else {
        emit(&format!(
            "{}outputs in {}\n",
            to_text(&result.summary),
            out.target().display()
        ))?;
    }
    out.commit()?;
    Ok(())
}

/// The output directory of a calibration.
fn out_dir(args: &CalibrateArgs, m: &crate::job::Model) -> PathBuf {
    args.out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{}_calibration", m.stem())))
}

/// Several traces, or several segments of one, in one fit (docs/calibration.md, "Several
/// traces"): each file once, named by its stem.
fn calibrate_traces(
    args: &CalibrateArgs,
    m: &crate::job::Model,
    text: &str,
    o: &CalibrateOptions,
) -> Result<(), Failure> {
    let mut seen: Vec<PathBuf> = Vec::new();
    let mut files = Vec::with_capacity(args.trace.len());
    for path in &args.trace {
        let canon = std::fs::canonicalize(path).unwrap_or_else(|_| path.clone());
        if seen.contains(&canon) {
            let shown = path.display().to_string();
            let msg = format!("trace = {shown}: the same file is given twice: each trace file once");
            return Err(crate::job::JobError::option("trace", &shown, "each trace file once", msg).into());
        }
        seen.push(canon);
        let name = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        files.push((name, TraceFile::load(path, o.missing())?));
    }
    let inputs = calibrate::stack::inputs(&files, o)?;
    let mut stack = calibrate::stack::prepare(m, text, &inputs, o)?;
    if let Some(path) = &args.band_from {
        let json = crate::job::read_text(path)?;
        stack.band_from(&json, &path.display().to_string())?;
    }
    let out = OutputDir::begin(&out_dir(args, m))?;
    let result = calibrate::stack_fit::fit(m, &stack, o, &|th| stack.evaluate(th))?;
    finish(args, out, &result, false)
}

/// Arguments of `trace`.
#[derive(clap::Args, Debug)]
pub struct TraceArgs {
    /// Trace CSV (the columns of `calibrate --trace`).
    pub trace: PathBuf,
    /// Refuse empty cells (by default their rows are dropped and counted).
    #[arg(long)]
    pub refuse_missing: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Read a trace file as `calibrate` reads it and print what it holds: rows, rows dropped for
/// empty cells (per column), the segments its gaps cut it into.
pub fn trace(args: &TraceArgs) -> Result<(), Failure> {
    let missing = if args.refuse_missing {
        Missing::Refuse
    } else {
        Missing::Drop
    };
    let file = TraceFile::load(&args.trace, missing)?;
    let s = file.summary();
    if args.json {
        return emit_json(&s);
    }
    let mut out = format!(
        "{}: {} rows, {} kept in {} segment(s), {} dropped for empty cells\n",
        s.source,
        s.rows,
        s.kept_rows,
        s.segments.len(),
        s.dropped_rows
    );
    for (c, n) in &s.missing_cells {
        out.push_str(&format!("  empty cells in {c}: {n}\n"));
    }
    out.push_str(&format!(
        "  nodes: {}; boundaries: {}\n",
        s.nodes.join(", "),
        s.boundaries.join(", ")
    ));
    for (k, g) in s.segments.iter().enumerate() {
        out.push_str(&format!(
            "  segment {k}: lines {}…{}, {} rows, from {} s for {} s\n",
            g.first_line, g.last_line, g.rows, g.start_s, g.duration_s
        ));
    }
    emit(&out)
}
