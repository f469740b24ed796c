//! Equilibrium of a scene at a fixed operating point: the scene's heat balance as a
//! [`HeatBalance`] for the damped-Newton / pseudo-transient solver of [`super::steady`], the same
//! right-hand side and Jacobian as the transient runs.

use std::cell::RefCell;

use nalgebra::DMatrix;

use crate::scene::{Inputs, Scene, Work};

use super::steady::{solve_steady, BoundSide, HeatBalance, SteadyError, SteadyOptions, SteadySolution};
use super::transient::{integrate, Method, Segment, TransientOptions};
use crate::physics::units::{c_to_k, k_to_c};

/// Time at which time-series boundaries are evaluated for a steady state: their final value.
pub const STEADY_TIME: f64 = 1e12;

/// Valid range of the oil node, °C: below −60 °C the Walther fit is far outside its data, above
/// 200 °C gear oils and ATFs are past their flash-point region (no equilibrium "exists" there).
pub const OIL_RANGE_C: (f64, f64) = (-60.0, 200.0);
/// Valid range of the other nodes, °C.
pub const NODE_RANGE_C: (f64, f64) = (-100.0, 600.0);

/// The scene's heat balance at fixed inputs.
pub struct SceneBalance<'a> {
    scene: &'a Scene,
    work: RefCell<Work>,
    y: RefCell<Vec<f64>>,
    v: RefCell<Vec<f64>>,
    out: RefCell<Vec<f64>>,
}

impl<'a> SceneBalance<'a> {
    /// The balance of `scene` at `inputs`.
    pub fn new(scene: &'a Scene, inputs: Inputs) -> Self {
        let ns = scene.n_states();
        Self {
            scene,
            work: RefCell::new(scene.work(inputs)),
            y: RefCell::new(vec![0.0; ns]),
            v: RefCell::new(vec![0.0; ns]),
            out: RefCell::new(vec![0.0; ns]),
        }
    }
}

impl HeatBalance for SceneBalance<'_> {
    fn dim(&self) -> usize {
        self.scene.nodes()
    }

    fn residual(&self, t: &[f64], out: &mut [f64]) -> Result<(), String> {
        let mut y = self.y.borrow_mut();
        y[..t.len()].copy_from_slice(t);
        let mut w = self.work.borrow_mut();
        self.scene.net_heat(STEADY_TIME, &y, &mut w, out);
        if let Some(k) = w.q.iter().position(|q| !q.is_finite()) {
            let it = &self.scene.losses().items[k];
            return Err(format!(
                "loss item {}:{} is not finite at oil temperature {:.2} °C",
                it.source.as_str(),
                it.name,
                k_to_c(self.scene.oil_temp(&y))
            ));
        }
        Ok(())
    }

    fn jacobian(&self, t: &[f64], jac: &mut DMatrix<f64>) -> Result<(), String> {
        let n = t.len();
        let mut y = self.y.borrow_mut();
        y[..n].copy_from_slice(t);
        let mut v = self.v.borrow_mut();
        let mut o = self.out.borrow_mut();
        let mut w = self.work.borrow_mut();
        for j in 0..n {
            v.iter_mut().for_each(|x| *x = 0.0);
            v[j] = 1.0;
            self.scene.jvp(STEADY_TIME, &y, &v, &mut w, &mut o);
            for i in 0..n {
                // jvp gives d(dT/dt)/dT = J / C for the temperature rows.
                jac[(i, j)] = o[i] * self.scene.thermal().capacity[i];
            }
        }
        if jac.iter().any(|x| !x.is_finite()) {
            return Err("the Jacobian is not finite".into());
        }
        Ok(())
    }

    fn capacities(&self) -> &[f64] {
        &self.scene.thermal().capacity
    }

    fn bounds(&self, i: usize) -> (f64, f64) {
        let (lo, hi) = if i == self.scene.thermal().oil {
            OIL_RANGE_C
        } else {
            NODE_RANGE_C
        };
        (c_to_k(lo), c_to_k(hi))
    }
}

/// An equilibrium with its losses.
#[derive(Debug, Clone)]
pub struct Equilibrium {
    /// Solver result (temperatures in K).
    pub solution: SteadySolution,
    /// Loss of each item at equilibrium, W.
    pub losses: Vec<f64>,
    /// Per source (indexed by `Source::index`), W.
    pub by_source: crate::scene::PerSource,
    /// Loss-free transmitted power T·ω, W.
    pub power: f64,
    /// Efficiency P / (P + losses) (None without power).
    pub efficiency: Option<f64>,
    /// With controllers that find no equilibrium: the cycle they keep (then `solution` holds its
    /// mean temperatures and the losses are those at the mean).
    pub limit_cycle: Option<super::limit_cycle::LimitCycle>,
}

