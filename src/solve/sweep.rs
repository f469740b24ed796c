//! Operating maps: equilibria over a speed × torque grid, in parallel (rayon, one speed per task)
//! with warm starts from the neighbouring torque point.

use rayon::prelude::*;

use crate::scene::{Inputs, Scene};

use super::equilibrium::{equilibrium, Equilibrium};
use super::steady::SteadyOptions;
use crate::physics::units::rpm_to_rad_s;

/// One grid point and its equilibrium (None: no equilibrium found, from the warm start nor from
/// ambient).
#[derive(Debug, Clone)]
pub struct MapPoint {
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Input torque, N·m.
    pub torque_nm: f64,
    /// The equilibrium.
    pub equilibrium: Option<Equilibrium>,
}

/// Equilibria of `scene` in gear state `state` over `speeds_rpm` × `torques_nm`, row-major by
/// speed. `vehicle_speed` (m/s) sets h(v) links. `tick` is called once per point (progress).
pub fn map(
    scene: &Scene,
    state: usize,
    speeds_rpm: &[f64],
    torques_nm: &[f64],
    vehicle_speed: f64,
    opts: &SteadyOptions,
    tick: &(dyn Fn() + Sync),
) -> Vec<MapPoint> {
    let inputs = |rpm: f64, tq: f64| Inputs {
        state,
        input_speed: rpm_to_rad_s(rpm),
        input_torque: tq,
        vehicle_speed,
    };
    speeds_rpm
        .par_iter()
        .map(|&sp| {
            let mut warm: Option<Vec<f64>> = None;
            torques_nm
                .iter()
                .map(|&tq| {
                    let eq = equilibrium(scene, inputs(sp, tq), warm.as_deref(), opts)
                        .or_else(|_| equilibrium(scene, inputs(sp, tq), None, opts))
                        .ok();
                    if let Some(e) = &eq {
                        warm = Some(e.solution.temperatures.clone());
                    }
                    tick();
                    MapPoint {
                        speed_rpm: sp,
                        torque_nm: tq,
                        equilibrium: eq,
                    }
                })
                .collect::<Vec<_>>()
        })
        .flatten()
        .collect()
}
