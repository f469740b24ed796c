//! Several traces in one fit (docs/calibration.md, "Several traces"): every segment of every
//! trace file (a gap in time starts a new segment) is a problem of its own, started from its own
//! measured temperatures, with its own boundary series; the fit's residual vector stacks their
//! fitted rows, and its parameters are shared by every trace (`KEYPATH[=LO:HI]`) or belong to
//! one trace (`KEYPATH@TRACE[=LO:HI]`, TRACE its 0-based index or its name; `KEYPATH@*` one
//! parameter per trace). The segments are independent given the parameters: [`Stack::evaluate`]
//! integrates them in parallel (rayon), [`Stack::evaluate_segment`] one of them (a Dask worker's
//! share, `python/pysrc/geartherm/calibration.py`).

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::model::Override;
use crate::solve::sensitivity::SensitivityOptions;

use super::lm::Evaluation;
use super::params::{canonical, split_bounds, split_owner, FitSpec, Parameter};
use super::prior::{PriorSpec, Priors};
use super::problem::{initial_overrides, Problem};
use super::residuals::Layout;
use super::trace_file::TraceFile;
use super::{checks, document, CalibrateOptions};
use crate::job::{JobError, Model};
use crate::model::overrides::KeyPath;

/// One trace of a fit over several: its name (`KEYPATH@NAME`), its file cut into segments and
/// the segments fitted (0-based).
pub struct TraceInput<'a> {
    /// Its name (a file's stem, or the name given to its text).
    pub name: String,
    /// The file.
    pub file: &'a TraceFile,
    /// The segments fitted.
    pub segments: Vec<usize>,
}

/// The segments of `--segment SPEC` for a file of `n` segments: `all`, or `K1,K2,…` (0-based,
/// each once). `trace` is the trace's name (the CLI and Python name a trace file alike by its
/// stem; their sources differ: a path, or the name Python was given).
pub fn segment_list(spec: &str, n: usize, trace: &str) -> Result<Vec<usize>, JobError> {
    let allowed = format!("all, or K1,K2,… in 0 … {}", n.saturating_sub(1));
    let bad = |msg: String| JobError::option("segment", spec, allowed.clone(), msg);
    if spec.trim() == "all" {
        return Ok((0..n).collect());
    }
    let mut out: Vec<usize> = Vec::new();
    for part in spec.split(',').map(str::trim).filter(|x| !x.is_empty()) {
        let k: usize = part
            .parse()
            .map_err(|_| bad(format!("segment = {spec}: \"{part}\" is not a segment number")))?;
        if k >= n {
            return Err(bad(format!(
                "segment = {spec}: {k} must lie in [0, {}] (trace {trace} has {n} segment(s))",
                n.saturating_sub(1)
            )));
        }
        if out.contains(&k) {
            return Err(bad(format!("segment = {spec}: segment {k} is named twice")));
        }
        out.push(k);
    }
    if out.is_empty() {
        return Err(bad(format!(
            "segment = {spec}: an empty segment list: name one or more segments, or all"
        )));
    }
    Ok(out)
}

/// The traces of a fit over several: `files` (name, file) in order; with one file the segments
/// `o.segments` selects, with several every segment of each (`--segment` refused).
pub fn inputs<'a>(
    files: &'a [(String, TraceFile)],
    o: &CalibrateOptions,
) -> Result<Vec<TraceInput<'a>>, JobError> {
    if files.len() > 1 {
        if let Some(k) = o.segment.map(|k| k.to_string()).or_else(|| o.segments.clone()) {
            let msg = format!(
                "segment = {k}: with several traces every segment of each is fitted; --segment selects \
                 segments of one trace"
            );
            return Err(JobError::option(
                "segment",
                &k,
                "no --segment with several traces",
                msg,
            ));
        }
    }
    files
        .iter()
        .map(|(name, file)| {
            let segments = match &o.segments {
                Some(spec) if files.len() == 1 => segment_list(spec, file.segments.len(), name)?,
                _ => (0..file.segments.len()).collect(),
            };
            Ok(TraceInput {
                name: name.clone(),
                file,
                segments,
            })
        })
        .collect()
}

