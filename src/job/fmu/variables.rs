//! The variables of an exported FMU: one table, built from the checked model and its compiled
//! scene, that both the exporter (modelDescription.xml) and the runtime (value references of
//! `fmi2GetReal` / `fmi2SetReal`) read, so the two cannot disagree.

use crate::job::run::{DEFAULT_ATOL, DEFAULT_RTOL};
use crate::model::Gearbox;
use crate::scene::{Scene, Source};

/// FMI causality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set by the importer at every communication point.
    Input,
    /// Computed.
    Output,
    /// Set before initialisation (exported model values, `param.*`, also between steps: tunable).
    Parameter,
}

/// What a variable is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Input shaft speed, rad/s.
    InputSpeed,
    /// Input torque (the torque the gear train transmits, loss-free, as `geartherm run`), N·m.
    InputTorque,
    /// Vehicle speed, m/s.
    VehicleSpeed,
    /// Gear-state index (model order, from 0).
    Gear,
    /// Temperature of boundary k, K.
    Boundary(usize),
    /// Initial temperature of node k, K.
    InitialTemp(usize),
    /// Relative tolerance of the integration.
    Rtol,
    /// Absolute tolerance on temperatures, K.
    Atol,
    /// Exported model parameter k (a key path listed at export).
    Param(usize),
    /// Temperature of node k, K.
    NodeTemp(usize),
    /// Loss power of a source, W.
    SourceLoss(Source),
    /// Total loss power, W.
    TotalLoss,
    /// Loss energy of a source since the start, J.
    SourceEnergy(Source),
    /// Total loss energy since the start, J.
    TotalEnergy,
    /// Efficiency P_out/(P_out + P_loss) (0 when no power flows to the output).
    Efficiency,
    /// Output shaft speed, rad/s.
    OutputSpeed,
    /// Output torque (loss-free input torque × ratio), N·m.
    OutputTorque,
    /// Input shaft torque with the losses supplied through the shaft, T + P_shaft/ω_in, N·m (as
    /// `timeseries.csv`: the converter's slip and an engine-driven pump are paid ahead of it).
    InputTorqueWithLosses,
    /// Kinematic viscosity of the oil at the oil temperature, m²/s.
    OilViscosity,
}

/// One variable.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Name (flat naming convention).
    pub name: String,
    /// Value reference.
    pub vr: u32,
    /// What it is.
    pub role: Role,
    /// Causality.
    pub causality: Causality,
    /// Integer (else Real).
    pub integer: bool,
    /// Unit (a name of the description's unit definitions).
    pub unit: &'static str,
    /// Start value (inputs and parameters).
    pub start: Option<f64>,
    /// Description.
    pub description: String,
}

/// The table being built: value references are positions from 1.
struct Table(Vec<Variable>);

impl Table {
    fn push(
        &mut self,
        name: String,
        role: Role,
        causality: Causality,
        unit: &'static str,
        start: Option<f64>,
        description: String,
    ) {
        let vr = self.0.len() as u32 + 1;
        self.0.push(Variable {
            name,
            vr,
            role,
            causality,
            integer: role == Role::Gear,
            unit,
            start,
            description,
        });
    }

    fn input(&mut self, name: &str, role: Role, unit: &'static str, start: f64, description: String) {
        self.push(
            name.into(),
            role,
            Causality::Input,
            unit,
            Some(start),
            description,
        );
    }

    fn parameter(&mut self, name: String, role: Role, unit: &'static str, start: f64, description: String) {
        self.push(name, role, Causality::Parameter, unit, Some(start), description);
    }

    fn output(&mut self, name: String, role: Role, unit: &'static str, description: String) {
        self.push(name, role, Causality::Output, unit, None, description);
    }
}

/// Every variable of an FMU of `gb` compiled into `scene`, with `params` (key paths and their
/// model values): inputs, parameters, outputs.
pub fn variables(gb: &Gearbox, scene: &Scene, params: &[(String, f64)]) -> Vec<Variable> {
    let mut t = Table(Vec::new());
    inputs(&mut t, gb, scene);
    parameters(&mut t, scene, params);
    outputs(&mut t, scene);
    t.0
}

