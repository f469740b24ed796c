//! `[[thermal.links]]`: links between two nodes with exactly one law: a conductance, convection
//! with a fixed h, an h(v) table or law, a rotating-disc correlation on a gear, or radiation.

use serde::{Deserialize, Serialize};

use super::common::{GearInfo, NodeNames, NodeRef};
use crate::model::choice::choice;
use crate::model::problems::Problems;
use crate::physics::thermal::{HTable, STEFAN_BOLTZMANN};

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
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fluid {
    /// Air at 50 °C.
    Air,
    /// The gearbox oil at the oil node's temperature.
    Oil,
}
choice!(Fluid {
    Air = "air",
    Oil = "oil",
});

/// Rotating-disc correlation on a gear.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RotatingSpec {
    /// Gear whose speed and tip radius are used.
    pub gear: String,
    /// Surrounding fluid.
    pub fluid: Fluid,
}

/// `[[thermal.links]]` as written: a link between two nodes; exactly one law.
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

impl LinkLaw {
    /// The law of one of `1/scale` equal parts of the link (areas, conductances and σεA scaled;
    /// coefficients kept).
    pub fn scaled(&self, scale: f64) -> LinkLaw {
        match self {
            LinkLaw::Conductance(g) => LinkLaw::Conductance(g * scale),
            LinkLaw::Convection { area, h } => LinkLaw::Convection {
                area: area * scale,
                h: *h,
            },
            LinkLaw::Table { area, table } => LinkLaw::Table {
                area: area * scale,
                table: table.clone(),
            },
            LinkLaw::Law { area, h0, h1 } => LinkLaw::Law {
                area: area * scale,
                h0: *h0,
                h1: *h1,
            },
            LinkLaw::Rotating {
                area,
                gear,
                radius,
                fluid,
            } => LinkLaw::Rotating {
                area: area * scale,
                gear: *gear,
                radius: *radius,
                fluid: *fluid,
            },
            LinkLaw::Radiation(k) => LinkLaw::Radiation(k * scale),
        }
    }
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

/// The law a link gives: the one law key it sets.
#[derive(Clone, Copy)]
enum LawSpec<'a> {
    Conductance(f64),
    Convection(f64),
    Table(&'a HTableSpec),
    Law(&'a HLawSpec),
    Rotating(&'a RotatingSpec),
    Radiation(f64),
}

impl LinkSpec {
    /// The law given, or None when none or several are.
    fn law(&self) -> Option<LawSpec<'_>> {
        let given: Vec<LawSpec<'_>> = [
            self.conductance_w_per_k.map(LawSpec::Conductance),
            self.h_w_per_m2k.map(LawSpec::Convection),
            self.h_table.as_ref().map(LawSpec::Table),
            self.h_law.as_ref().map(LawSpec::Law),
            self.rotating.as_ref().map(LawSpec::Rotating),
            self.emissivity.map(LawSpec::Radiation),
        ]
        .into_iter()
        .flatten()
        .collect();
        match given[..] {
            [one] => Some(one),
            _ => None,
        }
    }

    /// `area_m2` checked (a problem at `p` when `required` and missing); NaN when not given.
    fn area(&self, p: &str, required: bool, problems: &mut Problems) -> f64 {
        match self.area_m2 {
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
    }
}

/// Check every link: its two nodes (different, known) and its one law.
pub(crate) fn check_links(
    specs: &[LinkSpec],
    names: &NodeNames<'_>,
    gears: &[GearInfo<'_>],
    problems: &mut Problems,
) -> Vec<Link> {
    let mut links = Vec::new();
    for (i, l) in specs.iter().enumerate() {
        let p = format!("thermal.links[{i}]");
        let a = names.resolve(problems, &format!("{p}.between[0]"), &l.between[0]);
        let b = names.resolve(problems, &format!("{p}.between[1]"), &l.between[1]);
        if l.between[0] == l.between[1] {
            problems.push(
                format!("{p}.between"),
                &l.between[0],
                "a link needs two different nodes",
            );
        }
        let Some(given) = l.law() else {
            problems.push(
                &p,
                "",
                "give exactly one law: conductance_w_per_k, h_w_per_m2k, h_table, h_law, rotating or emissivity",
            );
            continue;
        };
        let Some(law) = link_law(l, given, &p, gears, problems) else {
            continue;
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
    links
}

/// The checked law of link `l` at key path `p` (None: a rotating link on an unknown gear).
fn link_law(
    l: &LinkSpec,
    given: LawSpec<'_>,
    p: &str,
    gears: &[GearInfo<'_>],
    problems: &mut Problems,
) -> Option<LinkLaw> {
    Some(match given {
        LawSpec::Conductance(g) => {
            if l.area_m2.is_some() {
                problems.push(format!("{p}.area_m2"), "", "not used with conductance_w_per_k");
            }
            problems.in_range(&format!("{p}.conductance_w_per_k"), g, 0.0, 1e9, " W/K");
            LinkLaw::Conductance(g)
        }
        LawSpec::Convection(h) => {
            problems.in_range(&format!("{p}.h_w_per_m2k"), h, 0.0, 1e6, " W/(m²·K)");
            LinkLaw::Convection {
                area: l.area(p, true, problems),
                h,
            }
        }
        LawSpec::Table(t) => h_table(l, t, p, problems),
        LawSpec::Law(hl) => {
            problems.in_range(
                &format!("{p}.h_law.h0_w_per_m2k"),
                hl.h0_w_per_m2k,
                0.0,
                1e6,
                " W/(m²·K)",
            );
            problems.in_range(&format!("{p}.h_law.h1"), hl.h1, 0.0, 1e5, "");
            LinkLaw::Law {
                area: l.area(p, true, problems),
                h0: hl.h0_w_per_m2k,
                h1: hl.h1,
            }
        }
        LawSpec::Rotating(r) => {
            let Some(gi) = gears.iter().position(|g| g.name == r.gear) else {
                problems.push(format!("{p}.rotating.gear"), &r.gear, "unknown gear");
                return None;
            };
            let g = &gears[gi];
            if !g.checked {
                return None;
            }
            // Default wetted area: both faces and the rim of the disc.
            let default = 2.0 * std::f64::consts::PI * g.radius * (g.radius + g.face_width);
            let a = if l.area_m2.is_some() {
                l.area(p, false, problems)
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
        LawSpec::Radiation(e) => {
            problems.in_range(&format!("{p}.emissivity"), e, 0.0, 1.0, "");
            LinkLaw::Radiation(STEFAN_BOLTZMANN * e * l.area(p, true, problems))
        }
    })
}

/// An h(v) table: speeds ≥ 0 and increasing, one h per speed (km/h → m/s inside).
fn h_table(l: &LinkSpec, t: &HTableSpec, p: &str, problems: &mut Problems) -> LinkLaw {
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
        area: l.area(p, true, problems),
        table: HTable::new(
            t.speed_kmh.iter().map(|v| v / 3.6).collect(),
            t.h_w_per_m2k.clone(),
        ),
    }
}
