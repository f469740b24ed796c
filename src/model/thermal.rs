//! `[thermal]`: the lumped thermal network in the model file (schema) and its validation into a
//! checked [`ThermalNetwork`] in SI units (temperatures in K).
//!
//! Validation reports every problem with its key path: unknown node names, duplicate names,
//! non-positive capacities, heat fractions that do not sum to 1, links with no or two laws,
//! nodes with no path to a boundary.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::problems::Problems;
use super::source::{Source, N_SOURCES};
use crate::physics::oil::KELVIN_OFFSET;
use crate::physics::thermal::{HTable, STEFAN_BOLTZMANN};

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
    /// `[[thermal.heat]]`: where loss heat goes (overrides of the defaults).
    #[serde(default)]
    pub heat: Vec<HeatSpec>,
    /// `[thermal.wall_mesh]`: discretise a wall node into patches (see [`super::wall_mesh`]).
    #[serde(default)]
    pub wall_mesh: Option<super::wall_mesh::WallMeshSpec>,
}

/// A node with heat capacity: `capacity_j_per_k`, or `mass_kg` × `cp_j_per_kgk`.
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

/// A boundary node: fixed temperature or a time series.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Identifier.
    pub name: String,
    /// Fixed temperature, °C.
    #[serde(default)]
    pub temp_c: Option<f64>,
    /// Time series `[[time_s, temp_c], ...]`, linear in between, constant beyond the ends.
    #[serde(default)]
    pub series: Option<Vec<[f64; 2]>>,
    /// The ambient air (set by `--ambient-c`); default: the boundary named `ambient`.
    #[serde(default)]
    pub ambient: Option<bool>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// h(v) table against vehicle speed.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HTableSpec {
    /// Vehicle speeds, km/h, increasing.
    pub speed_kmh: Vec<f64>,
    /// Heat-transfer coefficients, W/(m²·K).
    pub h_w_per_m2k: Vec<f64>,
}

/// h = h0 + h1·v^0.8 (v in m/s).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HLawSpec {
    /// h at rest, W/(m²·K).
    pub h0_w_per_m2k: f64,
    /// Coefficient of v^0.8, W/(m²·K)/(m/s)^0.8.
    pub h1: f64,
}

/// Fluid around a rotating part.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Fluid {
    /// Air at 50 °C.
    Air,
    /// The gearbox oil at the oil node's temperature.
    Oil,
}

/// Rotating-disc correlation on a gear.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RotatingSpec {
    /// Gear whose speed and tip radius are used.
    pub gear: String,
    /// Surrounding fluid.
    pub fluid: Fluid,
}

/// A link between two nodes; exactly one law.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LinkSpec {
    /// Display name (default `a-b`).
    #[serde(default)]
    pub name: Option<String>,
    /// The two nodes (either may be a boundary).
    pub between: [String; 2],
    /// Conductance G, W/K.
    #[serde(default)]
    pub conductance_w_per_k: Option<f64>,
    /// Area for convection or radiation, m².
    #[serde(default)]
    pub area_m2: Option<f64>,
    /// Fixed convection coefficient, W/(m²·K).
    #[serde(default)]
    pub h_w_per_m2k: Option<f64>,
    /// h(v) table.
    #[serde(default)]
    pub h_table: Option<HTableSpec>,
    /// h = h0 + h1 v^0.8.
    #[serde(default)]
    pub h_law: Option<HLawSpec>,
    /// Rotating-disc correlation.
    #[serde(default)]
    pub rotating: Option<RotatingSpec>,
    /// Radiation with this effective emissivity.
    #[serde(default)]
    pub emissivity: Option<f64>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// Thermostat: closed below `open_c`, fully open above `full_c`, smooth in between.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ThermostatSpec {
    /// Start of opening, °C.
    pub open_c: f64,
    /// Fully open, °C.
    pub full_c: f64,
}

