//! `[thermal.wall_mesh]`: discretise one lumped wall node (the housing) into a grid of patches.
//!
//! A gearbox case is a thin shell: its temperature varies over the surface (hot near the oil
//! pool and the bearing seats, cooler where the air flow strikes), which one lumped housing node
//! cannot show. The mesh replaces the node by `around × along` patches of a cylindrical shell of
//! circumference `c` and length `l` (wall thickness `t`, conductivity `k`):
//!
//! - each patch carries `C/N` of the node's heat capacity (N = around × along);
//! - neighbours conduct through the wall: G = k·t·(edge length)/(centre distance), i.e.
//!   `k·t·(l/along)/(c/around)` around the shell (periodic: the last column touches the first)
//!   and `k·t·(c/around)/(l/along)` along it (one-dimensional conduction in the shell plane,
//!   Incropera & DeWitt, *Fundamentals of Heat and Mass Transfer*, 6th ed., §4.4 finite-difference
//!   nodal network);
//! - every link of the lumped node (convection to the oil and the air, radiation, conductances to
//!   the shafts) is split evenly over the patches by area (`area/N`, `G/N`, `σεA/N`): a uniform
//!   film coefficient over the wall, as the lumped link assumed;
//! - except the links to the oil node when `oil_wetted_fraction` is given: those are split over
//!   the wetted columns only (the sump pool wets the lower part of the case);
//! - heat sent to the node (heat rules, `heat_to` of bearings and seals) is split evenly.
//!
//! With an infinitely conducting wall the patches move together and the mesh reduces exactly to
//! the lumped node (tested). The network then has N − 1 more nodes: the generator of the large
//! networks the sparse LU is for (docs/performance.md, "Large networks").

use serde::{Deserialize, Serialize};

use super::common::NodeRef;
use super::links::{Link, LinkLaw};
use super::network::ThermalNetwork;
use super::nodes::ThermalNode;
use crate::model::problems::Problems;

/// `[thermal.wall_mesh]` as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WallMeshSpec {
    /// The lumped wall node to discretise (not the oil node; it must lump no gears).
    pub node: String,
    /// Patches around the shell (periodic), ≥ 1.
    pub around: usize,
    /// Patches along its axis, ≥ 1.
    pub along: usize,
    /// Circumference (developed width) of the shell, m.
    pub circumference_m: f64,
    /// Length of the shell, m.
    pub length_m: f64,
    /// Wall thickness, mm.
    pub thickness_mm: f64,
    /// Thermal conductivity of the wall material, W/(m·K).
    pub conductivity_w_per_mk: f64,
    /// Fraction of the patches around the shell that the oil wets (the sump pool: the first
    /// `ceil(fraction × around)` columns, all along the axis); the node's links to the oil node
    /// are split over these patches only. Default 1: the oil links are spread over the whole wall
    /// like every other link.
    #[serde(default)]
    pub oil_wetted_fraction: Option<f64>,
}

/// Largest number of patches (a million-node network is not a gearbox model).
pub const MAX_PATCHES: usize = 100_000;

impl WallMeshSpec {
    /// Number of patches.
    pub fn patches(&self) -> usize {
        self.around * self.along
    }

    /// Conductances between neighbours (around, along), W/K.
    pub fn conductances(&self) -> (f64, f64) {
        let kt = self.conductivity_w_per_mk * self.thickness_mm * 1e-3;
        let (dc, dl) = (
            self.circumference_m / self.around as f64,
            self.length_m / self.along as f64,
        );
        (kt * dl / dc, kt * dc / dl)
    }

    fn check(&self, problems: &mut Problems) {
        let p = "thermal.wall_mesh";
        problems.in_range(
            &format!("{p}.around"),
            self.around as f64,
            1.0,
            MAX_PATCHES as f64,
            "",
        );
        problems.in_range(
            &format!("{p}.along"),
            self.along as f64,
            1.0,
            MAX_PATCHES as f64,
            "",
        );
        if self.patches() > MAX_PATCHES {
            problems.push(
                p,
                self.patches(),
                format!("around × along must be at most {MAX_PATCHES} patches"),
            );
        }
        problems.in_range(
            &format!("{p}.circumference_m"),
            self.circumference_m,
            1e-3,
            100.0,
            " m",
        );
        problems.in_range(&format!("{p}.length_m"), self.length_m, 1e-3, 100.0, " m");
        problems.in_range(&format!("{p}.thickness_mm"), self.thickness_mm, 0.1, 200.0, " mm");
        problems.in_range(
            &format!("{p}.conductivity_w_per_mk"),
            self.conductivity_w_per_mk,
            0.01,
            1e5,
            " W/(m·K)",
        );
        if let Some(f) = self.oil_wetted_fraction {
            problems.in_range(&format!("{p}.oil_wetted_fraction"), f, 1e-6, 1.0, "");
        }
    }

    /// Number of wetted columns around the shell.
    pub fn wetted_columns(&self) -> usize {
        let f = self.oil_wetted_fraction.unwrap_or(1.0);
        ((f * self.around as f64).ceil() as usize).clamp(1, self.around.max(1))
    }
}

/// Name of patch (i around, j along) of wall node `node`.
pub fn patch_name(node: &str, i: usize, j: usize) -> String {
    format!("{node}_{i}_{j}")
}