/// Whose value a `--fit` argument is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Owner {
    /// One value for every trace.
    Shared,
    /// The value of one trace (its index).
    One(usize),
    /// One value per trace (`@*`).
    Each,
}

/// One segment of one trace, mapped onto the model.
pub struct StackSegment<'a> {
    /// Index of its trace.
    pub trace: usize,
    /// Its index among its file's segments.
    pub index: usize,
    /// Time of its first row in its file, s.
    pub offset_s: f64,
    /// Its problem (its parameters: the shared ones and its trace's own).
    pub problem: Problem<'a>,
    /// Index among the stack's parameters of each of its problem's parameters.
    pub map: Vec<usize>,
    /// Per row: held out.
    pub held: Vec<bool>,
    /// Column of its trace's measured columns of each channel of the stack.
    pub perm: Vec<usize>,
}

/// The residuals and their Jacobian of one segment's fitted rows (`j` row-major, one column per
/// parameter of the stack).
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentEval {
    /// Residuals, K, fitted rows × channels.
    pub r: Vec<f64>,
    /// Jacobian, K per unit coordinate.
    pub j: Vec<f64>,
}

/// Several traces' segments in one fit.
pub struct Stack<'a> {
    /// The traces' names.
    pub names: Vec<String>,
    /// The traces' sources (files).
    pub sources: Vec<String>,
    /// The parameters (shared ones with `owner` None).
    pub params: Vec<Parameter>,
    /// The trace of each parameter (None: shared).
    pub owners: Vec<Option<usize>>,
    /// The segments, trace by trace.
    pub segments: Vec<StackSegment<'a>>,
    /// The measured node of each channel, and its column.
    pub nodes: Vec<(String, String)>,
    /// Held-out windows, s in each file's own time.
    pub windows: Vec<(f64, f64)>,
    /// Model text.
    pub text: &'a str,
    /// The command's overrides (`--set`).
    pub base: Vec<Override>,
    /// The priors (a MAP fit when not empty).
    pub priors: Priors,
    /// Index of each parameter whose profile is computed.
    pub profile: Vec<usize>,
    /// Per segment, the previous calibration its prediction band is taken from
    /// (`--band-from`; empty: the band is this fit's own).
    pub bands: Vec<super::transfer::BandSource<'a>>,
}

fn fit_error(arg: &str, allowed: &str, msg: String) -> JobError {
    JobError::option("fit", arg, allowed, msg)
}

/// Parse `KEYPATH[@TRACE][=LO:HI]` against the traces' names.
pub fn parse_fit(arg: &str, names: &[String]) -> Result<(FitSpec, Owner), JobError> {
    let allowed = "KEYPATH[@TRACE][=LO:HI], TRACE a trace's 0-based index, its name or *";
    let (path, bounds) = split_bounds(arg.trim());
    let (key, owner) = split_owner(path);
    let spec_text = match bounds {
        Some(b) => format!("{}={b}", key.trim()),
        None => key.trim().to_string(),
    };
    let spec: FitSpec = spec_text
        .parse()
        .map_err(|e: String| fit_error(arg, allowed, e))?;
    let Some(owner) = owner.map(str::trim) else {
        return Ok((spec, Owner::Shared));
    };
    let owner = owner_of(owner, names, &format!("fit = {arg}"))
        .map_err(|(msg, allowed_here)| fit_error(arg, allowed_here.unwrap_or(allowed), msg))?;
    Ok((spec, owner))
}

