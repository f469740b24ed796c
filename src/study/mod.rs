//! Design studies: a base model, parameters overridden by key path, a sampling plan, and a job
//! (drive cycles, steady points or a map) solved for every sample. A case is one sample on one
//! cycle or operating point; each yields one [`CaseRow`] (parameters, energy per source,
//! efficiency, final and max temperature per node, or the failure with its message).
//!
//! This module sits beside the CLI and the Python binding, above the use-case layer
//! ([`crate::job`]): a case is a job on the base model with the sample's overrides, solved by
//! the same job functions as `geartherm run` / `steady`. It does no writing itself; the caller
//! receives each finished case through a callback (the CLI journals it, Python collects it).

pub mod plan;
pub mod runner;
pub mod spec;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use toml::Value;

use crate::job::command::{command_line, join};
use crate::job::{self, JobError, RunOptions, SteadyOptions};
use crate::model::{self, overrides, KeyPath, Override};
pub use crate::report::study::{CaseRow, ParamValue};
use spec::{JobSpec, StudySpec};

/// A study that cannot start: unreadable or invalid study file, invalid base model, bad
/// parameter.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// File.
        file: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// Invalid study (the message names the file and key path).
    #[error("{0}")]
    Invalid(String),
    /// A job option, cycle or model that the job layer refuses (its kind sets the exit code).
    #[error("{0}")]
    Job(JobError),
}

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
    base: toml::Table,
    paths: Vec<KeyPath>,
    /// One value per parameter per sample.
    pub samples: Vec<Vec<ParamValue>>,
    /// The jobs every sample is solved on.
    pub jobs: Vec<Job>,
    /// Fingerprint of study and model (a journal of another study is refused).
    pub fingerprint: String,
    /// The table's output columns (the same for every case, whatever its overrides).
    pub outputs: Vec<String>,
}