/// Solve the equilibrium of `scene` at `inputs` from `start` (K per node; None: the ambient or
/// the initial temperatures).
pub fn equilibrium(
    scene: &Scene,
    inputs: Inputs,
    start: Option<&[f64]>,
    opts: &SteadyOptions,
) -> Result<Equilibrium, SteadyError> {
    let sys = SceneBalance::new(scene, inputs);
    let t0: Vec<f64> = match start {
        Some(s) => s.to_vec(),
        None => {
            let mut w = scene.thermal().work();
            scene.thermal().boundary_temperatures(STEADY_TIME, &mut w);
            let amb = scene.thermal().ambient.map(|a| w.boundary_t[a]);
            match amb {
                Some(a) => vec![a; scene.nodes()],
                None => scene.thermal().initial.clone(),
            }
        }
    };
    let (solution, limit_cycle) = if scene.thermal().controls.is_empty() {
        (settle_steady(scene, &sys, inputs, &t0, opts)?, None)
    } else if scene.thermal().pi_rows() > 0 {
        with_pi(scene, inputs, &t0, opts)?
    } else {
        controlled(scene, inputs, &t0, opts, None)?
    };
    let mut y = vec![0.0; scene.n_states()];
    y[..scene.nodes()].copy_from_slice(&solution.temperatures);
    let mut w = scene.work(inputs);
    scene.evaluate_losses(&y, &mut w);
    let by = crate::scene::sum_by_source(&scene.losses().items, &w.q);
    let power = inputs.input_torque * inputs.input_speed;
    let total: f64 = by.iter().sum();
    Ok(Equilibrium {
        solution,
        losses: w.q,
        by_source: by,
        power,
        efficiency: crate::physics::efficiency::efficiency(power, total),
        limit_cycle,
    })
}

/// Temperatures within this of a PI valve's set point end the search for its integral, K.
const PI_SET_TOL_K: f64 = 1e-9;

/// Most equilibria solved in the search for a PI valve's integral.
const PI_MAX_ITER: usize = 60;

/// An equilibrium with a PI valve (one per network in a steady state). With its share held at
/// u ([`Scene::with_pi_share_held`]), the equilibrium ([`controlled`]) gives its sensor's
/// temperature T(u), which falls as u (the cooler's share) grows. The PI valve's equilibrium
/// is the u where T(u) = set: its integral stands still only there while the share is within
/// its limits, and the integral is then u. When T(min) is already at or below the set point,
/// the valve rests at its lower limit (its integral stands still there, by the anti-windup),
/// and when T(max) is still above it, at its upper limit: those equilibria are returned. The
/// root is found by regula falsi (Illinois, [`super::bracket`]) on u.
fn with_pi(
    scene: &Scene,
    inputs: Inputs,
    t0: &[f64],
    opts: &SteadyOptions,
) -> Result<(SteadySolution, Option<super::limit_cycle::LimitCycle>), SteadyError> {
    use crate::scene::controls::Law;
    let th = scene.thermal();
    let pis: Vec<usize> = (0..th.controls.len())
        .filter(|&k| th.controls[k].is_pi())
        .collect();
    if pis.len() > 1 {
        return Err(SteadyError::InvalidInput(format!(
            "{} PI valves: at most one in a steady state",
            pis.len()
        )));
    }
    let k = pis[0];
    type Found = (SteadySolution, Option<super::limit_cycle::LimitCycle>);
    let Law::Pi { set, min, max, .. } = th.controls[k].law else {
        unreachable!("is_pi");
    };
    let sensor = th.controls[k].sensor;
    let held = scene.with_pi_share_held(k);
    // The equilibrium at share u and T − set there; a share at which the sensor has no
    // equilibrium in range is a T − set of ±∞ (too hot, too cold).
    let solve = |u: f64, start: &[f64]| -> Result<(Option<Found>, f64), SteadyError> {
        match controlled(&held, inputs, start, opts, Some((k, u))) {
            Ok(sol) => {
                let g = sol.0.temperatures[sensor] - set;
                Ok((Some(sol), g))
            }
            Err(SteadyError::NoEquilibriumInRange { which, .. }) => Ok((
                None,
                match which {
                    BoundSide::Upper => f64::INFINITY,
                    BoundSide::Lower => f64::NEG_INFINITY,
                },
            )),
            Err(e) => Err(e),
        }
    };
    let (lo, g_lo) = solve(min, t0)?;
    if let Some(lo) = lo.filter(|l| g_lo <= PI_SET_TOL_K || l.1.is_some()) {
        return Ok(lo);
    }
    let start = t0.to_vec();
    let (hi, g_hi) = solve(max, &start)?;
    if hi
        .as_ref()
        .is_some_and(|h| g_hi >= -PI_SET_TOL_K || h.1.is_some())
    {
        return hi.ok_or_else(|| SteadyError::Model("unreachable".into()));
    }
    if !(g_lo > 0.0 && g_hi < 0.0) {
        // No equilibrium at either limit and none between them.
        return controlled(
            &held,
            inputs,
            t0,
            opts,
            Some((k, if g_lo < 0.0 { min } else { max })),
        );
    }
    // g(u) = T(u) − set falls with u: the bracket of −g.
    let mut br = super::bracket::Bracket::new(min, -g_lo, max, -g_hi);
    let mut best = hi;
    for _ in 0..PI_MAX_ITER {
        let u = br.trial();
        let from = best.as_ref().map_or(&start, |b| &b.0.temperatures).clone();
        let (sol, g) = solve(u, &from)?;
        if sol.is_some() {
            best = sol;
        }
        if let Some(b) = best
            .as_ref()
            .filter(|_| g.abs() <= PI_SET_TOL_K || br.b - br.a <= 1e-15)
        {
            return Ok(b.clone());
        }
        br.update(u, -g);
    }
    let Some(best) = best else {
        return controlled(&held, inputs, t0, opts, Some((k, min)));
    };
    let off = best.0.temperatures[sensor] - set;
    Err(SteadyError::Model(format!(
        "PI valve {}: {PI_MAX_ITER} equilibria did not bring its sensor to the set point \
         (last {off:.3e} K off)",
        th.controls[k].name
    )))
}

