//! The loss part of a compiled scene: every loss item of a gearbox with its precomputed model,
//! per-gear-state kinematic factors, and an allocation-free evaluation at an operating point.
//!
//! Compile once (`LossScene::compile`): churning models only for gears that reach the oil,
//! pocketing integrals K per external mesh, sliding contact-path tables per mesh, and for every
//! gear state the gear speeds and mesh torques per unit input. Evaluating all losses at an
//! operating point (`LossScene::evaluate`) is then a loop over flat arrays with no allocation.

use crate::model::gearbox::{GearMount, Gearbox, SlidingChoice};
use crate::physics::geometry::MeshKind;
use crate::physics::losses::churning::{ChurningGear, GearChurning, OilState as ChurnOil};
use crate::physics::losses::pocketing::{PocketMeshInput, PocketingMesh};
use crate::physics::losses::sliding::friction::Schlenk;
use crate::physics::losses::sliding::{OilState as SlideOil, PowerLaw, SlidingMesh, SlidingMeshInput};
use crate::physics::oil::OilProperties;

use super::churn_sample::{self, ChurnSample, InputSpeedPowers};
use crate::physics::losses::churning::ChangenetSum;

/// Helical pockets: the exact infinitely-many-slices limit of the connected-slice model (one spur
/// pocket history summed over phases; 48 discrete slices are 1.8–2 % high on the AT6 meshes,
/// docs/performance.md "Helical pocket integral").
pub const HELIX_POCKET_SLICES: Option<usize> = None;

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
#[derive(Debug, Clone, serde::Serialize)]
pub struct Skipped {
    /// What (e.g. "churning of gear s1_sun").
    pub what: String,
    /// Why.
    pub why: String,
}

/// Kinematic factors of one gear state (per unit input speed / torque).
#[derive(Debug, Clone)]
struct StateFactors {
    /// |absolute speed| of each churning entry's gear.
    churn_speed: Vec<f64>,
    /// Carrier-frame speed of gear 1 of each pocketing entry's mesh.
    pocket_speed: Vec<f64>,
    /// Per sliding entry: torque on gear 1 (one mesh), carrier-frame ω1, ω2.
    slide: Vec<[f64; 3]>,
    /// Per sliding entry with a power law: loss (W, multiplicity included) at input speed
    /// 1 rad/s, η = 1 Pa·s and input torque +1 N·m / −1 N·m (the two power-flow directions).
    slide_unit: Vec<[f64; 2]>,
}

#[derive(Debug, Clone)]
struct ChurnEntry {
    item: usize,
    /// One model per immersion the gear takes, with its weight (a fixed-axis gear: one, weight 1;
    /// a planet set: the orbit-average quadrature with the planets counted, `planet_churning`).
    models: Vec<(GearChurning, f64)>,
    /// Their sum as a law of the oil per speed (Changenet–Velex immersions of one gear).
    law: Option<ChangenetSum>,
    /// Per gear state: the law's terms of the gear's speed ratio ([`ChangenetSum::ratio_terms`]).
    ratio_terms: Vec<[f64; 3]>,
}

#[derive(Debug, Clone)]
struct PocketEntry {
    item: usize,
    model: PocketingMesh,
    multiplicity: f64,
    /// Fraction of the time the mesh zone is below the oil level (0..1).
    wet_fraction: f64,
}

#[derive(Debug, Clone)]
enum SlideModel {
    Detailed(SlidingMesh),
    Iso14179(SlidingMesh, Schlenk),
}

#[derive(Debug, Clone)]
struct SlideEntry {
    item: usize,
    model: SlideModel,
    multiplicity: f64,
    /// Exponents of torque, speed and viscosity when the friction law makes the loss a product
    /// of their powers (`SlidingMesh::power_law`); `None`: evaluated in full at every call.
    law: Option<PowerLaw>,
}

/// What a run needs from the scene (scene pruning, docs/physics.md "Pruning and the per-sample cache").
#[derive(Debug, Clone, Default)]
pub struct Needs {
    /// Gear states the run visits (`None`: every state of the model). Loss items idle in all of
    /// them (no relative motion, no load) are not compiled.
    pub states: Option<Vec<usize>>,
    /// Evaluate everything: keep idle items and states, and recompute every loss in full at
    /// every call instead of caching per-sample terms. Only for measuring what pruning and
    /// caching gain; results agree to rounding.
    pub evaluate_all: bool,
    /// Loss energy per source only (three quadratures) instead of per item: for runs whose
    /// outputs do not include the energy of each item (the work-precision benchmark).
    pub energy_per_source_only: bool,
}

