//! `[losses]` → [`LossModels`]: model choices and coefficients, each checked with its key path.

use serde::{Deserialize, Serialize};

use crate::model::problems::Problems;
use crate::physics::losses::churning::{
    changenet::ChangenetParams, seetharaman::CavityTerm, ChurningConfig, ChurningModel,
};
use crate::physics::losses::sliding::friction::{BenedictKelley, FrictionLaw, IsoTc60, Schlenk};
use crate::physics::losses::sliding::helical::HelicalDistribution;
use crate::physics::losses::sliding::load_sharing::LoadSharing;
use crate::physics::losses::sliding::moment_balance::LossForm;
use crate::physics::losses::sliding::SlidingOptions;

/// `[losses]` as written: which loss models to use and their coefficients (defaults in docs/model-file.md).
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
    /// Lubricant factor X_L of the Schlenk / ISO/TR 14179-2 law (1.0 mineral, 0.8 PAO, ...).
    #[serde(default)]
    pub lubricant_factor: Option<f64>,
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
    /// Changenet–Velex low-Re law [factor, exp(h/D), exp(V0/D³), exp(Fr), exp(Re)] [recalled].
    #[serde(default)]
    pub changenet_low: Option<[f64; 5]>,
    /// Changenet–Velex high-Re law [factor, exp(h/D), exp(V0/D³), exp(Fr), exp(b/D)] [recalled].
    #[serde(default)]
    pub changenet_high: Option<[f64; 5]>,
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
}

/// Default friction law of the detailed sliding model (docs/validation.md, "Defaults").
pub const DEFAULT_FRICTION: &str = "schlenk";
/// Default line-load distribution of helical meshes (docs/validation.md, "Defaults").
pub const DEFAULT_HELICAL_DISTRIBUTION: &str = "uniform";

/// Default discharge coefficient of pocketing (physics.md §6: 0.6–0.7).
pub const DEFAULT_DISCHARGE_COEFFICIENT: f64 = 0.65;

fn choice<'a>(
    problems: &mut Problems,
    path: &str,
    v: &'a Option<String>,
    allowed: &[&'a str],
    default: &'a str,
) -> Option<&'a str> {
    match v.as_deref() {
        None => Some(default),
        Some(x) if allowed.contains(&x) => Some(x),
        Some(x) => {
            problems.push(
                path,
                format!("\"{x}\""),
                format!("must be one of: {}", allowed.join(", ")),
            );
            None
        }
    }
}

