//! `[[shift_elements]]`: the clutches and brakes, with the members they act on.

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use super::common::*;
use super::members::Members;
use crate::model::choice::choice;
use crate::model::problems::Problems;
use crate::physics::kinematics::Constraint;

/// Clutch or brake.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShiftElementKind {
    /// Joins two members when engaged.
    Clutch,
    /// Holds one member to the housing when engaged.
    Brake,
}
choice!(ShiftElementKind {
    Clutch = "clutch",
    Brake = "brake",
});

/// `[[shift_elements]]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ShiftElementSpec {
    /// Unique name (e.g. "A").
    pub name: String,
    /// `clutch` or `brake`.
    pub kind: ShiftElementKind,
    /// Clutch: the two members it joins. Brake: the one member it holds.
    pub members: Vec<String>,
}

/// A clutch or brake.
#[derive(Debug, Clone)]
pub struct ShiftElement {
    /// Name.
    pub name: String,
    /// Clutch or brake.
    pub kind: ShiftElementKind,
    /// Members (two for a clutch, one for a brake).
    pub members: Vec<usize>,
}

impl ShiftElement {
    /// The kinematic constraint of the element while engaged.
    pub fn row(&self) -> Constraint {
        match self.kind {
            ShiftElementKind::Clutch => Constraint::Clutch {
                a: self.members[0],
                b: self.members[1],
            },
            ShiftElementKind::Brake => Constraint::Brake {
                member: self.members[0],
            },
        }
    }
}

/// Checked shift elements with their name index; `ok` false if any failed.
pub(crate) struct Elements<'a> {
    /// As written.
    pub specs: &'a [ShiftElementSpec],
    /// The checked elements (those that passed).
    pub list: Vec<ShiftElement>,
    /// Name → index.
    pub ix: HashMap<&'a str, usize>,
    /// Every element passed.
    pub ok: bool,
}

/// Validate `[[shift_elements]]`.
pub(crate) fn validate_shift_elements<'a>(
    specs: &'a [ShiftElementSpec],
    members: &Members<'_>,
    problems: &mut Problems,
) -> Elements<'a> {
    let mut elem_ix: HashMap<&str, usize> = HashMap::new();
    let mut elements: Vec<ShiftElement> = Vec::new();
    let mut elem_ok = true;
    for (i, e) in specs.iter().enumerate() {
        let p = format!("shift_elements[{i}]");
        if elem_ix.insert(e.name.as_str(), i).is_some() {
            problems.push(format!("{p}.name"), q(&e.name), "duplicate shift element name");
        }
        let want = match e.kind {
            ShiftElementKind::Clutch => 2,
            ShiftElementKind::Brake => 1,
        };
        if e.members.len() != want {
            problems.push(
                format!("{p}.members"),
                format!("{:?}", e.members),
                if want == 2 {
                    "a clutch joins exactly two members"
                } else {
                    "a brake holds exactly one member"
                },
            );
            elem_ok = false;
            continue;
        }
        let ms: Vec<Option<usize>> = e
            .members
            .iter()
            .enumerate()
            .map(|(k, n)| members.lookup(n, format!("{p}.members[{k}]"), problems))
            .collect();
        if ms.iter().any(Option::is_none) {
            elem_ok = false;
            continue;
        }
        let ms: Vec<usize> = ms.into_iter().flatten().collect();
        if want == 2 && ms[0] == ms[1] {
            problems.push(
                format!("{p}.members"),
                format!("{:?}", e.members),
                "a clutch must join two different members",
            );
            elem_ok = false;
        }
        elements.push(ShiftElement {
            name: e.name.clone(),
            kind: e.kind,
            members: ms,
        });
    }

    Elements {
        specs,
        list: elements,
        ix: elem_ix,
        ok: elem_ok,
    }
}
