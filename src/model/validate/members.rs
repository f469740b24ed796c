//! `[[members]]` and `[train]`: names, and the input and output members.

use std::collections::HashMap;

use super::common::*;
use crate::model::problems::Problems;
use crate::model::schema::*;

/// Member names → index; every problem with the names pushed.
pub(super) fn validate_members<'a>(file: &'a ModelFile, problems: &mut Problems) -> HashMap<&'a str, usize> {
    let mut member_ix: HashMap<&str, usize> = HashMap::new();
    for (i, m) in file.members.iter().enumerate() {
        if m.name.trim().is_empty() {
            problems.push(format!("members[{i}].name"), "\"\"", "must not be empty");
        } else if member_ix.insert(m.name.as_str(), i).is_some() {
            problems.push(format!("members[{i}].name"), q(&m.name), "duplicate member name");
        }
    }
    if file.members.len() < 2 {
        problems.push(
            "members",
            format!("{} member(s)", file.members.len()),
            "a gearbox needs at least two members (input and output)",
        );
    }
    member_ix
}

/// `[train]`: input and output members (indices), which must differ.
pub(super) fn validate_train(
    ctx: &super::Ctx<'_>,
    problems: &mut Problems,
) -> (Option<usize>, Option<usize>) {
    let file = ctx.file;
    let input = ctx.member(&file.train.input, "train.input".into(), problems);
    let output = ctx.member(&file.train.output, "train.output".into(), problems);
    if input.is_some() && input == output {
        problems.push(
            "train.output",
            q(&file.train.output),
            "must differ from train.input",
        );
    }

    (input, output)
}
