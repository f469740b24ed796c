//! `[[members]]`: the rigid rotating bodies (shafts, carriers, drums) that gears and shift
//! elements attach to; names, and the name table later sections look members up in.

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use super::common::*;
use crate::model::choice::choice;
use crate::model::problems::Problems;

/// What kind of rotating member (informational; kinematics treats all alike).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MemberKind {
    /// A shaft.
    Shaft,
    /// A planet carrier.
    Carrier,
    /// A drum or hub (e.g. a clutch drum carrying a ring gear).
    Drum,
}
choice!(MemberKind {
    Shaft = "shaft",
    Carrier = "carrier",
    Drum = "drum",
});

/// `[[members]]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MemberSpec {
    /// Unique name.
    pub name: String,
    /// Kind (default `shaft`).
    #[serde(default)]
    pub kind: Option<MemberKind>,
    /// Permanently held by the housing (e.g. a sun gear bolted to the case).
    #[serde(default)]
    pub fixed: bool,
}

/// A checked member (shaft, carrier, drum).
#[derive(Debug, Clone)]
pub struct Member {
    /// Name from the file.
    pub name: String,
    /// Kind (informational).
    pub kind: MemberKind,
    /// Held by the housing permanently.
    pub fixed: bool,
}

/// The members by name.
pub(crate) struct Members<'a> {
    /// As written.
    pub specs: &'a [MemberSpec],
    /// Name → index.
    pub ix: HashMap<&'a str, usize>,
}

impl Members<'_> {
    /// Index of member `name`, or a problem at `path` listing the defined members.
    pub fn lookup(&self, name: &str, path: String, problems: &mut Problems) -> Option<usize> {
        let defined = self.specs.iter().map(|m| &m.name);
        lookup(&self.ix, name, path, "member", defined, problems)
    }

    /// The checked members, in file order.
    pub fn checked(&self) -> Vec<Member> {
        self.specs
            .iter()
            .map(|m| Member {
                name: m.name.clone(),
                kind: m.kind.unwrap_or(MemberKind::Shaft),
                fixed: m.fixed,
            })
            .collect()
    }
}

/// Check `[[members]]` (non-empty unique names, at least two) and index them by name.
pub(crate) fn validate_members<'a>(specs: &'a [MemberSpec], problems: &mut Problems) -> Members<'a> {
    let mut ix: HashMap<&str, usize> = HashMap::new();
    for (i, m) in specs.iter().enumerate() {
        if m.name.trim().is_empty() {
            problems.push(format!("members[{i}].name"), "\"\"", "must not be empty");
        } else if ix.insert(m.name.as_str(), i).is_some() {
            problems.push(format!("members[{i}].name"), q(&m.name), "duplicate member name");
        }
    }
    if specs.len() < 2 {
        problems.push(
            "members",
            format!("{} member(s)", specs.len()),
            "a gearbox needs at least two members (input and output)",
        );
    }
    Members { specs, ix }
}
