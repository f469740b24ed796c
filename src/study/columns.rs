//! The study table's output columns, named once: the columns of a run and of a steady point
//! over a model's thermal nodes. The table's column list ([`output_columns`], from the base
//! model) and every row's outputs ([`run_outputs`], [`steady_outputs`]) take their names from
//! the same functions, so the two cannot drift apart.

use crate::job::{self, JobError};
use crate::report::run::Summary;
use crate::scene::Source;

use super::Job;

/// The run columns in the order of their values: energy per source, total, output energy, the
/// two efficiencies, then final and max temperature per node.
fn run_names<'a>(nodes: impl IntoIterator<Item = &'a String>) -> Vec<String> {
    let mut cols: Vec<String> = Source::ALL
        .iter()
        .map(|s| format!("energy_{}_j", s.as_str()))
        .collect();
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
    cols
}

/// The steady columns in the order of their values: loss per source, total, efficiency, then
/// the temperature per node.
fn steady_names<'a>(nodes: impl IntoIterator<Item = &'a String>) -> Vec<String> {
    let mut cols: Vec<String> = Source::ALL
        .iter()
        .map(|s| format!("loss_{}_w", s.as_str()))
        .collect();
    cols.extend(["loss_total_w", "efficiency"].map(String::from));
    cols.extend(nodes.into_iter().map(|n| format!("temp_{n}_c")));
    cols
}

/// The table's output columns for `jobs` on the base model (the same for every case, whatever
/// its overrides).
pub(super) fn output_columns(jobs: &[Job], base: &job::Model) -> Result<Vec<String>, JobError> {
    let scene = base.compile(&crate::scene::Needs::default())?;
    let nodes = &scene.thermal().names;
    let mut cols = Vec::new();
    if jobs.iter().any(|j| matches!(j, Job::Run(_))) {
        cols.extend(run_names(nodes));
    }
    if jobs.iter().any(|j| matches!(j, Job::Steady(_))) {
        cols.extend(steady_names(nodes));
    }
    Ok(cols)
}

/// Table outputs of a run: energy per source, output energy, mean efficiency, final and max
/// temperature per node.
pub fn run_outputs(s: &Summary) -> Vec<(String, Option<f64>)> {
    let mut values: Vec<Option<f64>> = Source::ALL
        .iter()
        .map(|src| Some(s.energy_lost_j.get(*src)))
        .collect();
    values.extend([
        Some(s.energy_lost_j.sum()),
        Some(s.output_energy_j),
        s.cycle_efficiency,
        s.energy_efficiency,
    ]);
    for t in s.temperatures_c.values() {
        values.extend([Some(t.r#final), Some(t.max)]);
    }
    run_names(s.temperatures_c.keys())
        .into_iter()
        .zip(values)
        .collect()
}

/// Table outputs of a steady point: loss per source, total, efficiency, temperature per node.
pub fn steady_outputs(r: &job::SteadyResult) -> Vec<(String, Option<f64>)> {
    let mut values: Vec<Option<f64>> = Source::ALL.iter().map(|s| Some(r.by_source_w.get(*s))).collect();
    values.extend([Some(r.total_loss_w), r.efficiency]);
    values.extend(r.temperatures_c.values().map(|t| Some(*t)));
    steady_names(r.temperatures_c.keys())
        .into_iter()
        .zip(values)
        .collect()
}
