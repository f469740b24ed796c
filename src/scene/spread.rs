//! Model-form spread, compiled: for every loss item, each model choice of its source that the
//! model's data allow (churning models, windage models, sliding model and friction laws,
//! bearing models and SKF drag editions, seal laws), as a loss scene of its own.
//!
//! Compiled only when a job asks for it ([`SpreadScene::compile`]): the default scene and the
//! right-hand side of a run are untouched. Each alternative is the model with that one choice
//! changed (the other gear-loss sources switched off, which no item of the source depends on),
//! compiled with the same [`Needs`]; its items are matched to the default's by source and name.
//! Every value carries the item's `[losses] multiplier`, as the default's does.
//! Evaluation: [`super::spread_eval`].

use crate::model::alternative::Alternative;
use crate::model::gearbox::{Gearbox, SlidingChoice};
use crate::physics::losses::seals::SealLaw;

use super::items::Source;
use super::losses::{LossScene, Needs};

/// How one model choice gives one loss item of the default scene.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Slot {
    /// Not an item of the choice's source.
    Other,
    /// The item's own model (the default's value).
    Default,
    /// Item `k` of the choice's scene.
    Item(usize),
    /// Not applicable to this item: why.
    NotApplicable(String),
}

/// One model choice of one source.
#[derive(Debug, Clone)]
pub(super) struct SpreadModel {
    pub(super) source: Source,
    /// The choice's name as the model file writes it.
    pub(super) choice: &'static str,
    /// Its scene (None when it is the default for every item, or applies to none).
    pub(super) scene: Option<LossScene>,
    /// Per item of the default scene.
    pub(super) slots: Vec<Slot>,
}

/// Every applicable model choice of every loss item's source.
#[derive(Debug, Clone)]
pub struct SpreadScene {
    pub(super) models: Vec<SpreadModel>,
}

/// The label of a model choice in messages (`changenet` → `Changenet–Velex`).
pub fn label(choice: &str) -> &'static str {
    match choice {
        "changenet" => "Changenet–Velex",
        "seetharaman" => "Seetharaman–Kahraman",
        "stavytskyi" => "Stavytskyi",
        "schlenk" => "Schlenk",
        "iso_tc60" => "ISO TC60",
        "benedict_kelley" => "Benedict–Kelley",
        "constant" => "constant μ",
        "iso14179" => "ISO/TR 14179-2",
        "skf_current" => "SKF (current drag)",
        "skf_older" => "SKF (older drag)",
        "palmgren" => "Palmgren",
        "given_torque" => "given torque",
        _ => "the source's only model",
    }
}

/// The bearing choices, in output order.
const BEARING_CHOICES: [&str; 3] = ["skf_current", "skf_older", "palmgren"];

impl SpreadScene {
    /// The alternatives of `gb`, compiled for `needs`, matched to the items of `default` (the
    /// scene compiled from `gb` with the same `needs`).
    pub fn compile(gb: &Gearbox, needs: &Needs, default: &LossScene) -> SpreadScene {
        let alt = &gb.loss_alternatives;
        let mut models = Vec::new();
        for a in &alt.churning {
            models.push(choice(gb, needs, default, Source::Churning, a, |g, c| {
                g.losses.churning = Some(*c)
            }));
        }
        for a in &alt.windage {
            models.push(choice(gb, needs, default, Source::Windage, a, |g, m| {
                g.losses.windage = Some(*m)
            }));
        }
        for a in &alt.sliding {
            models.push(choice(
                gb,
                needs,
                default,
                Source::Sliding,
                a,
                |g, s: &SlidingChoice| g.losses.sliding = s.clone(),
            ));
        }
        if !gb.bearings.is_empty() {
            models.extend(
                BEARING_CHOICES
                    .iter()
                    .map(|c| bearing_choice(gb, needs, default, c)),
            );
        }
        if gb.seals.iter().any(|s| matches!(s.seal.law, SealLaw::Torque(_))) {
            models.extend(seal_choices(gb, needs, default));
        }
        SpreadScene { models }
    }

    /// True when no source has more than one model choice.
    pub fn is_empty(&self) -> bool {
        self.models.is_empty()
    }
}

/// `gb` with only `source` among the gear-loss sources (windage keeps the churning
/// coefficients it reads), and only that source's multipliers.
fn only(gb: &Gearbox, source: Source) -> Gearbox {
    let mut g = gb.clone();
    if !matches!(source, Source::Churning | Source::Windage) {
        g.losses.churning = None;
    }
    if source != Source::Windage {
        g.losses.windage = None;
    }
    if source != Source::Sliding {
        g.losses.sliding = SlidingChoice::Off;
    }
    g.losses.pocketing = None;
    g.losses.multipliers.retain(|m| m.0 == source);
    g
}

