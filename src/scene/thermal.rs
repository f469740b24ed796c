//! The thermal part of a compiled scene: the network as flat arrays, split by what its terms
//! depend on, so that each is computed only as often as it changes:
//!
//! - constant conductances (conduction, fixed-h convection): once per scene;
//! - conductances that depend on the operating point only (h(v) tables and laws, rotating parts in
//!   air): once per cycle sample ([`ThermalScene::sample_conductances`]);
//! - terms that depend on the temperatures (losses through ν(T_oil), rotating parts in oil,
//!   radiation, thermostat coolers): at every right-hand-side call.

use crate::model::gearbox::{GearMount, Gearbox};
use crate::model::thermal::{BoundaryTemp, Fluid, HeatTarget, LinkLaw, NodeRef, ThermalNetwork};
use crate::physics::oil::{Oil, OilLogSlopes, OilProperties};
use crate::physics::thermal::{
    fixed_fan_density_factor, h_power_law, radiation_derivative, radiation_power, rotating_disc_h,
    rotating_disc_h_slope_with, thermostat_opening, FluidProperties, HTable, AIR_50C, OIL_CONDUCTIVITY,
    OIL_SPECIFIC_HEAT,
};

use super::controls::{Action, ControlTerm, EVENTS_PER_CONTROL, ROWS_PER_CONTROL, ROWS_PER_PI};
use super::items::{DefaultHeat, LossItem};

/// Endpoint of a compiled link: a state (capacity node) or a boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// Capacity node index.
    Node(usize),
    /// Boundary index.
    Boundary(usize),
}

impl From<NodeRef> for End {
    fn from(r: NodeRef) -> Self {
        match r {
            NodeRef::Node(i) => End::Node(i),
            NodeRef::Boundary(i) => End::Boundary(i),
        }
    }
}

/// A conductance between two ends.
#[derive(Debug, Clone)]
struct Conductance {
    a: End,
    b: End,
    g: f64,
}

/// A conductance that depends on the operating point (vehicle speed or gear speed).
#[derive(Debug, Clone)]
enum SampleLaw {
    /// A fixed conductance a controller switches, W/K.
    Fixed(f64),
    Table {
        area: f64,
        table: HTable,
    },
    Law {
        area: f64,
        h0: f64,
        h1: f64,
    },
    RotatingAir {
        area: f64,
        radius: f64,
        speed_per_input: Vec<f64>,
    },
}

#[derive(Debug, Clone)]
struct SampleLink {
    a: End,
    b: End,
    law: SampleLaw,
    /// The controller that scales it, if any.
    control: Option<usize>,
}

/// A link whose conductance depends on the oil state: a rotating part in oil (h follows the gear
/// speed and ν(T_oil)) or the oil a circuit consumer carries through a node back to the oil node.
#[derive(Debug, Clone)]
struct OilLink {
    a: End,
    b: End,
    law: OilLaw,
}

#[derive(Debug, Clone)]
enum OilLaw {
    /// Rotating-disc correlation in oil.
    Rotating {
        area: f64,
        radius: f64,
        speed_per_input: Vec<f64>,
    },
    /// Advection by the flow of circuit consumer `consumer` \[std\]: the oil enters the node at
    /// the oil node's temperature and leaves it at the node's, so the heat it carries from a to b
    /// is `ṁ c_p (T_a − T_b)`: a conductance ṁ c_p that follows the flow (and the oil's density).
    Advection { consumer: usize },
}

#[derive(Debug, Clone)]
struct Radiation {
    a: End,
    b: End,
    k: f64,
}

#[derive(Debug, Clone)]
struct CoolerTerm {
    hot: usize,
    cold: End,
    g: f64,
    thermostat: Option<(f64, f64)>,
    two_way: bool,
    /// The controller that scales it (two-point or valve), if any.
    control: Option<usize>,
    /// Air temperature (K) at which `g` holds for a fixed-speed fan's air stream: `g` scales as
    /// this over the cold side's temperature. None: fixed.
    air_ref: Option<f64>,
}

impl CoolerTerm {
    /// Conductance ε·C_min (W/K) at cold-side temperature `tc` (K) and its derivative d/dT_cold:
    /// fixed, or a fixed-speed fan's air stream following the air's density
    /// ([`fixed_fan_density_factor`]).
    #[inline]
    fn conductance(&self, tc: f64) -> (f64, f64) {
        self.air_ref.map_or((self.g, 0.0), |r| {
            let (f, df) = fixed_fan_density_factor(tc, r);
            (self.g * f, self.g * df)
        })
    }

    /// ∂q/∂T_cold of the heat flow q = g(T_cold)·x·(T_hot − T_cold) at opening `x` (which does
    /// not follow T_cold): x·(g′·(T_hot − T_cold) − g).
    #[inline]
    fn cold_slope(g: f64, dg: f64, x: f64, th: f64, tc: f64) -> f64 {
        x * (dg * (th - tc) - g)
    }

    /// Opening x and dx/dT_hot at hot-side temperature `th` and cold-side `tc`: a two-way
    /// exchanger is fully open while the cold side is warmer (it heats the oil); otherwise the
    /// thermostat, if any, sets the opening.
    fn opening(&self, th: f64, tc: f64) -> (f64, f64) {
        if self.two_way && tc > th {
            return (1.0, 0.0);
        }
        self.thermostat
            .map_or((1.0, 0.0), |(a, b)| thermostat_opening(th, a, b))
    }

    /// Opening x, dx/dT_hot, dx/dT_sensor and dx/dI (a PI valve's integral) of its controller
    /// at node temperatures `temps` with hot and cold sides `th`, `tc`, the controllers' modes
    /// and integrals in `work`. A two-way exchanger is fully open while its cold side is the
    /// warmer one (it heats the oil), whatever its controller: a bypass valve or a fan throttles
    /// the cooling direction only, as a thermostat does.
    #[inline]
    fn opening_controlled(
        &self,
        controls: &[ControlTerm],
        work: &NetworkWork,
        temps: &[f64],
        th: f64,
        tc: f64,
    ) -> (f64, f64, f64, f64) {
        match self.control {
            Some(_) if self.two_way && tc > th => (1.0, 0.0, 0.0, 0.0),
            Some(c) => {
                let k = &controls[c];
                let (x, dxs, dxi) = k.share(work.mode[c], temps[k.sensor], work.integ[c]);
                (x, 0.0, dxs, dxi)
            }
            None => {
                let (x, dx) = self.opening(th, tc);
                (x, dx, 0.0, 0.0)
            }
        }
    }
}

