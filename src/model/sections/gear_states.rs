//! `[[gear_states]]`: the gears (1st, 2nd, …, R) with their engaged shift elements, and the
//! kinematic solution of each on the fixed rows of meshes, sets and fixed members.

use std::collections::BTreeSet;

use serde::{Deserialize, Serialize};

use super::common::*;
use super::members::MemberSpec;
use super::shift_elements::Elements;
use crate::model::problems::Problems;
use crate::physics::kinematics::{Constraint, GearTrain, KinematicsError, StateSolution};

/// `[[gear_states]]` as written: a gear (1st, 2nd, ..., R) and the shift elements engaged in it.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GearStateSpec {
    /// Name used on the command line and in cycle files ("1", "2", "R").
    pub name: String,
    /// Engaged shift elements.
    #[serde(default)]
    pub engaged: Vec<String>,
}

/// A gear state with its solved (lossless) kinematics per unit input speed and torque.
#[derive(Debug, Clone)]
pub struct GearState {
    /// Name ("1", "R").
    pub name: String,
    /// Engaged shift elements (indices).
    pub engaged: Vec<usize>,
    /// Kinematic solution.
    pub solution: StateSolution,
}

impl GearState {
    /// Ratio ω_in / ω_out (negative in reverse).
    pub fn ratio(&self) -> f64 {
        self.solution.ratio()
    }
}

/// Validate `[[gear_states]]`: the train of `fixed_rows` is built only when the structure had no
/// problem (`sound`), so one broken mesh is not also reported as an under-determined state.
pub(crate) fn validate_gear_states(
    specs: &[GearStateSpec],
    elements: &Elements<'_>,
    members: &[MemberSpec],
    fixed_rows: Vec<Constraint>,
    (input, output): (Option<usize>, Option<usize>),
    sound: bool,
    problems: &mut Problems,
) -> (Option<GearTrain>, Vec<GearState>) {
    let mut states_spec = specs.to_vec();
    if states_spec.is_empty() {
        if elements.specs.is_empty() {
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
    // Gear states are solved only on a sound structure, so one broken mesh is not also reported as
    // an under-determined state.
    let train = if sound {
        let member_names: Vec<String> = members.iter().map(|m| m.name.clone()).collect();
        GearTrain::new(member_names, fixed_rows)
            .map_err(|e| problems.push("members", "", format!("gear train: {e}")))
            .ok()
    } else {
        None
    };
    let mut gear_states = Vec::new();
    for (i, st) in states_spec.iter().enumerate() {
        let p = format!("gear_states[{i}]");
        if !state_names.insert(st.name.clone()) {
            problems.push(format!("{p}.name"), q(&st.name), "duplicate gear state name");
        }
        let engaged = engaged(st, &p, elements, problems);
        let (Some(train), Some(inp), Some(out), Some(engaged), true) =
            (&train, input, output, engaged, elements.ok)
        else {
            continue;
        };
        if input == output {
            continue;
        }
        let rows: Vec<Constraint> = engaged.iter().map(|&j| elements.list[j].row()).collect();
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

/// The engaged shift elements of state `st` (indices): known, each once. None after a problem.
fn engaged(
    st: &GearStateSpec,
    p: &str,
    elements: &Elements<'_>,
    problems: &mut Problems,
) -> Option<Vec<usize>> {
    let mut engaged = Vec::new();
    let mut seen = BTreeSet::new();
    let mut ok = true;
    for (k, en) in st.engaged.iter().enumerate() {
        let Some(&j) = elements.ix.get(en.as_str()) else {
            problems.push(
                format!("{p}.engaged[{k}]"),
                q(en),
                format!(
                    "unknown shift element; defined: {}",
                    list(elements.specs.iter().map(|e| &e.name))
                ),
            );
            ok = false;
            continue;
        };
        if !seen.insert(j) {
            problems.push(format!("{p}.engaged[{k}]"), q(en), "listed twice");
            ok = false;
        }
        engaged.push(j);
    }
    ok.then_some(engaged)
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
