//! Outputs of a calibration: `calibration.json` (fitted values with 95 % intervals, correlation
//! matrix, errors per channel on the fitted and the held-out rows, warnings) and `fit.csv`
//! (measured and simulated temperatures and residuals at every trace row).

use serde::Serialize;

/// A fitted parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedParameter {
    /// Key path in the model.
    pub key_path: String,
    /// Value before the fit (the model's, or the mean of the bounds).
    pub start: f64,
    /// Fitted value.
    pub value: f64,
    /// Lower bound.
    pub lower_bound: f64,
    /// Upper bound.
    pub upper_bound: f64,
    /// `log` (fitted on ln p) or `linear`.
    pub scale: &'static str,
    /// Standard error in the fitted coordinate (ln p or p); null when not identifiable.
    pub std_error: Option<f64>,
    /// 95 % interval, lower end (through the coordinate: asymmetric on a log scale).
    pub ci95_low: Option<f64>,
    /// 95 % interval, upper end.
    pub ci95_high: Option<f64>,
    /// The 95 % interval of an ordinary least-squares fit with independent errors (the
    /// residual model `independent`), lower end: reported beside for comparison.
    pub ci95_independent_low: Option<f64>,
    /// Its upper end.
    pub ci95_independent_high: Option<f64>,
    /// Largest change of a fitted temperature per unit of the coordinate, K.
    pub influence_k: f64,
    /// The prior on this parameter and its influence (null: none).
    pub prior: Option<PriorInfluence>,
}

/// A prior and how much it moved and narrowed the result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PriorInfluence {
    /// `normal` or `lognormal`.
    pub distribution: &'static str,
    /// Mean (normal) or median (log-normal).
    pub location: f64,
    /// Standard deviation of p (normal) or ln p (log-normal).
    pub width: f64,
    /// The prior's standard deviation in the fitted coordinate at the fitted value.
    pub prior_sd: f64,
    /// Standard error from the data alone at the fitted value (null: the data do not fix it).
    pub data_std_error: Option<f64>,
    /// Posterior standard error (the parameter's `std_error`).
    pub posterior_std_error: Option<f64>,
    /// Posterior over prior standard deviation: near 1 the data add nothing, near 0 the prior
    /// adds little.
    pub width_ratio: Option<f64>,
    /// The prior's share of the posterior precision, 1 − Var_post/Var_data (1 when the data
    /// do not fix the parameter).
    pub prior_share: Option<f64>,
    /// The value the fit without priors gave (least squares).
    pub without_prior: f64,
}

/// The calibrated model's losses at one operating point (or the mean of several).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LossAt {
    /// Input speed, rpm.
    pub input_speed_rpm: f64,
    /// Input torque, N·m (negative: power flows from the output to the input).
    pub input_torque_nm: f64,
    /// Power through the gearbox |T·ω| at the input, W.
    pub power_w: f64,
    /// Oil temperature the losses are evaluated at (the simulated oil), °C.
    pub oil_temp_c: f64,
    /// Loss per source, W.
    pub loss_by_source_w: Vec<(String, f64)>,
    /// Total loss, W.
    pub loss_total_w: f64,
    /// |P|/(|P| + loss).
    pub efficiency: Option<f64>,
}

/// A sourced loss figure for the kind of gearbox, and where the calibrated model lies.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reference {
    /// Gearbox kind (`--gearbox-kind`).
    pub kind: &'static str,
    /// What the source states.
    pub statement: &'static str,
    /// The source.
    pub source: &'static str,
    /// Loss share bounds the warning uses.
    pub loss_share_bounds: (f64, f64),
    /// The calibrated model's loss share (at the rated point when given, else the highest-power rows).
    pub loss_share: f64,
    /// Within the bounds.
    pub inside: bool,
}

