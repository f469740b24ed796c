//! Work–precision study (docs/numerics.md): a reference solution from two method families at
//! tight tolerance, then every solver over a range of tolerances, with errors against the
//! reference on the output grid, wall time (median of repeats) and work counters.

use serde::{Deserialize, Serialize};

use crate::scene::Scene;

use super::transient::{
    energy_balance, integrate, Method, Restart, Segment, Trajectory, TransientOptions, DEFAULT_ATOL,
    DEFAULT_METHOD, DEFAULT_RTOL,
};

/// One (solver, tolerance) point of the study.
#[derive(Debug, Clone, Serialize)]
pub struct BenchRow {
    /// Solver name.
    pub solver: String,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (K).
    pub atol: f64,
    /// Median wall time, s.
    pub wall_time_s: f64,
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// RHS evaluations.
    pub rhs_evals: usize,
    /// Jacobian (loss-column) evaluations.
    pub jac_evals: usize,
    /// LU factorisations.
    pub lu_count: usize,
    /// Max over nodes of |T − T_ref| at the final time, K.
    pub err_final_k: f64,
    /// Max over the output grid and nodes, K.
    pub err_max_k: f64,
    /// RMS over the output grid and nodes, K.
    pub err_rms_k: f64,
    /// Energy-balance residual (relative).
    pub energy_balance_relative: f64,
    /// True for the product's default setting.
    pub default: bool,
    /// Why the run failed, if it did (then the numbers are NaN).
    pub failure: Option<String>,
}

/// The reference and its self-check.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Reference {
    /// Tolerance used.
    pub rtol: f64,
    /// Max |ΔT| between the two reference solutions over the output grid, K.
    pub agreement_k: f64,
    /// The two methods.
    pub methods: [String; 2],
}

/// Errors of `traj` against `reference` over the first `n` state components (the temperatures).
pub fn errors(traj: &Trajectory, reference: &Trajectory, n: usize) -> (f64, f64, f64) {
    let mut max: f64 = 0.0;
    let mut sq = 0.0;
    let mut count = 0usize;
    for (a, b) in traj.states.iter().zip(&reference.states) {
        for i in 0..n {
            let d = (a[i] - b[i]).abs();
            max = max.max(d);
            sq += d * d;
            count += 1;
        }
    }
    let fin = match (traj.states.last(), reference.states.last()) {
        (Some(a), Some(b)) => (0..n).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max),
        _ => f64::NAN,
    };
    (fin, max, (sq / count.max(1) as f64).sqrt())
}

/// Reference: ESDIRK34 and BDF (restarted only at jumps) at `rtol` = atol. Returns the ESDIRK
/// solution and the agreement between the two.
pub fn reference(scene: &Scene, segs: &[Segment], rtol: f64) -> Result<(Trajectory, Reference), String> {
    let o = |m| TransientOptions {
        method: m,
        rtol,
        atol: rtol,
        restart: Restart::AtJumps,
        ..TransientOptions::default()
    };
    let a = integrate(scene, segs, &o(Method::Esdirk34), &mut |_, _| {}).map_err(|e| e.to_string())?;
    let b = integrate(scene, segs, &o(Method::Bdf), &mut |_, _| {}).map_err(|e| e.to_string())?;
    let (_, agree, _) = errors(&a, &b, scene.nodes());
    Ok((
        a,
        Reference {
            rtol,
            agreement_k: agree,
            methods: ["esdirk34".into(), "bdf".into()],
        },
    ))
}

