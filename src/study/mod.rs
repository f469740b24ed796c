//! Design studies: a base model, parameters overridden by key path, a sampling plan, and a job
//! (drive cycles, steady points or a map) solved for every sample. A case is one sample on one
//! cycle or operating point; each yields one [`CaseRow`] (parameters, energy per source,
//! efficiency, final and max temperature per node, or the failure with its message).
//!
//! This module sits beside the CLI and the Python binding, above the use-case layer
//! ([`crate::job`]): a case is a job on the base model with the sample's overrides, solved by
//! the same job functions as `geartherm run` / `steady`. It does no writing itself; the caller
//! receives each finished case through a callback (the CLI journals it, Python collects it).

mod checks;
mod columns;
pub mod plan;
pub mod runner;
pub mod schedule_cache;
mod selection;
pub mod spec;
pub mod uq;

use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use toml::Value;

use crate::job::command::{command_line, join};
use crate::job::{self, JobError, RunOptions, SteadyOptions};
use crate::model::overrides::scaled;
use crate::model::{self, overrides, KeyPath, Override};
pub use crate::report::study::{CaseRow, ParamValue};
use crate::scene::SampleCache;
pub use columns::{run_outputs, steady_outputs};
use schedule_cache::ScheduleCache;
pub use selection::Selection;
use spec::StudySpec;

/// What one case solves.
#[derive(Debug, Clone, PartialEq)]
pub enum Job {
    /// A drive cycle with these options.
    Run(RunOptions),
    /// A steady operating point.
    Steady(SteadyOptions),
}

impl Job {
    /// Label in the table's `job` column.
    pub fn label(&self) -> String {
        match self {
            Job::Run(o) => o.cycle.clone(),
            Job::Steady(p) => format!("gear {} @ {} rpm, {} N·m", p.gear, p.speed_rpm, p.torque_nm),
        }
    }
}

/// One case: a sample on a job.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Case {
    /// Position in the study's case list.
    pub index: usize,
    /// Sample index.
    pub sample: usize,
    /// Job index.
    pub job: usize,
}

/// The overrides of a sample and the parameter values shown in its row.
pub type SampleOverrides = (Vec<Override>, Vec<(String, ParamValue)>);

/// Files of one case (name, contents), written under `cases/<id>/` when asked.
pub type CaseFiles = Vec<(String, Vec<u8>)>;

/// A loaded, checked study.
pub struct Study {
    /// The study file's contents.
    pub spec: StudySpec,
    /// The base model's text (shipped whole to remote workers).
    pub model_text: String,
    /// The base model's file name (for messages).
    pub model_file: PathBuf,
    base: model::BaseDocument,
    paths: Vec<KeyPath>,
    /// The base model's value at each parameter's path (None: not in the model).
    base_values: Vec<Option<Value>>,
    /// One value per parameter per sample.
    pub samples: Vec<Vec<ParamValue>>,
    /// The jobs every sample is solved on.
    pub jobs: Vec<Job>,
    /// Fingerprint of study and model (a journal of another study is refused).
    pub fingerprint: String,
    /// The table's output columns (the same for every case, whatever its overrides).
    pub outputs: Vec<String>,
    /// Grid points of the time series a run case keeps in its row (an uncertainty study's
    /// bands; [`crate::job::series`]); None: no series.
    pub series_points: Option<usize>,
    /// An uncertainty plan's sampled quantities and design (None for other plans).
    pub uq_plan: Option<(Vec<uq::plan::InputInfo>, uq::plan::Design)>,
    /// Per job: the per-sample loss terms of its cycle, computed by the first case solved and
    /// read by every case whose compiled bearings or converter equal that case's
    /// ([`crate::scene::SampleCache`]).
    sample_caches: Vec<OnceLock<Arc<SampleCache>>>,
    /// Per job: its cycle's schedule, computed by the first case solved and reused by every
    /// case whose vehicle, gear ratios and launch device equal that case's.
    schedules: Vec<ScheduleCache>,
}