/// What the network needs of the operating point during one cycle interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Operating {
    /// Gear-state index.
    pub state: usize,
    /// Gearbox input speed, rad/s.
    pub input_speed: f64,
    /// Vehicle speed, m/s (for h(v)).
    pub vehicle_speed: f64,
}

/// The compiled thermal network.
#[derive(Debug, Clone)]
pub struct ThermalScene {
    /// Capacity-node names.
    pub names: Vec<String>,
    /// Boundary names.
    pub boundary_names: Vec<String>,
    /// Heat capacities, J/K.
    pub capacity: Vec<f64>,
    /// Their reciprocals, 1/(J/K) (the Jacobian multiplies).
    pub inv_capacity: Vec<f64>,
    /// The fixed links' Jacobian values, constant: the head of [`Self::network_partial_values`].
    fixed_partials: Vec<f64>,
    /// Initial temperatures, K.
    pub initial: Vec<f64>,
    /// Oil node.
    pub oil: usize,
    /// Ambient boundary, if any.
    pub ambient: Option<usize>,
    /// Heat destination of every loss item: (node, fraction).
    pub heat: Vec<Vec<(usize, f64)>>,
    boundaries: Vec<BoundaryTemp>,
    fixed: Vec<Conductance>,
    sample: Vec<SampleLink>,
    oil_links: Vec<OilLink>,
    radiation: Vec<Radiation>,
    coolers: Vec<CoolerTerm>,
    /// Controllers.
    pub controls: Vec<ControlTerm>,
    /// Per controller: its index among the PI valves, when it is one.
    pi_slot: Vec<Option<usize>>,
    /// State row of the first PI valve's rows ([`ROWS_PER_PI`] each: its integral, time at the
    /// lower and at the upper limit), set by the scene that lays out the state.
    pi_row0: usize,
    /// The thermostats' opening and fully-open temperatures as switching surfaces: no mode
    /// changes the right-hand side there, but the opening's second derivative jumps (from zero
    /// to the band's), so a step across one would integrate as if the band were not there; the
    /// integrators end a step at each crossing ([`ControlTerm`] valve-like regions).
    pub kinks: Vec<ControlTerm>,
    oil_model: Oil,
    /// c_p of the oil carried by the advection links, J/(kg·K): the oil node's `cp_j_per_kgk`
    /// (the model check requires it of a model with a `[circuit]`, the only source of advection
    /// links; [`OIL_SPECIFIC_HEAT`] stands in for a model without links).
    advection_cp: f64,
}

/// Buffers and per-sample values of the network (one per solver; no allocation when used).
#[derive(Debug, Clone)]
pub struct NetworkWork {
    /// Conductances of the operating-point-dependent links for the current sample, W/K.
    pub sample_g: Vec<f64>,
    /// Boundary temperatures at the current time, K.
    pub boundary_t: Vec<f64>,
    /// Per boundary: where its series lookup starts ([`BoundaryTemp::at_from`]).
    boundary_hint: Vec<usize>,
    /// Their rates of change, K/s ([`ThermalScene::boundary_slopes`]).
    pub boundary_slope: Vec<f64>,
    /// Mode of every controller ([`ControlTerm`]); the integrators change it only at events.
    pub mode: Vec<u8>,
    /// Region of every thermostat kink (below, in, above the band).
    pub kink_mode: Vec<u8>,
    /// Switches of every controller so far.
    pub switches: Vec<usize>,
    /// Time of every controller's last switch, s (−∞ before the first): the start of its
    /// minimum on or off time.
    pub last_switch: Vec<f64>,
    /// Every controller's integral (a PI valve's I, 0 for the others) at the state being
    /// evaluated: the scene copies it from the state before each evaluation.
    pub integ: Vec<f64>,
}

/// The oil as the fluid of the rotating-disc correlation (Pr = μ·c_p/k).
fn oil_fluid(oil: &OilProperties) -> FluidProperties {
    FluidProperties {
        conductivity: OIL_CONDUCTIVITY,
        kinematic_viscosity: oil.nu,
        prandtl: oil.mu * OIL_SPECIFIC_HEAT / OIL_CONDUCTIVITY,
    }
}

/// Speed of each gear relative to the surrounding fluid, per unit input speed, per gear state:
/// the spin for planets (the oil/air in a carrier rotates roughly with it), the absolute speed
/// otherwise.
fn fluid_speeds(gb: &Gearbox) -> Vec<Vec<f64>> {
    (0..gb.gear_states.len())
        .map(|s| {
            gb.gear_speeds(s)
                .iter()
                .zip(&gb.gears)
                .map(|(w, g)| match g.mount {
                    GearMount::Planet { .. } => w.relative,
                    GearMount::OnMember => w.absolute,
                })
                .collect()
        })
        .collect()
}

/// The network's links sorted by what their conductance depends on.
#[derive(Default)]
struct Links {
    fixed: Vec<Conductance>,
    sample: Vec<SampleLink>,
    oil: Vec<OilLink>,
    radiation: Vec<Radiation>,
}

impl Links {
    /// Mark the links called `name` as switched by controller `k` (a fixed one moves to the
    /// operating-point links).
    fn mark_controlled(&mut self, net: &ThermalNetwork, name: &str, k: usize) {
        let ends: Vec<(End, End)> = net
            .links
            .iter()
            .filter(|l| l.name == name)
            .map(|l| (End::from(l.a), End::from(l.b)))
            .collect();
        let is_target = |a: End, b: End| ends.contains(&(a, b));
        let mut moved = Vec::new();
        self.fixed.retain(|c| {
            let hit = is_target(c.a, c.b);
            if hit {
                moved.push(SampleLink {
                    a: c.a,
                    b: c.b,
                    law: SampleLaw::Fixed(c.g),
                    control: Some(k),
                });
            }
            !hit
        });
        for l in self.sample.iter_mut().filter(|l| is_target(l.a, l.b)) {
            l.control = Some(k);
        }
        self.sample.extend(moved);
    }

