//! The calibration problem: the model text and its overrides, the trace mapped onto the model
//! (segments, boundary series, measured nodes, initial temperatures), the parameters, and the
//! simulation at a parameter point with or without sensitivities.

use crate::physics::units::{c_to_k, k_to_c};
use std::path::PathBuf;

use crate::model::overrides;
use crate::model::parse::{parse_document, parse_table};
use crate::model::thermal::BoundaryTemp;
use crate::model::validate::validate;
use crate::model::{self, Gearbox, Override, Problems};
use crate::scene::{Needs, Scene};
use crate::solve::drive::segments;
use crate::solve::sensitivity::{
    integrate_sensitivities, Direction, SensitivityOptions, SensitivityTrajectory,
};
use crate::solve::transient::Segment;

use super::params::Parameter;
use super::trace::Trace;
use crate::job::envelope::Envelope;
use crate::job::{JobError, Model};

/// Everything a simulation at a parameter point needs.
pub struct Problem<'a> {
    /// Model text (the file as read).
    pub text: &'a str,
    /// Model file, for messages.
    pub file: PathBuf,
    /// Overrides before the parameters': the command's `--set`, then the initial temperatures
    /// taken from the trace.
    pub base: Vec<Override>,
    /// The trace.
    pub trace: &'a Trace,
    /// Fitted parameters.
    pub params: Vec<Parameter>,
    /// Integration segments (the trace's rows).
    pub segs: Vec<Segment>,
    /// What the scene compiles.
    pub needs: Needs,
    /// Node index of each measured channel.
    pub channels: Vec<usize>,
    /// Output row of each trace row.
    pub rows: Vec<usize>,
    /// Integration options.
    pub opts: SensitivityOptions,
    /// The model document with the base overrides applied, parsed once.
    doc: toml::Table,
}

/// Simulated temperatures at every trace row (°C, `[row][channel]`) and, with sensitivities,
/// their derivatives (K per unit coordinate, `[row][channel * P + k]`).
pub struct Simulation {
    /// Simulated temperature of each channel at each trace row, °C.
    pub temps_c: Vec<Vec<f64>>,
    /// Derivatives (empty without sensitivities).
    pub sens: Vec<Vec<f64>>,
    /// Steps and rejected steps of the integration.
    pub steps: (usize, usize),
    /// Where the trajectory first leaves the physics envelope (time and node), if it does.
    pub breach: Option<String>,
}

fn invalid(label: &str, what: String) -> JobError {
    JobError::invalid(format!("{label}: {what}"))
}

/// The model text parsed, with `base` applied.
fn base_document(text: &str, base: &[Override]) -> Result<toml::Table, String> {
    let mut problems = Problems::default();
    let mut doc = parse_document(text, &mut problems).ok_or("the model text does not parse")?;
    for ov in base {
        overrides::apply(&mut doc, ov)?;
    }
    Ok(doc)
}

/// Position of every trace row among the output times (the segment boundaries).
fn output_rows(trace: &Trace, segs: &[Segment]) -> Result<Vec<usize>, String> {
    let mut times = Vec::with_capacity(segs.len() + 1);
    times.extend(segs.first().map(|s| s.t0));
    times.extend(segs.iter().map(|s| s.t1));
    trace
        .times
        .iter()
        .map(|&t| {
            let k = times.partition_point(|&x| x < t - 1e-9 * t.abs().max(1.0));
            match times.get(k) {
                Some(&x) if (x - t).abs() <= 1e-9 * t.abs().max(1.0) => Ok(k),
                _ => Err(format!("trace time {t} s is not an output time of the schedule")),
            }
        })
        .collect()
}

