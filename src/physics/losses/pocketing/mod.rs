//! Pocketing losses: oil squeezed out of the closing tooth spaces of a mesh.
//!
//! Geometry after seed 004 (Choupo & Tchotang 2022): for a driver rotation angle φ1 the pocket
//! formed by a tooth of one gear entering a space of the other has a transverse area
//! `A_axial(φ1)` (the axial leakage area, also the pocket cross-section), a volume
//! `V = A_axial·b` and two radial leakage surfaces `S_r1 = g1·b`, `S_r2 = g2·b` (g = minimal
//! distance between the two flanks on each side). Everything is closed-form (involute properties,
//! closed-form polar integrals); see `areas.rs`. The tooth outline (involute and hob-generated
//! trochoid root) is the one of `physics::geometry::ToothProfile`, read through `teeth.rs`.
//!
//! Power after physics.md §6 [derived from seeds 000 and 004]: with
//! `A_out = 2·A_axial + S_r1 + S_r2`, outflow `Q = −ω1·dV/dφ1` while the pocket closes, Bernoulli
//! exit pressure `½ρ(Q/(C_d A_out))²`, energy per pocket passage `½ρω1²·K`,
//! `K = ∫ (−dV/dφ1)³/(C_d A_out)² dφ1` (closing phase only), and per family
//! `P = z1·ρ·ω1³·K/(4π)`. `K` is geometric and precomputed once (`PocketingMesh::new`).
//!
//! Files: `teeth.rs` (what the pocket geometry reads from `geometry::ToothProfile`), `areas.rs` (pocket geometry vs
//! φ1), `integral.rs` (tables, derivative, K, helical slices), `power.rs` (the run-time object).
//! All quantities SI (m, rad, m², m³, W); no allocation in `PocketingMesh::power`.

pub mod areas;
pub mod integral;
pub mod power;
pub mod teeth;

#[cfg(test)]
mod brute;

pub use areas::{GapKind, PocketFamily, PocketFamilyKind, PocketState};
pub use integral::PocketTable;
pub use power::{PocketingMesh, PocketingOptions};
pub use teeth::PocketTeeth;

use std::fmt;

/// Plain description of one external spur/helical gear mesh for the pocketing model (SI, rad).
///
/// `module` and `pressure_angle` are the normal values (m_n, α_n); for `helix_angle = 0` they are
/// the transverse ones. Tooth thicknesses follow the standard formula
/// `s_n = m_n(π/2 + 2x·tan α_n)` [std] (no thickness allowance); tip and root radii are given
/// (physics.md §2: `r_f = r − m_n(1.25 − x)` if not known), and the tool tip radius factor
/// ρ_fP* of the hob that generated the root fillet (ISO 53: 0.25 unless known). Gear 1 is the
/// driver: φ1 is its rotation angle, gear 2 turns by −φ1·z1/z2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PocketMeshInput {
    /// Number of teeth of gear 1 (driver).
    pub z1: u32,
    /// Number of teeth of gear 2.
    pub z2: u32,
    /// Normal module m_n (m).
    pub module: f64,
    /// Normal pressure angle α_n (rad).
    pub pressure_angle: f64,
    /// Profile shift coefficient of gear 1 (−).
    pub x1: f64,
    /// Profile shift coefficient of gear 2 (−).
    pub x2: f64,
    /// Tip radius of gear 1 (m).
    pub tip_radius1: f64,
    /// Tip radius of gear 2 (m).
    pub tip_radius2: f64,
    /// Root radius of gear 1 (m).
    pub root_radius1: f64,
    /// Root radius of gear 2 (m).
    pub root_radius2: f64,
    /// Operating centre distance a_w (m).
    pub centre_distance: f64,
    /// Face width b (m).
    pub face_width: f64,
    /// Reference helix angle β (rad); 0 for spur gears.
    pub helix_angle: f64,
    /// Tool tip radius factor ρ_fP* of gear 1 (−): fillet radius of the generating rack
    /// ρ_fP*·m_n (physics.md §2).
    pub rho_fp1: f64,
    /// Tool tip radius factor ρ_fP* of gear 2 (−).
    pub rho_fp2: f64,
}

/// Why a pocketing geometry could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum PocketingError {
    /// An input value is out of its allowed range (field name and message).
    InvalidInput(&'static str, String),
    /// The two gears do not mesh without interference with the given data.
    Interference(String),
    /// A numerical procedure did not converge (should not happen for valid gears).
    Numerical(String),
}

impl fmt::Display for PocketingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PocketingError::InvalidInput(field, msg) => {
                write!(f, "pocketing: invalid `{field}`: {msg}")
            }
            PocketingError::Interference(msg) => write!(f, "pocketing: gear interference: {msg}"),
            PocketingError::Numerical(msg) => write!(f, "pocketing: numerical failure: {msg}"),
        }
    }
}

impl std::error::Error for PocketingError {}

/// Check that a value is finite and strictly positive.
pub(crate) fn positive(field: &'static str, v: f64) -> Result<f64, PocketingError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(PocketingError::InvalidInput(
            field,
            format!("must be finite and > 0, got {v}"),
        ))
    }
}