/// Heat exchanger `Q = ε·C_min·x(T_hot)·(T_hot − T_cold)`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CoolerSpec {
    /// Display name.
    pub name: String,
    /// Node on the oil side (its temperature drives the thermostat).
    pub hot: String,
    /// Node on the coolant side (usually a boundary).
    pub cold: String,
    /// Effectiveness ε, 0..1.
    pub effectiveness: f64,
    /// Smaller capacity rate ṁ·c_p of the two streams, W/K.
    pub capacity_rate_w_per_k: f64,
    /// Optional thermostat on the hot side.
    #[serde(default)]
    pub thermostat: Option<ThermostatSpec>,
    /// Two-way exchanger (ATF warmer/cooler): while the cold side is warmer than the hot side
    /// the exchanger is fully open and heats the oil (the thermostat throttles only the cooling
    /// direction). Default false: a cooler that never heats.
    #[serde(default)]
    pub two_way: bool,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// Where the heat of a loss item, or of all items of a source, goes.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HeatSpec {
    /// One item: `churning:<gear>`, `pocketing:<mesh>` or `sliding:<mesh>`.
    #[serde(default)]
    pub item: Option<String>,
    /// Every item of a source: `churning`, `pocketing` or `sliding`.
    #[serde(default)]
    pub source: Option<String>,
    /// Node → fraction (sum 1).
    pub to: BTreeMap<String, f64>,
}

/// A node reference: capacity node or boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeRef {
    /// Index into [`ThermalNetwork::nodes`].
    Node(usize),
    /// Index into [`ThermalNetwork::boundaries`].
    Boundary(usize),
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
    /// Gear indices whose bodies this node lumps.
    pub gears: Vec<usize>,
}

/// Temperature of a boundary.
#[derive(Debug, Clone)]
pub enum BoundaryTemp {
    /// Constant, K.
    Fixed(f64),
    /// (time s, K) pairs, strictly increasing time.
    Series(Vec<(f64, f64)>),
}

impl BoundaryTemp {
    /// True when the temperature changes with time.
    pub fn moves(&self) -> bool {
        match self {
            BoundaryTemp::Fixed(_) => false,
            BoundaryTemp::Series(s) => s.windows(2).any(|w| w[0].1 != w[1].1),
        }
    }

    /// dT/dt (K/s) on the piece the series follows just after `t` (a kink at `t` gives the
    /// slope of the piece that starts there); 0 before the first and after the last point.
    pub fn slope_at(&self, t: f64) -> f64 {
        match self {
            BoundaryTemp::Fixed(_) => 0.0,
            BoundaryTemp::Series(s) => {
                let k = s.partition_point(|p| p.0 <= t);
                if k == 0 || k == s.len() {
                    0.0
                } else {
                    let (a, b) = (s[k - 1], s[k]);
                    (b.1 - a.1) / (b.0 - a.0)
                }
            }
        }
    }

    /// Temperature at time `t`, K.
    pub fn at(&self, t: f64) -> f64 {
        match self {
            BoundaryTemp::Fixed(v) => *v,
            BoundaryTemp::Series(s) => {
                let k = s.partition_point(|p| p.0 <= t);
                if k == 0 {
                    s[0].1
                } else if k == s.len() {
                    s[s.len() - 1].1
                } else {
                    let (a, b) = (s[k - 1], s[k]);
                    a.1 + (t - a.0) / (b.0 - a.0) * (b.1 - a.1)
                }
            }
        }
    }
}

/// A checked boundary node.
#[derive(Debug, Clone)]
pub struct Boundary {
    /// Name.
    pub name: String,
    /// Temperature law.
    pub temp: BoundaryTemp,
    /// True for the ambient air.
    pub ambient: bool,
}

/// Law of a link.
#[derive(Debug, Clone)]
pub enum LinkLaw {
    /// Constant conductance, W/K.
    Conductance(f64),
    /// Convection with a fixed h: G = h·A, W/K (kept apart to report h·A).
    Convection {
        /// Area, m².
        area: f64,
        /// h, W/m²K.
        h: f64,
    },
    /// h(v) table against vehicle speed (m/s inside).
    Table {
        /// Area, m².
        area: f64,
        /// Table in m/s → W/m²K.
        table: HTable,
    },
    /// h0 + h1·v^0.8.
    Law {
        /// Area, m².
        area: f64,
        /// h0, W/m²K.
        h0: f64,
        /// h1, W/m²K/(m/s)^0.8.
        h1: f64,
    },
    /// Rotating-disc correlation on a gear.
    Rotating {
        /// Area, m².
        area: f64,
        /// Gear index.
        gear: usize,
        /// Disc radius, m.
        radius: f64,
        /// Fluid.
        fluid: Fluid,
    },
    /// Radiation, σ·ε·A in W/K⁴.
    Radiation(f64),
}

