//! `[losses]` → [`LossModels`]: model choices (each an enum, read once with the file) and
//! coefficients, each checked with its key path.

use serde::{Deserialize, Serialize};

use crate::model::choice::choice;
use crate::model::problems::Problems;
use crate::model::source::Source;
use crate::physics::losses::churning::{
    changenet::{ChangenetJoin, ChangenetParams},
    seetharaman::CavityTerm,
    ChurningConfig, ChurningModel,
};
use crate::physics::losses::sliding::friction::{
    BenedictKelley, ContactLineLoad, FrictionLaw, IsoTc60, Schlenk,
};
use crate::physics::losses::sliding::helical::HelicalDistribution;
use crate::physics::losses::sliding::load_sharing::LoadSharing;
use crate::physics::losses::sliding::moment_balance::LossForm;
use crate::physics::losses::sliding::SlidingOptions;

/// `churning`: the churning model (docs/physics.md §5).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ChurningChoice {
    /// Changenet–Velex (the only one fitted to measurements; needs `lubrication.sump_volume_l`).
    #[default]
    Changenet,
    /// Seetharaman–Kahraman.
    Seetharaman,
    /// Stavytskyi.
    Stavytskyi,
    /// No churning loss.
    Off,
}
choice!(ChurningChoice {
    Changenet = "changenet",
    Seetharaman = "seetharaman",
    Stavytskyi = "stavytskyi",
    Off = "off",
});

/// `changenet_join`: how the two Changenet–Velex laws are joined (docs/physics.md §5).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ChangenetJoinChoice {
    /// The log-linear bridge between the regimes (default).
    #[default]
    Bridge,
    /// Where the two laws cross (the smaller of the two).
    Crossing,
}
choice!(ChangenetJoinChoice {
    Bridge = "bridge",
    Crossing = "crossing",
});

/// `windage`: the drag of gears that run above the oil, in air (docs/physics.md §14).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum WindageChoice {
    /// Seetharaman–Kahraman's drag terms (faces, periphery, tooth cavities) on a gear wholly in
    /// air.
    #[default]
    Seetharaman,
    /// Stavytskyi et al.'s model with the gear wholly immersed, in air.
    Stavytskyi,
    /// No windage loss.
    Off,
}
choice!(WindageChoice {
    Seetharaman = "seetharaman",
    Stavytskyi = "stavytskyi",
    Off = "off",
});

/// `pocketing`: pocketing of external meshes (docs/physics.md §6) on or off.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum PocketingChoice {
    /// Counted.
    #[default]
    On,
    /// Not counted.
    Off,
}
choice!(PocketingChoice {
    On = "on",
    Off = "off",
});

/// `sliding`: the sliding-loss model.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SlidingModelChoice {
    /// Contact-path model (load sharing, local friction law, helical line-load distribution).
    #[default]
    Detailed,
    /// ISO/TR 14179-2 closed form `P_in μ_mz H_V`.
    Iso14179,
    /// No sliding loss.
    Off,
}
choice!(SlidingModelChoice {
    Detailed = "detailed",
    Iso14179 = "iso14179",
    Off = "off",
});

/// `friction`: the friction law of the detailed sliding model.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum FrictionChoice {
    /// ISO TC60.
    IsoTc60,
    /// Benedict–Kelley.
    BenedictKelley,
    /// Schlenk (the default: docs/validation.md, "Defaults").
    #[default]
    Schlenk,
    /// A constant μ (`friction_coefficient`).
    Constant,
}
choice!(FrictionChoice {
    IsoTc60 = "iso_tc60",
    BenedictKelley = "benedict_kelley",
    Schlenk = "schlenk",
    Constant = "constant",
});

/// `contact_line_load`: the load per length in Schlenk's μ.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ContactLineLoadChoice {
    /// F_bn/l_min, the FZG group's form with which their oils' X_L were fitted (the default:
    /// docs/validation.md, "Contact-line load").
    #[default]
    ContactLine,
    /// F_bt/b, ISO/TR 14179-2.
    FaceWidth,
}
choice!(ContactLineLoadChoice {
    ContactLine = "contact_line",
    FaceWidth = "face_width",
});