/// The trace `owner` names (`*`, an index or a name) among `names`; the message (starting with
/// `what`) and, for one trace only, the allowed form.
fn owner_of(owner: &str, names: &[String], what: &str) -> Result<Owner, (String, Option<&'static str>)> {
    let n = names.len();
    if n < 2 {
        let msg = format!(
            "{what}: @{owner} names a trace, but one trace is fitted: a parameter of one trace needs \
             several --trace"
        );
        return Err((msg, Some("KEYPATH[=LO:HI] with one trace")));
    }
    if owner == "*" {
        return Ok(Owner::Each);
    }
    match owner.parse::<usize>() {
        Ok(i) if i < n => Ok(Owner::One(i)),
        Ok(i) => Err((
            format!(
                "{what}: trace {i} does not exist: the traces are 0 … {} ({})",
                n - 1,
                names.join(", ")
            ),
            None,
        )),
        Err(_) => names
            .iter()
            .position(|x| x == owner)
            .map(Owner::One)
            .ok_or_else(|| {
                (
                    format!(
                        "{what}: no trace is named \"{owner}\" (traces: {})",
                        names.join(", ")
                    ),
                    None,
                )
            }),
    }
}

/// The stack's parameters a `KEYPATH[@TRACE]` names (several for `@*`): `what` starts the
/// message of a key that is not fitted (so, or not for that trace).
fn owned_params(
    path: &KeyPath,
    owner: Option<&str>,
    s: (&[Parameter], &[Option<usize>], &[String]),
    doc: &toml::Table,
    what: &str,
) -> Result<Vec<usize>, String> {
    let (params, owners, names) = s;
    let owner = match owner {
        None => Owner::Shared,
        Some(o) => owner_of(o.trim(), names, what).map_err(|e| e.0)?,
    };
    let c = canonical(path, doc);
    let out: Vec<usize> = (0..params.len())
        .filter(|&q| canonical(&params[q].path, doc) == c)
        .filter(|&q| match owner {
            Owner::Shared => owners[q].is_none(),
            Owner::One(i) => owners[q] == Some(i),
            Owner::Each => owners[q].is_some(),
        })
        .collect();
    if out.is_empty() {
        let fitted: Vec<String> = params.iter().map(Parameter::name).collect();
        let whose = match owner {
            Owner::Shared => "a parameter shared by every trace".to_string(),
            Owner::One(i) => format!("a parameter of trace {} ({i})", names[i]),
            Owner::Each => "a parameter of each trace".to_string(),
        };
        return Err(format!(
            "{what}: {path} is not fitted as {whose} (fitted: {})",
            fitted.join(", ")
        ));
    }
    Ok(out)
}

/// The priors of a fit over several traces: `KEYPATH[@TRACE]=DIST:…`, each on the parameters
/// its key path and trace name (`@*`: the parameter of every trace).
fn resolve_priors(
    specs: &[PriorSpec],
    s: (&[Parameter], &[Option<usize>], &[String]),
    doc: &toml::Table,
) -> Result<Priors, JobError> {
    let mut out = Priors::default();
    for spec in specs {
        let what = format!("prior = {}", spec.text);
        let which = owned_params(&spec.path, spec.owner.as_deref(), s, doc, &what)
            .map_err(|e| Priors::refuse(spec, e.trim_start_matches(&format!("{what}: "))))?;
        for q in which {
            out.add(spec, q, &s.0[q])?;
        }
    }
    Ok(out)
}

/// The parameters of `--profile KEYPATH[@TRACE]` (each once).
fn resolve_profile(
    keys: &[String],
    s: (&[Parameter], &[Option<usize>], &[String]),
    doc: &toml::Table,
) -> Result<Vec<usize>, JobError> {
    let mut out = Vec::new();
    for k in keys {
        let what = format!("profile = {k}");
        let bad = |m: String| JobError::option("profile", k, "the key path of a fitted parameter[@TRACE]", m);
        let (path, owner) = split_owner(k.trim());
        let path: KeyPath = path
            .trim()
            .parse()
            .map_err(|e| bad(format!("{what}: bad key path: {e}")))?;
        for q in owned_params(&path, owner, s, doc, &what).map_err(bad)? {
            if !out.contains(&q) {
                out.push(q);
            }
        }
    }
    Ok(out)
}