/// A checked link.
#[derive(Debug, Clone)]
pub struct Link {
    /// Name.
    pub name: String,
    /// From.
    pub a: NodeRef,
    /// To.
    pub b: NodeRef,
    /// Law.
    pub law: LinkLaw,
}

/// A checked cooler.
#[derive(Debug, Clone)]
pub struct Cooler {
    /// Name.
    pub name: String,
    /// Hot (oil) side.
    pub hot: NodeRef,
    /// Cold side.
    pub cold: NodeRef,
    /// ε·C_min, W/K.
    pub conductance: f64,
    /// Thermostat (open, full) in K.
    pub thermostat: Option<(f64, f64)>,
    /// Heats the oil, fully open, while the cold side is the warmer one.
    pub two_way: bool,
}

/// What a heat rule applies to.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum HeatTarget {
    /// All items of a source (`churning`, `pocketing`, `sliding`).
    Source(String),
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

/// Default initial temperature, °C (a cold start in a test cell).
pub const DEFAULT_INITIAL_TEMP_C: f64 = 23.0;

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
    fn knows(&self, item: &str) -> bool {
        item.split_once(':')
            .and_then(|(s, n)| Source::parse(s).map(|s| self.of(s).contains(&n)))
            .unwrap_or(false)
    }
}

fn is_identifier(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

fn temp_ok(problems: &mut Problems, path: &str, t: f64) -> bool {
    problems.in_range(path, t, -60.0, 300.0, " °C")
}

/// Gear information the thermal validation needs.
pub struct GearInfo<'a> {
    /// Gear name.
    pub name: &'a str,
    /// Outer radius of the body (tip, or root for internal gears), m.
    pub radius: f64,
    /// Face width, m.
    pub face_width: f64,
}

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

    // Names: identifiers, unique over nodes and boundaries.
    let mut names: BTreeMap<&str, NodeRef> = BTreeMap::new();
    for (i, n) in spec.nodes.iter().enumerate() {
        let p = format!("thermal.nodes[{i}].name");
        if !is_identifier(&n.name) {
            problems.push(&p, &n.name, "must be an identifier (letters, digits, _)");
        } else if names.insert(&n.name, NodeRef::Node(i)).is_some() {
            problems.push(&p, &n.name, "duplicate node name");
        }
    }
    for (i, b) in spec.boundaries.iter().enumerate() {
        let p = format!("thermal.boundaries[{i}].name");
        if !is_identifier(&b.name) {
            problems.push(&p, &b.name, "must be an identifier (letters, digits, _)");
        } else if names.insert(&b.name, NodeRef::Boundary(i)).is_some() {
            problems.push(
                &p,
                &b.name,
                "duplicate node name (nodes and boundaries share names)",
            );
        }
    }
    if spec.nodes.is_empty() {
        problems.push(
            "thermal.nodes",
            "",
            "at least one node with heat capacity is required",
        );
    }
    if spec.boundaries.is_empty() {
        problems.push(
            "thermal.boundaries",
            "",
            "at least one boundary (e.g. ambient air) is required: without one no heat leaves the gearbox",
        );
    }
    let known = |names: &BTreeMap<&str, NodeRef>| names.keys().copied().collect::<Vec<_>>().join(", ");
    let resolve = |problems: &mut Problems, path: &str, name: &str| -> Option<NodeRef> {
        let r = names.get(name).copied();
        if r.is_none() {
            problems.push(path, name, format!("unknown node; known: {}", known(&names)));
        }
        r
    };

    // Nodes.
    let mut gear_owner: BTreeMap<usize, usize> = BTreeMap::new();
    let mut nodes = Vec::new();
    for (i, n) in spec.nodes.iter().enumerate() {
        let p = format!("thermal.nodes[{i}]");
        let capacity = match (n.capacity_j_per_k, n.mass_kg, n.cp_j_per_kgk) {
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
                    &p,
                    "",
                    "give either capacity_j_per_k, or mass_kg and cp_j_per_kgk (not both)",
                );
                f64::NAN
            }
        };
        if let Some(t) = n.initial_temp_c {
            temp_ok(problems, &format!("{p}.initial_temp_c"), t);
        }
        let mut gi = Vec::new();
        for (k, g) in n.gears.iter().enumerate() {
            let gp = format!("{p}.gears[{k}]");
            match gears.iter().position(|x| x.name == g) {
                Some(idx) => {
                    if let Some(prev) = gear_owner.insert(idx, i) {
                        problems.push(
                            &gp,
                            g,
                            format!("gear already lumped in node {}", spec.nodes[prev].name),
                        );
                    }
                    gi.push(idx);
                }
                None => problems.push(&gp, g, "unknown gear"),
            }
        }
        nodes.push(ThermalNode {
            name: n.name.clone(),
            capacity,
            initial_temp: n.initial_temp_c.map(|t| t + KELVIN_OFFSET),
            gears: gi,
        });
    }

    // Boundaries.
    let mut boundaries = Vec::new();
    for (i, b) in spec.boundaries.iter().enumerate() {
        let p = format!("thermal.boundaries[{i}]");
        let temp = match (&b.temp_c, &b.series) {
            (Some(t), None) => {
                temp_ok(problems, &format!("{p}.temp_c"), *t);
                BoundaryTemp::Fixed(t + KELVIN_OFFSET)
            }
            (None, Some(s)) if !s.is_empty() => {
                let mut ok = true;
                for (k, pt) in s.iter().enumerate() {
                    ok &= temp_ok(problems, &format!("{p}.series[{k}][1]"), pt[1]);
                    if !pt[0].is_finite() || (k > 0 && pt[0] <= s[k - 1][0]) {
                        problems.push(
                            format!("{p}.series[{k}][0]"),
                            pt[0],
                            "times must increase strictly",
                        );
                        ok = false;
                    }
                }
                if !ok {
                    continue;
                }
                BoundaryTemp::Series(s.iter().map(|pt| (pt[0], pt[1] + KELVIN_OFFSET)).collect())
            }
            _ => {
                problems.push(&p, "", "give either temp_c or a non-empty series (not both)");
                continue;
            }
        };
        boundaries.push(Boundary {
            name: b.name.clone(),
            temp,
            ambient: b.ambient.unwrap_or(false),
        });
    }
    if boundaries.iter().filter(|b| b.ambient).count() > 1 {
        problems.push(
            "thermal.boundaries",
            "",
            "at most one boundary may be marked ambient = true",
        );
    }
    if !boundaries.iter().any(|b| b.ambient) {
        if let Some(b) = boundaries.iter_mut().find(|b| b.name == "ambient") {
            b.ambient = true;
        }
    }

    // Links.
    let mut links = Vec::new();
    for (i, l) in spec.links.iter().enumerate() {
        let p = format!("thermal.links[{i}]");
        let a = resolve(problems, &format!("{p}.between[0]"), &l.between[0]);
        let b = resolve(problems, &format!("{p}.between[1]"), &l.between[1]);
        if l.between[0] == l.between[1] {
            problems.push(
                format!("{p}.between"),
                &l.between[0],
                "a link needs two different nodes",
            );
        }
        let laws = [
            l.conductance_w_per_k.is_some(),
            l.h_w_per_m2k.is_some(),
            l.h_table.is_some(),
            l.h_law.is_some(),
            l.rotating.is_some(),
            l.emissivity.is_some(),
        ];
        if laws.iter().filter(|&&x| x).count() != 1 {
            problems.push(
                &p,
                "",
                "give exactly one law: conductance_w_per_k, h_w_per_m2k, h_table, h_law, rotating or emissivity",
            );
            continue;
        }
        let area = |problems: &mut Problems, required: bool| -> f64 {
            match l.area_m2 {
                Some(a) => {
                    problems.in_range(&format!("{p}.area_m2"), a, 1e-9, 1e3, " m²");
                    a
                }
                None if required => {
                    problems.push(format!("{p}.area_m2"), "", "required for this law");
                    f64::NAN
                }
                None => f64::NAN,
            }
        };
        let law = if let Some(g) = l.conductance_w_per_k {
            if l.area_m2.is_some() {
                problems.push(format!("{p}.area_m2"), "", "not used with conductance_w_per_k");
            }
            problems.in_range(&format!("{p}.conductance_w_per_k"), g, 0.0, 1e9, " W/K");
            LinkLaw::Conductance(g)
        } else if let Some(h) = l.h_w_per_m2k {
            problems.in_range(&format!("{p}.h_w_per_m2k"), h, 0.0, 1e6, " W/(m²·K)");
            LinkLaw::Convection {
                area: area(problems, true),
                h,
            }
        } else if let Some(t) = &l.h_table {
            let tp = format!("{p}.h_table");
            if t.speed_kmh.is_empty() || t.speed_kmh.len() != t.h_w_per_m2k.len() {
                problems.push(
                    &tp,
                    "",
                    "speed_kmh and h_w_per_m2k must be non-empty and of equal length",
                );
            }
            for (k, v) in t.speed_kmh.iter().enumerate() {
                if !v.is_finite() || *v < 0.0 || (k > 0 && *v <= t.speed_kmh[k - 1]) {
                    problems.push(
                        format!("{tp}.speed_kmh[{k}]"),
                        v,
                        "speeds must be ≥ 0 and increase strictly",
                    );
                }
            }
            for (k, h) in t.h_w_per_m2k.iter().enumerate() {
                problems.in_range(&format!("{tp}.h_w_per_m2k[{k}]"), *h, 0.0, 1e6, " W/(m²·K)");
            }
            LinkLaw::Table {
                area: area(problems, true),
                table: HTable::new(
                    t.speed_kmh.iter().map(|v| v / 3.6).collect(),
                    t.h_w_per_m2k.clone(),
                ),
            }
        } else if let Some(hl) = &l.h_law {
            problems.in_range(
                &format!("{p}.h_law.h0_w_per_m2k"),
                hl.h0_w_per_m2k,
                0.0,
                1e6,
                " W/(m²·K)",
            );
            problems.in_range(&format!("{p}.h_law.h1"), hl.h1, 0.0, 1e5, "");
            LinkLaw::Law {
                area: area(problems, true),
                h0: hl.h0_w_per_m2k,
                h1: hl.h1,
            }
        } else if let Some(r) = &l.rotating {
            match gears.iter().position(|g| g.name == r.gear) {
                Some(gi) => {
                    let g = &gears[gi];
                    // Default wetted area: both faces and the rim of the disc.
                    let default = 2.0 * std::f64::consts::PI * g.radius * (g.radius + g.face_width);
                    let a = if l.area_m2.is_some() {
                        area(problems, false)
                    } else {
                        default
                    };
                    LinkLaw::Rotating {
                        area: a,
                        gear: gi,
                        radius: g.radius,
                        fluid: r.fluid,
                    }
                }
                None => {
                    problems.push(format!("{p}.rotating.gear"), &r.gear, "unknown gear");
                    continue;
                }
            }
        } else {
            let e = l.emissivity.unwrap_or(f64::NAN);
            problems.in_range(&format!("{p}.emissivity"), e, 0.0, 1.0, "");
            LinkLaw::Radiation(STEFAN_BOLTZMANN * e * area(problems, true))
        };
        if let (Some(a), Some(b)) = (a, b) {
            links.push(Link {
                name: l
                    .name
                    .clone()
                    .unwrap_or_else(|| format!("{}-{}", l.between[0], l.between[1])),
                a,
                b,
                law,
            });
        }
    }

    // Coolers.
    let mut coolers = Vec::new();
    for (i, c) in spec.coolers.iter().enumerate() {
        let p = format!("thermal.coolers[{i}]");
        let hot = resolve(problems, &format!("{p}.hot"), &c.hot);
        let cold = resolve(problems, &format!("{p}.cold"), &c.cold);
        if c.hot == c.cold {
            problems.push(format!("{p}.cold"), &c.cold, "must differ from hot");
        }
        if matches!(hot, Some(NodeRef::Boundary(_))) {
            problems.push(
                format!("{p}.hot"),
                &c.hot,
                "the hot side must be a node with capacity",
            );
        }
        problems.in_range(&format!("{p}.effectiveness"), c.effectiveness, 0.0, 1.0, "");
        problems.in_range(
            &format!("{p}.capacity_rate_w_per_k"),
            c.capacity_rate_w_per_k,
            0.0,
            1e7,
            " W/K",
        );
        let thermostat = c.thermostat.as_ref().map(|t| {
            let okk = temp_ok(problems, &format!("{p}.thermostat.open_c"), t.open_c)
                & temp_ok(problems, &format!("{p}.thermostat.full_c"), t.full_c);
            if okk && t.full_c <= t.open_c {
                problems.push(format!("{p}.thermostat.full_c"), t.full_c, "must be above open_c");
            }
            (t.open_c + KELVIN_OFFSET, t.full_c + KELVIN_OFFSET)
        });
        if let (Some(hot), Some(cold)) = (hot, cold) {
            coolers.push(Cooler {
                name: c.name.clone(),
                hot,
                cold,
                conductance: c.effectiveness * c.capacity_rate_w_per_k,
                thermostat,
                two_way: c.two_way,
            });
        }
    }

    // Oil node.
    let oil_node = match names.get(spec.oil_node.as_str()) {
        Some(NodeRef::Node(i)) => Some(*i),
        Some(NodeRef::Boundary(_)) => {
            problems.push(
                "thermal.oil_node",
                &spec.oil_node,
                "must be a node with capacity, not a boundary",
            );
            None
        }
        None => {
            problems.push(
                "thermal.oil_node",
                &spec.oil_node,
                format!("unknown node; known: {}", known(&names)),
            );
            None
        }
    };

    // Heat rules.
    let mut heat = Vec::new();
    for (i, h) in spec.heat.iter().enumerate() {
        let p = format!("thermal.heat[{i}]");
        let target = match (&h.item, &h.source) {
            (Some(item), None) => {
                if !items.knows(item) {
                    problems.push(
                        format!("{p}.item"),
                        item,
                        "must be <source>:<name> with a loss item of the model (churning:<gear>, \
                         pocketing:<mesh>, sliding:<mesh>, bearing:<bearing>, seal:<seal>, …)",
                    );
                }
                HeatTarget::Item(item.clone())
            }
            (None, Some(s)) => {
                if Source::parse(s).is_none() {
                    problems.push(
                        format!("{p}.source"),
                        s,
                        format!("must be one of {}", Source::names()),
                    );
                }
                HeatTarget::Source(s.clone())
            }
            _ => {
                problems.push(&p, "", "give either item or source");
                continue;
            }
        };
        let mut to = Vec::new();
        let mut sum = 0.0;
        for (node, f) in &h.to {
            let np = format!("{p}.to.{node}");
            match names.get(node.as_str()) {
                Some(NodeRef::Node(k)) => {
                    if problems.in_range(&np, *f, 0.0, 1.0, "") {
                        to.push((*k, *f));
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
                None => problems.push(&np, node, format!("unknown node; known: {}", known(&names))),
            }
        }
        if (sum - 1.0).abs() > 1e-9 && !to.is_empty() {
            problems.push(format!("{p}.to"), format!("sum {sum}"), "fractions must sum to 1");
        }
        heat.push(HeatRule { target, to });
    }

    // Every node needs a path to a boundary (else its temperature grows without bound and the
    // steady state does not exist).
    if problems.len() == start {
        let n = nodes.len();
        let mut reach = vec![false; n];
        let edges: Vec<(NodeRef, NodeRef)> = links
            .iter()
            .map(|l| (l.a, l.b))
            .chain(coolers.iter().map(|c| (c.hot, c.cold)))
            .collect();
        let mut changed = true;
        while changed {
            changed = false;
            for &(a, b) in &edges {
                let ra = match a {
                    NodeRef::Boundary(_) => true,
                    NodeRef::Node(i) => reach[i],
                };
                let rb = match b {
                    NodeRef::Boundary(_) => true,
                    NodeRef::Node(i) => reach[i],
                };
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

    if problems.len() > start {
        return None;
    }
    let net = ThermalNetwork {
        nodes,
        boundaries,
        links,
        coolers,
        heat,
        oil_node: oil_node?,
        initial_temp: initial + KELVIN_OFFSET,
        groups: Vec::new(),
    };
    Some(match &spec.wall_mesh {
        Some(m) => super::wall_mesh::mesh_wall(net, m, problems),
        None => net,
    })
}
