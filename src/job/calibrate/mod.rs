//! `calibrate`: fit model parameters (key paths with bounds) to a measured temperature trace by
//! least squares, with the Jacobian from the forward sensitivities of the integration
//! ([`crate::solve::sensitivity`]), and report the fitted values with 95 % intervals, their
//! correlations, the errors per channel on the fitted and the held-out rows, and the model file
//! with the fitted values written in (docs/calibration.md).
//!
//! - [`trace`]: the trace reader (line and column of every problem);
//! - [`params`]: `KEYPATH[=LO:HI]`, the fitted coordinate (ln p or p), the overrides;
//! - [`problem`]: the trace mapped onto the model, the simulation at a parameter point;
//! - [`lm`]: Levenberg–Marquardt with box bounds;
//! - [`stats`]: covariance, t quantile, correlations;
//! - [`model_file`]: the calibrated model text.

pub mod bands;
pub mod checks;
pub mod lm;
pub mod model_file;
pub mod params;
pub mod plausibility;
pub mod prior;
pub mod problem;
pub mod profile;
pub mod residuals;
pub mod stack;
pub mod stack_fit;
pub mod stats;
pub mod trace;
pub mod trace_file;
pub mod transfer;

use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::model::overrides;
use crate::model::parse::parse_document;
use crate::model::Problems;
use crate::report::calibration::{
    fit_csv, CalibrationSummary, ChannelErrors, Component, Correlation, Direction, Errors, FitStats,
    FittedParameter, Noise, PriorInfluence,
};
use crate::solve::sensitivity::SensitivityOptions;

use super::limits::{self, Limit};
use super::{JobError, Model};
use lm::{Evaluation, LmOptions};
use params::{FitSpec, Parameter};
use problem::{initial_overrides, Problem};
pub use trace::Trace;
pub use trace_file::{Missing, TraceFile};

/// Default relative tolerance of a calibration's integrations (that of `run`: the fit and its
/// sensitivities are those of the discrete solution `run` computes).
pub const DEFAULT_RTOL: f64 = crate::solve::transient::DEFAULT_RTOL;
/// Default most evaluations with sensitivities.
pub const DEFAULT_MAX_ITERATIONS: usize = 30;
/// A parameter that moves no fitted temperature by more than this per unit of its coordinate
/// (a factor e on a log scale, 1 K on a temperature) has no influence, K.
pub const MIN_INFLUENCE_K: f64 = 1e-6;
/// Correlation above which two parameters are reported as not told apart by the trace.
pub const CORRELATION_WARNING: f64 = 0.95;

/// A direction of the scaled Fisher information whose relative eigenvalue lies below this is
/// reported as weakly determined (for two parameters λ/λ_max = (1 − |r|)/(1 + |r|): a
/// correlation above about 0.98).
pub const WEAK_EIGENVALUE: f64 = 1e-2;

/// Most evaluations with sensitivities.
pub const MAX_ITERATIONS: Limit = Limit {
    name: "max_iterations",
    lo: 1.0,
    hi: 1000.0,
    unit: "",
};

/// Options of a calibration (`geartherm calibrate`, `Model.calibrate` in Python).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CalibrateOptions {
    /// Trace file (the CLI) or the name given to trace text (Python).
    pub trace: String,
    /// Parameters: `KEYPATH[=LO:HI]`.
    pub fit: Vec<String>,
    /// Held-out time windows `T0:T1`, s (their rows are predicted, not fitted).
    pub holdout: Vec<String>,
    /// Relative tolerance of the integrations.
    pub rtol: f64,
    /// Absolute tolerance, K.
    pub atol: f64,
    /// Step budget of one integration.
    pub max_steps: usize,
    /// Most evaluations with sensitivities.
    pub max_iterations: usize,
    /// Start every measured node at its first measured value and the others at their mean
    /// (else at the model's initial temperatures).
    pub initial_from_trace: bool,
    /// Further traces fitted together with `trace` (files, or names given to trace text):
    /// docs/calibration.md, "Several traces".
    pub traces: Vec<String>,
    /// The segment of the trace file fitted (0-based; needed when gaps cut it into several).
    pub segment: Option<usize>,
    /// Several segments of a one-trace file fitted together: `all` or `K1,K2,…` (0-based).
    pub segments: Option<String>,
    /// Refuse empty cells (else their rows are dropped and counted).
    pub refuse_missing: bool,
    /// Residual model: `ar1` (least squares; intervals and bands from per channel AR(1)
    /// errors), `ar1-gls` (generalised least squares under those errors) or `independent`.
    pub residuals: String,
    /// The prediction band's multiplier: `empirical` (the fitted rows' 95 % quantile of
    /// |residual|/sd, t when they carry fewer than [`bands::MIN_EFFECTIVE_ROWS`] effective
    /// rows) or `t` (Student's t(0.975, dof), Gaussian residuals).
    pub band_quantile: String,
    /// Priors: `KEYPATH=normal:MEAN:SD` or `KEYPATH=lognormal:MEDIAN:SD_LN` (a MAP fit).
    pub prior: Vec<String>,
    /// Parameters (fitted key paths) whose profile likelihood is computed.
    pub profile: Vec<String>,
    /// Kind of gearbox whose sourced loss figure the calibrated losses are compared with
    /// (`wind-turbine`).
    pub gearbox_kind: Option<String>,
    /// Rated point `RPM:NM` (input speed and torque) at which the calibrated losses are reported.
    pub rated: Option<String>,
}

impl CalibrateOptions {
    /// How the trace file's empty cells are read.
    pub fn missing(&self) -> Missing {
        if self.refuse_missing {
            Missing::Refuse
        } else {
            Missing::Drop
        }
    }
}

impl Default for CalibrateOptions {
    fn default() -> Self {
        CalibrateOptions {
            trace: String::new(),
            fit: Vec::new(),
            holdout: Vec::new(),
            rtol: DEFAULT_RTOL,
            atol: crate::solve::transient::DEFAULT_ATOL,
            max_steps: super::run::DEFAULT_MAX_STEPS,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            initial_from_trace: true,
            traces: Vec::new(),
            segment: None,
            segments: None,
            refuse_missing: false,
            residuals: "ar1".into(),
            band_quantile: "empirical".into(),
            prior: Vec::new(),
            profile: Vec::new(),
            gearbox_kind: None,
            rated: None,
        }
    }
}

