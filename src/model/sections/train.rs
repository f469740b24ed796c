//! `[train]`: where power enters and leaves: the input and output members.

use serde::{Deserialize, Serialize};

use super::common::q;
use super::members::Members;
use crate::model::problems::Problems;

/// `[train]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TrainSpec {
    /// Input member (engine / motor side).
    pub input: String,
    /// Output member (final drive side).
    pub output: String,
}

/// Input and output members (indices), which must differ.
pub(crate) fn validate_train(
    t: &TrainSpec,
    members: &Members<'_>,
    problems: &mut Problems,
) -> (Option<usize>, Option<usize>) {
    let input = members.lookup(&t.input, "train.input".into(), problems);
    let output = members.lookup(&t.output, "train.output".into(), problems);
    if input.is_some() && input == output {
        problems.push("train.output", q(&t.output), "must differ from train.input");
    }
    (input, output)
}
