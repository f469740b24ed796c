//! Outputs of a transient run: `timeseries.csv` ([`Timeseries`]) and `summary.json`
//! ([`Summary`]).
//!
//! Each file has one set of types: the run writes them, and `report DIR`, the plots and
//! Python's `read_run` read them back with the same types (serde both ways for the summary, one
//! table for the time series). Keys that earlier versions did not write read as their defaults,
//! and renamed keys are read under their old names (docs/outputs.md, "Reading older
//! directories").

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::scene::{
    sum_by_source, OperatingPoint, PerSource, RangeLog, RangeWarning, Scene, Skipped, Source, N_SOURCES,
};

use super::sources::SourceValues;
use super::timeseries::Timeseries;
use crate::physics::units::{k_to_c, rpm_to_rad_s};
use crate::solve::transient::{energy_balance, Stats, Trajectory};

pub use crate::solve::drive::RowInputs;

/// Energy of one loss item.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ItemEnergy {
    /// Source.
    pub source: Source,
    /// Item name.
    pub name: String,
    /// Energy, J.
    pub j: f64,
}

/// Min / max / final temperature of a node, °C.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
pub struct TempStats {
    /// Minimum over the output rows.
    pub min: f64,
    /// Maximum.
    pub max: f64,
    /// Final.
    pub r#final: f64,
}

/// A node listed in the summary.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NodeInfo {
    /// Name.
    pub name: String,
    /// True for boundary nodes.
    pub boundary: bool,
}

/// `summary.json`. Read back with the same type: a key missing from the file (one an earlier
/// version did not write) reads as its default (empty, zero, absent).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Summary {
    /// Model name.
    pub model: String,
    /// Cycle name.
    pub cycle: String,
    /// Solver.
    pub solver: String,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance on temperatures, K.
    pub atol: f64,
    /// Wall time of the integration, s.
    pub wall_time_s: f64,
    /// Accepted steps.
    pub steps: usize,
    /// All counters.
    #[serde(deserialize_with = "super::stats_de::stats")]
    pub stats: Stats,
    /// Cycle duration, s.
    pub duration_s: f64,
    /// Energy lost per source, J (`<source>` keys and `total`).
    pub energy_lost_j: SourceValues,
    /// Energy per item, J.
    pub energy_by_item_j: Vec<ItemEnergy>,
    /// Heat stored in the nodes, J.
    pub energy_stored_j: f64,
    /// Heat into boundaries (ambient, coolant), J.
    pub energy_to_boundaries_j: f64,
    /// |lost − stored − to boundaries| / max of the three.
    pub energy_balance_relative: f64,
    /// Output energy, J (positive output power integrated).
    pub output_energy_j: f64,
    /// Cycle efficiency, energy-weighted: ∫P_out / ∫P_in over the driving time, with
    /// ∫P_in = ∫P_out + loss energy while driving (`physics::efficiency`). Read also under its
    /// earlier name `mean_efficiency`.
    #[serde(alias = "mean_efficiency")]
    pub cycle_efficiency: Option<f64>,
    /// All-in energy efficiency E_out/(E_out + E_loss), E_loss every loss item's energy over
    /// the whole cycle (driving, coasting, standing; the engine side's converter and pump
    /// included) (docs/outputs.md).
    pub energy_efficiency: Option<f64>,
    /// Temperatures per node, °C.
    pub temperatures_c: BTreeMap<String, TempStats>,
    /// Nodes (capacity nodes then boundaries).
    pub nodes: Vec<NodeInfo>,
    /// Oil node.
    pub oil_node: String,
    /// What the scene left out and why.
    pub skipped: Vec<Skipped>,
    /// True when the oil properties were frozen (viscosity feedback off).
    pub frozen_viscosity: bool,
    /// Loss models used outside their fitted range over the output rows, and items not counted
    /// (docs/validation.md).
    pub warnings: Vec<RangeWarning>,
    /// Engine side of a run with a launch device (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub launch: Option<LaunchSummary>,
    /// Per controller of `[[thermal.controls]]`: switches, duty cycle, heat moved (absent
    /// without controllers).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub controls: Vec<ControlSummary>,
    /// With `--spread`: per source, the energy each applicable model choice gives along the
    /// run's own trajectory (docs/uq.md, "Model-form spread"; absent without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spread: Option<Vec<crate::scene::SourceSpread>>,
}

