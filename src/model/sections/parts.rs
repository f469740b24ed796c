//! The parts later sections name: the members and gears (checked first), and which gears are
//! planets of a set.

use std::collections::HashMap;

use super::gears::Gears;
use super::members::Members;
use crate::model::problems::Problems;

/// Members and gears by name, and the planet roles.
pub(crate) struct Parts<'a> {
    /// The members.
    pub members: Members<'a>,
    /// The gears with their geometry and members.
    pub gears: Gears<'a>,
    /// Gear name → index of the set naming it as a planet.
    pub planet_of: HashMap<&'a str, usize>,
}

impl Parts<'_> {
    /// Index of member `name`, or a problem at `path` listing the defined members.
    pub fn member(&self, name: &str, path: String, problems: &mut Problems) -> Option<usize> {
        self.members.lookup(name, path, problems)
    }

    /// Index of gear `name`, or a problem at `path` listing the defined gears.
    pub fn gear(&self, name: &str, path: String, problems: &mut Problems) -> Option<usize> {
        self.gears.lookup(name, path, problems)
    }

    /// True if gear `gi` is a planet of a set.
    pub fn is_planet(&self, gi: usize) -> bool {
        self.planet_of.contains_key(self.gears.specs[gi].name.as_str())
    }
}