/// Parse one holdout window `T0:T1` (s).
fn window(s: &str) -> Result<(f64, f64), JobError> {
    let bad = || {
        JobError::option(
            "holdout",
            s,
            "T0:T1 in s, T0 < T1",
            format!("holdout = {s}: must be T0:T1, two finite times in s with T0 < T1"),
        )
    };
    let (a, b) = s.split_once(':').ok_or_else(bad)?;
    let (a, b): (f64, f64) = (
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    );
    if a.is_finite() && b.is_finite() && a < b {
        Ok((a, b))
    } else {
        Err(bad())
    }
}

/// The parsed `--fit` specs, `--holdout` windows (s) and `--prior` specs.
pub type Checked = (Vec<FitSpec>, Vec<(f64, f64)>, Vec<prior::PriorSpec>);

impl CalibrateOptions {
    /// Range checks; the parsed fit specs and holdout windows.
    pub fn check(&self) -> Result<Checked, JobError> {
        limits::RTOL.check(self.rtol)?;
        limits::ATOL.check(self.atol)?;
        limits::MAX_STEPS.check(self.max_steps as f64)?;
        MAX_ITERATIONS.check(self.max_iterations as f64)?;
        if !["ar1", "ar1-gls", "independent"].contains(&self.residuals.as_str()) {
            let msg = format!(
                "residuals = {}: must be ar1, ar1-gls or independent",
                self.residuals
            );
            return Err(JobError::option(
                "residuals",
                &self.residuals,
                "ar1, ar1-gls or independent",
                msg,
            ));
        }
        if !["empirical", "t"].contains(&self.band_quantile.as_str()) {
            let msg = format!("band_quantile = {}: must be empirical or t", self.band_quantile);
            return Err(JobError::option(
                "band_quantile",
                &self.band_quantile,
                "empirical or t",
                msg,
            ));
        }
        let mut specs: Vec<FitSpec> = Vec::with_capacity(self.fit.len());
        for f in &self.fit {
            let s: FitSpec = f
                .parse()
                .map_err(|e: String| JobError::option("fit", f, "KEYPATH[=LO:HI]", e))?;
            if specs.iter().any(|x| x.path == s.path) {
                let msg = format!("fit = {f}: {} is fitted twice", s.path);
                return Err(JobError::option("fit", f, "each key path once", msg));
            }
            specs.push(s);
        }
        let windows = self
            .holdout
            .iter()
            .map(|h| window(h))
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(k) = &self.gearbox_kind {
            plausibility::check_kind(k)?;
        }
        if let Some(r) = &self.rated {
            plausibility::rated_point(r)?;
        }
        let priors = self
            .prior
            .iter()
            .map(|s| s.parse::<prior::PriorSpec>())
            .collect::<Result<Vec<_>, _>>()?;
        Ok((specs, windows, priors))
    }
}

/// A finished calibration.
#[derive(Debug, Clone)]
pub struct CalibrateResult {
    /// `calibration.json`.
    pub summary: CalibrationSummary,
    /// `fit.csv`.
    pub fit_csv: String,
    /// `calibrated.toml`: the model text with the fitted values, the trace's initial
    /// temperatures and boundary series written in.
    pub calibrated_model: String,
    /// `cycle.csv`: the trace's input columns (`geartherm run calibrated.toml --cycle cycle.csv`
    /// reproduces the fitted trajectory).
    pub cycle_csv: String,
    /// With several traces and parameters of one trace: per trace its calibrated model
    /// (`calibrated_<trace>.toml`, text).
    pub per_trace_models: Vec<(String, String)>,
}

impl CalibrateResult {
    /// The files of the output directory (a fit over several traces with parameters of one
    /// trace writes one `calibrated_<trace>.toml` per trace instead of `calibrated.toml`, and
    /// no `cycle.csv`).
    pub fn files(&self) -> Result<Vec<(String, Vec<u8>)>, JobError> {
        let json = serde_json::to_vec_pretty(&self.summary)
            .map_err(|e| JobError::numerical(format!("cannot serialise the calibration: {e}")))?;
        let mut files = vec![
            ("calibration.json".to_string(), json),
            ("fit.csv".to_string(), self.fit_csv.clone().into_bytes()),
        ];
        if !self.calibrated_model.is_empty() {
            files.push((
                "calibrated.toml".into(),
                self.calibrated_model.clone().into_bytes(),
            ));
        }
        for (name, text) in &self.per_trace_models {
            files.push((name.clone(), text.clone().into_bytes()));
        }
        if !self.cycle_csv.is_empty() {
            files.push(("cycle.csv".into(), self.cycle_csv.clone().into_bytes()));
        }
        if !self.summary.profiles.is_empty() {
            files.push((
                "profile.csv".into(),
                profile_csv(&self.summary.profiles).into_bytes(),
            ));
        }
        Ok(files)
    }
}

/// `profile.csv`: `key_path,value,statistic,threshold` for every profile point.
fn profile_csv(profiles: &[crate::report::calibration::Profile]) -> String {
    let mut s = String::from("key_path,value,statistic,threshold\n");
    for p in profiles {
        for x in &p.points {
            s.push_str(&format!(
                "\"{}\",{},{:.6},{:.6}\n",
                p.key_path.replace('"', "\"\""),
                x.value,
                x.statistic,
                p.threshold
            ));
        }
    }
    s
}

/// The model document with the base overrides applied (for the parameters' start values).
fn document(m: &Model, text: &str, base: &[crate::model::Override]) -> Result<toml::Table, JobError> {
    let mut problems = Problems::default();
    let mut doc = parse_document(text, &mut problems)
        .ok_or_else(|| JobError::invalid(format!("{}: the model text does not parse", m.label())))?;
    for ov in base {
        overrides::apply(&mut doc, ov).map_err(|e| JobError::invalid(format!("{}: {e}", m.label())))?;
    }
    Ok(doc)
}

