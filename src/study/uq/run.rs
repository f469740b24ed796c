//! The uncertainty study `geartherm uq`, `Model.uq` in Python: its options and their checks, and
//! the study it is underneath. The uncertain inputs (the model's `[uncertainty]`, the inputs
//! given instead, a calibration's covariance) become a study whose plan samples them
//! ([`super::plan`]); every case is one run of the cycle (or one steady point) solved by the
//! study runner — the same selection, journal, resume and shards as `geartherm study` — and a
//! run case keeps its node temperatures and energies per source on a fixed time grid in its
//! journal row for the bands.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::job::{self, JobError, RunOptions, SteadyOptions};
use crate::study::spec::{JobSpec, Meta, OutputSpec, Plan, Sampling, StudySpec};
use crate::study::{Job, Study};

use super::plan::{Design, InputInfo, MAX_UQ_SAMPLES};
use crate::model::uncertainty::{calibration_block, CalibrationSpec, UncertaintySpec};

/// Default number of samples (N; Saltelli's design runs N(d + 2)).
pub const DEFAULT_SAMPLES: usize = 1000;

/// Default grid points of the band time series.
pub const DEFAULT_SERIES_POINTS: usize = 201;

/// Default percentiles, %.
pub const DEFAULT_PERCENTILES: [f64; 3] = [5.0, 50.0, 95.0];

/// Most bootstrap resamples of the Sobol indices.
pub const MAX_BOOTSTRAP: usize = 10_000;

/// A temperature limit: the probability that the node's highest temperature over the cycle (its
/// temperature at a steady point) exceeds it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Limit {
    /// Thermal node.
    pub node: String,
    /// Limit, °C.
    pub temp_c: f64,
}

/// What every sample is solved on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum UqJob {
    /// A drive cycle.
    Run(RunOptions),
    /// A steady operating point.
    Steady(SteadyOptions),
}

/// Options of an uncertainty study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct UqOptions {
    /// The job every sample is solved on (None: a study file's first cycle or point, else the
    /// WLTC).
    pub job: Option<UqJob>,
    /// Samples N (Saltelli's design: base points; None: a study file's `sampling.cases`, else
    /// the inputs' `uncertainty.samples`, else [`DEFAULT_SAMPLES`]).
    pub samples: Option<usize>,
    /// Seed of the scrambled Sobol' points and the bootstrap (None: a study file's, else 1).
    pub seed: Option<u64>,
    /// Saltelli's design and Sobol indices (also with a study file's `plan = "saltelli"`).
    pub sobol: bool,
    /// Percentiles of the bands, %, each in (0, 100).
    pub percentiles: Vec<f64>,
    /// Temperature limits.
    pub limits: Vec<Limit>,
    /// Grid points of the band time series.
    pub series_points: usize,
    /// Confidence level of the intervals (exceedance probability, Sobol indices).
    pub confidence: f64,
    /// Bootstrap resamples of the Sobol indices.
    pub bootstrap: usize,
    /// The uncertain inputs instead of the model's `[uncertainty]` (None: the model's).
    pub inputs: Option<UncertaintySpec>,
    /// A calibration's fitted parameters and covariance, sampled jointly besides the inputs.
    pub calibration: Option<CalibrationSpec>,
}

impl Default for UqOptions {
    fn default() -> Self {
        UqOptions {
            job: None,
            samples: None,
            seed: None,
            sobol: false,
            percentiles: DEFAULT_PERCENTILES.to_vec(),
            limits: Vec::new(),
            series_points: DEFAULT_SERIES_POINTS,
            confidence: 0.95,
            bootstrap: 200,
            inputs: None,
            calibration: None,
        }
    }
}

fn option_error(name: &str, value: impl std::fmt::Display, allowed: &str) -> JobError {
    JobError::option(name, &value, allowed, format!("{name} = {value}: {allowed}"))
}

