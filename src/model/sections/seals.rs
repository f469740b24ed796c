//! `[[seals]]`: radial lip seals: members, shaft diameter, friction law, heat targets.

use std::collections::BTreeSet;

use serde::{Deserialize, Serialize};

use super::common::*;
use super::members::Members;
use crate::model::problems::Problems;
use crate::physics::losses::seals::{LipSeal, SealLaw};

/// `[[seals]]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SealSpec {
    /// Unique name.
    pub name: String,
    /// Member whose shaft the lip runs on.
    pub member: String,
    /// Member holding the seal (default: the housing).
    #[serde(default)]
    pub outer: Option<String>,
    /// Shaft diameter at the lip, mm.
    pub shaft_diameter_mm: f64,
    /// Measured or maker's friction torque, N·m (default: ISO/TR 14179-2 law).
    #[serde(default)]
    pub torque_nm: Option<f64>,
    /// Thermal nodes with fractions (default: the member's body node, else the oil).
    #[serde(default)]
    pub heat_to: Option<Vec<(String, f64)>>,
    /// Where the entry comes from.
    #[serde(default)]
    pub source: Option<String>,
}

/// A checked seal.
#[derive(Debug, Clone)]
pub struct Seal {
    /// Name.
    pub name: String,
    /// Member the lip runs on.
    pub member: usize,
    /// Member holding the seal (None: housing).
    pub outer: Option<usize>,
    /// Model.
    pub seal: LipSeal,
    /// Heat destinations named in the file.
    pub heat_to: Option<Vec<(String, f64)>>,
}

/// Check `[[seals]]`: names, members, shaft diameter, torque, heat targets (`nodes`: the thermal
/// node names).
pub(crate) fn validate_seals(
    specs: &[SealSpec],
    members: &Members<'_>,
    nodes: &BTreeSet<&str>,
    problems: &mut Problems,
) -> Vec<Seal> {
    let mut names = BTreeSet::new();
    let mut out = Vec::new();
    for (i, s) in specs.iter().enumerate() {
        let p = format!("seals[{i}]");
        if !is_identifier(&s.name) {
            problems.push(
                format!("{p}.name"),
                q(&s.name),
                "must be an identifier (letters, digits, _)",
            );
        } else if !names.insert(s.name.clone()) {
            problems.push(format!("{p}.name"), q(&s.name), "duplicate seal name");
        }
        let member = members.lookup(&s.member, format!("{p}.member"), problems);
        let outer = s
            .outer
            .as_ref()
            .and_then(|o| members.lookup(o, format!("{p}.outer"), problems));
        let ok = problems.in_range(
            &format!("{p}.shaft_diameter_mm"),
            s.shaft_diameter_mm,
            1.0,
            2000.0,
            " mm",
        );
        let law = match s.torque_nm {
            Some(t) => {
                problems.in_range(&format!("{p}.torque_nm"), t, 0.0, 1e4, " N m");
                SealLaw::Torque(t)
            }
            None => SealLaw::Iso14179,
        };
        let heat = heat_to(&s.heat_to, nodes, &format!("{p}.heat_to"), problems);
        if let (Some(member), true) = (member, ok) {
            out.push(Seal {
                name: s.name.clone(),
                member,
                outer,
                seal: LipSeal {
                    shaft_diameter: s.shaft_diameter_mm * MM,
                    law,
                },
                heat_to: heat,
            });
        }
    }
    out
}
