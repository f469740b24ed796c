//! The vocabulary of a compiled scene's losses, shared by every part that compiles loss items
//! (gears and meshes, bearings and seals, the automatic's own parts): the loss item with its
//! source and default heat destination, what a compile left out, and the operating point the
//! items are evaluated at.

use crate::physics::oil::OilProperties;

pub use crate::model::source::{PerSource, Source, N_SOURCES};

/// Sum the values of `items` (W or J, one per item) per source.
pub fn sum_by_source(items: &[LossItem], values: &[f64]) -> PerSource {
    let mut by = [0.0; N_SOURCES];
    for (it, v) in items.iter().zip(values) {
        by[it.source.index()] += v;
    }
    by
}

/// Where a loss item's heat goes unless a `[[thermal.heat]]` rule says otherwise.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DefaultHeat {
    /// The oil node (churning, pocketing).
    Oil,
    /// The body nodes of the item's gears with their fractions (sliding); a gear in no node
    /// heats the oil.
    Gears,
    /// The body node of a gear on a member (a bearing or seal on that member: its shaft node),
    /// else the oil node. Gear indices with fractions.
    Member(Vec<(usize, f64)>),
    /// Named thermal nodes with fractions, as the model says (e.g. a bearing's shaft and
    /// housing nodes).
    Nodes(Vec<(String, f64)>),
}

/// One loss item: what it is, where its heat goes.
#[derive(Debug, Clone, serde::Serialize)]
pub struct LossItem {
    /// Source kind.
    pub source: Source,
    /// Gear name (churning) or mesh name (pocketing, sliding).
    pub name: String,
    /// Gears heated and the fraction each receives (sliding: split between the two gears;
    /// churning and pocketing: the gear(s) concerned, whose heat goes to the oil by default;
    /// empty for items that are not gears or meshes).
    pub gears: Vec<(usize, f64)>,
    /// Default heat destination.
    pub heat: DefaultHeat,
    /// Supplied by the engine ahead of the gearbox input shaft (the converter's slip, a pump
    /// driven by the engine side of the launch device), not through the input shaft: the input
    /// torque (T_in = T_out/i + P_loss/ω_in) leaves it out.
    pub engine_side: bool,
}

/// A part of the model the scene left out, and why.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Skipped {
    /// What (e.g. "churning of gear s1_sun").
    pub what: String,
    /// Why.
    pub why: String,
}

/// Operating point of the whole gearbox.
#[derive(Debug, Clone, Copy)]
pub struct OperatingPoint {
    /// Gear-state index.
    pub state: usize,
    /// Input speed, rad/s.
    pub input_speed: f64,
    /// Input torque, N·m (drive torque the input delivers to the train, losses excluded).
    pub input_torque: f64,
    /// Oil properties at the oil temperature.
    pub oil: OilProperties,
}

/// A loss model could not be built for a part of the model.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{what}: {why}")]
pub struct SceneError {
    /// Which item.
    pub what: String,
    /// Why.
    pub why: String,
}
