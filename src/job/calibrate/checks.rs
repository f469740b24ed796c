//! The checks a calibration's input and result pass besides the model's own: the measured
//! temperatures and the start inside the physics envelope ([`crate::job::envelope`]), the
//! trace's boundary columns inside the model file's range for a boundary series (they are
//! written into `calibrated.toml`), each number fitted once whatever its spelling, and the
//! fitted trajectory inside the envelope.

use crate::job::envelope::{Envelope, OilRange, NODE_RANGE_C};
use crate::job::{JobError, Model};

use super::params::{canonical, FitSpec};
use super::problem::Problem;

/// Every measured value of a channel inside the range of its node: the oil's range for the oil
/// node, the solid nodes' range for the others (exit 1, naming file, line, column and value).
pub fn measured_in_envelope(m: &Model, pr: &Problem<'_>) -> Result<(), JobError> {
    let scene = pr.scene_at(&pr.start())?;
    let oil = OilRange::of(scene.thermal().oil_model());
    let (lo, hi) = NODE_RANGE_C;
    for (c, &node) in pr.trace.measured.iter().zip(&pr.channels) {
        let is_oil = node == scene.thermal().oil;
        let bad = c.values_c.iter().position(|&v| {
            if is_oil {
                !oil.contains(v)
            } else {
                !(lo..=hi).contains(&v)
            }
        });
        if let Some(r) = bad {
            let range = if is_oil {
                oil.describe()
            } else {
                format!("[{lo}, {hi}] °C, the range of the thermal network's solid nodes")
            };
            return Err(JobError::invalid(format!(
                "{}: line {}, column {}: {} °C is outside {range}: {} cannot be fitted there",
                pr.trace.source,
                pr.trace.lines[r],
                c.column,
                c.values_c[r],
                m.label()
            )));
        }
    }
    let y = scene.initial_state(None);
    Envelope::of(&scene).check(&y[..scene.nodes()]).map_err(|b| {
        JobError::invalid(format!(
            "{}: the initial state is outside the range where the models hold: {b} (the trace's first row \
             sets the measured nodes and the mean of them the others; --keep-initial keeps the model's)",
            m.label()
        ))
    })
}

/// The trace's boundary columns, written into the model as `series` (as `calibrated.toml`
/// holds them), pass the model file's own checks (exit 1 naming the column and the model's
/// message with the value and its range).
pub fn boundaries_in_model_range(m: &Model, pr: &Problem<'_>) -> Result<(), JobError> {
    if pr.trace.boundaries.is_empty() {
        return Ok(());
    }
    let text = super::model_file::calibrated_text(pr.text, &[], &pr.boundary_series())
        .map_err(|e| JobError::invalid(format!("{}: {e}", m.label())))?;
    crate::model::from_str_with(&text, &pr.file, &pr.base)
        .map(|_| ())
        .map_err(|e| {
            let detail = match &e {
                crate::model::ModelError::Invalid { problems, .. } => {
                    let first: Vec<String> = problems.iter().take(3).map(|p| p.to_string()).collect();
                    format!("{} ({} in all)", first.join("; "), problems.len())
                }
                other => other.to_string(),
            };
            let cols: Vec<&str> = pr.trace.boundaries.iter().map(|c| c.column.as_str()).collect();
            JobError::invalid(format!(
                "{}: column {}: the boundary temperatures, written into {} as a series \
                 (thermal.boundaries[…].series[ROW][1], ROW counting the trace's rows from 0), are refused \
                 by the model file's checks: {detail}",
                pr.trace.source,
                cols.join(", "),
                m.label()
            ))
        })
}

/// Each fitted number once: two `--fit` arguments that name the same number (an index and a
/// `["name"]` selector of one entry) are refused.
pub fn fitted_once(specs: &[FitSpec], doc: &toml::Table) -> Result<(), JobError> {
    let canon: Vec<_> = specs.iter().map(|s| canonical(&s.path, doc)).collect();
    for b in 0..specs.len() {
        if let Some(a) = (0..b).find(|&a| canon[a] == canon[b]) {
            let msg = format!(
                "fit = {}: the same number as fit {} ({}): each number is fitted once",
                specs[b], specs[a], canon[a]
            );
            return Err(JobError::option(
                "fit",
                specs[b].to_string(),
                "each key path once",
                msg,
            ));
        }
    }
    Ok(())
}
