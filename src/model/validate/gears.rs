//! `[[gears]]`: names, members, geometry.

use std::collections::HashMap;

use super::common::*;
use super::geometry::gear_geometry;
use crate::model::problems::Problems;
use crate::physics::geometry::GearGeometry;

/// Gear names → index, geometry and member of each gear (None where it failed).
pub(super) struct GearTable<'a> {
    /// Name → index.
    pub ix: HashMap<&'a str, usize>,
    /// Geometry per gear.
    pub geoms: Vec<Option<GearGeometry>>,
    /// Member per gear.
    pub member: Vec<Option<usize>>,
}

/// Validate `[[gears]]`; `member` resolves a member name at a key path.
pub(super) fn validate_gears<'a>(
    file: &'a crate::model::schema::ModelFile,
    member: &dyn Fn(&str, String, &mut Problems) -> Option<usize>,
    problems: &mut Problems,
) -> GearTable<'a> {
    let mut gear_ix: HashMap<&str, usize> = HashMap::new();
    let mut geoms: Vec<Option<GearGeometry>> = Vec::new();
    let mut gear_member: Vec<Option<usize>> = Vec::new();
    let roots = super::geometry::mating_tip_roots(file);
    for (i, g) in file.gears.iter().enumerate() {
        let p = format!("gears[{i}]");
        if g.name.trim().is_empty() {
            problems.push(format!("{p}.name"), "\"\"", "must not be empty");
        } else if gear_ix.insert(g.name.as_str(), i).is_some() {
            problems.push(format!("{p}.name"), q(&g.name), "duplicate gear name");
        }
        gear_member.push(member(&g.member, format!("{p}.member"), problems));
        geoms.push(gear_geometry(g, &p, roots[i], problems));
    }
    if file.gears.is_empty() {
        problems.push("gears", "[]", "at least one [[gears]] entry is required");
    }

    GearTable {
        ix: gear_ix,
        geoms,
        member: gear_member,
    }
}
