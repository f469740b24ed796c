//! The model-file sections, one file each, holding the section's serde struct(s) as written
//! (units in the keys), its checks with their key paths, and the checked form it becomes (SI).
//! Files that are not a section: [`common`] (helpers), [`parts`] (members and gears by name, which
//! later sections look up), [`bearing_friction`] (constants of the bearing friction models).

pub mod bearing_friction;
pub mod bearings;
pub mod circuit;
pub mod clutch_packs;
pub mod common;
pub mod gear_states;
pub mod gears;
pub mod launch;
pub mod loss_alternatives;
pub mod losses;
pub mod lubrication;
pub mod members;
pub mod meshes;
pub mod model;
pub mod oil;
pub mod parts;
pub mod planetary_sets;
pub mod pump;
pub mod seals;
pub mod shift_elements;
pub mod thermal;
pub mod train;
pub mod uncertainty;
pub mod vehicle;