/// A checked, mapped calibration problem, ready to fit.
pub struct Prepared<'a> {
    /// The problem.
    pub problem: Problem<'a>,
    /// Held-out windows, s.
    pub windows: Vec<(f64, f64)>,
    /// Per trace row: held out.
    pub held: Vec<bool>,
    /// The priors (a MAP fit when not empty).
    pub priors: prior::Priors,
    /// Index of each parameter whose profile is computed.
    pub profile: Vec<usize>,
    /// A previous calibration whose uncertainty gives the band where this run fits no row.
    pub band_source: Option<transfer::BandSource<'a>>,
}

impl<'a> Prepared<'a> {
    /// Take the prediction band from a previous calibration (`calibration.json` text, `file`
    /// naming it) for a run that fits no row: invalid input when this run fits parameters or rows.
    pub fn band_from(&mut self, json: &str, file: &str) -> Result<(), JobError> {
        if !self.problem.params.is_empty() || self.held.iter().any(|h| !h) {
            return Err(JobError::option(
                "band_from",
                file,
                "a run that fits nothing (no fit, every row held out)",
                format!(
                    "band_from = {file}: only for a prediction (no fit, holdout over the whole \
                     trace); this run fits its own band"
                ),
            ));
        }
        let doc = self.problem.document().clone();
        let name = transfer::trace_name(&self.problem.trace.source);
        self.band_source = Some(transfer::band_source(&self.problem, &doc, json, file, &name)?);
        Ok(())
    }
}

/// Check the options and map the trace onto the model: every invalid input fails here.
pub fn prepare<'a>(
    m: &Model,
    text: &'a str,
    trace: &'a Trace,
    o: &CalibrateOptions,
) -> Result<Prepared<'a>, JobError> {
    let (specs, windows, prior_specs) = o.check()?;
    problem::check_names(m, trace)?;
    let mut base = m.overrides.clone();
    if o.initial_from_trace {
        base.extend(initial_overrides(trace));
    }
    let doc = document(m, text, &base)?;
    let params = specs
        .iter()
        .map(|s| {
            Parameter::resolve(s, &doc)
                .map_err(|e| JobError::option("fit", s.to_string(), "a number in the model", e))
        })
        .collect::<Result<Vec<_>, _>>()?;
    checks::fitted_once(&specs, &doc)?;
    let priors = prior::Priors::resolve(&prior_specs, &params, &doc)?;
    let profile = profile::resolve(&o.profile, &params, &doc)?;
    let opts = SensitivityOptions {
        rtol: o.rtol,
        atol: o.atol,
        max_steps: o.max_steps,
        initial: None,
    };
    let problem = Problem::new(m, text, trace, params, base, opts)?;
    let held: Vec<bool> = trace
        .times
        .iter()
        .map(|t| windows.iter().any(|(a, b)| (a..=b).contains(&t)))
        .collect();
    let fitted = held.iter().filter(|h| !**h).count() * trace.measured.len();
    if !problem.params.is_empty() && fitted <= problem.params.len() {
        return Err(JobError::invalid(format!(
            "{}: {fitted} fitted values (rows outside --holdout × measured columns) for {} parameters: \
             a fit needs more values than parameters",
            trace.source,
            problem.params.len()
        )));
    }
    // The model at the start point must check (bounds written into the file are checked there).
    problem.gearbox_at(&problem.start())?;
    checks::boundaries_in_model_range(m, &problem)?;
    checks::measured_in_envelope(m, &problem)?;
    Ok(Prepared {
        problem,
        windows,
        held,
        priors,
        profile,
        band_source: None,
    })
}

/// A fit that stopped on normal equations without a solution (a non-finite residual or
/// sensitivity) is a numerical failure (exit 2), not a result.
fn singular(p: &Prepared<'_>, res: &lm::LmResult) -> Result<(), JobError> {
    if res.stop != lm::Stop::Singular {
        return Ok(());
    }
    Err(JobError::numerical(format!(
        "{} on {}: the fit stopped after {} evaluations at a point where the residuals or their \
         sensitivities are not finite, or the damped normal equations have no solution: no \
         calibrated model is written (narrow the bounds or check the trace)",
        p.problem.file.display(),
        p.problem.trace.source,
        res.evaluations
    )))
}

/// The error of a fitted model whose trajectory leaves the physics envelope (exit 2).
fn breach_error(p: &Prepared<'_>, theta: &[f64], breach: &str) -> JobError {
    let pr = &p.problem;
    let values: Vec<String> = pr
        .params
        .iter()
        .zip(theta)
        .map(|(q, &t)| format!("{} = {}", q.name(), q.written(t)))
        .collect();
    JobError::numerical(format!(
        "{} on {}: with {} the trajectory leaves the range where the models hold {breach}: no calibrated \
         model is written (narrow the bounds or check the trace)",
        pr.file.display(),
        pr.trace.source,
        values.join(", ")
    ))
}

/// Residuals (simulated − measured, K) and their Jacobian over the fitted rows. The points the
/// fit passes through may leave the physics envelope (a start far from the data); the fitted
/// point may not ([`fit`]).
fn evaluate(p: &Prepared<'_>, theta: &[f64]) -> Result<Evaluation, JobError> {
    let pr = &p.problem;
    let sim = pr.simulate(theta, true)?;
    let (nc, np) = (pr.channels.len(), pr.params.len());
    let rows: Vec<usize> = (0..p.held.len()).filter(|&r| !p.held[r]).collect();
    let m = rows.len() * nc;
    let mut r = DVector::zeros(m);
    let mut j = DMatrix::zeros(m, np);
    for (i, &row) in rows.iter().enumerate() {
        for c in 0..nc {
            let k = i * nc + c;
            r[k] = sim.temps_c[row][c] - pr.trace.measured[c].values_c[row];
            for q in 0..np {
                j[(k, q)] = sim.sens[row][c * np + q];
            }
        }
    }
    Ok(Evaluation { r, j })
}

/// Calibrate: fit the parameters of `o.fit` to the trace. `text` is the model file's text (`m`
/// is it checked with its overrides).
pub fn calibrate(
    m: &Model,
    text: &str,
    trace: &Trace,
    o: &CalibrateOptions,
) -> Result<CalibrateResult, JobError> {
    let p = prepare(m, text, trace, o)?;
    fit(m, &p, o)
}