/// With controllers: the first mode combination of the two-point controllers (the start's
/// first) whose equilibrium no controller would leave; the valves' regions follow the solution.
/// `fixed`: a PI valve's integral (controller, value) set, the valve in its proportional
/// region at the start. None: the limit cycle
/// ([`super::limit_cycle`]).
fn controlled(
    scene: &Scene,
    inputs: Inputs,
    t0: &[f64],
    opts: &SteadyOptions,
    fixed: Option<(usize, f64)>,
) -> Result<(SteadySolution, Option<super::limit_cycle::LimitCycle>), SteadyError> {
    use super::limit_cycle::{find_limit_cycle, mean_solution, MAX_TWO_POINT};
    let two: Vec<usize> = (0..scene.thermal().controls.len())
        .filter(|&k| scene.thermal().controls[k].is_two_point())
        .collect();
    if two.len() > MAX_TWO_POINT {
        return Err(SteadyError::InvalidInput(format!(
            "{} two-point controllers: at most {MAX_TWO_POINT} in a steady state",
            two.len()
        )));
    }
    let nc = scene.thermal().controls.len() * crate::scene::controls::EVENTS_PER_CONTROL;
    let mut y0 = scene.initial_state(None);
    y0[..t0.len()].copy_from_slice(t0);
    if let Some(r) = fixed.and_then(|(k, _)| scene.thermal().integral_row(k)) {
        y0[r] = fixed.map_or(0.0, |f| f.1);
    }
    let start = scene.work(inputs);
    let first: usize = two
        .iter()
        .enumerate()
        .map(|(b, &k)| usize::from(start.net.mode[k]) << b)
        .sum();
    for c in (0..1usize << two.len()).map(|c| c ^ first) {
        let sys = SceneBalance::new(scene, inputs);
        sys.y.borrow_mut().copy_from_slice(&y0);
        {
            let mut w = sys.work.borrow_mut();
            scene.initial_control_modes(&y0, &mut w);
            for (b, &k) in two.iter().enumerate() {
                w.net.mode[k] = u8::from(c >> b & 1 == 1);
            }
            if let Some((k, _)) = fixed {
                w.net.mode[k] = 1;
            }
            let m = w.net.mode.clone();
            for (k, x) in m.into_iter().enumerate() {
                w.net.mode[k] = 255;
                scene.set_control_mode(k, x, &mut w);
            }
        }
        let mut t = t0.to_vec();
        let mut g = vec![0.0; scene.switching_count()];
        for _ in 0..4 {
            let sol = match settle_steady(scene, &sys, inputs, &t, opts) {
                Ok(sol) => sol,
                // Without two-point controllers nothing can cycle: a node past its range is
                // the answer.
                Err(e @ SteadyError::NoEquilibriumInRange { .. }) if two.is_empty() => return Err(e),
                Err(_) => break,
            };
            let mut y = y0.clone();
            y[..sol.temperatures.len()].copy_from_slice(&sol.temperatures);
            let mut w = sys.work.borrow_mut();
            scene.switching_functions(&y, &w, &mut g);
            if g[..nc].iter().all(|v| *v <= 0.0) {
                return Ok((sol, None));
            }
            // A valve in the wrong region: take the solution's and solve again; a two-point
            // controller that would switch: this combination has no equilibrium.
            let valves_only = scene
                .thermal()
                .controls
                .iter()
                .enumerate()
                .all(|(k, ct)| !ct.is_two_point() || g[2 * k..2 * k + 2].iter().all(|v| *v <= 0.0));
            if !valves_only {
                break;
            }
            for (k, ct) in scene.thermal().controls.iter().enumerate() {
                if !ct.is_two_point() {
                    let m = ct.settle(w.net.mode[k], scene.thermal().signal_in(k, &y));
                    scene.set_control_mode(k, m, &mut w);
                }
            }
            t = sol.temperatures;
        }
    }
    let cycle = find_limit_cycle(scene, inputs, t0)?;
    Ok((mean_solution(&cycle), Some(cycle)))
}

