//! The fit over several traces ([`super::stack::Stack`]): the same least squares, residual model
//! (AR(1) per channel, restarted at every segment), sandwich covariance, intervals,
//! identifiability and bands as a fit of one segment, over the stacked residuals; errors per
//! trace and per channel; `calibrated.toml` (every parameter shared) or one
//! `calibrated_<trace>.toml` per trace (the shared values and the trace's own).

use std::time::Instant;

use crate::report::calibration::{
    fit_csv, CalibrationSummary, ChannelErrors, Errors, Noise, Plausibility, Profile, TraceErrors,
};

use super::lm::{self, Evaluation};
use super::params::Parameter;
use super::problem::Simulation;
use super::residuals::{Ar1, Layout};
use super::stack::{Stack, TraceInput};
use super::{
    bands, check_finite, correlation, identifiability, identifiable, model_file, parameters, plausibility,
    prior_influence, profile, solve, stats, CalibrateOptions, CalibrateResult, Fitted, Setup,
    MIN_INFLUENCE_K,
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
/// here or on Dask workers). The residual model, the priors (a MAP fit) and the profiles are
/// those of a fit of one segment ([`super::solve`]) over the stacked rows.
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
    let setup = Setup {
        params: &s.params,
        priors: &s.priors,
        layout: s.layout(),
        fail: &|r| singular(s, r),
    };
    let f = solve(eval, &setup, (&theta0, at0), influence, free, o)?;
    assemble(m, s, o, &f, eval, clock)
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
    // A prediction with its band from a calibration runs each segment at that calibration's
    // parameters (a per-trace one at its trace's value), with their sensitivities.
    let sims: Vec<Simulation> = (0..s.segments.len())
        .into_par_iter()
        .map(|k| match s.bands.get(k) {
            Some(b) => b.problem.simulate(&b.problem.start(), true),
            None => s.segments[k]
                .problem
                .simulate(&s.local_theta(k, theta), !s.params.is_empty()),
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

/// Per segment: residual and band standard deviation, `[row][channel]` in the stack's channel
/// order (with `--band-from` the calibration's covariance and processes; else the fit's).
fn residual_sds(s: &Stack<'_>, sims: &[Simulation], cov: &[Vec<f64>], noise: &[Ar1]) -> Rows {
    use rayon::prelude::*;
    (0..sims.len())
        .into_par_iter()
        .map(|k| {
            let (g, sim) = (&s.segments[k], &sims[k]);
            let sd = match s.bands.get(k) {
                Some(b) => bands::sds(sim, &b.covariance, &b.noise),
                None => {
                    let mut local = noise.to_vec();
                    for (c, &col) in g.perm.iter().enumerate() {
                        local[col] = noise[c];
                    }
                    bands::sds(sim, &local_cov(s, k, cov), &local)
                }
            };
            let res = (0..sim.temps_c.len())
                .map(|r| {
                    g.perm
                        .iter()
                        .map(|&c| sim.temps_c[r][c] - g.problem.trace.measured[c].values_c[r])
                        .collect()
                })
                .collect();
            let sd = sd
                .iter()
                .map(|h| g.perm.iter().map(|&c| h[c]).collect())
                .collect();
            (res, sd)
        })
        .collect()
}

/// The band multipliers per channel (stack order): of each trace (from its segments' fitted
/// rows) and of every trace's fitted rows together (`calibration.json`'s `channels`); with
/// `--band-from` the calibration's, per segment's trace.
struct Multipliers {
    /// Per trace.
    traces: Vec<Vec<bands::Multiplier>>,
    /// Every trace's rows together.
    all: Vec<bands::Multiplier>,
}

fn multipliers(s: &Stack<'_>, rows: &Rows, noise: &[Ar1], t: f64, o: &CalibrateOptions) -> Multipliers {
    let how = bands::Quantile::of(&o.band_quantile);
    let of = |which: &[usize]| -> Vec<bands::Multiplier> {
        if let Some(b) = which.first().and_then(|&k| s.bands.get(k)) {
            return s.segments[which[0]]
                .perm
                .iter()
                .map(|&c| b.multipliers[c])
                .collect();
        }
        (0..s.nodes.len())
            .map(|c| {
                let mut z = Vec::new();
                for &k in which {
                    let fitted: Vec<usize> = (0..s.segments[k].held.len())
                        .filter(|&r| !s.segments[k].held[r])
                        .collect();
                    z.extend(bands::standardised(&rows[k].0, &rows[k].1, &fitted, c));
                }
                bands::multiplier(&z, noise[c].phi, t, how)
            })
            .collect()
    };
    let all: Vec<usize> = (0..s.segments.len()).collect();
    Multipliers {
        traces: (0..s.names.len()).map(|ti| of(&segments_of(s, ti))).collect(),
        all: of(&all),
    }
}

/// Per segment: residual and band half-width (its standard deviation times its trace's
/// multiplier).
fn residual_rows(s: &Stack<'_>, sds: Rows, mult: &Multipliers) -> Rows {
    sds.into_iter()
        .enumerate()
        .map(|(k, (res, sd))| {
            let half = bands::scaled(&sd, &mult.traces[s.segments[k].trace]);
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
fn noise_table(f: &Fitted, noise: &[Ar1], mult: &[bands::Multiplier]) -> Vec<Noise> {
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
                band_multiplier: mult[c].value,
                band_quantile: mult[c].kind(),
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

/// The traces' reader notes (once each; the segment notes left out) and the fit's stop.
fn first_warnings(s: &Stack<'_>, res: &lm::LmResult) -> Vec<String> {
    let mut warnings: Vec<String> = Vec::new();
    for g in &s.segments {
        for n in &g.problem.trace.notes {
            if !n.contains("segment") && !warnings.contains(n) {
                warnings.push(n.clone());
            }
        }
    }
    warnings.extend(lm::stop_warning(res));
    warnings
}

/// The segments of trace `ti`.
fn segments_of(s: &Stack<'_>, ti: usize) -> Vec<usize> {
    (0..s.segments.len())
        .filter(|&k| s.segments[k].trace == ti)
        .collect()
}

/// The calibrated losses (docs/calibration.md, "Plausibility") over the segments `which` (one
/// trace's, or every segment when every parameter is shared), their warnings prefixed by
/// `label`.
fn plausibility_of(
    s: &Stack<'_>,
    sims: &[Simulation],
    which: &[usize],
    theta: &[f64],
    o: &CalibrateOptions,
    label: &str,
    warnings: &mut Vec<String>,
) -> Result<Option<Plausibility>, JobError> {
    let Some(&first) = which.first() else {
        return Ok(None);
    };
    let rated = o.rated.as_deref().map(plausibility::rated_point).transpose()?;
    let parts: Vec<(&super::problem::Problem<'_>, &[Vec<f64>])> = which
        .iter()
        .map(|&k| (&s.segments[k].problem, &sims[k].temps_c[..]))
        .collect();
    let mut own = Vec::new();
    let p = plausibility::assess(
        &parts,
        &s.local_theta(first, theta),
        o.gearbox_kind.as_deref(),
        rated,
        &mut own,
    )?;
    for w in own {
        let w = format!("{label}{w}");
        if !warnings.contains(&w) {
            warnings.push(w);
        }
    }
    Ok(p)
}

/// The profile likelihoods asked for, of the stacked objective.
fn profiles_of(
    s: &Stack<'_>,
    f: &Fitted,
    eval: &dyn Fn(&[f64]) -> Result<Evaluation, JobError>,
    noise: &[Ar1],
    lin: &stats::Linearised,
    warnings: &mut Vec<String>,
) -> Result<Vec<Profile>, JobError> {
    let objective = profile::Objective {
        eval,
        params: &s.params,
        priors: &s.priors,
        fail: &|r| singular(s, r),
        noise,
        whitened: f.whitened,
        layout: &f.layout,
    };
    let profiles = s
        .profile
        .iter()
        .map(|&k| profile::profile(&objective, k, &f.res.theta, lin.std_err[k], lin.dof, &f.free))
        .collect::<Result<Vec<_>, _>>()?;
    for q in profiles.iter().filter(|q| q.below_fit.is_some()) {
        warnings.push(format!(
            "profile of {}: the objective is lower by {:.3} at {} than at the fitted value: the fit stopped short \
             along a flat valley (the least point of profile.csv is the better one)",
            q.key_path,
            q.below_fit.unwrap_or(0.0),
            q.points.iter().find(|x| x.statistic == 0.0).map_or(f64::NAN, |x| x.value)
        ));
    }
    Ok(profiles)
}

/// Per trace: its segments, rows, errors per channel and, when the parameters differ per trace,
/// its calibrated model's losses.
fn trace_reports(
    s: &Stack<'_>,
    sims: &[Simulation],
    rows: &Rows,
    (noise, known, mult): (&[Noise], bool, &Multipliers),
    o: &CalibrateOptions,
    theta: &[f64],
    warnings: &mut Vec<String>,
) -> Result<Vec<TraceErrors>, JobError> {
    let per_trace = s.owners.iter().any(Option::is_some);
    (0..s.names.len())
        .map(|ti| {
            let which = segments_of(s, ti);
            let label = format!("trace {}: ", s.names[ti]);
            let plausibility = if per_trace {
                plausibility_of(s, sims, &which, theta, o, &label, warnings)?
            } else {
                None
            };
            let own: Vec<Noise> = noise
                .iter()
                .zip(&mult.traces[ti])
                .map(|(n, m)| Noise {
                    band_multiplier: m.value,
                    band_quantile: m.kind(),
                    ..n.clone()
                })
                .collect();
            Ok(TraceErrors {
                name: s.names[ti].clone(),
                source: s.sources[ti].clone(),
                index: ti,
                segments: which.iter().map(|&k| s.segments[k].index).collect(),
                rows: which.iter().map(|&k| s.segments[k].held.len()).sum(),
                channels: channel_table(s, rows, &which, &own, known),
                plausibility,
            })
        })
        .collect()
}

/// The residual process of each channel: the fit's, or with `--band-from` the calibration's
/// (in the stack's channel order); without either, independent errors of variance σ².
fn channel_noise(s: &Stack<'_>, f: &Fitted, sigma2: f64) -> Vec<Ar1> {
    if let Some(b) = s.bands.first() {
        return s.segments[0].perm.iter().map(|&c| b.noise[c]).collect();
    }
    f.noise.clone().unwrap_or_else(|| {
        vec![
            Ar1 {
                phi: 0.0,
                sigma: sigma2.sqrt()
            };
            s.nodes.len()
        ]
    })
}

/// The calibrated model texts: `calibrated.toml` (every parameter shared) or one per trace.
fn model_texts(
    s: &Stack<'_>,
    m: &Model,
    theta: &[f64],
    comment: &str,
) -> Result<(String, Vec<(String, String)>), JobError> {
    if !s.owners.iter().any(Option::is_some) {
        return Ok((model_text(s, m, theta, None, comment)?, Vec::new()));
    }
    let models = (0..s.names.len())
        .map(|ti| {
            Ok((
                format!("calibrated_{}.toml", file_safe(&s.names[ti])),
                model_text(s, m, theta, Some(ti), comment)?,
            ))
        })
        .collect::<Result<Vec<_>, JobError>>()?;
    Ok((String::new(), models))
}

fn assemble(
    m: &Model,
    s: &Stack<'_>,
    o: &CalibrateOptions,
    f: &Fitted,
    eval: &dyn Fn(&[f64]) -> Result<Evaluation, JobError>,
    clock: Instant,
) -> Result<CalibrateResult, JobError> {
    let res = &f.res;
    let bounds: Vec<(f64, f64)> = s.params.iter().map(Parameter::theta_bounds).collect();
    let ident = identifiable(&res.theta, &bounds, &f.free);
    let (mut lin, data_se) = super::statistics(f, &ident);
    if !s.priors.is_empty() {
        stats::posterior(&mut lin, &s.priors.information(&s.params, &res.theta));
    }
    let t = stats::t975(lin.dof);
    let mut warnings = first_warnings(s, res);
    let mut params = parameters(&s.params, f, &ident, &lin, t, &mut warnings);
    prior_influence(&s.priors, &s.params, f, &data_se, &mut params);
    let correlation = correlation(&s.params, &lin, &mut warnings);
    let identifiability = identifiability(&s.params, &lin, t, &mut warnings);
    let sims = final_sims(s, &res.theta)?;
    let fit_noise = f.noise.clone().unwrap_or_else(|| channel_noise(s, f, lin.sigma2));
    let sds = residual_sds(s, &sims, &lin.covariance, &fit_noise);
    let mult = multipliers(s, &sds, &fit_noise, t, o);
    let rows = residual_rows(s, sds, &mult);
    let known = !f.layout.stretch.is_empty() || !s.bands.is_empty();
    let ar = channel_noise(s, f, lin.sigma2);
    let noise = noise_table(f, &ar, &mult.all);
    let all: Vec<usize> = (0..s.segments.len()).collect();
    let channels = channel_table(s, &rows, &all, &noise, known);
    let plausibility = if s.owners.iter().any(Option::is_some) {
        None
    } else {
        plausibility_of(s, &sims, &all, &res.theta, o, "", &mut warnings)?
    };
    let traces = trace_reports(
        s,
        &sims,
        &rows,
        (&noise, known, &mult),
        o,
        &res.theta,
        &mut warnings,
    )?;
    let profiles = profiles_of(s, f, eval, &fit_noise, &lin, &mut warnings)?;
    let covariance: Vec<Vec<Option<f64>>> = lin
        .covariance
        .iter()
        .map(|row| row.iter().map(|&x| x.is_finite().then_some(x)).collect())
        .collect();
    let comment = model_file::covariance_comment(&params, &covariance);
    let (calibrated, per_trace_models) = model_texts(s, m, &res.theta, &comment)?;
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
        profiles,
        plausibility,
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
