//! `[[clutch_packs]]`: the friction pack of a shift element, whose drag counts while the element
//! is open.

use serde::{Deserialize, Serialize};

use crate::model::problems::Problems;
use crate::physics::losses::clutch_drag::ClutchPack;

fn one() -> f64 {
    1.0
}

/// `[[clutch_packs]]` as written: the friction pack of one shift element.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ClutchPackSpec {
    /// Shift element whose pack this is.
    pub element: String,
    /// Friction interfaces (oil films) = 2 × friction plates for a pack between steel plates.
    pub friction_interfaces: u32,
    /// Inner radius of the friction face, mm.
    pub inner_radius_mm: f64,
    /// Outer radius of the friction face, mm.
    pub outer_radius_mm: f64,
    /// Clearance per interface of the open pack, mm (total release clearance / interfaces).
    pub clearance_mm: f64,
    /// Lubrication flow through the pack, L/min.
    pub oil_flow_l_per_min: f64,
    /// Land fraction of the grooved friction face (1 = plain face; default 1).
    #[serde(default = "one")]
    pub groove_factor: f64,
    /// Mist viscosity beyond the film edge, fraction of the oil's (default 0).
    #[serde(default)]
    pub mist_viscosity_ratio: f64,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// A checked clutch pack on a shift element.
#[derive(Debug, Clone, PartialEq)]
pub struct ClutchPackModel {
    /// Shift-element name (the loss item's name).
    pub name: String,
    /// Shift-element index.
    pub element: usize,
    /// The pack (SI).
    pub pack: ClutchPack,
}

/// Check `[[clutch_packs]]` against the shift-element names.
pub(crate) fn validate_clutch_packs(
    specs: &[ClutchPackSpec],
    elements: &[&str],
    problems: &mut Problems,
) -> Vec<ClutchPackModel> {
    let mut out = Vec::new();
    for (i, s) in specs.iter().enumerate() {
        let p = format!("clutch_packs[{i}]");
        let element = elements.iter().position(|e| *e == s.element);
        if element.is_none() {
            problems.push(
                format!("{p}.element"),
                format!("\"{}\"", s.element),
                format!("not a shift element of the model ({})", elements.join(", ")),
            );
        } else if specs[..i].iter().any(|o| o.element == s.element) {
            problems.push(
                format!("{p}.element"),
                format!("\"{}\"", s.element),
                "has a pack already",
            );
        }
        let before = problems.len();
        let z = f64::from(s.friction_interfaces);
        problems.in_range(&format!("{p}.friction_interfaces"), z, 1.0, 40.0, "");
        problems.in_range(
            &format!("{p}.inner_radius_mm"),
            s.inner_radius_mm,
            5.0,
            500.0,
            " mm",
        );
        problems.in_range(
            &format!("{p}.outer_radius_mm"),
            s.outer_radius_mm,
            5.0,
            500.0,
            " mm",
        );
        if s.outer_radius_mm <= s.inner_radius_mm {
            problems.push(
                format!("{p}.outer_radius_mm"),
                s.outer_radius_mm,
                format!("must exceed inner_radius_mm = {}", s.inner_radius_mm),
            );
        }
        problems.in_range(&format!("{p}.clearance_mm"), s.clearance_mm, 0.005, 2.0, " mm");
        problems.in_range(
            &format!("{p}.oil_flow_l_per_min"),
            s.oil_flow_l_per_min,
            0.0,
            50.0,
            " L/min",
        );
        if !(s.groove_factor > 0.0 && s.groove_factor <= 1.0) {
            problems.push(
                format!("{p}.groove_factor"),
                s.groove_factor,
                "must lie in (0, 1]",
            );
        }
        problems.in_range(
            &format!("{p}.mist_viscosity_ratio"),
            s.mist_viscosity_ratio,
            0.0,
            1.0,
            "",
        );
        if let (Some(e), true) = (element, problems.len() == before) {
            out.push(ClutchPackModel {
                name: s.element.clone(),
                element: e,
                pack: ClutchPack {
                    interfaces: z,
                    inner_radius: s.inner_radius_mm * 1e-3,
                    outer_radius: s.outer_radius_mm * 1e-3,
                    clearance: s.clearance_mm * 1e-3,
                    oil_flow: s.oil_flow_l_per_min * 1e-3 / 60.0,
                    groove_factor: s.groove_factor,
                    mist_viscosity_ratio: s.mist_viscosity_ratio,
                },
            });
        }
    }
    out
}
