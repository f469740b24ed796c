//! The checked model: a [`Gearbox`] in SI units, built by [`super::validate`] from a model file.
//! Everything here has passed validation; the scene compile step reads only this.

use crate::physics::geometry::{GearGeometry, MeshGeometry};
use crate::physics::kinematics::{planet_spin, ring_pinion_spin, GearTrain, StateSolution};
use crate::physics::oil::Oil;

pub use super::schema::{MemberKind, PlanetarySetKind, ShiftElementKind};
use crate::physics::losses::churning::ChurningConfig;
use crate::physics::losses::sliding::{friction::Schlenk, SlidingOptions};

/// Pocketing options (resolved from `[losses]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PocketingOptions {
    /// Discharge coefficient C_d.
    pub discharge_coefficient: f64,
    /// Density pumped by the part of a mesh zone above the oil level, kg/m³; `None` (default):
    /// unknown, that part is not counted and is reported in `warnings` (docs/validation.md).
    pub mixture_density: Option<f64>,
}

/// Sliding-loss model choice.
#[derive(Debug, Clone, PartialEq)]
pub enum SlidingChoice {
    /// No sliding loss.
    Off,
    /// Contact-path model (load sharing, local friction law, Niemann–Richer for helical meshes).
    Detailed(SlidingOptions),
    /// ISO/TR 14179-2 closed form `P_in μ_mz H_V` with the Schlenk mean friction coefficient.
    Iso14179(Schlenk, f64),
}

/// Loss models selected by the model file (`[losses]`), with their coefficients.
#[derive(Debug, Clone, PartialEq)]
pub struct LossModels {
    /// Churning model and coefficients (None: churning off).
    pub churning: Option<ChurningConfig>,
    /// Pocketing (None: off).
    pub pocketing: Option<PocketingOptions>,
    /// Sliding.
    pub sliding: SlidingChoice,
    /// Loss multipliers `[losses] multiplier`: (source, None) for a source, (source, Some(item))
    /// for one item; each multiplies the item's loss (default 1).
    pub multipliers: Vec<(crate::model::source::Source, Option<String>, f64)>,
}

/// A rotating member (shaft, carrier, drum).
#[derive(Debug, Clone)]
pub struct Member {
    /// Name from the file.
    pub name: String,
    /// Kind (informational).
    pub kind: MemberKind,
    /// Held by the housing permanently.
    pub fixed: bool,
}

/// How a gear turns: with its member, or as a planet on a carrier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GearMount {
    /// Fixed to a member (shaft, sun, ring): turns at the member's speed.
    OnMember,
    /// A planet of a set: turns at the carrier speed plus its spin `ω_P − ω_C = factor·(ω_ref − ω_C)`,
    /// `reference` being the member whose gear drives the spin (a sun or the ring).
    Planet {
        /// Planetary set index.
        set: usize,
        /// Member that sets the spin (sun or ring member).
        reference: usize,
        /// Spin factor (e.g. −z_S/z_P for a planet meshing the sun).
        factor: f64,
    },
}

/// A gear: geometry, member, lubrication.
#[derive(Debug, Clone)]
pub struct Gear {
    /// Name from the file.
    pub name: String,
    /// Member index (for planets: the carrier).
    pub member: usize,
    /// Geometry (SI).
    pub geometry: GearGeometry,
    /// Flank roughness Ra, m.
    pub roughness_ra: f64,
    /// How it turns.
    pub mount: GearMount,
    /// Carrier member of the planetary set the gear belongs to (None: fixed-axis gear).
    pub carrier: Option<usize>,
    /// Height of the gear axis above the datum, m (planets: lowest point of the orbit).
    pub centre_height: f64,
    /// Depth of the gear's lowest point below the static oil level, m (≤ 0: not immersed).
    pub immersion: f64,
    /// Axial position of the face-width centre along its member (planets: along the pin), m.
    pub position: f64,
}

impl Gear {
    /// True when the gear dips into the oil.
    pub fn is_immersed(&self) -> bool {
        self.immersion > 0.0
    }
}

