//! `[[thermal.heat]]`: where the heat of a loss item, or of every item of a source, goes
//! (overrides of the default destinations).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::common::{LossItemNames, NodeNames, NodeRef};
use crate::model::problems::Problems;
use crate::model::source::Source;

/// `[[thermal.heat]]` as written: where the heat of a loss item, or of all items of a source, goes.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HeatSpec {
    /// One item: `churning:<gear>`, `pocketing:<mesh>` or `sliding:<mesh>`.
    #[serde(default)]
    pub item: Option<String>,
    /// Every item of a source (a [`Source`] name: `churning`, `pocketing`, `sliding`, …).
    #[serde(default)]
    pub source: Option<Source>,
    /// Node → fraction (sum 1).
    pub to: BTreeMap<String, f64>,
}

/// What a heat rule applies to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum HeatTarget {
    /// All items of a source.
    Source(Source),
    /// One item, `source:name`.
    Item(String),
}

/// A checked heat rule: fractions of a loss item's heat per node.
#[derive(Debug, Clone)]
pub struct HeatRule {
    /// What it applies to.
    pub target: HeatTarget,
    /// (node index, fraction), fractions sum to 1.
    pub to: Vec<(usize, f64)>,
}

/// Check every heat rule: its target (a loss item of the model or a source) and its fractions
/// (nodes with capacity, summing to 1).
pub(crate) fn check_heat(
    specs: &[HeatSpec],
    names: &NodeNames<'_>,
    items: &LossItemNames<'_>,
    problems: &mut Problems,
) -> Vec<HeatRule> {
    let mut heat = Vec::new();
    for (i, h) in specs.iter().enumerate() {
        let p = format!("thermal.heat[{i}]");
        let Some(target) = target(h, &p, items, problems) else {
            continue;
        };
        let to = fractions(&h.to, &p, names, problems);
        heat.push(HeatRule { target, to });
    }
    heat
}

/// What the rule applies to: one item `<source>:<name>`, or every item of a source.
fn target(h: &HeatSpec, p: &str, items: &LossItemNames<'_>, problems: &mut Problems) -> Option<HeatTarget> {
    match (&h.item, &h.source) {
        (Some(item), None) => {
            if !items.knows(item) {
                problems.push(
                    format!("{p}.item"),
                    item,
                    "must be <source>:<name> with a loss item of the model (churning:<gear>, \
                     pocketing:<mesh>, sliding:<mesh>, bearing:<bearing>, seal:<seal>, …)",
                );
            }
            Some(HeatTarget::Item(item.clone()))
        }
        (None, Some(s)) => Some(HeatTarget::Source(*s)),
        _ => {
            problems.push(p, "", "give either item or source");
            None
        }
    }
}

/// (node index, fraction) of `to`: nodes with capacity, fractions in [0, 1] summing to 1.
fn fractions(
    to_spec: &BTreeMap<String, f64>,
    p: &str,
    names: &NodeNames<'_>,
    problems: &mut Problems,
) -> Vec<(usize, f64)> {
    let mut to = Vec::new();
    let mut sum = 0.0;
    for (node, f) in to_spec {
        let np = format!("{p}.to.{node}");
        match names.get(node.as_str()) {
            Some(NodeRef::Node(k)) => {
                if problems.in_range(&np, *f, 0.0, 1.0, "") {
                    to.push((k, *f));
                    sum += f;
                }
            }
            Some(NodeRef::Boundary(_)) => {
                problems.push(
                    &np,
                    node,
                    "loss heat must go to nodes with capacity, not boundaries",
                );
            }
            None => problems.push(&np, node, format!("unknown node; known: {}", names.known())),
        }
    }
    if (sum - 1.0).abs() > 1e-9 && !to.is_empty() {
        problems.push(format!("{p}.to"), format!("sum {sum}"), "fractions must sum to 1");
    }
    to
}