impl UqOptions {
    /// Every range check of the options that needs no model (the job's own, the sample count,
    /// percentiles, limits' values, confidence, bootstrap, series points).
    pub fn check(&self) -> Result<(), JobError> {
        match &self.job {
            Some(UqJob::Run(o)) => {
                o.check()?;
            }
            Some(UqJob::Steady(p)) => p.check()?,
            None => {}
        }
        if let Some(n) = self.samples.filter(|&n| n == 0 || n > MAX_UQ_SAMPLES) {
            return Err(option_error(
                "samples",
                n,
                &format!("must lie in [1, {MAX_UQ_SAMPLES}]"),
            ));
        }
        super::stats::quantiles::check_percentiles(&self.percentiles).map_err(|e| {
            let shown: Vec<String> = self.percentiles.iter().map(f64::to_string).collect();
            let message = if e.starts_with('[') {
                format!("percentiles{e}")
            } else {
                format!("percentiles: {e}")
            };
            JobError::option(
                "percentiles",
                shown.join(","),
                "increasing, each in (0, 100)",
                message,
            )
        })?;
        for l in &self.limits {
            if !(l.temp_c.is_finite() && l.temp_c > -273.15 && l.temp_c < 2000.0) {
                return Err(option_error(
                    "limit",
                    format!("{}={}", l.node, l.temp_c),
                    "a temperature in (-273.15, 2000) °C",
                ));
            }
        }
        if !(self.confidence > 0.5 && self.confidence < 1.0) {
            return Err(option_error(
                "confidence",
                self.confidence,
                "must lie in (0.5, 1)",
            ));
        }
        if self.bootstrap > MAX_BOOTSTRAP {
            return Err(option_error(
                "bootstrap",
                self.bootstrap,
                &format!("must lie in [0, {MAX_BOOTSTRAP}]"),
            ));
        }
        let (lo, hi) = job::series::POINTS;
        if !(lo..=hi).contains(&self.series_points) {
            return Err(option_error(
                "series_points",
                self.series_points,
                &format!("must lie in [{lo}, {hi}]"),
            ));
        }
        Ok(())
    }
}

/// A checked uncertainty study, ready to run.
pub struct Uq {
    /// The study underneath (its cases, journal fingerprint, runner).
    pub study: Study,
    /// The options, every `None` resolved.
    pub options: UqOptions,
    /// The job.
    pub job_kind: UqJob,
    /// Seed.
    pub seed: u64,
    /// The sampled quantities.
    pub inputs: Vec<InputInfo>,
    /// The design.
    pub design: Design,
    /// Band series names (`temp_<node>_c`, `energy_<source>_j`); empty for a steady point.
    pub series_names: Vec<String>,
    /// Band grid times, s; empty for a steady point.
    pub times_s: Vec<f64>,
    /// Thermal nodes of the model.
    pub nodes: Vec<String>,
    /// The model's name.
    pub model_name: String,
}

/// The `[uncertainty]` of a model document, if any (checked as the study file's).
fn model_uncertainty(base: &toml::Table) -> Result<Option<UncertaintySpec>, JobError> {
    let Some(u) = base.get("uncertainty") else {
        return Ok(None);
    };
    let de = u.clone();
    serde_path_to_error::deserialize(de)
        .map(Some)
        .map_err(|e| JobError::invalid(format!("uncertainty.{}: {}", e.path(), e.inner().message())))
}

/// A calibration's block read from a file (`calibrated.toml` with its `# [calibration]` comment
/// block, or a TOML file with a `[calibration]` table).
pub fn read_calibration(path: &Path) -> Result<CalibrationSpec, JobError> {
    let text = job::read_text(path)?;
    calibration_block(&text)
        .map_err(|e| JobError::invalid(format!("{}: {e}", path.display())))?
        .ok_or_else(|| {
            JobError::invalid(format!(
                "{}: no calibration covariance (the `# [calibration]` block `geartherm calibrate` writes at the end of \
                 calibrated.toml, or a [calibration] table)",
                path.display()
            ))
        })
}

/// What a study file gives an uncertainty study: its model, its `[uncertainty]`, its first job,
/// its sample count, seed and plan (each used where the options leave it open).
struct FromStudy {
    model: PathBuf,
    uncertainty: Option<UncertaintySpec>,
    job: Option<UqJob>,
    sampling: Sampling,
}