/// Fit a prepared problem and assemble the result (the second half of [`calibrate`]).
pub fn fit(m: &Model, p: &Prepared<'_>, o: &CalibrateOptions) -> Result<CalibrateResult, JobError> {
    let clock = Instant::now();
    let pr = &p.problem;
    let theta0 = pr.start();
    let at0 = evaluate(p, &theta0)?;
    let influence: Vec<f64> = (0..pr.params.len())
        .map(|k| at0.j.column(k).iter().fold(0.0, |a: f64, x| a.max(x.abs())))
        .collect();
    let free: Vec<bool> = influence.iter().map(|&x| x > MIN_INFLUENCE_K).collect();
    let setup = Setup {
        params: &pr.params,
        priors: &p.priors,
        layout: residuals::Layout::of(&p.held, pr.channels.len()),
        fail: &|r| singular(p, r),
    };
    let fitted = solve(&|th| evaluate(p, th), &setup, (&theta0, at0), influence, free, o)?;
    assemble(m, p, o, &fitted, clock)
}

/// What the fit of one segment and the fit over several traces share: the parameters, their
/// priors, the fitted rows' layout, and the error of a fit that stopped on a singular point.
struct Setup<'a> {
    /// The parameters.
    params: &'a [Parameter],
    /// Their priors (a MAP fit when not empty).
    pub priors: &'a prior::Priors,
    /// The fitted rows' layout (a stretch per segment and held-out window).
    pub layout: residuals::Layout,
    /// The error of a fit stopped on `Singular` (exit 2 naming the trace).
    pub fail: &'a dyn Fn(&lm::LmResult) -> Result<(), JobError>,
}

/// The fit from `start` (θ₀ and its evaluation): least squares, then under the residual model
/// of `o` the weighted, MAP or prewhitened (`ar1-gls`) fit (docs/calibration.md, "The residual
/// model", "Priors"). `eval` gives the unweighted residuals and Jacobian of the fitted rows.
fn solve(
    eval: &dyn Fn(&[f64]) -> Result<Evaluation, JobError>,
    s: &Setup<'_>,
    start: (&[f64], Evaluation),
    influence: Vec<f64>,
    free: Vec<bool>,
    o: &CalibrateOptions,
) -> Result<Fitted, JobError> {
    let bounds: Vec<(f64, f64)> = s.params.iter().map(Parameter::theta_bounds).collect();
    let lmo = LmOptions {
        max_iterations: o.max_iterations,
        ..LmOptions::default()
    };
    let ols = lm::minimise(eval, start.0, start.1, &bounds, &free, &lmo)?;
    (s.fail)(&ols)?;
    let id_ols = identifiable(&ols.theta, &bounds, &free);
    let independent = Independent {
        lin: stats::linearised(&ols.at.j, ols.at.r.norm_squared(), &id_ols, 0),
        theta: ols.theta.clone(),
    };
    let layout = &s.layout;
    let known = !layout.stretch.is_empty();
    let mut channel_weights = None;
    let (res, noise) = match o.residuals.as_str() {
        "ar1-gls" if known => {
            let (res, models) = residuals::refit(
                eval,
                |e, th| s.priors.augment(e, s.params, th),
                |e| s.priors.strip(e),
                ols,
                layout,
                &bounds,
                &free,
                &lmo,
            )?;
            (res, Some(models))
        }
        "ar1" if known => {
            let models = layout.estimate(&ols.at.r);
            let weights: Vec<f64> = models.iter().map(residuals::Ar1::long_run_sd).collect();
            let res = map_fit(eval, s, ols, &weights, &bounds, &free, &lmo)?;
            let models = if s.priors.is_empty() && !unequal(&weights) {
                models
            } else {
                layout.estimate(&res.at.r)
            };
            channel_weights = unequal(&weights).then_some(weights);
            (res, Some(models))
        }
        _ => {
            let dof = ols.at.r.len().saturating_sub(s.params.len()).max(1);
            let sd = (ols.at.r.norm_squared() / dof as f64).sqrt().max(1e-12);
            let weights = vec![sd; layout.nc];
            (map_fit(eval, s, ols, &weights, &bounds, &free, &lmo)?, None)
        }
    };
    (s.fail)(&res)?;
    Ok(Fitted {
        res,
        weights: channel_weights,
        noise,
        whitened: o.residuals == "ar1-gls" && known,
        layout: s.layout.clone(),
        independent,
        influence,
        free,
    })
}

/// Channels' noise scales that differ (each finite and above zero): a fit of several channels
/// weights each by its own. A channel the fit matches exactly (scale 0) leaves the fit unweighted.
fn unequal(weights: &[f64]) -> bool {
    weights.iter().all(|&w| w.is_finite() && w > 0.0) && weights.iter().any(|&w| w != weights[0])
}

/// The MAP fit from the least-squares fit `ols`: the data rows divided by their channel's
/// noise scale `weights`, the prior rows appended (docs/calibration.md, "Priors"). Without
/// priors and with equal weights (one channel) `ols` itself; without priors and with unequal
/// weights (several channels) the weighted least-squares fit. The result's evaluation is the
/// data's, unweighted; its evaluations count those of `ols`.
fn map_fit(
    eval: &dyn Fn(&[f64]) -> Result<Evaluation, JobError>,
    s: &Setup<'_>,
    ols: lm::LmResult,
    weights: &[f64],
    bounds: &[(f64, f64)],
    free: &[bool],
    lmo: &LmOptions,
) -> Result<lm::LmResult, JobError> {
    if s.priors.is_empty() && !unequal(weights) {
        return Ok(ols);
    }
    let ev = |th: &[f64]| -> Result<Evaluation, JobError> {
        let e = prior::weighted(eval(th)?, weights);
        Ok(s.priors.augment(e, s.params, th))
    };
    let at0 = s
        .priors
        .augment(prior::weighted(ols.at, weights), s.params, &ols.theta);
    let mut res = lm::minimise(ev, &ols.theta, at0, bounds, free, lmo)?;
    let back: Vec<f64> = weights.iter().map(|w| 1.0 / w).collect();
    res.at = prior::weighted(s.priors.strip(res.at), &back);
    res.evaluations += ols.evaluations;
    res.iterations += ols.iterations;
    Ok(res)
}

