//! Validation: a parsed [`ModelFile`] → a checked [`Gearbox`] in SI units, or the list of every
//! problem found (key path, value, what is allowed).
//!
//! Each model section has its own validator (one file each); [`validate`] runs them in order.
//! The checks run section by section and keep going after a failure, so one run of
//! `geartherm check` shows everything that is wrong. Checks that need earlier sections (a mesh
//! needs its two gears' geometry) are skipped for entries whose inputs already failed, so one
//! mistake is reported once.

use std::collections::HashMap;

use super::gearbox::*;
use super::problems::Problems;
use super::schema::*;
use super::source::Source;
use super::thermal::{validate_thermal, GearInfo, LossItemNames, ThermalNetwork};
use crate::cycle::{GearTable as RatioTable, Vehicle, VehicleSpec};

mod bearings;
mod common;
mod gears;
mod geometry;
mod lubrication;
mod members;
mod meshes;
mod oil;
mod sets;
mod shift;

use common::*;

/// What the section validators share: the file and the name tables of members and gears.
struct Ctx<'a> {
    /// The parsed file.
    file: &'a ModelFile,
    /// Member name → index.
    member_ix: HashMap<&'a str, usize>,
    /// Gear name → index of the set naming it as a planet.
    planet_of: HashMap<&'a str, usize>,
    /// Gears: names, geometry, members.
    gears: gears::GearTable<'a>,
}

impl Ctx<'_> {
    /// Index of member `name`, or a problem at `path` listing the defined members.
    fn member(&self, name: &str, path: String, problems: &mut Problems) -> Option<usize> {
        lookup_member(self.file, &self.member_ix, name, path, problems)
    }

    /// Index of gear `name`, or a problem at `path` listing the defined gears.
    fn gear(&self, name: &str, path: String, problems: &mut Problems) -> Option<usize> {
        let r = self.gears.ix.get(name).copied();
        if r.is_none() {
            problems.push(
                path,
                q(name),
                format!(
                    "unknown gear; defined gears: {}",
                    list(self.file.gears.iter().map(|g| &g.name))
                ),
            );
        }
        r
    }
}

fn lookup_member(
    file: &ModelFile,
    member_ix: &HashMap<&str, usize>,
    name: &str,
    path: String,
    problems: &mut Problems,
) -> Option<usize> {
    let r = member_ix.get(name).copied();
    if r.is_none() {
        problems.push(
            path,
            q(name),
            format!(
                "unknown member; defined members: {}",
                list(file.members.iter().map(|m| &m.name))
            ),
        );
    }
    r
}