/// The stack's parameters (each `@*` expanded into one per trace), resolved against `doc`,
/// each number fitted once per trace whatever its spelling.
fn resolve_params(
    args: &[String],
    names: &[String],
    doc: &toml::Table,
) -> Result<(Vec<Parameter>, Vec<Option<usize>>), JobError> {
    let mut out: Vec<(String, Parameter, Option<usize>, String)> = Vec::new();
    for arg in args {
        let (spec, owner) = parse_fit(arg, names)?;
        let owners: Vec<Option<usize>> = match owner {
            Owner::Shared => vec![None],
            Owner::One(i) => vec![Some(i)],
            Owner::Each => (0..names.len()).map(Some).collect(),
        };
        let key = canonical(&spec.path, doc).to_string();
        for o in owners {
            let clash = out
                .iter()
                .find(|(k, _, w, _)| *k == key && (w.is_none() || o.is_none() || *w == o));
            if let Some((_, _, _, first)) = clash {
                let msg = format!(
                    "fit = {arg}: {} is already fitted by fit = {first} (a key is fitted once for every \
                     trace, or once per trace)",
                    spec.path
                );
                return Err(fit_error(arg, "each key path once per trace", msg));
            }
            let mut p =
                Parameter::resolve(&spec, doc).map_err(|e| fit_error(arg, "a number in the model", e))?;
            p.owner = o.map(|i| names[i].clone());
            out.push((key.clone(), p, o, arg.clone()));
        }
    }
    Ok(out.into_iter().map(|(_, p, o, _)| (p, o)).unzip())
}

