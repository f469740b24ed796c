//! The gear and mesh loss items of a compiled scene: churning per gear that reaches the oil,
//! pocketing per external mesh, sliding per mesh. What each entry holds, how it is compiled from
//! the model (skipping items idle in every needed gear state), and the per-state kinematic factors
//! [`super::losses::LossScene`] evaluates them with.

use crate::model::gearbox::{GearMount, Gearbox, SlidingChoice, Target};
use crate::physics::geometry::MeshKind;
use crate::physics::losses::churning::ranges as churning_ranges;
use crate::physics::losses::churning::{ChangenetSum, ChurningGear, ChurningModel, GearChurning};
use crate::physics::losses::pocketing::{PocketMeshInput, PocketingMesh};
use crate::physics::losses::sliding::friction::Schlenk;
use crate::physics::losses::sliding::{OilState as SlideOil, PowerLaw, SlidingMesh, SlidingMeshInput};
use crate::physics::losses::windage::GearWindage;

use super::churn_sample;
use super::items::{DefaultHeat, LossItem, SceneError, Skipped, Source};
use super::usage::{Needs, Usage};
use super::warning::{above_oil_warning, RangeWarning};

/// Helical pockets: the exact infinitely-many-slices limit of the connected-slice model (one spur
/// pocket history summed over phases; 48 discrete slices are 0.5 % off and cost 0.35 s per AT6
/// compile).
pub const HELIX_POCKET_SLICES: Option<usize> = None;

/// Kinematic factors of one gear state (per unit input speed / torque).
#[derive(Debug, Clone)]
pub(super) struct StateFactors {
    /// |absolute speed| of each churning entry's gear.
    pub(super) churn_speed: Vec<f64>,
    /// Carrier-frame speed of gear 1 of each pocketing entry's mesh.
    pub(super) pocket_speed: Vec<f64>,
    /// Per sliding entry: torque on gear 1 (one mesh), carrier-frame ω1, ω2.
    pub(super) slide: Vec<[f64; 3]>,
    /// Per windage entry: its gear's speed relative to the air (planets: spin; others: absolute).
    pub(super) wind_speed: Vec<f64>,
    /// Per sliding entry with a power law: loss (W, multiplicity included) at input speed
    /// 1 rad/s, η = 1 Pa·s and input torque +1 N·m / −1 N·m (the two power-flow directions).
    pub(super) slide_unit: Vec<[f64; 2]>,
}

#[derive(Debug, Clone)]
pub(super) struct ChurnEntry {
    pub(super) item: usize,
    /// One model per immersion the gear takes, with its weight (a fixed-axis gear: one, weight 1;
    /// a planet set: the orbit-average quadrature with the planets counted, `planet_churning`).
    pub(super) models: Vec<(GearChurning, f64)>,
    /// Their sum as a law of the oil per speed (Changenet–Velex immersions of one gear).
    pub(super) law: Option<ChangenetSum>,
    /// Per gear state: the law's terms of the gear's speed ratio ([`ChangenetSum::ratio_terms`]).
    pub(super) ratio_terms: Vec<[f64; 3]>,
    /// Reference (pitch) radius of the gear, m (its pitch-line speed for the range warnings).
    pub(super) pitch_radius: f64,
}

#[derive(Debug, Clone)]
pub(super) struct PocketEntry {
    pub(super) item: usize,
    pub(super) model: PocketingMesh,
    pub(super) multiplicity: f64,
    /// Fraction of the time the mesh zone is below the oil level (0..1).
    pub(super) wet_fraction: f64,
    /// Circuit consumers that deliver oil to one of its instances: (consumer, fraction of the
    /// consumer's flow each instance receives).
    pub(super) feeds: Vec<(usize, f64)>,
}

#[derive(Debug, Clone)]
pub(super) struct WindEntry {
    pub(super) item: usize,
    pub(super) model: GearWindage,
    /// Planets of the set (1 for a gear on a member).
    pub(super) multiplicity: f64,
}

#[derive(Debug, Clone)]
pub(super) enum SlideModel {
    Detailed(SlidingMesh),
    Iso14179(SlidingMesh, Schlenk),
}

