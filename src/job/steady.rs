//! `steady`: the equilibrium at one operating point, its checks and its report.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::report::sources::SourceValues;
use crate::scene::{Inputs, Needs, OperatingPoint, RangeLog, RangeWarning, Scene};
use crate::solve::equilibrium::{equilibrium, Equilibrium};
use crate::solve::steady::{SteadyError, SteadyOptions as NewtonOptions};

use super::envelope::Envelope;
use super::limits::{self, short};
use super::{JobError, Model};
use crate::physics::units::{k_to_c, kmh_to_m_s, rpm_to_rad_s};

/// Largest residual of an equilibrium relative to its total loss (the solver converges to about
/// 1e-12; a larger residual is not an equilibrium, whatever the step criterion said).
pub const MAX_RELATIVE_RESIDUAL: f64 = 1e-6;

/// Options of an equilibrium (`geartherm steady`, a study's steady point, `Model.steady`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteadyOptions {
    /// Gear-state name.
    pub gear: String,
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m (negative: overrun).
    pub torque_nm: f64,
    /// Vehicle speed for h(v) links, km/h.
    #[serde(default)]
    pub vehicle_speed_kmh: f64,
    /// Ambient temperature, °C (None: the model's).
    #[serde(default)]
    pub ambient_c: Option<f64>,
}

impl SteadyOptions {
    /// Every range check of the options but the gear, which needs the model.
    pub fn check(&self) -> Result<(), JobError> {
        limits::SPEED_RPM.check(self.speed_rpm)?;
        limits::TORQUE_NM.check(self.torque_nm)?;
        check_point(self.vehicle_speed_kmh, self.ambient_c)
    }

    /// `gear G at N rpm, T N m` for messages.
    pub fn describe(&self) -> String {
        format!(
            "gear {} at {} rpm, {} N m{}",
            self.gear,
            short(self.speed_rpm),
            short(self.torque_nm),
            self.ambient_c
                .map_or(String::new(), |c| format!(", ambient {} °C", short(c)))
        )
    }
}

/// Checks shared by steady points and maps: vehicle speed and ambient.
pub(crate) fn check_point(vehicle_speed_kmh: f64, ambient_c: Option<f64>) -> Result<(), JobError> {
    limits::VEHICLE_SPEED_KMH.check(vehicle_speed_kmh)?;
    limits::AMBIENT_C.check_opt(ambient_c)?;
    Ok(())
}

/// A checked equilibrium (the `geartherm steady --json` document).
#[derive(Debug, Clone, Serialize)]
pub struct SteadyResult {
    /// Model name.
    pub model: String,
    /// Gear-state name.
    pub gear: String,
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m.
    pub torque_nm: f64,
    /// Temperature per node, °C.
    pub temperatures_c: BTreeMap<String, f64>,
    /// Loss per item (`source:name`), W.
    pub losses_w: BTreeMap<String, f64>,
    /// Loss per source and their sum, W (every source, zero where the model has none), flat
    /// keys `loss_<source>_w`, `loss_total_w`.
    #[serde(flatten)]
    pub by_source_w: SourceValues,
    /// Total loss, W (serialised as `loss_total_w` with the per-source values).
    #[serde(skip)]
    pub total_loss_w: f64,
    /// Efficiency P/(P + losses) (None without power).
    pub efficiency: Option<f64>,
    /// Newton iterations.
    pub iterations: usize,
    /// Pseudo-transient iterations.
    pub ptc_iterations: usize,
    /// `newton` or `newton+ptc`.
    pub method: &'static str,
    /// Final residual, W.
    pub residual_w: f64,
    /// Loss models used outside their fitted range at the equilibrium.
    pub warnings: Vec<RangeWarning>,
    /// With `[[thermal.controls]]` that have no equilibrium: the cycle they keep (`method` is
    /// then `limit_cycle`, `temperatures_c` and the losses are the cycle's means).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit_cycle: Option<LimitCycleReport>,
    /// Model-form spread at the equilibrium (`steady` fills it; not with a limit cycle).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spread: Option<crate::report::spread::SpreadBlock>,
}