/// The traces' names once each and their files once each, each trace with a segment.
fn check_traces(traces: &[TraceInput<'_>]) -> Result<(), JobError> {
    if traces.is_empty() {
        let msg = "trace: no trace given: name at least one".to_string();
        return Err(JobError::option("trace", "", "one or more trace files", msg));
    }
    for (i, t) in traces.iter().enumerate() {
        if let Some(j) = traces[..i].iter().position(|u| u.file.source == t.file.source) {
            let msg = format!(
                "trace = {}: given twice (traces {j} and {i}): each file once",
                t.file.source
            );
            return Err(JobError::option(
                "trace",
                &t.file.source,
                "each trace file once",
                msg,
            ));
        }
        if let Some(j) = traces[..i].iter().position(|u| u.name == t.name) {
            let msg = format!(
                "trace = {}: its name \"{}\" is that of trace {j} ({}): traces need distinct names (KEYPATH@NAME)",
                t.file.source, t.name, traces[j].file.source
            );
            return Err(JobError::option(
                "trace",
                &t.file.source,
                "traces of distinct names",
                msg,
            ));
        }
        if t.segments.is_empty() {
            let msg = format!(
                "segment: no segment of {} is selected: select one or more",
                t.file.source
            );
            return Err(JobError::option("segment", "", "one or more segments", msg));
        }
        let n = t.file.segments.len();
        if let Some(&k) = t.segments.iter().find(|&&k| k >= n) {
            let msg = format!(
                "segment = {k}: must lie in [0, {}] ({} has {n} segment(s))",
                n.saturating_sub(1),
                t.file.source
            );
            return Err(JobError::option(
                "segment",
                k,
                format!("0 … {}", n.saturating_sub(1)),
                msg,
            ));
        }
    }
    Ok(())
}

/// Position in `trace`'s measured columns of each of `nodes` (the same set, any order).
fn channel_perm(nodes: &[(String, String)], pr: &Problem<'_>, first: &str) -> Result<Vec<usize>, JobError> {
    let have: Vec<&str> = pr.trace.measured.iter().map(|c| c.name.as_str()).collect();
    let perm: Vec<Option<usize>> = nodes
        .iter()
        .map(|(n, _)| have.iter().position(|h| h == n))
        .collect();
    if have.len() == nodes.len() && perm.iter().all(Option::is_some) {
        return Ok(perm.into_iter().flatten().collect());
    }
    let cols = |v: Vec<String>| v.join(", ");
    Err(JobError::option(
        "trace",
        &pr.trace.source,
        "traces measuring the same nodes",
        format!(
            "trace = {}: measures {}, {first} measures {}: traces fitted together must measure the same nodes",
            pr.trace.source,
            cols(pr.trace.measured.iter().map(|c| c.column.clone()).collect()),
            cols(nodes.iter().map(|(_, c)| c.clone()).collect())
        ),
    ))
}

/// The columns of a trace's header besides its measured ones: its cycle's and its boundaries'.
fn input_columns(t: &super::Trace) -> Vec<String> {
    use crate::cycle::CycleKind;
    let mut cols: Vec<String> = match (t.cycle.kind, t.cycle.has_gear) {
        (CycleKind::Rig, _) => vec!["input_speed_rpm".into(), "input_torque_nm".into(), "gear".into()],
        (CycleKind::Vehicle, true) => vec!["speed_kmh".into(), "gear".into()],
        (CycleKind::Vehicle, false) => vec!["speed_kmh".into()],
    };
    cols.extend(t.boundaries.iter().map(|c| c.column.clone()));
    cols
}

/// Traces fitted together have the same input and boundary columns (in any order): a column one
/// trace has and another lacks is invalid input naming both files and the column.
fn same_columns(first: &super::Trace, this: &super::Trace) -> Result<(), JobError> {
    let (a, b) = (input_columns(first), input_columns(this));
    let missing = a
        .iter()
        .find(|c| !b.contains(c))
        .map(|c| (c, &first.source, &this.source));
    let extra = b
        .iter()
        .find(|c| !a.contains(c))
        .map(|c| (c, &this.source, &first.source));
    let Some((col, has, lacks)) = missing.or(extra) else {
        return Ok(());
    };
    Err(JobError::option(
        "trace",
        &this.source,
        "traces with the same columns",
        format!(
            "trace = {}: column {col} is in {has}, not in {lacks}: traces fitted together must have the same \
             columns (cycle, boundary:NAME and node:NAME)",
            this.source
        ),
    ))
}

/// The model at a segment's start checks, its boundary columns lie in the model file's range and
/// its measured values in the physics envelope.
fn check_segment(m: &Model, problem: &Problem<'_>) -> Result<(), JobError> {
    problem.gearbox_at(&problem.start())?;
    checks::boundaries_in_model_range(m, problem)?;
    checks::measured_in_envelope(m, problem)
}

/// Check the options and the traces and map every segment onto the model: every invalid input
/// fails here (exit 1), before any fit.
pub fn prepare<'a>(
    m: &Model,
    text: &'a str,
    traces: &[TraceInput<'a>],
    o: &CalibrateOptions,
) -> Result<Stack<'a>, JobError> {
    check_traces(traces)?;
    let mut plain = o.clone();
    plain.fit.clear();
    let (_, windows, prior_specs) = plain.check()?;
    let names: Vec<String> = traces.iter().map(|t| t.name.clone()).collect();
    let doc = document(m, text, &m.overrides)?;
    let (params, owners) = resolve_params(&o.fit, &names, &doc)?;
    let priors = resolve_priors(&prior_specs, (&params, &owners, &names), &doc)?;
    let profile = resolve_profile(&o.profile, (&params, &owners, &names), &doc)?;
    let opts = SensitivityOptions {
        rtol: o.rtol,
        atol: o.atol,
        max_steps: o.max_steps,
        initial: None,
    };
    let mut segments = Vec::new();
    let mut nodes: Vec<(String, String)> = Vec::new();
    for (ti, t) in traces.iter().enumerate() {
        for &k in &t.segments {
            let seg = &t.file.segments[k];
            let map: Vec<usize> = (0..params.len())
                .filter(|&q| owners[q].map_or(true, |w| w == ti))
                .collect();
            let local = map.iter().map(|&q| params[q].clone()).collect();
            let mut base = m.overrides.clone();
            if o.initial_from_trace {
                base.extend(initial_overrides(&seg.trace));
            }
            let problem = Problem::new(m, text, &seg.trace, local, base, opts.clone())?;
            if nodes.is_empty() {
                nodes = seg
                    .trace
                    .measured
                    .iter()
                    .map(|c| (c.name.clone(), c.column.clone()))
                    .collect();
            }
            let perm = channel_perm(&nodes, &problem, &traces[0].file.source)?;
            same_columns(&traces[0].file.segments[traces[0].segments[0]].trace, &seg.trace)?;
            check_segment(m, &problem)?;
            let held = seg
                .trace
                .times
                .iter()
                .map(|&t| {
                    windows
                        .iter()
                        .any(|&(a, b)| (a..=b).contains(&(t + seg.offset_s)))
                })
                .collect();
            segments.push(StackSegment {
                trace: ti,
                index: k,
                offset_s: seg.offset_s,
                problem,
                map,
                held,
                perm,
            });
        }
    }
    let stack = Stack {
        names,
        sources: traces.iter().map(|t| t.file.source.clone()).collect(),
        params,
        owners,
        segments,
        nodes,
        windows,
        text,
        base: m.overrides.clone(),
        priors,
        profile,
        bands: Vec::new(),
    };
    stack.check_size()?;
    Ok(stack)
}

