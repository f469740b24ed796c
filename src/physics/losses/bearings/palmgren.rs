//! Palmgren's bearing friction: a load-independent term and a load term,
//!
//! ```text
//! M0 = 1e-7·f0·(ν·n)^(2/3)·d_m³      (ν·n ≥ 2000)       [N·mm, ν mm²/s, n r/min, d_m mm]
//! M0 = 160e-7·f0·d_m³                 (ν·n < 2000; used here: the larger of the two, continuous)
//! M1 = f1·P1·d_m,   P1 = max(F_r, k_a·F_a + k_r·F_r)
//! ```
//!
//! Source: Palmgren's model as given by Harris & Kotzalas, *Rolling Bearing Analysis* (the form
//! every bearing maker's catalogue repeats). The factors f0 (type and lubrication) and f1 (type
//! and load) have no defaults here: their tables were not found in an accessible source, so each
//! bearing gives its own (docs/physics.md §Bearings).

use super::{BearingError, BearingLoad, BearingMoment, BearingOil, BearingSize, LoadTerms};
use crate::physics::units::{MM_PER_M, N_M_PER_N_MM};

/// Palmgren model of one bearing.
#[derive(Debug, Clone, PartialEq)]
pub struct Palmgren {
    /// f0·d_m³ in mm³.
    f0_dm3: f64,
    /// f1·d_m in mm.
    f1_dm: f64,
    /// Load factors of P1 = max(F_r, k_a·F_a + k_r·F_r).
    k_a: f64,
    k_r: f64,
}

impl Palmgren {
    /// Build from the size, f0, f1 and the load factors of P1.
    pub fn new(size: BearingSize, f0: f64, f1: f64, k_a: f64, k_r: f64) -> Result<Palmgren, BearingError> {
        let dm = size.mean() * MM_PER_M;
        if !(dm > 0.0 && f0 >= 0.0 && f1 >= 0.0 && k_a.is_finite() && k_r.is_finite()) {
            return Err(BearingError(format!(
                "d_m = {dm} mm, f0 = {f0}, f1 = {f1}: need d_m > 0 and f0, f1 ≥ 0"
            )));
        }
        Ok(Palmgren {
            f0_dm3: f0 * dm.powi(3),
            f1_dm: f1 * dm,
            k_a,
            k_r,
        })
    }

    /// M1 (N·mm) at `load`; speed `n` (r/min) kept for the per-call term.
    pub fn load_terms(&self, n: f64, load: BearingLoad) -> LoadTerms {
        let (fr, fa) = (load.radial.abs(), load.axial.abs());
        let p1 = fr.max(self.k_a * fa + self.k_r * fr);
        LoadTerms {
            n_rpm: n,
            g_rr: 0.0,
            g_sl: self.f1_dm * p1,
            speed: [n.powf(2.0 / 3.0), 0.0, 0.0, 0.0],
        }
    }

    /// Moment with the load terms `t` at `oil`.
    pub fn moment(&self, t: &LoadTerms, oil: BearingOil) -> BearingMoment {
        if t.n_rpm == 0.0 {
            return BearingMoment::default();
        }

        // Published: (ν n)^(2/3) for ν n ≥ 2000, the constant 160 below — a 0.8 % jump at
        // 2000 (2000^(2/3) = 158.7). The larger of the two is used instead: continuous in the oil
        // temperature (the integrator's error control needs a smooth right-hand side), equal to
        // the published law except for 2000 ≤ ν n < 2024 (docs/physics.md §Bearings).
        let m0 = 1e-7 * self.f0_dm3 * (t.speed[0] * oil.p0667).max(160.0);
        BearingMoment {
            rolling: N_M_PER_N_MM * m0,
            sliding: N_M_PER_N_MM * t.g_sl,
            seal: 0.0,
            drag: 0.0,
        }
    }
}