/// A limit cycle in °C per node.
#[derive(Debug, Clone, Serialize)]
pub struct LimitCycleReport {
    /// The controller whose switches mark the period.
    pub controller: String,
    /// Period, s.
    pub period_s: f64,
    /// Time-mean temperature per node over a period, °C.
    pub mean_c: BTreeMap<String, f64>,
    /// Lowest, °C.
    pub min_c: BTreeMap<String, f64>,
    /// Highest, °C.
    pub max_c: BTreeMap<String, f64>,
}

/// The report of a limit cycle of `scene`.
fn cycle_report(scene: &Scene, c: &crate::solve::limit_cycle::LimitCycle) -> LimitCycleReport {
    let by_node = |v: &[f64]| -> BTreeMap<String, f64> {
        scene
            .thermal()
            .names
            .iter()
            .zip(v)
            .map(|(n, t)| (n.clone(), k_to_c(*t)))
            .collect()
    };
    LimitCycleReport {
        controller: c.controller.clone(),
        period_s: c.period_s,
        mean_c: by_node(&c.mean_k),
        min_c: by_node(&c.min_k),
        max_c: by_node(&c.max_k),
    }
}

/// The scene of one gear state with the ambient set.
pub(crate) fn point_scene(
    m: &Model,
    gear: &str,
    vehicle_speed_kmh: f64,
    ambient_c: Option<f64>,
) -> Result<(Scene, usize), JobError> {
    let state = m.state(gear)?;
    check_point(vehicle_speed_kmh, ambient_c)?;
    // Scene pruning: only this gear state's active items are compiled.
    let needs = Needs {
        states: Some(vec![state]),
        ambient_k: m.ambient_k(ambient_c)?,
        ..Needs::default()
    };
    let scene = m.compile(&needs)?;
    Ok((scene, state))
}

/// The inputs of an equilibrium.
pub(crate) fn inputs(state: usize, speed_rpm: f64, torque_nm: f64, vehicle_speed_kmh: f64) -> Inputs {
    Inputs {
        state,
        input_speed: rpm_to_rad_s(speed_rpm),
        input_torque: torque_nm,
        vehicle_speed: kmh_to_m_s(vehicle_speed_kmh),
    }
}

/// Solve and check the equilibrium at `o`.
pub fn steady(m: &Model, o: &SteadyOptions) -> Result<SteadyResult, JobError> {
    o.check()?;
    let (scene, state) = point_scene(m, &o.gear, o.vehicle_speed_kmh, o.ambient_c)?;
    let at = inputs(state, o.speed_rpm, o.torque_nm, o.vehicle_speed_kmh);
    let eq = equilibrium(&scene, at, None, &NewtonOptions::default()).map_err(|e| {
        JobError::numerical(format!(
            "{}: no equilibrium in {}: {}",
            m.label(),
            o.describe(),
            describe(&scene, &e)
        ))
    })?;
    check_equilibrium(&scene, &eq)
        .and_then(|()| check_envelope(&Envelope::of(&scene), &eq))
        .map_err(|what| JobError::numerical(format!("{}: {}: {what}", m.label(), o.describe())))?;
    let mut r = result(m, o, &scene, state, &eq);
    r.spread = spread(m, &scene, &at, &eq);
    Ok(r)
}

/// The report of the checked equilibrium `eq` at `o` (`steady`'s, and a rating point's).
pub(crate) fn result(
    m: &Model,
    o: &SteadyOptions,
    scene: &Scene,
    state: usize,
    eq: &Equilibrium,
) -> SteadyResult {
    let temperatures_c = scene
        .thermal()
        .names
        .iter()
        .zip(&eq.solution.temperatures)
        .map(|(n, t)| (n.clone(), k_to_c(*t)))
        .collect();
    let losses_w = scene
        .losses()
        .items
        .iter()
        .zip(&eq.losses)
        .map(|(it, q)| (format!("{}:{}", it.source.as_str(), it.name), *q))
        .collect();
    let mut log = RangeLog::new(scene.losses());
    let t_oil = eq.solution.temperatures[scene.thermal().oil];
    log.check(
        scene.losses(),
        &OperatingPoint {
            state,
            input_speed: rpm_to_rad_s(o.speed_rpm),
            input_torque: o.torque_nm,
            oil: scene.thermal().oil_properties(t_oil),
        },
    );
    SteadyResult {
        model: m.gearbox.name.clone(),
        gear: o.gear.clone(),
        speed_rpm: o.speed_rpm,
        torque_nm: o.torque_nm,
        temperatures_c,
        losses_w,
        by_source_w: SourceValues::new(eq.by_source, "_w", true).prefixed("loss_"),
        total_loss_w: eq.by_source.iter().sum(),
        efficiency: eq.efficiency,
        iterations: eq.solution.iterations,
        ptc_iterations: eq.solution.ptc_iterations,
        method: eq.solution.method,
        residual_w: eq.solution.residual_w,
        warnings: log.warnings(scene.losses()),
        limit_cycle: eq.limit_cycle.as_ref().map(|c| cycle_report(scene, c)),
        spread: None,
    }
}