/// The ordinary least-squares fit's statistics (the residual model `independent`), reported
/// beside those of the AR(1) model.
struct Independent {
    lin: stats::Linearised,
    theta: Vec<f64>,
}

/// A finished fit.
struct Fitted {
    /// The last fit (its evaluation whitened with `noise`).
    res: lm::LmResult,
    /// Each channel's noise scale, K, when the fit weighted its channels by them (several
    /// channels, residual model `ar1`): the covariance is the weighted fit's sandwich.
    weights: Option<Vec<f64>>,
    /// The channels' AR(1) errors (None: independent).
    noise: Option<Vec<residuals::Ar1>>,
    /// `res` is the generalised least-squares fit (its evaluation whitened); else the ordinary
    /// one, whose covariance under AR(1) errors is the sandwich.
    whitened: bool,
    layout: residuals::Layout,
    independent: Independent,
    influence: Vec<f64>,
    free: Vec<bool>,
}

/// Each prior's influence: its width against the posterior's and the data's.
fn prior_influence(
    priors: &prior::Priors,
    params: &[Parameter],
    f: &Fitted,
    data_se: &[Option<f64>],
    out: &mut [FittedParameter],
) {
    for q in &priors.list {
        let k = q.param;
        let prior_sd = priors.sd_theta(q, params, &f.res.theta);
        let post = out[k].std_error;
        let share = match (post, data_se[k]) {
            (Some(a), Some(d)) if d > 0.0 => Some(1.0 - (a / d).powi(2)),
            (Some(_), None) => Some(1.0),
            _ => None,
        };
        out[k].prior = Some(PriorInfluence {
            distribution: match q.spec.kind {
                prior::Kind::Normal => "normal",
                prior::Kind::Lognormal => "lognormal",
            },
            location: q.spec.location,
            width: q.spec.width,
            prior_sd,
            data_std_error: data_se[k],
            posterior_std_error: post,
            width_ratio: post.map(|a| a / prior_sd),
            prior_share: share,
            without_prior: params[k].written(f.independent.theta[k]),
        });
    }
}

/// Free and not at a bound.
fn identifiable(theta: &[f64], bounds: &[(f64, f64)], free: &[bool]) -> Vec<bool> {
    (0..free.len())
        .map(|k| free[k] && !at_bound(theta[k], bounds[k]))
        .collect()
}

/// A fitted coordinate within 1e-6 of the bounds' width of a bound.
fn at_bound(theta: f64, (lo, hi): (f64, f64)) -> bool {
    let w = 1e-6 * (hi - lo);
    theta <= lo + w || theta >= hi - w
}

/// The parameters with their intervals, and the warnings about them.
fn parameters(
    params: &[Parameter],
    f: &Fitted,
    identifiable: &[bool],
    lin: &stats::Linearised,
    t: f64,
    warnings: &mut Vec<String>,
) -> Vec<FittedParameter> {
    let (res, influence) = (&f.res, &f.influence);
    let ind = &f.independent;
    let t_ind = stats::t975(ind.lin.dof);
    let mut out = Vec::with_capacity(params.len());
    for (k, par) in params.iter().enumerate() {
        let th = res.theta[k];
        let (ith, ise) = (ind.theta[k], ind.lin.std_err[k].filter(|_| f.noise.is_some()));
        if influence[k] <= MIN_INFLUENCE_K {
            warnings.push(format!(
                "{}: the trace does not influence this parameter (no fitted temperature moves by more than \
                 {MIN_INFLUENCE_K:e} K): left at {}, not identifiable",
                par.name(),
                par.start
            ));
        } else if !identifiable[k] {
            warnings.push(format!(
                "{}: at its bound ({}): no interval; widen the bounds or fix the parameter",
                par.name(),
                par.written(th)
            ));
        }
        let se = lin.std_err[k];
        out.push(FittedParameter {
            key_path: par.name(),
            start: par.start,
            value: par.written(th),
            lower_bound: par.lo,
            upper_bound: par.hi,
            scale: if par.log { "log" } else { "linear" },
            std_error: se,
            ci95_low: se.map(|s| par.value(th - t * s)),
            ci95_high: se.map(|s| par.value(th + t * s)),
            ci95_independent_low: ise.map(|s| par.value(ith - t_ind * s)),
            ci95_independent_high: ise.map(|s| par.value(ith + t_ind * s)),
            influence_k: influence[k],
            prior: None,
        });
    }
    out
}

fn correlation(params: &[Parameter], lin: &stats::Linearised, warnings: &mut Vec<String>) -> Correlation {
    let names: Vec<String> = params.iter().map(Parameter::name).collect();
    let np = names.len();
    for a in 0..np {
        for b in a + 1..np {
            let r = lin.correlation[a][b];
            if r.is_finite() && r.abs() > CORRELATION_WARNING {
                warnings.push(format!(
                    "{} and {}: correlation {r:.3}: the trace cannot tell them apart (fit one, fix the other, \
                     or add a trace that separates them)",
                    names[a], names[b]
                ));
            }
        }
    }
    let matrix = lin
        .correlation
        .iter()
        .map(|row| row.iter().map(|&x| x.is_finite().then_some(x)).collect())
        .collect();
    Correlation {
        parameters: names,
        matrix,
    }
}

