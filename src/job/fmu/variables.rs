//! The variables of an exported FMU: one table, built from the checked model and its compiled
//! scene, that both the exporter (modelDescription.xml) and the runtime (value references of
//! `fmi2GetReal` / `fmi2SetReal`) read, so the two cannot disagree.

use crate::job::run::DEFAULT_RTOL;
use crate::model::Gearbox;
use crate::scene::{Scene, Source};

/// FMI causality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set by the importer at every communication point.
    Input,
    /// Computed.
    Output,
    /// Set before initialisation.
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

/// Every variable of an FMU of `gb` compiled into `scene`, with `params` (key paths and their
/// model values).
pub fn variables(gb: &Gearbox, scene: &Scene, params: &[(String, f64)]) -> Vec<Variable> {
    let mut v = Vec::new();
    let mut push = |name: String, role, causality, unit, start, description: String| {
        let vr = v.len() as u32 + 1;
        v.push(Variable {
            name,
            vr,
            role,
            causality,
            integer: role == Role::Gear,
            unit,
            start,
            description,
        });
    };
    use Causality::*;
    let states: Vec<String> = gb
        .gear_states
        .iter()
        .enumerate()
        .map(|(i, s)| format!("{i} = {}", s.name))
        .collect();
    let th = &scene.thermal;
    push(
        "input_speed".into(),
        Role::InputSpeed,
        Input,
        "rad/s",
        Some(0.0),
        "input shaft speed (0 to 50000 rpm)".into(),
    );
    push(
        "input_torque".into(),
        Role::InputTorque,
        Input,
        "N.m",
        Some(0.0),
        "torque the gear train transmits, referred to the input, loss-free (negative: overrun)".into(),
    );
    push(
        "vehicle_speed".into(),
        Role::VehicleSpeed,
        Input,
        "m/s",
        Some(0.0),
        "vehicle speed, for speed-dependent links (0 to 400 km/h)".into(),
    );
    push(
        "gear".into(),
        Role::Gear,
        Input,
        "",
        Some(0.0),
        format!("gear-state index: {}", states.join(", ")),
    );
    for (k, name) in th.boundary_names.iter().enumerate() {
        let t0 = th.boundary_temperature_at(k, 0.0).unwrap_or(f64::NAN);
        push(
            format!("T_boundary.{name}"),
            Role::Boundary(k),
            Input,
            "K",
            Some(t0),
            format!("temperature of boundary {name}"),
        );
    }
    for (k, name) in th.names.iter().enumerate() {
        push(
            format!("T_initial.{name}"),
            Role::InitialTemp(k),
            Parameter,
            "K",
            Some(th.initial[k]),
            format!("initial temperature of node {name}"),
        );
    }
    push(
        "rtol".into(),
        Role::Rtol,
        Parameter,
        "",
        Some(DEFAULT_RTOL),
        "relative tolerance of the integration (1e-14 to 0.1)".into(),
    );
    push(
        "atol".into(),
        Role::Atol,
        Parameter,
        "K",
        Some(crate::job::run::DEFAULT_ATOL),
        "absolute tolerance on temperatures (1e-14 to 1)".into(),
    );
    for (k, (path, value)) in params.iter().enumerate() {
        push(
            format!("param.{path}"),
            Role::Param(k),
            Parameter,
            "",
            Some(*value),
            format!("model value {path} (checked as the model file)"),
        );
    }
    for (k, name) in th.names.iter().enumerate() {
        push(
            format!("T.{name}"),
            Role::NodeTemp(k),
            Output,
            "K",
            None,
            format!("temperature of node {name}"),
        );
    }
    for s in sources(scene) {
        push(
            format!("P_loss.{}", s.as_str()),
            Role::SourceLoss(s),
            Output,
            "W",
            None,
            format!("{} loss power", s.as_str()),
        );
    }
    push(
        "P_loss.total".into(),
        Role::TotalLoss,
        Output,
        "W",
        None,
        "total loss power".into(),
    );
    for s in sources(scene) {
        push(
            format!("E_loss.{}", s.as_str()),
            Role::SourceEnergy(s),
            Output,
            "J",
            None,
            format!("{} loss energy since the start", s.as_str()),
        );
    }
    push(
        "E_loss.total".into(),
        Role::TotalEnergy,
        Output,
        "J",
        None,
        "total loss energy since the start".into(),
    );
    push(
        "efficiency".into(),
        Role::Efficiency,
        Output,
        "1",
        None,
        "P_out/(P_out + P_loss); 0 when no power flows to the output".into(),
    );
    push(
        "output_speed".into(),
        Role::OutputSpeed,
        Output,
        "rad/s",
        None,
        "output shaft speed".into(),
    );
    push(
        "output_torque".into(),
        Role::OutputTorque,
        Output,
        "N.m",
        None,
        "output torque, loss-free (input torque x ratio)".into(),
    );
    push(
        "input_torque_with_losses".into(),
        Role::InputTorqueWithLosses,
        Output,
        "N.m",
        None,
        "input shaft torque: input torque plus the losses supplied through the input shaft / input speed (converter slip and an engine-driven pump excluded)".into(),
    );
    push(
        "oil_viscosity".into(),
        Role::OilViscosity,
        Output,
        "m2/s",
        None,
        "kinematic viscosity of the oil at the oil temperature".into(),
    );
    v
}

/// The loss sources the scene has items of, in output order.
pub fn sources(scene: &Scene) -> Vec<Source> {
    Source::ALL
        .into_iter()
        .filter(|s| scene.losses.items.iter().any(|it| it.source == *s))
        .collect()
}
