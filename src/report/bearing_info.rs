//! Per bearing: its friction model and, for SKF, the sliding friction pair (μ_bl, μ_EHL) used
//! with where each comes from (`geartherm info` and `losses --json`).

use std::fmt::Write as _;

use serde::Serialize;

use crate::model::Gearbox;
use crate::physics::losses::bearings::BearingFriction;

/// One bearing's friction model and μ pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BearingInfo {
    /// Bearing name.
    pub name: String,
    /// Catalogue designation.
    pub designation: String,
    /// Friction model: `skf` or `palmgren`.
    pub model: &'static str,
    /// SKF μ_bl (null for Palmgren).
    pub mu_bl: Option<f64>,
    /// SKF μ_EHL (null for Palmgren).
    pub mu_ehl: Option<f64>,
    /// Where μ_bl comes from: `model file key mu_bl`, `catalogue oil <key> (<pair>: <source>)` or
    /// `SKF constant (…)`.
    pub mu_bl_origin: Option<String>,
    /// Where μ_EHL comes from.
    pub mu_ehl_origin: Option<String>,
}

/// Every bearing of `gb`, in model order.
pub fn bearing_infos(gb: &Gearbox) -> Vec<BearingInfo> {
    gb.bearings
        .iter()
        .map(|b| BearingInfo {
            name: b.name.clone(),
            designation: b.designation.clone(),
            model: match b.friction {
                BearingFriction::Skf(_) => "skf",
                BearingFriction::Palmgren(_) => "palmgren",
            },
            mu_bl: b.mu.as_ref().map(|m| m.mu_bl),
            mu_ehl: b.mu.as_ref().map(|m| m.mu_ehl),
            mu_bl_origin: b.mu.as_ref().map(|m| m.mu_bl_origin.clone()),
            mu_ehl_origin: b.mu.as_ref().map(|m| m.mu_ehl_origin.clone()),
        })
        .collect()
}

/// The bearings as a text table (empty without bearings).
pub fn bearings_text(list: &[BearingInfo]) -> String {
    let mut s = String::new();
    if list.is_empty() {
        return s;
    }
    let _ = writeln!(s, "\nbearings");
    for b in list {
        match (b.mu_bl, b.mu_ehl) {
            (Some(bl), Some(ehl)) => {
                let _ = writeln!(
                    s,
                    "  {:<14} {:<12} {:<8} mu_bl {bl} [{}], mu_ehl {ehl} [{}]",
                    b.name,
                    b.designation,
                    b.model,
                    short(b.mu_bl_origin.as_deref()),
                    short(b.mu_ehl_origin.as_deref())
                );
            }
            _ => {
                let _ = writeln!(s, "  {:<14} {:<12} {:<8}", b.name, b.designation, b.model);
            }
        }
    }
    s
}

/// An origin up to its first parenthesis (the JSON keeps the whole text).
fn short(origin: Option<&str>) -> &str {
    origin.map_or("", |o| o.split(" (").next().unwrap_or(o).trim())
}
