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
use super::params::{canonical, split_bounds, FitSpec, Parameter};
use super::problem::{initial_overrides, Problem};
use super::residuals::Layout;
use super::trace_file::TraceFile;
use super::{checks, document, CalibrateOptions};
use crate::job::{JobError, Model};

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
/// each once).
pub fn segment_list(spec: &str, n: usize, source: &str) -> Result<Vec<usize>, JobError> {
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
                "segment = {spec}: {k} must lie in [0, {}] ({source} has {n} segment(s))",
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
                Some(spec) if files.len() == 1 => segment_list(spec, file.segments.len(), &file.source)?,
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
}

fn fit_error(arg: &str, allowed: &str, msg: String) -> JobError {
    JobError::option("fit", arg, allowed, msg)
}

/// The `@TRACE` of a key path (the last `@` outside quotes and brackets), if any.
fn split_owner(path: &str) -> (&str, Option<&str>) {
    let (mut in_quotes, mut depth, mut at) = (false, 0i32, None);
    for (k, c) in path.char_indices() {
        match c {
            '"' => in_quotes = !in_quotes,
            '[' if !in_quotes => depth += 1,
            ']' if !in_quotes => depth -= 1,
            '@' if !in_quotes && depth == 0 => at = Some(k),
            _ => {}
        }
    }
    match at {
        Some(k) => (&path[..k], Some(&path[k + 1..])),
        None => (path, None),
    }
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
    let n = names.len();
    if n < 2 {
        let msg = format!(
            "fit = {arg}: @{owner} names a trace, but one trace is fitted: a parameter of one trace needs \
             several --trace"
        );
        return Err(fit_error(arg, "KEYPATH[=LO:HI] with one trace", msg));
    }
    if owner == "*" {
        return Ok((spec, Owner::Each));
    }
    let index = match owner.parse::<usize>() {
        Ok(i) if i < n => i,
        Ok(i) => {
            let msg = format!(
                "fit = {arg}: trace {i} does not exist: the traces are 0 … {} ({})",
                n - 1,
                names.join(", ")
            );
            return Err(fit_error(arg, allowed, msg));
        }
        Err(_) => names.iter().position(|x| x == owner).ok_or_else(|| {
            let msg = format!(
                "fit = {arg}: no trace is named \"{owner}\" (traces: {})",
                names.join(", ")
            );
            fit_error(arg, allowed, msg)
        })?,
    };
    Ok((spec, Owner::One(index)))
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

/// Options a fit over several traces does not take (exit 1 naming the option).
fn refuse_single_trace_options(o: &CalibrateOptions) -> Result<(), JobError> {
    let refuse = |name: &str, value: &str| {
        let msg = format!(
            "{name} = {value}: not available in a fit over several traces or segments (fit one segment \
             with --segment K for it)"
        );
        Err(JobError::option(name, value, "a fit of one segment", msg))
    };
    if o.residuals == "ar1-gls" {
        return refuse("residuals", "ar1-gls");
    }
    if let Some(p) = o.prior.first() {
        return refuse("prior", p);
    }
    if let Some(p) = o.profile.first() {
        return refuse("profile", p);
    }
    if let Some(k) = &o.gearbox_kind {
        return refuse("gearbox_kind", k);
    }
    if let Some(r) = &o.rated {
        return refuse("rated", r);
    }
    Ok(())
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
    refuse_single_trace_options(o)?;
    let mut plain = o.clone();
    plain.fit.clear();
    let (_, windows, _) = plain.check()?;
    let names: Vec<String> = traces.iter().map(|t| t.name.clone()).collect();
    let doc = document(m, text, &m.overrides)?;
    let (params, owners) = resolve_params(&o.fit, &names, &doc)?;
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
    };
    stack.check_size()?;
    Ok(stack)
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
