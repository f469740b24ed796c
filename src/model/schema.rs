//! The model file format: serde structs mirroring the TOML.
//!
//! Keys carry their unit (`module_mm`, `pressure_angle_deg`, `nu40_cst`); every struct denies
//! unknown fields so a misspelt key is an error, not a silent default. The full schema is
//! documented in `docs/model-file.md`. Conversion to SI happens in [`super::validate`].

use serde::{Deserialize, Serialize};

use crate::physics::oil::WaltherVariant;

/// `[model]`: identification of the gearbox.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModelMeta {
    /// Display name.
    pub name: String,
    /// Free text: where the data come from and what is assumed.
    #[serde(default)]
    pub description: Option<String>,
}

/// `[oil]`: either a catalogue name or inline data.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OilSpec {
    /// Name of an oil in `models/oils.toml` (the catalogue compiled into the binary).
    #[serde(default)]
    pub catalogue: Option<String>,
    /// Display name for an inline oil.
    #[serde(default)]
    pub name: Option<String>,
    /// Kinematic viscosity at 40 °C, cSt (mm²/s).
    #[serde(default)]
    pub nu40_cst: Option<f64>,
    /// Kinematic viscosity at 100 °C, cSt.
    #[serde(default)]
    pub nu100_cst: Option<f64>,
    /// Density at 15 °C, kg/m³.
    #[serde(default)]
    pub rho15_kg_m3: Option<f64>,
    /// Volumetric thermal expansion α_T, 1/K (default −6.5e−4, mineral).
    #[serde(default)]
    pub thermal_expansion_per_k: Option<f64>,
    /// Walther constant: `astm_d341` (0.7, default), `c06` (0.6, seed 001), `c08` (0.8, DIN 51563).
    #[serde(default)]
    pub walther: Option<WaltherVariant>,
    /// Base stock (`mineral`, `pao`, `ester`, `pag`, ...): sets the default lubricant factor.
    #[serde(default)]
    pub base: Option<crate::physics::oil::BaseOil>,
    /// Lubricant factor X_L measured for this oil (default: the base's standard value).
    #[serde(default)]
    pub lubricant_factor: Option<f64>,
}

/// What kind of rotating member (informational; kinematics treats all alike).
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum MemberKind {
    /// A shaft.
    Shaft,
    /// A planet carrier.
    Carrier,
    /// A drum or hub (e.g. a clutch drum carrying a ring gear).
    Drum,
}

/// `[[members]]`: a rigid rotating body (shaft, carrier, drum) that gears and shift elements attach to.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MemberSpec {
    /// Unique name.
    pub name: String,
    /// Kind (default `shaft`).
    #[serde(default)]
    pub kind: Option<MemberKind>,
    /// Permanently held by the housing (e.g. a sun gear bolted to the case).
    #[serde(default)]
    pub fixed: bool,
}

/// `[[gears]]`: one cylindrical involute gear (planets: one entry per planet type, counted by the set).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GearSpecFile {
    /// Unique name.
    pub name: String,
    /// Member the gear is fixed to (for planets: the carrier).
    pub member: String,
    /// Number of teeth.
    pub teeth: i64,
    /// Normal module, mm.
    pub module_mm: f64,
    /// Normal pressure angle, degrees (default 20).
    #[serde(default)]
    pub pressure_angle_deg: Option<f64>,
    /// Helix angle, degrees (default 0 = spur).
    #[serde(default)]
    pub helix_angle_deg: Option<f64>,
    /// Profile shift coefficient x (default 0).
    #[serde(default)]
    pub profile_shift: Option<f64>,
    /// Face width, mm.
    pub face_width_mm: f64,
    /// Tip diameter, mm (default from the basic rack).
    #[serde(default)]
    pub tip_diameter_mm: Option<f64>,
    /// Root diameter, mm (default from the basic rack).
    #[serde(default)]
    pub root_diameter_mm: Option<f64>,
    /// Addendum factor h_a* (default 1.0).
    #[serde(default)]
    pub addendum_factor: Option<f64>,
    /// Dedendum factor h_f* (default 1.25).
    #[serde(default)]
    pub dedendum_factor: Option<f64>,
    /// Tool tip radius factor ρ_fP* (default 0.25; usual 0.25–0.38).
    #[serde(default)]
    pub tool_tip_radius_factor: Option<f64>,
    /// Arithmetic mean flank roughness Ra, µm (default 0.5).
    #[serde(default)]
    pub roughness_ra_um: Option<f64>,
    /// `true` for an internal (ring) gear.
    #[serde(default)]
    pub internal: bool,
    /// Axial position of the face-width centre along the member (planets: along the pin), mm
    /// (default 0; bearing loads use it).
    #[serde(default)]
    pub position_mm: Option<f64>,
}

/// External or internal mesh.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum MeshKindSpec {
    /// Two external gears.
    External,
    /// An external pinion inside an internal (ring) gear; list the pinion first.
    Internal,
}