/// Which constraint rows of a gear state carry a mesh's tooth force, and with what sign: the torque
/// applied to gear 1 by the mesh (one planet's share) is `z1/planets · Σ sign·λ_row`. In the
/// carrier frame an external mesh applies torques of equal sign to its gears (`T2 = T1·z2/z1`), an
/// internal mesh opposite signs (`T2 = −T1·z2/z1`); each planet is in equilibrium, which fixes the
/// signs along a planet chain (sun mesh +1, next mesh −1, ...).
#[derive(Debug, Clone)]
pub struct MeshLoadPath {
    /// (row index among the train's fixed rows, sign).
    pub rows: Vec<(usize, f64)>,
}

/// A gear pair in mesh (fixed-axis pair or one mesh of a planetary set).
#[derive(Debug, Clone)]
pub struct Mesh {
    /// Name.
    pub name: String,
    /// Gear 1 (external; pinion of an internal mesh; the sun side in a planetary set).
    pub gear1: usize,
    /// Gear 2.
    pub gear2: usize,
    /// Geometry (SI).
    pub geometry: MeshGeometry,
    /// Planetary set it belongs to (None for a fixed-axis pair).
    pub set: Option<usize>,
    /// How many identical meshes act in parallel (planets of the set; 1 for a fixed-axis pair).
    pub multiplicity: u32,
    /// Where its tooth force comes from in the kinematic solution.
    pub load_path: MeshLoadPath,
}

/// Gears of a planetary set by role.
#[derive(Debug, Clone)]
pub struct PlanetarySet {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: PlanetarySetKind,
    /// Carrier member index.
    pub carrier: usize,
    /// Number of planets (of each planet type).
    pub planets: u32,
    /// Gear indices in role order: simple `[sun, planet, ring]`, double pinion
    /// `[sun, inner, outer, ring]`, Ravigneaux `[large_sun, small_sun, long, short, ring]`.
    pub gears: Vec<usize>,
}

/// A clutch or brake.
#[derive(Debug, Clone)]
pub struct ShiftElement {
    /// Name.
    pub name: String,
    /// Clutch or brake.
    pub kind: ShiftElementKind,
    /// Members (two for a clutch, one for a brake).
    pub members: Vec<usize>,
}

/// A gear state with its solved (lossless) kinematics per unit input speed and torque.
#[derive(Debug, Clone)]
pub struct GearState {
    /// Name ("1", "R").
    pub name: String,
    /// Engaged shift elements (indices).
    pub engaged: Vec<usize>,
    /// Kinematic solution.
    pub solution: StateSolution,
}

impl GearState {
    /// Ratio ω_in / ω_out (negative in reverse).
    pub fn ratio(&self) -> f64 {
        self.solution.ratio()
    }
}

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
    /// The thermal network (`[thermal]`), if the model has one.
    pub thermal: Option<super::thermal::ThermalNetwork>,
    /// The vehicle (`[vehicle]`), if the model has one.
    pub vehicle: Option<crate::cycle::Vehicle>,
    /// Friction packs of shift elements (`[[clutch_packs]]`): drag while open.
    pub clutch_packs: Vec<super::automatic::ClutchPackModel>,
    /// The oil pump (`[pump]`), if any.
    pub pump: Option<super::automatic::PumpModel>,
    /// The launch device (`[launch]`), if any: torque converter with lock-up.
    pub launch: Option<crate::cycle::LaunchDevice>,
    /// Rolling bearings (`[[bearings]]`).
    pub bearings: Vec<super::bearings::Bearing>,
    /// Shaft seals (`[[seals]]`).
    pub seals: Vec<super::bearings::Seal>,
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

/// Planet spin factors (re-exported helpers so the validator and the scene agree).
pub fn spin_from_sun(z_sun: f64, z_planet: f64) -> f64 {
    planet_spin(z_sun, z_planet, 1.0, 0.0)
}

/// Spin factor of a pinion meshing the ring.
pub fn spin_from_ring(z_ring: f64, z_planet: f64) -> f64 {
    ring_pinion_spin(z_ring, z_planet, 1.0, 0.0)
}