/// True when controller `c` switches a link with an end at node `h`.
fn switches_link_of(net: &ThermalNetwork, c: &super::controls::Control, h: usize) -> bool {
    let super::controls::ControlTarget::Link { link, .. } = &c.target else {
        return false;
    };
    net.links
        .iter()
        .any(|l| &l.name == link && (l.a == NodeRef::Node(h) || l.b == NodeRef::Node(h)))
}

/// Replace the node `spec.node` of `net` by the patches of `spec`. Problems (unknown node, the oil
/// node, a node lumping gears or feeding a cooler, out-of-range sizes) go to `problems` with the
/// key path; the network is returned unchanged then.
pub fn mesh_wall(mut net: ThermalNetwork, spec: &WallMeshSpec, problems: &mut Problems) -> ThermalNetwork {
    let start = problems.len();
    spec.check(problems);
    let path = "thermal.wall_mesh.node";
    let h = net.nodes.iter().position(|n| n.name == spec.node);
    match h {
        None => problems.push(path, &spec.node, "unknown node (a node with heat capacity)"),
        Some(h) if h == net.oil_node => {
            problems.push(path, &spec.node, "the oil node cannot be meshed as a wall")
        }
        Some(h) if !net.nodes[h].gears.is_empty() => {
            problems.push(path, &spec.node, "a node that lumps gears is not a wall")
        }
        Some(h)
            if net
                .coolers
                .iter()
                .any(|c| c.hot == NodeRef::Node(h) || c.cold == NodeRef::Node(h)) =>
        {
            problems.push(path, &spec.node, "a cooler side cannot be meshed as a wall")
        }
        Some(h) if net.controls.iter().any(|c| c.reads_or_heats(h) || switches_link_of(&net, c, h)) => {
            problems.push(
                path,
                &spec.node,
                "a controller's sensor or heater node, or an end of a link a controller switches, cannot be meshed as a wall",
            )
        }
        Some(_) => {}
    }
    let Some(h) = h.filter(|_| problems.len() == start) else {
        return net;
    };
    let n = spec.patches();
    let scale = 1.0 / n as f64;
    let base = net.nodes[h].clone();
    let patch = |i: usize, j: usize| ThermalNode {
        name: patch_name(&base.name, i, j),
        capacity: base.capacity * scale,
        initial_temp: base.initial_temp,
        specific_heat: base.specific_heat,
        gears: Vec::new(),
    };
    // Patch (0, 0) takes the node's index (other indices stay valid); the rest are appended.
    let first_new = net.nodes.len();
    let index = |i: usize, j: usize| -> usize {
        let k = j * spec.around + i;
        if k == 0 {
            h
        } else {
            first_new + k - 1
        }
    };
    net.nodes[h] = patch(0, 0);
    for k in 1..n {
        net.nodes.push(patch(k % spec.around, k / spec.around));
    }
    let all: Vec<usize> = (0..n).map(|k| index(k % spec.around, k / spec.around)).collect();
    let wet = spec.wetted_columns();
    let wetted: Vec<usize> = (0..n)
        .filter(|k| k % spec.around < wet)
        .map(|k| index(k % spec.around, k / spec.around))
        .collect();

    // Split the node's links over the patches.
    let mut links = Vec::with_capacity(net.links.len() + 3 * n);
    for l in net.links.drain(..) {
        let touches = |r: NodeRef| r == NodeRef::Node(h);
        if !touches(l.a) && !touches(l.b) {
            links.push(l);
            continue;
        }
        let oil = NodeRef::Node(net.oil_node);
        let targets: Vec<usize> = if l.a == oil || l.b == oil {
            wetted.clone()
        } else {
            all.clone()
        };
        let law = l.law.scaled(1.0 / targets.len() as f64);
        let at = |r: NodeRef, p: usize| if touches(r) { NodeRef::Node(p) } else { r };
        for &p in &targets {
            links.push(Link {
                name: format!("{} [{}]", l.name, net.nodes[p].name),
                a: at(l.a, p),
                b: at(l.b, p),
                law: law.clone(),
            });
        }
    }
    // Conduction in the wall between neighbours.
    let (g_around, g_along) = spec.conductances();
    for j in 0..spec.along {
        for i in 0..spec.around {
            let a = index(i, j);
            let mut link = |b: usize, g: f64| {
                links.push(Link {
                    name: format!("wall {} – {}", net.nodes[a].name, net.nodes[b].name),
                    a: NodeRef::Node(a),
                    b: NodeRef::Node(b),
                    law: LinkLaw::Conductance(g),
                });
            };
            // Periodic around the shell (two patches around: two paths, one on each side).
            if spec.around > 1 {
                link(index((i + 1) % spec.around, j), g_around);
            }
            if j + 1 < spec.along {
                link(index(i, j + 1), g_along);
            }
        }
    }
    net.links = links;

    // Heat rules and named heat destinations: split evenly.
    for rule in &mut net.heat {
        let mut to = Vec::with_capacity(rule.to.len() + n);
        for &(node, f) in &rule.to {
            if node == h {
                to.extend(all.iter().map(|&p| (p, f * scale)));
            } else {
                to.push((node, f));
            }
        }
        rule.to = to;
    }
    net.groups
        .push((base.name.clone(), all.iter().map(|&p| (p, scale)).collect()));
    net
}