/// `load_sharing`: load sharing of spur meshes in double contact.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum LoadSharingChoice {
    /// 50:50.
    #[default]
    Uniform,
    /// 1/3 : 2/3.
    Share33_67,
    /// 0.45 : 0.55.
    Share45_55,
    /// Linear ramp.
    Ramp,
}
choice!(LoadSharingChoice {
    Uniform = "uniform",
    Share33_67 = "33:67",
    Share45_55 = "45:55",
    Ramp = "ramp",
});

/// `helical_distribution`: line load along the contact lines of helical meshes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum HelicalDistributionChoice {
    /// Niemann–Richer.
    NiemannRicher,
    /// Constant load per unit line length (the default: docs/validation.md, "Defaults").
    #[default]
    Uniform,
}
choice!(HelicalDistributionChoice {
    NiemannRicher = "niemann_richer",
    Uniform = "uniform",
});

/// `loss_form`: how the friction power of a contact element is formed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum LossFormChoice {
    /// μ·F·v_g.
    #[default]
    FirstOrder,
    /// Seed 003's moment-balance ratio.
    MomentBalance,
}
choice!(LossFormChoice {
    FirstOrder = "first_order",
    MomentBalance = "moment_balance",
});

/// `seetharaman_cavity`: the tooth-cavity term of the Seetharaman–Kahraman model.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum CavityChoice {
    /// Lid-driven Stokes cavity.
    #[default]
    Stokes,
    /// Form drag of the immersed teeth (C_D = 1).
    FormDrag,
    /// No cavity term.
    None,
}
choice!(CavityChoice {
    Stokes = "stokes",
    FormDrag = "form_drag",
    None = "none",
});

/// `[losses]` as written: which loss models to use and their coefficients (defaults in
/// docs/model-file.md).
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LossesSpec {
    /// Churning model (default `changenet`).
    #[serde(default)]
    pub churning: Option<ChurningChoice>,
    /// Pocketing (default `on`).
    #[serde(default)]
    pub pocketing: Option<PocketingChoice>,
    /// Windage of gears above the oil (default `seetharaman`).
    #[serde(default)]
    pub windage: Option<WindageChoice>,
    /// Sliding model (default `detailed`).
    #[serde(default)]
    pub sliding: Option<SlidingModelChoice>,
    /// Friction law of the detailed sliding model (default `schlenk`).
    #[serde(default)]
    pub friction: Option<FrictionChoice>,
    /// μ for `friction = "constant"`.
    #[serde(default)]
    pub friction_coefficient: Option<f64>,
    /// Lubricant factor X_L of the Schlenk / ISO/TR 14179-2 law (default: the oil's).
    #[serde(default)]
    pub lubricant_factor: Option<f64>,
    /// Load per length in Schlenk's μ (default `contact_line`).
    #[serde(default)]
    pub contact_line_load: Option<ContactLineLoadChoice>,
    /// Spur load sharing (default `uniform`).
    #[serde(default)]
    pub load_sharing: Option<LoadSharingChoice>,
    /// Line-load distribution of helical meshes (default `uniform`).
    #[serde(default)]
    pub helical_distribution: Option<HelicalDistributionChoice>,
    /// Loss form (default `first_order`).
    #[serde(default)]
    pub loss_form: Option<LossFormChoice>,
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
    /// Seetharaman–Kahraman tooth-cavity term (default `stokes`).
    #[serde(default)]
    pub seetharaman_cavity: Option<CavityChoice>,
    /// Stavytskyi: edge coefficient k_s (0.85 sharp, 0.9 deburred).
    #[serde(default)]
    pub stavytskyi_ks: Option<f64>,
    /// Changenet–Velex low-Re law [factor, exp(h/D), exp(V0/D³), exp(Fr), exp(Re)] \[recalled\].
    #[serde(default)]
    pub changenet_low: Option<[f64; 5]>,
    /// Changenet–Velex high-Re law [factor, exp(h/D), exp(V0/D³), exp(Fr), exp(b/D)] \[recalled\].
    #[serde(default)]
    pub changenet_high: Option<[f64; 5]>,
    /// How the two Changenet–Velex laws are joined (default `bridge`).
    #[serde(default)]
    pub changenet_join: Option<ChangenetJoinChoice>,
    /// Loss multipliers: a source (`churning = 1.3`) or one item (`"bearing:hss_a" = 0.8`).
    #[serde(default)]
    pub multiplier: Option<std::collections::BTreeMap<String, f64>>,
}