/// Loss terms that change only from one cycle sample to the next (gear state, input speed and
/// torque), kept apart from what changes at every right-hand-side call (the oil temperature).
/// Filled by [`LossScene::prepare`]; allocation-free afterwards.
#[derive(Debug, Clone)]
pub struct SampleTerms {
    /// (state, input speed bits, input torque bits) the terms were computed for.
    key: Option<(usize, u64, u64)>,
    /// Per sliding entry: loss at η = 1 Pa·s for this sample's torque and speed (W,
    /// multiplicity included); unused for entries without a power law.
    slide_unit: Vec<f64>,
    /// Per bearing: the load- and speed-dependent terms of this sample.
    bearing: Vec<crate::physics::losses::bearings::LoadTerms>,
    /// Per churning entry: its power as a law of the oil at this sample's speed.
    churn: Vec<ChurnSample>,
    /// Samples prepared.
    pub prepared: usize,
    /// Pump and converter values of the sample (they need the vehicle speed too).
    pub auto: super::automatic::AutoSample,
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

/// Compiled loss models of a gearbox.
#[derive(Debug, Clone)]
pub struct LossScene {
    /// Loss items in output order (churning per immersed gear, pocketing per mesh, sliding per mesh).
    pub items: Vec<LossItem>,
    /// What was left out and why.
    pub skipped: Vec<Skipped>,
    churn: Vec<ChurnEntry>,
    pocket: Vec<PocketEntry>,
    slide: Vec<SlideEntry>,
    states: Vec<StateFactors>,
    /// Density pumped by the part of a mesh zone above the oil (`None`: unknown, not counted).
    mixture_density: Option<f64>,
    /// Warnings known at compile time (e.g. pocketing of meshes above the oil not counted).
    pub warnings: Vec<super::ranges::RangeWarning>,
    /// Gear-state names (for reports that know a state by name).
    pub state_names: Vec<String>,
    auto: super::automatic::AutoLosses,
    /// Bearings and seals.
    elements: super::element_losses::ElementLosses,
    /// Multiplier of each item (`[losses] multiplier`), when any differs from 1.
    factor: Option<Vec<f64>>,
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

/// Churning data of gear `gi` (immersion at its lowest position; planets: the lowest orbit point).
pub fn churning_gear(gb: &Gearbox, gi: usize) -> ChurningGear {
    let g = &gb.gears[gi];
    let geo = &g.geometry;
    let (tip, root) = if geo.is_internal() {
        // A ring's outer rim dips: treated as an external gear of the same tooth count and module
        // whose tip circle is the ring's root circle (docs/physics.md §5, "ring gears").
        let h = (geo.d_f - geo.d_a).abs() / 2.0;
        (geo.d_f / 2.0, geo.d_f / 2.0 - h)
    } else {
        (geo.d_a / 2.0, geo.d_f / 2.0)
    };
    let space_tip = if geo.is_internal() {
        (geo.p_t - geo.s_t).max(0.0)
    } else {
        geo.e_at.max(0.0)
    };
    ChurningGear {
        tip_radius: tip,
        root_radius: root,
        pitch_radius: geo.d / 2.0,
        face_width: geo.spec.b,
        teeth: geo.z(),
        normal_module: geo.spec.mn,
        helix_angle: geo.spec.beta,
        normal_pressure_angle: geo.spec.alpha_n,
        profile_shift: if geo.is_internal() { 0.0 } else { geo.spec.x },
        space_width_tip: space_tip,
        tooth_height: tip - root,
        immersion_depth: g.immersion,
    }
}

/// Fraction of a circle of radius `r` around height `yc` lying below the level `level`.
fn wet_fraction(yc: f64, r: f64, level: f64) -> f64 {
    if r <= 0.0 {
        return if yc < level { 1.0 } else { 0.0 };
    }
    let c = ((yc - level) / r).clamp(-1.0, 1.0);
    // Points y = yc + r cos t below the level: cos t < −(yc − level)/r … fraction acos(c)/π.
    (c.acos() / std::f64::consts::PI).clamp(0.0, 1.0)
}

impl LossScene {
    /// Build the loss models of `gb` for every gear state.
    pub fn compile(gb: &Gearbox) -> Result<LossScene, SceneError> {
        Self::compile_for(gb, &Needs::default())
    }