/// A study file (a TOML file with a `[study]` table), parsed; None for a model file.
fn study_file(path: &Path, text: &str) -> Result<Option<FromStudy>, JobError> {
    let is_study = text.parse::<toml::Table>().is_ok_and(|t| t.contains_key("study"));
    if !is_study {
        return Ok(None);
    }
    let at = |e: String| JobError::invalid(format!("{}: {e}", path.display()));
    let de = toml::de::Deserializer::parse(text).map_err(|e| at(e.message().to_string()))?;
    let spec: StudySpec = serde_path_to_error::deserialize(de)
        .map_err(|e| at(format!("{}: {}", e.path(), e.inner().message())))?;
    if !spec.parameters.is_empty() {
        return Err(at(
            "[[parameters]]: an uncertainty study samples its [uncertainty] inputs only".into(),
        ));
    }
    let job = match &spec.job {
        JobSpec::Run { cycles, options } => cycles.first().map(|c| {
            UqJob::Run(RunOptions {
                cycle: c.clone(),
                summary_only: true,
                ..options.clone().unwrap_or_default()
            })
        }),
        JobSpec::Steady { points } => points.first().cloned().map(UqJob::Steady),
        JobSpec::Map { .. } => {
            return Err(at(
                "job.kind = map: an uncertainty study solves one cycle or one point".into(),
            ))
        }
    };
    Ok(Some(FromStudy {
        model: path.parent().unwrap_or(Path::new(".")).join(&spec.study.model),
        uncertainty: spec.uncertainty,
        job,
        sampling: spec.sampling,
    }))
}

impl Uq {
    /// Read a model file (its `[uncertainty]`) or a study file (its model, `[uncertainty]`,
    /// first job and `[sampling]`) and check the study.
    pub fn from_file(path: &Path, mut options: UqOptions) -> Result<Uq, JobError> {
        let text = job::read_text(path)?;
        let Some(s) = study_file(path, &text)? else {
            return Uq::new(text, path.to_path_buf(), options);
        };
        options.job = options.job.or(s.job);
        options.samples = options.samples.or(s.sampling.cases);
        options.seed = options.seed.or(Some(s.sampling.seed));
        options.sobol |= s.sampling.plan == Plan::Saltelli;
        if options.inputs.is_none() {
            options.inputs = s.uncertainty;
        }
        let model_text = job::read_text(&s.model)?;
        Uq::new(model_text, s.model, options).map_err(|e| match e.kind {
            job::ErrorKind::Io => e,
            _ if e.message.starts_with("uncertainty") => e.prefixed(&path.display().to_string()),
            _ => e,
        })
    }

    /// Check the options and the uncertain inputs against the model, draw the plan.
    pub fn new(model_text: String, model_file: PathBuf, mut options: UqOptions) -> Result<Uq, JobError> {
        options.check()?;
        let job_kind = options.job.clone().unwrap_or_else(|| {
            UqJob::Run(RunOptions {
                summary_only: true,
                ..RunOptions::default()
            })
        });
        options.job = Some(job_kind.clone());
        let seed = options.seed.unwrap_or(1);
        options.seed = Some(seed);
        let base_model = job::Model::from_text(&model_text, &model_file, &[])?;
        let mut problems = crate::model::Problems::default();
        let base = crate::model::parse::parse_document(&model_text, &mut problems)
            .ok_or_else(|| JobError::invalid(format!("{}: not a TOML document", model_file.display())))?;
        let in_model = options.inputs.is_none();
        let mut u = match &options.inputs {
            Some(u) => u.clone(),
            None => model_uncertainty(&base)
                .map_err(|e| e.prefixed(&model_file.display().to_string()))?
                .unwrap_or_default(),
        };
        if options.calibration.is_some() {
            u.calibration = options.calibration.clone();
        }
        options.samples = Some(options.samples.or(u.samples).unwrap_or(DEFAULT_SAMPLES));
        let spec = spec_of(&options, &job_kind, seed, u, &base_model);
        let label = model_file.display().to_string();
        let mut study = Study::new(spec, model_text, model_file).map_err(|e| match e.kind {
            job::ErrorKind::Io => e,
            _ if in_model && e.message.starts_with("uncertainty") => e.prefixed(&label),
            _ => e,
        })?;
        let (inputs, design) = study
            .uq_plan
            .clone()
            .ok_or_else(|| JobError::invalid("uncertainty: no plan"))?;
        let (series_names, times_s, nodes) = grid_of(&base_model, &job_kind, options.series_points)?;
        check_limits(&options, &nodes)?;
        if let UqJob::Run(_) = job_kind {
            study.series_points = Some(options.series_points);
        }
        // A journal of the same inputs with another series grid is another study.
        study.fingerprint = format!(
            "{:016x}",
            crate::study::fnv1a(&[study.fingerprint.as_bytes(), &options.series_points.to_le_bytes()])
        );
        Ok(Uq {
            study,
            options,
            job_kind,
            seed,
            inputs,
            design,
            series_names,
            times_s,
            nodes,
            model_name: base_model.gearbox.name.clone(),
        })
    }
}