impl ContactLineLoadChoice {
    /// The load per length.
    pub fn load(self) -> ContactLineLoad {
        match self {
            ContactLineLoadChoice::ContactLine => ContactLineLoad::ContactLine,
            ContactLineLoadChoice::FaceWidth => ContactLineLoad::FaceWidth,
        }
    }
}

impl LoadSharingChoice {
    /// The load-sharing model.
    pub fn law(self) -> LoadSharing {
        match self {
            LoadSharingChoice::Uniform => LoadSharing::Uniform,
            LoadSharingChoice::Share33_67 => LoadSharing::Share33_67,
            LoadSharingChoice::Share45_55 => LoadSharing::Share45_55,
            LoadSharingChoice::Ramp => LoadSharing::Ramp,
        }
    }
}

impl HelicalDistributionChoice {
    /// The line-load distribution (Niemann–Richer with its default coefficient).
    pub fn law(self) -> HelicalDistribution {
        match self {
            HelicalDistributionChoice::NiemannRicher => HelicalDistribution::default(),
            HelicalDistributionChoice::Uniform => HelicalDistribution::Uniform,
        }
    }
}

impl LossFormChoice {
    /// The loss form.
    pub fn law(self) -> LossForm {
        match self {
            LossFormChoice::FirstOrder => LossForm::FirstOrder,
            LossFormChoice::MomentBalance => LossForm::MomentBalance,
        }
    }
}

impl CavityChoice {
    /// The cavity term (form drag with C_D = 1).
    pub fn term(self) -> CavityTerm {
        match self {
            CavityChoice::Stokes => CavityTerm::default(),
            CavityChoice::FormDrag => CavityTerm::FormDrag {
                drag_coefficient: 1.0,
            },
            CavityChoice::None => CavityTerm::None,
        }
    }
}

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
    /// Windage of gears above the oil (None: off).
    pub windage: Option<ChurningModel>,
    /// Loss multipliers `[losses] multiplier`: (source, None) for a source, (source, Some(item))
    /// for one item; each multiplies the item's loss (default 1).
    pub multipliers: Vec<(Source, Option<String>, f64)>,
}

/// Default discharge coefficient of pocketing (physics.md §6: 0.6–0.7).
pub const DEFAULT_DISCHARGE_COEFFICIENT: f64 = 0.65;

/// Resolve and check `[losses]`. `sump_volume_l` feeds the Changenet–Velex model;
/// `oil_lubricant_factor` is the oil's X_L (its measured value, else its base's), the default of
/// `lubricant_factor`.
pub fn validate_losses(
    l: &LossesSpec,
    sump_volume_l: Option<f64>,
    oil_lubricant_factor: f64,
    problems: &mut Problems,
) -> Option<LossModels> {
    let start = problems.len();
    let churning = churning(l, sump_volume_l, problems);
    let pocketing = pocketing(l, problems);
    let sliding = sliding(l, oil_lubricant_factor, problems);
    let multipliers = multipliers(l, problems);
    if problems.len() > start {
        return None;
    }
    let windage = match l.windage.unwrap_or_default() {
        WindageChoice::Seetharaman => Some(ChurningModel::Seetharaman),
        WindageChoice::Stavytskyi => Some(ChurningModel::Stavytskyi),
        WindageChoice::Off => None,
    };
    Some(LossModels {
        churning,
        pocketing,
        sliding,
        windage,
        multipliers,
    })
}

