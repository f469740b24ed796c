//! Per-sample loss terms shared between solves of the same cycle: the bearings' load terms, the
//! pump and converter values and the sliding losses' powers of torque and speed of every cycle
//! sample, computed once from one compiled scene and read by every scene whose compiled
//! bearings (and, separately, whose compiled pump, converter and clutch packs, and whose
//! sliding power-law exponents) equal that scene's.
//!
//! The terms are a function of the compiled part and the sample's (state, input speed, input
//! torque, vehicle speed) only, so a term read from the cache is bitwise the term
//! [`LossScene::prepare_at`](super::LossScene::prepare_at) would compute: a part is used only
//! when it compares equal (`PartialEq`, every field) to the part the cache was built from, and
//! an entry only for the exact bits of its sample. An uncertainty study varies heat-transfer
//! coefficients, the oil level or multipliers, not the bearings or the converter, so its cases
//! share one cache per cycle.

use std::collections::HashMap;
use std::sync::Arc;

use crate::physics::losses::bearings::LoadTerms;
use crate::physics::losses::sliding::PowerLaw;

use super::automatic::{AutoLosses, AutoSample};
use super::element_losses::ElementLosses;

/// (state, input speed, input torque, vehicle speed) bits of a cycle sample.
pub type SampleKey = (usize, u64, u64, u64);

/// The key of a cycle sample.
pub fn sample_key(state: usize, input_speed: f64, input_torque: f64, vehicle_speed: f64) -> SampleKey {
    (
        state,
        input_speed.to_bits(),
        input_torque.to_bits(),
        vehicle_speed.to_bits(),
    )
}

/// Terms of every distinct sample of a cycle, computed from one compiled scene.
#[derive(Debug)]
pub struct SampleCache {
    /// The compiled bearings and seals the bearing terms were computed from.
    elements: ElementLosses,
    /// The compiled packs, pump and converter the pump and converter values were computed from.
    auto: AutoLosses,
    /// Sample keys, in the order given.
    keys: Vec<SampleKey>,
    /// Position of each key in `keys`.
    index: HashMap<SampleKey, usize>,
    /// Pump and converter values per sample.
    auto_samples: Vec<AutoSample>,
    /// Bearing load terms, `bearings` per sample.
    bearing_terms: Vec<LoadTerms>,
    /// Bearings per sample.
    bearings: usize,
    /// The sliding entries' power laws the powers were computed for.
    slide_laws: Vec<Option<PowerLaw>>,
    /// |T|^a and |ω|^b of every sliding entry with a power law, `slide_laws.len()` per sample
    /// (0 for the others and where T or ω is 0).
    slide_powers: Vec<[f64; 2]>,
}

/// |T|^a and |ω|^b of a sliding power law at torque `t` and speed `w`: the two factors
/// [`LossScene::prepare_at`](super::LossScene::prepare_at) multiplies, computed alike.
pub fn law_powers(law: &PowerLaw, t: f64, w: f64) -> [f64; 2] {
    [t.abs().powf(law.torque), w.abs().powf(law.speed)]
}

impl SampleCache {
    /// The terms of every distinct sample of `inputs` (a cycle's segments in order: state,
    /// input speed, input torque, vehicle speed) for the compiled parts `elements` and `auto`.
    pub(super) fn build(
        elements: &ElementLosses,
        auto: &AutoLosses,
        slide_laws: Vec<Option<PowerLaw>>,
        inputs: impl IntoIterator<Item = (usize, f64, f64, f64)>,
    ) -> SampleCache {
        let bearings = elements.bearings();
        let mut c = SampleCache {
            elements: elements.clone(),
            auto: auto.clone(),
            keys: Vec::new(),
            index: HashMap::new(),
            auto_samples: Vec::new(),
            bearing_terms: Vec::new(),
            bearings,
            slide_laws,
            slide_powers: Vec::new(),
        };
        let mut terms = vec![LoadTerms::default(); bearings];
        for (state, w, t, v) in inputs {
            let key = sample_key(state, w, t, v);
            if c.index.contains_key(&key) {
                continue;
            }
            c.index.insert(key, c.keys.len());
            c.keys.push(key);
            let mut s = AutoSample::default();
            auto.prepare(state, w, t, v, &mut s);
            c.auto_samples.push(s);
            elements.prepare(state, w, t, &mut terms);
            c.bearing_terms.extend_from_slice(&terms);
            for law in &c.slide_laws {
                c.slide_powers.push(match law {
                    Some(l) if t != 0.0 && w != 0.0 => law_powers(l, t, w),
                    _ => [0.0; 2],
                });
            }
        }
        c
    }

