//! `[[thermal.nodes]]`: nodes with heat capacity, their initial temperatures and the gear bodies
//! they lump.

use crate::physics::units::c_to_k;
use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::common::{temp_ok, GearInfo};
use crate::model::problems::Problems;

/// `[[thermal.nodes]]` as written: a node with heat capacity, `capacity_j_per_k`, or `mass_kg` × `cp_j_per_kgk`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NodeSpec {
    /// Identifier (letters, digits, `_`).
    pub name: String,
    /// Mass, kg.
    #[serde(default)]
    pub mass_kg: Option<f64>,
    /// Specific heat, J/(kg·K).
    #[serde(default)]
    pub cp_j_per_kgk: Option<f64>,
    /// Heat capacity, J/K (instead of mass × c_p).
    #[serde(default)]
    pub capacity_j_per_k: Option<f64>,
    /// Initial temperature, °C (default: `thermal.initial_temp_c`).
    #[serde(default)]
    pub initial_temp_c: Option<f64>,
    /// Gears whose bodies this node lumps (their sliding heat goes here by default).
    #[serde(default)]
    pub gears: Vec<String>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// A checked node with heat capacity.
#[derive(Debug, Clone)]
pub struct ThermalNode {
    /// Name.
    pub name: String,
    /// Heat capacity C, J/K.
    pub capacity: f64,
    /// Initial temperature, K (None: the network's default).
    pub initial_temp: Option<f64>,
    /// Specific heat c_p, J/(kg·K), when the node is given as `mass_kg` × `cp_j_per_kgk`.
    pub specific_heat: Option<f64>,
    /// Gear indices whose bodies this node lumps.
    pub gears: Vec<usize>,
}

/// Check every node: capacity, initial temperature, lumped gears (each gear in one node at most).
pub(crate) fn check_nodes(
    specs: &[NodeSpec],
    gears: &[GearInfo<'_>],
    problems: &mut Problems,
) -> Vec<ThermalNode> {
    let mut gear_owner: BTreeMap<usize, usize> = BTreeMap::new();
    let mut nodes = Vec::new();
    for (i, n) in specs.iter().enumerate() {
        let p = format!("thermal.nodes[{i}]");
        let capacity = capacity(n, &p, problems);
        if let Some(t) = n.initial_temp_c {
            temp_ok(problems, &format!("{p}.initial_temp_c"), t);
        }
        let mut gi = Vec::new();
        for (k, g) in n.gears.iter().enumerate() {
            let gp = format!("{p}.gears[{k}]");
            let Some(idx) = gears.iter().position(|x| x.name == g) else {
                problems.push(&gp, g, "unknown gear");
                continue;
            };
            if !gears[idx].checked {
                continue;
            }
            if let Some(prev) = gear_owner.insert(idx, i) {
                problems.push(
                    &gp,
                    g,
                    format!("gear already lumped in node {}", specs[prev].name),
                );
            }
            gi.push(idx);
        }
        nodes.push(ThermalNode {
            name: n.name.clone(),
            capacity,
            initial_temp: n.initial_temp_c.map(c_to_k),
            specific_heat: n.cp_j_per_kgk,
            gears: gi,
        });
    }
    nodes
}

/// Heat capacity C, J/K: `capacity_j_per_k`, or `mass_kg` × `cp_j_per_kgk` (NaN after a problem).
fn capacity(n: &NodeSpec, p: &str, problems: &mut Problems) -> f64 {
    match (n.capacity_j_per_k, n.mass_kg, n.cp_j_per_kgk) {
        (Some(c), None, None) => {
            problems.in_range(&format!("{p}.capacity_j_per_k"), c, 1e-9, 1e12, " J/K");
            c
        }
        (None, Some(m), Some(cp)) => {
            problems.in_range(&format!("{p}.mass_kg"), m, 1e-9, 1e6, " kg");
            problems.in_range(&format!("{p}.cp_j_per_kgk"), cp, 1.0, 1e5, " J/(kg·K)");
            m * cp
        }
        _ => {
            problems.push(
                p,
                "",
                "give either capacity_j_per_k, or mass_kg and cp_j_per_kgk (not both)",
            );
            f64::NAN
        }
    }
}