/// FNV-1a, 64 bit: a stable fingerprint (the same on every platform and version).
pub(crate) fn fnv1a(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for &b in *p {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        h ^= 0xff;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

pub(crate) fn key_of(label: &str) -> String {
    let s: String = label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    s.chars().take(40).collect()
}

fn jobs_cache(n: usize) -> Vec<OnceLock<Arc<SampleCache>>> {
    (0..n).map(|_| OnceLock::new()).collect()
}

/// An uncertainty plan's sampled quantities and design.
type UqPlan = Option<(Vec<uq::plan::InputInfo>, uq::plan::Design)>;

/// The samples of a study's plan: an `[uncertainty]` plan (qmc, saltelli) expands its inputs
/// into the parameters (the study's `[[parameters]]` must then be empty), any other plan samples
/// the parameters.
fn sampled(
    mut spec: StudySpec,
    base: &toml::Table,
    model_file: &Path,
) -> Result<(StudySpec, Vec<Vec<ParamValue>>, UqPlan), JobError> {
    let invalid = JobError::invalid;
    match (&spec.uncertainty, spec.sampling.plan) {
        (Some(u), spec::Plan::Qmc | spec::Plan::Saltelli) => {
            if !spec.parameters.is_empty() {
                return Err(invalid(
                    "[[parameters]] and [uncertainty] together: an uncertainty plan samples its inputs only",
                ));
            }
            let e = uq::plan::expand(u, &spec.sampling, base, model_file)?;
            spec.parameters = e.params;
            Ok((spec, e.samples, Some((e.inputs, e.design))))
        }
        (Some(_), _) => Err(invalid(
            "[uncertainty] needs sampling.plan = \"qmc\" or \"saltelli\" (its inputs are sampled from their distributions)",
        )),
        (None, _) => {
            let s = plan::samples(&spec.parameters, &spec.sampling).map_err(JobError::invalid)?;
            Ok((spec, s, None))
        }
    }
}

impl Study {
    /// Read a study file; its `study.model` is resolved relative to the study file. Every
    /// message after the first line names the study file.
    pub fn from_file(path: &Path) -> Result<Study, JobError> {
        let text = job::read_text(path)?;
        let de = toml::de::Deserializer::parse(&text)
            .map_err(|e| JobError::invalid(format!("{}: {}", path.display(), e.message())))?;
        let spec: StudySpec = serde_path_to_error::deserialize(de).map_err(|e| {
            let at = e.path().to_string();
            let msg = e.inner().message().to_string();
            JobError::invalid(format!("{}: {at}: {msg}", path.display()))
        })?;
        let model_path = path.parent().unwrap_or(Path::new(".")).join(&spec.study.model);
        let model_text = job::read_text(&model_path)?;
        Study::new(spec, model_text, model_path).map_err(|e| match e.kind {
            job::ErrorKind::Io => e,
            _ => e.prefixed(&path.display().to_string()),
        })
    }

    /// Check a study given as values: the base model must validate, every parameter path must
    /// exist in the model (or be accepted by its schema), the plan must be well formed.
    pub fn new(spec: StudySpec, model_text: String, model_file: PathBuf) -> Result<Study, JobError> {
        let invalid = JobError::invalid;
        checks::check_name(&spec.study.name).map_err(invalid)?;
        let base_model = job::Model::from_text(&model_text, &model_file, &[])?;
        let mut problems = model::Problems::default();
        let base = model::parse::parse_document(&model_text, &mut problems)
            .ok_or_else(|| invalid(format!("{}: not a TOML document", model_file.display())))?;
        let (spec, samples, uq_plan) = sampled(spec, &base, &model_file)?;
        let paths = checks::parameter_paths(&spec.parameters)?;
        checks::paths_in_schema(
            &spec.parameters,
            &paths,
            &samples,
            &base,
            &model_text,
            &model_file,
        )?;
        let jobs = checks::jobs_of(&spec.job).map_err(invalid)?;
        let jobs_len = jobs.len();
        if samples.len().saturating_mul(jobs.len()) > plan::MAX_SAMPLES {
            return Err(invalid(format!(
                "{} samples × {} jobs: more than {} cases",
                samples.len(),
                jobs.len(),
                plan::MAX_SAMPLES
            )));
        }
        checks::check_jobs(&spec.job, &jobs, &base_model)?;
        checks::check_distinct_cycles(&jobs).map_err(invalid)?;
        let outputs = columns::output_columns(&jobs, &base_model)?;
        checks::check_outputs(&spec.outputs, &outputs)?;
        let base_values = paths.iter().map(|p| overrides::get(&base, p).ok()).collect();
        let spec_json = serde_json::to_string(&spec).map_err(|e| invalid(e.to_string()))?;
        let fingerprint = format!("{:016x}", fnv1a(&[spec_json.as_bytes(), model_text.as_bytes()]));
        Ok(Study {
            spec,
            model_text,
            model_file,
            base: model::BaseDocument::new(base),
            paths,
            base_values,
            samples,
            jobs,
            fingerprint,
            outputs,
            series_points: None,
            uq_plan,
            sample_caches: jobs_cache(jobs_len),
            schedules: (0..jobs_len).map(|_| ScheduleCache::default()).collect(),
        })
    }

    /// Every case, sample-major.
    pub fn cases(&self) -> Vec<Case> {
        let nj = self.jobs.len();
        (0..self.samples.len() * nj)
            .map(|index| Case {
                index,
                sample: index / nj,
                job: index % nj,
            })
            .collect()
    }

    /// The cases of shard `i` of `n` (every n-th case from i; i from 0).
    pub fn shard(&self, i: usize, n: usize) -> Vec<Case> {
        self.cases()
            .into_iter()
            .filter(|c| c.index % n.max(1) == i)
            .collect()
    }

    /// Case id: `<sample>-<job>` (usable as a directory name).
    pub fn case_id(&self, c: &Case) -> String {
        let job = match &self.jobs[c.job] {
            Job::Run(o) => checks::cycle_key(&o.cycle),
            Job::Steady(_) => format!("p{:04}", c.job),
        };
        format!("{:06}-{job}", c.sample)
    }

    /// Column name of parameter `j` (a scale parameter's value is the factor).
    pub fn column(&self, j: usize) -> String {
        let p = &self.spec.parameters[j];
        if p.scale.is_some() || p.factors {
            format!("{} (scale)", p.path)
        } else {
            p.path.clone()
        }
    }

    /// The overrides of a sample, and the parameter values actually used (integers rounded).
    pub fn overrides(&self, sample: usize) -> Result<SampleOverrides, String> {
        let mut ovs = Vec::new();
        let mut used = Vec::new();
        for (j, v) in self.samples[sample].iter().enumerate() {
            let p = &self.spec.parameters[j];
            let base = self.base_values[j].clone();
            let (value, shown) = match v {
                ParamValue::Text(s) => (Value::String(s.clone()), v.clone()),
                ParamValue::Number(f) if p.scale.is_some() || p.factors => {
                    let b = base.ok_or_else(|| format!("{}: not in the model", p.path))?;
                    (scaled(&b, *f).map_err(|e| format!("{}: {e}", p.path))?, v.clone())
                }
                ParamValue::Number(f) => match base {
                    Some(Value::Integer(_)) => {
                        (Value::Integer(f.round() as i64), ParamValue::Number(f.round()))
                    }
                    _ => (Value::Float(*f), v.clone()),
                },
            };
            ovs.push(Override {
                path: self.paths[j].clone(),
                value,
            });
            used.push((self.column(j), shown));
        }
        Ok((ovs, used))
    }

    /// The job a case runs: a run job is summary-only unless per-case files are asked for.
    pub fn case_job(&self, c: &Case, per_case: bool) -> Job {
        match &self.jobs[c.job] {
            Job::Run(o) => Job::Run(RunOptions {
                summary_only: !per_case,
                ..o.clone()
            }),
            other => other.clone(),
        }
    }

    /// The equivalent stand-alone command of a case (for job arrays without Python), rendered
    /// from the options the case runs with.
    pub fn command_line(&self, c: &Case) -> String {
        let per_case = self.spec.outputs.per_case;
        match self.overrides(c.sample) {
            Ok((ovs, _)) => match self.case_job(c, per_case) {
                Job::Run(o) => command_line(&self.model_file, &ovs, &o),
                Job::Steady(p) => command_line(&self.model_file, &ovs, &p),
            },
            Err(e) => format!(
                "{}  # {e}",
                join(&["geartherm".into(), self.model_file.display().to_string()])
            ),
        }
    }

    /// Solve one case. Never fails: a failure is a row with status `invalid` or `failed` and
    /// its message. With `per_case`, the run's files are returned too.
    pub fn run_case(&self, c: &Case, per_case: bool) -> (CaseRow, CaseFiles) {
        let mut row = CaseRow {
            case: self.case_id(c),
            sample: c.sample,
            job: self.jobs[c.job].label(),
            params: Vec::new(),
            status: "ok".into(),
            message: String::new(),
            outputs: Vec::new(),
            series: None,
        };
        let result =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| self.solve(c, per_case, &mut row)));
        let outcome = result.unwrap_or_else(|p| {
            let what = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(JobError::numerical(format!("internal error (panic): {what}")))
        });
        match outcome {
            Ok(files) => (row, files),
            Err(e) => {
                row.status = if e.is_invalid() { "invalid" } else { "failed" }.into();
                row.message = e.to_string();
                row.outputs.clear();
                row.series = None;
                (row, Vec::new())
            }
        }
    }

    /// Whether a sample's row keeps the band series (with [`Study::series_points`]): every
    /// sample but the mixed rows of Saltelli's design, which serve the Sobol indices only.
    fn keeps_series(&self, sample: usize) -> bool {
        match &self.uq_plan {
            Some((_, d)) => d.is_draw(sample),
            None => true,
        }
    }

    fn solve(&self, c: &Case, per_case: bool, row: &mut CaseRow) -> Result<CaseFiles, JobError> {
        let (ovs, used) = self.overrides(c.sample).map_err(JobError::invalid)?;
        row.params = used;
        let m = job::Model::from_base(&self.base, &self.model_file, &ovs)?;
        match self.case_job(c, per_case) {
            Job::Run(o) => {
                let schedule = |gb: &model::gearbox::Gearbox, cycle: &crate::cycle::DriveCycle| {
                    self.schedules[c.job].segments(gb, cycle)
                };
                let mut p = job::run::prepare_with(&m, &o, &schedule)?;
                // A table row keeps no range warnings: only a case's own summary.json shows them.
                p.range_warnings = per_case;
                if !o.evaluate_all {
                    let cache = self.sample_caches[c.job]
                        .get_or_init(|| Arc::new(p.scene.sample_cache(p.segs.iter().map(|s| s.inputs))));
                    p.scene.use_sample_cache(Arc::clone(cache));
                }
                let r = match self.series_points.filter(|_| self.keeps_series(c.sample)) {
                    Some(points) => {
                        let (r, s) = job::series::solve_with_series(&m, &p, points)?;
                        row.series = Some(uq::run::rounded(&s));
                        r
                    }
                    None => job::run::solve(&m, &p, &mut |_, _| {})?,
                };
                row.outputs = run_outputs(&r.summary);
                let files = if per_case { r.files()? } else { Vec::new() };
                Ok(files.into_iter().map(|(n, b)| (n.to_string(), b)).collect())
            }
            Job::Steady(p) => {
                let r = job::steady::steady(&m, &p)?;
                row.outputs = steady_outputs(&r);
                let mut files = Vec::new();
                if per_case {
                    let json = serde_json::to_vec_pretty(&r)
                        .map_err(|e| JobError::numerical(format!("cannot serialise steady.json: {e}")))?;
                    files.push(("steady.json".to_string(), json));
                }
                Ok(files)
            }
        }
    }
}
