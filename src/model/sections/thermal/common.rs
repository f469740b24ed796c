//! What the `[thermal]` sub-table checks share: node references and names (nodes and boundaries
//! share one name space), the gears and loss items the network refers to, the temperature range.

use std::collections::BTreeMap;

use crate::model::problems::Problems;
use crate::model::sections::common::is_identifier;
use crate::model::source::{Source, N_SOURCES};

/// A node reference: capacity node or boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeRef {
    /// Index into [`ThermalNetwork::nodes`].
    Node(usize),
    /// Index into [`ThermalNetwork::boundaries`].
    Boundary(usize),
}

/// Gear information the thermal validation needs.
pub struct GearInfo<'a> {
    /// Gear name.
    pub name: &'a str,
    /// Outer radius of the body (tip, or root for internal gears), m.
    pub radius: f64,
    /// Face width, m.
    pub face_width: f64,
    /// False for a gear the file declares whose own checks failed: a reference to it is not a
    /// second problem (the first is reported where the gear is defined).
    pub checked: bool,
}

/// Names of the loss items of each source that heat rules may name (`"<source>:<name>"`):
/// gears for churning, meshes for pocketing and sliding, the model's bearings, seals, ….
#[derive(Debug, Clone, Default)]
pub struct LossItemNames<'a> {
    /// Item names per source, indexed by [`Source::index`].
    pub by_source: [Vec<&'a str>; N_SOURCES],
}

impl<'a> LossItemNames<'a> {
    /// Item names of source `s`.
    pub fn of(&self, s: Source) -> &[&'a str] {
        &self.by_source[s.index()]
    }

    /// Set the item names of source `s`.
    pub fn set(&mut self, s: Source, names: impl IntoIterator<Item = &'a str>) {
        self.by_source[s.index()] = names.into_iter().collect();
    }

    /// True if `item` is `<source>:<name>` with a known source and name.
    pub(crate) fn knows(&self, item: &str) -> bool {
        item.split_once(':')
            .and_then(|(s, n)| Source::parse(s).map(|s| self.of(s).contains(&n)))
            .unwrap_or(false)
    }
}

/// A temperature in °C within the range every thermal temperature must lie in.
pub(crate) fn temp_ok(problems: &mut Problems, path: &str, t: f64) -> bool {
    problems.in_range(path, t, -60.0, 300.0, " °C")
}

/// Node and boundary names → reference.
pub(crate) struct NodeNames<'a>(BTreeMap<&'a str, NodeRef>);

impl<'a> NodeNames<'a> {
    /// The names of `[[thermal.nodes]]` and `[[thermal.boundaries]]`: identifiers, unique over
    /// both; at least one of each.
    pub fn new(nodes: &[&'a str], boundaries: &[&'a str], problems: &mut Problems) -> Self {
        let mut names: BTreeMap<&str, NodeRef> = BTreeMap::new();
        for (i, &n) in nodes.iter().enumerate() {
            let p = format!("thermal.nodes[{i}].name");
            if !is_identifier(n) {
                problems.push(&p, n, "must be an identifier (letters, digits, _)");
            } else if names.insert(n, NodeRef::Node(i)).is_some() {
                problems.push(&p, n, "duplicate node name");
            }
        }
        for (i, &b) in boundaries.iter().enumerate() {
            let p = format!("thermal.boundaries[{i}].name");
            if !is_identifier(b) {
                problems.push(&p, b, "must be an identifier (letters, digits, _)");
            } else if names.insert(b, NodeRef::Boundary(i)).is_some() {
                problems.push(&p, b, "duplicate node name (nodes and boundaries share names)");
            }
        }
        if nodes.is_empty() {
            problems.push(
                "thermal.nodes",
                "",
                "at least one node with heat capacity is required",
            );
        }
        if boundaries.is_empty() {
            problems.push(
            "thermal.boundaries",
            "",
            "at least one boundary (e.g. ambient air) is required: without one no heat leaves the gearbox",
        );
        }
        NodeNames(names)
    }

    /// The reference of `name`, if known.
    pub fn get(&self, name: &str) -> Option<NodeRef> {
        self.0.get(name).copied()
    }

    /// Every name, comma-separated (sorted).
    pub fn known(&self) -> String {
        self.0.keys().copied().collect::<Vec<_>>().join(", ")
    }

    /// The reference of `name`, or a problem at `path` listing the known names.
    pub fn resolve(&self, problems: &mut Problems, path: &str, name: &str) -> Option<NodeRef> {
        let r = self.get(name);
        if r.is_none() {
            problems.push(path, name, format!("unknown node; known: {}", self.known()));
        }
        r
    }
}