/// `[[meshes]]`: a fixed-axis gear pair (planetary-set meshes are generated from the set).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// Name (default `"<gear1>/<gear2>"`).
    #[serde(default)]
    pub name: Option<String>,
    /// The two gears; gear 1 drives in the loss convention (for internal meshes: pinion, ring).
    pub gears: Vec<String>,
    /// `external` (default) or `internal`.
    #[serde(default)]
    pub kind: Option<MeshKindSpec>,
    /// Operating centre distance, mm (default: from the profile shifts, backlash-free).
    #[serde(default)]
    pub centre_distance_mm: Option<f64>,
}

/// Kind of planetary set.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum PlanetarySetKind {
    /// Sun – planet – ring.
    Simple,
    /// Sun – inner planet – outer planet – ring.
    DoublePinion,
    /// Large sun – long planet – ring, plus small sun – short planet – long planet.
    Ravigneaux,
}

/// `[[planetary_sets]]`: which gears form the set, its carrier and its number of planets.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PlanetarySetSpec {
    /// Unique name.
    pub name: String,
    /// `simple`, `double_pinion` or `ravigneaux`.
    pub kind: PlanetarySetKind,
    /// Carrier member.
    pub carrier: String,
    /// Number of planets (of each planet type).
    pub planets: i64,
    /// Ring gear (all kinds).
    pub ring: String,
    /// Sun gear (simple, double_pinion).
    #[serde(default)]
    pub sun: Option<String>,
    /// Planet gear (simple).
    #[serde(default)]
    pub planet: Option<String>,
    /// Planet meshing the sun (double_pinion).
    #[serde(default)]
    pub inner_planet: Option<String>,
    /// Planet meshing the ring (double_pinion).
    #[serde(default)]
    pub outer_planet: Option<String>,
    /// Large sun, meshing the long planet (ravigneaux).
    #[serde(default)]
    pub large_sun: Option<String>,
    /// Small sun, meshing the short planet (ravigneaux).
    #[serde(default)]
    pub small_sun: Option<String>,
    /// Long planet: large sun, ring, short planet (ravigneaux).
    #[serde(default)]
    pub long_planet: Option<String>,
    /// Short planet: small sun, long planet (ravigneaux).
    #[serde(default)]
    pub short_planet: Option<String>,
}

/// Clutch or brake.
#[derive(Debug, Clone, Copy, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ShiftElementKind {
    /// Joins two members when engaged.
    Clutch,
    /// Holds one member to the housing when engaged.
    Brake,
}

/// `[[shift_elements]]`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ShiftElementSpec {
    /// Unique name (e.g. "A").
    pub name: String,
    /// `clutch` or `brake`.
    pub kind: ShiftElementKind,
    /// Clutch: the two members it joins. Brake: the one member it holds.
    pub members: Vec<String>,
}

/// `[[gear_states]]`: a gear (1st, 2nd, ..., R) and the shift elements engaged in it.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GearStateSpec {
    /// Name used on the command line and in cycle files ("1", "2", "R").
    pub name: String,
    /// Engaged shift elements.
    #[serde(default)]
    pub engaged: Vec<String>,
}

/// `[train]`: where power enters and leaves.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TrainSpec {
    /// Input member (engine / motor side).
    pub input: String,
    /// Output member (final drive side).
    pub output: String,
}

/// `[lubrication]`: dip lubrication geometry. Heights share one vertical datum (any, e.g. the sump floor).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LubricationSpec {
    /// Height of the static oil surface, mm.
    pub oil_level_mm: f64,
    /// Height of each non-planet gear's axis, mm, keyed by gear name. Planets orbit: their immersion
    /// is taken at the lowest position of the orbit (from the sun's axis height).
    pub centre_height_mm: std::collections::BTreeMap<String, f64>,
    /// Oil volume in the sump, litres (used by the Changenet–Velex churning model).
    #[serde(default)]
    pub sump_volume_l: Option<f64>,
}

