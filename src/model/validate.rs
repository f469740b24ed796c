//! Validation: a parsed [`ModelFile`] → a checked [`Gearbox`] in SI units, or the list of every
//! problem found (key path, value, what is allowed).
//!
//! Each section's checks live beside its serde struct in [`super::sections`]; [`validate`] runs
//! them in order. The checks keep going after a failure, so one run of `geartherm check` shows
//! everything that is wrong. Checks that need earlier sections (a mesh needs its two gears'
//! geometry) are skipped for entries whose inputs already failed, so one mistake is reported once.

use std::collections::BTreeSet;

use super::catalogue;
use super::file::ModelFile;
use super::gearbox::Gearbox;
use super::problems::Problems;
use super::sections::*;
use super::source::Source;
use crate::cycle::GearTable as RatioTable;
use crate::physics::kinematics::{Constraint, GearTrain};

/// The kinematic structure: members, gears, meshes, sets, shift elements and gear states.
struct Structure {
    members: Vec<members::Member>,
    gears: Vec<gears::Gear>,
    meshes: Vec<meshes::Mesh>,
    sets: Vec<planetary_sets::PlanetarySet>,
    elements: Vec<shift_elements::ShiftElement>,
    train: Option<GearTrain>,
    gear_states: Vec<gear_states::GearState>,
    io: (Option<usize>, Option<usize>),
    oil_level: f64,
}

/// The top-level sections the gear train and the gear states' kinematics are solved from.
pub const KINEMATIC_SECTIONS: &[&str] = &[
    "members",
    "gears",
    "meshes",
    "planetary_sets",
    "shift_elements",
    "gear_states",
    "train",
];

/// The solved gear train and gear states of a valid file, to reuse for a file whose
/// [`KINEMATIC_SECTIONS`] are the same.
#[derive(Debug, Clone)]
pub struct Kinematics {
    train: Option<GearTrain>,
    gear_states: Vec<gear_states::GearState>,
}

/// The kinematics of `file` (None when its structure has a problem).
pub fn kinematics(file: &ModelFile) -> Option<Kinematics> {
    let mut problems = Problems::default();
    let (s, _) = structure(file, None, &mut problems);
    problems.is_empty().then_some(Kinematics {
        train: s.train,
        gear_states: s.gear_states,
    })
}

/// Validate a parsed file. `problems` receives every problem; `None` if there was any.
pub fn validate(file: &ModelFile, problems: &mut Problems) -> Option<Gearbox> {
    validate_with(file, None, problems)
}