    /// Build the loss models `needs` asks for, once. Items that neither move nor carry load in
    /// any needed gear state are skipped and listed in [`Self::skipped`] (unless
    /// `needs.evaluate_all`).
    pub fn compile_for(gb: &Gearbox, needs: &Needs) -> Result<LossScene, SceneError> {
        let usage = Usage::of(gb, needs);
        let mut items = Vec::new();
        let mut skipped = Vec::new();
        let mut churn = Vec::new();
        let mut pocket = Vec::new();
        let mut slide = Vec::new();
        let mut warnings = Vec::new();
        let models = &gb.losses;

        // Churning: one item per gear that reaches the oil.
        let mut churn_gears = Vec::new();
        match &models.churning {
            None => skipped.push(Skipped {
                what: "churning".into(),
                why: "switched off ([losses] churning = \"off\")".into(),
            }),
            Some(cfg) => {
                for (gi, g) in gb.gears.iter().enumerate() {
                    if !g.is_immersed() {
                        skipped.push(Skipped {
                            what: format!("churning of gear {}", g.name),
                            why: format!(
                                "does not reach the oil (lowest point {:.1} mm above the level)",
                                -g.immersion * 1e3
                            ),
                        });
                        continue;
                    }
                    if !usage.any(|u, st| u.speeds[st][gi].absolute != 0.0) {
                        skipped.push(usage.idle(format!("churning of gear {}", g.name), "stands still"));
                        continue;
                    }
                    let models = super::planet_churning::models(cfg, gb, gi, &churning_gear(gb, gi))
                        .map_err(|e| SceneError {
                            what: format!("churning of gear {}", g.name),
                            why: e.to_string(),
                        })?;
                    churn.push(ChurnEntry {
                        item: items.len(),
                        // `evaluate_all` measures the scene without its per-sample laws.
                        law: churn_sample::sum_law(&models).filter(|_| !needs.evaluate_all),
                        ratio_terms: Vec::new(),
                        models,
                    });
                    if cfg.model == crate::physics::losses::churning::ChurningModel::Stavytskyi {
                        let out = crate::physics::losses::churning::ranges::stavytskyi_geometry(
                            &churning_gear(gb, gi),
                        );
                        if !out.is_empty() {
                            warnings.push(super::ranges::RangeWarning {
                                item: format!("churning of gear {}", g.name),
                                range: crate::physics::losses::churning::ranges::STAVYTSKYI_TESTED.into(),
                                seen: out.join(", "),
                            });
                        }
                    }
                    churn_gears.push(gi);
                    items.push(LossItem {
                        source: Source::Churning,
                        name: g.name.clone(),
                        gears: vec![(gi, 1.0)],
                        heat: DefaultHeat::Oil,
                        engine_side: false,
                    });
                }
            }
        }

        // Pocketing: external meshes.
        let mut pocket_meshes = Vec::new();
        // meshes of identical geometry (and C_d) share one K computation
        let mut pocket_built: Vec<(PocketMeshInput, PocketingMesh)> = Vec::new();
        match &models.pocketing {
            None => skipped.push(Skipped {
                what: "pocketing".into(),
                why: "switched off ([losses] pocketing = \"off\")".into(),
            }),
            Some(opt) => {
                for (mi, m) in gb.meshes.iter().enumerate() {
                    let geo = &m.geometry;
                    if geo.kind == MeshKind::Internal {
                        skipped.push(Skipped {
                            what: format!("pocketing of mesh {}", m.name),
                            why: "internal mesh: the pocket model (seed 004) covers external meshes only"
                                .into(),
                        });
                        continue;
                    }
                    // (Before the idle check: a mesh above the oil is unknown in every state.) Height of the pitch point; planets orbit, so the mesh point sweeps a circle.
                    let (wet, _) = mesh_zone(gb, mi);
                    if wet < 1.0 && opt.mixture_density.is_none() {
                        let w = super::ranges::above_oil_warning(&m.name, wet);
                        let dry = wet <= 0.0;
                        warnings.push(w);
                        if dry {
                            skipped.push(Skipped {
                                what: format!("pocketing of mesh {}", m.name),
                                why: "mesh zone entirely above the oil: pumped density unknown (set [losses] pocketing_mixture_density_kg_m3)".into(),
                            });
                            continue;
                        }
                    }
                    if !usage.any(|u, st| u.speeds[st][m.gear1].relative != 0.0) {
                        skipped.push(usage.idle(
                            format!("pocketing of mesh {}", m.name),
                            "has no relative motion (its gears turn as one)",
                        ));
                        continue;
                    }
                    let (g1, g2) = (&gb.gears[m.gear1], &gb.gears[m.gear2]);
                    let input = PocketMeshInput::from_gears(&g1.geometry, &g2.geometry, geo.a_w);
                    let popts = crate::physics::losses::pocketing::PocketingOptions {
                        discharge_coefficient: opt.discharge_coefficient,
                        helix_slices: HELIX_POCKET_SLICES,
                    };
                    let model = match pocket_built.iter().find(|(i, pm)| {
                        *i == input && pm.discharge_coefficient() == popts.discharge_coefficient
                    }) {
                        Some((_, pm)) => *pm,
                        None => {
                            let pm = PocketingMesh::with_options(&input, &popts).map_err(|e| SceneError {
                                what: format!("pocketing of mesh {}", m.name),
                                why: e.to_string(),
                            })?;
                            pocket_built.push((input, pm));
                            pm
                        }
                    };
                    pocket.push(PocketEntry {
                        item: items.len(),
                        model,
                        multiplicity: m.multiplicity as f64,
                        wet_fraction: wet,
                    });
                    pocket_meshes.push(mi);
                    items.push(LossItem {
                        source: Source::Pocketing,
                        name: m.name.clone(),
                        gears: vec![(m.gear1, 0.5), (m.gear2, 0.5)],
                        heat: DefaultHeat::Oil,
                        engine_side: false,
                    });
                }
            }
        }

        // Sliding.
        let mut slide_meshes = Vec::new();
        let (opts, schlenk) = match &models.sliding {
            SlidingChoice::Off => {
                skipped.push(Skipped {
                    what: "sliding".into(),
                    why: "switched off ([losses] sliding = \"off\")".into(),
                });
                (None, None)
            }
            SlidingChoice::Detailed(o) => (Some(*o), None),
            SlidingChoice::Iso14179(s, split) => (
                Some(crate::physics::losses::sliding::SlidingOptions {
                    heat_to_gear1: *split,
                    ..Default::default()
                }),
                Some(*s),
            ),
        };
        if let Some(opts) = opts {
            for (mi, m) in gb.meshes.iter().enumerate() {
                let loaded = |u: &Usage, st: usize| {
                    u.torques[st][mi] != 0.0
                        && (u.speeds[st][m.gear1].relative != 0.0 || u.speeds[st][m.gear2].relative != 0.0)
                };
                if !usage.any(loaded) {
                    skipped.push(usage.idle(
                        format!("sliding of mesh {}", m.name),
                        "carries no load or has no relative motion",
                    ));
                    continue;
                }
                let geo = &m.geometry;
                let (g1, g2) = (&gb.gears[m.gear1], &gb.gears[m.gear2]);
                let input = SlidingMeshInput {
                    base_radius1: geo.r_b1,
                    base_radius2: geo.r_b2,
                    operating_pressure_angle: geo.alpha_wt,
                    tip_radius1: geo.r_a1,
                    tip_radius2: geo.r_a2,
                    centre_distance: geo.a_w,
                    face_width: geo.b,
                    base_helix_angle: geo.beta_b,
                    transverse_base_pitch: geo.p_bt,
                    internal: geo.kind == MeshKind::Internal,
                    z1: geo.z1,
                    z2: geo.z2,
                    roughness_ra1: g1.roughness_ra,
                    roughness_ra2: g2.roughness_ra,
                };
                let what = format!("sliding of mesh {}", m.name);
                let sm = SlidingMesh::new(&input, &opts).map_err(|e| SceneError {
                    what: what.clone(),
                    why: e.to_string(),
                })?;
                let (model, law) = match schlenk {
                    // μ_mz ∝ (F/b/(v ρ))^0.2·η^−0.05 and the closed form is linear in μ
                    Some(s) => (SlideModel::Iso14179(sm, s), Some(PowerLaw::SCHLENK)),
                    None => {
                        let k = sm.power_law();
                        (SlideModel::Detailed(sm), k)
                    }
                };
                slide.push(SlideEntry {
                    item: items.len(),
                    model,
                    multiplicity: m.multiplicity as f64,
                    law: if needs.evaluate_all { None } else { law },
                });
                slide_meshes.push(mi);
                let f1 = opts.heat_to_gear1;
                items.push(LossItem {
                    source: Source::Sliding,
                    name: m.name.clone(),
                    gears: vec![(m.gear1, f1), (m.gear2, 1.0 - f1)],
                    heat: DefaultHeat::Gears,
                    engine_side: false,
                });
            }
        }

        // Per-state kinematic factors of the compiled entries, and the sliding element sums of
        // the separable laws per state and power-flow direction (unit torque, speed, viscosity).
        let states = (0..gb.gear_states.len())
            .map(|si| {
                let (speeds, torques) = (&usage.speeds[si], &usage.torques[si]);
                let mut f = StateFactors {
                    churn_speed: churn_gears.iter().map(|&gi| speeds[gi].absolute.abs()).collect(),
                    pocket_speed: pocket_meshes
                        .iter()
                        .map(|&mi| speeds[gb.meshes[mi].gear1].relative)
                        .collect(),
                    slide: slide_meshes
                        .iter()
                        .map(|&mi| {
                            let m = &gb.meshes[mi];
                            [torques[mi], speeds[m.gear1].relative, speeds[m.gear2].relative]
                        })
                        .collect(),
                    slide_unit: Vec::new(),
                };
                f.slide_unit = slide
                    .iter()
                    .zip(&f.slide)
                    .map(|(e, k)| match e.law {
                        Some(_) if usage.needed(si) => [
                            sliding(e, k, 1.0, 1.0, 1.0, 1.0),
                            sliding(e, k, -1.0, 1.0, 1.0, 1.0),
                        ],
                        _ => [f64::NAN; 2],
                    })
                    .collect();
                f
            })
            .collect::<Vec<StateFactors>>();
        for (j, e) in churn.iter_mut().enumerate() {
            if let Some(law) = &e.law {
                e.ratio_terms = states.iter().map(|f| law.ratio_terms(f.churn_speed[j])).collect();
            }
        }

        // The automatic's own parts: open clutch packs, pump, converter.
        let auto = super::automatic::AutoLosses::compile(
            gb,
            &|st| usage.needed(st),
            needs.evaluate_all,
            &mut items,
            &mut skipped,
        );

        let mixture_density = models.pocketing.and_then(|p| p.mixture_density);
        let elements = super::element_losses::ElementLosses::compile(
            gb,
            &|si| usage.needed(si),
            &|what, why| usage.idle(what, why),
            needs.evaluate_all,
            &mut items,
            &mut skipped,
        );
        let factor = multipliers(&models.multipliers, &items)?;
        Ok(LossScene {
            factor,
            items,
            skipped,
            churn,
            pocket,
            slide,
            states,
            mixture_density,
            warnings,
            state_names: gb.gear_states.iter().map(|s| s.name.clone()).collect(),
            auto,
            elements,
        })
    }