/// Losses and efficiency of the calibrated model where they matter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plausibility {
    /// Rows averaged (the highest-power 1 % of the trace).
    pub rows: usize,
    /// Mean over the trace's highest-power rows at their simulated oil temperatures.
    pub highest_power: LossAt,
    /// At the rated point given (`--rated`), at the highest-power rows' mean oil temperature.
    pub rated: Option<LossAt>,
    /// The sourced figure for the gearbox kind (`--gearbox-kind`).
    pub reference: Option<Reference>,
}

/// One point of a profile likelihood.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProfilePoint {
    /// The parameter's value, held.
    pub value: f64,
    /// D = S(value) − S_min, the objective's rise with the other parameters refitted.
    pub statistic: f64,
}

/// The profile likelihood of one parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Profile {
    /// Key path.
    pub key_path: String,
    /// D at the 95 % interval's ends, t(0.975, ν)².
    pub threshold: f64,
    /// The grid, ascending.
    pub points: Vec<ProfilePoint>,
    /// Lower end of the 95 % profile interval (null: not reached within the grid or the bounds).
    pub ci95_low: Option<f64>,
    /// Upper end.
    pub ci95_high: Option<f64>,
    /// Evaluations with sensitivities the profile took.
    pub evaluations: usize,
    /// The objective's drop below the fit's (refitted) optimum at the profile's least point, when
    /// that point is not the fitted value: the fit stopped short along a flat valley.
    pub below_fit: Option<f64>,
}

/// Errors of one measured channel on a set of rows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Errors {
    /// Rows.
    pub rows: usize,
    /// Root-mean-square of simulated − measured, K.
    pub rmse_k: f64,
    /// Largest |simulated − measured|, K.
    pub max_abs_k: f64,
    /// Mean of simulated − measured, K.
    pub bias_k: f64,
    /// Fraction of the measured values inside the 95 % prediction band (null when the run
    /// fitted no rows: the residual process, and so the band, is then unknown).
    pub inside_band95: Option<f64>,
}

impl Errors {
    /// Errors of the residuals `r` with the band half-widths `half` (None when empty).
    pub fn of(r: &[f64], half: Option<&[f64]>) -> Option<Errors> {
        if r.is_empty() {
            return None;
        }
        let n = r.len() as f64;
        let inside = half.map(|h| r.iter().zip(h).filter(|(x, h)| x.abs() <= **h).count() as f64 / n);
        Some(Errors {
            rows: r.len(),
            rmse_k: (r.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
            max_abs_k: r.iter().fold(0.0, |m, x| m.max(x.abs())),
            bias_k: r.iter().sum::<f64>() / n,
            inside_band95: inside,
        })
    }
}

/// The residual process of one channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Noise {
    /// AR(1) coefficient φ (0 for the residual model `independent`).
    pub phi: f64,
    /// Innovation standard deviation, K.
    pub innovation_sd_k: f64,
    /// Stationary standard deviation, K (the residual process's part of the band).
    pub marginal_sd_k: f64,
    /// Autocorrelation of the fitted rows' residuals at lags 1, 2 and 6 rows.
    pub autocorrelation_lag_1_2_6: [Option<f64>; 3],
    /// The 95 % band's half-width over its standard deviation √(sᵀ·Cov·s + σ_a²/(1 − φ²)).
    pub band_multiplier: f64,
    /// How the multiplier was found: `empirical` (the fitted rows' 95 % quantile of
    /// |residual|/sd) or `t` (Student's t(0.975, dof)).
    pub band_quantile: &'static str,
}

/// One measured channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelErrors {
    /// Trace column.
    pub column: String,
    /// Node.
    pub node: String,
    /// On the fitted rows.
    pub fitted: Option<Errors>,
    /// On the held-out rows.
    pub holdout: Option<Errors>,
    /// The residual process.
    pub noise: Noise,
}

/// The correlation matrix of the fitted coordinates.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Correlation {
    /// Parameter key paths (rows and columns).
    pub parameters: Vec<String>,
    /// r_ij (null where undefined: a parameter not identifiable).
    pub matrix: Vec<Vec<Option<f64>>>,
}

/// One parameter's part in an eigen-direction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Component {
    /// Key path.
    pub key_path: String,
    /// Component in the fitted coordinate (ln p or p), the largest ±1.
    pub component: f64,
}