/// Run one point `repeats` times (median wall time).
pub fn point(
    scene: &Scene,
    segs: &[Segment],
    reference: &Trajectory,
    opts: &TransientOptions,
    repeats: usize,
    is_default: bool,
) -> BenchRow {
    let mut times = Vec::with_capacity(repeats);
    let mut last: Option<Result<Trajectory, String>> = None;
    for _ in 0..repeats.max(1) {
        let r = integrate(scene, segs, opts, &mut |_, _| {}).map_err(|e| e.to_string());
        if let Ok(t) = &r {
            times.push(t.wall_time_s);
        }
        let failed = r.is_err();
        last = Some(r);
        if failed {
            break;
        }
    }
    times.sort_by(f64::total_cmp);
    let base = BenchRow {
        solver: opts.method.name().into(),
        rtol: opts.rtol,
        atol: opts.atol,
        wall_time_s: f64::NAN,
        steps: 0,
        rejected: 0,
        rhs_evals: 0,
        jac_evals: 0,
        lu_count: 0,
        err_final_k: f64::NAN,
        err_max_k: f64::NAN,
        err_rms_k: f64::NAN,
        energy_balance_relative: f64::NAN,
        default: is_default,
        failure: None,
    };
    match last {
        Some(Ok(t)) => {
            let (f, m, r) = errors(&t, reference, scene.nodes());
            BenchRow {
                wall_time_s: times[times.len() / 2],
                steps: t.stats.steps,
                rejected: t.stats.rejected,
                rhs_evals: t.stats.rhs_evals,
                jac_evals: t.stats.jac_evals,
                lu_count: t.stats.lu_factorisations,
                err_final_k: f,
                err_max_k: m,
                err_rms_k: r,
                energy_balance_relative: energy_balance(scene, &t).relative,
                ..base
            }
        }
        Some(Err(e)) => BenchRow {
            failure: Some(e),
            ..base
        },
        None => base,
    }
}

/// Every method at every tolerance (atol scaled with rtol in the default's ratio
/// `DEFAULT_ATOL / DEFAULT_RTOL`), restarted at jumps; `on_row` sees each row as it is measured.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    scene: &Scene,
    segs: &[Segment],
    reference: &Trajectory,
    methods: &[Method],
    rtols: &[f64],
    repeats: usize,
    max_steps: usize,
    on_row: &mut dyn FnMut(&BenchRow),
) -> Vec<BenchRow> {
    let mut rows = Vec::with_capacity(methods.len() * rtols.len());
    for &m in methods {
        for &rt in rtols {
            let o = TransientOptions {
                method: m,
                rtol: rt,
                atol: rt * DEFAULT_ATOL / DEFAULT_RTOL,
                restart: Restart::AtJumps,
                max_steps,
                ..TransientOptions::default()
            };
            let n = scene.nodes();
            let is_default =
                m.resolve(n) == DEFAULT_METHOD.resolve(n) && (rt / DEFAULT_RTOL - 1.0).abs() < 1e-9;
            let row = point(scene, segs, reference, &o, repeats, is_default);
            on_row(&row);
            rows.push(row);
        }
    }
    rows
}

/// Timing noise margin of the Pareto test: the spread of median wall times measured on the
/// benchmark machine (docs/numerics.md).
pub const TIME_NOISE: f64 = 0.03;

/// Rows on the Pareto front of (wall time, max error): a row is dominated when another is at
/// least as accurate and faster by more than the timing noise, or at least twice as accurate and
/// no slower. Failed rows are never on it.
pub fn pareto(rows: &[BenchRow]) -> Vec<bool> {
    rows.iter()
        .map(|a| a.failure.is_none() && a.err_max_k.is_finite() && !rows.iter().any(|b| dominates(b, a)))
        .collect()
}

/// True when the successful row `b` is at least as accurate as `a` and faster by more than the
/// timing noise, or at least twice as accurate and no slower.
fn dominates(b: &BenchRow, a: &BenchRow) -> bool {
    let faster = b.err_max_k <= a.err_max_k && b.wall_time_s < a.wall_time_s * (1.0 - TIME_NOISE);
    let more_accurate = b.err_max_k <= 0.5 * a.err_max_k && b.wall_time_s <= a.wall_time_s;
    b.failure.is_none() && (faster || more_accurate)
}

/// `bench.csv` text.
pub fn to_csv(rows: &[BenchRow]) -> String {
    let mut s = String::from(
        "solver,rtol,atol,wall_time_s,steps,rejected,rhs_evals,jac_evals,lu_count,err_final_k,err_max_k,err_rms_k,energy_balance_relative,default\n",
    );
    let f = |v: f64| {
        if v.is_finite() {
            format!("{v:e}")
        } else {
            String::new()
        }
    };
    for r in rows {
        s.push_str(&format!(
            "{},{:e},{:e},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.solver,
            r.rtol,
            r.atol,
            f(r.wall_time_s),
            r.steps,
            r.rejected,
            r.rhs_evals,
            r.jac_evals,
            r.lu_count,
            f(r.err_final_k),
            f(r.err_max_k),
            f(r.err_rms_k),
            f(r.energy_balance_relative),
            r.default
        ));
    }
    s
}