/// Per item of `default`: `f(k)` for the items of `source`, [`Slot::Other`] for the rest.
fn slots(default: &LossScene, source: Source, f: impl Fn(usize) -> Slot) -> Vec<Slot> {
    default
        .items
        .iter()
        .enumerate()
        .map(|(k, it)| if it.source == source { f(k) } else { Slot::Other })
        .collect()
}

/// Compile `g` and match its items of `source` to the default's; a model that cannot be built
/// for this gearbox is not applicable, with the reason.
fn compiled(
    g: &Gearbox,
    needs: &Needs,
    default: &LossScene,
    source: Source,
) -> (Option<LossScene>, Vec<Slot>) {
    match LossScene::compile_for(g, needs) {
        Ok(scene) => {
            let s = slots(default, source, |k| {
                let name = &default.items[k].name;
                scene
                    .items
                    .iter()
                    .position(|x| x.source == source && x.name == *name)
                    .map_or(
                        Slot::NotApplicable("not compiled with this model".into()),
                        Slot::Item,
                    )
            });
            (Some(scene), s)
        }
        Err(e) => (
            None,
            slots(default, source, |_| Slot::NotApplicable(e.to_string())),
        ),
    }
}

/// One gearbox-wide choice of `source`.
fn choice<T>(
    gb: &Gearbox,
    needs: &Needs,
    default: &LossScene,
    source: Source,
    a: &Alternative<T>,
    set: impl Fn(&mut Gearbox, &T),
) -> SpreadModel {
    let (scene, slots) = match &a.model {
        _ if a.default => (None, slots(default, source, |_| Slot::Default)),
        Err(why) => (None, slots(default, source, |_| Slot::NotApplicable(why.clone()))),
        Ok(m) => {
            let mut g = only(gb, source);
            set(&mut g, m);
            compiled(&g, needs, default, source)
        }
    };
    SpreadModel {
        source,
        choice: a.choice,
        scene,
        slots,
    }
}

/// Bearing choice `c` for every bearing: its own model where `c` is its default, not applicable
/// where its data do not allow `c`.
fn bearing_choice(gb: &Gearbox, needs: &Needs, default: &LossScene, c: &'static str) -> SpreadModel {
    let mut g = only(gb, Source::Bearing);
    let mut own = Vec::new();
    for b in g.bearings.iter_mut() {
        match b
            .alternatives
            .iter()
            .find(|a| a.choice == c)
            .map(|a| (a.default, &a.model))
        {
            Some((true, _)) => own.push((b.name.clone(), Slot::Default)),
            Some((false, Ok(f))) => b.friction = f.clone(),
            Some((false, Err(why))) => own.push((b.name.clone(), Slot::NotApplicable(why.clone()))),
            None => own.push((b.name.clone(), Slot::NotApplicable("no such model".into()))),
        }
    }
    let needed = own.len() < g.bearings.len();
    let (scene, mut s) = if needed {
        compiled(&g, needs, default, Source::Bearing)
    } else {
        (None, slots(default, Source::Bearing, |_| Slot::Other))
    };
    for (k, it) in default.items.iter().enumerate() {
        if let Some((_, slot)) = own
            .iter()
            .find(|(n, _)| it.source == Source::Bearing && *n == it.name)
        {
            s[k] = slot.clone();
        }
    }
    SpreadModel {
        source: Source::Bearing,
        choice: c,
        scene,
        slots: s,
    }
}

/// The seal laws: a given torque (where the file gives one) and ISO/TR 14179-2's law.
fn seal_choices(gb: &Gearbox, needs: &Needs, default: &LossScene) -> Vec<SpreadModel> {
    let given = |name: &str| {
        gb.seals
            .iter()
            .any(|s| s.name == name && matches!(s.seal.law, SealLaw::Torque(_)))
    };
    let torque = slots(default, Source::Seal, |k| {
        if given(&default.items[k].name) {
            Slot::Default
        } else {
            Slot::NotApplicable("no torque_nm given for this seal".into())
        }
    });
    let mut g = only(gb, Source::Seal);
    g.seals.iter_mut().for_each(|s| s.seal.law = SealLaw::Iso14179);
    let (scene, mut iso) = compiled(&g, needs, default, Source::Seal);
    for (k, it) in default.items.iter().enumerate() {
        if it.source == Source::Seal && !given(&it.name) {
            iso[k] = Slot::Default;
        }
    }
    vec![
        SpreadModel {
            source: Source::Seal,
            choice: "given_torque",
            scene: None,
            slots: torque,
        },
        SpreadModel {
            source: Source::Seal,
            choice: "iso14179",
            scene,
            slots: iso,
        },
    ]
}
