//! Sliding (load-dependent mesh friction) losses — physics.md §7, seed 003 (Ponchai).
//!
//! Build once per mesh with [`SlidingMesh::new`] (path of contact, contact-path tables over one base
//! pitch, load shares); evaluate with [`SlidingMesh::power`] (allocation-free: it only reads the
//! tables and accumulates scalars).
//!
//! Files: `contact` (path of contact, tables), `load_sharing` (spur sharing models), `helical`
//! (Niemann–Richer, slices, three-case contact length), `friction` (μ laws and unit conversions),
//! `moment_balance` (seed 003 ratio vs first order), `closed_form` (ISO/TR 14179-2, Ohlendorf).
//!
//! Conventions: SI inside. Speeds are taken in magnitude (planetary meshes: the caller passes
//! carrier-frame speeds); the power-flow direction is sign(T1·ω1): ≥ 0 means gear 1 drives.
//! Instantaneous loss of element k: `P_k = μ_k F_k v_g,k` [std], F_k = |T1|·LS_k/(r_b1 cos β_b),
//! v_g = |s|(ω1 + ω2) external, |s||ω1 − ω2| internal, v_Σ = ω1ρ1 + ω2ρ2; mesh power = average over
//! one base pitch `P̄ = (1/p_bt)∫Σ_k P_k ds_ref` (Gauss–Legendre for spur, midpoint for helical).

pub mod closed_form;
pub mod contact;
pub mod friction;
pub mod helical;
pub mod load_sharing;
pub mod mesh;
pub mod moment_balance;

use std::fmt;

pub use contact::{ContactElement, ContactPath, Sample};
pub use friction::{BenedictKelley, ContactState, FrictionLaw, IsoTc60, Schlenk};
pub use helical::HelicalDistribution;
pub use load_sharing::LoadSharing;
pub use mesh::PowerLaw;
pub use mesh::SlidingMesh;
pub use moment_balance::LossForm;

/// Errors from building a sliding-loss mesh.
#[derive(Debug, Clone, PartialEq)]
pub enum SlidingError {
    /// A scalar is out of its admissible range.
    InvalidInput {
        /// Field name.
        field: &'static str,
        /// Offending value.
        value: f64,
        /// What is allowed.
        expected: &'static str,
    },
    /// Inconsistent or impossible mesh geometry (interference, inconsistent centre distance...).
    Geometry(String),
    /// Contact ratio outside what a model supports.
    ContactRatio {
        /// ε_α of the mesh.
        eps_alpha: f64,
        /// Explanation.
        detail: &'static str,
    },
}

impl fmt::Display for SlidingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SlidingError::InvalidInput {
                field,
                value,
                expected,
            } => write!(
                f,
                "sliding loss: {field} = {value} is invalid (expected {expected})"
            ),
            SlidingError::Geometry(s) => write!(f, "sliding loss: {s}"),
            SlidingError::ContactRatio { eps_alpha, detail } => {
                write!(f, "sliding loss: ε_α = {eps_alpha:.4}: {detail}")
            }
        }
    }
}

impl std::error::Error for SlidingError {}

/// Mesh description from primitive scalars (SI, rad). Gear 1 is the pinion (for an internal mesh,
/// gear 2 is the ring and `tip_radius2` its internal tip radius, smaller than its pitch radius).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlidingMeshInput {
    /// Base radius r_b1 (m).
    pub base_radius1: f64,
    /// Base radius r_b2 (m).
    pub base_radius2: f64,
    /// Transverse operating pressure angle α_wt (rad).
    pub operating_pressure_angle: f64,
    /// Tip radius r_a1 (m).
    pub tip_radius1: f64,
    /// Tip radius r_a2 (m; ring: internal tip radius).
    pub tip_radius2: f64,
    /// Operating centre distance a_w (m).
    pub centre_distance: f64,
    /// Common face width b (m).
    pub face_width: f64,
    /// Base helix angle β_b (rad, ≥ 0; 0 = spur).
    pub base_helix_angle: f64,
    /// Transverse base pitch p_bt (m).
    pub transverse_base_pitch: f64,
    /// Internal mesh (gear 2 is a ring gear).
    pub internal: bool,
    /// Tooth count of gear 1.
    pub z1: u32,
    /// Tooth count of gear 2.
    pub z2: u32,
    /// Arithmetic-mean roughness Ra of gear 1's flanks (m).
    pub roughness_ra1: f64,
    /// Arithmetic-mean roughness Ra of gear 2's flanks (m).
    pub roughness_ra2: f64,
}