/// The eigen-directions as reported, with a warning for each the trace does not or only weakly
/// determines.
fn identifiability(
    params: &[Parameter],
    lin: &stats::Linearised,
    t: f64,
    warnings: &mut Vec<String>,
) -> Vec<Direction> {
    let mut out = Vec::new();
    for d in &lin.directions {
        let components: Vec<Component> = params
            .iter()
            .zip(&d.direction)
            .filter(|(_, c)| c.abs() > stats::INVOLVED)
            .map(|(q, &c)| Component {
                key_path: q.name(),
                component: c,
            })
            .collect();
        let label = |c: &Component| {
            let log = params.iter().any(|q| q.name() == c.key_path && q.log);
            if log {
                format!("{:+.3}·ln {}", c.component, c.key_path)
            } else {
                format!("{:+.3}·{}", c.component, c.key_path)
            }
        };
        let along: Vec<String> = components.iter().map(label).collect();
        let names: Vec<&str> = components.iter().map(|c| c.key_path.as_str()).collect();
        let half = d.std_error.map(|s| t * s);
        let status = match half {
            None => "not determined",
            Some(_) if d.relative_eigenvalue < WEAK_EIGENVALUE => "weakly determined",
            Some(_) => "determined",
        };
        match half {
            None => warnings.push(format!(
                "{} are not identifiable: a step along ({}) leaves the fitted temperatures unchanged (relative \
                 eigenvalue {:.1e} of the scaled Fisher information): the trace fixes only the combinations \
                 across it; fix all but one of them, give a prior, or add a trace that separates them",
                names.join(" and "),
                along.join(", "),
                d.relative_eigenvalue
            )),
            Some(h) if d.relative_eigenvalue < WEAK_EIGENVALUE && components.len() > 1 => {
                warnings.push(format!(
                    "{} move together: the trace fixes a step along ({}) only to ±{h:.3} (95 %; relative \
                     eigenvalue {:.1e})",
                    names.join(" and "),
                    along.join(", "),
                    d.relative_eigenvalue
                ))
            }
            _ => {}
        }
        out.push(Direction {
            status,
            relative_eigenvalue: d.relative_eigenvalue,
            components,
            ci95_half_width: half,
        });
    }
    out
}

/// Errors per channel on the fitted and the held-out rows (with the fraction inside the band),
/// and the residual process (its autocorrelation at lags 1, 2 and 6 rows on the fitted rows).
fn channel_errors(
    p: &Prepared<'_>,
    f: &Fitted,
    temps_c: &[Vec<f64>],
    (band, band_known): (&[Vec<f64>], bool),
    noise: &[residuals::Ar1],
    mult: &[bands::Multiplier],
) -> Vec<ChannelErrors> {
    let pr = &p.problem;
    pr.trace
        .measured
        .iter()
        .enumerate()
        .map(|(c, ch)| {
            let rows = |held: bool| (0..p.held.len()).filter(move |&r| p.held[r] == held);
            let res =
                |held: bool| -> Vec<f64> { rows(held).map(|r| temps_c[r][c] - ch.values_c[r]).collect() };
            let half = |held: bool| -> Option<Vec<f64>> {
                band_known.then(|| rows(held).map(|r| band[r][c]).collect())
            };
            let fitted = res(false);
            let acf = [1, 2, 6].map(|lag| f.layout.autocorrelation(&fitted, lag));
            ChannelErrors {
                column: ch.column.clone(),
                node: ch.name.clone(),
                fitted: Errors::of(&fitted, half(false).as_deref()),
                holdout: Errors::of(&res(true), half(true).as_deref()),
                noise: Noise {
                    phi: noise[c].phi,
                    innovation_sd_k: noise[c].sigma,
                    marginal_sd_k: noise[c].marginal_sd(),
                    autocorrelation_lag_1_2_6: acf,
                    band_multiplier: mult[c].value,
                    band_quantile: mult[c].kind(),
                },
            }
        })
        .collect()
}

/// The band's half-widths `[row][channel]`, each channel's multiplier and whether the band is
/// known (a run that fits no row and takes no band from a calibration has none): with
/// `--band-from` that calibration's processes and multipliers; else the fit's covariance `cov`
/// and processes `noise`, each channel's multiplier from its fitted rows (`--band-quantile`,
/// [`bands::multiplier`]; `t` Student's quantile of the fit).
fn band_of(
    p: &Prepared<'_>,
    o: &CalibrateOptions,
    sim: &problem::Simulation,
    cov: &[Vec<f64>],
    noise: &[residuals::Ar1],
    t: f64,
) -> (Vec<Vec<f64>>, Vec<bands::Multiplier>, bool) {
    if let Some(b) = &p.band_source {
        let sd = bands::sds(sim, &b.covariance, &b.noise);
        return (bands::scaled(&sd, &b.multipliers), b.multipliers.clone(), true);
    }
    let sd = bands::sds(sim, cov, noise);
    let measured = &p.problem.trace.measured;
    let res: Vec<Vec<f64>> = (0..sim.temps_c.len())
        .map(|r| {
            measured
                .iter()
                .enumerate()
                .map(|(c, ch)| sim.temps_c[r][c] - ch.values_c[r])
                .collect()
        })
        .collect();
    let fitted: Vec<usize> = (0..p.held.len()).filter(|&r| !p.held[r]).collect();
    let how = bands::Quantile::of(&o.band_quantile);
    let mult: Vec<bands::Multiplier> = noise
        .iter()
        .enumerate()
        .map(|(c, a)| bands::multiplier(&bands::standardised(&res, &sd, &fitted, c), a.phi, t, how))
        .collect();
    (bands::scaled(&sd, &mult), mult, !fitted.is_empty())
}

/// The cycle columns of the trace as a cycle file.
fn cycle_csv(trace: &Trace) -> String {
    use crate::cycle::parse::{KMH, RPM};
    use crate::cycle::CycleKind;
    let c = &trace.cycle;
    let mut s = match (c.kind, c.has_gear) {
        (CycleKind::Rig, _) => String::from("time_s,input_speed_rpm,input_torque_nm,gear\n"),
        (CycleKind::Vehicle, true) => String::from("time_s,speed_kmh,gear\n"),
        (CycleKind::Vehicle, false) => String::from("time_s,speed_kmh\n"),
    };
    for r in &c.rows {
        let gear = r.gear.as_deref().unwrap_or("");
        match (c.kind, c.has_gear) {
            (CycleKind::Rig, _) => s.push_str(&format!(
                "{},{},{},{gear}\n",
                r.time,
                r.input_speed / RPM,
                r.input_torque
            )),
            (CycleKind::Vehicle, true) => {
                s.push_str(&format!("{},{},{gear}\n", r.time, r.vehicle_speed / KMH))
            }
            (CycleKind::Vehicle, false) => s.push_str(&format!("{},{}\n", r.time, r.vehicle_speed / KMH)),
        }
    }
    s
}