    /// The links of `net`; `speeds[state][gear]` is a gear's speed relative to its fluid per
    /// unit input speed ([`fluid_speeds`]).
    fn compile(net: &ThermalNetwork, speeds: &[Vec<f64>]) -> Links {
        let per_state = |gear: usize| -> Vec<f64> { speeds.iter().map(|s| s[gear].abs()).collect() };
        let mut links = Links::default();
        for l in &net.links {
            let (a, b) = (End::from(l.a), End::from(l.b));
            let sample = |law| SampleLink {
                a,
                b,
                law,
                control: None,
            };
            match &l.law {
                LinkLaw::Conductance(g) => links.fixed.push(Conductance { a, b, g: *g }),
                LinkLaw::Convection { area, h } => links.fixed.push(Conductance { a, b, g: area * h }),
                LinkLaw::Table { area, table } => links.sample.push(sample(SampleLaw::Table {
                    area: *area,
                    table: table.clone(),
                })),
                LinkLaw::Law { area, h0, h1 } => links.sample.push(sample(SampleLaw::Law {
                    area: *area,
                    h0: *h0,
                    h1: *h1,
                })),
                LinkLaw::Rotating {
                    area,
                    gear,
                    radius,
                    fluid: Fluid::Air,
                } => links.sample.push(sample(SampleLaw::RotatingAir {
                    area: *area,
                    radius: *radius,
                    speed_per_input: per_state(*gear),
                })),
                LinkLaw::Rotating {
                    area,
                    gear,
                    radius,
                    fluid: Fluid::Oil,
                } => links.oil.push(OilLink {
                    a,
                    b,
                    law: OilLaw::Rotating {
                        area: *area,
                        radius: *radius,
                        speed_per_input: per_state(*gear),
                    },
                }),
                LinkLaw::Radiation(k) => links.radiation.push(Radiation { a, b, k: *k }),
            }
        }
        links
    }
}

/// One advection link per circuit consumer whose oil flows through a capacity node other than the
/// oil node: from that node to the oil node.
fn advection_links(gb: &Gearbox, net: &ThermalNetwork) -> Vec<OilLink> {
    gb.circuit
        .consumers
        .iter()
        .enumerate()
        .filter_map(|(c, x)| {
            let node = consumer_node(gb, net, x)?;
            (node != net.oil_node).then_some(OilLink {
                a: End::Node(node),
                b: End::Node(net.oil_node),
                law: OilLaw::Advection { consumer: c },
            })
        })
        .collect()
}

/// The capacity node the oil of consumer `x` flows through: the node it names, else the node
/// that lumps its target's gears (mesh, jet: gear 1 then gear 2; set: its gears in role order);
/// none for packs and bearings without a named node.
fn consumer_node(gb: &Gearbox, net: &ThermalNetwork, x: &crate::model::gearbox::Consumer) -> Option<usize> {
    use crate::model::gearbox::Target;
    if let Some(n) = &x.node {
        return net.nodes.iter().position(|m| &m.name == n);
    }
    let body = |g: usize| net.nodes.iter().position(|m| m.gears.contains(&g));
    match x.target {
        Target::Mesh(k) | Target::Jet { mesh: k, .. } => {
            let m = &gb.meshes[k];
            body(m.gear1).or_else(|| body(m.gear2))
        }
        Target::Set { set, .. } => gb.planetary_sets[set].gears.iter().find_map(|&g| body(g)),
        Target::ClutchPack(_) | Target::Bearing(_) => None,
    }
}

/// The coolers of `net` whose hot side is a capacity node.
fn cooler_terms(net: &ThermalNetwork) -> Vec<CoolerTerm> {
    net.coolers
        .iter()
        .filter_map(|c| match c.hot {
            NodeRef::Node(h) => Some(CoolerTerm {
                hot: h,
                cold: c.cold.into(),
                g: c.conductance,
                thermostat: c.thermostat,
                two_way: c.two_way,
                control: None,
                air_ref: c.air_density_reference_k,
            }),
            NodeRef::Boundary(_) => None,
        })
        .collect()
}

/// The thermostats' band edges as switching surfaces on their hot nodes.
fn thermostat_kinks(coolers: &[CoolerTerm]) -> Vec<ControlTerm> {
    use super::controls::Law;
    coolers
        .iter()
        .filter_map(|c| {
            let (open, full) = c.thermostat?;
            Some(ControlTerm {
                name: String::new(),
                sensor: c.hot,
                law: Law::Valve {
                    closed: open,
                    open: full,
                    min: 0.0,
                    max: 1.0,
                    lo: open,
                    hi: full,
                },
                action: Action::Link,
                off_fraction: 1.0,
            })
        })
        .collect()
}

/// The controllers of `net`, compiled, and the coolers and links they act on marked with them:
/// a switched fixed-conductance link moves to the operating-point links (its conductance is
/// then set per sample and per mode).
fn compile_controls(net: &ThermalNetwork, coolers: &mut [CoolerTerm], links: &mut Links) -> Vec<ControlTerm> {
    use crate::model::thermal::ControlTarget;
    // Compiled cooler index of model cooler i: those with a capacity hot side, in order.
    let cooler_index = |i: usize| {
        net.coolers[..i]
            .iter()
            .filter(|c| matches!(c.hot, NodeRef::Node(_)))
            .count()
    };
    let mut out = Vec::with_capacity(net.controls.len());
    for (k, c) in net.controls.iter().enumerate() {
        let term = ControlTerm::compile(c, cooler_index);
        match (&c.target, term.action) {
            (_, Action::Cooler(i)) => {
                if let Some(x) = coolers.get_mut(i) {
                    x.control = Some(k);
                }
            }
            (ControlTarget::Link { link, .. }, _) => links.mark_controlled(net, link, k),
            _ => {}
        }
        out.push(term);
    }
    out
}

/// Where the heat of loss item `it` goes: (node, fraction), one entry per node, none with a zero
/// fraction. The last `[[thermal.heat]]` rule for the item wins, then the last rule for its
/// source, then the item's default.
fn heat_destination(net: &ThermalNetwork, it: &LossItem) -> Vec<(usize, f64)> {
    let key = format!("{}:{}", it.source.as_str(), it.name);
    let rule = net
        .heat
        .iter()
        .rev()
        .find(|r| r.target == HeatTarget::Item(key.clone()))
        .or_else(|| {
            net.heat
                .iter()
                .rev()
                .find(|r| r.target == HeatTarget::Source(it.source))
        });
    let mut to: Vec<(usize, f64)> = match rule {
        Some(r) => r.to.clone(),
        None => default_destination(net, it),
    };
    // Merge duplicates (both gears in one node).
    to.sort_by_key(|x| x.0);
    to.dedup_by(|x, y| {
        if x.0 == y.0 {
            y.1 += x.1;
            true
        } else {
            false
        }
    });
    to.retain(|x| x.1 != 0.0);
    to
}

