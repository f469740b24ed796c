//! Model-form spread, evaluated: every applicable model's value of each loss item at an
//! operating point (with the validity ranges it leaves there), and the energy each model would
//! give per source along a run's trajectory.

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use super::items::{OperatingPoint, Source};
use super::losses::{LossScene, SampleTerms};
use super::ranges::RangeLog;
use super::spread::{label, Slot, SpreadScene};
use super::system::Inputs;
use super::warning::RangeWarning;
use crate::physics::oil::OilProperties;

/// One model's value of one loss item.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelValue {
    /// The model choice as the model file writes it (`default` for a source with one model).
    pub model: &'static str,
    /// Its name in the literature.
    pub label: &'static str,
    /// True for the item's own model.
    pub default: bool,
    /// Loss, W (null: not applicable).
    pub w: Option<f64>,
    /// Why the model's data do not allow this model (null: applicable).
    pub not_applicable: Option<String>,
    /// Validity ranges the model leaves at this point (range and what was seen).
    pub outside: Vec<String>,
}

/// Every applicable model's value of one loss item.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ItemSpread {
    /// Loss source.
    pub source: Source,
    /// Item name.
    pub name: String,
    /// The default's value, W.
    pub default_w: f64,
    /// Smallest applicable value, W.
    pub min_w: f64,
    /// Largest applicable value, W.
    pub max_w: f64,
    /// max/min (null when the smallest is 0 W and the largest is not).
    pub factor: Option<f64>,
    /// Every model choice of the item's source.
    pub models: Vec<ModelValue>,
}

/// The ranges of `warnings` about item `it` of source `source`.
fn outside(warnings: &[RangeWarning], source: Source, name: &str) -> Vec<String> {
    let s = source.as_str();
    warnings
        .iter()
        .filter(|w| w.item == format!("{s} of gear {name}") || w.item == format!("{s} of mesh {name}"))
        .map(|w| format!("{} ({})", w.range, w.seen))
        .collect()
}

/// The range warnings of `scene` at `op`.
fn range_warnings(scene: &LossScene, op: &OperatingPoint) -> Vec<RangeWarning> {
    let mut log = RangeLog::new(scene);
    log.check(scene, op);
    log.warnings(scene)
}

impl SpreadScene {
    /// Every item of `default` at `op` with every applicable model's value; `default_out` is
    /// the default scene's evaluation at `op`.
    pub fn evaluate(&self, default: &LossScene, default_out: &[f64], op: &OperatingPoint) -> Vec<ItemSpread> {
        let evaluated: Vec<Option<(Vec<f64>, Vec<RangeWarning>)>> = self
            .models
            .iter()
            .map(|m| {
                m.scene.as_ref().map(|s| {
                    let mut out = vec![0.0; s.len()];
                    s.evaluate(op, &mut out);
                    (out, range_warnings(s, op))
                })
            })
            .collect();
        let own = range_warnings(default, op);
        default
            .items
            .iter()
            .enumerate()
            .map(|(k, it)| {
                let mut models: Vec<ModelValue> = self
                    .models
                    .iter()
                    .zip(&evaluated)
                    .filter(|(m, _)| m.slots[k] != Slot::Other)
                    .map(|(m, e)| model_value(m, e.as_ref(), k, it, default_out[k], &own))
                    .collect();
                if models.is_empty() {
                    models.push(ModelValue {
                        model: "default",
                        label: label("default"),
                        default: true,
                        w: Some(default_out[k]),
                        not_applicable: None,
                        outside: outside(&own, it.source, &it.name),
                    });
                }
                item_spread(it.source, &it.name, default_out[k], models)
            })
            .collect()
    }
}

/// Model `m`'s value of item `k` (`it`), from its evaluation `e` (values, range warnings) or
/// the default's value `own_w` and warnings `own`; a non-finite value is not applicable.
fn model_value(
    m: &super::spread::SpreadModel,
    e: Option<&(Vec<f64>, Vec<RangeWarning>)>,
    k: usize,
    it: &super::items::LossItem,
    own_w: f64,
    own: &[RangeWarning],
) -> ModelValue {
    let (w, why, out) = match (&m.slots[k], e) {
        (Slot::Item(i), Some((v, warn))) if v[*i].is_finite() => {
            (Some(v[*i]), None, outside(warn, it.source, &it.name))
        }
        (Slot::Item(_), _) => (None, Some("not finite at this point".to_string()), Vec::new()),
        (Slot::NotApplicable(why), _) => (None, Some(why.clone()), Vec::new()),
        _ => (Some(own_w), None, outside(own, it.source, &it.name)),
    };
    ModelValue {
        model: m.choice,
        label: label(m.choice),
        default: m.slots[k] == Slot::Default,
        w,
        not_applicable: why,
        outside: out,
    }
}

/// The spread of one item from its models' values.
fn item_spread(source: Source, name: &str, default_w: f64, models: Vec<ModelValue>) -> ItemSpread {
    let values = models.iter().filter_map(|m| m.w);
    let min_w = values.clone().fold(default_w, f64::min);
    let max_w = values.fold(default_w, f64::max);
    let factor = if min_w > 0.0 {
        Some(max_w / min_w)
    } else if max_w <= 0.0 {
        Some(1.0)
    } else {
        None
    };
    ItemSpread {
        source,
        name: name.to_string(),
        default_w,
        min_w,
        max_w,
        factor,
        models,
    }
}