#[derive(Debug, Clone)]
pub(super) struct SlideEntry {
    pub(super) item: usize,
    pub(super) model: SlideModel,
    pub(super) multiplicity: f64,
    /// Exponents of torque, speed and viscosity when the friction law makes the loss a product
    /// of their powers (`SlidingMesh::power_law`); `None`: evaluated in full at every call.
    pub(super) law: Option<PowerLaw>,
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

/// The lists a compile fills item by item: the loss items in output order, what was left out
/// and the warnings known at compile time.
#[derive(Default)]
pub(super) struct Lists {
    pub(super) items: Vec<LossItem>,
    pub(super) skipped: Vec<Skipped>,
    pub(super) warnings: Vec<RangeWarning>,
}

/// Churning: one item per gear that reaches the oil and turns in a needed state. Returns the
/// entries and their gears.
pub(super) fn compile_churning(
    gb: &Gearbox,
    needs: &Needs,
    usage: &Usage,
    lists: &mut Lists,
) -> Result<(Vec<ChurnEntry>, Vec<usize>), SceneError> {
    let (mut churn, mut churn_gears) = (Vec::new(), Vec::new());
    let Some(cfg) = &gb.losses.churning else {
        lists.skipped.push(Skipped {
            what: "churning".into(),
            why: "switched off ([losses] churning = \"off\")".into(),
        });
        return Ok((churn, churn_gears));
    };
    for (gi, g) in gb.gears.iter().enumerate() {
        if !g.is_immersed() {
            lists.skipped.push(Skipped {
                what: format!("churning of gear {}", g.name),
                why: format!(
                    "does not reach the oil (lowest point {:.1} mm above the level)",
                    -g.immersion * 1e3
                ),
            });
            continue;
        }
        if !usage.any(|u, st| u.speeds[st][gi].absolute != 0.0) {
            lists
                .skipped
                .push(usage.idle(format!("churning of gear {}", g.name), "stands still"));
            continue;
        }
        let models =
            super::planet_churning::models(cfg, gb, gi, &churning_gear(gb, gi)).map_err(|e| SceneError {
                what: format!("churning of gear {}", g.name),
                why: e.to_string(),
            })?;
        churn.push(ChurnEntry {
            item: lists.items.len(),
            // `evaluate_all` measures the scene without its per-sample laws.
            law: churn_sample::sum_law(&models).filter(|_| !needs.evaluate_all),
            ratio_terms: Vec::new(),
            pitch_radius: churning_gear(gb, gi).pitch_radius,
            models,
        });
        if cfg.model == ChurningModel::Stavytskyi {
            lists.warnings.extend(stavytskyi_warning(gb, gi));
        }
        churn_gears.push(gi);
        lists.items.push(LossItem {
            source: Source::Churning,
            name: g.name.clone(),
            gears: vec![(gi, 1.0)],
            heat: DefaultHeat::Oil,
            engine_side: false,
        });
    }
    Ok((churn, churn_gears))
}

/// The warning for gear `gi` when its geometry lies outside Stavytskyi's tested range.
fn stavytskyi_warning(gb: &Gearbox, gi: usize) -> Option<RangeWarning> {
    let out = churning_ranges::stavytskyi_geometry(&churning_gear(gb, gi));
    (!out.is_empty()).then(|| RangeWarning {
        item: format!("churning of gear {}", gb.gears[gi].name),
        range: churning_ranges::STAVYTSKYI_TESTED.into(),
        seen: out.join(", "),
    })
}

/// Pocketing: one item per external mesh that reaches the oil (or whose dry share has a density)
/// and has relative motion in a needed state. Meshes of identical geometry (and C_d) share one
/// K computation. Returns the entries and their meshes.
pub(super) fn compile_pocketing(
    gb: &Gearbox,
    usage: &Usage,
    lists: &mut Lists,
) -> Result<(Vec<PocketEntry>, Vec<usize>), SceneError> {
    let (mut pocket, mut pocket_meshes) = (Vec::new(), Vec::new());
    let mut pocket_built: Vec<(PocketMeshInput, PocketingMesh)> = Vec::new();
    let Some(opt) = &gb.losses.pocketing else {
        lists.skipped.push(Skipped {
            what: "pocketing".into(),
            why: "switched off ([losses] pocketing = \"off\")".into(),
        });
        return Ok((pocket, pocket_meshes));
    };
    for (mi, m) in gb.meshes.iter().enumerate() {
        let feeds = mesh_feeds(gb, mi);
        let known = opt.mixture_density.is_some() || !feeds.is_empty();
        let Some(wet) = pocket_wet_fraction(gb, mi, known, lists) else {
            continue;
        };
        if !usage.any(|u, st| u.speeds[st][m.gear1].relative != 0.0) {
            lists.skipped.push(usage.idle(
                format!("pocketing of mesh {}", m.name),
                "has no relative motion (its gears turn as one)",
            ));
            continue;
        }
        let (g1, g2) = (&gb.gears[m.gear1], &gb.gears[m.gear2]);
        let input = PocketMeshInput::from_gears(&g1.geometry, &g2.geometry, m.geometry.a_w);
        let popts = crate::physics::losses::pocketing::PocketingOptions {
            discharge_coefficient: opt.discharge_coefficient,
            helix_slices: HELIX_POCKET_SLICES,
        };
        let model = match pocket_built
            .iter()
            .find(|(i, pm)| *i == input && pm.discharge_coefficient() == popts.discharge_coefficient)
        {
            Some((_, pm)) => *pm,
            None => {
                let pm = pocketing_mesh(&input, &popts).map_err(|e| SceneError {
                    what: format!("pocketing of mesh {}", m.name),
                    why: e.to_string(),
                })?;
                pocket_built.push((input, pm));
                pm
            }
        };
        pocket.push(PocketEntry {
            item: lists.items.len(),
            model,
            multiplicity: m.multiplicity as f64,
            wet_fraction: wet,
            feeds,
        });
        pocket_meshes.push(mi);
        lists.items.push(LossItem {
            source: Source::Pocketing,
            name: m.name.clone(),
            gears: vec![(m.gear1, 0.5), (m.gear2, 0.5)],
            heat: DefaultHeat::Oil,
            engine_side: false,
        });
    }
    Ok((pocket, pocket_meshes))
}

/// The circuit consumers that deliver oil to mesh `mi`, with the fraction of their flow one
/// instance of the mesh receives: a mesh or jet consumer splits its flow over the mesh's
/// instances (planets), a set consumer over every mesh instance of its set.
pub(super) fn mesh_feeds(gb: &Gearbox, mi: usize) -> Vec<(usize, f64)> {
    let m = &gb.meshes[mi];
    let set_instances = |set: usize| -> f64 {
        gb.meshes
            .iter()
            .filter(|x| x.set == Some(set))
            .map(|x| x.multiplicity as f64)
            .sum()
    };
    gb.circuit
        .consumers
        .iter()
        .enumerate()
        .filter_map(|(c, x)| match x.target {
            Target::Mesh(k) | Target::Jet { mesh: k, .. } if k == mi => {
                Some((c, 1.0 / m.multiplicity as f64))
            }
            Target::Set { set, .. } if m.set == Some(set) => Some((c, 1.0 / set_instances(set))),
            _ => None,
        })
        .collect()
}

/// Most pocket models kept by [`pocketing_mesh`].
const POCKET_MEMO: usize = 64;

/// [`PocketingMesh::with_options`], remembered across compiles: the pocket geometry (most of a
/// compile's time for a model with pocketing) depends only on the mesh's geometry and options,
/// and the cases of a study mostly vary other values. A pure function's results, so a
/// remembered model is the one the computation gives, bit for bit; the last [`POCKET_MEMO`]
/// distinct inputs are kept.
fn pocketing_mesh(
    input: &PocketMeshInput,
    opts: &crate::physics::losses::pocketing::PocketingOptions,
) -> Result<PocketingMesh, crate::physics::losses::pocketing::PocketingError> {
    type Memo = Vec<(
        PocketMeshInput,
        crate::physics::losses::pocketing::PocketingOptions,
        PocketingMesh,
    )>;
    static MEMO: std::sync::Mutex<Memo> = std::sync::Mutex::new(Vec::new());
    let found = {
        let memo = MEMO.lock().unwrap_or_else(|e| e.into_inner());
        memo.iter()
            .find(|(i, o, _)| i == input && o == opts)
            .map(|(_, _, pm)| *pm)
    };
    if let Some(pm) = found {
        return Ok(pm);
    }
    let pm = PocketingMesh::with_options(input, opts)?;
    let mut memo = MEMO.lock().unwrap_or_else(|e| e.into_inner());
    if memo.len() >= POCKET_MEMO {
        memo.remove(0);
    }
    memo.push((*input, *opts, pm));
    Ok(pm)
}

/// Windage: one item per gear that does not reach the oil and turns (relative to the air) in a
/// needed state. Returns the entries and their gears.
pub(super) fn compile_windage(
    gb: &Gearbox,
    usage: &Usage,
    lists: &mut Lists,
) -> Result<(Vec<WindEntry>, Vec<usize>), SceneError> {
    let (mut wind, mut gears) = (Vec::new(), Vec::new());
    let Some(model) = gb.losses.windage else {
        lists.skipped.push(Skipped {
            what: "windage".into(),
            why: "switched off ([losses] windage = \"off\")".into(),
        });
        return Ok((wind, gears));
    };
    let cfg = gb.losses.churning.unwrap_or_default();
    for (gi, g) in gb.gears.iter().enumerate() {
        if g.is_immersed() {
            // Listed, so that its column stays when an override lowers the oil below it.
            lists.skipped.push(Skipped {
                what: format!("windage of gear {}", g.name),
                why: "dips in the oil (its churning is counted)".into(),
            });
            continue;
        }
        // A gear on a member the housing holds never turns (nor does it in any state of the model).
        if (0..gb.gear_states.len()).all(|st| gb.gear_speeds(st)[gi].absolute.abs() < 1e-12) {
            lists.skipped.push(Skipped {
                what: format!("windage of gear {}", g.name),
                why: "never turns (its member is held by the housing)".into(),
            });
            continue;
        }
        let planets = match g.mount {
            GearMount::Planet { set, .. } => gb.planetary_sets[set].planets,
            GearMount::OnMember => 1,
        };
        if !usage.any(|u, st| air_speed(&u.speeds[st][gi], g.mount) != 0.0) {
            lists
                .skipped
                .push(usage.idle(format!("windage of gear {}", g.name), "stands still"));
            continue;
        }
        let model = GearWindage::new(model, &cfg, &churning_gear(gb, gi)).map_err(|e| SceneError {
            what: format!("windage of gear {}", g.name),
            why: e.to_string(),
        })?;
        wind.push(WindEntry {
            item: lists.items.len(),
            model,
            multiplicity: f64::from(planets),
        });
        gears.push(gi);
        lists.items.push(LossItem {
            source: Source::Windage,
            name: g.name.clone(),
            gears: vec![(gi, 1.0)],
            heat: DefaultHeat::Oil,
            engine_side: false,
        });
    }
    Ok((wind, gears))
}

/// Speed of a gear relative to the air around it: a planet's spin (the air in a carrier turns
/// with it), else its absolute speed.
fn air_speed(w: &crate::model::gearbox::GearSpeed, mount: GearMount) -> f64 {
    match mount {
        GearMount::Planet { .. } => w.relative,
        GearMount::OnMember => w.absolute,
    }
}

/// The wet fraction of mesh `mi`'s zone, or `None` when the mesh has no pocketing item (an
/// internal mesh, or a zone wholly above the oil without a density for it: skipped). A zone partly
/// or wholly above the oil without that density is warned about. `has_mixture_density`: the model
/// gives the density of the dry share.
fn pocket_wet_fraction(gb: &Gearbox, mi: usize, has_mixture_density: bool, lists: &mut Lists) -> Option<f64> {
    let m = &gb.meshes[mi];
    if m.geometry.kind == MeshKind::Internal {
        lists.skipped.push(Skipped {
            what: format!("pocketing of mesh {}", m.name),
            why: "internal mesh: the pocket model (seed 004) covers external meshes only".into(),
        });
        return None;
    }
    // (Before the idle check: a mesh above the oil is unknown in every state.) Height of the
    // pitch point; planets orbit, so the mesh point sweeps a circle.
    let (wet, _) = mesh_zone(gb, mi);
    if wet < 1.0 && !has_mixture_density {
        lists.warnings.push(above_oil_warning(&m.name, wet));
        if wet <= 0.0 {
            lists.skipped.push(Skipped {
                what: format!("pocketing of mesh {}", m.name),
                why: "mesh zone entirely above the oil: pumped density unknown (set [losses] pocketing_mixture_density_kg_m3)".into(),
            });
            return None;
        }
    }
    Some(wet)
}

/// Sliding: one item per mesh that carries load with relative motion in a needed state.
/// Returns the entries and their meshes.
pub(super) fn compile_sliding(
    gb: &Gearbox,
    needs: &Needs,
    usage: &Usage,
    lists: &mut Lists,
) -> Result<(Vec<SlideEntry>, Vec<usize>), SceneError> {
    let (mut slide, mut slide_meshes) = (Vec::new(), Vec::new());
    let (opts, schlenk) = match &gb.losses.sliding {
        SlidingChoice::Off => {
            lists.skipped.push(Skipped {
                what: "sliding".into(),
                why: "switched off ([losses] sliding = \"off\")".into(),
            });
            return Ok((slide, slide_meshes));
        }
        SlidingChoice::Detailed(o) => (*o, None),
        SlidingChoice::Iso14179(s, split) => (
            crate::physics::losses::sliding::SlidingOptions {
                heat_to_gear1: *split,
                ..Default::default()
            },
            Some(*s),
        ),
    };
    for (mi, m) in gb.meshes.iter().enumerate() {
        let loaded = |u: &Usage, st: usize| {
            u.torques[st][mi] != 0.0
                && (u.speeds[st][m.gear1].relative != 0.0 || u.speeds[st][m.gear2].relative != 0.0)
        };
        if !usage.any(loaded) {
            lists.skipped.push(usage.idle(
                format!("sliding of mesh {}", m.name),
                "carries no load or has no relative motion",
            ));
            continue;
        }
        let sm =
            super::sliding_memo::sliding_mesh(&sliding_input(gb, mi), &opts).map_err(|e| SceneError {
                what: format!("sliding of mesh {}", m.name),
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
            item: lists.items.len(),
            model,
            multiplicity: m.multiplicity as f64,
            law: if needs.evaluate_all { None } else { law },
        });
        slide_meshes.push(mi);
        let f1 = opts.heat_to_gear1;
        lists.items.push(LossItem {
            source: Source::Sliding,
            name: m.name.clone(),
            gears: vec![(m.gear1, f1), (m.gear2, 1.0 - f1)],
            heat: DefaultHeat::Gears,
            engine_side: false,
        });
    }
    Ok((slide, slide_meshes))
}

/// The sliding model's input for mesh `mi`: its contact geometry and the flanks' roughness.
fn sliding_input(gb: &Gearbox, mi: usize) -> SlidingMeshInput {
    let m = &gb.meshes[mi];
    let geo = &m.geometry;
    let (g1, g2) = (&gb.gears[m.gear1], &gb.gears[m.gear2]);
    SlidingMeshInput {
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
    }
}

/// The compiled gear and mesh entries, for their per-state factors.
pub(super) struct Compiled<'a> {
    pub(super) churn_gears: &'a [usize],
    pub(super) pocket_meshes: &'a [usize],
    pub(super) slide_meshes: &'a [usize],
    pub(super) slide: &'a [SlideEntry],
    pub(super) wind_gears: &'a [usize],
}