impl<'a> Stack<'a> {
    /// Take every segment's prediction band from a previous calibration (`calibration.json`
    /// text, `file` naming it; trace X's segments with the calibration's parameters of X and
    /// the shared ones): invalid input when this run fits parameters or rows.
    pub fn band_from(&mut self, json: &str, file: &str) -> Result<(), JobError> {
        let fits_rows = self.segments.iter().any(|g| g.held.iter().any(|h| !h));
        if !self.params.is_empty() || fits_rows {
            return Err(JobError::option(
                "band_from",
                file,
                "a run that fits nothing (no fit, every row held out)",
                format!(
                    "band_from = {file}: only for a prediction (no fit, holdout over the whole of every \
                     trace); this run fits its own band"
                ),
            ));
        }
        let mut out = Vec::with_capacity(self.segments.len());
        for g in &self.segments {
            let doc = g.problem.document().clone();
            out.push(super::transfer::band_source(
                &g.problem,
                &doc,
                json,
                file,
                &self.names[g.trace],
            )?);
        }
        self.bands = out;
        Ok(())
    }
}

impl Stack<'_> {
    /// More fitted values than parameters; every trace with a fitted row when it owns a parameter.
    fn check_size(&self) -> Result<(), JobError> {
        let nc = self.nodes.len();
        let fitted: usize = self
            .segments
            .iter()
            .map(|s| s.held.iter().filter(|h| !**h).count() * nc)
            .sum();
        if !self.params.is_empty() && fitted <= self.params.len() {
            return Err(JobError::invalid(format!(
                "{}: {fitted} fitted values (rows outside --holdout × measured columns) for {} parameters: a fit \
                 needs more values than parameters",
                self.sources.join(", "),
                self.params.len()
            )));
        }
        Ok(())
    }

    /// Coordinates of the parameters' start values.
    pub fn start(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.theta(p.start)).collect()
    }

    /// Fitted rows of segment `k`.
    pub fn fitted_rows(&self, k: usize) -> usize {
        self.segments[k].held.iter().filter(|h| !**h).count()
    }

    /// Segment `k`'s coordinates from the stack's θ.
    pub fn local_theta(&self, k: usize, theta: &[f64]) -> Vec<f64> {
        self.segments[k].map.iter().map(|&q| theta[q]).collect()
    }

    /// Segment `k`'s residuals and Jacobian over its fitted rows at θ (the stack's coordinates).
    pub fn evaluate_segment(&self, k: usize, theta: &[f64]) -> Result<SegmentEval, JobError> {
        let s = &self.segments[k];
        let sim = s.problem.simulate(&self.local_theta(k, theta), true)?;
        let (nc, np, nl) = (self.nodes.len(), self.params.len(), s.map.len());
        let mut r = Vec::with_capacity(self.fitted_rows(k) * nc);
        let mut j = Vec::with_capacity(self.fitted_rows(k) * nc * np);
        for row in (0..s.held.len()).filter(|&row| !s.held[row]) {
            for &c in &s.perm {
                r.push(sim.temps_c[row][c] - s.problem.trace.measured[c].values_c[row]);
                let mut line = vec![0.0; np];
                for (l, &q) in s.map.iter().enumerate() {
                    line[q] = sim.sens[row][c * nl + l];
                }
                j.extend(line);
            }
        }
        Ok(SegmentEval { r, j })
    }

    /// Every segment's residuals and Jacobian at θ, in parallel.
    pub fn evaluate_parts(&self, theta: &[f64]) -> Result<Vec<SegmentEval>, JobError> {
        (0..self.segments.len())
            .into_par_iter()
            .map(|k| self.evaluate_segment(k, theta))
            .collect()
    }

    /// The stacked residuals and Jacobian at θ (segments integrated in parallel).
    pub fn evaluate(&self, theta: &[f64]) -> Result<Evaluation, JobError> {
        self.stacked(&self.evaluate_parts(theta)?)
    }

    /// The segments' evaluations stacked (each checked for its size: one computed elsewhere,
    /// by a Dask worker, may not match).
    pub fn stacked(&self, parts: &[SegmentEval]) -> Result<Evaluation, JobError> {
        let (nc, np) = (self.nodes.len(), self.params.len());
        if parts.len() != self.segments.len() {
            return Err(JobError::numerical(format!(
                "{} segment evaluations for {} segments",
                parts.len(),
                self.segments.len()
            )));
        }
        let m: usize = (0..parts.len()).map(|k| self.fitted_rows(k) * nc).sum();
        let (mut r, mut j) = (DVector::zeros(m), DMatrix::zeros(m, np));
        let mut at = 0;
        for (k, e) in parts.iter().enumerate() {
            let n = self.fitted_rows(k) * nc;
            if e.r.len() != n || e.j.len() != n * np {
                return Err(JobError::numerical(format!(
                    "segment {k}: an evaluation of {} residuals for {n} fitted values",
                    e.r.len()
                )));
            }
            for i in 0..n {
                r[at + i] = e.r[i];
                for q in 0..np {
                    j[(at + i, q)] = e.j[i * np + q];
                }
            }
            at += n;
        }
        Ok(Evaluation { r, j })
    }

    /// The residual layout of the stacked vector: a segment, and a held-out window within one,
    /// starts a new stretch (no lag across a gap).
    pub fn layout(&self) -> Layout {
        let nc = self.nodes.len();
        let mut stretch = Vec::new();
        let mut next = 0;
        for s in &self.segments {
            let l = Layout::of(&s.held, nc);
            let n = l.stretch.iter().max().map_or(0, |x| x + 1);
            stretch.extend(l.stretch.iter().map(|x| x + next));
            next += n;
        }
        Layout { nc, stretch }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        vec!["a".into(), "b".into()]
    }

    #[test]
    fn owners_parse() {
        let (s, o) = parse_fit("losses.multiplier.churning=0.1:10", &names()).unwrap();
        assert_eq!((s.bounds, o), (Some((0.1, 10.0)), Owner::Shared));
        let (s, o) = parse_fit("thermal.links[\"x@y\"].h_w_per_m2k@1=1:5", &names()).unwrap();
        assert_eq!(s.path.to_string(), "thermal.links[\"x@y\"].h_w_per_m2k");
        assert_eq!(o, Owner::One(1));
        assert_eq!(parse_fit("a.b@b", &names()).unwrap().1, Owner::One(1));
        assert_eq!(parse_fit("a.b@*", &names()).unwrap().1, Owner::Each);
        let e = parse_fit("a.b@2", &names()).unwrap_err().to_string();
        assert!(e.contains("trace 2 does not exist"), "{e}");
        let e = parse_fit("a.b@c", &names()).unwrap_err().to_string();
        assert!(e.contains("no trace is named \"c\""), "{e}");
        let e = parse_fit("a.b@0", &names()[..1]).unwrap_err().to_string();
        assert!(e.contains("one trace is fitted"), "{e}");
    }
}