/// The default heat destination of `it` in `net` (before merging duplicates).
fn default_destination(net: &ThermalNetwork, it: &LossItem) -> Vec<(usize, f64)> {
    // The body node of a gear: the node that lists it, else the oil.
    let body = |gear: usize| -> usize {
        net.nodes
            .iter()
            .position(|x| x.gears.contains(&gear))
            .unwrap_or(net.oil_node)
    };
    match &it.heat {
        DefaultHeat::Oil => vec![(net.oil_node, 1.0)],
        DefaultHeat::Gears => it.gears.iter().map(|&(g, f)| (body(g), f)).collect(),
        DefaultHeat::Member(gears) => gears.iter().map(|&(g, f)| (body(g), f)).collect(),
        DefaultHeat::Nodes(nodes) => nodes
            .iter()
            .flat_map(|(name, f)| named_destination(net, name, *f))
            .collect(),
    }
}

/// Fraction `f` of an item's heat into the node called `name`: a meshed wall's name stands for
/// its patches (each with its share); an unknown name heats the oil.
fn named_destination(net: &ThermalNetwork, name: &str, f: f64) -> Vec<(usize, f64)> {
    match net.groups.iter().find(|g| g.0 == name) {
        Some(g) => g.1.iter().map(|&(i, s)| (i, f * s)).collect(),
        None => vec![(
            net.nodes
                .iter()
                .position(|x| x.name == name)
                .unwrap_or(net.oil_node),
            f,
        )],
    }
}

impl ThermalScene {
    /// Compile the network of `gb` for the loss items `items`.
    pub fn compile(gb: &Gearbox, net: &ThermalNetwork, items: &[LossItem]) -> ThermalScene {
        let n = net.nodes.len();
        let capacity: Vec<f64> = net.nodes.iter().map(|x| x.capacity).collect();
        let initial = net
            .nodes
            .iter()
            .map(|x| x.initial_temp.unwrap_or(net.initial_temp))
            .collect();
        let mut links = Links::compile(net, &fluid_speeds(gb));
        links.oil.extend(advection_links(gb, net));
        let mut coolers = cooler_terms(net);
        let controls = compile_controls(net, &mut coolers, &mut links);
        let mut n_pi = 0;
        let pi_slot = controls
            .iter()
            .map(|c| {
                c.is_pi().then(|| {
                    n_pi += 1;
                    n_pi - 1
                })
            })
            .collect();
        debug_assert!(net.oil_node < n);
        let mut scene = ThermalScene {
            names: net.nodes.iter().map(|x| x.name.clone()).collect(),
            boundary_names: net.boundaries.iter().map(|b| b.name.clone()).collect(),
            inv_capacity: capacity.iter().map(|c| 1.0 / c).collect(),
            capacity,
            initial,
            oil: net.oil_node,
            ambient: net.ambient(),
            heat: items.iter().map(|it| heat_destination(net, it)).collect(),
            boundaries: net.boundaries.iter().map(|b| b.temp.clone()).collect(),
            fixed: links.fixed,
            sample: links.sample,
            oil_links: links.oil,
            radiation: links.radiation,
            kinks: thermostat_kinks(&coolers),
            coolers,
            controls,
            pi_slot,
            pi_row0: n,
            oil_model: gb.oil.clone(),
            advection_cp: net.nodes[net.oil_node].specific_heat.unwrap_or(OIL_SPECIFIC_HEAT),
            fixed_partials: Vec::new(),
        };
        let mut fixed_partials = Vec::new();
        scene.fixed_link_partials(&mut |r, _, d| fixed_partials.push(scene.scaled_partial(r, d)));
        scene.fixed_partials = fixed_partials;
        scene
    }

    /// Number of capacity nodes.
    pub fn len(&self) -> usize {
        self.capacity.len()
    }

    /// True when the network has no capacity node (never, for a validated network).
    pub fn is_empty(&self) -> bool {
        self.capacity.is_empty()
    }

    /// The oil model.
    pub fn oil_model(&self) -> &Oil {
        &self.oil_model
    }

    /// Oil properties at temperature `t` (K).
    pub fn oil_properties(&self, t: f64) -> OilProperties {
        self.oil_model.properties(t)
    }

    /// Oil properties at `t` (K) and their logarithmic temperature slopes.
    pub fn oil_properties_and_slopes(&self, t: f64) -> (OilProperties, OilLogSlopes) {
        self.oil_model.properties_and_slopes(t)
    }

    /// Fresh work buffers.
    pub fn work(&self) -> NetworkWork {
        NetworkWork {
            sample_g: vec![0.0; self.sample.len()],
            boundary_t: self.boundaries.iter().map(|b| b.at(0.0)).collect(),
            boundary_hint: vec![0; self.boundaries.len()],
            boundary_slope: vec![0.0; self.boundaries.len()],
            mode: self
                .controls
                .iter()
                .map(|c| c.initial_mode(c.signal(self.initial[c.sensor], c.initial_integral())))
                .collect(),
            switches: vec![0; self.controls.len()],
            last_switch: vec![f64::NEG_INFINITY; self.controls.len()],
            integ: self.controls.iter().map(ControlTerm::initial_integral).collect(),
            kink_mode: self
                .kinks
                .iter()
                .map(|c| c.initial_mode(self.initial[c.sensor]))
                .collect(),
        }
    }

    /// Hold boundary `index` at one constant temperature, K (the scenario's ambient, applied by
    /// the compile); an index beyond the boundaries is an error.
    pub(crate) fn set_boundary_fixed(&mut self, index: usize, temp: f64) -> Result<(), super::SceneError> {
        let n = self.boundaries.len();
        let b = self.boundaries.get_mut(index).ok_or_else(|| super::SceneError {
            what: format!("boundary {index}"),
            why: format!("the network has {n} boundaries"),
        })?;
        *b = BoundaryTemp::Fixed(temp);
        Ok(())
    }