/// The fit's evaluation and residual processes in the units it was fitted in: each channel
/// divided by its weight when the fit weighted its channels (the weighted fit's sandwich
/// (JᵀWJ)⁻¹ JᵀWΣWJ (JᵀWJ)⁻¹ is the unweighted one on rows and processes scaled by 1/w, W the
/// diagonal of 1/w²); else as they are.
fn weighted_at(f: &Fitted) -> (Evaluation, Option<Vec<residuals::Ar1>>) {
    let at = Evaluation {
        r: f.res.at.r.clone(),
        j: f.res.at.j.clone(),
    };
    match (&f.weights, &f.noise) {
        (Some(w), Some(models)) => {
            let scaled = models
                .iter()
                .zip(w)
                .map(|(a, w)| residuals::Ar1 {
                    phi: a.phi,
                    sigma: a.sigma / w,
                })
                .collect();
            (prior::weighted(at, w), Some(scaled))
        }
        _ => (at, f.noise.clone()),
    }
}

/// The linearised statistics of a fit: the covariance (the sandwich under AR(1) errors), the
/// degrees of freedom (at most the effective rows less the parameters), and the data's standard
/// errors.
fn statistics(f: &Fitted, identifiable: &[bool]) -> (stats::Linearised, Vec<Option<f64>>) {
    let lost = f.noise.as_ref().map_or(0, Vec::len);
    let (at, scaled) = weighted_at(f);
    let mut lin = stats::linearised(&at.j, at.r.norm_squared(), identifiable, lost);
    if let (Some(models), false) = (&scaled, f.whitened) {
        let sj = f.layout.covariance_times(&at.j, models);
        stats::sandwich(&mut lin, &(at.j.transpose() * sj));
    }
    if let Some(models) = &f.noise {
        let used = identifiable.iter().filter(|&&k| k).count() as f64;
        let eff = residuals::effective_rows(&f.layout, models) - used;
        lin.dof = lin.dof.min(eff.floor().max(1.0) as usize);
    }
    let data_se = lin.std_err.clone();
    (lin, data_se)
}

fn assemble(
    m: &Model,
    p: &Prepared<'_>,
    o: &CalibrateOptions,
    f: &Fitted,
    clock: Instant,
) -> Result<CalibrateResult, JobError> {
    let (pr, res) = (&p.problem, &f.res);
    let bounds: Vec<(f64, f64)> = pr.params.iter().map(Parameter::theta_bounds).collect();
    let identifiable = identifiable(&res.theta, &bounds, &f.free);
    let (mut lin, data_se) = statistics(f, &identifiable);
    if !p.priors.is_empty() {
        stats::posterior(&mut lin, &p.priors.information(&pr.params, &res.theta));
    }
    let t = stats::t975(lin.dof);
    let mut warnings = pr.trace.notes.clone();
    let mut parameters = parameters(&pr.params, f, &identifiable, &lin, t, &mut warnings);
    prior_influence(&p.priors, &pr.params, f, &data_se, &mut parameters);
    let correlation = correlation(&pr.params, &lin, &mut warnings);
    let identifiability = identifiability(&pr.params, &lin, t, &mut warnings);
    singular(p, res)?;
    warnings.extend(lm::stop_warning(res));
    // A prediction with a band from a calibration runs at that calibration's parameters: the
    // model's values, a per-trace parameter of this trace the calibration's value for it.
    let sim = match &p.band_source {
        Some(b) => b.problem.simulate(&b.problem.start(), true)?,
        None => pr.simulate(&res.theta, !pr.params.is_empty())?,
    };
    if let Some(b) = &sim.breach {
        return Err(breach_error(p, &res.theta, b));
    }
    let noise = f.noise.clone().unwrap_or_else(|| {
        let a = residuals::Ar1 {
            phi: 0.0,
            sigma: lin.sigma2.sqrt(),
        };
        vec![a; pr.channels.len()]
    });
    let (band, mult, band_known) = band_of(p, o, &sim, &lin.covariance, &noise, t);
    let rated = o.rated.as_deref().map(plausibility::rated_point).transpose()?;
    let plausibility = plausibility::assess(
        &[(pr, &sim.temps_c)],
        &res.theta,
        o.gearbox_kind.as_deref(),
        rated,
        &mut warnings,
    )?;
    let objective = profile::Objective {
        eval: &|th| evaluate(p, th),
        params: &pr.params,
        priors: &p.priors,
        fail: &|r| singular(p, r),
        noise: &noise,
        whitened: f.whitened,
        layout: &f.layout,
    };
    let profiles = p
        .profile
        .iter()
        .map(|&k| profile::profile(&objective, k, &res.theta, lin.std_err[k], lin.dof, &f.free))
        .collect::<Result<Vec<_>, _>>()?;
    for q in profiles.iter().filter(|q| q.below_fit.is_some()) {
        warnings.push(format!(
            "profile of {}: the objective is lower by {:.3} at {} than at the fitted value: the fit stopped short \
             along a flat valley (the least point of profile.csv is the better one)",
            q.key_path,
            q.below_fit.unwrap_or(0.0),
            q.points.iter().find(|x| x.statistic == 0.0).map_or(f64::NAN, |x| x.value)
        ));
    }
    let noise = p.band_source.as_ref().map_or(noise, |b| b.noise.clone());
    let channels = channel_errors(p, f, &sim.temps_c, (&band, band_known), &noise, &mult);
    let nodes: Vec<String> = pr.trace.measured.iter().map(|c| c.name.clone()).collect();
    let measured: Vec<Vec<f64>> = pr.trace.measured.iter().map(|c| c.values_c.clone()).collect();
    let csv = fit_csv(&pr.trace.times, &p.held, &nodes, &measured, &sim.temps_c, &band);
    let covariance: Vec<Vec<Option<f64>>> = lin
        .covariance
        .iter()
        .map(|row| row.iter().map(|&x| x.is_finite().then_some(x)).collect())
        .collect();
    let mut calibrated =
        model_file::calibrated_text(pr.text, &pr.overrides_at(&res.theta), &pr.boundary_series())
            .map_err(|e| JobError::invalid(format!("{}: {e}", m.label())))?;
    calibrated.push_str(&model_file::covariance_comment(&parameters, &covariance));
    let summary = CalibrationSummary {
        model: m.gearbox.name.clone(),
        trace: pr.trace.source.clone(),
        rows: pr.trace.len(),
        holdout_s: p.windows.clone(),
        parameters,
        covariance,
        correlation,
        identifiability,
        channels,
        fit: fit_stats(res, o, &noise, &lin, t, clock),
        profiles,
        plausibility,
        warnings,
        traces: Vec::new(),
    };
    check_finite(&summary)?;
    Ok(CalibrateResult {
        summary,
        fit_csv: csv,
        calibrated_model: calibrated,
        cycle_csv: cycle_csv(pr.trace),
        per_trace_models: Vec::new(),
    })
}

