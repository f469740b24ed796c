//! The checked thermal network: nodes with capacity, boundaries, links with their laws, coolers
//! and heat rules, in SI units (temperatures in K); the scene compiles it. Each part's type is
//! defined beside its sub-table.

use super::boundaries::Boundary;
use super::common::NodeRef;
use super::controls::Control;
use super::coolers::Cooler;
use super::heat::HeatRule;
use super::links::Link;
use super::nodes::ThermalNode;

/// The checked thermal network.
#[derive(Debug, Clone)]
pub struct ThermalNetwork {
    /// Nodes with capacity.
    pub nodes: Vec<ThermalNode>,
    /// Boundary nodes.
    pub boundaries: Vec<Boundary>,
    /// Links.
    pub links: Vec<Link>,
    /// Coolers.
    pub coolers: Vec<Cooler>,
    /// Controllers.
    pub controls: Vec<Control>,
    /// Heat rules (item rules override source rules, which override the defaults).
    pub heat: Vec<HeatRule>,
    /// Oil node index.
    pub oil_node: usize,
    /// Default initial temperature, K.
    pub initial_temp: f64,
    /// Names that stand for several nodes (a meshed wall): heat sent to the name is split over
    /// (node, fraction).
    pub groups: Vec<(String, Vec<(usize, f64)>)>,
}

impl ThermalNetwork {
    /// Name of a node reference.
    pub fn name(&self, r: NodeRef) -> &str {
        match r {
            NodeRef::Node(i) => &self.nodes[i].name,
            NodeRef::Boundary(i) => &self.boundaries[i].name,
        }
    }

    /// Index of the ambient boundary, if any.
    pub fn ambient(&self) -> Option<usize> {
        self.boundaries.iter().position(|b| b.ambient)
    }
}
