//! One job on one checked gearbox, without I/O: a drive-cycle transient (summary and, when asked,
//! the time-series table), a steady equilibrium, or an equilibrium map. The study runner and the
//! Python binding call these; `geartherm run` / `steady` / `map` solve the same problems.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::cycle::DriveCycle;
use crate::model::Gearbox;
use crate::physics::oil::KELVIN_OFFSET;
use crate::report::run::{summary, timeseries_csv, Summary};
use crate::scene::{Inputs, Needs, Scene};
use crate::solve::drive::{row_inputs, segments};
use crate::solve::equilibrium::equilibrium;
use crate::solve::steady::SteadyOptions;
use crate::solve::transient::{
    check_stored_values, integrate, Method, Restart, TransientOptions, DEFAULT_ATOL, DEFAULT_METHOD,
    DEFAULT_RTOL,
};

/// Why a job failed: bad input (exit code 1 on the CLI) or a numerical failure (exit code 2).
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum JobError {
    /// Invalid input: unknown cycle, gear state, value out of range.
    #[error("{0}")]
    Invalid(String),
    /// The solver failed (the message names time, node or loss item).
    #[error("{0}")]
    Numerical(String),
}

fn check(name: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Result<(), JobError> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(JobError::Invalid(format!(
            "{name} = {v}: must lie in [{lo}, {hi}]{unit}"
        )))
    }
}

/// Options of a drive-cycle run (the `geartherm run` flags).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RunOptions {
    /// Bundled cycle name or a CSV file.
    pub cycle: String,
    /// Solver name (auto, ros3, tr-bdf2, esdirk34, bdf, tsit45).
    pub solver: String,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance on temperatures, K.
    pub atol: f64,
    /// Initial temperature of every node, °C (None: the model's).
    pub initial_temp_c: Option<f64>,
    /// Ambient temperature, °C (None: the model's).
    pub ambient_c: Option<f64>,
    /// Step budget.
    pub max_steps: usize,
    /// Summary only: no time series, energy per source instead of per item (faster).
    pub summary_only: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            cycle: "wltc".into(),
            solver: DEFAULT_METHOD.name().into(),
            rtol: DEFAULT_RTOL,
            atol: DEFAULT_ATOL,
            initial_temp_c: None,
            ambient_c: None,
            max_steps: 5_000_000,
            summary_only: false,
        }
    }
}

/// A finished run.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// `summary.json` contents.
    pub summary: Summary,
    /// `timeseries.csv` text (None with `summary_only`).
    pub timeseries_csv: Option<String>,
}

fn set_ambient(scene: &mut Scene, ambient_c: Option<f64>) -> Result<(), JobError> {
    if let Some(a) = ambient_c {
        check("ambient_c", a, -60.0, 80.0, " °C")?;
        let idx = scene
            .thermal
            .ambient
            .ok_or_else(|| JobError::Invalid("ambient_c: the model has no ambient boundary".into()))?;
        scene.thermal.set_boundary_fixed(idx, a + KELVIN_OFFSET);
    }
    Ok(())
}