/// The node of every measured column (an unknown node or boundary is invalid input, naming the
/// column and what the model has).
pub fn check_names(m: &Model, trace: &Trace) -> Result<Vec<usize>, JobError> {
    let label = m.label();
    let net = m.gearbox.thermal.as_ref().ok_or_else(|| {
        invalid(
            &label,
            "the model has no [thermal] section: nothing to calibrate".into(),
        )
    })?;
    let names: Vec<&str> = net.nodes.iter().map(|n| n.name.as_str()).collect();
    let channels = trace
        .measured
        .iter()
        .map(|c| {
            names.iter().position(|n| *n == c.name).ok_or_else(|| {
                JobError::invalid(format!(
                    "{}: column {}: {label} has no capacity node \"{}\" (nodes: {})",
                    trace.source,
                    c.column,
                    c.name,
                    names.join(", ")
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let bnames: Vec<&str> = net.boundaries.iter().map(|b| b.name.as_str()).collect();
    for c in &trace.boundaries {
        if !bnames.contains(&c.name.as_str()) {
            return Err(JobError::invalid(format!(
                "{}: column {}: {label} has no boundary \"{}\" (boundaries: {})",
                trace.source,
                c.column,
                c.name,
                bnames.join(", ")
            )));
        }
    }
    Ok(channels)
}

/// The initial temperatures the trace sets: every measured node at its first value, the
/// network's default at their mean.
pub fn initial_overrides(trace: &Trace) -> Vec<Override> {
    let first: Vec<f64> = trace.measured.iter().map(|c| c.values_c[0]).collect();
    let mean = first.iter().sum::<f64>() / first.len() as f64;
    let mut out = vec![Override {
        path: "thermal.initial_temp_c".parse().expect("a valid key path"),
        value: toml::Value::Float(mean),
    }];
    for (c, v) in trace.measured.iter().zip(&first) {
        out.push(Override {
            path: model::KeyPath(vec![
                model::overrides::Step::Key("thermal".into()),
                model::overrides::Step::Key("nodes".into()),
                model::overrides::Step::Named(c.name.clone()),
                model::overrides::Step::Key("initial_temp_c".into()),
            ]),
            value: toml::Value::Float(*v),
        });
    }
    out
}

impl<'a> Problem<'a> {
    /// Map the trace onto the checked model `m` (text `text`): every unknown node or boundary,
    /// every cycle problem is invalid input here.
    pub fn new(
        m: &Model,
        text: &'a str,
        trace: &'a Trace,
        params: Vec<Parameter>,
        base: Vec<Override>,
        opts: SensitivityOptions,
    ) -> Result<Problem<'a>, JobError> {
        let label = m.label();
        let channels = check_names(m, trace)?;
        let (_, segs) = segments(&m.gearbox, &trace.cycle).map_err(|e| invalid(&label, e.to_string()))?;
        let rows = output_rows(trace, &segs).map_err(|e| invalid(&trace.source, e))?;
        let needs = Needs {
            states: Some(segs.iter().map(|s| s.inputs.state).collect()),
            evaluate_all: false,
            energy_per_source_only: true,
            ..Needs::default()
        };
        let doc = base_document(text, &base).map_err(|e| invalid(&label, e))?;
        Ok(Problem {
            doc,
            text,
            file: m.file.clone(),
            base,
            trace,
            params,
            segs,
            needs,
            channels,
            rows,
            opts,
        })
    }

    /// The same problem with other parameters.
    pub fn with_params(&self, params: Vec<Parameter>) -> Problem<'a> {
        Problem {
            doc: self.doc.clone(),
            text: self.text,
            file: self.file.clone(),
            base: self.base.clone(),
            trace: self.trace,
            params,
            segs: self.segs.clone(),
            needs: self.needs.clone(),
            channels: self.channels.clone(),
            rows: self.rows.clone(),
            opts: self.opts.clone(),
        }
    }

    /// The model document with the base overrides applied.
    pub fn document(&self) -> &toml::Table {
        &self.doc
    }

    /// The overrides at coordinates θ: the base ones, then each parameter's value.
    pub fn overrides_at(&self, theta: &[f64]) -> Vec<Override> {
        let mut ovs = self.base.clone();
        ovs.extend(
            self.params
                .iter()
                .zip(theta)
                .map(|(p, &t)| p.override_at(p.written(t))),
        );
        ovs
    }

    /// The checked gearbox at θ with the trace's boundary temperatures: the parameters written
    /// into the parsed document; a model they make invalid is checked again from the text, for
    /// the messages that name the overrides.
    pub fn gearbox_at(&self, theta: &[f64]) -> Result<Gearbox, JobError> {
        let mut doc = self.doc.clone();
        let mut problems = Problems::default();
        for (p, &t) in self.params.iter().zip(theta) {
            if let Err(e) = overrides::apply(&mut doc, &p.override_at(p.written(t))) {
                problems.push(p.name(), t, e);
            }
        }
        let parsed = problems
            .is_empty()
            .then(|| parse_table(doc, &mut problems))
            .flatten();
        let checked = parsed
            .and_then(|f| validate(&f, &mut problems))
            .filter(|_| problems.is_empty());
        let mut gb = match checked {
            Some(gb) => gb,
            None => model::from_str_with(self.text, &self.file, &self.overrides_at(theta))?,
        };
        if let Some(net) = gb.thermal.as_mut() {
            for c in &self.trace.boundaries {
                if let Some(b) = net.boundaries.iter_mut().find(|b| b.name == c.name) {
                    let series = self
                        .trace
                        .times
                        .iter()
                        .zip(&c.values_c)
                        .map(|(&t, &v)| (t, c_to_k(v)))
                        .collect();
                    b.temp = BoundaryTemp::Series(series);
                }
            }
        }
        Ok(gb)
    }

    /// The scene at θ.
    pub fn scene_at(&self, theta: &[f64]) -> Result<Scene, JobError> {
        let gb = self.gearbox_at(theta)?;
        Scene::compile_for(&gb, &self.needs)
            .map_err(|e| JobError::invalid(format!("{}: {e}", self.file.display())))
    }

    /// Simulate at θ; with `sens`, also the derivatives along every parameter.
    pub fn simulate(&self, theta: &[f64], sens: bool) -> Result<Simulation, JobError> {
        let scene = self.scene_at(theta)?;
        let mut pairs = Vec::new();
        if sens {
            for (k, p) in self.params.iter().enumerate() {
                let (up, down, d) = p.difference_pair(theta[k]);
                let mut th = theta.to_vec();
                th[k] = up;
                let plus = self.scene_at(&th)?;
                th[k] = down;
                let minus = self.scene_at(&th)?;
                for s in [&plus, &minus] {
                    if s.nodes() != scene.nodes() || s.items() != scene.items() {
                        return Err(JobError::invalid(format!(
                            "{}: parameter {} changes the model's structure (nodes or loss items) within its \
                             difference step: it cannot be fitted",
                            self.file.display(),
                            p.name()
                        )));
                    }
                }
                pairs.push((plus, minus, d));
            }
        }
        let dirs: Vec<Direction<'_>> = pairs
            .iter()
            .map(|(plus, minus, d)| Direction {
                plus,
                minus,
                delta: *d,
            })
            .collect();
        let traj = integrate_sensitivities(&scene, &dirs, &self.segs, &self.opts)
            .map_err(|e| JobError::numerical(format!("{}: {e}", self.file.display())))?;
        let mut sim = self.collect(&traj, dirs.len());
        sim.breach = trajectory_breach(&Envelope::of(&scene), &traj.times, &traj.temps);
        Ok(sim)
    }

    /// The coordinates of the parameters' start values.
    pub fn start(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.theta(p.start)).collect()
    }

    /// The trace's boundary columns as (name, (time s, °C) pairs).
    pub fn boundary_series(&self) -> Vec<(String, Vec<(f64, f64)>)> {
        self.trace
            .boundaries
            .iter()
            .map(|c| {
                let pts = self.trace.times.iter().copied().zip(c.values_c.iter().copied());
                (c.name.clone(), pts.collect())
            })
            .collect()
    }

    /// The channels' values at the trace rows.
    fn collect(&self, traj: &SensitivityTrajectory, p: usize) -> Simulation {
        let mut temps_c = Vec::with_capacity(self.rows.len());
        let mut sens = Vec::with_capacity(if p > 0 { self.rows.len() } else { 0 });
        for &r in &self.rows {
            temps_c.push(self.channels.iter().map(|&n| k_to_c(traj.temps[r][n])).collect());
            if p > 0 {
                let mut row = Vec::with_capacity(self.channels.len() * p);
                for &n in &self.channels {
                    row.extend((0..p).map(|k| traj.sens_at(r, n, k, p)));
                }
                sens.push(row);
            }
        }
        Simulation {
            temps_c,
            sens,
            steps: (traj.steps.len(), traj.rejected),
            breach: None,
        }
    }
}

/// The first output row (time, s) at which a node of `temps_k` (K, every node, per row) leaves
/// the envelope of the scene, with the breach.
fn trajectory_breach(envelope: &Envelope, times: &[f64], temps_k: &[Vec<f64>]) -> Option<String> {
    temps_k
        .iter()
        .zip(times)
        .find_map(|(y, t)| envelope.check(y).err().map(|b| format!("at t = {t} s: {b}")))
}