/// An eigen-direction of the scaled Fisher information: how well the trace fixes a step along it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Direction {
    /// `not determined` (null), `weakly determined` or `determined`.
    pub status: &'static str,
    /// λ/λ_max of the scaled information.
    pub relative_eigenvalue: f64,
    /// The direction (components above 0.05 only).
    pub components: Vec<Component>,
    /// 95 % half-width of the step along the direction (null: none).
    pub ci95_half_width: Option<f64>,
}

/// How the fit went.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitStats {
    /// Evaluations with sensitivities.
    pub evaluations: usize,
    /// Accepted steps.
    pub iterations: usize,
    /// Why it stopped.
    pub stop: String,
    /// Residual model: `ar1` or `independent`.
    pub residual_model: String,
    /// Residual standard deviation, K: √(SSR/(m − P)) with independent errors; with AR(1)
    /// errors the root-mean-square of the channels' stationary standard deviations.
    pub sigma_k: f64,
    /// √(SSR/dof) of the residuals the intervals use (K with independent errors; the whitened,
    /// dimensionless residuals with AR(1) errors, about 1 when the model fits).
    pub scale: f64,
    /// Degrees of freedom of the t quantile: m − P with independent errors; with AR(1) errors
    /// the effective number of independent residuals less the parameters (at most m − P − channels).
    pub dof: usize,
    /// Student's t(0.975, dof).
    pub t975: f64,
    /// Relative and absolute tolerance of the integration.
    pub rtol: f64,
    /// Absolute tolerance, K.
    pub atol: f64,
    /// Wall time, s.
    pub wall_time_s: f64,
}

/// `calibration.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CalibrationSummary {
    /// Model name.
    pub model: String,
    /// Trace source.
    pub trace: String,
    /// Trace rows.
    pub rows: usize,
    /// Held-out time windows, s.
    pub holdout_s: Vec<(f64, f64)>,
    /// Fitted parameters.
    pub parameters: Vec<FittedParameter>,
    /// Their covariance in the fitted coordinates (ln p or p; null where undefined).
    pub covariance: Vec<Vec<Option<f64>>>,
    /// Their correlations.
    pub correlation: Correlation,
    /// The eigen-directions of the scaled Fisher information, least determined first.
    pub identifiability: Vec<Direction>,
    /// Errors per measured channel.
    pub channels: Vec<ChannelErrors>,
    /// The fit.
    pub fit: FitStats,
    /// Profile likelihoods asked for (`--profile`).
    pub profiles: Vec<Profile>,
    /// Losses and efficiency of the calibrated model (null: a vehicle trace or the oil not measured).
    pub plausibility: Option<Plausibility>,
    /// What the user should know: pairs the trace cannot tell apart, parameters without
    /// influence or at a bound, a fit that ran out of iterations.
    pub warnings: Vec<String>,
    /// A fit over several traces (or segments): per trace its segments and its errors per
    /// channel (empty for a fit of one segment).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub traces: Vec<TraceErrors>,
}

/// One trace of a fit over several traces: its segments and its errors per channel (the
/// residual process is that of every trace together, in [`CalibrationSummary::channels`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TraceErrors {
    /// The trace's name (`KEYPATH@NAME` names its own parameters).
    pub name: String,
    /// Its file (or the name given to its text).
    pub source: String,
    /// Its index among the traces (`KEYPATH@INDEX`).
    pub index: usize,
    /// The segments of its file fitted (0-based, as `geartherm trace` lists them).
    pub segments: Vec<usize>,
    /// Rows over those segments.
    pub rows: usize,
    /// Errors per measured channel (its `noise` is the common residual process's).
    pub channels: Vec<ChannelErrors>,
    /// With parameters of one trace: the trace's calibrated model's losses at its
    /// highest-power rows (and at the rated point).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plausibility: Option<Plausibility>,
}