/// Relative tolerance of the consistency checks between the input scalars.
pub const CONSISTENCY_TOL: f64 = 1e-6;

/// Base helix angles below this (rad) are treated as spur (load-sharing models apply).
pub const SPUR_BETA_B: f64 = 1e-9;

impl SlidingMeshInput {
    /// Check ranges and consistency: a_w cos α_wt = r_b1 ± r_b2 and p_bt = 2π r_b1/z1 = 2π r_b2/z2
    /// (relative tolerance [`CONSISTENCY_TOL`]).
    pub fn validate(&self) -> Result<(), SlidingError> {
        let positive = [
            ("base_radius1", self.base_radius1),
            ("base_radius2", self.base_radius2),
            ("tip_radius1", self.tip_radius1),
            ("tip_radius2", self.tip_radius2),
            ("centre_distance", self.centre_distance),
            ("face_width", self.face_width),
            ("transverse_base_pitch", self.transverse_base_pitch),
        ];
        for (field, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(SlidingError::InvalidInput {
                    field,
                    value,
                    expected: "finite and > 0 (m)",
                });
            }
        }
        let a = self.operating_pressure_angle;
        if !(a.is_finite() && a > 0.0 && a < std::f64::consts::FRAC_PI_2) {
            return Err(SlidingError::InvalidInput {
                field: "operating_pressure_angle",
                value: a,
                expected: "0 < α_wt < π/2 (rad)",
            });
        }
        let bb = self.base_helix_angle;
        if !(bb.is_finite() && (0.0..std::f64::consts::FRAC_PI_2).contains(&bb)) {
            return Err(SlidingError::InvalidInput {
                field: "base_helix_angle",
                value: bb,
                expected: "0 <= β_b < π/2 (rad)",
            });
        }
        for (field, value) in [
            ("roughness_ra1", self.roughness_ra1),
            ("roughness_ra2", self.roughness_ra2),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(SlidingError::InvalidInput {
                    field,
                    value,
                    expected: "finite and >= 0 (m)",
                });
            }
        }
        if self.z1 == 0 || self.z2 == 0 {
            return Err(SlidingError::InvalidInput {
                field: "z1/z2",
                value: self.z1.min(self.z2) as f64,
                expected: ">= 1",
            });
        }
        if self.internal && self.z2 <= self.z1 {
            return Err(SlidingError::InvalidInput {
                field: "z2 (ring)",
                value: self.z2 as f64,
                expected: "internal mesh: ring tooth count z2 > pinion tooth count z1",
            });
        }
        let rb_sum = if self.internal {
            self.base_radius2 - self.base_radius1
        } else {
            self.base_radius2 + self.base_radius1
        };
        let lhs = self.centre_distance * a.cos();
        if ((lhs - rb_sum) / rb_sum).abs() > CONSISTENCY_TOL {
            return Err(SlidingError::Geometry(format!(
                "a_w·cos α_wt = {lhs} m but r_b2 {} r_b1 = {rb_sum} m",
                if self.internal { "−" } else { "+" }
            )));
        }
        let tau = 2.0 * std::f64::consts::PI;
        for (rb, z, name) in [
            (self.base_radius1, self.z1, "1"),
            (self.base_radius2, self.z2, "2"),
        ] {
            let p = tau * rb / z as f64;
            if ((p - self.transverse_base_pitch) / p).abs() > CONSISTENCY_TOL {
                return Err(SlidingError::Geometry(format!(
                    "p_bt = {} m but 2π r_b{name}/z{name} = {p} m",
                    self.transverse_base_pitch
                )));
            }
        }
        Ok(())
    }

    /// Gear ratio u = z2/z1.
    pub fn gear_ratio(&self) -> f64 {
        self.z2 as f64 / self.z1 as f64
    }

    /// Composite roughness Ra = (Ra1 + Ra2)/2 (m), as used by all μ laws here.
    pub fn composite_roughness(&self) -> f64 {
        0.5 * (self.roughness_ra1 + self.roughness_ra2)
    }
}

