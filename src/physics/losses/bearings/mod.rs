//! Rolling-bearing friction: the SKF (2004) frictional-moment model ([`skf`]) and Palmgren's
//! load-and-speed model ([`palmgren`]) as the simple alternative.
//!
//! Interface in SI (m, N, rad/s, m²/s, W); both models are published in catalogue units (mm,
//! N, r/min, mm²/s → N·mm) and convert at their boundary. The split into a per-sample part
//! ([`BearingFriction::load_terms`]: everything that depends on the loads and the speed) and a
//! per-call part ([`BearingFriction::moment`]: everything that depends on the oil viscosity) lets
//! the scene cache the first per cycle sample.

pub mod palmgren;
pub mod skf;

pub use palmgren::Palmgren;
pub use skf::{DragForm, Skf, SkfConstants, SkfKind};

use crate::physics::units::MM2_S_PER_M2_S;

/// A bearing's boundary dimensions, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BearingSize {
    /// Bore diameter d, m.
    pub bore: f64,
    /// Outside diameter D, m.
    pub outside: f64,
}

impl BearingSize {
    /// Mean diameter d_m = (d + D)/2, m.
    pub fn mean(&self) -> f64 {
        0.5 * (self.bore + self.outside)
    }
}

/// Loads on a bearing, N (magnitudes).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BearingLoad {
    /// Radial load F_r, N.
    pub radial: f64,
    /// Axial load F_a, N.
    pub axial: f64,
}

/// Lubricant state at the bearing: ν in mm²/s and the powers of it the models use, computed
/// once per oil state and shared by every bearing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BearingOil {
    /// Kinematic viscosity ν, mm²/s.
    pub nu: f64,
    /// ν^0.6, ν^0.64, ν^1.4, ν^1.379, ν^(2/3).
    pub p060: f64,
    /// ν^0.64.
    pub p064: f64,
    /// ν^1.4.
    pub p140: f64,
    /// ν^1.379.
    pub p1379: f64,
    /// ν^(2/3).
    pub p0667: f64,
}

impl BearingOil {
    /// Oil of kinematic viscosity `nu` (m²/s).
    pub fn new(nu: f64) -> BearingOil {
        let v = nu * MM2_S_PER_M2_S;
        let ln = v.ln();
        BearingOil {
            nu: v,
            p060: (0.6 * ln).exp(),
            p064: (0.64 * ln).exp(),
            p140: (1.4 * ln).exp(),
            p1379: (1.379 * ln).exp(),
            p0667: (ln * 2.0 / 3.0).exp(),
        }
    }
}

/// A bearing friction model.
#[derive(Debug, Clone, PartialEq)]
pub enum BearingFriction {
    /// SKF (2004) frictional-moment model.
    Skf(Skf),
    /// Palmgren's load and speed terms.
    Palmgren(Palmgren),
}

/// Terms of a bearing's friction fixed by its loads and speed (one cycle sample).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoadTerms {
    /// Relative speed of the rings, r/min (catalogue unit; ≥ 0).
    pub n_rpm: f64,
    /// SKF: G_rr (incl. its catalogue units); Palmgren: unused.
    pub g_rr: f64,
    /// SKF: G_sl; Palmgren: M1 = f1·P1·d_m in N·mm.
    pub g_sl: f64,
    /// Powers of the speed: SKF `[(n d_m)^1.28, n^0.6, n^1.4, n²·(n d_m² f_t)^−1.379]`;
    /// Palmgren `[n^(2/3), 0, 0, 0]`.
    pub speed: [f64; 4],
}

/// Frictional moment of a bearing split in its terms, N·m.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BearingMoment {
    /// Rolling (SKF M_rr; Palmgren load-independent M0), N·m.
    pub rolling: f64,
    /// Sliding (SKF M_sl; Palmgren load term M1), N·m.
    pub sliding: f64,
    /// Integral seals (SKF M_seal), N·m.
    pub seal: f64,
    /// Oil-bath drag (SKF M_drag), N·m.
    pub drag: f64,
}

impl BearingMoment {
    /// Total frictional moment, N·m.
    pub fn total(&self) -> f64 {
        self.rolling + self.sliding + self.seal + self.drag
    }
}

/// r/min per rad/s.
pub(crate) const RPM_PER_RAD_S: f64 = 30.0 / std::f64::consts::PI;

impl BearingFriction {
    /// Load- and speed-dependent terms for ring speed `omega` (rad/s, sign ignored) and `load`.
    pub fn load_terms(&self, omega: f64, load: BearingLoad) -> LoadTerms {
        let n = omega.abs() * RPM_PER_RAD_S;
        match self {
            BearingFriction::Skf(m) => m.load_terms(n, load),
            BearingFriction::Palmgren(m) => m.load_terms(n, load),
        }
    }

    /// The SKF speed powers ([`LoadTerms::speed`]) of a ring turning at `ratio` times a
    /// reference speed, per unit reference speed (rad/s): at reference speed ω they are this
    /// times [`skf::speed_exponent_powers`]`(ω)`. `None` for Palmgren.
    pub fn speed_powers_per_unit(&self, ratio: f64) -> Option<[f64; 4]> {
        match self {
            BearingFriction::Skf(m) => Some(m.speed_powers(ratio.abs() * RPM_PER_RAD_S)),
            BearingFriction::Palmgren(_) => None,
        }
    }

    /// As [`Self::load_terms`], with the SKF speed powers `speed` at `omega` when already known
    /// (ignored by Palmgren). The result equals [`Self::load_terms`]'s to rounding.
    pub fn load_terms_with_speed(&self, omega: f64, load: BearingLoad, speed: Option<[f64; 4]>) -> LoadTerms {
        let n = omega.abs() * RPM_PER_RAD_S;
        match self {
            BearingFriction::Skf(m) => m.load_terms_with(n, load, speed),
            BearingFriction::Palmgren(m) => m.load_terms(n, load),
        }
    }

    /// Frictional moment with terms `t` and oil `oil`.
    pub fn moment(&self, t: &LoadTerms, oil: BearingOil) -> BearingMoment {
        match self {
            BearingFriction::Skf(m) => m.moment(t, oil),
            BearingFriction::Palmgren(m) => m.moment(t, oil),
        }
    }

    /// Power loss, W, at ring speed `omega` (rad/s), `load` and `oil`.
    pub fn power(&self, omega: f64, load: BearingLoad, oil: BearingOil) -> f64 {
        let t = self.load_terms(omega, load);
        self.moment(&t, oil).total() * omega.abs()
    }
}

/// A model could not be built from its inputs.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct BearingError(pub String);

#[cfg(test)]
mod tests;
