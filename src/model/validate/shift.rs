//! `[[shift_elements]]` and `[[gear_states]]`: elements, and the kinematic solution of every
//! gear state on the fixed rows of meshes, sets and fixed members.

use std::collections::{BTreeSet, HashMap};

use super::common::*;
use super::Ctx;
use crate::model::gearbox::*;
use crate::model::problems::Problems;
use crate::model::schema::*;
use crate::physics::kinematics::{Constraint, GearTrain, KinematicsError};

/// Checked shift elements with their name index; `ok` false if any failed.
pub(super) struct Elements<'a> {
    pub list: Vec<ShiftElement>,
    pub ix: HashMap<&'a str, usize>,
    pub ok: bool,
}

/// Validate `[[shift_elements]]`.
pub(super) fn validate_shift_elements<'a>(ctx: &Ctx<'a>, problems: &mut Problems) -> Elements<'a> {
    let file = ctx.file;
    let member = |name: &str, path: String, problems: &mut Problems| ctx.member(name, path, problems);
    let mut elem_ix: HashMap<&str, usize> = HashMap::new();
    let mut elements: Vec<ShiftElement> = Vec::new();
    let mut elem_ok = true;
    for (i, e) in file.shift_elements.iter().enumerate() {
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
            .map(|(k, n)| member(n, format!("{p}.members[{k}]"), problems))
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
        list: elements,
        ix: elem_ix,
        ok: elem_ok,
    }
}

/// Validate `[[gear_states]]`: the train of `fixed_rows` is built only when the structure had no
/// problem (`sound`), so one broken mesh is not also reported as an under-determined state.
pub(super) fn validate_gear_states(
    ctx: &Ctx<'_>,
    elements: &Elements<'_>,
    fixed_rows: Vec<Constraint>,
    (input, output): (Option<usize>, Option<usize>),
    sound: bool,
    problems: &mut Problems,
) -> (Option<GearTrain>, Vec<GearState>) {
    let file = ctx.file;
    let (elem_ix, elem_ok, elements) = (&elements.ix, elements.ok, &elements.list);
    let mut states_spec = file.gear_states.clone();
    if states_spec.is_empty() {
        if file.shift_elements.is_empty() {
            states_spec.push(GearStateSpec {
                name: "1".into(),
                engaged: vec![],
            });
        } else {
            problems.push(
                "gear_states",
                "[]",
                "a gearbox with shift elements must list its [[gear_states]]",
            );
        }
    }
    let mut state_names = BTreeSet::new();
    let member_names: Vec<String> = file.members.iter().map(|m| m.name.clone()).collect();
    // Gear states are solved only on a sound structure, so one broken mesh is not also reported as
    // an under-determined state.
    let train = if sound {
        match GearTrain::new(member_names, fixed_rows) {
            Ok(t) => Some(t),
            Err(e) => {
                problems.push("members", "", format!("gear train: {e}"));
                None
            }
        }
    } else {
        None
    };
    let mut gear_states = Vec::new();
    for (i, st) in states_spec.iter().enumerate() {
        let p = format!("gear_states[{i}]");
        if !state_names.insert(st.name.clone()) {
            problems.push(format!("{p}.name"), q(&st.name), "duplicate gear state name");
        }
        let mut engaged = Vec::new();
        let mut seen = BTreeSet::new();
        let mut ok = true;
        for (k, en) in st.engaged.iter().enumerate() {
            match elem_ix.get(en.as_str()) {
                None => {
                    problems.push(
                        format!("{p}.engaged[{k}]"),
                        q(en),
                        format!(
                            "unknown shift element; defined: {}",
                            list(file.shift_elements.iter().map(|e| &e.name))
                        ),
                    );
                    ok = false;
                }
                Some(&j) => {
                    if !seen.insert(j) {
                        problems.push(format!("{p}.engaged[{k}]"), q(en), "listed twice");
                        ok = false;
                    }
                    engaged.push(j);
                }
            }
        }
        let (Some(train), Some(inp), Some(out), true, true) = (&train, input, output, ok, elem_ok) else {
            continue;
        };
        if input == output {
            continue;
        }
        let rows: Vec<Constraint> = engaged
            .iter()
            .map(|&j| {
                let e = &elements[j];
                match e.kind {
                    ShiftElementKind::Clutch => Constraint::Clutch {
                        a: e.members[0],
                        b: e.members[1],
                    },
                    ShiftElementKind::Brake => Constraint::Brake { member: e.members[0] },
                }
            })
            .collect();
        match train.solve_state(&rows, inp, out) {
            Ok(solution) => gear_states.push(GearState {
                name: st.name.clone(),
                engaged,
                solution,
            }),
            Err(e) => problems.push(p.clone(), q(&st.name), kinematics_message(&e, &st.engaged)),
        }
    }

    (train, gear_states)
}

fn kinematics_message(e: &KinematicsError, engaged: &[String]) -> String {
    let what = if engaged.is_empty() {
        "no shift element engaged".to_string()
    } else {
        format!("engaged {}", engaged.join("+"))
    };
    match e {
        KinematicsError::UnderDetermined { free_members, dof } => format!(
            "under-determined ({what}): {dof} degree(s) of freedom too many; members free to turn with the input held: {}",
            free_members.join(", ")
        ),
        KinematicsError::OverConstrained { locked_members, removable_elements } => format!(
            "over-constrained ({what}): the train locks; members held: {}{}",
            locked_members.join(", "),
            if removable_elements.is_empty() {
                String::new()
            } else {
                format!("; releasing any one of {} would free it", removable_elements.iter().map(|r| r.description.clone()).collect::<Vec<_>>().join(", "))
            }
        ),
        other => format!("({what}): {other}"),
    }
}