    /// Distinct samples held.
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    /// True when no sample is held.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// Position of `key`, looked for at `cursor` and the next position first (a cycle's
    /// segments in order), then in the index; `cursor` follows. No allocation.
    fn find(&self, key: SampleKey, cursor: &mut usize) -> Option<usize> {
        let at = |i: usize| (self.keys.get(i) == Some(&key)).then_some(i);
        let i = at(*cursor)
            .or_else(|| at(*cursor + 1))
            .or_else(|| self.index.get(&key).copied())?;
        *cursor = i;
        Some(i)
    }
}

/// A cache attached to a compiled loss scene, with the parts of it the scene may read.
#[derive(Debug, Clone)]
pub struct CacheUse {
    cache: Arc<SampleCache>,
    /// The scene's bearings equal the cache's.
    bearings: bool,
    /// The scene's packs, pump and converter equal the cache's.
    auto: bool,
    /// The scene's sliding power laws equal the cache's.
    slide: bool,
}

impl CacheUse {
    /// The parts of `cache` a scene with compiled `elements`, `auto` and sliding power laws
    /// `slide_laws` may read (None: none).
    pub(super) fn new(
        cache: Arc<SampleCache>,
        elements: &ElementLosses,
        auto: &AutoLosses,
        slide_laws: &[Option<PowerLaw>],
    ) -> Option<CacheUse> {
        let bearings = cache.elements == *elements;
        let auto = cache.auto == *auto;
        let slide = cache.slide_laws == slide_laws;
        (bearings || auto || slide).then_some(CacheUse {
            cache,
            bearings,
            auto,
            slide,
        })
    }

    /// The entry of `key` (`cursor`: where the last one was). No allocation.
    pub(super) fn find(&self, key: SampleKey, cursor: &mut usize) -> Option<usize> {
        self.cache.find(key, cursor)
    }

    /// The pump and converter values of entry `i`, when the scene may read them.
    pub(super) fn auto(&self, i: usize) -> Option<&AutoSample> {
        self.auto.then(|| &self.cache.auto_samples[i])
    }

    /// The bearing load terms of entry `i`, when the scene may read them.
    pub(super) fn bearing_terms(&self, i: usize) -> Option<&[LoadTerms]> {
        let n = self.cache.bearings;
        self.bearings
            .then(|| &self.cache.bearing_terms[i * n..(i + 1) * n])
    }

    /// The sliding entries' powers of torque and speed of entry `i`, when the scene may read
    /// them.
    pub(super) fn slide_powers(&self, i: usize) -> Option<&[[f64; 2]]> {
        let n = self.cache.slide_laws.len();
        self.slide.then(|| &self.cache.slide_powers[i * n..(i + 1) * n])
    }

    /// Which parts the scene reads from the cache.
    pub fn parts(&self) -> CacheParts {
        CacheParts {
            bearings: self.bearings,
            auto: self.auto,
            slide: self.slide,
        }
    }
}

/// The parts of a [`SampleCache`] a scene reads.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CacheParts {
    /// The bearings' load terms.
    pub bearings: bool,
    /// The pump and converter values.
    pub auto: bool,
    /// The sliding losses' powers of torque and speed.
    pub slide: bool,
}
