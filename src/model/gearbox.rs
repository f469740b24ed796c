//! The checked model: a [`Gearbox`] in SI units, built by [`super::validate`] from a model file.
//! Everything here has passed validation; the scene compile step reads only this. Each part's
//! checked type is defined beside its section in [`super::sections`] and named here too.

use crate::cycle::{LaunchDevice, Vehicle};
use crate::physics::kinematics::GearTrain;
use crate::physics::oil::Oil;

pub use super::sections::bearings::Bearing;
pub use super::sections::circuit::{Circuit, Consumer, FlowSource, SourceKind, Split, Target};
pub use super::sections::clutch_packs::ClutchPackModel;
pub use super::sections::gear_states::GearState;
pub use super::sections::gears::{Gear, GearMount};
pub use super::sections::losses::{LossModels, PocketingOptions, SlidingChoice};
pub use super::sections::members::{Member, MemberKind};
pub use super::sections::meshes::{Mesh, MeshLoadPath};
pub use super::sections::planetary_sets::{spin_from_ring, spin_from_sun, PlanetarySet, PlanetarySetKind};
pub use super::sections::pump::PumpModel;
pub use super::sections::seals::Seal;
pub use super::sections::shift_elements::{ShiftElement, ShiftElementKind};
pub use super::sections::thermal::ThermalNetwork;

/// Speed of a gear per unit input speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearSpeed {
    /// Absolute angular speed.
    pub absolute: f64,
    /// Relative to the carrier of its planetary set (equal to `absolute` for fixed-axis gears).
    pub relative: f64,
}

/// The checked gearbox.
#[derive(Debug, Clone)]
pub struct Gearbox {
    /// Name.
    pub name: String,
    /// Description from the file.
    pub description: String,
    /// Lubricant.
    pub oil: Oil,
    /// Members.
    pub members: Vec<Member>,
    /// Gears.
    pub gears: Vec<Gear>,
    /// Meshes (fixed-axis pairs first, then planetary-set meshes).
    pub meshes: Vec<Mesh>,
    /// Planetary sets.
    pub planetary_sets: Vec<PlanetarySet>,
    /// Shift elements.
    pub shift_elements: Vec<ShiftElement>,
    /// Gear states in file order.
    pub gear_states: Vec<GearState>,
    /// Kinematic train (fixed rows: meshes, sets, fixed members).
    pub train: GearTrain,
    /// Input member.
    pub input: usize,
    /// Output member.
    pub output: usize,
    /// Static oil level above the datum, m.
    pub oil_level: f64,
    /// Sump oil volume, m³ (if given).
    pub sump_volume: Option<f64>,
    /// Loss models with their coefficients.
    pub losses: LossModels,
    /// Every model choice of churning, windage and sliding, resolved or why not applicable
    /// (the model-form spread).
    pub loss_alternatives: crate::model::sections::loss_alternatives::LossAlternatives,
    /// The thermal network (`[thermal]`), if the model has one.
    pub thermal: Option<ThermalNetwork>,
    /// The vehicle (`[vehicle]`), if the model has one.
    pub vehicle: Option<Vehicle>,
    /// Friction packs of shift elements (`[[clutch_packs]]`): drag while open.
    pub clutch_packs: Vec<ClutchPackModel>,
    /// The oil pump (`[pump]`), if any.
    pub pump: Option<PumpModel>,
    /// The launch device (`[launch]`), if any: torque converter with lock-up.
    pub launch: Option<LaunchDevice>,
    /// Rolling bearings (`[[bearings]]`).
    pub bearings: Vec<Bearing>,
    /// Shaft seals (`[[seals]]`).
    pub seals: Vec<Seal>,
    /// The lubrication circuit (`[circuit]`; empty without one).
    pub circuit: Circuit,
}

impl Gearbox {
    /// Index of a gear state by name.
    pub fn state_index(&self, name: &str) -> Option<usize> {
        self.gear_states.iter().position(|s| s.name == name)
    }

    /// Speeds of every gear in a state, per unit input speed.
    pub fn gear_speeds(&self, state: usize) -> Vec<GearSpeed> {
        let w = &self.gear_states[state].solution.speeds;
        self.gears
            .iter()
            .map(|g| match g.mount {
                GearMount::OnMember => {
                    let abs = w[g.member];
                    let rel = g.carrier.map_or(abs, |c| abs - w[c]);
                    GearSpeed {
                        absolute: abs,
                        relative: rel,
                    }
                }
                GearMount::Planet {
                    set,
                    reference,
                    factor,
                } => {
                    let wc = w[self.planetary_sets[set].carrier];
                    let rel = factor * (w[reference] - wc);
                    GearSpeed {
                        absolute: wc + rel,
                        relative: rel,
                    }
                }
            })
            .collect()
    }

    /// Torque applied to gear 1 by each mesh (one planet's mesh), per unit input torque, in a state.
    /// Gear 1 drives when this torque opposes its (carrier-frame) rotation.
    pub fn mesh_torques(&self, state: usize) -> Vec<f64> {
        let sol = &self.gear_states[state].solution;
        self.meshes
            .iter()
            .map(|m| {
                let z1 = self.gears[m.gear1].geometry.z() as f64;
                let lam: f64 = m
                    .load_path
                    .rows
                    .iter()
                    .map(|&(k, s)| s * sol.multipliers[k])
                    .sum();
                z1 * lam / m.multiplicity as f64
            })
            .collect()
    }
}