    /// Temperature of boundary `index` at time `t`, K (None: no such boundary).
    pub fn boundary_temperature_at(&self, index: usize, t: f64) -> Option<f64> {
        self.boundaries.get(index).map(|b| b.at(t))
    }

    /// Make boundary `index` go linearly from `temp0` at `t0` to `temp1` at `t1` (K; constant
    /// when they are equal, and constant outside [t0, t1]): a co-simulation's boundary input over
    /// one communication step.
    pub fn set_boundary_ramp(&mut self, index: usize, (t0, temp0): (f64, f64), (t1, temp1): (f64, f64)) {
        if let Some(b) = self.boundaries.get_mut(index) {
            *b = if temp0 == temp1 || t1 <= t0 {
                BoundaryTemp::Fixed(temp0)
            } else {
                BoundaryTemp::Series(vec![(t0, temp0), (t1, temp1)])
            };
        }
    }

    /// Conductances of the operating-point-dependent links (call once per cycle sample).
    pub fn sample_conductances(&self, op: &Operating, work: &mut NetworkWork) {
        for (g, l) in work.sample_g.iter_mut().zip(&self.sample) {
            let x = l
                .control
                .map_or(1.0, |c| self.controls[c].share(work.mode[c], 0.0, 0.0).0);
            *g = x * match &l.law {
                SampleLaw::Fixed(g) => *g,
                SampleLaw::Table { area, table } => area * table.at(op.vehicle_speed),
                SampleLaw::Law { area, h0, h1 } => area * h_power_law(*h0, *h1, op.vehicle_speed),
                SampleLaw::RotatingAir {
                    area,
                    radius,
                    speed_per_input,
                } => {
                    let w = speed_per_input[op.state] * op.input_speed;
                    area * rotating_disc_h(w, *radius, &AIR_50C)
                }
            };
        }
    }

    /// True when some boundary temperature changes with time (then f depends on t).
    pub fn boundaries_move(&self) -> bool {
        self.boundaries.iter().any(|b| b.moves())
    }

    /// Boundary temperatures at time `t` (call at each RHS evaluation; constant ones are cheap).
    pub fn boundary_temperatures(&self, t: f64, work: &mut NetworkWork) {
        let hints = work.boundary_hint.iter_mut();
        for ((x, b), h) in work.boundary_t.iter_mut().zip(&self.boundaries).zip(hints) {
            *x = b.at_from(t, h);
        }
    }

    /// True when no boundary temperature changes on the pieces that follow `t` (then f does not
    /// depend on t there: ∂f/∂t = 0).
    pub fn boundaries_still_at(&self, t: f64) -> bool {
        self.boundaries.iter().all(|b| b.slope_at(t) == 0.0)
    }

    /// The boundary temperatures' rates of change at time `t` into `work.boundary_slope`.
    pub fn boundary_slopes(&self, t: f64, work: &mut NetworkWork) {
        for (x, b) in work.boundary_slope.iter_mut().zip(&self.boundaries) {
            *x = b.slope_at(t);
        }
    }

    #[inline]
    fn temp(e: End, temps: &[f64], bt: &[f64]) -> f64 {
        match e {
            End::Node(i) => temps[i],
            End::Boundary(i) => bt[i],
        }
    }

    /// Add a flow `q` (W) from `a` to `b`; heat reaching a boundary is added to `to_boundary`.
    #[inline]
    fn flow(a: End, b: End, q: f64, heat: &mut [f64], to_boundary: &mut f64) {
        match a {
            End::Node(i) => heat[i] -= q,
            End::Boundary(_) => *to_boundary -= q,
        }
        match b {
            End::Node(i) => heat[i] += q,
            End::Boundary(_) => *to_boundary += q,
        }
    }

    /// Net heat flow (W) into each node from the network (not the losses), at node temperatures
    /// `temps` (K), the rotating-in-oil links' conductances `oil_g` (W/K,
    /// [`Self::oil_link_conductances`]) and the sample conductances in `work`. Returns the heat
    /// flowing into boundaries (W). `heat` is overwritten.
    pub fn network_heat(&self, temps: &[f64], oil_g: &[f64], work: &NetworkWork, heat: &mut [f64]) -> f64 {
        heat.iter_mut().for_each(|x| *x = 0.0);
        let bt = &work.boundary_t;
        let mut to_b = 0.0;
        for c in &self.fixed {
            let q = c.g * (Self::temp(c.a, temps, bt) - Self::temp(c.b, temps, bt));
            Self::flow(c.a, c.b, q, heat, &mut to_b);
        }
        for (l, g) in self.sample.iter().zip(&work.sample_g) {
            let q = g * (Self::temp(l.a, temps, bt) - Self::temp(l.b, temps, bt));
            Self::flow(l.a, l.b, q, heat, &mut to_b);
        }
        for (l, g) in self.oil_links.iter().zip(oil_g) {
            let q = g * (Self::temp(l.a, temps, bt) - Self::temp(l.b, temps, bt));
            Self::flow(l.a, l.b, q, heat, &mut to_b);
        }
        for r in &self.radiation {
            let q = radiation_power(r.k, Self::temp(r.a, temps, bt), Self::temp(r.b, temps, bt));
            Self::flow(r.a, r.b, q, heat, &mut to_b);
        }
        for c in &self.coolers {
            let th = temps[c.hot];
            let tc = Self::temp(c.cold, temps, bt);
            let x = c.opening_controlled(&self.controls, work, temps, th, tc).0;
            let q = c.conductance(tc).0 * x * (th - tc);
            Self::flow(End::Node(c.hot), c.cold, q, heat, &mut to_b);
        }
        for (c, &m) in self.controls.iter().zip(&work.mode) {
            if let Action::Heater { node, power } = c.action {
                // The heater's power comes from outside: a negative heat into the boundaries.
                let p = if m == 1 { power } else { 0.0 };
                heat[node] += p;
                to_b -= p;
            }
        }
        to_b
    }

    /// Rows of the controllers in the state (after the boundary-energy quadrature).
    pub fn control_rows(&self) -> usize {
        self.controls.len() * ROWS_PER_CONTROL
    }

    /// Rows of the PI valves in the state (after the controllers' rows).
    pub fn pi_rows(&self) -> usize {
        self.pi_slot.iter().flatten().count() * ROWS_PER_PI
    }

    /// Lay the PI valves' rows out from state row `row` on (the scene's layout).
    pub(crate) fn set_pi_row0(&mut self, row: usize) {
        self.pi_row0 = row;
    }