/// Model options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlidingOptions {
    /// Spur load sharing (ignored for helical meshes).
    pub load_sharing: LoadSharing,
    /// Helical load distribution along the contact lines (ignored for spur meshes).
    pub helical_distribution: HelicalDistribution,
    /// Friction law.
    pub friction: FrictionLaw,
    /// First-order loss or seed 003's moment-balance form.
    pub loss_form: LossForm,
    /// Spur: number of quadrature nodes over one base pitch (rounded up to whole 4-point panels).
    pub samples: usize,
    /// Helical: number of time samples over one base pitch (midpoint rule).
    pub helical_time_samples: usize,
    /// Helical: number of face-width slices (seed 003 uses 150).
    pub slices: usize,
    /// Fraction of the sliding loss that heats gear 1 (default 0.5); gear 2 gets the rest.
    pub heat_to_gear1: f64,
}

impl Default for SlidingOptions {
    fn default() -> Self {
        Self {
            load_sharing: LoadSharing::Uniform,
            helical_distribution: HelicalDistribution::default(),
            friction: FrictionLaw::default(),
            loss_form: LossForm::FirstOrder,
            samples: 64,
            helical_time_samples: 24,
            slices: 150,
            heat_to_gear1: 0.5,
        }
    }
}

/// Oil state at the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OilState {
    /// Dynamic viscosity η (Pa·s), > 0.
    pub dynamic_viscosity: f64,
    /// Density ρ (kg/m³) (not used by the implemented μ laws; kept for kinematic-viscosity laws).
    pub density: f64,
}

/// Mesh sliding loss, averaged over one base pitch.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SlidingPower {
    /// Total loss (W).
    pub total: f64,
    /// Part heating gear 1 (W).
    pub to_gear1: f64,
    /// Part heating gear 2 (W).
    pub to_gear2: f64,
    /// Effective friction coefficient P/Σ(F v_g) (loss-weighted mean μ); 0 when nothing slides.
    pub mean_mu: f64,
}

/// Test fixtures shared by the sliding modules' tests.
#[cfg(test)]
pub(crate) mod cases {
    use super::SlidingMeshInput;

    /// Two equal gears, standard addendum, at the reference centre distance: z teeth, transverse
    /// module `m`, pressure angle `alpha`, pitch-circle helix angle `beta`, b 20 mm, roughness `ra`.
    /// Seed 003's example is `equal_pair(30, 0.003, 20°, β, 0.825e-6)`.
    pub(crate) fn equal_pair(z: u32, m: f64, alpha: f64, beta: f64, ra: f64) -> SlidingMeshInput {
        let rp = 0.5 * m * z as f64;
        let rb = rp * alpha.cos();
        SlidingMeshInput {
            base_radius1: rb,
            base_radius2: rb,
            operating_pressure_angle: alpha,
            tip_radius1: rp + m,
            tip_radius2: rp + m,
            centre_distance: 2.0 * rp,
            face_width: 0.02,
            base_helix_angle: (beta.tan() * alpha.cos()).atan(),
            transverse_base_pitch: std::f64::consts::PI * m * alpha.cos(),
            internal: false,
            z1: z,
            z2: z,
            roughness_ra1: ra,
            roughness_ra2: ra,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spur() -> SlidingMeshInput {
        let (m, alpha) = (0.003, 20f64.to_radians());
        SlidingMeshInput {
            base_radius1: 0.045 * alpha.cos(),
            base_radius2: 0.045 * alpha.cos(),
            operating_pressure_angle: alpha,
            tip_radius1: 0.048,
            tip_radius2: 0.048,
            centre_distance: 0.09,
            face_width: 0.02,
            base_helix_angle: 0.0,
            transverse_base_pitch: std::f64::consts::PI * m * alpha.cos(),
            internal: false,
            z1: 30,
            z2: 30,
            roughness_ra1: 0.5e-6,
            roughness_ra2: 1.0e-6,
        }
    }

    #[test]
    fn validate_accepts_consistent_and_rejects_inconsistent_input() {
        let g = spur();
        assert!(g.validate().is_ok());
        assert!((g.composite_roughness() - 0.75e-6).abs() < 1e-20);
        assert_eq!(g.gear_ratio(), 1.0);
        let e = SlidingMeshInput { z2: 31, ..g }.validate().unwrap_err();
        assert!(matches!(e, SlidingError::Geometry(_)), "{e}");
        let e = SlidingMeshInput {
            roughness_ra2: -1.0,
            ..g
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("roughness_ra2"), "{e}");
        let e = SlidingMeshInput {
            base_helix_angle: 1.6,
            ..g
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("base_helix_angle"));
        // internal mesh: ring must have more teeth; a_w cos α_wt = r_b2 − r_b1
        let int = SlidingMeshInput { internal: true, ..g };
        assert!(int.validate().is_err());
    }
}