    /// Number of loss items.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when there is no loss item.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Evaluate every loss item (W) at `op` into `out` (length [`Self::len`]), everything in
    /// full. No allocation.
    pub fn evaluate(&self, op: &OperatingPoint, out: &mut [f64]) {
        self.evaluate_unscaled(op, out);
        self.scale(out);
    }

    fn evaluate_unscaled(&self, op: &OperatingPoint, out: &mut [f64]) {
        self.evaluate_load_independent(op, None, out);
        let none = super::automatic::AutoSample::default();
        self.auto
            .evaluate(op.state, op.input_speed, op.input_torque, &op.oil, &none, out);
        let st = &self.states[op.state];
        for (e, f) in self.slide.iter().zip(&st.slide) {
            out[e.item] = sliding(e, f, op.input_torque, op.input_speed, op.oil.mu, op.oil.rho);
        }
        self.elements
            .evaluate(op.state, op.input_speed, op.input_torque, &op.oil, None, out);
    }

    /// Empty per-sample terms for this scene (allocates once).
    pub fn sample_terms(&self) -> SampleTerms {
        SampleTerms {
            key: None,
            slide_unit: vec![0.0; self.slide.len()],
            bearing: vec![Default::default(); self.elements.bearings()],
            churn: vec![ChurnSample::Direct; self.churn.len()],
            prepared: 0,
            auto: Default::default(),
        }
    }