/// A controller over the run.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ControlSummary {
    /// Name.
    pub name: String,
    /// Switches (located events).
    pub switches: usize,
    /// Time-mean share: a two-point controller's fraction of time on (its duty cycle), a
    /// valve's mean share through the cooler.
    pub duty_cycle: f64,
    /// Heat moved, J: through its cooler or links (positive from the hot/first end), or its
    /// heater's energy.
    pub energy_j: f64,
    /// A PI valve's time with its share at the lower limit, s (absent for other kinds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_at_lower_limit_s: Option<f64>,
    /// A PI valve's time with its share at the upper limit, s (absent for other kinds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_at_upper_limit_s: Option<f64>,
    /// A PI valve's integral at the end (share; absent for other kinds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integral_final: Option<f64>,
}

/// The controllers' summaries from the first and last state of `traj`.
pub fn control_summaries(scene: &Scene, traj: &Trajectory) -> Vec<ControlSummary> {
    let (Some(y0), Some(y1)) = (traj.states.first(), traj.states.last()) else {
        return Vec::new();
    };
    let r0 = scene.control_row_index();
    let dur = traj.times.last().copied().unwrap_or(0.0) - traj.times.first().copied().unwrap_or(0.0);
    let rows = crate::scene::controls::ROWS_PER_CONTROL;
    scene
        .thermal()
        .controls
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let r = r0 + rows * k;
            let pi = scene.thermal().integral_row(k);
            let at = |j: usize| pi.map(|p| y1[p + j] - y0[p + j]);
            ControlSummary {
                name: c.name.clone(),
                switches: traj.switches.get(k).copied().unwrap_or(0),
                duty_cycle: if dur > 0.0 {
                    (y1[r + 1] - y0[r + 1]) / dur
                } else {
                    0.0
                },
                energy_j: y1[r] - y0[r],
                time_at_lower_limit_s: at(1),
                time_at_upper_limit_s: at(2),
                integral_final: pi.map(|p| y1[p]),
            }
        })
        .collect()
}

/// Engine side of a run with a launch device (torque converter), from the output rows: each row
/// holds its segment's inputs until the next row.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct LaunchSummary {
    /// Highest engine (impeller) speed, rpm.
    pub engine_speed_max_rpm: f64,
    /// Time with the lock-up clutch closed, s.
    pub lockup_time_s: f64,
    /// Time at standstill in gear (gearbox input at rest, engine idling against the stalled
    /// converter), s.
    pub standstill_time_s: f64,
    /// Converter slip energy at standstill in gear, J.
    pub converter_standstill_j: f64,
    /// Converter slip energy while the input turns, J.
    pub converter_driving_j: f64,
}

/// The engine-side figures of `rows` over `times` (None when the rows carry no engine side).
pub fn launch_summary(times: &[f64], rows: &[RowInputs]) -> Option<LaunchSummary> {
    let mut s = LaunchSummary {
        engine_speed_max_rpm: 0.0,
        lockup_time_s: 0.0,
        standstill_time_s: 0.0,
        converter_standstill_j: 0.0,
        converter_driving_j: 0.0,
    };
    let mut any = false;
    for (k, r) in rows.iter().enumerate() {
        let Some(e) = r.engine else { continue };
        any = true;
        s.engine_speed_max_rpm = s.engine_speed_max_rpm.max(e.speed_rpm);
        let Some(dt) = times.get(k + 1).map(|t1| t1 - times[k]) else {
            continue;
        };
        if e.lockup {
            s.lockup_time_s += dt;
        }
        if r.input_speed_rpm == 0.0 {
            s.standstill_time_s += dt;
            s.converter_standstill_j += e.converter_loss_w * dt;
        } else {
            s.converter_driving_j += e.converter_loss_w * dt;
        }
    }
    any.then_some(s)
}