/// One model choice's energy over a run (J).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelEnergy {
    /// The model choice as the model file writes it.
    pub model: Cow<'static, str>,
    /// Its name in the literature.
    pub label: Cow<'static, str>,
    /// True when it is the file's choice for every item of the source.
    pub default: bool,
    /// Energy of the source with this model, J (items it does not apply to at their default's
    /// energy; null when it applies to none).
    pub j: Option<f64>,
    /// Items of the source it does not apply to, with why.
    pub not_applicable: Vec<String>,
}

/// The model-form spread of one source's energy over a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SourceSpread {
    /// Loss source.
    pub source: Source,
    /// Energy with the model file's choices, J (the same quadrature as the alternatives').
    pub default_j: f64,
    /// Smallest energy over the model choices, J.
    pub min_j: f64,
    /// Largest, J.
    pub max_j: f64,
    /// Every model choice.
    pub models: Vec<ModelEnergy>,
}

/// Work area of the energy quadrature along a trajectory (allocated once per run).
pub struct SpreadWork {
    terms: Vec<Option<SampleTerms>>,
    out: Vec<[Vec<f64>; 2]>,
    /// Per scene (the default first), per item: energy, J.
    energy: Vec<Vec<f64>>,
}

impl SpreadScene {
    /// A work area for the default scene and every alternative's.
    pub fn work(&self, default: &LossScene) -> SpreadWork {
        let scenes = std::iter::once(Some(default)).chain(self.models.iter().map(|m| m.scene.as_ref()));
        let (mut terms, mut out, mut energy) = (Vec::new(), Vec::new(), Vec::new());
        for s in scenes {
            let n = s.map_or(0, |s| s.len());
            terms.push(s.map(|s| s.sample_terms()));
            out.push([vec![0.0; n], vec![0.0; n]]);
            energy.push(vec![0.0; n]);
        }
        SpreadWork { terms, out, energy }
    }

    /// Add one interval of `dt` s with `inputs`, the oil at `oil[0]` at its start and `oil[1]`
    /// at its end (trapezoid rule), to every scene's item energies.
    pub fn accumulate(
        &self,
        default: &LossScene,
        inputs: &Inputs,
        oil: [OilProperties; 2],
        dt: f64,
        work: &mut SpreadWork,
    ) {
        let scenes = std::iter::once(Some(default)).chain(self.models.iter().map(|m| m.scene.as_ref()));
        for (i, s) in scenes.enumerate() {
            let (Some(s), Some(terms)) = (s, work.terms[i].as_mut()) else {
                continue;
            };
            let (a, v) = (inputs, &mut work.out[i]);
            s.prepare_at(a.state, a.input_speed, a.input_torque, a.vehicle_speed, terms);
            for (end, o) in oil.iter().enumerate() {
                let op = OperatingPoint {
                    state: a.state,
                    input_speed: a.input_speed,
                    input_torque: a.input_torque,
                    oil: *o,
                };
                s.evaluate_cached(&op, terms, &mut v[end]);
            }
            for ((e, p0), p1) in work.energy[i].iter_mut().zip(&v[0]).zip(&v[1]) {
                *e += 0.5 * (p0 + p1) * dt;
            }
        }
    }

    /// Per source with more than one model: the energy of each model choice.
    pub fn source_energies(&self, default: &LossScene, work: &SpreadWork) -> Vec<SourceSpread> {
        let own = &work.energy[0];
        let mut out: Vec<SourceSpread> = Vec::new();
        for (mi, m) in self.models.iter().enumerate() {
            let mut j = 0.0;
            let (mut applies, mut na, mut all_default) = (false, Vec::new(), true);
            for (k, it) in default.items.iter().enumerate() {
                match &m.slots[k] {
                    Slot::Other => continue,
                    Slot::Default => {
                        applies = true;
                        j += own[k];
                    }
                    Slot::Item(i) => {
                        applies = true;
                        all_default = false;
                        j += work.energy[mi + 1][*i];
                    }
                    Slot::NotApplicable(why) => {
                        all_default = false;
                        na.push(format!("{}: {why}", it.name));
                        j += own[k];
                    }
                }
            }
            let e = ModelEnergy {
                model: m.choice.into(),
                label: label(m.choice).into(),
                default: all_default && applies,
                j: applies.then_some(j),
                not_applicable: na,
            };
            match out.iter_mut().find(|s| s.source == m.source) {
                Some(s) => s.models.push(e),
                None => {
                    let d: f64 = default
                        .items
                        .iter()
                        .zip(own)
                        .filter(|(it, _)| it.source == m.source)
                        .map(|(_, e)| e)
                        .sum();
                    out.push(SourceSpread {
                        source: m.source,
                        default_j: d,
                        min_j: d,
                        max_j: d,
                        models: vec![e],
                    });
                }
            }
        }
        out.retain(|s| s.models.iter().any(|m| m.j.is_some()));
        for s in &mut out {
            for j in s.models.iter().filter_map(|m| m.j) {
                s.min_j = s.min_j.min(j);
                s.max_j = s.max_j.max(j);
            }
        }
        out
    }
}