/// FNV-1a, 64 bit: a stable fingerprint (the same on every platform and version).
fn fnv1a(parts: &[&[u8]]) -> u64 {
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

fn key_of(label: &str) -> String {
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

fn jobs_of(spec: &JobSpec) -> Result<Vec<Job>, String> {
    let jobs: Vec<Job> = match spec {
        JobSpec::Run { cycles, options } => cycles
            .iter()
            .map(|c| {
                Job::Run(RunOptions {
                    cycle: c.clone(),
                    ..options.clone().unwrap_or_default()
                })
            })
            .collect(),
        JobSpec::Steady { points } => points.iter().cloned().map(Job::Steady).collect(),
        JobSpec::Map {
            gear,
            speed_rpm,
            torque_nm,
            vehicle_speed_kmh,
        } => map_jobs(job::MapOptions {
            gear: gear.clone(),
            speed_rpm: speed_rpm.clone(),
            torque_nm: torque_nm.clone(),
            vehicle_speed_kmh: *vehicle_speed_kmh,
            ambient_c: None,
        })?,
    };
    if jobs.is_empty() {
        return Err("job: no cycles or points".into());
    }
    Ok(jobs)
}

/// A map job's points, one steady job each; the grid's size and values are checked as
/// `geartherm map` checks them, before its points are built.
fn map_jobs(grid: job::MapOptions) -> Result<Vec<Job>, String> {
    grid.check().map_err(|e| format!("job: {}", e.message))?;
    let point = |s: f64, t: f64| {
        Job::Steady(SteadyOptions {
            gear: grid.gear.clone(),
            speed_rpm: s,
            torque_nm: t,
            vehicle_speed_kmh: grid.vehicle_speed_kmh,
            ambient_c: None,
        })
    };
    Ok(grid
        .speed_rpm
        .iter()
        .flat_map(|&s| grid.torque_nm.iter().map(move |&t| (s, t)))
        .map(|(s, t)| point(s, t))
        .collect())
}

/// A study's name names its default output directory (`studies/<name>`): a plain name
/// ([`model::parse::is_plain_name`]) that is one path component, neither `.` nor `..`.
fn check_name(name: &str) -> Result<(), String> {
    if model::parse::is_plain_name(name) && !name.contains('/') && name != "." && name != ".." {
        return Ok(());
    }
    Err(format!(
        "study.name = {name:?}: must be a plain name usable as a directory name: 1–{} characters, \
         no `/`, no control characters, none of , \" ' | \\ ; `, not `.` or `..`",
        model::parse::MAX_NAME_LEN
    ))
}

/// Run jobs whose cycles give one case-id key (the same cycle twice, or two files with one
/// name) would share case ids, and a resumed study would take one for the other.
fn check_distinct_cycles(jobs: &[Job]) -> Result<(), String> {
    let mut seen = std::collections::BTreeMap::new();
    for (k, j) in jobs.iter().enumerate() {
        if let Job::Run(o) = j {
            if let Some(first) = seen.insert(cycle_key(&o.cycle), k) {
                return Err(format!(
                    "job.cycles[{first}] and job.cycles[{k}] ({}) give the same case id `{}`: \
                     each cycle once, with distinct file names",
                    o.cycle,
                    cycle_key(&o.cycle)
                ));
            }
        }
    }
    Ok(())
}

/// The case-id key of a cycle: its file stem, made a plain directory-name part.
fn cycle_key(cycle: &str) -> String {
    key_of(
        Path::new(cycle)
            .file_stem()
            .map_or(cycle, |s| s.to_str().unwrap_or("cycle")),
    )
}

/// Every job's options checked before any case runs (their ranges, the cycles read, the gear
/// states known to the base model): a study with a bad option fails at once, not per case. The
/// message is the job layer's, after the key path of the job in the study file.
fn check_jobs(spec: &JobSpec, jobs: &[Job], base: &job::Model) -> Result<(), StudyError> {
    let mut cycles_seen = std::collections::BTreeSet::new();
    for (k, j) in jobs.iter().enumerate() {
        match j {
            Job::Run(o) => {
                let at = |key: String| move |e: JobError| StudyError::Job(e.prefixed(&key));
                o.check().map_err(at("job.options".into()))?;
                if cycles_seen.insert(o.cycle.clone()) {
                    crate::cycle::DriveCycle::resolve(&o.cycle)
                        .map_err(|e| at(format!("job.cycles[{k}]"))(e.into()))?;
                }
            }
            Job::Steady(p) => {
                let key = match spec {
                    JobSpec::Steady { .. } => format!("job.points[{k}]"),
                    _ => "job".to_string(),
                };
                let at = |e: JobError| StudyError::Job(e.prefixed(&key));
                p.check().map_err(at)?;
                base.state(&p.gear).map_err(at)?;
            }
        }
    }
    Ok(())
}

/// The table's output columns for `jobs` on the base model (the same names
/// [`run_outputs`] and [`steady_outputs`] give each row).
fn output_columns(jobs: &[Job], base: &job::Model) -> Result<Vec<String>, StudyError> {
    let scene = base
        .compile(&crate::scene::Needs::default())
        .map_err(StudyError::Job)?;
    let nodes = &scene.thermal.names;
    let sources = crate::scene::Source::ALL.map(|s| s.as_str());
    let mut cols = Vec::new();
    if jobs.iter().any(|j| matches!(j, Job::Run(_))) {
        cols.extend(sources.iter().map(|s| format!("energy_{s}_j")));
        cols.extend(
            [
                "energy_total_j",
                "output_energy_j",
                "cycle_efficiency",
                "energy_efficiency",
            ]
            .map(String::from),
        );
        for n in nodes {
            cols.push(format!("temp_final_{n}_c"));
            cols.push(format!("temp_max_{n}_c"));
        }
    }
    if jobs.iter().any(|j| matches!(j, Job::Steady(_))) {
        cols.extend(sources.iter().map(|s| format!("loss_{s}_w")));
        cols.extend(["loss_total_w", "efficiency"].map(String::from));
        cols.extend(nodes.iter().map(|n| format!("temp_{n}_c")));
    }
    Ok(cols)
}

/// Every column `[outputs]` names exists in the table.
fn check_outputs(o: &spec::OutputSpec, columns: &[String]) -> Result<(), StudyError> {
    let named = o.effects.iter().flatten().map(|n| ("outputs.effects", n));
    let pareto = o.pareto.iter().flatten().map(|n| ("outputs.pareto", n));
    for (key, name) in named.chain(pareto) {
        if !columns.contains(name) {
            return Err(StudyError::Invalid(format!(
                "{key}: no output column `{name}`; the table has: {}",
                columns.join(", ")
            )));
        }
    }
    Ok(())
}

/// Scale a number or (nested) array of numbers.
fn scaled(v: &Value, f: f64) -> Result<Value, String> {
    match v {
        Value::Integer(i) => Ok(Value::Float(*i as f64 * f)),
        Value::Float(x) => Ok(Value::Float(x * f)),
        Value::Array(a) => a
            .iter()
            .map(|x| scaled(x, f))
            .collect::<Result<Vec<_>, _>>()
            .map(Value::Array),
        other => Err(format!(
            "a scale parameter needs a number or an array of numbers, found {other}"
        )),
    }
}

impl Study {
    /// Read a study file; its `study.model` is resolved relative to the study file.
    pub fn from_file(path: &Path) -> Result<Study, StudyError> {
        let io = |file: &Path| {
            let file = file.to_path_buf();
            move |source| StudyError::Io { file, source }
        };
        let text = std::fs::read_to_string(path).map_err(io(path))?;
        let de = toml::de::Deserializer::parse(&text)
            .map_err(|e| StudyError::Invalid(format!("{}: {}", path.display(), e.message())))?;
        let spec: StudySpec = serde_path_to_error::deserialize(de).map_err(|e| {
            let at = e.path().to_string();
            let msg = e.inner().message().to_string();
            StudyError::Invalid(format!("{}: {at}: {msg}", path.display()))
        })?;
        let model_path = path.parent().unwrap_or(Path::new(".")).join(&spec.study.model);
        let model_text = std::fs::read_to_string(&model_path).map_err(io(&model_path))?;
        Study::new(spec, model_text, model_path).map_err(|e| match e {
            StudyError::Invalid(m) => StudyError::Invalid(format!("{}: {m}", path.display())),
            StudyError::Job(j) => StudyError::Job(j.prefixed(&path.display().to_string())),
            other => other,
        })
    }

    /// Check a study given as values: the base model must validate, every parameter path must
    /// exist in the model (or be accepted by its schema), the plan must be well formed.
    pub fn new(spec: StudySpec, model_text: String, model_file: PathBuf) -> Result<Study, StudyError> {
        let invalid = StudyError::Invalid;
        check_name(&spec.study.name).map_err(invalid)?;
        let base_model =
            job::Model::from_text(&model_text, &model_file, &[]).map_err(|e| invalid(e.message))?;
        let mut problems = model::Problems::default();
        let base = model::parse::parse_document(&model_text, &mut problems)
            .ok_or_else(|| invalid(format!("{}: not a TOML document", model_file.display())))?;
        if spec.parameters.is_empty() {
            return Err(invalid("no [[parameters]]".into()));
        }
        let mut paths = Vec::new();
        for (k, p) in spec.parameters.iter().enumerate() {
            let path: KeyPath = p
                .path
                .parse()
                .map_err(|e| invalid(format!("parameters[{k}].path `{}`: {e}", p.path)))?;
            if let Some(j) = paths.iter().position(|q| *q == path) {
                return Err(invalid(format!(
                    "parameters[{k}].path `{}`: given twice (parameters[{j}] varies it already); each key path once",
                    p.path
                )));
            }
            paths.push(path);
        }
        let samples = plan::samples(&spec.parameters, &spec.sampling).map_err(invalid)?;
        for (k, (p, path)) in spec.parameters.iter().zip(&paths).enumerate() {
            let Err(e) = overrides::get(&base, path) else {
                continue;
            };
            if p.scale.is_some() {
                return Err(invalid(format!("parameters[{k}].path: {e}")));
            }
            // Not written in the model: accepted when the schema takes it (probed with the
            // first sample's value).
            let value = match samples.first().map(|s| &s[k]) {
                Some(ParamValue::Text(t)) => Value::String(t.clone()),
                Some(ParamValue::Number(x)) => Value::Float(*x),
                None => continue,
            };
            let probe = Override {
                path: path.clone(),
                value,
            };
            if let Err(e) = model::from_str_with(&model_text, &model_file, &[probe]) {
                let r = e.report();
                if r.contains("unknown") || r.contains("has no") || r.contains("not a table") {
                    return Err(invalid(format!("parameters[{k}].path `{}`: {r}", p.path)));
                }
            }
        }
        let jobs = jobs_of(&spec.job).map_err(invalid)?;
        if samples.len().saturating_mul(jobs.len()) > plan::MAX_SAMPLES {
            return Err(invalid(format!(
                "{} samples × {} jobs: more than {} cases",
                samples.len(),
                jobs.len(),
                plan::MAX_SAMPLES
            )));
        }
        check_jobs(&spec.job, &jobs, &base_model)?;
        check_distinct_cycles(&jobs).map_err(invalid)?;
        let outputs = output_columns(&jobs, &base_model)?;
        check_outputs(&spec.outputs, &outputs)?;
        let spec_json = serde_json::to_string(&spec).map_err(|e| invalid(e.to_string()))?;
        let fingerprint = format!("{:016x}", fnv1a(&[spec_json.as_bytes(), model_text.as_bytes()]));
        Ok(Study {
            spec,
            model_text,
            model_file,
            base,
            paths,
            samples,
            jobs,
            fingerprint,
            outputs,
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
            Job::Run(o) => cycle_key(&o.cycle),
            Job::Steady(_) => format!("p{:04}", c.job),
        };
        format!("{:06}-{job}", c.sample)
    }

    /// Column name of parameter `j` (a scale parameter's value is the factor).
    pub fn column(&self, j: usize) -> String {
        let p = &self.spec.parameters[j];
        if p.scale.is_some() {
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
            let base = overrides::get(&self.base, &self.paths[j]).ok();
            let (value, shown) = match v {
                ParamValue::Text(s) => (Value::String(s.clone()), v.clone()),
                ParamValue::Number(f) if p.scale.is_some() => {
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
                (row, Vec::new())
            }
        }
    }

    fn solve(&self, c: &Case, per_case: bool, row: &mut CaseRow) -> Result<CaseFiles, JobError> {
        let (ovs, used) = self.overrides(c.sample).map_err(JobError::invalid)?;
        row.params = used;
        let m = job::Model::from_document(self.base.clone(), &self.model_file, &ovs)?;
        match self.case_job(c, per_case) {
            Job::Run(o) => {
                let r = job::run::run(&m, &o, &mut |_, _| {})?;
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

    /// Solve `cases` in parallel (rayon); `on_done` receives each case as it finishes (from
    /// worker threads, in completion order).
    pub fn run(&self, cases: &[Case], per_case: bool, on_done: &(dyn Fn(CaseRow, CaseFiles) + Sync)) {
        self.run_until(cases, per_case, &AtomicBool::new(false), on_done);
    }

    /// [`Study::run`] that starts no new case once `cancel` is set (the cases already running
    /// finish and reach `on_done`).
    pub fn run_until(
        &self,
        cases: &[Case],
        per_case: bool,
        cancel: &AtomicBool,
        on_done: &(dyn Fn(CaseRow, CaseFiles) + Sync),
    ) {
        cases.par_iter().with_max_len(1).for_each(|c| {
            if cancel.load(Ordering::SeqCst) {
                return;
            }
            let (row, files) = self.run_case(c, per_case);
            on_done(row, files);
        });
    }
}

/// Table outputs of a run: energy per source, output energy, mean efficiency, final and max
/// temperature per node.
pub fn run_outputs(s: &crate::report::run::Summary) -> Vec<(String, Option<f64>)> {
    let mut out = Vec::new();
    for src in crate::scene::Source::ALL {
        out.push((
            format!("energy_{}_j", src.as_str()),
            Some(s.energy_lost_j.get(src)),
        ));
    }
    out.push(("energy_total_j".into(), Some(s.energy_lost_j.sum())));
    out.push(("output_energy_j".into(), Some(s.output_energy_j)));
    out.push(("cycle_efficiency".into(), s.cycle_efficiency));
    out.push(("energy_efficiency".into(), s.energy_efficiency));
    for (node, t) in &s.temperatures_c {
        out.push((format!("temp_final_{node}_c"), Some(t.r#final)));
        out.push((format!("temp_max_{node}_c"), Some(t.max)));
    }
    out
}

/// Table outputs of a steady point: loss per source, total, efficiency, temperature per node.
pub fn steady_outputs(r: &job::SteadyResult) -> Vec<(String, Option<f64>)> {
    let mut out: Vec<(String, Option<f64>)> = crate::scene::Source::ALL
        .iter()
        .map(|s| (format!("loss_{}_w", s.as_str()), Some(r.by_source_w.get(*s))))
        .collect();
    out.push(("loss_total_w".into(), Some(r.total_loss_w)));
    out.push(("efficiency".into(), r.efficiency));
    for (node, t) in &r.temperatures_c {
        out.push((format!("temp_{node}_c"), Some(*t)));
    }
    out
}
