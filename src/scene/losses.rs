//! The loss part of a compiled scene: every loss item of a gearbox with its precomputed model,
//! per-gear-state kinematic factors, and an allocation-free evaluation at an operating point.
//!
//! Compile once (`LossScene::compile`): churning models only for gears that reach the oil,
//! pocketing integrals K per external mesh, sliding contact-path tables per mesh, and for every
//! gear state the gear speeds and mesh torques per unit input. Evaluating all losses at an
//! operating point (`LossScene::evaluate`) is then a loop over flat arrays with no allocation.

use std::sync::Arc;

use crate::model::gearbox::Gearbox;
use crate::physics::losses::churning::{GearChurning, OilState as ChurnOil};

use super::churn_sample::{ChurnSample, InputSpeedPowers};
use super::circuit::{CircuitSample, CircuitScene};
use super::gear_losses::{
    compile_churning, compile_pocketing, compile_sliding, compile_windage, sliding, with_ratio_terms,
    ChurnEntry, Compiled, Lists, PocketEntry, SlideEntry, StateFactors, WindEntry,
};
use super::sample_cache::{law_powers, sample_key, CacheParts, CacheUse, SampleCache};
use super::usage::Usage;
use super::warning::RangeWarning;
use crate::physics::losses::sliding::PowerLaw;
use crate::physics::losses::windage::AIR;
use crate::physics::lubrication::{mixture_density, oil_fraction};

