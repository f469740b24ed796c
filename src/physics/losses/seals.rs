//! Radial lip seals on rotating shafts.
//!
//! ISO/TR 14179-2 gives the power loss of a radial shaft seal as
//!
//! ```text
//! P_seal = 7.69e-6 · d_sh² · n        [W; d_sh shaft diameter in mm, n in r/min]
//! ```
//!
//! Source: ISO/TR 14179-2:2001, as used by an open gearbox-loss script ("P_VD
//! Dichtungsverluste nach ISO 14179-2"; docs/physics.md §Seals names it). The technical report
//! gives no temperature dependence: the loss is independent of the oil temperature here, and the
//! lip is taken as running in, lubricated and without pressure differential.

use crate::physics::units::{rad_s_to_rpm, MM_PER_M};

/// Seal-loss law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SealLaw {
    /// ISO/TR 14179-2: P = 7.69e-6·d²·n (d mm, n r/min).
    Iso14179,
    /// A maker's or measured constant friction torque, N·m.
    Torque(f64),
}

/// A radial lip seal on a shaft.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LipSeal {
    /// Shaft diameter at the lip, m.
    pub shaft_diameter: f64,
    /// Law.
    pub law: SealLaw,
}

/// ISO/TR 14179-2 coefficient, W/(mm²·r/min).
pub const ISO14179_SEAL: f64 = 7.69e-6;

impl LipSeal {
    /// Friction torque, N·m (constant in speed for ISO/TR 14179-2: P ∝ n).
    pub fn torque(&self) -> f64 {
        match self.law {
            SealLaw::Iso14179 => {
                // P = k d² n with n = ω·30/π → M = P/ω = k d² · 30/π.
                let d = self.shaft_diameter * MM_PER_M;
                rad_s_to_rpm(ISO14179_SEAL * d * d)
            }
            SealLaw::Torque(m) => m,
        }
    }

    /// Power loss at relative shaft speed `omega` (rad/s), W.
    pub fn power(&self, omega: f64) -> f64 {
        self.torque() * omega.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso14179_law_in_catalogue_units() {
        // 50 mm shaft at 3000 r/min: 7.69e-6 · 2500 · 3000 = 57.675 W.
        let s = LipSeal {
            shaft_diameter: 0.05,
            law: SealLaw::Iso14179,
        };
        let w = crate::physics::units::rpm_to_rad_s(3000.0);
        assert!((s.power(w) - 57.675).abs() < 1e-9);
        // Quadratic in the diameter, linear in the speed.
        let s2 = LipSeal {
            shaft_diameter: 0.1,
            ..s
        };
        assert!((s2.power(w) / s.power(w) - 4.0).abs() < 1e-12);
        assert!((s.power(2.0 * w) / s.power(w) - 2.0).abs() < 1e-12);
        assert_eq!(s.power(0.0), 0.0);
    }
}