/// `fit.csv`: `time_s,holdout`, then per channel `<node>_measured_c,<node>_simulated_c,
/// <node>_residual_k,<node>_band95_k` (the half-width of the 95 % prediction band).
pub fn fit_csv(
    times: &[f64],
    holdout: &[bool],
    nodes: &[String],
    measured: &[Vec<f64>],
    simulated: &[Vec<f64>],
    band: &[Vec<f64>],
) -> String {
    let mut s = String::from("time_s,holdout");
    for n in nodes {
        s.push_str(&format!(
            ",{n}_measured_c,{n}_simulated_c,{n}_residual_k,{n}_band95_k"
        ));
    }
    s.push('\n');
    for (r, t) in times.iter().enumerate() {
        s.push_str(&format!("{t},{}", u8::from(holdout[r])));
        for c in 0..nodes.len() {
            let (m, x) = (measured[c][r], simulated[r][c]);
            s.push_str(&format!(",{m},{x:.6},{:.6},{:.6}", x - m, band[r][c]));
        }
        s.push('\n');
    }
    s
}

/// The errors per trace of a fit over several (empty for one segment).
fn trace_table(s: &CalibrationSummary) -> String {
    let mut t = String::new();
    if s.traces.is_empty() {
        return t;
    }
    let e = |x: &Option<Errors>| {
        x.map_or("—".to_string(), |e| {
            let band = e
                .inside_band95
                .map_or("—".into(), |f| format!("{:.1} %", 100.0 * f));
            format!("{:.3} / {:.3} / {band}", e.rmse_k, e.max_abs_k)
        })
    };
    t.push_str(
        "trace, channel            segments    rows   fitted rmse / max, K / in band   held-out rmse / max, K / in band   \
         band ×\n",
    );
    for tr in &s.traces {
        for c in &tr.channels {
            t.push_str(&format!(
                "  {} {}: {}, {:>8} {:>6} {:>32} {:>34}   {}\n",
                tr.index,
                tr.name,
                c.node,
                tr.segments.len(),
                tr.rows,
                e(&c.fitted),
                e(&c.holdout),
                multiplier(&c.noise)
            ));
        }
    }
    t
}

/// A channel's band multiplier and how it was found: `1.823 (empirical)`, `1.972 (t)`.
fn multiplier(n: &Noise) -> String {
    format!("{:.3} ({})", n.band_multiplier, n.band_quantile)
}

/// The calibrated losses at the highest-power rows and the rated point, each line starting
/// with `label`.
fn plausibility_text(label: &str, p: &Plausibility) -> String {
    let mut t = String::new();
    let line = |what: &str, x: &LossAt| {
        let by: Vec<String> = x
            .loss_by_source_w
            .iter()
            .map(|(k, v)| format!("{k} {:.1}", v / 1e3))
            .collect();
        format!(
            "{label}{what}: {:.0} kW at {:.0} rpm, {:.0} N m, oil {:.1} °C: loss {:.1} kW ({}), efficiency {}\n",
            x.power_w / 1e3,
            x.input_speed_rpm,
            x.input_torque_nm,
            x.oil_temp_c,
            x.loss_total_w / 1e3,
            by.join(", "),
            x.efficiency.map_or("—".into(), |e| format!("{e:.4}"))
        )
    };
    t.push_str(&line(
        &format!("highest-power rows ({})", p.rows),
        &p.highest_power,
    ));
    if let Some(r) = &p.rated {
        t.push_str(&line("rated point", r));
    }
    if let Some(r) = &p.reference {
        t.push_str(&format!(
            "  {label}{} gearbox: {} ({}); the model: {:.2} % ({})\n",
            r.kind,
            r.statement,
            r.source,
            100.0 * r.loss_share,
            if r.inside { "within" } else { "OUTSIDE" }
        ));
    }
    t
}