    /// State row of controller `k`'s integral, when it is a PI valve.
    #[inline]
    pub fn integral_row(&self, k: usize) -> Option<usize> {
        self.pi_slot[k].map(|j| self.pi_row0 + ROWS_PER_PI * j)
    }

    /// Controller `k`'s integral in the state `y` (0 when it is not a PI valve).
    #[inline]
    pub fn integral_in(&self, k: usize, y: &[f64]) -> f64 {
        self.integral_row(k).map_or(0.0, |r| y[r])
    }

    /// Copy the PI valves' integrals of the state `y` into the work area.
    #[inline]
    pub fn load_integrals(&self, y: &[f64], work: &mut NetworkWork) {
        for (k, x) in work.integ.iter_mut().enumerate() {
            if let Some(r) = self.integral_row(k) {
                *x = y[r];
            }
        }
    }

    /// Controller `k`'s signal ([`ControlTerm::signal`]) in the state `y`.
    #[inline]
    pub fn signal_in(&self, k: usize, y: &[f64]) -> f64 {
        let c = &self.controls[k];
        c.signal(y[c.sensor], self.integral_in(k, y))
    }

    /// Switching functions of every controller at time `time` (s) and state `y` (node
    /// temperatures first, the PI valves' integrals at their rows) in the work area's modes into
    /// `g` ([`EVENTS_PER_CONTROL`] each); `time` = +∞ leaves the minimum times aside.
    pub fn switching_functions(&self, time: f64, y: &[f64], work: &NetworkWork, g: &mut [f64]) {
        let temps = y;
        let nc = self.controls.len();
        let (gc, gk) = g.split_at_mut(nc * EVENTS_PER_CONTROL);
        for (k, (c, g)) in self
            .controls
            .iter()
            .zip(gc.chunks_exact_mut(EVENTS_PER_CONTROL))
            .enumerate()
        {
            c.events_at(work.mode[k], time, work.last_switch[k], self.signal_in(k, y), g);
        }
        for ((c, &m), g) in self
            .kinks
            .iter()
            .zip(&work.kink_mode)
            .zip(gk.chunks_exact_mut(EVENTS_PER_CONTROL))
        {
            c.events(m, temps[c.sensor], g);
        }
    }

    /// The rates of the controllers' rows at `temps`: per controller the heat it moves (W: its
    /// cooler's or links' heat flow, its heater's power) and its share (on = 1); then per PI
    /// valve dI/dt and its indicators at the lower and the upper limit.
    pub fn control_rates(&self, temps: &[f64], work: &NetworkWork, out: &mut [f64]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        let bt = &work.boundary_t;
        let base = self.control_rows();
        for (k, c) in self.controls.iter().enumerate() {
            let m = work.mode[k];
            if let Some(j) = self.pi_slot[k] {
                let r = base + ROWS_PER_PI * j;
                out[r] = c.integral_rate(m, temps[c.sensor], work.integ[k]).0;
                out[r + 1] = f64::from(u8::from(m == 0));
                out[r + 2] = f64::from(u8::from(m == 2));
            }
            let (x, _, _) = c.share(m, temps[c.sensor], work.integ[k]);
            // Time on: a two-point controller's on-indicator (its share while off is not time
            // on), a valve's share.
            out[ROWS_PER_CONTROL * k + 1] = if c.is_two_point() {
                f64::from(u8::from(work.mode[k] == 1))
            } else {
                x
            };
            if let Action::Heater { power, .. } = c.action {
                out[ROWS_PER_CONTROL * k] = x * power;
            }
        }
        for c in &self.coolers {
            if let Some(k) = c.control {
                let th = temps[c.hot];
                let tc = Self::temp(c.cold, temps, bt);
                let x = c.opening_controlled(&self.controls, work, temps, th, tc).0;
                out[ROWS_PER_CONTROL * k] = c.conductance(tc).0 * x * (th - tc);
            }
        }
        for (l, g) in self.sample.iter().zip(&work.sample_g) {
            if let Some(k) = l.control {
                out[ROWS_PER_CONTROL * k] += g * (Self::temp(l.a, temps, bt) - Self::temp(l.b, temps, bt));
            }
        }
    }

    /// Partials of [`Self::control_rates`]: calls `add(row, col, d)` with `row` the offset among
    /// the controllers' rows; the sequence does not depend on the state.
    pub fn control_rate_partials(
        &self,
        temps: &[f64],
        work: &NetworkWork,
        add: &mut impl FnMut(usize, usize, f64),
    ) {
        let bt = &work.boundary_t;
        let base = self.control_rows();
        for (k, c) in self.controls.iter().enumerate() {
            let (_, dx, dxi) = c.share(work.mode[k], temps[c.sensor], work.integ[k]);
            add(ROWS_PER_CONTROL * k + 1, c.sensor, dx);
            if let (Some(j), Some(col)) = (self.pi_slot[k], self.integral_row(k)) {
                let r = base + ROWS_PER_PI * j;
                add(ROWS_PER_CONTROL * k + 1, col, dxi);
                let (_, ds, di) = c.integral_rate(work.mode[k], temps[c.sensor], work.integ[k]);
                add(r, c.sensor, ds);
                add(r, col, di);
            }
        }
        for c in &self.coolers {
            if let Some(k) = c.control {
                let th = temps[c.hot];
                let tc = Self::temp(c.cold, temps, bt);
                let (x, _, dxs, dxi) = c.opening_controlled(&self.controls, work, temps, th, tc);
                let (g, dg) = c.conductance(tc);
                let r = ROWS_PER_CONTROL * k;
                add(r, c.hot, g * x);
                if let End::Node(j) = c.cold {
                    add(r, j, CoolerTerm::cold_slope(g, dg, x, th, tc));
                }
                add(r, self.controls[k].sensor, g * dxs * (th - tc));
                if let Some(col) = self.integral_row(k) {
                    add(r, col, g * dxi * (th - tc));
                }
            }
        }
        for (l, g) in self.sample.iter().zip(&work.sample_g) {
            if let Some(k) = l.control {
                for (e, d) in [(l.a, *g), (l.b, -g)] {
                    if let End::Node(j) = e {
                        add(ROWS_PER_CONTROL * k, j, d);
                    }
                }
            }
        }
    }