    /// Compute the per-sample terms for gear state `state`, input speed (rad/s) and torque
    /// (N·m): each separable sliding loss at η = 1 Pa·s, from its per-state unit value scaled by
    /// two powers. No allocation.
    pub fn prepare(&self, state: usize, input_speed: f64, input_torque: f64, terms: &mut SampleTerms) {
        self.prepare_at(state, input_speed, input_torque, 0.0, terms);
    }

    /// [`Self::prepare`] with the vehicle speed (m/s), which the converter's lock-up needs.
    pub fn prepare_at(
        &self,
        state: usize,
        input_speed: f64,
        input_torque: f64,
        vehicle_speed: f64,
        terms: &mut SampleTerms,
    ) {
        self.auto
            .prepare(state, input_speed, input_torque, vehicle_speed, &mut terms.auto);
        let key = (state, input_speed.to_bits(), input_torque.to_bits());
        if terms.key == Some(key) {
            return;
        }
        let st = &self.states[state];
        let (t, w) = (input_torque, input_speed);
        // P(T, ω) = P(sign(T·ω)·1 N·m, 1 rad/s)·|T|^a·|ω|^b: reversing both T and ω leaves the
        // power flow and every magnitude unchanged.
        let dir = usize::from(t * w < 0.0);
        // Meshes with the same friction law share their powers of |T| and |ω| (the last pair of
        // exponents is remembered; the same values as computing them per mesh).
        let mut memo = [(f64::NAN, 0.0); 2];
        let mut power = |i: usize, x: f64, e: f64| {
            if memo[i].0 != e {
                memo[i] = (e, x.abs().powf(e));
            }
            memo[i].1
        };
        for ((e, unit), u) in self.slide.iter().zip(&st.slide_unit).zip(&mut terms.slide_unit) {
            if let Some(law) = e.law {
                *u = if t == 0.0 || w == 0.0 {
                    0.0
                } else {
                    unit[dir] * power(0, t, law.torque) * power(1, w, law.speed)
                };
            }
        }
        self.elements.prepare(state, w, t, &mut terms.bearing);
        let mut input = InputSpeedPowers::new(w);
        for ((e, k), c) in self.churn.iter().zip(&st.churn_speed).zip(&mut terms.churn) {
            let ratio = e.ratio_terms.get(state).unwrap_or(&[0.0; 3]);
            *c = ChurnSample::prepare(e.law.as_ref(), ratio, k * w, &mut input);
        }
        terms.key = Some(key);
        terms.prepared += 1;
    }

