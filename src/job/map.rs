//! `map`: equilibria over a speed × torque grid in one gear state (rayon, warm starts), written
//! whole or not at all.

use serde::{Deserialize, Serialize};

use crate::solve::steady::SteadyOptions as NewtonOptions;
use crate::solve::sweep::{self, MapPoint};

use super::envelope::Envelope;
use super::limits::{self, short, MAX_MAP_POINTS};
use super::steady::{check_envelope, check_equilibrium, point_scene};
use super::{JobError, Model};
use crate::physics::units::{kmh_to_m_s, rpm_to_rad_s};

/// Options of a map (`geartherm map`, `Model.map`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapOptions {
    /// Gear-state name.
    pub gear: String,
    /// Input speeds, rpm.
    pub speed_rpm: Vec<f64>,
    /// Input torques, N·m.
    pub torque_nm: Vec<f64>,
    /// Vehicle speed for h(v) links, km/h.
    #[serde(default)]
    pub vehicle_speed_kmh: f64,
    /// Ambient temperature, °C (None: the model's).
    #[serde(default)]
    pub ambient_c: Option<f64>,
}

/// `A:B:N`: N points from A to B (A ≤ B), as the grid axes are written on the command line.
pub fn axis(name: &str, flag: &str, s: &str) -> Result<Vec<f64>, JobError> {
    let max = limits::MAP_AXIS_POINTS.hi;
    let bad = || {
        JobError::option(
            name,
            s,
            format!("A:B:N with A ≤ B finite and 1 ≤ N ≤ {max}"),
            format!("{name} ({flag}) = {s}: expected A:B:N (from A to B in N points, A ≤ B finite, 1 ≤ N ≤ {max})"),
        )
    };
    let parts: Vec<&str> = s.split(':').collect();
    let [a, b, n] = parts.as_slice() else {
        return Err(bad());
    };
    let a: f64 = a.trim().parse().map_err(|_| bad())?;
    let b: f64 = b.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    if n == 0 || n as f64 > max || !a.is_finite() || !b.is_finite() || (n > 1 && b < a) {
        return Err(bad());
    }
    Ok((0..n)
        .map(|k| {
            if n == 1 {
                a
            } else {
                a + (b - a) * k as f64 / (n - 1) as f64
            }
        })
        .collect())
}

impl MapOptions {
    /// Every range check of the options but the gear, which needs the model.
    pub fn check(&self) -> Result<(), JobError> {
        for (axis, values) in [("speed_rpm", &self.speed_rpm), ("torque_nm", &self.torque_nm)] {
            if values.is_empty() || values.len() as f64 > limits::MAP_AXIS_POINTS.hi {
                return Err(JobError::option(
                    axis,
                    values.len(),
                    format!("1 to {} points", limits::MAP_AXIS_POINTS.hi),
                    format!(
                        "{axis}: {} points; a map axis has 1 to {} points",
                        values.len(),
                        limits::MAP_AXIS_POINTS.hi
                    ),
                ));
            }
        }
        let n = self.speed_rpm.len() * self.torque_nm.len();
        if n > MAX_MAP_POINTS {
            return Err(JobError::option(
                "points",
                n,
                format!("at most {MAX_MAP_POINTS}"),
                format!(
                    "speed_rpm × torque_nm: {} × {} = {n} points; a map may have at most {MAX_MAP_POINTS} points \
                     (a larger grid is a study)",
                    self.speed_rpm.len(),
                    self.torque_nm.len()
                ),
            ));
        }
        for &s in &self.speed_rpm {
            limits::SPEED_RPM.check(s)?;
        }
        for &t in &self.torque_nm {
            limits::TORQUE_NM.check(t)?;
        }
        super::steady::check_point(self.vehicle_speed_kmh, self.ambient_c)
    }
}

pub use crate::report::map::{MapMeta, MapRow};

/// A finished map: the rows of `map.csv` and the contents of `map.json`, the types their files
/// are written and read with.
#[derive(Debug, Clone)]
pub struct MapResult {
    /// The rows of `map.csv`, one per grid point, speed-major.
    pub rows: Vec<MapRow>,
    /// The `map.json` contents.
    pub meta: MapMeta,
}

impl MapResult {
    /// The `map.csv` text.
    pub fn csv(&self) -> String {
        crate::report::map::map_csv(&self.rows)
    }