/// Largest loss multiplier.
pub const MAX_MULTIPLIER: f64 = 100.0;

/// `[losses] multiplier = { SOURCE = m, "SOURCE:ITEM" = m }`: each m in (0, 100]; the item
/// names are checked when the scene is compiled (they depend on what reaches the oil).
fn multipliers(l: &LossesSpec, problems: &mut Problems) -> Vec<(Source, Option<String>, f64)> {
    let mut out = Vec::new();
    for (key, &m) in l.multiplier.iter().flatten() {
        let path = format!("losses.multiplier.\"{key}\"");
        let (src, item) = match key.split_once(':') {
            Some((s, i)) => (s, Some(i.to_string())),
            None => (key.as_str(), None),
        };
        let Some(source) = Source::parse(src) else {
            problems.push(
                path,
                key,
                format!("must name a source ({}) or SOURCE:ITEM", Source::names()),
            );
            continue;
        };
        if !(m.is_finite() && m > 0.0 && m <= MAX_MULTIPLIER) {
            problems.push(path, m, format!("must lie in (0, {MAX_MULTIPLIER}]"));
            continue;
        }
        out.push((source, item, m));
    }
    out
}

/// The churning model with its coefficients (None: churning off).
pub(super) fn churning(
    l: &LossesSpec,
    sump_volume_l: Option<f64>,
    problems: &mut Problems,
) -> Option<ChurningConfig> {
    let model = l.churning.unwrap_or_default();
    let mut cfg = ChurningConfig::default();
    if let Some(re) = l.seetharaman_transition_reynolds {
        if problems.in_range("losses.seetharaman_transition_reynolds", re, 1e3, 1e8, "") {
            cfg.seetharaman.transition_reynolds = re;
        }
    }
    cfg.seetharaman.cavity = l.seetharaman_cavity.unwrap_or_default().term();
    if let Some(ks) = l.stavytskyi_ks {
        if problems.in_range("losses.stavytskyi_ks", ks, 0.1, 1.0, "") {
            cfg.stavytskyi.k_s = ks;
        }
    }
    for (key, arr, target) in [
        ("losses.changenet_low", l.changenet_low, &mut cfg.changenet.low),
        ("losses.changenet_high", l.changenet_high, &mut cfg.changenet.high),
    ] {
        if let Some(a) = arr {
            if a.iter().all(|v| v.is_finite()) && a[0] > 0.0 {
                *target = a;
            } else {
                problems.push(
                    key,
                    format!("{a:?}"),
                    "five finite numbers with a positive factor first",
                );
            }
        }
    }
    cfg.changenet.join = match l.changenet_join.unwrap_or_default() {
        ChangenetJoinChoice::Bridge => ChangenetJoin::Bridge,
        ChangenetJoinChoice::Crossing => ChangenetJoin::Crossing,
    };
    if let Some(v) = sump_volume_l {
        cfg.changenet.sump_oil_volume = v * 1e-3;
    } else if model == ChurningChoice::Changenet {
        cfg.changenet.sump_oil_volume = ChangenetParams::default().sump_oil_volume;
        problems.push(
            "lubrication.sump_volume_l",
            "",
            "required by the Changenet–Velex churning model (or choose losses.churning = \"seetharaman\")",
        );
    }
    cfg.model = match model {
        ChurningChoice::Changenet => ChurningModel::Changenet,
        ChurningChoice::Seetharaman => ChurningModel::Seetharaman,
        ChurningChoice::Stavytskyi => ChurningModel::Stavytskyi,
        ChurningChoice::Off => return None,
    };
    Some(cfg)
}