/// Range warnings over the output rows of a run (gear state by name, oil temperature of the row).
pub fn run_warnings(scene: &Scene, traj: &Trajectory, rows: &[RowInputs]) -> Vec<RangeWarning> {
    let mut log = RangeLog::new(scene.losses());
    for (r, y) in rows.iter().zip(&traj.states) {
        let Some(state) = scene
            .losses()
            .state_names
            .iter()
            .position(|n| n.as_str() == &*r.gear)
        else {
            continue;
        };
        let op = OperatingPoint {
            state,
            input_speed: rpm_to_rad_s(r.input_speed_rpm),
            input_torque: r.input_torque_nm,
            oil: scene.thermal().oil_properties(scene.oil_temp(y)),
        };
        log.check(scene.losses(), &op);
    }
    log.warnings(scene.losses())
}

/// Build the summary of a run, its `warnings` empty (the caller adds [`run_warnings`] when it
/// keeps them).
#[allow(clippy::too_many_arguments)]
pub fn summary(
    scene: &Scene,
    traj: &Trajectory,
    rows: &[RowInputs],
    model: &str,
    cycle: &str,
    solver: &str,
    rtol: f64,
    atol: f64,
) -> Summary {
    let n = scene.nodes();
    let last = traj.states.last().map(<[f64]>::to_vec).unwrap_or_default();
    let by = if last.is_empty() {
        [0.0; N_SOURCES]
    } else {
        scene.loss_energy_by_source(&last)
    };
    let per_source = SourceValues::new(by, "", true);
    // Per-item energies only when the scene integrates them (an output that can be switched off).
    let items = scene
        .losses()
        .items
        .iter()
        .enumerate()
        .filter_map(|(k, it)| {
            let j = (!last.is_empty())
                .then(|| scene.item_energy(&last, k))
                .flatten()?;
            Some(ItemEnergy {
                source: it.source,
                name: it.name.clone(),
                j,
            })
        })
        .collect();
    let bal = energy_balance(scene, traj);

    // Output energy and the loss energy while driving (positive output power), by the trapezoidal
    // rule over each segment with its constant inputs: the output power is constant per segment,
    // and the loss energy while driving comes from the exact per-item energies' increments.
    let mut out_e = 0.0;
    let mut loss_drive = 0.0;
    for (k, row) in rows.iter().enumerate().take(traj.times.len().saturating_sub(1)) {
        let p = row.output_power_w;
        if p > 0.0 {
            let dt = traj.times[k + 1] - traj.times[k];
            out_e += p * dt;
            loss_drive += scene.loss_energy(&traj.states[k + 1]) - scene.loss_energy(&traj.states[k]);
        }
    }
    let mean_eff = crate::physics::efficiency::efficiency(out_e, loss_drive);

    let mut temps = BTreeMap::new();
    for i in 0..n {
        let series = traj.states.iter().map(|y| k_to_c(y[i]));
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in series {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        temps.insert(
            scene.thermal().names[i].clone(),
            TempStats {
                min: lo,
                max: hi,
                r#final: last.get(i).map_or(f64::NAN, |t| k_to_c(*t)),
            },
        );
    }
    let mut nodes: Vec<NodeInfo> = scene
        .thermal()
        .names
        .iter()
        .map(|x| NodeInfo {
            name: x.clone(),
            boundary: false,
        })
        .collect();
    nodes.extend(scene.thermal().boundary_names.iter().map(|x| NodeInfo {
        name: x.clone(),
        boundary: true,
    }));
    Summary {
        model: model.to_string(),
        cycle: cycle.to_string(),
        solver: solver.to_string(),
        rtol,
        atol,
        wall_time_s: traj.wall_time_s,
        steps: traj.stats.steps,
        stats: traj.stats,
        duration_s: traj.times.last().copied().unwrap_or(0.0) - traj.times.first().copied().unwrap_or(0.0),
        energy_lost_j: per_source,
        energy_by_item_j: items,
        energy_stored_j: bal.stored,
        energy_to_boundaries_j: bal.to_boundaries,
        energy_balance_relative: bal.relative,
        output_energy_j: out_e,
        cycle_efficiency: mean_eff,
        energy_efficiency: crate::physics::efficiency::efficiency(out_e, by.iter().sum()),
        temperatures_c: temps,
        nodes,
        oil_node: scene.thermal().names[scene.thermal().oil].clone(),
        skipped: scene.skipped().to_vec(),
        frozen_viscosity: scene.frozen_oil_temp().is_some(),
        warnings: Vec::new(),
        launch: launch_summary(&traj.times, rows),
        controls: control_summaries(scene, traj),
        spread: None,
    }
}

/// `timeseries.csv` text: the table of [`timeseries`] written ([`Timeseries::to_csv`]).
pub fn timeseries_csv(
    scene: &Scene,
    traj: &Trajectory,
    rows: &[RowInputs],
    boundary_temps: &dyn Fn(f64) -> Vec<f64>,
) -> String {
    timeseries(scene, traj, rows, boundary_temps).to_csv()
}

/// The `timeseries.csv` table: one row per output time. `boundary_temps(t)` gives the boundary
/// temperatures (K) at time t. Column order: inputs, the engine side (runs with a launch device
/// only), node then boundary temperatures, loss items (those the scene left out as zeros),
/// per-source sums, total, efficiency, controllers (docs/outputs.md).
pub fn timeseries(
    scene: &Scene,
    traj: &Trajectory,
    rows: &[RowInputs],
    boundary_temps: &dyn Fn(f64) -> Vec<f64>,
) -> Timeseries {
    let m = traj.times.len();
    let col = |f: &dyn Fn(usize) -> f64| -> Vec<f64> { (0..m).map(f).collect() };
    let mut t = Timeseries::default();
    t.push_num("time_s", traj.times.clone());
    t.push_num("vehicle_speed_kmh", col(&|k| rows[k].vehicle_speed_kmh));
    t.push_text("gear", (0..m).map(|k| rows[k].gear.to_string()).collect());
    t.push_num("input_speed_rpm", col(&|k| rows[k].input_speed_rpm));
    // The input supplies the transmitted torque and the losses: T_in = T_out/i + P_loss/ω_in
    // (physics spec §9). The loss items themselves are evaluated at the loss-free torque
    // (docs/physics.md §10, "Mesh loads").
    t.push_num(
        "input_torque_nm",
        col(&|k| input_shaft_torque(scene, &rows[k], &traj.losses[k])),
    );
    t.push_num("output_power_w", col(&|k| rows[k].output_power_w));
    // Engine side only for runs with a launch device (docs/outputs.md).
    if rows.iter().any(|r| r.engine.is_some()) {
        let e = |f: &dyn Fn(&crate::solve::drive::EngineRow) -> f64| {
            col(&|k| rows[k].engine.as_ref().map_or(f64::NAN, f))
        };
        t.push_num("engine_speed_rpm", e(&|e| e.speed_rpm));
        t.push_num("engine_torque_nm", e(&|e| e.torque_nm));
        t.push_num("lockup", e(&|e| f64::from(u8::from(e.lockup))));
    }
    for (i, name) in scene.thermal().names.iter().enumerate() {
        t.push_num(format!("temp_{name}_c"), col(&|k| k_to_c(traj.states[k][i])));
    }
    let bt: Vec<Vec<f64>> = traj.times.iter().map(|x| boundary_temps(*x)).collect();
    for (j, name) in scene.thermal().boundary_names.iter().enumerate() {
        t.push_num(
            format!("temp_{name}_c"),
            col(&|k| bt[k].get(j).map_or(f64::NAN, |v| k_to_c(*v))),
        );
    }
    for (i, it) in scene.losses().items.iter().enumerate() {
        t.push_num(
            format!("loss_{}_{}_w", it.source.as_str(), it.name),
            col(&|k| traj.losses[k][i]),
        );
    }
    for (source, name) in skipped_items(scene) {
        t.push_num(format!("loss_{}_{name}_w", source.as_str()), vec![0.0; m]);
    }
    let by: Vec<PerSource> = (0..m)
        .map(|k| sum_by_source(&scene.losses().items, &traj.losses[k]))
        .collect();
    for s in Source::ALL {
        t.push_num(format!("loss_{}_w", s.as_str()), col(&|k| by[k][s.index()]));
    }
    let total: Vec<f64> = by.iter().map(|b| b.iter().sum()).collect();
    let eff = col(&|k| {
        crate::physics::efficiency::efficiency(rows[k].output_power_w, total[k]).unwrap_or(f64::NAN)
    });
    t.push_num("loss_total_w", total);
    t.push_num("efficiency", eff);
    for (j, c) in scene.thermal().controls.iter().enumerate() {
        t.push_num(
            format!("control_{}", c.name),
            col(&|k| {
                traj.controls
                    .get(k)
                    .and_then(|x| x.get(j))
                    .copied()
                    .unwrap_or(f64::NAN)
            }),
        );
    }
    // A PI valve's integral follows the controllers' shares in the trajectory's control rows.
    let n = scene.thermal().controls.len();
    let pis = scene.thermal().controls.iter().filter(|c| c.is_pi());
    for (j, c) in pis.enumerate() {
        t.push_num(
            format!("control_{}_integral", c.name),
            col(&|k| {
                traj.controls
                    .get(k)
                    .and_then(|x| x.get(n + j))
                    .copied()
                    .unwrap_or(f64::NAN)
            }),
        );
    }
    t
}

/// The loss items the scene left out (its `skipped` list, `<source> of <gear|mesh> <name>`),
/// as (source, name): `timeseries.csv` writes their columns as zeros, so that its column set is
/// the model's whatever the overrides (an oil level that leaves a gear dry keeps its column).
pub fn skipped_items(scene: &Scene) -> Vec<(Source, String)> {
    scene
        .skipped()
        .iter()
        .filter_map(|sk| {
            let (src, rest) = sk.what.split_once(" of ")?;
            let source = Source::ALL.into_iter().find(|x| x.as_str() == src)?;
            let name = rest.split_once(' ')?.1;
            let present = scene
                .losses()
                .items
                .iter()
                .any(|it| it.source == source && it.name == name);
            (!present).then(|| (source, name.to_string()))
        })
        .collect()
}

/// Torque at the gearbox input shaft, N·m: T_in = T_out/i + P_loss/ω_in (physics spec §9) with
/// only the losses supplied through the input shaft — the converter's slip and an engine-driven
/// pump are paid ahead of it (the engine columns show that side). The loss items themselves are
/// evaluated at the loss-free torque (docs/physics.md §10, "Mesh loads").
fn input_shaft_torque(scene: &Scene, r: &RowInputs, losses: &[f64]) -> f64 {
    let w_in = rpm_to_rad_s(r.input_speed_rpm);
    let shaft_loss: f64 = scene
        .losses()
        .items
        .iter()
        .zip(losses)
        .filter(|(it, _)| !it.engine_side)
        .map(|(_, p)| p)
        .sum();
    if w_in > 0.0 {
        r.input_torque_nm + shaft_loss / w_in
    } else {
        r.input_torque_nm
    }
}

/// The first non-finite number a run would write, named (`time 12.5 s, node oil`), or `Ok`.
/// Checked before anything is written: a run whose numbers are not all finite fails (exit 2)
/// instead of writing blanks or `null`s.
pub fn check_finite(
    scene: &Scene,
    traj: &Trajectory,
    rows: &[RowInputs],
    sum: &Summary,
) -> Result<(), String> {
    for (k, t) in traj.times.iter().enumerate() {
        if let Some(i) = traj.states[k]
            .iter()
            .take(scene.nodes())
            .position(|v| !v.is_finite())
        {
            return Err(format!(
                "temperature of node {} at t = {t} s is not finite",
                scene.thermal().names[i]
            ));
        }
        if let Some(q) = traj.losses.get(k) {
            if let Some(i) = q.iter().position(|v| !v.is_finite()) {
                let it = &scene.losses().items[i];
                return Err(format!(
                    "loss item {}:{} at t = {t} s is not finite",
                    it.source.as_str(),
                    it.name
                ));
            }
        }
        if let Some(r) = rows.get(k) {
            let t_in = traj
                .losses
                .get(k)
                .map_or(r.input_torque_nm, |q| input_shaft_torque(scene, r, q));
            for (what, v) in [
                ("vehicle speed", r.vehicle_speed_kmh),
                ("input speed", r.input_speed_rpm),
                ("input torque", t_in),
                ("output power", r.output_power_w),
            ] {
                if !v.is_finite() {
                    return Err(format!("{what} at t = {t} s is not finite"));
                }
            }
            if let Some(e) = r.engine {
                for (what, v) in [
                    ("engine speed", e.speed_rpm),
                    ("engine torque", e.torque_nm),
                    ("converter loss", e.converter_loss_w),
                ] {
                    if !v.is_finite() {
                        return Err(format!("{what} at t = {t} s is not finite"));
                    }
                }
            }
        }
    }
    sum.check_finite()
}

impl Summary {
    /// True when `node` is a boundary node of the run.
    pub fn is_boundary(&self, node: &str) -> bool {
        self.nodes.iter().any(|n| n.name == node && n.boundary)
    }

    /// The first non-finite number of the summary, named, or `Ok`.
    pub fn check_finite(&self) -> Result<(), String> {
        let e = &self.energy_lost_j;
        let mut named: Vec<(String, f64)> = vec![
            ("duration_s".into(), self.duration_s),
            ("energy_lost_j.total".into(), e.sum()),
            ("energy_stored_j".into(), self.energy_stored_j),
            ("energy_to_boundaries_j".into(), self.energy_to_boundaries_j),
            ("energy_balance_relative".into(), self.energy_balance_relative),
            ("output_energy_j".into(), self.output_energy_j),
            ("cycle_efficiency".into(), self.cycle_efficiency.unwrap_or(0.0)),
        ];
        for src in Source::ALL {
            named.push((format!("energy_lost_j.{}", src.as_str()), e.get(src)));
        }
        for it in &self.energy_by_item_j {
            named.push((
                format!("energy_by_item_j {}:{}", it.source.as_str(), it.name),
                it.j,
            ));
        }
        for (n, t) in &self.temperatures_c {
            named.push((format!("temperatures_c.{n}.min"), t.min));
            named.push((format!("temperatures_c.{n}.max"), t.max));
            named.push((format!("temperatures_c.{n}.final"), t.r#final));
        }
        for c in &self.controls {
            named.push((format!("controls.{}.duty_cycle", c.name), c.duty_cycle));
            named.push((format!("controls.{}.energy_j", c.name), c.energy_j));
            for (what, v) in [
                ("time_at_lower_limit_s", c.time_at_lower_limit_s),
                ("time_at_upper_limit_s", c.time_at_upper_limit_s),
                ("integral_final", c.integral_final),
            ] {
                if let Some(v) = v {
                    named.push((format!("controls.{}.{what}", c.name), v));
                }
            }
        }
        if let Some(l) = &self.launch {
            named.push(("launch.engine_speed_max_rpm".into(), l.engine_speed_max_rpm));
            named.push(("launch.converter_standstill_j".into(), l.converter_standstill_j));
            named.push(("launch.converter_driving_j".into(), l.converter_driving_j));
        }
        match named.into_iter().find(|(_, v)| !v.is_finite()) {
            Some((n, v)) => Err(format!("summary value {n} = {v} is not finite")),
            None => Ok(()),
        }
    }
}
