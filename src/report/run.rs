//! Outputs of a transient run: `timeseries.csv` and `summary.json`.
//!
//! Column and key names are the contract the plots (`report::plots`) and users rely on; see
//! docs/outputs.md.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use crate::physics::oil::KELVIN_OFFSET;
use crate::scene::{sum_by_source, Scene, Skipped, Source, N_SOURCES};

use super::sources::{csv_columns, SourceValues};
use crate::solve::transient::{energy_balance, Stats, Trajectory};

pub use crate::solve::drive::RowInputs;

/// Energy of one loss item.
#[derive(Debug, Clone, Serialize)]
pub struct ItemEnergy {
    /// Source.
    pub source: Source,
    /// Item name.
    pub name: String,
    /// Energy, J.
    pub j: f64,
}

/// Min / max / final temperature of a node, °C.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct TempStats {
    /// Minimum over the output rows.
    pub min: f64,
    /// Maximum.
    pub max: f64,
    /// Final.
    pub r#final: f64,
}

/// A node listed in the summary.
#[derive(Debug, Clone, Serialize)]
pub struct NodeInfo {
    /// Name.
    pub name: String,
    /// True for boundary nodes.
    pub boundary: bool,
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize)]
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
    /// Mean efficiency: output energy / (output energy + loss energy while driving).
    pub mean_efficiency: Option<f64>,
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
}

/// Build the summary of a run.
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
    let last = traj.states.last().cloned().unwrap_or_default();
    let by = if last.is_empty() {
        [0.0; N_SOURCES]
    } else {
        scene.loss_energy_by_source(&last)
    };
    let per_source = SourceValues::new(by, "", true);
    // Per-item energies only when the scene integrates them (an output that can be switched off).
    let items = scene
        .losses
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
    let mean_eff = (out_e > 0.0).then(|| out_e / (out_e + loss_drive));

    let mut temps = BTreeMap::new();
    for i in 0..n {
        let series = traj.states.iter().map(|y| y[i] - KELVIN_OFFSET);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in series {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        temps.insert(
            scene.thermal.names[i].clone(),
            TempStats {
                min: lo,
                max: hi,
                r#final: last.get(i).map_or(f64::NAN, |t| t - KELVIN_OFFSET),
            },
        );
    }
    let mut nodes: Vec<NodeInfo> = scene
        .thermal
        .names
        .iter()
        .map(|x| NodeInfo {
            name: x.clone(),
            boundary: false,
        })
        .collect();
    nodes.extend(scene.thermal.boundary_names.iter().map(|x| NodeInfo {
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
        mean_efficiency: mean_eff,
        temperatures_c: temps,
        nodes,
        oil_node: scene.thermal.names[scene.thermal.oil].clone(),
        skipped: scene.skipped.clone(),
        frozen_viscosity: scene.frozen_oil_temp.is_some(),
    }
}

fn num(s: &mut String, v: f64) {
    if v.is_finite() {
        let _ = write!(s, "{v}");
    }
}

/// `timeseries.csv` text: one row per output time. `boundary_temps(t)` gives the boundary
/// temperatures (K) at time t.
pub fn timeseries_csv(
    scene: &Scene,
    traj: &Trajectory,
    rows: &[RowInputs],
    boundary_temps: &dyn Fn(f64) -> Vec<f64>,
) -> String {
    let n = scene.nodes();
    let mut s = String::with_capacity(traj.times.len() * 64 * (n + scene.items() + 10));
    s.push_str("time_s,vehicle_speed_kmh,gear,input_speed_rpm,input_torque_nm,output_power_w");
    for name in scene.thermal.names.iter().chain(&scene.thermal.boundary_names) {
        let _ = write!(s, ",temp_{name}_c");
    }
    for it in &scene.losses.items {
        let _ = write!(s, ",loss_{}_{}_w", it.source.as_str(), it.name);
    }
    let _ = writeln!(s, ",{},total_loss_w,efficiency", csv_columns());
    for (k, t) in traj.times.iter().enumerate() {
        let r = &rows[k];
        let y = &traj.states[k];
        let by = sum_by_source(&scene.losses.items, &traj.losses[k]);
        let total: f64 = by.iter().sum();
        // The input supplies the transmitted torque and the losses: T_in = T_out/i + P_loss/ω_in
        // (physics spec §9). The loss items themselves are evaluated at the loss-free torque
        // (docs/physics.md §10, "Mesh loads").
        let w_in = r.input_speed_rpm * std::f64::consts::PI / 30.0;
        let t_in = if w_in > 0.0 {
            r.input_torque_nm + total / w_in
        } else {
            r.input_torque_nm
        };
        let _ = write!(
            s,
            "{t},{},{},{},{},{}",
            r.vehicle_speed_kmh, r.gear, r.input_speed_rpm, t_in, r.output_power_w
        );
        for v in y.iter().take(n) {
            s.push(',');
            num(&mut s, v - KELVIN_OFFSET);
        }
        for v in boundary_temps(*t) {
            s.push(',');
            num(&mut s, v - KELVIN_OFFSET);
        }
        for q in &traj.losses[k] {
            s.push(',');
            num(&mut s, *q);
        }
        for v in by {
            let _ = write!(s, ",{v}");
        }
        let _ = write!(s, ",{total}");
        s.push(',');
        if r.output_power_w > 0.0 {
            num(&mut s, r.output_power_w / (r.output_power_w + total));
        }
        s.push('\n');
    }
    s
}
