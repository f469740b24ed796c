//! The model-form alternatives of `[losses]`: every churning model, windage model and sliding
//! model / friction law, each resolved by the checks of the choice written in the file
//! ([`super::losses`]) on a copy of the section with only that choice changed.

use crate::model::alternative::Alternative;
use crate::model::choice::Choice;
use crate::model::problems::Problems;
use crate::physics::losses::churning::{ChurningConfig, ChurningModel};

use super::losses::{
    ChurningChoice, FrictionChoice, LossesSpec, SlidingChoice, SlidingModelChoice, WindageChoice,
};

/// The alternatives of each gear-loss source (empty for a source switched off).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LossAlternatives {
    /// Churning models (Changenet–Velex, Seetharaman–Kahraman, Stavytskyi).
    pub churning: Vec<Alternative<ChurningConfig>>,
    /// Windage models.
    pub windage: Vec<Alternative<ChurningModel>>,
    /// Sliding: the detailed model with each friction law, and the ISO/TR 14179-2 closed form.
    pub sliding: Vec<Alternative<SlidingChoice>>,
}

/// The alternatives of `l` (the section as written; `sump_volume_l` and `oil_lubricant_factor`
/// as [`super::losses::validate_losses`] takes them).
pub fn alternatives(
    l: &LossesSpec,
    sump_volume_l: Option<f64>,
    oil_lubricant_factor: f64,
) -> LossAlternatives {
    LossAlternatives {
        churning: churning(l, sump_volume_l),
        windage: windage(l),
        sliding: sliding(l, oil_lubricant_factor),
    }
}

fn churning(l: &LossesSpec, sump_volume_l: Option<f64>) -> Vec<Alternative<ChurningConfig>> {
    let chosen = l.churning.unwrap_or_default();
    if chosen == ChurningChoice::Off {
        return Vec::new();
    }
    [
        ChurningChoice::Changenet,
        ChurningChoice::Seetharaman,
        ChurningChoice::Stavytskyi,
    ]
    .into_iter()
    .map(|c| {
        let spec = LossesSpec {
            churning: Some(c),
            ..l.clone()
        };
        let mut problems = Problems::default();
        let found = super::losses::churning(&spec, sump_volume_l, &mut problems);
        Alternative::checked(c.name(), c == chosen, found, problems)
    })
    .collect()
}

fn windage(l: &LossesSpec) -> Vec<Alternative<ChurningModel>> {
    let chosen = l.windage.unwrap_or_default();
    if chosen == WindageChoice::Off {
        return Vec::new();
    }
    [
        (WindageChoice::Seetharaman, ChurningModel::Seetharaman),
        (WindageChoice::Stavytskyi, ChurningModel::Stavytskyi),
    ]
    .into_iter()
    .map(|(c, m)| Alternative {
        choice: c.name(),
        default: c == chosen,
        model: Ok(m),
    })
    .collect()
}

/// The sliding alternatives: `detailed` with each friction law (named by the law); the closed
/// form (`iso14179`) when it is the file's choice (it is a sliding model, not a friction law).
fn sliding(l: &LossesSpec, oil_lubricant_factor: f64) -> Vec<Alternative<SlidingChoice>> {
    let model = l.sliding.unwrap_or_default();
    if model == SlidingModelChoice::Off {
        return Vec::new();
    }
    let law = l.friction.unwrap_or_default();
    let detailed = [
        FrictionChoice::Schlenk,
        FrictionChoice::IsoTc60,
        FrictionChoice::BenedictKelley,
        FrictionChoice::Constant,
    ]
    .into_iter()
    .map(|f| {
        let chosen = model == SlidingModelChoice::Detailed && f == law;
        (f.name(), chosen, SlidingModelChoice::Detailed, Some(f))
    });
    let closed = (model == SlidingModelChoice::Iso14179).then_some((
        SlidingModelChoice::Iso14179.name(),
        true,
        SlidingModelChoice::Iso14179,
        None,
    ));
    detailed
        .chain(closed)
        .map(|(name, chosen, m, f)| {
            let spec = LossesSpec {
                sliding: Some(m),
                friction: f.or(l.friction),
                ..l.clone()
            };
            let mut problems = Problems::default();
            let found = super::losses::sliding(&spec, oil_lubricant_factor, &mut problems);
            Alternative::checked(name, chosen, Some(found), problems)
        })
        .collect()
}