/// `[losses]`: which loss models to use and their coefficients (defaults in docs/model-file.md).
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LossesSpec {
    /// Churning model: `changenet` (default), `seetharaman`, `stavytskyi` or `off`.
    #[serde(default)]
    pub churning: Option<String>,
    /// Pocketing: `on` (default) or `off`.
    #[serde(default)]
    pub pocketing: Option<String>,
    /// Sliding model: `detailed` (default), `iso14179` (closed form) or `off`.
    #[serde(default)]
    pub sliding: Option<String>,
    /// Friction law of the detailed sliding model: `iso_tc60` (default), `benedict_kelley`,
    /// `schlenk` or `constant`.
    #[serde(default)]
    pub friction: Option<String>,
    /// μ for `friction = "constant"`.
    #[serde(default)]
    pub friction_coefficient: Option<f64>,
    /// Lubricant factor X_L of the Schlenk / ISO/TR 14179-2 law (default: the oil's).
    #[serde(default)]
    pub lubricant_factor: Option<f64>,
    /// Load per length in Schlenk's μ: `contact_line` (default, F_bn/l_min) or `face_width`
    /// (F_bt/b, ISO/TR 14179-2).
    #[serde(default)]
    pub contact_line_load: Option<String>,
    /// Spur load sharing: `uniform` (default), `33:67`, `45:55`, `ramp`.
    #[serde(default)]
    pub load_sharing: Option<String>,
    /// Line-load distribution of helical meshes: `niemann_richer` (default) or `uniform`.
    #[serde(default)]
    pub helical_distribution: Option<String>,
    /// `first_order` (default, μ·F·v_g) or `moment_balance` (seed 003).
    #[serde(default)]
    pub loss_form: Option<String>,
    /// Helical meshes: face-width slices (default 50; seed 003 uses 150).
    #[serde(default)]
    pub helical_slices: Option<i64>,
    /// Helical meshes: time samples over one base pitch (default 8).
    #[serde(default)]
    pub helical_time_samples: Option<i64>,
    /// Fraction of a mesh's sliding loss that heats gear 1 (default 0.5).
    #[serde(default)]
    pub sliding_heat_to_gear1: Option<f64>,
    /// Pocketing discharge coefficient C_d (default 0.65).
    #[serde(default)]
    pub pocketing_discharge_coefficient: Option<f64>,
    /// Density of the oil–air mixture pumped by a mesh above the oil level, kg/m³ (no default: unknown, not counted, warned).
    #[serde(default)]
    pub pocketing_mixture_density_kg_m3: Option<f64>,
    /// Seetharaman–Kahraman: face transition Reynolds number (default 5e5).
    #[serde(default)]
    pub seetharaman_transition_reynolds: Option<f64>,
    /// Seetharaman–Kahraman tooth-cavity term: `stokes` (default), `form_drag` or `none`.
    #[serde(default)]
    pub seetharaman_cavity: Option<String>,
    /// Stavytskyi: edge coefficient k_s (0.85 sharp, 0.9 deburred).
    #[serde(default)]
    pub stavytskyi_ks: Option<f64>,
    /// Changenet–Velex low-Re law [factor, exp(h/D), exp(V0/D³), exp(Fr), exp(Re)] \[recalled\].
    #[serde(default)]
    pub changenet_low: Option<[f64; 5]>,
    /// Changenet–Velex high-Re law [factor, exp(h/D), exp(V0/D³), exp(Fr), exp(b/D)] \[recalled\].
    #[serde(default)]
    pub changenet_high: Option<[f64; 5]>,
}

/// The whole model file.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// `[model]`.
    pub model: ModelMeta,
    /// `[oil]`.
    pub oil: OilSpec,
    /// `[[members]]`.
    #[serde(default)]
    pub members: Vec<MemberSpec>,
    /// `[[gears]]`.
    pub gears: Vec<GearSpecFile>,
    /// `[[meshes]]` (fixed-axis pairs).
    #[serde(default)]
    pub meshes: Vec<MeshSpec>,
    /// `[[planetary_sets]]`.
    #[serde(default)]
    pub planetary_sets: Vec<PlanetarySetSpec>,
    /// `[[shift_elements]]`.
    #[serde(default)]
    pub shift_elements: Vec<ShiftElementSpec>,
    /// `[[gear_states]]` (a fixed-ratio box may omit it: one state named "1").
    #[serde(default)]
    pub gear_states: Vec<GearStateSpec>,
    /// `[train]`.
    pub train: TrainSpec,
    /// `[lubrication]`.
    pub lubrication: LubricationSpec,
    /// `[losses]` (reserved: loss-model choices).
    #[serde(default)]
    pub losses: Option<LossesSpec>,
    /// `[thermal]`: the lumped thermal network.
    #[serde(default)]
    pub thermal: Option<super::thermal::ThermalSpec>,
    /// `[vehicle]` (reserved: vehicle and shift strategy; read by the transient issue).
    #[serde(default)]
    pub vehicle: Option<toml::Table>,
    /// `[[clutch_packs]]`: friction packs of shift elements (open-clutch drag).
    #[serde(default)]
    pub clutch_packs: Vec<super::automatic::ClutchPackSpec>,
    /// `[pump]`: the transmission oil pump.
    #[serde(default)]
    pub pump: Option<super::automatic::PumpSpec>,
    /// `[launch]`: torque converter between engine and gearbox input (checked by the cycle layer).
    #[serde(default)]
    pub launch: Option<toml::Table>,
    /// `[[bearings]]`.
    #[serde(default)]
    pub bearings: Vec<super::bearings::BearingSpec>,
    /// `[[seals]]`.
    #[serde(default)]
    pub seals: Vec<super::bearings::SealSpec>,
}