    /// Directional derivative of [`Self::control_rates`] along node rates `v` and boundary
    /// rates `vb` into `out`.
    pub fn control_rate_derivative(
        &self,
        temps: &[f64],
        work: &NetworkWork,
        v: Option<&[f64]>,
        vb: Option<&[f64]>,
        out: &mut [f64],
    ) {
        out.iter_mut().for_each(|x| *x = 0.0);
        let dv = |e: End| match e {
            End::Node(i) => v.map_or(0.0, |v| v[i]),
            End::Boundary(j) => vb.map_or(0.0, |b| b[j]),
        };
        if let Some(v) = v {
            self.control_rate_partials(temps, work, &mut |r, c, d| out[r] += d * v[c]);
        }
        if vb.is_none() {
            return;
        }
        // The boundary ends' share (the node columns were added above only through `v`).
        let bt = &work.boundary_t;
        for c in &self.coolers {
            if let (Some(k), End::Boundary(_)) = (c.control, c.cold) {
                let th = temps[c.hot];
                let tc = Self::temp(c.cold, temps, bt);
                let x = c.opening_controlled(&self.controls, work, temps, th, tc).0;
                let (g, dg) = c.conductance(tc);
                out[ROWS_PER_CONTROL * k] += CoolerTerm::cold_slope(g, dg, x, th, tc) * dv(c.cold);
            }
        }
        for (l, g) in self.sample.iter().zip(&work.sample_g) {
            if let Some(k) = l.control {
                let d = |e: End| if matches!(e, End::Boundary(_)) { dv(e) } else { 0.0 };
                out[ROWS_PER_CONTROL * k] += g * (d(l.a) - d(l.b));
            }
        }
    }

    /// Conductances of the oil-state-dependent links (W/K) at the oil state `oil` into `g`, and
    /// their temperature derivatives (W/K², analytic, from the oil's logarithmic slopes) into `dg`:
    /// one per link, in the order [`Self::network_heat`] and its derivatives take them. Advection
    /// links take the consumers' mass flows `mdot` (kg/s) and their temperature derivatives
    /// `dmdot` (kg/s/K).
    #[allow(clippy::too_many_arguments)]
    pub fn oil_link_conductances(
        &self,
        oil: &OilProperties,
        slopes: &OilLogSlopes,
        op: &Operating,
        mdot: &[f64],
        dmdot: &[f64],
        g: &mut [f64],
        dg: &mut [f64],
    ) {
        let fluid = oil_fluid(oil);
        let dln_pr = slopes.nu + slopes.rho;
        let pr_cbrt = fluid.prandtl.cbrt();
        for ((g, dg), l) in g.iter_mut().zip(dg.iter_mut()).zip(&self.oil_links) {
            (*g, *dg) = match &l.law {
                OilLaw::Rotating {
                    area,
                    radius,
                    speed_per_input,
                } => {
                    let w = speed_per_input[op.state] * op.input_speed;
                    let (h, dh) = rotating_disc_h_slope_with(w, *radius, &fluid, pr_cbrt, slopes.nu, dln_pr);
                    (area * h, area * dh)
                }
                OilLaw::Advection { consumer } => (
                    mdot[*consumer] * self.advection_cp,
                    dmdot[*consumer] * self.advection_cp,
                ),
            };
        }
    }

    /// Number of advection links (circuit consumers' oil through a node).
    pub fn advection_link_count(&self) -> usize {
        self.oil_links
            .iter()
            .filter(|l| matches!(l.law, OilLaw::Advection { .. }))
            .count()
    }

    /// Number of oil-state-dependent links (rotating parts in oil and advection).
    pub fn oil_link_count(&self) -> usize {
        self.oil_links.len()
    }

    /// ∂(network heat)/∂T_oil through the oil properties alone (the rotating-in-oil links), from
    /// their conductances' derivatives `dg` ([`Self::oil_link_conductances`]): adds W/K per node
    /// into `col`, returns the boundary share. The other terms do not depend on the oil
    /// properties.
    pub fn oil_property_derivative(
        &self,
        temps: &[f64],
        dg: &[f64],
        work: &NetworkWork,
        col: &mut [f64],
    ) -> f64 {
        let bt = &work.boundary_t;
        let mut to_b = 0.0;
        for (l, dg) in self.oil_links.iter().zip(dg) {
            let dq = dg * (Self::temp(l.a, temps, bt) - Self::temp(l.b, temps, bt));
            Self::flow(l.a, l.b, dq, col, &mut to_b);
        }
        to_b
    }

    /// True when some network term depends on the oil properties (rotating parts in oil).
    pub fn has_oil_links(&self) -> bool {
        !self.oil_links.is_empty()
    }

    /// Partial derivatives of [`Self::network_heat`] (the analytic Jacobian of the network, oil
    /// properties held fixed as in [`Self::network_heat_jvp`]): calls `add(row, col, ∂q_row/∂T_col)`
    /// in W/K for every term, where `row` is the node receiving the heat or a boundary (the heat
    /// into boundaries). The sequence of `(row, col)` does not depend on the state, so a caller
    /// can record the pattern once and then fill values in the same order: the fixed links
    /// first (`Self::fixed_link_partials`), then the others.
    pub fn network_heat_partials(
        &self,
        temps: &[f64],
        oil_g: &[f64],
        work: &NetworkWork,
        add: &mut impl FnMut(End, usize, f64),
    ) {
        self.fixed_link_partials(add);
        self.varying_link_partials(temps, oil_g, work, add);
    }

    /// The network's partials as the Jacobian holds them, in [`Self::network_heat_partials`]'s
    /// order, into `vals`: node rows per unit capacity (K/s per K), boundary rows in W/K. The
    /// fixed links' values are constant and copied. Returns how many were written.
    pub fn network_partial_values(
        &self,
        temps: &[f64],
        oil_g: &[f64],
        work: &NetworkWork,
        vals: &mut [f64],
    ) -> usize {
        let mut k = self.fixed_partials.len();
        vals[..k].copy_from_slice(&self.fixed_partials);
        self.varying_link_partials(temps, oil_g, work, &mut |r, _, d| {
            vals[k] = self.scaled_partial(r, d);
            k += 1;
        });
        k
    }

    /// A partial ∂q_row/∂T as the Jacobian holds it: per unit capacity for a node row.
    #[inline]
    fn scaled_partial(&self, row: End, d: f64) -> f64 {
        match row {
            End::Node(i) => d * self.inv_capacity[i],
            End::Boundary(_) => d,
        }
    }

