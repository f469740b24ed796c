//! `[thermal]`: the lumped thermal network in the model file and its checks into a checked
//! [`ThermalNetwork`] in SI units (temperatures in K). One file per sub-table, each with its
//! serde struct, its checks and its checked type: [`nodes`], [`boundaries`], [`links`],
//! [`coolers`], [`controls`], [`heat`], [`wall_mesh`]; [`common`] holds what they share (node references and
//! names, gears, loss items), [`network`] the checked network they make up.
//!
//! Validation reports every problem with its key path: unknown node names, duplicate names,
//! non-positive capacities, heat fractions that do not sum to 1, links with no or two laws,
//! nodes with no path to a boundary.

use crate::physics::units::c_to_k;
use serde::{Deserialize, Serialize};

pub mod boundaries;
pub mod common;
pub mod controls;
pub mod coolers;
pub mod heat;
pub mod links;
pub mod network;
pub mod nodes;
pub mod wall_mesh;

pub use boundaries::{Boundary, BoundarySpec, BoundaryTemp};
pub use common::{GearInfo, LossItemNames, NodeRef};
pub use controls::{Control, ControlKind, ControlLaw, ControlSpec, ControlTarget};
pub use coolers::{Cooler, CoolerSpec, ThermostatSpec};
pub use heat::{HeatRule, HeatSpec, HeatTarget};
pub use links::{Fluid, HLawSpec, HTableSpec, Link, LinkLaw, LinkSpec, RotatingSpec};
pub use network::ThermalNetwork;
pub use nodes::{NodeSpec, ThermalNode};
pub use wall_mesh::WallMeshSpec;

use crate::model::problems::Problems;
use common::{temp_ok, NodeNames};

/// `[thermal]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ThermalSpec {
    /// Node whose temperature sets ν(T) and ρ(T) of the oil for every loss model.
    pub oil_node: String,
    /// Initial temperature of every node without its own, °C (default 23; `run --initial-temp-c`
    /// overrides both).
    #[serde(default)]
    pub initial_temp_c: Option<f64>,
    /// `[[thermal.nodes]]`: nodes with heat capacity.
    #[serde(default)]
    pub nodes: Vec<NodeSpec>,
    /// `[[thermal.boundaries]]`: nodes with a given temperature.
    #[serde(default)]
    pub boundaries: Vec<BoundarySpec>,
    /// `[[thermal.links]]`: conductances, convection, radiation.
    #[serde(default)]
    pub links: Vec<LinkSpec>,
    /// `[[thermal.coolers]]`: heat exchangers with an optional thermostat.
    #[serde(default)]
    pub coolers: Vec<CoolerSpec>,
    /// `[[thermal.controls]]`: two-point controllers and bypass valves.
    #[serde(default)]
    pub controls: Vec<ControlSpec>,
    /// `[[thermal.heat]]`: where loss heat goes (overrides of the defaults).
    #[serde(default)]
    pub heat: Vec<HeatSpec>,
    /// `[thermal.wall_mesh]`: discretise a wall node into patches (see [`wall_mesh`]).
    #[serde(default)]
    pub wall_mesh: Option<WallMeshSpec>,
}

/// Default initial temperature, °C (a cold start in a test cell).
pub const DEFAULT_INITIAL_TEMP_C: f64 = 23.0;

/// Validate `[thermal]` against the gears (names, radii) and the loss items (names per source)
/// of the model.
pub fn validate_thermal(
    spec: &ThermalSpec,
    gears: &[GearInfo<'_>],
    items: &LossItemNames<'_>,
    problems: &mut Problems,
) -> Option<ThermalNetwork> {
    let start = problems.len();
    let initial = spec.initial_temp_c.unwrap_or(DEFAULT_INITIAL_TEMP_C);
    temp_ok(problems, "thermal.initial_temp_c", initial);
    let node_names: Vec<&str> = spec.nodes.iter().map(|n| n.name.as_str()).collect();
    let boundary_names: Vec<&str> = spec.boundaries.iter().map(|b| b.name.as_str()).collect();
    let names = NodeNames::new(&node_names, &boundary_names, problems);
    let nodes = nodes::check_nodes(&spec.nodes, gears, problems);
    let boundaries = boundaries::check_boundaries(&spec.boundaries, problems);
    let links = links::check_links(&spec.links, &names, gears, problems);
    let coolers = coolers::check_coolers(&spec.coolers, &names, problems);
    let controls = controls::check_controls(&spec.controls, &names, &coolers, &links, problems);
    let oil_node = oil_node(&spec.oil_node, &names, problems);
    let heat = heat::check_heat(&spec.heat, &names, items, problems);
    if problems.len() == start {
        check_connected(&nodes, &links, &coolers, problems);
    }
    if problems.len() > start {
        return None;
    }
    let net = ThermalNetwork {
        nodes,
        boundaries,
        links,
        coolers,
        controls,
        heat,
        oil_node: oil_node?,
        initial_temp: c_to_k(initial),
        groups: Vec::new(),
    };
    Some(match &spec.wall_mesh {
        Some(m) => wall_mesh::mesh_wall(net, m, problems),
        None => net,
    })
}

/// `oil_node`: a node with capacity.
fn oil_node(name: &str, names: &NodeNames<'_>, problems: &mut Problems) -> Option<usize> {
    match names.get(name) {
        Some(NodeRef::Node(i)) => Some(i),
        Some(NodeRef::Boundary(_)) => {
            problems.push(
                "thermal.oil_node",
                name,
                "must be a node with capacity, not a boundary",
            );
            None
        }
        None => {
            problems.push(
                "thermal.oil_node",
                name,
                format!("unknown node; known: {}", names.known()),
            );
            None
        }
    }
}

/// Every node needs a path to a boundary (else its temperature grows without bound and the
/// steady state does not exist).
fn check_connected(nodes: &[ThermalNode], links: &[Link], coolers: &[Cooler], problems: &mut Problems) {
    let mut reach = vec![false; nodes.len()];
    let edges: Vec<(NodeRef, NodeRef)> = links
        .iter()
        .map(|l| (l.a, l.b))
        .chain(coolers.iter().map(|c| (c.hot, c.cold)))
        .collect();
    let reached = |reach: &[bool], r: NodeRef| match r {
        NodeRef::Boundary(_) => true,
        NodeRef::Node(i) => reach[i],
    };
    let mut changed = true;
    while changed {
        changed = false;
        for &(a, b) in &edges {
            let (ra, rb) = (reached(&reach, a), reached(&reach, b));
            for (x, other) in [(a, rb), (b, ra)] {
                if let NodeRef::Node(i) = x {
                    if other && !reach[i] {
                        reach[i] = true;
                        changed = true;
                    }
                }
            }
        }
    }
    for (i, r) in reach.iter().enumerate() {
        if !r {
            problems.push(
                format!("thermal.nodes[{i}]"),
                &nodes[i].name,
                "isolated: no chain of links or coolers connects this node to a boundary",
            );
        }
    }
}