/// Resolve and check `[losses]`. `sump_volume_l` feeds the Changenet–Velex model.
pub fn validate_losses(
    l: &LossesSpec,
    sump_volume_l: Option<f64>,
    problems: &mut Problems,
) -> Option<LossModels> {
    let start = problems.len();
    // Churning.
    let churning_model = choice(
        problems,
        "losses.churning",
        &l.churning,
        &["changenet", "seetharaman", "stavytskyi", "off"],
        "changenet",
    );
    let mut cfg = ChurningConfig::default();
    if let Some(re) = l.seetharaman_transition_reynolds {
        if problems.in_range("losses.seetharaman_transition_reynolds", re, 1e3, 1e8, "") {
            cfg.seetharaman.transition_reynolds = re;
        }
    }
    match choice(
        problems,
        "losses.seetharaman_cavity",
        &l.seetharaman_cavity,
        &["stokes", "form_drag", "none"],
        "stokes",
    ) {
        Some("form_drag") => {
            cfg.seetharaman.cavity = CavityTerm::FormDrag {
                drag_coefficient: 1.0,
            }
        }
        Some("none") => cfg.seetharaman.cavity = CavityTerm::None,
        _ => {}
    }
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
    if let Some(v) = sump_volume_l {
        cfg.changenet.sump_oil_volume = v * 1e-3;
    } else if churning_model == Some("changenet") {
        cfg.changenet.sump_oil_volume = ChangenetParams::default().sump_oil_volume;
    }
    let churning = match churning_model {
        Some("off") | None => None,
        Some(m) => {
            cfg.model = match m {
                "seetharaman" => ChurningModel::Seetharaman,
                "stavytskyi" => ChurningModel::Stavytskyi,
                _ => ChurningModel::Changenet,
            };
            Some(cfg)
        }
    };
    if churning_model == Some("changenet") && sump_volume_l.is_none() {
        problems.push(
            "lubrication.sump_volume_l",
            "",
            "required by the Changenet–Velex churning model (or choose losses.churning = \"seetharaman\")",
        );
    }

    // Pocketing.
    let pocketing = match choice(problems, "losses.pocketing", &l.pocketing, &["on", "off"], "on") {
        Some("on") => {
            let cd = l
                .pocketing_discharge_coefficient
                .unwrap_or(DEFAULT_DISCHARGE_COEFFICIENT);
            problems.in_range("losses.pocketing_discharge_coefficient", cd, 0.1, 1.0, "");
            // No default: the density a mesh above the oil pumps has no source (issue 14).
            let rho = l.pocketing_mixture_density_kg_m3;
            if let Some(r) = rho {
                problems.in_range("losses.pocketing_mixture_density_kg_m3", r, 0.0, 1000.0, " kg/m3");
            }
            Some(PocketingOptions {
                discharge_coefficient: cd,
                mixture_density: rho,
            })
        }
        _ => None,
    };

    // Sliding.
    let xl = l.lubricant_factor.unwrap_or(1.0);
    problems.in_range("losses.lubricant_factor", xl, 0.3, 2.0, "");
    let schlenk = Schlenk {
        x_l: xl,
        ..Schlenk::default()
    };
    let friction = match choice(
        problems,
        "losses.friction",
        &l.friction,
        &["iso_tc60", "benedict_kelley", "schlenk", "constant"],
        // Chosen by the evidence (docs/validation.md, "Defaults"): within 0.1–3 % of GEARpie on
        // the held-out FZG pairs, where ISO TC60 is 1.5–1.9× higher.
        DEFAULT_FRICTION,
    ) {
        Some("benedict_kelley") => FrictionLaw::BenedictKelley(BenedictKelley::default()),
        Some("schlenk") => FrictionLaw::Schlenk(schlenk),
        Some("constant") => match l.friction_coefficient {
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
        _ => FrictionLaw::IsoTc60(IsoTc60::default()),
    };
    let load_sharing = match choice(
        problems,
        "losses.load_sharing",
        &l.load_sharing,
        &["uniform", "33:67", "45:55", "ramp"],
        "uniform",
    ) {
        Some("33:67") => LoadSharing::Share33_67,
        Some("45:55") => LoadSharing::Share45_55,
        Some("ramp") => LoadSharing::Ramp,
        _ => LoadSharing::Uniform,
    };
    let helical_distribution = match choice(
        problems,
        "losses.helical_distribution",
        &l.helical_distribution,
        &["niemann_richer", "uniform"],
        DEFAULT_HELICAL_DISTRIBUTION,
    ) {
        Some("niemann_richer") => HelicalDistribution::default(),
        _ => HelicalDistribution::Uniform,
    };
    let loss_form = match choice(
        problems,
        "losses.loss_form",
        &l.loss_form,
        &["first_order", "moment_balance"],
        "first_order",
    ) {
        Some("moment_balance") => LossForm::MomentBalance,
        _ => LossForm::FirstOrder,
    };
    let mut opts = SlidingOptions {
        friction,
        load_sharing,
        helical_distribution,
        loss_form,
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
    let sliding = match choice(
        problems,
        "losses.sliding",
        &l.sliding,
        &["detailed", "iso14179", "off"],
        "detailed",
    ) {
        Some("iso14179") => SlidingChoice::Iso14179(schlenk, opts.heat_to_gear1),
        Some("off") => SlidingChoice::Off,
        _ => SlidingChoice::Detailed(opts),
    };
    if problems.len() > start {
        return None;
    }
    Some(LossModels {
        churning,
        pocketing,
        sliding,
    })
}