/// Human-readable summary.
pub fn to_text(s: &CalibrationSummary) -> String {
    let mut t = format!(
        "{} on {} ({} rows): {} evaluations, {} steps accepted, stopped on {}, σ = {:.3} K ({} dof), {:.2} s\n",
        s.model, s.trace, s.rows, s.fit.evaluations, s.fit.iterations, s.fit.stop, s.fit.sigma_k, s.fit.dof,
        s.fit.wall_time_s
    );
    if !s.parameters.is_empty() {
        t.push_str(&format!(
            "parameter                                   start        fitted     95 % interval ({} residuals)    \
             [independent errors]\n",
            s.fit.residual_model
        ));
    }
    for p in &s.parameters {
        let ci = |lo: Option<f64>, hi: Option<f64>| match (lo, hi) {
            (Some(a), Some(b)) => format!("[{a:.5}, {b:.5}]"),
            _ => "not identifiable".into(),
        };
        let ind = match (p.ci95_independent_low, p.ci95_independent_high) {
            (None, None) => String::new(),
            (a, b) => format!("   {}", ci(a, b)),
        };
        t.push_str(&format!(
            "  {:<40} {:>10.5} {:>12.5}   {}{ind}\n",
            p.key_path,
            p.start,
            p.value,
            ci(p.ci95_low, p.ci95_high)
        ));
    }
    for p in &s.parameters {
        if let Some(q) = &p.prior {
            let opt = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or("—".to_string(), f);
            t.push_str(&format!(
                "  prior {} {}({}, {}): posterior/prior width {}, prior's share of the precision {}, \
                 without the prior {:.5}\n",
                p.key_path,
                q.distribution,
                q.location,
                q.width,
                opt(q.width_ratio, &|v| format!("{v:.3}")),
                opt(q.prior_share, &|v| format!("{:.1} %", 100.0 * v)),
                q.without_prior
            ));
        }
    }
    t.push_str(
        "channel          fitted rmse / max, K / in band   held-out rmse / max, K / in band   \
         φ     σ_a, K  acf lag 1, 2, 6      band ×\n",
    );
    for c in &s.channels {
        let e = |x: &Option<Errors>| {
            x.map_or("—".to_string(), |e| {
                let band = e
                    .inside_band95
                    .map_or("—".into(), |f| format!("{:.1} %", 100.0 * f));
                format!("{:.3} / {:.3} / {band}", e.rmse_k, e.max_abs_k)
            })
        };
        let acf: Vec<String> = c
            .noise
            .autocorrelation_lag_1_2_6
            .iter()
            .map(|a| a.map_or("—".into(), |v| format!("{v:.3}")))
            .collect();
        t.push_str(&format!(
            "  {:<14} {:>32} {:>34}   {:.3} {:.3}  {:<19}  {}\n",
            c.node,
            e(&c.fitted),
            e(&c.holdout),
            c.noise.phi,
            c.noise.innovation_sd_k,
            acf.join(", "),
            multiplier(&c.noise)
        ));
    }
    t.push_str(&trace_table(s));
    for d in s.identifiability.iter().filter(|d| d.status != "determined") {
        let along: Vec<String> = d
            .components
            .iter()
            .map(|c| format!("{:+.3} {}", c.component, c.key_path))
            .collect();
        let half = d.ci95_half_width.map_or("none".into(), |h| format!("±{h:.3}"));
        t.push_str(&format!(
            "{}: direction ({}), relative eigenvalue {:.1e}, 95 % step {half}\n",
            d.status,
            along.join(", "),
            d.relative_eigenvalue
        ));
    }
    if let Some(p) = &s.plausibility {
        t.push_str(&plausibility_text("", p));
    }
    for tr in &s.traces {
        if let Some(p) = &tr.plausibility {
            t.push_str(&plausibility_text(&format!("trace {}: ", tr.name), p));
        }
    }
    for p in &s.profiles {
        let end = |x: Option<f64>| x.map_or("beyond the grid".to_string(), |v| format!("{v:.5}"));
        t.push_str(&format!(
            "profile {}: 95 % interval [{}, {}] (D ≤ {:.3}; {} points, {} evaluations)\n",
            p.key_path,
            end(p.ci95_low),
            end(p.ci95_high),
            p.threshold,
            p.points.len(),
            p.evaluations
        ));
    }
    t
}