/// [`solve_steady`], falling back on the transient when Newton and PTC give up.
fn settle_steady(
    scene: &Scene,
    sys: &SceneBalance<'_>,
    inputs: Inputs,
    t0: &[f64],
    opts: &SteadyOptions,
) -> Result<SteadySolution, SteadyError> {
    Ok(match solve_steady(sys, t0, opts) {
        Ok(s) => s,
        // Newton and PTC gave up: follow the physical transient (the real ODE with the driver of
        // the transient runs) until it either settles, giving Newton a start next to the
        // equilibrium, or carries a node past its limit, which proves there is none in range.
        Err(SteadyError::NotConverged { .. }) => {
            let settled = transient_fallback(scene, sys, inputs, t0)?;
            solve_steady(sys, &settled, opts)?
        }
        Err(e) => return Err(e),
    })
}

/// Follow the transient from `t0` at constant inputs, in segments of growing length, until the
/// temperatures settle (returns them) or a node leaves its valid range (no equilibrium).
fn transient_fallback(
    scene: &Scene,
    sys: &SceneBalance<'_>,
    inputs: Inputs,
    t0: &[f64],
) -> Result<Vec<f64>, SteadyError> {
    let n = scene.nodes();
    // Node time constants are at most hours; 40 segments growing ×2 from 60 s cover ~2000 years.
    let mut segs = Vec::new();
    let (mut t, mut len) = (0.0, 60.0);
    for _ in 0..40 {
        segs.push(Segment {
            t0: t,
            t1: t + len,
            inputs,
        });
        t += len;
        len *= 2.0;
    }
    let o = TransientOptions {
        method: Method::Bdf,
        rtol: 1e-8,
        atol: 1e-8,
        initial_temp: None,
        ..TransientOptions::default()
    };
    let clamped = scene.clone().with_oil_temp_clamp(sys.bounds(scene.thermal().oil));
    let mut last = t0.to_vec();
    // One segment at a time, checking the limits between them.
    for seg in &segs {
        let scene_from = clamped.clone().with_initial(last.clone());
        let traj = integrate(&scene_from, std::slice::from_ref(seg), &o, &mut |_, _| {})
            .map_err(|e| SteadyError::Model(format!("transient fallback failed: {e}")))?;
        let y = traj.states.last().map_or(&last[..], |v| &v[..n]).to_vec();
        for (i, &yi) in y.iter().enumerate() {
            let (lo, hi) = sys.bounds(i);
            if yi > hi || yi < lo {
                return Err(SteadyError::NoEquilibriumInRange {
                    node: i,
                    temperature_k: yi,
                    bound_k: if yi > hi { hi } else { lo },
                    which: if yi > hi {
                        BoundSide::Upper
                    } else {
                        BoundSide::Lower
                    },
                });
            }
        }
        let settled = y.iter().zip(&last).all(|(a, b)| (a - b).abs() < 1e-9 * a.abs());
        last = y;
        if settled {
            break;
        }
    }
    Ok(last)
}