fn inputs(t: &mut Table, gb: &Gearbox, scene: &Scene) {
    let states: Vec<String> = gb
        .gear_states
        .iter()
        .enumerate()
        .map(|(i, s)| format!("{i} = {}", s.name))
        .collect();
    t.input(
        "input_speed",
        Role::InputSpeed,
        "rad/s",
        0.0,
        "input shaft speed (0 to 50000 rpm)".into(),
    );
    let torque = "torque the gear train transmits, referred to the input, loss-free (negative: overrun)";
    t.input("input_torque", Role::InputTorque, "N.m", 0.0, torque.into());
    let v = "vehicle speed, for speed-dependent links (0 to 400 km/h)";
    t.input("vehicle_speed", Role::VehicleSpeed, "m/s", 0.0, v.into());
    t.input(
        "gear",
        Role::Gear,
        "",
        0.0,
        format!("gear-state index: {}", states.join(", ")),
    );
    let th = scene.thermal();
    for (k, name) in th.boundary_names.iter().enumerate() {
        let t0 = th.boundary_temperature_at(k, 0.0).unwrap_or(f64::NAN);
        t.input(
            &format!("T_boundary.{name}"),
            Role::Boundary(k),
            "K",
            t0,
            format!("temperature of boundary {name}"),
        );
    }
}

fn parameters(t: &mut Table, scene: &Scene, params: &[(String, f64)]) {
    let th = scene.thermal();
    for (k, name) in th.names.iter().enumerate() {
        let d = format!("initial temperature of node {name}");
        t.parameter(
            format!("T_initial.{name}"),
            Role::InitialTemp(k),
            "K",
            th.initial[k],
            d,
        );
    }
    let rtol = "relative tolerance of the integration (1e-14 to 0.1)";
    t.parameter("rtol".into(), Role::Rtol, "", DEFAULT_RTOL, rtol.into());
    let atol = "absolute tolerance on temperatures (1e-14 to 1)";
    t.parameter("atol".into(), Role::Atol, "K", DEFAULT_ATOL, atol.into());
    for (k, (path, value)) in params.iter().enumerate() {
        let d = format!("model value {path} (checked as the model file)");
        t.parameter(format!("param.{path}"), Role::Param(k), "", *value, d);
    }
}

fn outputs(t: &mut Table, scene: &Scene) {
    for (k, name) in scene.thermal().names.iter().enumerate() {
        t.output(
            format!("T.{name}"),
            Role::NodeTemp(k),
            "K",
            format!("temperature of node {name}"),
        );
    }
    for s in sources(scene) {
        let n = s.as_str();
        t.output(
            format!("P_loss.{n}"),
            Role::SourceLoss(s),
            "W",
            format!("{n} loss power"),
        );
    }
    t.output(
        "P_loss.total".into(),
        Role::TotalLoss,
        "W",
        "total loss power".into(),
    );
    for s in sources(scene) {
        let n = s.as_str();
        t.output(
            format!("E_loss.{n}"),
            Role::SourceEnergy(s),
            "J",
            format!("{n} loss energy since the start"),
        );
    }
    t.output(
        "E_loss.total".into(),
        Role::TotalEnergy,
        "J",
        "total loss energy since the start".into(),
    );
    let eta = "P_out/(P_out + P_loss); 0 when no power flows to the output";
    t.output("efficiency".into(), Role::Efficiency, "1", eta.into());
    t.output(
        "output_speed".into(),
        Role::OutputSpeed,
        "rad/s",
        "output shaft speed".into(),
    );
    let tq = "output torque, loss-free (input torque x ratio)";
    t.output("output_torque".into(), Role::OutputTorque, "N.m", tq.into());
    let shaft = "input shaft torque: input torque plus the losses supplied through the input shaft / input speed (converter slip and an engine-driven pump excluded)";
    t.output(
        "input_torque_with_losses".into(),
        Role::InputTorqueWithLosses,
        "N.m",
        shaft.into(),
    );
    let nu = "kinematic viscosity of the oil at the oil temperature";
    t.output("oil_viscosity".into(), Role::OilViscosity, "m2/s", nu.into());
}

/// The loss sources the scene has items of, in output order.
pub fn sources(scene: &Scene) -> Vec<Source> {
    Source::ALL
        .into_iter()
        .filter(|s| scene.losses().items.iter().any(|it| it.source == *s))
        .collect()
}
