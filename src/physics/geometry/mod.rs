//! Gear and mesh geometry of cylindrical involute gears (external and internal, spur and
//! helical), in SI units (m, rad).
//!
//! * [`involute`]: `inv`, `inv_inverse` and numerical helpers;
//! * [`gear`]: [`GearSpec`] (input) → [`GearGeometry`] (diameters, pitches, thicknesses,
//!   undercut flag; conventions for ring gears documented there);
//! * [`profile`]: [`ToothProfile`] — involute + rack-generated trochoidal root fillet
//!   (external) or circular-arc fillet (ring), sampled polygons and exact areas;
//! * [`mesh`]: [`MeshGeometry`] — operating pressure angle and centre distance, path of
//!   contact A..E in the coordinate `s` along the line of action, contact ratios, curvature
//!   radii and speeds along the path.
//!
//! Sources: ISO 21771 / ISO 53 relations as given in `spec/physics.md` §2 [std]; derivations
//! written next to each formula (\[derived\]); the internal-gear tip-interference criterion is
//! \[recalled\] from the KHK gear technical reference and checked by a brute-force test.

// `!(a > b)` is used on purpose: it also rejects NaN, which `a <= b` would let through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod error;
pub mod gear;
pub mod involute;
pub mod mesh;
pub mod profile;

pub use error::GeometryError;
pub use gear::{GearGeometry, GearSpec};
pub use involute::{inv, inv_inverse};
pub use mesh::{MeshGeometry, MeshKind};
pub use profile::{polygon_area, ToothProfile};