/// Pocketing options (None: pocketing off).
fn pocketing(l: &LossesSpec, problems: &mut Problems) -> Option<PocketingOptions> {
    match l.pocketing.unwrap_or_default() {
        PocketingChoice::Off => None,
        PocketingChoice::On => {
            let cd = l
                .pocketing_discharge_coefficient
                .unwrap_or(DEFAULT_DISCHARGE_COEFFICIENT);
            problems.in_range("losses.pocketing_discharge_coefficient", cd, 0.1, 1.0, "");
            // No default: the density a mesh above the oil pumps has no source.
            let rho = l.pocketing_mixture_density_kg_m3;
            if let Some(r) = rho {
                problems.in_range("losses.pocketing_mixture_density_kg_m3", r, 0.0, 1000.0, " kg/m3");
            }
            Some(PocketingOptions {
                discharge_coefficient: cd,
                mixture_density: rho,
            })
        }
    }
}

/// The sliding model with its friction law and options.
pub(super) fn sliding(l: &LossesSpec, oil_lubricant_factor: f64, problems: &mut Problems) -> SlidingChoice {
    let xl = l.lubricant_factor.unwrap_or(oil_lubricant_factor);
    problems.in_range("losses.lubricant_factor", xl, 0.3, 2.0, "");
    let schlenk = Schlenk {
        x_l: xl,
        line_load: l.contact_line_load.unwrap_or_default().load(),
        ..Schlenk::default()
    };
    let friction = friction(l, schlenk, problems);
    let mut opts = SlidingOptions {
        friction,
        load_sharing: l.load_sharing.unwrap_or_default().law(),
        helical_distribution: l.helical_distribution.unwrap_or_default().law(),
        loss_form: l.loss_form.unwrap_or_default().law(),
        slices: 50,
        helical_time_samples: 8,
        ..SlidingOptions::default()
    };
    if let Some(n) = l.helical_slices {
        if (4..=1000).contains(&n) {
            opts.slices = n as usize;
        } else {
            problems.push("losses.helical_slices", n, "must be an integer in [4, 1000]");
        }
    }
    if let Some(n) = l.helical_time_samples {
        if (2..=1000).contains(&n) {
            opts.helical_time_samples = n as usize;
        } else {
            problems.push(
                "losses.helical_time_samples",
                n,
                "must be an integer in [2, 1000]",
            );
        }
    }
    if let Some(f) = l.sliding_heat_to_gear1 {
        if problems.in_range("losses.sliding_heat_to_gear1", f, 0.0, 1.0, "") {
            opts.heat_to_gear1 = f;
        }
    }
    match l.sliding.unwrap_or_default() {
        SlidingModelChoice::Detailed => SlidingChoice::Detailed(opts),
        SlidingModelChoice::Iso14179 => SlidingChoice::Iso14179(schlenk, opts.heat_to_gear1),
        SlidingModelChoice::Off => SlidingChoice::Off,
    }
}

/// The friction law of the detailed model (`schlenk`: with the file's lubricant factor).
fn friction(l: &LossesSpec, schlenk: Schlenk, problems: &mut Problems) -> FrictionLaw {
    match l.friction.unwrap_or_default() {
        FrictionChoice::IsoTc60 => FrictionLaw::IsoTc60(IsoTc60::default()),
        FrictionChoice::BenedictKelley => FrictionLaw::BenedictKelley(BenedictKelley::default()),
        FrictionChoice::Schlenk => FrictionLaw::Schlenk(schlenk),
        FrictionChoice::Constant => match l.friction_coefficient {
            Some(mu) if problems.in_range("losses.friction_coefficient", mu, 0.0, 0.5, "") => {
                FrictionLaw::Constant(mu)
            }
            Some(_) => FrictionLaw::Constant(0.0),
            None => {
                problems.push(
                    "losses.friction_coefficient",
                    "",
                    "required when losses.friction = \"constant\"",
                );
                FrictionLaw::Constant(0.0)
            }
        },
    }
}
