//! The checks of a study file before any case runs: its name, its job's options (ranges,
//! cycles read, gear states known to the base model), distinct case ids, and the output
//! columns `[outputs]` names. Each message names the key path in the study file.

use std::path::Path;

use toml::Value;

use crate::job::{self, JobError, RunOptions, SteadyOptions};
use crate::model::{self, overrides, KeyPath, Override};

use super::spec::{self, JobSpec};
use super::{key_of, Job, ParamValue};

/// The jobs of a study file's `[job]`: one per cycle, per point, or per point of a map grid.
pub(super) fn jobs_of(spec: &JobSpec) -> Result<Vec<Job>, String> {
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
pub(super) fn check_name(name: &str) -> Result<(), String> {
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
pub(super) fn check_distinct_cycles(jobs: &[Job]) -> Result<(), String> {
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
pub(super) fn cycle_key(cycle: &str) -> String {
    key_of(
        Path::new(cycle)
            .file_stem()
            .map_or(cycle, |s| s.to_str().unwrap_or("cycle")),
    )
}

/// Every job's options checked before any case runs (their ranges, the cycles read, the gear
/// states known to the base model): a study with a bad option fails at once, not per case. The
/// message is the job layer's, after the key path of the job in the study file.
pub(super) fn check_jobs(spec: &JobSpec, jobs: &[Job], base: &job::Model) -> Result<(), JobError> {
    let mut cycles_seen = std::collections::BTreeSet::new();
    for (k, j) in jobs.iter().enumerate() {
        match j {
            Job::Run(o) => {
                let at = |key: String| move |e: JobError| e.prefixed(&key);
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
                let at = |e: JobError| e.prefixed(&key);
                p.check().map_err(at)?;
                base.state(&p.gear).map_err(at)?;
            }
        }
    }
    Ok(())
}

/// Every column `[outputs]` names exists in the table.
pub(super) fn check_outputs(o: &spec::OutputSpec, columns: &[String]) -> Result<(), JobError> {
    let named = o.effects.iter().flatten().map(|n| ("outputs.effects", n));
    let pareto = o.pareto.iter().flatten().map(|n| ("outputs.pareto", n));
    for (key, name) in named.chain(pareto) {
        if !columns.contains(name) {
            return Err(JobError::invalid(format!(
                "{key}: no output column `{name}`; the table has: {}",
                columns.join(", ")
            )));
        }
    }
    Ok(())
}

/// Every parameter's key path parsed, each once.
pub(super) fn parameter_paths(params: &[spec::ParamSpec]) -> Result<Vec<KeyPath>, JobError> {
    if params.is_empty() {
        return Err(JobError::invalid("no [[parameters]]"));
    }
    let mut paths = Vec::new();
    for (k, p) in params.iter().enumerate() {
        let path: KeyPath = p
            .path
            .parse()
            .map_err(|e| JobError::invalid(format!("parameters[{k}].path `{}`: {e}", p.path)))?;
        if let Some(j) = paths.iter().position(|q| *q == path) {
            return Err(JobError::invalid(format!(
                "parameters[{k}].path `{}`: given twice (parameters[{j}] varies it already); each key path once",
                p.path
            )));
        }
        paths.push(path);
    }
    Ok(paths)
}

/// A parameter whose key path is not written in the base model is accepted when the model's
/// schema takes it ([`model::schema_takes`], probed with the first sample's value); a scale
/// parameter needs a value in the model to scale.
pub(super) fn paths_in_schema(
    params: &[spec::ParamSpec],
    paths: &[KeyPath],
    samples: &[Vec<ParamValue>],
    base: &toml::Table,
    model_text: &str,
    model_file: &Path,
) -> Result<(), JobError> {
    for (k, (p, path)) in params.iter().zip(paths).enumerate() {
        let Err(e) = overrides::get(base, path) else {
            continue;
        };
        if p.scale.is_some() || p.factors {
            return Err(JobError::invalid(format!("parameters[{k}].path: {e}")));
        }
        let value = match samples.first().map(|s| &s[k]) {
            Some(ParamValue::Text(t)) => Value::String(t.clone()),
            Some(ParamValue::Number(x)) => Value::Float(*x),
            None => continue,
        };
        let probe = Override {
            path: path.clone(),
            value,
        };
        if model::schema_takes(base.clone(), &probe).is_err() {
            // The message: the model's own report with the probe applied.
            let report = model::from_str_with(model_text, model_file, &[probe])
                .err()
                .map(|e| e.report())
                .unwrap_or_default();
            return Err(JobError::invalid(format!(
                "parameters[{k}].path `{}`: {report}",
                p.path
            )));
        }
    }
    Ok(())
}