/// Validate a parsed file. `problems` receives every problem; `None` if there was any.
pub fn validate(file: &ModelFile, problems: &mut Problems) -> Option<Gearbox> {
    let start = problems.len();
    if file.model.name.trim().is_empty() {
        problems.push("model.name", "\"\"", "must not be empty");
    }
    let oil = oil::validate_oil(&file.oil, problems);
    let structure_start = problems.len();

    let member_ix = members::validate_members(file, problems);
    let planet_of = sets::planet_roles(file);
    let gear_table = {
        let member = |name: &str, path: String, problems: &mut Problems| {
            lookup_member(file, &member_ix, name, path, problems)
        };
        gears::validate_gears(file, &member, problems)
    };
    let ctx = Ctx {
        file,
        member_ix,
        planet_of,
        gears: gear_table,
    };
    let io = members::validate_train(&ctx, problems);

    let mut meshes: Vec<Mesh> = Vec::new();
    let mut fixed_rows = Vec::new();
    meshes::validate_meshes(&ctx, &mut meshes, &mut fixed_rows, problems);
    let (sets, mounts) = sets::validate_sets(&ctx, &mut meshes, &mut fixed_rows, problems);
    // Fixed members.
    for (i, m) in file.members.iter().enumerate() {
        if m.fixed {
            fixed_rows.push(crate::physics::kinematics::Constraint::Brake { member: i });
        }
    }
    let elements = shift::validate_shift_elements(&ctx, problems);
    let sound = problems.len() == structure_start;
    let (train, gear_states) = shift::validate_gear_states(&ctx, &elements, fixed_rows, io, sound, problems);
    let (gears, level) = lubrication::validate_lubrication(&ctx, &sets, &meshes, &mounts, problems);
    let (bearings, seals) = bearings::validate_bearings(&ctx, &gears, &sets, level, problems);
    let lub = &file.lubrication;
    let oil_x_l = oil.as_ref().map_or(1.0, |o| o.lubricant_factor_or_default().0);
    let losses = super::losses::validate_losses(
        &file.losses.clone().unwrap_or_default(),
        lub.sump_volume_l,
        oil_x_l,
        problems,
    );
    let element_names: Vec<&str> = file.shift_elements.iter().map(|e| e.name.as_str()).collect();
    let member_names: Vec<&str> = file.members.iter().map(|m| m.name.as_str()).collect();
    let clutch_packs = super::automatic::validate_clutch_packs(&file.clutch_packs, &element_names, problems);
    let pump = file
        .pump
        .as_ref()
        .and_then(|p| super::automatic::validate_pump(p, &member_names, problems));
    let launch = file.launch.as_ref().and_then(|t| {
        let gt = RatioTable::new(gear_states.iter().map(|g| (g.name.clone(), g.ratio())).collect());
        super::automatic::validate_launch(t, &gt, problems)
    });
    let auto_names = AutoNames {
        packs: clutch_packs.iter().map(|c| c.name.as_str()).collect(),
        pump: file.pump.is_some(),
        converter: file.launch.is_some(),
    };
    let thermal = file
        .thermal
        .as_ref()
        .and_then(|spec| thermal(spec, &gears, &meshes, (&bearings, &seals), &auto_names, problems));
    let vehicle = file
        .vehicle
        .as_ref()
        .and_then(|table| vehicle(table, &gear_states, problems));

    if problems.len() > start {
        return None;
    }
    let (input, output) = io;
    Some(Gearbox {
        name: file.model.name.clone(),
        description: file.model.description.clone().unwrap_or_default(),
        oil: oil?,
        members: file
            .members
            .iter()
            .map(|m| Member {
                name: m.name.clone(),
                kind: m.kind.unwrap_or(MemberKind::Shaft),
                fixed: m.fixed,
            })
            .collect(),
        gears,
        meshes,
        planetary_sets: sets,
        shift_elements: elements.list,
        gear_states,
        train: train?,
        input: input?,
        output: output?,
        oil_level: level,
        sump_volume: lub.sump_volume_l.map(|v| v * 1e-3),
        losses: losses?,
        thermal,
        vehicle,
        clutch_packs,
        pump,
        launch,
        bearings,
        seals,
    })
}

/// Loss-item names of the automatic's own parts (for heat rules).
struct AutoNames<'a> {
    packs: Vec<&'a str>,
    pump: bool,
    converter: bool,
}

/// `[thermal]` against the checked gears and the loss items of the model.
fn thermal(
    spec: &super::thermal::ThermalSpec,
    gears: &[Gear],
    meshes: &[Mesh],
    (bearings, seals): (&[super::bearings::Bearing], &[super::bearings::Seal]),
    auto: &AutoNames<'_>,
    problems: &mut Problems,
) -> Option<ThermalNetwork> {
    let infos: Vec<GearInfo<'_>> = gears
        .iter()
        .map(|g: &Gear| GearInfo {
            name: &g.name,
            radius: 0.5 * g.geometry.d_a.max(g.geometry.d_f),
            face_width: g.geometry.spec.b,
        })
        .collect();
    let mut names = LossItemNames::default();
    names.set(Source::Churning, gears.iter().map(|g| g.name.as_str()));
    names.set(Source::Pocketing, meshes.iter().map(|m| m.name.as_str()));
    names.set(Source::Sliding, meshes.iter().map(|m| m.name.as_str()));
    names.set(Source::ClutchDrag, auto.packs.iter().copied());
    names.set(Source::Pump, auto.pump.then_some("pump"));
    names.set(Source::Converter, auto.converter.then_some("converter"));
    names.set(Source::Bearing, bearings.iter().map(|b| b.name.as_str()));
    names.set(Source::Seal, seals.iter().map(|s| s.name.as_str()));
    validate_thermal(spec, &infos, &names, problems)
}

/// `[vehicle]` against the gear-state ratios.
fn vehicle(table: &toml::Table, gear_states: &[GearState], problems: &mut Problems) -> Option<Vehicle> {
    let gt = RatioTable::new(gear_states.iter().map(|g| (g.name.clone(), g.ratio())).collect());
    let checked = VehicleSpec::from_table(table).and_then(|spec| spec.validate(&gt));
    match checked {
        Ok(v) => Some(v),
        Err(list) => {
            for p in list {
                problems.push(p.path, p.value, p.allowed);
            }
            None
        }
    }
}