/// [`validate`] taking the gear train and gear states from `known` (the [`kinematics`] of a
/// file whose [`KINEMATIC_SECTIONS`] equal `file`'s) instead of solving them again.
pub fn validate_with(
    file: &ModelFile,
    known: Option<&Kinematics>,
    problems: &mut Problems,
) -> Option<Gearbox> {
    let start = problems.len();
    model::validate_meta(&file.model, problems);
    let oil = oil::validate_oil(&file.oil, problems);
    let (s, parts) = structure(file, known, problems);
    let nodes: BTreeSet<&str> = file
        .thermal
        .as_ref()
        .map(|t| t.nodes.iter().map(|n| n.name.as_str()).collect())
        .unwrap_or_default();
    let catalogue_oil = file.oil.catalogue.as_deref().and_then(catalogue::find);
    let bath = bearings::OilBath {
        level: s.oil_level,
        catalogue: catalogue_oil.as_ref(),
    };
    let bearings = bearings::validate_bearings(&file.bearings, &nodes, &parts, &s.gears, &bath, problems);
    let seals = seals::validate_seals(&file.seals, &parts.members, &nodes, problems);
    let lub = &file.lubrication;
    let oil_x_l = oil.as_ref().map_or(1.0, |o| o.lubricant_factor_or_default().0);
    let loss_alternatives = crate::model::sections::loss_alternatives::alternatives(
        &file.losses.clone().unwrap_or_default(),
        lub.sump_volume_l,
        oil_x_l,
    );
    let losses = losses::validate_losses(
        &file.losses.clone().unwrap_or_default(),
        lub.sump_volume_l,
        oil_x_l,
        problems,
    );
    let element_names: Vec<&str> = file.shift_elements.iter().map(|e| e.name.as_str()).collect();
    let member_names: Vec<&str> = file.members.iter().map(|m| m.name.as_str()).collect();
    let clutch_packs = clutch_packs::validate_clutch_packs(&file.clutch_packs, &element_names, problems);
    let pump = file
        .pump
        .as_ref()
        .and_then(|p| pump::validate_pump(p, &member_names, problems));
    let ratios = RatioTable::new(
        s.gear_states
            .iter()
            .map(|g| (g.name.clone(), g.ratio()))
            .collect(),
    );
    // A train that failed (a gear, mesh, set or shift element in error) has no gear states:
    // the sections that name gear states are not checked against an empty list (one mistake,
    // one problem; they are checked once the train is right).
    let train_failed = s.train.is_none() && !file.gear_states.is_empty();
    let launch = file
        .launch
        .as_ref()
        .filter(|_| !train_failed)
        .and_then(|spec| launch::validate_launch(spec, &ratios, problems));
    let items = ItemNames {
        gears: &s.gears,
        declared: file.gears.iter().map(|g| g.name.as_str()).collect(),
        meshes: &s.meshes,
        bearings: &bearings,
        seals: &seals,
        packs: clutch_packs.iter().map(|c| c.name.as_str()).collect(),
        pump: file.pump.is_some(),
        converter: file.launch.is_some(),
        circuit: file.circuit.as_ref(),
    };
    let thermal = file
        .thermal
        .as_ref()
        .and_then(|spec| check_thermal(spec, &items, problems));
    let circuit = file.circuit.as_ref().and_then(|spec| {
        let names = circuit::CircuitNames {
            // Names as the file writes them: an entry in error is reported where it is
            // defined, not again where the circuit names it.
            gears: file.gears.iter().map(|g| g.name.as_str()).collect(),
            meshes: s.meshes.iter().map(|m| m.name.as_str()).collect(),
            sets: file.planetary_sets.iter().map(|x| x.name.as_str()).collect(),
            packs: clutch_packs.iter().map(|c| c.name.as_str()).collect(),
            bearings: bearings.iter().map(|b| b.name.as_str()).collect(),
            nodes: &nodes,
            pump: file.pump.is_some(),
        };
        circuit::validate_circuit(spec, &names, problems)
    });
    if let (Some(_), Some(net)) = (&circuit, &thermal) {
        oil_node_gives_cp(net, problems);
    }
    let vehicle = file
        .vehicle
        .as_ref()
        .filter(|_| !train_failed)
        .and_then(|spec| vehicle::validate_vehicle(spec, &ratios, problems));
    if let Some(u) = &file.uncertainty {
        uncertainty::check_spec(u, problems);
    }

    if problems.len() > start {
        return None;
    }
    let (input, output) = s.io;
    Some(Gearbox {
        name: file.model.name.clone(),
        description: file.model.description.clone().unwrap_or_default(),
        oil: oil?,
        members: s.members,
        gears: s.gears,
        meshes: s.meshes,
        planetary_sets: s.sets,
        shift_elements: s.elements,
        gear_states: s.gear_states,
        train: s.train?,
        input: input?,
        output: output?,
        oil_level: s.oil_level,
        sump_volume: lub.sump_volume_l.map(|v| v * 1e-3),
        losses: losses?,
        loss_alternatives,
        thermal,
        vehicle,
        clutch_packs,
        pump,
        launch,
        bearings,
        seals,
        circuit: circuit.unwrap_or_default(),
    })
}

/// Members, gears, `[train]`, meshes, sets, shift elements and gear states (solved on a sound
/// structure only; taken from `known` when given), and `[lubrication]`; with the parts by name
/// for the sections after them.
fn structure<'a>(
    file: &'a ModelFile,
    known: Option<&Kinematics>,
    problems: &mut Problems,
) -> (Structure, parts::Parts<'a>) {
    let structure_start = problems.len();
    let members = members::validate_members(&file.members, problems);
    let planet_of = planetary_sets::planet_roles(&file.planetary_sets);
    let roots = meshes::mating_tip_roots(&file.gears, &file.meshes);
    let gears = gears::validate_gears(&file.gears, &members, &roots, problems);
    let parts = parts::Parts {
        members,
        gears,
        planet_of,
    };
    let io = train::validate_train(&file.train, &parts.members, problems);

    let mut meshes = Vec::new();
    let mut fixed_rows = Vec::new();
    meshes::validate_meshes(&file.meshes, &parts, &mut meshes, &mut fixed_rows, problems);
    let (sets, mounts) = planetary_sets::validate_sets(
        &file.planetary_sets,
        &parts,
        &mut meshes,
        &mut fixed_rows,
        problems,
    );
    // Fixed members.
    for (i, m) in file.members.iter().enumerate() {
        if m.fixed {
            fixed_rows.push(Constraint::Brake { member: i });
        }
    }
    let elements = shift_elements::validate_shift_elements(&file.shift_elements, &parts.members, problems);
    let sound = problems.len() == structure_start;
    let (train, gear_states) = match known {
        Some(k) if sound => (k.train.clone(), k.gear_states.clone()),
        _ => gear_states::validate_gear_states(
            &file.gear_states,
            &elements,
            &file.members,
            fixed_rows,
            io,
            sound,
            problems,
        ),
    };
    let (gears, oil_level) =
        lubrication::validate_lubrication(&file.lubrication, &parts, &sets, &meshes, &mounts, problems);
    let s = Structure {
        members: parts.members.checked(),
        gears,
        meshes,
        sets,
        elements: elements.list,
        train,
        gear_states,
        io,
        oil_level,
    };
    (s, parts)
}