pub use super::gear_losses::{churning_gear, HELIX_POCKET_SLICES};
pub use super::items::{
    sum_by_source, DefaultHeat, LossItem, OperatingPoint, PerSource, SceneError, Skipped, Source, N_SOURCES,
};
pub use super::usage::Needs;

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
    /// Entry of the attached [`SampleCache`] the last sample was found at.
    cursor: usize,
    /// Pump and converter values of the sample (they need the vehicle speed too).
    pub auto: super::automatic::AutoSample,
    /// What the circuit's sources deliver in this sample.
    pub circuit: CircuitSample,
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
    wind: Vec<WindEntry>,
    states: Vec<StateFactors>,
    /// Density pumped by the part of a mesh zone above the oil (`None`: unknown, not counted).
    mixture_density: Option<f64>,
    /// Warnings known at compile time (e.g. pocketing of meshes above the oil not counted).
    pub warnings: Vec<RangeWarning>,
    /// Gear-state names (for reports that know a state by name).
    pub state_names: Vec<String>,
    auto: super::automatic::AutoLosses,
    /// Bearings and seals.
    elements: super::element_losses::ElementLosses,
    /// The lubrication circuit and the items that follow its flows.
    pub circuit: CircuitScene,
    /// Multiplier of each item (`[losses] multiplier`), when any is given.
    factor: Option<Vec<f64>>,
    /// Per-sample terms computed once for a cycle, read instead of computed where the compiled
    /// parts they come from are equal ([`LossScene::use_sample_cache`]).
    cache: Option<CacheUse>,
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
        let mut lists = Lists::default();
        let (churn, churn_gears) = compile_churning(gb, needs, &usage, &mut lists)?;
        let (pocket, pocket_meshes) = compile_pocketing(gb, &usage, &mut lists)?;
        let (slide, slide_meshes) = compile_sliding(gb, needs, &usage, &mut lists)?;
        let (wind, wind_gears) = compile_windage(gb, &usage, &mut lists)?;
        let compiled = Compiled {
            churn_gears: &churn_gears,
            pocket_meshes: &pocket_meshes,
            slide_meshes: &slide_meshes,
            slide: &slide,
            wind_gears: &wind_gears,
        };
        let states = (0..gb.gear_states.len())
            .map(|si| compiled.state_factors(gb, &usage, si))
            .collect::<Vec<StateFactors>>();
        let churn = with_ratio_terms(churn, &states);
        let Lists {
            mut items,
            mut skipped,
            mut warnings,
        } = lists;
        warnings.extend(super::warning::ineffective_key_warnings(gb));

        // The automatic's own parts: open clutch packs, pump, converter.
        let auto = super::automatic::AutoLosses::compile(
            gb,
            &|st| usage.needed(st),
            needs.evaluate_all,
            &mut items,
            &mut skipped,
        );

        let mixture_density = gb.losses.pocketing.and_then(|p| p.mixture_density);
        let elements = super::element_losses::ElementLosses::compile(
            gb,
            &|si| usage.needed(si),
            &|what, why| usage.idle(what, why),
            needs.evaluate_all,
            &mut items,
            &mut skipped,
        );
        let circuit = CircuitScene::compile(gb, &mut items);
        let factor = multipliers(&gb.losses.multipliers, &items)?;
        Ok(LossScene {
            factor,
            items,
            skipped,
            churn,
            pocket,
            slide,
            wind,
            states,
            mixture_density,
            warnings,
            state_names: gb.gear_states.iter().map(|s| s.name.clone()).collect(),
            auto,
            elements,
            circuit,
            cache: None,
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
        let auto = self.auto.sample(op.state, op.input_speed, op.input_torque, 0.0);
        let cs = self.circuit.sample(op.state, op.input_speed, &auto);
        self.evaluate_load_independent(op, None, &cs, out);
        let flow = |c| self.circuit.flow(c, &cs, op.oil.rho).0;
        self.auto.evaluate(
            op.state,
            op.input_speed,
            op.input_torque,
            &op.oil,
            &auto,
            flow,
            out,
        );
        self.circuit.evaluate(op.state, op.input_speed, &op.oil, &cs, out);
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
            cursor: 0,
            auto: Default::default(),
            circuit: Default::default(),
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
        let cached = self.cache.as_ref().and_then(|c| {
            let key = sample_key(state, input_speed, input_torque, vehicle_speed);
            c.find(key, &mut terms.cursor).map(|i| (c, i))
        });
        match cached.and_then(|(c, i)| c.auto(i)) {
            Some(s) => terms.auto = *s,
            None => self
                .auto
                .prepare(state, input_speed, input_torque, vehicle_speed, &mut terms.auto),
        }
        terms.circuit = self.circuit.sample(state, input_speed, &terms.auto);
        let key = (state, input_speed.to_bits(), input_torque.to_bits());
        if terms.key == Some(key) {
            return;
        }
        let st = &self.states[state];
        let (t, w) = (input_torque, input_speed);
        let cached_powers = cached.and_then(|(c, i)| c.slide_powers(i));
        self.prepare_sliding(st, t, w, cached_powers, &mut terms.slide_unit);
        match cached.and_then(|(c, i)| c.bearing_terms(i)) {
            Some(b) => terms.bearing.copy_from_slice(b),
            None => self.elements.prepare(state, w, t, &mut terms.bearing),
        }
        let mut input = InputSpeedPowers::new(w);
        for ((e, k), c) in self.churn.iter().zip(&st.churn_speed).zip(&mut terms.churn) {
            let ratio = e.ratio_terms.get(state).unwrap_or(&[0.0; 3]);
            *c = ChurnSample::prepare(e.law.as_ref(), ratio, k * w, &mut input);
        }
        terms.key = Some(key);
        terms.prepared += 1;
    }

    /// Each sliding entry's loss at η = 1 Pa·s for torque `t` and speed `w` in state `st` into
    /// `units` (entries without a power law are left as they are), with the powers of |T| and
    /// |ω| of an attached cache's sample when given (`cached`, one pair per entry).
    fn prepare_sliding(
        &self,
        st: &StateFactors,
        t: f64,
        w: f64,
        cached: Option<&[[f64; 2]]>,
        units: &mut [f64],
    ) {
        // P(T, ω) = P(sign(T·ω)·1 N·m, 1 rad/s)·|T|^a·|ω|^b: reversing both T and ω leaves the
        // power flow and every magnitude unchanged.
        let dir = usize::from(t * w < 0.0);
        // Meshes with the same friction law share their powers of |T| and |ω| (the last law is
        // remembered; the same values as computing them per mesh); a cache holds the same two
        // factors per entry for the sample (`law_powers`).
        let mut memo = (None, [0.0; 2]);
        let mut powers = |k: usize, law: PowerLaw| match cached {
            Some(p) => p[k],
            None => {
                if memo.0 != Some(law) {
                    memo = (Some(law), law_powers(&law, t, w));
                }
                memo.1
            }
        };
        for (k, ((e, unit), u)) in self.slide.iter().zip(&st.slide_unit).zip(units).enumerate() {
            let Some(law) = e.law else { continue };
            *u = if t == 0.0 || w == 0.0 {
                0.0
            } else {
                let [pt, pw] = powers(k, law);
                unit[dir] * pt * pw
            };
        }
    }

    /// The bearings' load terms and the pump and converter values of every sample of `inputs`
    /// (a cycle's segments: state, input speed, input torque, vehicle speed), computed once for
    /// this scene's compiled parts.
    pub fn sample_cache(&self, inputs: impl IntoIterator<Item = (usize, f64, f64, f64)>) -> SampleCache {
        SampleCache::build(&self.elements, &self.auto, self.slide_laws(), inputs)
    }

    /// The power law of every sliding entry (None: evaluated in full).
    fn slide_laws(&self) -> Vec<Option<PowerLaw>> {
        self.slide.iter().map(|e| e.law).collect()
    }

    /// Read the per-sample terms of `cache` where this scene's compiled parts equal those it was
    /// built from (bitwise the terms [`Self::prepare_at`] computes); returns which parts are read.
    pub fn use_sample_cache(&mut self, cache: Arc<SampleCache>) -> CacheParts {
        self.cache = CacheUse::new(cache, &self.elements, &self.auto, &self.slide_laws());
        self.cache.as_ref().map_or(CacheParts::default(), CacheUse::parts)
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
        let cs = &terms.circuit;
        self.evaluate_load_independent(op, Some(&terms.churn), cs, out);
        let flow = |c| self.circuit.flow(c, cs, op.oil.rho).0;
        self.auto.evaluate(
            op.state,
            op.input_speed,
            op.input_torque,
            &op.oil,
            &terms.auto,
            flow,
            out,
        );
        self.circuit.evaluate(op.state, op.input_speed, &op.oil, cs, out);
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

    /// Every churning item with its gear's pitch-line speed (m/s) at `input_speed` (rad/s) in
    /// `state` (range warnings).
    pub fn churning_pitch_speeds(
        &self,
        state: usize,
        input_speed: f64,
    ) -> impl Iterator<Item = (usize, f64)> + '_ {
        let st = &self.states[state];
        self.churn
            .iter()
            .zip(&st.churn_speed)
            .map(move |(e, k)| (e.item, k * input_speed * e.pitch_radius))
    }

    /// Mass flow (kg/s) of every circuit consumer at `op` into `mdot`, and its temperature
    /// derivative (kg/s/K) from d ln ρ/dT `dln_rho` into `dmdot`; from the prepared `terms` when
    /// they are for `op`'s sample. No allocation.
    pub fn consumer_flows(
        &self,
        op: &OperatingPoint,
        terms: &SampleTerms,
        dln_rho: f64,
        mdot: &mut [f64],
        dmdot: &mut [f64],
    ) {
        let fresh;
        let cs = if terms.key == Some((op.state, op.input_speed.to_bits(), op.input_torque.to_bits())) {
            &terms.circuit
        } else {
            let auto = self.auto.sample(op.state, op.input_speed, op.input_torque, 0.0);
            fresh = self.circuit.sample(op.state, op.input_speed, &auto);
            &fresh
        };
        self.circuit.mass_flows(cs, op.oil.rho, dln_rho, mdot, dmdot);
    }

    /// Every windage model with its loss item and its gear's speed relative to the air (rad/s) in
    /// gear state `state` at input speed `input_speed` (for range checks, with the air state).
    pub fn windage_models(
        &self,
        state: usize,
        input_speed: f64,
    ) -> impl Iterator<Item = (usize, &crate::physics::losses::churning::GearChurning, f64)> + '_ {
        let st = &self.states[state];
        self.wind
            .iter()
            .zip(&st.wind_speed)
            .map(move |(e, k)| (e.item, e.model.model(), k * input_speed))
    }

    /// Churning, windage and pocketing at `op` into `out`; churning from the sample's laws `churn`
    /// when given (prepared for `op`'s state and speed); pocketing of fed meshes with the oil the
    /// circuit delivers in sample `cs`.
    fn evaluate_load_independent(
        &self,
        op: &OperatingPoint,
        churn: Option<&[ChurnSample]>,
        cs: &CircuitSample,
        out: &mut [f64],
    ) {
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
        for (e, k) in self.wind.iter().zip(&st.wind_speed) {
            out[e.item] = e.multiplicity * e.model.power(k * w_in);
        }
        for (e, k) in self.pocket.iter().zip(&st.pocket_speed) {
            let w1 = k * w_in;
            // The share above the oil pumps the oil–air mixture the circuit's flow makes; without
            // a feed, the density the model file gives, else it is not counted (and reported in
            // `warnings`).
            let dry = if e.feeds.is_empty() {
                self.mixture_density.unwrap_or(0.0)
            } else {
                let q: f64 = e
                    .feeds
                    .iter()
                    .map(|&(c, f)| f * self.circuit.flow(c, cs, op.oil.rho).0)
                    .sum();
                mixture_density(oil_fraction(q, e.model.swept_flow(w1)), op.oil.rho, AIR.density)
            };
            let rho = e.wet_fraction * op.oil.rho + (1.0 - e.wet_fraction) * dry;
            out[e.item] = e.multiplicity * e.model.power(w1, rho);
        }
    }
}

/// Each item's multiplier from `[losses] multiplier` (sources, then items), or None when none
/// is given; an item name that matches no item is an error naming the items of that source.
fn multipliers(
    given: &[(crate::model::source::Source, Option<String>, f64)],
    items: &[LossItem],
) -> Result<Option<Vec<f64>>, SceneError> {
    if given.is_empty() {
        return Ok(None);
    }
    let mut f = vec![1.0; items.len()];
    for (source, _, m) in given.iter().filter(|g| g.1.is_none()) {
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
