//! The fit over several traces ([`super::stack::Stack`]): the same least squares, residual model
//! (AR(1) per channel, restarted at every segment), sandwich covariance, intervals,
//! identifiability and bands as a fit of one segment, over the stacked residuals; errors per
//! trace and per channel; `calibrated.toml` (every parameter shared) or one
//! `calibrated_<trace>.toml` per trace (the shared values and the trace's own).

use std::time::Instant;

use crate::report::calibration::{fit_csv, CalibrationSummary, ChannelErrors, Errors, Noise, TraceErrors};

use super::lm::{self, Evaluation, LmOptions};
use super::params::Parameter;
use super::problem::Simulation;
use super::residuals::{Ar1, Layout};
use super::stack::{Stack, TraceInput};
use super::{
    bands, check_finite, correlation, identifiability, identifiable, model_file, parameters, stats, unequal,
    CalibrateOptions, CalibrateResult, Fitted, Independent, MIN_INFLUENCE_K,
};
use crate::job::{JobError, Model};

/// Calibrate over several traces (or several segments of one), the segments integrated in
/// parallel on this machine.
pub fn calibrate_traces(
    m: &Model,
    text: &str,
    traces: &[TraceInput<'_>],
    o: &CalibrateOptions,
) -> Result<CalibrateResult, JobError> {
    let s = super::stack::prepare(m, text, traces, o)?;
    fit(m, &s, o, &|th| s.evaluate(th))
}

/// A parameter no fitted temperature of any trace depends on is invalid input: a shared one no
/// trace influences, or one of a trace that does not influence it.
fn influenced(s: &Stack<'_>, influence: &[f64]) -> Result<(), JobError> {
    for (q, p) in s.params.iter().enumerate() {
        if influence[q] <= MIN_INFLUENCE_K {
            let whose = match s.owners[q] {
                Some(t) => format!("trace {t} ({})", s.sources[t]),
                None => format!("none of the traces ({})", s.sources.join(", ")),
            };
            return Err(JobError::option(
                "fit",
                p.name(),
                "a parameter the traces influence",
                format!(
                    "fit = {}: {whose} influences it (no fitted temperature moves by more than {MIN_INFLUENCE_K:e} K): \
                     it cannot be fitted",
                    p.name()
                ),
            ));
        }
    }
    Ok(())
}

/// Fit the stack; `eval` gives the stacked residuals and Jacobian at θ (the segments integrated
/// here or on Dask workers).
pub fn fit(
    m: &Model,
    s: &Stack<'_>,
    o: &CalibrateOptions,
    eval: &dyn Fn(&[f64]) -> Result<Evaluation, JobError>,
) -> Result<CalibrateResult, JobError> {
    let clock = Instant::now();
    let theta0 = s.start();
    let at0 = eval(&theta0)?;
    let influence: Vec<f64> = (0..s.params.len())
        .map(|k| at0.j.column(k).iter().fold(0.0, |a: f64, x| a.max(x.abs())))
        .collect();
    influenced(s, &influence)?;
    let free = vec![true; s.params.len()];
    let bounds: Vec<(f64, f64)> = s.params.iter().map(Parameter::theta_bounds).collect();
    let lmo = LmOptions {
        max_iterations: o.max_iterations,
        ..LmOptions::default()
    };
    let ols = lm::minimise(eval, &theta0, at0, &bounds, &free, &lmo)?;
    singular(s, &ols)?;
    let id_ols = identifiable(&ols.theta, &bounds, &free);
    let independent = Independent {
        lin: stats::linearised(&ols.at.j, ols.at.r.norm_squared(), &id_ols, 0),
        theta: ols.theta.clone(),
    };
    let layout = s.layout();
    let known = !layout.stretch.is_empty();
    let (res, noise, weights) = if o.residuals == "ar1" && known {
        let models = layout.estimate(&ols.at.r);
        let w: Vec<f64> = models.iter().map(Ar1::long_run_sd).collect();
        if unequal(&w) {
            let res = map_weighted(eval, ols, &w, &bounds, &free, &lmo)?;
            let models = layout.estimate(&res.at.r);
            (res, Some(models), Some(w))
        } else {
            (ols, Some(models), None)
        }
    } else {
        (ols, None, None)
    };
    let f = Fitted {
        res,
        weights,
        noise,
        whitened: false,
        layout,
        independent,
        influence,
        free,
    };
    assemble(m, s, o, &f, clock)
}

/// The weighted least-squares fit from `ols`: each channel's rows divided by its noise scale
/// `w` (docs/calibration.md, "The residual model"); its evaluation unweighted, its evaluations
/// counting those of `ols`.
fn map_weighted(
    eval: &dyn Fn(&[f64]) -> Result<Evaluation, JobError>,
    ols: lm::LmResult,
    w: &[f64],
    bounds: &[(f64, f64)],
    free: &[bool],
    lmo: &LmOptions,
) -> Result<lm::LmResult, JobError> {
    let ev = |th: &[f64]| eval(th).map(|e| super::prior::weighted(e, w));
    let at0 = super::prior::weighted(ols.at, w);
    let mut res = lm::minimise(ev, &ols.theta, at0, bounds, free, lmo)?;
    let back: Vec<f64> = w.iter().map(|x| 1.0 / x).collect();
    res.at = super::prior::weighted(res.at, &back);
    res.evaluations += ols.evaluations;
    res.iterations += ols.iterations;
    Ok(res)
}

fn singular(s: &Stack<'_>, res: &lm::LmResult) -> Result<(), JobError> {
    if res.stop != lm::Stop::Singular {
        return Ok(());
    }
    Err(JobError::numerical(format!(
        "{}: the fit stopped after {} evaluations at a point where the residuals or their sensitivities are \
         not finite, or the damped normal equations have no solution: no calibrated model is written",
        s.sources.join(", "),
        res.evaluations
    )))
}

/// The covariance of the stack's coordinates restricted to segment `k`'s parameters.
fn local_cov(s: &Stack<'_>, k: usize, cov: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let map = &s.segments[k].map;
    map.iter()
        .map(|&a| map.iter().map(|&b| cov[a][b]).collect())
        .collect()
}

/// Every segment simulated at the fitted point with its sensitivities (in parallel), and a
/// trajectory that leaves the physics envelope as an error (exit 2).
fn final_sims(s: &Stack<'_>, theta: &[f64]) -> Result<Vec<Simulation>, JobError> {
    use rayon::prelude::*;
    let sims: Vec<Simulation> = (0..s.segments.len())
        .into_par_iter()
        .map(|k| {
            s.segments[k]
                .problem
                .simulate(&s.local_theta(k, theta), !s.params.is_empty())
        })
        .collect::<Result<_, _>>()?;
    for (k, sim) in sims.iter().enumerate() {
        if let Some(b) = &sim.breach {
            let g = &s.segments[k];
            let values: Vec<String> = s
                .params
                .iter()
                .zip(theta)
                .map(|(q, &t)| format!("{} = {}", q.name(), q.written(t)))
                .collect();
            return Err(JobError::numerical(format!(
                "{} (segment {}): with {} the trajectory leaves the range where the models hold {b}: no calibrated \
                 model is written",
                s.sources[g.trace],
                g.index,
                values.join(", ")
            )));
        }
    }
    Ok(sims)
}

/// Per segment: residual and band half-width, `[row][channel]` in the stack's channel order.
type Rows = Vec<(Vec<Vec<f64>>, Vec<Vec<f64>>)>;

fn residual_rows(s: &Stack<'_>, sims: &[Simulation], cov: &[Vec<f64>], noise: &[Ar1], t: f64) -> Rows {
    sims.iter()
        .enumerate()
        .map(|(k, sim)| {
            let g = &s.segments[k];
            let local_noise: Vec<Ar1> = {
                let mut v = noise.to_vec();
                for (c, &col) in g.perm.iter().enumerate() {
                    v[col] = noise[c];
                }
                v
            };
            let half = bands::half_widths(sim, &local_cov(s, k, cov), &local_noise, t);
            let res = (0..sim.temps_c.len())
                .map(|r| {
                    g.perm
                        .iter()
                        .map(|&c| sim.temps_c[r][c] - g.problem.trace.measured[c].values_c[r])
                        .collect()
                })
                .collect();
            let half = half
                .iter()
                .map(|h| g.perm.iter().map(|&c| h[c]).collect())
                .collect();
            (res, half)
        })
        .collect()
}

/// Errors of channel `c` over the segments `which`, fitted (`held` false) or held-out rows.
fn errors_of(
    s: &Stack<'_>,
    rows: &Rows,
    which: &[usize],
    c: usize,
    held: bool,
    known: bool,
) -> Option<Errors> {
    let (mut r, mut h) = (Vec::new(), Vec::new());
    for &k in which {
        let g = &s.segments[k];
        for row in (0..g.held.len()).filter(|&row| g.held[row] == held) {
            r.push(rows[k].0[row][c]);
            h.push(rows[k].1[row][c]);
        }
    }
    Errors::of(&r, known.then_some(&h[..]))
}

fn channel_table(
    s: &Stack<'_>,
    rows: &Rows,
    which: &[usize],
    noise: &[Noise],
    known: bool,
) -> Vec<ChannelErrors> {
    s.nodes
        .iter()
        .enumerate()
        .map(|(c, (node, column))| ChannelErrors {
            column: column.clone(),
            node: node.clone(),
            fitted: errors_of(s, rows, which, c, false, known),
            holdout: errors_of(s, rows, which, c, true, known),
            noise: noise[c].clone(),
        })
        .collect()
}

/// The residual process per channel, with the autocorrelation of the stacked fitted residuals
/// (pairs within a stretch).
fn noise_table(f: &Fitted, noise: &[Ar1]) -> Vec<Noise> {
    let layout: &Layout = &f.layout;
    noise
        .iter()
        .enumerate()
        .map(|(c, a)| {
            let x = layout.channel(&f.res.at.r, c);
            Noise {
                phi: a.phi,
                innovation_sd_k: a.sigma,
                marginal_sd_k: a.marginal_sd(),
                autocorrelation_lag_1_2_6: [1, 2, 6].map(|lag| layout.autocorrelation(&x, lag)),
            }
        })
        .collect()
}

/// `fit.csv` with `trace,segment` first and each row's time in its file.
fn stacked_csv(s: &Stack<'_>, sims: &[Simulation], rows: &Rows) -> String {
    let nodes: Vec<String> = s.nodes.iter().map(|(n, _)| n.clone()).collect();
    let mut out = String::new();
    for (k, sim) in sims.iter().enumerate() {
        let g = &s.segments[k];
        let times: Vec<f64> = g.problem.trace.times.iter().map(|t| t + g.offset_s).collect();
        let measured: Vec<Vec<f64>> = g
            .perm
            .iter()
            .map(|&c| g.problem.trace.measured[c].values_c.clone())
            .collect();
        let temps: Vec<Vec<f64>> = sim
            .temps_c
            .iter()
            .map(|row| g.perm.iter().map(|&c| row[c]).collect())
            .collect();
        let csv = fit_csv(&times, &g.held, &nodes, &measured, &temps, &rows[k].1);
        let mut lines = csv.lines();
        let header = lines.next().unwrap_or_default();
        if k == 0 {
            out.push_str(&format!("trace,segment,{header}\n"));
        }
        for l in lines {
            out.push_str(&format!(
                "\"{}\",{},{l}\n",
                s.names[g.trace].replace('"', "\"\""),
                g.index
            ));
        }
    }
    out
}

/// The calibrated model text of trace `t` (None: every parameter), with the covariance block.
fn model_text(
    s: &Stack<'_>,
    m: &Model,
    theta: &[f64],
    t: Option<usize>,
    comment: &str,
) -> Result<String, JobError> {
    let mut ovs = s.base.clone();
    for (q, p) in s.params.iter().enumerate() {
        if t.is_none() || s.owners[q].is_none() || s.owners[q] == t {
            ovs.push(p.override_at(p.written(theta[q])));
        }
    }
    let mut text = model_file::calibrated_text(s.text, &ovs, &[])
        .map_err(|e| JobError::invalid(format!("{}: {e}", m.label())))?;
    text.push_str(comment);
    Ok(text)
}

fn assemble(
    m: &Model,
    s: &Stack<'_>,
    o: &CalibrateOptions,
    f: &Fitted,
    clock: Instant,
) -> Result<CalibrateResult, JobError> {
    let res = &f.res;
    let bounds: Vec<(f64, f64)> = s.params.iter().map(Parameter::theta_bounds).collect();
    let ident = identifiable(&res.theta, &bounds, &f.free);
    let (lin, _) = super::statistics(f, &ident);
    let t = stats::t975(lin.dof);
    let mut warnings: Vec<String> = Vec::new();
    for g in &s.segments {
        for n in &g.problem.trace.notes {
            if !n.contains("segment") && !warnings.contains(n) {
                warnings.push(n.clone());
            }
        }
    }
    let params = parameters(&s.params, f, &ident, &lin, t, &mut warnings);
    let correlation = correlation(&s.params, &lin, &mut warnings);
    let identifiability = identifiability(&s.params, &lin, t, &mut warnings);
    if res.stop == lm::Stop::Budget {
        warnings.push(format!(
            "the fit stopped after {} evaluations (max_iterations) before converging",
            res.evaluations
        ));
    }
    let sims = final_sims(s, &res.theta)?;
    let ar = f.noise.clone().unwrap_or_else(|| {
        vec![
            Ar1 {
                phi: 0.0,
                sigma: lin.sigma2.sqrt()
            };
            s.nodes.len()
        ]
    });
    let rows = residual_rows(s, &sims, &lin.covariance, &ar, t);
    let known = !f.layout.stretch.is_empty();
    let noise = noise_table(f, &ar);
    let all: Vec<usize> = (0..s.segments.len()).collect();
    let channels = channel_table(s, &rows, &all, &noise, known);
    let traces = (0..s.names.len())
        .map(|ti| {
            let which: Vec<usize> = all
                .iter()
                .copied()
                .filter(|&k| s.segments[k].trace == ti)
                .collect();
            TraceErrors {
                name: s.names[ti].clone(),
                source: s.sources[ti].clone(),
                index: ti,
                segments: which.iter().map(|&k| s.segments[k].index).collect(),
                rows: which.iter().map(|&k| s.segments[k].held.len()).sum(),
                channels: channel_table(s, &rows, &which, &noise, known),
            }
        })
        .collect();
    let covariance: Vec<Vec<Option<f64>>> = lin
        .covariance
        .iter()
        .map(|row| row.iter().map(|&x| x.is_finite().then_some(x)).collect())
        .collect();
    let comment = model_file::covariance_comment(&params, &covariance);
    let per_trace = s.owners.iter().any(Option::is_some);
    let (calibrated, per_trace_models) = if per_trace {
        let models = (0..s.names.len())
            .map(|ti| {
                Ok((
                    format!("calibrated_{}.toml", file_safe(&s.names[ti])),
                    model_text(s, m, &res.theta, Some(ti), &comment)?,
                ))
            })
            .collect::<Result<Vec<_>, JobError>>()?;
        (String::new(), models)
    } else {
        (model_text(s, m, &res.theta, None, &comment)?, Vec::new())
    };
    let summary = CalibrationSummary {
        model: m.gearbox.name.clone(),
        trace: s.sources.join(", "),
        rows: s.segments.iter().map(|g| g.held.len()).sum(),
        holdout_s: s.windows.clone(),
        parameters: params,
        covariance,
        correlation,
        identifiability,
        channels,
        fit: super::fit_stats(&f.res, o, &ar, &lin, t, clock),
        profiles: Vec::new(),
        plausibility: None,
        warnings,
        traces,
    };
    check_finite(&summary)?;
    Ok(CalibrateResult {
        summary,
        fit_csv: stacked_csv(s, &sims, &rows),
        calibrated_model: calibrated,
        cycle_csv: String::new(),
        per_trace_models,
    })
}

/// A trace name as part of a file name: letters, digits, `-`, `_` and `.` kept, others `_`.
fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}