    /// q flows a → b with ∂q/∂T_a = da and ∂q/∂T_b = db: the entries of both ends' columns.
    #[inline]
    fn link_partials(a: End, b: End, da: f64, db: f64, add: &mut impl FnMut(End, usize, f64)) {
        for (e, d) in [(a, da), (b, db)] {
            if let End::Node(col) = e {
                add(a, col, -d);
                add(b, col, d);
            }
        }
    }

    /// The partials of the fixed-conductance links (constant).
    fn fixed_link_partials(&self, add: &mut impl FnMut(End, usize, f64)) {
        for c in &self.fixed {
            Self::link_partials(c.a, c.b, c.g, -c.g, add);
        }
    }

    /// The partials of the links whose conductance follows the sample, the oil or the
    /// temperatures.
    fn varying_link_partials(
        &self,
        temps: &[f64],
        oil_g: &[f64],
        work: &NetworkWork,
        add: &mut impl FnMut(End, usize, f64),
    ) {
        let bt = &work.boundary_t;
        for (l, g) in self.sample.iter().zip(&work.sample_g) {
            Self::link_partials(l.a, l.b, *g, -g, add);
        }
        for (l, g) in self.oil_links.iter().zip(oil_g) {
            Self::link_partials(l.a, l.b, *g, -g, add);
        }
        for r in &self.radiation {
            let (ta, tb) = (Self::temp(r.a, temps, bt), Self::temp(r.b, temps, bt));
            Self::link_partials(
                r.a,
                r.b,
                radiation_derivative(r.k, ta),
                -radiation_derivative(r.k, tb),
                add,
            );
        }
        for c in &self.coolers {
            let th = temps[c.hot];
            let tc = Self::temp(c.cold, temps, bt);
            let (x, dx, dxs, dxi) = c.opening_controlled(&self.controls, work, temps, th, tc);
            let (g, dg) = c.conductance(tc);
            Self::link_partials(
                End::Node(c.hot),
                c.cold,
                g * (x + dx * (th - tc)),
                CoolerTerm::cold_slope(g, dg, x, th, tc),
                add,
            );
            if let Some(k) = c.control {
                // The controller's sensor column: the share follows its temperature.
                let d = g * dxs * (th - tc);
                let s = self.controls[k].sensor;
                add(End::Node(c.hot), s, -d);
                add(c.cold, s, d);
                if let Some(col) = self.integral_row(k) {
                    // The PI valve's integral column: the share follows it one to one.
                    let d = g * dxi * (th - tc);
                    add(End::Node(c.hot), col, -d);
                    add(c.cold, col, d);
                }
            }
        }
    }

    /// Directional derivative of [`Self::network_heat`] along the state direction `v` (K on
    /// the nodes; the PI valves' integrals at their rows), holding the oil properties (the
    /// caller adds their T_oil dependence) and the boundary temperatures fixed: W per node into
    /// `out`; returns the derivative of the boundary heat. Allocation-free.
    pub fn network_heat_jvp(
        &self,
        temps: &[f64],
        oil_g: &[f64],
        work: &NetworkWork,
        v: &[f64],
        out: &mut [f64],
    ) -> f64 {
        let dv = |e: End| match e {
            End::Node(i) => v[i],
            End::Boundary(_) => 0.0,
        };
        let di = |k: usize| self.integral_row(k).map_or(0.0, |r| v[r]);
        self.heat_derivative(temps, oil_g, work, (dv, di), out)
    }

    /// ∂(network heat)/∂t: the response to the boundary temperatures' rates of change in
    /// `work.boundary_slope` (node temperatures and oil properties fixed): heat per node into
    /// `out` (W/s), returns the boundary share. Allocation-free.
    pub fn network_heat_time_rate(
        &self,
        temps: &[f64],
        oil_g: &[f64],
        work: &NetworkWork,
        out: &mut [f64],
    ) -> f64 {
        let dv = |e: End| match e {
            End::Node(_) => 0.0,
            End::Boundary(j) => work.boundary_slope[j],
        };
        self.heat_derivative(temps, oil_g, work, (dv, |_| 0.0), out)
    }

    /// Derivative of [`Self::network_heat`] along the rates `dv` of every end (nodes and
    /// boundaries) and `di` of every controller's integral, oil properties fixed.
    fn heat_derivative(
        &self,
        temps: &[f64],
        oil_g: &[f64],
        work: &NetworkWork,
        (dv, di): (impl Fn(End) -> f64, impl Fn(usize) -> f64),
        out: &mut [f64],
    ) -> f64 {
        out.iter_mut().for_each(|x| *x = 0.0);
        let bt = &work.boundary_t;
        let mut to_b = 0.0;
        for c in &self.fixed {
            Self::flow(c.a, c.b, c.g * (dv(c.a) - dv(c.b)), out, &mut to_b);
        }
        for (l, g) in self.sample.iter().zip(&work.sample_g) {
            Self::flow(l.a, l.b, g * (dv(l.a) - dv(l.b)), out, &mut to_b);
        }
        for (l, g) in self.oil_links.iter().zip(oil_g) {
            Self::flow(l.a, l.b, g * (dv(l.a) - dv(l.b)), out, &mut to_b);
        }
        for r in &self.radiation {
            let (ta, tb) = (Self::temp(r.a, temps, bt), Self::temp(r.b, temps, bt));
            let dq = radiation_derivative(r.k, ta) * dv(r.a) - radiation_derivative(r.k, tb) * dv(r.b);
            Self::flow(r.a, r.b, dq, out, &mut to_b);
        }
        for c in &self.coolers {
            let th = temps[c.hot];
            let tc = Self::temp(c.cold, temps, bt);
            let (x, dx, dxs, dxi) = c.opening_controlled(&self.controls, work, temps, th, tc);
            let ds = c.control.map_or(0.0, |k| {
                dxs * dv(End::Node(self.controls[k].sensor)) + dxi * di(k)
            });
            let (g, dg) = c.conductance(tc);
            let dq = g * ((x + dx * (th - tc)) * dv(End::Node(c.hot)) + ds * (th - tc))
                + CoolerTerm::cold_slope(g, dg, x, th, tc) * dv(c.cold);
            Self::flow(End::Node(c.hot), c.cold, dq, out, &mut to_b);
        }
        to_b
    }
}