/// No NaN reaches a file: every number of the summary must be finite.
fn check_finite(s: &CalibrationSummary) -> Result<(), JobError> {
    let bad = |what: &str| {
        JobError::numerical(format!(
            "calibration of {} on {}: {what} is not finite",
            s.model, s.trace
        ))
    };
    for p in &s.parameters {
        let vals = [
            Some(p.value),
            p.std_error,
            p.ci95_low,
            p.ci95_high,
            p.ci95_independent_low,
            p.ci95_independent_high,
            Some(p.influence_k),
        ];
        if vals.iter().flatten().any(|v| !v.is_finite()) {
            return Err(bad(&p.key_path));
        }
    }
    for c in &s.channels {
        for e in [c.fitted, c.holdout].iter().flatten() {
            if !(e.rmse_k.is_finite()
                && e.max_abs_k.is_finite()
                && e.bias_k.is_finite()
                && e.inside_band95.map_or(true, f64::is_finite))
            {
                return Err(bad(&c.column));
            }
        }
    }
    for d in &s.identifiability {
        let vals = [Some(d.relative_eigenvalue), d.ci95_half_width];
        if vals.iter().flatten().any(|v| !v.is_finite())
            || d.components.iter().any(|c| !c.component.is_finite())
        {
            return Err(bad("an eigen-direction of the Fisher information"));
        }
    }
    if !s.fit.sigma_k.is_finite() {
        return Err(bad("σ"));
    }
    for p in &s.parameters {
        if let Some(q) = &p.prior {
            let vals = [
                Some(q.prior_sd),
                q.data_std_error,
                q.posterior_std_error,
                q.width_ratio,
                q.prior_share,
                Some(q.without_prior),
            ];
            if vals.iter().flatten().any(|v| !v.is_finite()) {
                return Err(bad(&format!("the prior of {}", p.key_path)));
            }
        }
    }
    if let Some(p) = &s.plausibility {
        let mut xs = vec![&p.highest_power];
        xs.extend(p.rated.as_ref());
        for x in xs {
            let vals = [
                x.power_w,
                x.loss_total_w,
                x.oil_temp_c,
                x.efficiency.unwrap_or(0.0),
            ];
            if vals
                .iter()
                .chain(x.loss_by_source_w.iter().map(|(_, v)| v))
                .any(|v| !v.is_finite())
            {
                return Err(bad("the losses of the plausibility check"));
            }
        }
    }
    for p in &s.profiles {
        let ends = [p.ci95_low, p.ci95_high, p.below_fit];
        if ends.iter().flatten().any(|v| !v.is_finite())
            || p.points
                .iter()
                .any(|x| !(x.value.is_finite() && x.statistic.is_finite()))
        {
            return Err(bad(&format!("the profile of {}", p.key_path)));
        }
    }
    Ok(())
}

/// The limits a calibration's options are checked against.
pub const LIMITS: [Limit; 4] = [limits::RTOL, limits::ATOL, limits::MAX_STEPS, MAX_ITERATIONS];

impl super::command::ToArgs for CalibrateOptions {
    const COMMAND: &'static str = "calibrate";
    fn to_args(&self) -> Vec<String> {
        // Each option by its name, spelled as a flag by the one rule of `options::flag`.
        let flag = super::options::flag;
        let mut a = vec![flag("trace"), self.trace.clone()];
        for t in &self.traces {
            a.extend([flag("trace"), t.clone()]);
        }
        for f in &self.fit {
            a.extend([flag("fit"), f.clone()]);
        }
        for h in &self.holdout {
            a.extend([flag("holdout"), h.clone()]);
        }
        a.extend([
            flag("rtol"),
            format!("{}", self.rtol),
            flag("atol"),
            format!("{}", self.atol),
        ]);
        a.extend([flag("max_steps"), self.max_steps.to_string()]);
        a.extend([flag("max_iterations"), self.max_iterations.to_string()]);
        if !self.initial_from_trace {
            a.push(flag("keep_initial"));
        }
        if let Some(k) = self.segment {
            a.extend([flag("segment"), k.to_string()]);
        }
        if let Some(k) = &self.segments {
            a.extend([flag("segment"), k.clone()]);
        }
        if self.refuse_missing {
            a.push(flag("refuse_missing"));
        }
        a.extend([flag("residuals"), self.residuals.clone()]);
        a.extend([flag("band_quantile"), self.band_quantile.clone()]);
        for p in &self.prior {
            a.extend([flag("prior"), p.clone()]);
        }
        for p in &self.profile {
            a.extend([flag("profile"), p.clone()]);
        }
        if let Some(k) = &self.gearbox_kind {
            a.extend([flag("gearbox_kind"), k.clone()]);
        }
        if let Some(r) = &self.rated {
            a.extend([flag("rated"), r.clone()]);
        }
        a
    }
}

/// The fit's figures for `calibration.json`: its evaluations and stop, the residual model and its
/// marginal σ (root mean square over the channels), the scale and degrees of freedom of the
/// intervals, the tolerances and the wall time since `clock`.
pub(super) fn fit_stats(
    res: &lm::LmResult,
    o: &CalibrateOptions,
    noise: &[residuals::Ar1],
    lin: &stats::Linearised,
    t: f64,
    clock: Instant,
) -> FitStats {
    let sigma2 = noise.iter().map(|a| a.marginal_sd().powi(2)).sum::<f64>();
    FitStats {
        evaluations: res.evaluations,
        iterations: res.iterations,
        stop: serde_json::to_value(res.stop)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default(),
        residual_model: o.residuals.clone(),
        sigma_k: (sigma2 / noise.len().max(1) as f64).sqrt(),
        scale: lin.sigma2.sqrt(),
        dof: lin.dof,
        t975: t,
        rtol: o.rtol,
        atol: o.atol,
        wall_time_s: clock.elapsed().as_secs_f64(),
    }
}