    /// Evaluate every loss item (W) at `op` into `out` using the per-sample terms prepared for
    /// `op`'s state, speed and torque: sliding losses with a viscosity exponent cost one power
    /// of η. Terms prepared for another sample are ignored (full evaluation). No allocation.
    pub fn evaluate_cached(&self, op: &OperatingPoint, terms: &SampleTerms, out: &mut [f64]) {
        if terms.key != Some((op.state, op.input_speed.to_bits(), op.input_torque.to_bits())) {
            return self.evaluate(op, out);
        }
        self.evaluate_cached_unscaled(op, terms, out);
        self.scale(out);
    }

    /// Apply the items' multipliers.
    fn scale(&self, out: &mut [f64]) {
        if let Some(f) = &self.factor {
            out.iter_mut().zip(f).for_each(|(q, m)| *q *= m);
        }
    }

    fn evaluate_cached_unscaled(&self, op: &OperatingPoint, terms: &SampleTerms, out: &mut [f64]) {
        self.evaluate_load_independent(op, Some(&terms.churn), out);
        self.auto.evaluate(
            op.state,
            op.input_speed,
            op.input_torque,
            &op.oil,
            &terms.auto,
            out,
        );
        let st = &self.states[op.state];
        let mut memo = (f64::NAN, 0.0);
        for ((e, f), u) in self.slide.iter().zip(&st.slide).zip(&terms.slide_unit) {
            out[e.item] = match e.law {
                Some(law) => {
                    let k = law.viscosity;
                    if k != memo.0 {
                        memo = (k, op.oil.mu.powf(k));
                    }
                    u * memo.1
                }
                None => sliding(e, f, op.input_torque, op.input_speed, op.oil.mu, op.oil.rho),
            };
        }
        self.elements.evaluate(
            op.state,
            op.input_speed,
            op.input_torque,
            &op.oil,
            Some(&terms.bearing),
            out,
        );
    }

    /// Every churning model with its loss item and its gear's speed (rad/s) in gear state
    /// `state` at input speed `input_speed` (for range checks; planets: one per orbit node).
    pub fn churning_models(
        &self,
        state: usize,
        input_speed: f64,
    ) -> impl Iterator<Item = (usize, &GearChurning, f64)> + '_ {
        let st = &self.states[state];
        self.churn
            .iter()
            .zip(&st.churn_speed)
            .flat_map(move |(e, k)| e.models.iter().map(move |(m, _)| (e.item, m, k * input_speed)))
    }