/// The model-form spread at equilibrium `eq` (None with a limit cycle).
fn spread(
    m: &Model,
    scene: &Scene,
    at: &Inputs,
    eq: &Equilibrium,
) -> Option<crate::report::spread::SpreadBlock> {
    if eq.limit_cycle.is_some() {
        return None;
    }
    let needs = Needs {
        states: Some(vec![at.state]),
        ..Needs::default()
    };
    let op = OperatingPoint {
        state: at.state,
        input_speed: at.input_speed,
        input_torque: at.input_torque,
        oil: scene
            .thermal()
            .oil_properties(scene.oil_temp(&eq.solution.temperatures)),
    };
    Some(super::spread::at_point(
        &m.gearbox,
        &needs,
        scene.losses(),
        &eq.losses,
        &op,
    ))
}

/// Every number of an equilibrium finite and its residual small, else the first failure named.
pub fn check_equilibrium(scene: &Scene, eq: &Equilibrium) -> Result<(), String> {
    for (n, t) in scene.thermal().names.iter().zip(&eq.solution.temperatures) {
        if !t.is_finite() {
            return Err(format!("temperature of node {n} is not finite"));
        }
    }
    for (it, q) in scene.losses().items.iter().zip(&eq.losses) {
        if !q.is_finite() {
            return Err(format!(
                "loss item {}:{} is not finite",
                it.source.as_str(),
                it.name
            ));
        }
    }
    if let Some(c) = &eq.limit_cycle {
        let all = c.mean_k.iter().chain(&c.min_k).chain(&c.max_k);
        if !c.period_s.is_finite() || c.period_s <= 0.0 || all.clone().any(|v| !v.is_finite()) {
            return Err(format!("the limit cycle of {} is not finite", c.controller));
        }
    }
    let total: f64 = eq.by_source.iter().sum();
    let r = eq.solution.residual_w;
    if !r.is_finite() || r > MAX_RELATIVE_RESIDUAL * total.abs().max(1.0) {
        return Err(format!(
            "no equilibrium: residual {r:.3e} W exceeds {MAX_RELATIVE_RESIDUAL:e} of the total loss {total:.3e} W"
        ));
    }
    Ok(())
}

/// The equilibrium's temperatures inside the envelope, else the node that left it.
pub fn check_envelope(envelope: &Envelope, eq: &Equilibrium) -> Result<(), String> {
    envelope
        .check(&eq.solution.temperatures)
        .map_err(|b| format!("the equilibrium is outside the range where the models hold: {b}"))
}

/// A steady-solver failure in words, with node names.
pub fn describe(scene: &Scene, e: &SteadyError) -> String {
    let name = |i: usize| scene.thermal().names.get(i).cloned().unwrap_or_default();
    match e {
        SteadyError::NoEquilibriumInRange {
            node,
            temperature_k,
            bound_k,
            which,
        } => format!(
            "node {} is driven past its {which} limit {:.1} °C (toward {:.1} °C): the losses grow faster with \
             temperature than the cooling removes heat",
            name(*node),
            k_to_c(*bound_k),
            k_to_c(*temperature_k)
        ),
        SteadyError::Singular { nodes } => format!(
            "node(s) {} have no thermal path to a boundary",
            nodes.iter().map(|&i| name(i)).collect::<Vec<_>>().join(", ")
        ),
        other => other.to_string(),
    }
}
