//! Helpers the section checks share: units, quoting, name lists, identifiers, heat targets.

use std::collections::{BTreeSet, HashMap};

use crate::model::problems::Problems;

/// mm → m.
pub(crate) const MM: f64 = 1e-3;
/// Degrees → radians.
pub(crate) const DEG: f64 = std::f64::consts::PI / 180.0;

/// A name in quotes, as messages show it (quotes, backslashes and control characters escaped,
/// so that a message stays on one line).
pub(crate) fn q(s: &str) -> String {
    format!("{s:?}")
}

/// Names joined by commas, or `(none)`.
pub(crate) fn list<'a, T: AsRef<str> + 'a + ?Sized>(it: impl Iterator<Item = &'a T>) -> String {
    let v: Vec<&str> = it.map(|s| s.as_ref()).collect();
    if v.is_empty() {
        "(none)".into()
    } else {
        v.join(", ")
    }
}

/// Index of part `name` in `ix`, or a problem at `path` naming what it is not (`what`: "member",
/// "gear") and listing the defined ones.
pub(crate) fn lookup<'a, T: AsRef<str> + 'a + ?Sized>(
    ix: &HashMap<&str, usize>,
    name: &str,
    path: String,
    what: &str,
    defined: impl Iterator<Item = &'a T>,
    problems: &mut Problems,
) -> Option<usize> {
    let r = ix.get(name).copied();
    if r.is_none() {
        problems.push(
            path,
            q(name),
            format!("unknown {what}; defined {what}s: {}", list(defined)),
        );
    }
    r
}

/// Letters, digits and `_`, at least one: the names of thermal nodes, bearings and seals.
pub(crate) fn is_identifier(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Check a `heat_to` list (bearings, seals) against the thermal node names: known nodes,
/// fractions in [0, 1] summing to 1.
pub(crate) fn heat_to(
    list: &Option<Vec<(String, f64)>>,
    nodes: &BTreeSet<&str>,
    path: &str,
    problems: &mut Problems,
) -> Option<Vec<(String, f64)>> {
    let l = list.as_ref()?;
    let mut sum = 0.0;
    for (k, (n, f)) in l.iter().enumerate() {
        if !nodes.contains(n.as_str()) {
            problems.push(
                format!("{path}[{k}]"),
                q(n),
                format!("unknown thermal node; nodes: {}", node_list(nodes)),
            );
        }
        problems.in_range(&format!("{path}[{k}]"), *f, 0.0, 1.0, "");
        sum += f;
    }
    if (sum - 1.0).abs() > 1e-9 {
        problems.push(path, sum, "fractions must sum to 1");
    }
    Some(l.clone())
}

fn node_list(s: &BTreeSet<&str>) -> String {
    if s.is_empty() {
        "(none: the model has no [thermal] nodes)".into()
    } else {
        s.iter().copied().collect::<Vec<_>>().join(", ")
    }
}
