//! `map.csv`: one row per grid point of an operating map (the contract `report::plots` reads),
//! and `map.json` ([`MapMeta`]), written by `map` and read back by `report DIR` with this type.

use crate::physics::units::k_to_c;
use crate::scene::N_SOURCES;
use crate::solve::sweep::MapPoint;

use super::sources::csv_columns;

/// `map.csv` text; `oil` is the oil node index. Points without equilibrium have empty fields and
/// `converged = false`. A point where a controller cycles (no equilibrium exists: the limit
/// cycle of docs/numerics.md, "Controllers that switch") has the cycle's mean in the usual
/// columns and its period and oil band in `limit_cycle_period_s`, `oil_min_c`, `oil_max_c`
/// (empty at an equilibrium).
pub fn map_csv(points: &[MapPoint], oil: usize) -> String {
    let mut csv = format!(
        "speed_rpm,torque_nm,efficiency,loss_total_w,{},oil_temp_c,iterations,converged,\
         limit_cycle_period_s,oil_min_c,oil_max_c\n",
        csv_columns()
    );
    for p in points {
        match &p.equilibrium {
            Some(e) => {
                let total: f64 = e.by_source.iter().sum();
                csv.push_str(&format!(
                    "{},{},{},{},",
                    p.speed_rpm,
                    p.torque_nm,
                    e.efficiency.map_or(String::new(), |x| x.to_string()),
                    total,
                ));
                for v in e.by_source {
                    csv.push_str(&format!("{v},"));
                }
                csv.push_str(&format!(
                    "{},{},true,",
                    k_to_c(e.solution.temperatures[oil]),
                    e.solution.iterations + e.solution.ptc_iterations
                ));
                match &e.limit_cycle {
                    Some(c) => csv.push_str(&format!(
                        "{},{},{}\n",
                        c.period_s,
                        k_to_c(c.min_k[oil]),
                        k_to_c(c.max_k[oil])
                    )),
                    None => csv.push_str(",,\n"),
                }
            }
            None => csv.push_str(&format!(
                "{},{},,,{},,,false,,,\n",
                p.speed_rpm,
                p.torque_nm,
                ",".repeat(N_SOURCES)
            )),
        }
    }
    csv
}

/// What a map found besides its table (`map.json`); `report DIR` reads it back with this type
/// (a key an earlier version did not write reads as its default).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct MapMeta {
    /// Model name.
    pub model: String,
    /// Gear-state name.
    pub gear: String,
    /// Grid points.
    pub points: usize,
    /// Points with an equilibrium (all of them in a returned map).
    pub converged: usize,
    /// Newton + pseudo-transient iterations per point.
    pub mean_iterations: f64,
    /// Wall time of the sweep, s.
    pub wall_time_s: f64,
    /// Worker threads.
    pub threads: usize,
    /// Loss models used outside their fitted range at the map's equilibria.
    pub warnings: Vec<crate::scene::RangeWarning>,
}