    /// Churning and pocketing at `op` into `out`; churning from the sample's laws `churn` when
    /// given (prepared for `op`'s state and speed).
    fn evaluate_load_independent(&self, op: &OperatingPoint, churn: Option<&[ChurnSample]>, out: &mut [f64]) {
        let st = &self.states[op.state];
        let w_in = op.input_speed;
        let churn_oil = ChurnOil {
            density: op.oil.rho,
            kinematic_viscosity: op.oil.nu,
        };
        match churn {
            Some(laws) if !self.churn.is_empty() => {
                let ln_nu = op.oil.nu.ln();
                for ((e, k), law) in self.churn.iter().zip(&st.churn_speed).zip(laws) {
                    out[e.item] = law.power(&e.models, e.law.as_ref(), k * w_in, &churn_oil, ln_nu);
                }
            }
            _ => {
                for (e, k) in self.churn.iter().zip(&st.churn_speed) {
                    out[e.item] = ChurnSample::Direct.power(&e.models, None, k * w_in, &churn_oil, 0.0);
                }
            }
        }
        for (e, k) in self.pocket.iter().zip(&st.pocket_speed) {
            // The share above the oil pumps an unknown density unless the model file gives one;
            // it is then not counted (and reported in `warnings`).
            let rho =
                e.wet_fraction * op.oil.rho + (1.0 - e.wet_fraction) * self.mixture_density.unwrap_or(0.0);
            out[e.item] = e.multiplicity * e.model.power(k * w_in, rho);
        }
    }
}

/// Sliding loss of one entry (W, multiplicity included) with state factors `f`, input
/// torque `torque` (N·m), input speed `w_in` (rad/s), oil viscosity `mu` (Pa·s), density `rho`.
fn sliding(e: &SlideEntry, f: &[f64; 3], torque: f64, w_in: f64, mu: f64, rho: f64) -> f64 {
    // The sliding model takes the torque gear 1 transmits (it drives when t1·ω1 > 0): the
    // opposite of the torque the mesh applies to it.
    let t1 = -f[0] * torque;
    let (w1, w2) = (f[1] * w_in, f[2] * w_in);
    if t1 == 0.0 || (w1 == 0.0 && w2 == 0.0) {
        // No load or no relative motion in this state (e.g. a locked planetary set): skipped.
        return 0.0;
    }
    let oil = SlideOil {
        dynamic_viscosity: mu,
        density: rho,
    };
    let p = match &e.model {
        SlideModel::Detailed(m) => m.power(t1, w1, w2, oil).total,
        SlideModel::Iso14179(m, s) => {
            let mu = m.mu_mz(t1, w1, w2, oil, s);
            m.closed_form_power(t1, w1, mu).total
        }
    };
    e.multiplicity * p
}

/// Kinematics of every gear state and which states a run needs.
struct Usage {
    /// Per state: gear speeds per unit input speed.
    speeds: Vec<Vec<crate::model::gearbox::GearSpeed>>,
    /// Per state: mesh torques per unit input torque.
    torques: Vec<Vec<f64>>,
    /// Needed states.
    used: Vec<usize>,
    /// Names of the needed states when they are not all of the model's.
    subset: Option<String>,
    /// Keep everything.
    all: bool,
}

impl Usage {
    fn of(gb: &Gearbox, needs: &Needs) -> Usage {
        // Round-off from the kinematic solve (~1e-16 per unit input) is snapped to exact zero so a
        // locked set (all members at one speed) has no relative motion at all.
        let clean = |v: f64| if v.abs() < 1e-12 { 0.0 } else { v };
        let n = gb.gear_states.len();
        let speeds = (0..n)
            .map(|si| {
                gb.gear_speeds(si)
                    .into_iter()
                    .map(|s| crate::model::gearbox::GearSpeed {
                        absolute: clean(s.absolute),
                        relative: clean(s.relative),
                    })
                    .collect()
            })
            .collect();
        let torques = (0..n)
            .map(|si| gb.mesh_torques(si).into_iter().map(clean).collect())
            .collect();
        let mut used: Vec<usize> = match (&needs.states, needs.evaluate_all) {
            (Some(s), false) => s.iter().copied().filter(|&i| i < n).collect(),
            _ => (0..n).collect(),
        };
        used.sort_unstable();
        used.dedup();
        let subset = (used.len() < n).then(|| {
            used.iter()
                .map(|&i| gb.gear_states[i].name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        });
        Usage {
            speeds,
            torques,
            used,
            subset,
            all: needs.evaluate_all,
        }
    }

    /// True if state `si` is needed.
    fn needed(&self, si: usize) -> bool {
        self.all || self.used.binary_search(&si).is_ok()
    }

    /// True if `pred` holds in a needed state (always true when everything is kept).
    fn any(&self, pred: impl Fn(&Usage, usize) -> bool) -> bool {
        self.all || self.used.iter().any(|&st| pred(self, st))
    }

    fn idle(&self, what: String, why: &str) -> Skipped {
        Skipped {
            what,
            why: match &self.subset {
                Some(names) => format!("{why} in every gear state the run uses ({names})"),
                None => format!("{why} in every gear state"),
            },
        }
    }
}

/// Wet fraction of a mesh zone and the height of its pitch point (lowest orbit position for
/// planetary meshes).
fn mesh_zone(gb: &Gearbox, mi: usize) -> (f64, f64) {
    let m = &gb.meshes[mi];
    let (g1, g2) = (&gb.gears[m.gear1], &gb.gears[m.gear2]);
    let geo = &m.geometry;
    let level = gb.oil_level;
    match m.set {
        None => {
            // Pitch point on the line of centres at r_w1 from gear 1's axis; the vertical offset
            // of the axes is known, the horizontal is not needed.
            let y = g1.centre_height + (g2.centre_height - g1.centre_height) * geo.r_w1 / geo.a_w;
            // The mesh zone spans about one tooth height above and below the pitch point; its wet
            // fraction is the share of that band below the oil surface (0.5 with the oil at the
            // pitch point, as in an FZG box filled to the shaft centres).
            let band = 2.25 * geo.mn;
            (((level - (y - band)) / (2.0 * band)).clamp(0.0, 1.0), y)
        }
        Some(si) => {
            // Set axis height and the radius of the circle the pitch point sweeps.
            let set = &gb.planetary_sets[si];
            let axis = set
                .gears
                .iter()
                .find(|&&gi| gb.gears[gi].mount == GearMount::OnMember)
                .map_or(g1.centre_height, |&gi| gb.gears[gi].centre_height);
            let planet_low = |g: &crate::model::gearbox::Gear| axis - g.centre_height;
            let r = match (g1.mount, g2.mount) {
                // sun–planet: pitch point at r_w1 from the axis; planet–ring: at orbit + r_w1.
                (GearMount::OnMember, _) => geo.r_w1,
                (_, GearMount::OnMember) => planet_low(g1) + geo.r_w1,
                // planet–planet: approximate by the mean of the two planets' orbits.
                _ => 0.5 * (planet_low(g1) + planet_low(g2)),
            };
            (wet_fraction(axis, r, level), axis - r)
        }
    }
}

/// Each item's multiplier from `[losses] multiplier` (source, then item), or None when none is
/// given; an item name that matches no item is an error naming the items of that source.
fn multipliers(
    given: &[(crate::model::source::Source, Option<String>, f64)],
    items: &[LossItem],
) -> Result<Option<Vec<f64>>, SceneError> {
    if given.is_empty() {
        return Ok(None);
    }
    let mut f = vec![1.0; items.len()];
    for (source, item, m) in given.iter().filter(|g| g.1.is_none()) {
        debug_assert!(item.is_none());
        f.iter_mut()
            .zip(items)
            .filter(|(_, it)| it.source == *source)
            .for_each(|(x, _)| *x *= m);
    }
    for (source, item, m) in given {
        let Some(name) = item else { continue };
        let k = items
            .iter()
            .position(|it| it.source == *source && it.name == *name)
            .ok_or_else(|| SceneError {
                what: format!("losses.multiplier.\"{}:{name}\"", source.as_str()),
                why: format!(
                    "no {} item named {name} (items: {})",
                    source.as_str(),
                    items
                        .iter()
                        .filter(|it| it.source == *source)
                        .map(|it| it.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })?;
        f[k] *= m;
    }
    Ok(Some(f))
}

#[cfg(test)]
mod tests {
    use super::wet_fraction;

    #[test]
    fn wet_fraction_of_a_circle() {
        assert_eq!(wet_fraction(0.0, 1.0, -2.0), 0.0);
        assert_eq!(wet_fraction(0.0, 1.0, 2.0), 1.0);
        assert!((wet_fraction(0.0, 1.0, 0.0) - 0.5).abs() < 1e-15);
        // level at the bottom quarter: cos t < −0.5 → t ∈ (2π/3, 4π/3): 1/3 of the circle.
        assert!((wet_fraction(0.0, 1.0, -0.5) - 1.0 / 3.0).abs() < 1e-12);
    }
}