impl PocketMeshInput {
    /// The pocket input of an external mesh of two gears built by the geometry module, at the
    /// operating centre distance `a_w` (m): their tip and root diameters, normal data, tool tip
    /// radius factors and the smaller face width.
    pub fn from_gears(
        g1: &crate::physics::geometry::GearGeometry,
        g2: &crate::physics::geometry::GearGeometry,
        a_w: f64,
    ) -> Self {
        Self {
            z1: g1.z(),
            z2: g2.z(),
            module: g1.spec.mn,
            pressure_angle: g1.spec.alpha_n,
            x1: g1.spec.x,
            x2: g2.spec.x,
            tip_radius1: g1.d_a / 2.0,
            tip_radius2: g2.d_a / 2.0,
            root_radius1: g1.d_f / 2.0,
            root_radius2: g2.d_f / 2.0,
            centre_distance: a_w,
            face_width: g1.spec.b.min(g2.spec.b),
            helix_angle: g1.spec.beta,
            rho_fp1: g1.spec.rho_fp,
            rho_fp2: g2.spec.rho_fp,
        }
    }

    /// Same mesh with every length multiplied by `k` (used by the units tests).
    pub fn scaled(&self, k: f64) -> Self {
        Self {
            module: self.module * k,
            tip_radius1: self.tip_radius1 * k,
            tip_radius2: self.tip_radius2 * k,
            root_radius1: self.root_radius1 * k,
            root_radius2: self.root_radius2 * k,
            centre_distance: self.centre_distance * k,
            face_width: self.face_width * k,
            ..*self
        }
    }
}

#[cfg(test)]
pub(crate) mod cases {
    //! Test meshes shared by the unit tests of this module.
    use super::PocketMeshInput;

    /// Root radius from physics.md §2: d_f = d − 2 m (1.25 − x).
    pub fn root_radius(z: u32, m: f64, x: f64) -> f64 {
        0.5 * (m * z as f64 - 2.0 * m * (1.25 - x))
    }

    /// FZG C-type gears (physics.md §2), root radii from the standard dedendum.
    pub fn fzg_c() -> PocketMeshInput {
        let m = 4.5e-3;
        PocketMeshInput {
            z1: 16,
            z2: 24,
            module: m,
            pressure_angle: 20f64.to_radians(),
            x1: 0.1817,
            x2: 0.1715,
            tip_radius1: 0.5 * 82.46e-3,
            tip_radius2: 0.5 * 118.36e-3,
            root_radius1: root_radius(16, m, 0.1817),
            root_radius2: root_radius(24, m, 0.1715),
            centre_distance: 91.5e-3,
            face_width: 14e-3,
            helix_angle: 0.0,
            rho_fp1: 0.25,
            rho_fp2: 0.25,
        }
    }

    /// Seed 004 table 2: z1 = z2 = 76, m = 4 mm, α = 20°, x = 0, b = 100 mm, standard
    /// tip (r + m) and root (r − 1.25 m) radii, standard centre distance.
    pub fn seed004() -> PocketMeshInput {
        let m = 4e-3;
        PocketMeshInput {
            z1: 76,
            z2: 76,
            module: m,
            pressure_angle: 20f64.to_radians(),
            x1: 0.0,
            x2: 0.0,
            tip_radius1: 0.5 * m * 76.0 + m,
            tip_radius2: 0.5 * m * 76.0 + m,
            root_radius1: root_radius(76, m, 0.0),
            root_radius2: root_radius(76, m, 0.0),
            centre_distance: m * 76.0,
            face_width: 0.1,
            helix_angle: 0.0,
            rho_fp1: 0.25,
            rho_fp2: 0.25,
        }
    }

    /// A helical version of `base` (normal data kept): reference diameters m_n z/cos β, tip
    /// d + 2m_n(1 + x), root d − 2m_n(1.25 − x), zero-backlash centre distance from
    /// `inv α_wt = inv α_t + 2 tan α_n (x1 + x2)/(z1 + z2)` (physics.md §2).
    pub fn helical(base: &PocketMeshInput, beta: f64) -> PocketMeshInput {
        let (m, an) = (base.module, base.pressure_angle);
        let at = (an.tan() / beta.cos()).atan();
        let (z1, z2) = (base.z1 as f64, base.z2 as f64);
        let (r1, r2) = (0.5 * m * z1 / beta.cos(), 0.5 * m * z2 / beta.cos());
        let inv = |a: f64| a.tan() - a;
        let target = inv(at) + 2.0 * an.tan() * (base.x1 + base.x2) / (z1 + z2);
        let mut aw = at;
        for _ in 0..50 {
            aw -= (inv(aw) - target) / aw.tan().powi(2);
        }
        PocketMeshInput {
            tip_radius1: r1 + m * (1.0 + base.x1),
            tip_radius2: r2 + m * (1.0 + base.x2),
            root_radius1: r1 - m * (1.25 - base.x1),
            root_radius2: r2 - m * (1.25 - base.x2),
            centre_distance: (r1 + r2) * at.cos() / aw.cos(),
            helix_angle: beta,
            ..*base
        }
    }

    /// An unequal, un-shifted pair with backlash (centre distance increased by 0.1 mm) and a
    /// small pinion (segment + arc root, seed 004 first case).
    pub fn unequal_with_backlash() -> PocketMeshInput {
        let m = 3e-3;
        let (z1, z2) = (13u32, 31u32);
        PocketMeshInput {
            z1,
            z2,
            module: m,
            pressure_angle: 20f64.to_radians(),
            x1: 0.3,
            x2: -0.1,
            tip_radius1: 0.5 * m * z1 as f64 + m * (1.0 + 0.3),
            tip_radius2: 0.5 * m * z2 as f64 + m * (1.0 - 0.1),
            root_radius1: root_radius(z1, m, 0.3),
            root_radius2: root_radius(z2, m, -0.1),
            centre_distance: 0.5 * m * (z1 + z2) as f64 + 0.7e-3,
            face_width: 20e-3,
            helix_angle: 0.0,
            rho_fp1: 0.25,
            rho_fp2: 0.25,
        }
    }
}