/// Run a drive (or rig) cycle on `gb`.
pub fn run_cycle(gb: &Gearbox, o: &RunOptions) -> Result<RunResult, JobError> {
    let method = Method::parse(&o.solver).ok_or_else(|| {
        JobError::Invalid(format!(
            "solver {}: unknown; allowed: {}",
            o.solver,
            Method::ALL.map(|m| m.name()).join(", ")
        ))
    })?;
    check("rtol", o.rtol, 1e-14, 1e-1, "")?;
    check("atol", o.atol, 1e-14, 1.0, " K")?;
    if let Some(t) = o.initial_temp_c {
        check("initial_temp_c", t, -60.0, 250.0, " °C")?;
    }
    let cycle = DriveCycle::resolve(&o.cycle).map_err(|e| JobError::Invalid(format!("cycle: {e}")))?;
    let (sched, segs) = segments(gb, &cycle).map_err(|e| JobError::Invalid(e.to_string()))?;
    let needs = Needs {
        states: Some(segs.iter().map(|s| s.inputs.state).collect()),
        evaluate_all: false,
        energy_per_source_only: o.summary_only,
    };
    let mut scene = Scene::compile_for(gb, &needs).map_err(|e| JobError::Invalid(e.to_string()))?;
    set_ambient(&mut scene, o.ambient_c)?;
    let opts = TransientOptions {
        method,
        rtol: o.rtol,
        atol: o.atol,
        restart: Restart::AtJumps,
        max_steps: o.max_steps,
        initial_temp: o.initial_temp_c.map(|c| c + KELVIN_OFFSET),
        record_losses: !o.summary_only,
        ..TransientOptions::default()
    };
    check_stored_values(&scene, &segs, &opts).map_err(JobError::Invalid)?;
    let traj =
        integrate(&scene, &segs, &opts, &mut |_, _| {}).map_err(|e| JobError::Numerical(e.to_string()))?;
    let rows = row_inputs(gb, &sched, &traj);
    let sum = summary(
        &scene,
        &traj,
        &rows,
        &gb.name,
        &cycle.name,
        method.name(),
        o.rtol,
        o.atol,
    );
    let csv = (!o.summary_only).then(|| {
        let work = std::cell::RefCell::new(scene.thermal.work());
        let bt = |t: f64| {
            let mut w = work.borrow_mut();
            scene.thermal.boundary_temperatures(t, &mut w);
            w.boundary_t.clone()
        };
        timeseries_csv(&scene, &traj, &rows, &bt)
    });
    Ok(RunResult {
        summary: sum,
        timeseries_csv: csv,
    })
}

/// One steady operating point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Point {
    /// Gear-state name.
    pub gear: String,
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m.
    pub torque_nm: f64,
    /// Vehicle speed for h(v) links, km/h.
    #[serde(default)]
    pub vehicle_speed_kmh: f64,
    /// Ambient temperature, °C (None: the model's).
    #[serde(default)]
    pub ambient_c: Option<f64>,
}

/// A steady equilibrium (the `geartherm steady --json` quantities).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct SteadyResult {
    /// Temperatures per node, °C.
    pub temperatures_c: BTreeMap<String, f64>,
    /// Loss per item (`source:name`), W.
    pub losses_w: BTreeMap<String, f64>,
    /// Loss per source, W.
    pub by_source_w: BTreeMap<String, f64>,
    /// Total loss, W.
    pub total_loss_w: f64,
    /// Efficiency P/(P + losses) (None without power).
    pub efficiency: Option<f64>,
    /// Newton iterations.
    pub iterations: usize,
    /// Pseudo-transient iterations.
    pub ptc_iterations: usize,
    /// Final residual, W.
    pub residual_w: f64,
}

fn point_scene(gb: &Gearbox, p: &Point) -> Result<(Scene, usize), JobError> {
    let state = gb.state_index(&p.gear).ok_or_else(|| {
        let names: Vec<&str> = gb.gear_states.iter().map(|s| s.name.as_str()).collect();
        JobError::Invalid(format!(
            "gear {}: unknown gear state; the model has: {}",
            p.gear,
            names.join(", ")
        ))
    })?;
    check("vehicle_speed_kmh", p.vehicle_speed_kmh, 0.0, 400.0, " km/h")?;
    let needs = Needs {
        states: Some(vec![state]),
        ..Needs::default()
    };
    let mut scene = Scene::compile_for(gb, &needs).map_err(|e| JobError::Invalid(e.to_string()))?;
    set_ambient(&mut scene, p.ambient_c)?;
    Ok((scene, state))
}