/// The study file the options amount to.
fn spec_of(o: &UqOptions, job: &UqJob, seed: u64, u: UncertaintySpec, base: &job::Model) -> StudySpec {
    let job = match job {
        UqJob::Run(r) => JobSpec::Run {
            cycles: vec![r.cycle.clone()],
            options: Some(r.clone()),
        },
        UqJob::Steady(p) => JobSpec::Steady {
            points: vec![p.clone()],
        },
    };
    let stem = crate::study::key_of(&base.stem());
    StudySpec {
        study: Meta {
            name: format!("uq_{stem}"),
            model: String::new(),
        },
        job,
        sampling: Sampling {
            plan: if o.sobol { Plan::Saltelli } else { Plan::Qmc },
            cases: o.samples,
            seed,
        },
        parameters: Vec::new(),
        uncertainty: Some(u),
        outputs: OutputSpec::default(),
    }
}

/// Series names, grid times, node names.
type Grid = (Vec<String>, Vec<f64>, Vec<String>);

/// Series names, grid times and node names of the base model on the job.
fn grid_of(base: &job::Model, job: &UqJob, points: usize) -> Result<Grid, JobError> {
    match job {
        UqJob::Run(r) => {
            let p = job::run::prepare(base, r)?;
            let t0 = p.segs.first().map_or(0.0, |s| s.t0);
            let t1 = p.segs.last().map_or(0.0, |s| s.t1);
            let nodes = p.scene.thermal().names.clone();
            Ok((
                job::series::names(&p.scene),
                job::series::grid(t0, t1, points),
                nodes,
            ))
        }
        UqJob::Steady(s) => {
            base.state(&s.gear)?;
            let scene = base.compile(&crate::scene::Needs::default())?;
            Ok((Vec::new(), Vec::new(), scene.thermal().names.clone()))
        }
    }
}

fn check_limits(o: &UqOptions, nodes: &[String]) -> Result<(), JobError> {
    for l in &o.limits {
        if !nodes.contains(&l.node) {
            return Err(JobError::option(
                "limit",
                &l.node,
                nodes.join(", "),
                format!(
                    "limit = {}={}: no thermal node `{}`; the model has: {}",
                    l.node,
                    l.temp_c,
                    l.node,
                    nodes.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// A run's series rounded for the journal: temperatures to 0.001 °C, energies to 0.1 J.
pub fn rounded(s: &job::series::RunSeries) -> Vec<Vec<f64>> {
    s.names
        .iter()
        .zip(&s.values)
        .map(|(n, v)| {
            let step = if n.starts_with("temp_") { 1e3 } else { 1e1 };
            v.iter().map(|x| (x * step).round() / step).collect()
        })
        .collect()
}

impl Uq {
    /// The job of the study's single job slot.
    pub fn job(&self) -> &Job {
        &self.study.jobs[0]
    }
}