/// The loss items of the model by source, for heat rules (`"<source>:<name>"`).
struct ItemNames<'a> {
    gears: &'a [gears::Gear],
    /// Every gear name the file declares, checked or not.
    declared: Vec<&'a str>,
    meshes: &'a [meshes::Mesh],
    bearings: &'a [bearings::Bearing],
    seals: &'a [seals::Seal],
    packs: Vec<&'a str>,
    pump: bool,
    converter: bool,
    /// `[circuit]` consumer names by kind (jets, sets) and electric-pump source names.
    circuit: Option<&'a circuit::CircuitSpec>,
}

/// `[thermal]` against the checked gears and the loss items of the model.
fn check_thermal(
    spec: &thermal::ThermalSpec,
    it: &ItemNames<'_>,
    problems: &mut Problems,
) -> Option<thermal::ThermalNetwork> {
    let infos: Vec<thermal::GearInfo<'_>> = it
        .gears
        .iter()
        .map(|g| thermal::GearInfo {
            name: &g.name,
            radius: 0.5 * g.geometry.d_a.max(g.geometry.d_f),
            face_width: g.geometry.spec.b,
            checked: true,
        })
        .chain(
            it.declared
                .iter()
                // Only after a problem: a gear dropped without one stays an unknown name.
                .filter(|_| !problems.is_empty())
                .filter(|d| !it.gears.iter().any(|g| g.name == **d))
                .map(|d| thermal::GearInfo {
                    name: d,
                    radius: 0.0,
                    face_width: 0.0,
                    checked: false,
                }),
        )
        .collect();
    let mut names = thermal::LossItemNames::default();
    names.set(Source::Churning, it.gears.iter().map(|g| g.name.as_str()));
    names.set(Source::Pocketing, it.meshes.iter().map(|m| m.name.as_str()));
    names.set(Source::Sliding, it.meshes.iter().map(|m| m.name.as_str()));
    names.set(Source::ClutchDrag, it.packs.iter().copied());
    let consumers = |k: circuit::ConsumerKindChoice| -> Vec<&str> {
        it.circuit
            .map(|c| {
                c.consumers
                    .iter()
                    .filter(|x| x.kind == k)
                    .map(|x| x.name.as_str())
                    .collect()
            })
            .unwrap_or_default()
    };
    let e_pumps: Vec<&str> = it
        .circuit
        .map(|c| {
            c.sources
                .iter()
                .filter(|x| x.kind == circuit::SourceKindChoice::ElectricPump)
                .map(|x| x.name.as_str())
                .collect()
        })
        .unwrap_or_default();
    names.set(Source::Pump, it.pump.then_some("pump").into_iter().chain(e_pumps));
    names.set(Source::Windage, it.gears.iter().map(|g| g.name.as_str()));
    names.set(Source::Jet, consumers(circuit::ConsumerKindChoice::Jet));
    names.set(Source::Fling, consumers(circuit::ConsumerKindChoice::Set));
    names.set(Source::Converter, it.converter.then_some("converter"));
    names.set(Source::Bearing, it.bearings.iter().map(|b| b.name.as_str()));
    names.set(Source::Seal, it.seals.iter().map(|s| s.name.as_str()));
    thermal::validate_thermal(spec, &infos, &names, problems)
}

/// With a `[circuit]`, the oil its consumers carry back to the sump takes the oil node's c_p
/// (advection links ṁ c_p ΔT, docs/physics.md §14): the oil node must state it.
fn oil_node_gives_cp(net: &thermal::ThermalNetwork, problems: &mut Problems) {
    let i = net.oil_node;
    if net.nodes.get(i).is_some_and(|n| n.specific_heat.is_none()) {
        problems.push(
            format!("thermal.nodes[{i}]"),
            &net.nodes[i].name,
            "the oil node of a model with a [circuit] needs mass_kg and cp_j_per_kgk (the oil the \
             circuit carries takes its c_p), not capacity_j_per_k alone",
        );
    }
}