/// Equilibrium at one operating point.
pub fn steady_point(gb: &Gearbox, p: &Point) -> Result<SteadyResult, JobError> {
    check("speed_rpm", p.speed_rpm, 0.0, 50_000.0, " rpm")?;
    check("torque_nm", p.torque_nm, -1e6, 1e6, " N m")?;
    let (scene, state) = point_scene(gb, p)?;
    let inputs = Inputs {
        state,
        input_speed: p.speed_rpm * std::f64::consts::PI / 30.0,
        input_torque: p.torque_nm,
        vehicle_speed: p.vehicle_speed_kmh / 3.6,
    };
    let eq = equilibrium(&scene, inputs, None, &SteadyOptions::default())
        .map_err(|e| JobError::Numerical(format!("no equilibrium: {e}")))?;
    let temperatures_c = scene
        .thermal
        .names
        .iter()
        .zip(&eq.solution.temperatures)
        .map(|(n, t)| (n.clone(), t - KELVIN_OFFSET))
        .collect();
    let mut losses_w = BTreeMap::new();
    let mut by_source_w = BTreeMap::new();
    for (it, q) in scene.losses.items.iter().zip(&eq.losses) {
        losses_w.insert(format!("{}:{}", it.source.as_str(), it.name), *q);
        by_source_w.insert(it.source.as_str().to_string(), eq.by_source[it.source.index()]);
    }
    Ok(SteadyResult {
        temperatures_c,
        losses_w,
        by_source_w,
        total_loss_w: eq.by_source.iter().sum(),
        efficiency: eq.efficiency,
        iterations: eq.solution.iterations,
        ptc_iterations: eq.solution.ptc_iterations,
        residual_w: eq.solution.residual_w,
    })
}

/// Equilibria over a speed × torque grid in gear `p.gear` (p's speed and torque are ignored):
/// the `map.csv` text (blank cells where no equilibrium was found).
pub fn map_csv(gb: &Gearbox, p: &Point, speeds_rpm: &[f64], torques_nm: &[f64]) -> Result<String, JobError> {
    for &s in speeds_rpm {
        check("speed_rpm", s, 0.0, 50_000.0, " rpm")?;
    }
    for &t in torques_nm {
        check("torque_nm", t, -1e6, 1e6, " N m")?;
    }
    let (scene, state) = point_scene(gb, p)?;
    let points = crate::solve::sweep::map(
        &scene,
        state,
        speeds_rpm,
        torques_nm,
        p.vehicle_speed_kmh / 3.6,
        &SteadyOptions::default(),
        &|| {},
    );
    Ok(crate::report::map::map_csv(&points, scene.thermal.oil))
}

/// Every loss item at one operating point and oil temperature (the `geartherm losses` report).
pub fn losses_at(
    gb: &Gearbox,
    gear: &str,
    speed_rpm: f64,
    torque_nm: f64,
    oil_temp_c: f64,
) -> Result<crate::report::losses::LossReport, JobError> {
    let state = gb.state_index(gear).ok_or_else(|| {
        let names: Vec<&str> = gb.gear_states.iter().map(|s| s.name.as_str()).collect();
        JobError::Invalid(format!(
            "gear {gear}: unknown gear state; the model has: {}",
            names.join(", ")
        ))
    })?;
    check("speed_rpm", speed_rpm, 0.0, 50_000.0, " rpm")?;
    check("torque_nm", torque_nm, 0.0, 1e6, " N m")?;
    check("oil_temp_c", oil_temp_c, -60.0, 250.0, " °C")?;
    let scene = crate::scene::LossScene::compile(gb).map_err(|e| JobError::Invalid(e.to_string()))?;
    let op = crate::scene::OperatingPoint {
        state,
        input_speed: speed_rpm * std::f64::consts::PI / 30.0,
        input_torque: torque_nm,
        oil: gb.oil.properties(oil_temp_c + KELVIN_OFFSET),
    };
    Ok(crate::report::losses::losses(gb, &scene, &op, oil_temp_c))
}