impl Compiled<'_> {
    /// Kinematic factors of the compiled entries in gear state `si`, and the sliding losses of
    /// the separable laws per power-flow direction (unit torque, speed and viscosity).
    pub(super) fn state_factors(&self, gb: &Gearbox, usage: &Usage, si: usize) -> StateFactors {
        let (speeds, torques) = (&usage.speeds[si], &usage.torques[si]);
        let mut f = StateFactors {
            churn_speed: self
                .churn_gears
                .iter()
                .map(|&gi| speeds[gi].absolute.abs())
                .collect(),
            pocket_speed: self
                .pocket_meshes
                .iter()
                .map(|&mi| speeds[gb.meshes[mi].gear1].relative)
                .collect(),
            slide: self
                .slide_meshes
                .iter()
                .map(|&mi| {
                    let m = &gb.meshes[mi];
                    [torques[mi], speeds[m.gear1].relative, speeds[m.gear2].relative]
                })
                .collect(),
            wind_speed: self
                .wind_gears
                .iter()
                .map(|&gi| air_speed(&speeds[gi], gb.gears[gi].mount).abs())
                .collect(),
            slide_unit: Vec::new(),
        };
        f.slide_unit = self
            .slide
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
    }
}

/// The churning entries with the terms of their laws per gear state.
pub(super) fn with_ratio_terms(mut churn: Vec<ChurnEntry>, states: &[StateFactors]) -> Vec<ChurnEntry> {
    for (j, e) in churn.iter_mut().enumerate() {
        if let Some(law) = &e.law {
            e.ratio_terms = states.iter().map(|f| law.ratio_terms(f.churn_speed[j])).collect();
        }
    }
    churn
}

/// Sliding loss of one entry (W, multiplicity included) with state factors `f`, input
/// torque `torque` (N·m), input speed `w_in` (rad/s), oil viscosity `mu` (Pa·s), density `rho`.
pub(super) fn sliding(e: &SlideEntry, f: &[f64; 3], torque: f64, w_in: f64, mu: f64, rho: f64) -> f64 {
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
