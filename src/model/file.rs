//! The model file as a whole: one field per section, each section's serde struct in its own file
//! under [`super::sections`].

use serde::{Deserialize, Serialize};

use super::sections::*;

/// The top-level keys a model file may have: its sections, in the order of [`ModelFile`].
pub const SECTIONS: &[&str] = &[
    "model",
    "oil",
    "members",
    "gears",
    "meshes",
    "planetary_sets",
    "shift_elements",
    "gear_states",
    "train",
    "lubrication",
    "losses",
    "thermal",
    "vehicle",
    "clutch_packs",
    "pump",
    "launch",
    "bearings",
    "seals",
    "circuit",
    "uncertainty",
];

/// The whole model file.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// `[model]`.
    pub model: model::ModelMeta,
    /// `[oil]`.
    pub oil: oil::OilSpec,
    /// `[[members]]`.
    #[serde(default)]
    pub members: Vec<members::MemberSpec>,
    /// `[[gears]]`.
    pub gears: Vec<gears::GearSpecFile>,
    /// `[[meshes]]` (fixed-axis pairs).
    #[serde(default)]
    pub meshes: Vec<meshes::MeshSpec>,
    /// `[[planetary_sets]]`.
    #[serde(default)]
    pub planetary_sets: Vec<planetary_sets::PlanetarySetSpec>,
    /// `[[shift_elements]]`.
    #[serde(default)]
    pub shift_elements: Vec<shift_elements::ShiftElementSpec>,
    /// `[[gear_states]]` (a fixed-ratio box may omit it: one state named "1").
    #[serde(default)]
    pub gear_states: Vec<gear_states::GearStateSpec>,
    /// `[train]`.
    pub train: train::TrainSpec,
    /// `[lubrication]`.
    pub lubrication: lubrication::LubricationSpec,
    /// `[losses]`: loss-model choices and coefficients.
    #[serde(default)]
    pub losses: Option<losses::LossesSpec>,
    /// `[thermal]`: the lumped thermal network.
    #[serde(default)]
    pub thermal: Option<thermal::ThermalSpec>,
    /// `[vehicle]`: the vehicle and its shift strategy.
    #[serde(default)]
    pub vehicle: Option<vehicle::VehicleSpec>,
    /// `[[clutch_packs]]`: friction packs of shift elements (open-clutch drag).
    #[serde(default)]
    pub clutch_packs: Vec<clutch_packs::ClutchPackSpec>,
    /// `[pump]`: the transmission oil pump.
    #[serde(default)]
    pub pump: Option<pump::PumpSpec>,
    /// `[launch]`: torque converter between engine and gearbox input.
    #[serde(default)]
    pub launch: Option<launch::LaunchSpec>,
    /// `[[bearings]]`.
    #[serde(default)]
    pub bearings: Vec<bearings::BearingSpec>,
    /// `[[seals]]`.
    #[serde(default)]
    pub seals: Vec<seals::SealSpec>,
    /// `[circuit]`: the lubrication circuit (sources and consumers).
    #[serde(default)]
    pub circuit: Option<circuit::CircuitSpec>,
    /// `[uncertainty]`: the uncertain inputs `geartherm uq` samples (no part of the gearbox;
    /// checked without the model by every command, against it by `check` and `uq`).
    #[serde(default)]
    pub uncertainty: Option<uncertainty::UncertaintySpec>,
}