    /// The files of a map's output directory: `map.csv` and `map.json`.
    pub fn files(&self) -> Result<Vec<(&'static str, Vec<u8>)>, JobError> {
        let json = serde_json::to_vec_pretty(&self.meta)
            .map_err(|e| JobError::numerical(format!("cannot serialise map.json: {e}")))?;
        Ok(vec![("map.csv", self.csv().into_bytes()), ("map.json", json)])
    }
}

/// A checked map with its compiled scene, ready to solve.
pub struct Prepared {
    /// The scene of the map's gear state.
    pub scene: crate::scene::Scene,
    /// The gear state's index.
    pub state: usize,
}

/// Check the options and compile the scene: everything that can fail as invalid input.
pub fn prepare(m: &Model, o: &MapOptions) -> Result<Prepared, JobError> {
    o.check()?;
    let (scene, state) = point_scene(m, &o.gear, o.vehicle_speed_kmh, o.ambient_c)?;
    Ok(Prepared { scene, state })
}

/// Solve the map; `tick` is called once per point (progress).
pub fn map(m: &Model, o: &MapOptions, tick: &(dyn Fn() + Sync)) -> Result<MapResult, JobError> {
    solve(m, o, &prepare(m, o)?, tick)
}

/// Solve a prepared map and check every point (the second half of [`map`]).
pub fn solve(
    m: &Model,
    o: &MapOptions,
    p: &Prepared,
    tick: &(dyn Fn() + Sync),
) -> Result<MapResult, JobError> {
    let (scene, state) = (&p.scene, p.state);
    let start = std::time::Instant::now();
    let points = sweep::map(
        scene,
        state,
        &o.speed_rpm,
        &o.torque_nm,
        kmh_to_m_s(o.vehicle_speed_kmh),
        &NewtonOptions::default(),
        tick,
    );
    let wall = start.elapsed().as_secs_f64();
    // A map is returned whole or not at all: points without an equilibrium are a failure that
    // names them, not a map with holes.
    let failed = failures(scene, &points);
    if !failed.is_empty() {
        return Err(JobError::numerical(format!(
            "{}: {} of {} points failed, nothing written (narrow the grid); first: {}",
            m.label(),
            failed.len(),
            points.len(),
            failed.iter().take(5).cloned().collect::<Vec<_>>().join("; ")
        )));
    }
    let iterations: usize = points
        .iter()
        .filter_map(|p| p.equilibrium.as_ref())
        .map(|e| e.solution.iterations + e.solution.ptc_iterations)
        .sum();
    let n = points.len();
    Ok(MapResult {
        rows: points
            .iter()
            .map(|p| MapRow::of(p, scene.thermal().oil))
            .collect(),
        meta: MapMeta {
            model: m.gearbox.name.clone(),
            gear: o.gear.clone(),
            points: n,
            converged: n,
            mean_iterations: iterations as f64 / n.max(1) as f64,
            wall_time_s: wall,
            threads: rayon::current_num_threads(),
            warnings: warnings(scene, state, &points),
        },
    })
}

/// The range warnings over every point of a map, one per item and range.
fn warnings(
    scene: &crate::scene::Scene,
    state: usize,
    points: &[MapPoint],
) -> Vec<crate::scene::RangeWarning> {
    let mut log = crate::scene::RangeLog::new(scene.losses());
    for p in points {
        if let Some(e) = &p.equilibrium {
            log.check(
                scene.losses(),
                &crate::scene::OperatingPoint {
                    state,
                    input_speed: rpm_to_rad_s(p.speed_rpm),
                    input_torque: p.torque_nm,
                    oil: scene
                        .thermal()
                        .oil_properties(e.solution.temperatures[scene.thermal().oil]),
                },
            );
        }
    }
    log.warnings(scene.losses())
}

fn failures(scene: &crate::scene::Scene, points: &[MapPoint]) -> Vec<String> {
    let envelope = Envelope::of(scene);
    points
        .iter()
        .filter_map(|p| {
            let why = match &p.equilibrium {
                None => "no equilibrium".to_string(),
                Some(e) => check_equilibrium(scene, e)
                    .and_then(|()| check_envelope(&envelope, e))
                    .err()?,
            };
            Some(format!(
                "{} rpm, {} N m: {why}",
                short(p.speed_rpm),
                short(p.torque_nm)
            ))
        })
        .collect()
}
