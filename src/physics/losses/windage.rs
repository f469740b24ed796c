//! Windage: the drag of a gear that runs above the oil, in the housing's air.
//!
//! Two models, both the churning models of §5 applied to a gear wholly surrounded by air:
//!
//! - **Seetharaman–Kahraman** (default): their spin-loss formulation models the drag of a gear
//!   "along its periphery and faces, as well as for eddies formed in the cavities between
//!   adjacent teeth", with the lubricant as the fluid for churning and "air or air–oil mixture in
//!   the case of windage" (Seetharaman 2009, dissertation abstract). Here: the drag terms of
//!   [`super::churning::seetharaman`] with the gear fully immersed (θ = π) in air.
//! - **Stavytskyi et al.** (seed 001 §2.1): "when h_i ≤ 0, similar to the case of h_i = 2, we can
//!   consider that the wheel is completely immersed, but in air". Here: [`super::churning::stavytskyi`]
//!   with h̄ = 2 in air.
//!
//! The two disagree (the Stavytskyi form carries a Coriolis term of the air in the tooth spaces,
//! Seetharaman–Kahraman a cavity eddy term; docs/validation.md "Windage").
//!
//! Air: dry, 1 atm, 50 °C (the temperature of [`crate::physics::thermal::AIR_50C`], whose ν is
//! used); density from the ideal gas law ρ = p/(R T) \[std\] with p = 101 325 Pa and
//! R = 287.05 J/(kg·K). Oil mist in the air is not modelled.

use super::churning::{ChurningConfig, ChurningError, ChurningGear, ChurningModel, GearChurning, OilState};
use crate::physics::thermal::AIR_50C;

/// Dry air at 50 °C and 1 atm: density from p/(R T), kinematic viscosity of [`AIR_50C`].
pub const AIR: OilState = OilState {
    density: 101_325.0 / (287.05 * 323.15),
    kinematic_viscosity: AIR_50C.kinematic_viscosity,
};

/// Windage model of one gear.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearWindage {
    model: GearChurning,
}

impl GearWindage {
    /// Build the windage model `model` (Seetharaman or Stavytskyi; their coefficients from
    /// `config`) of `gear`; its immersion is replaced by full immersion.
    pub fn new(
        model: ChurningModel,
        config: &ChurningConfig,
        gear: &ChurningGear,
    ) -> Result<Self, ChurningError> {
        let mut g = *gear;
        g.immersion_depth = 2.0 * g.tip_radius;
        let cfg = ChurningConfig { model, ..*config };
        Ok(GearWindage {
            model: GearChurning::new(&cfg, &g)?,
        })
    }

    /// Windage power (W) at speed `omega` (rad/s, relative to the surrounding air).
    pub fn power(&self, omega: f64) -> f64 {
        self.model.power(omega, &AIR).total
    }

    /// The underlying drag model (for its range checks, with [`AIR`]).
    pub fn model(&self) -> &GearChurning {
        &self.model
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::units::rpm_to_rad_s;

    fn gear() -> ChurningGear {
        // FZG C wheel-like: z 24, m 4.5 mm, b 14 mm.
        ChurningGear {
            tip_radius: 0.05918,
            root_radius: 0.04915,
            pitch_radius: 0.054,
            face_width: 0.014,
            teeth: 24,
            normal_module: 0.0045,
            helix_angle: 0.0,
            normal_pressure_angle: 20f64.to_radians(),
            profile_shift: 0.17,
            space_width_tip: 0.004,
            tooth_height: 0.01,
            immersion_depth: -0.01,
        }
    }

    #[test]
    fn air_density_is_the_ideal_gas_value() {
        assert!((AIR.density - 1.0923).abs() < 1e-3);
    }

    #[test]
    fn windage_is_positive_grows_with_speed_and_the_models_differ() {
        let cfg = ChurningConfig::default();
        let s = GearWindage::new(ChurningModel::Seetharaman, &cfg, &gear()).unwrap();
        let t = GearWindage::new(ChurningModel::Stavytskyi, &cfg, &gear()).unwrap();
        let w = |rpm: f64| rpm_to_rad_s(rpm);
        let (a, b) = (s.power(w(3000.0)), s.power(w(6000.0)));
        assert!(a > 0.0 && b > 2.0 * a, "{a} {b}");
        let (c, d) = (t.power(w(3000.0)), t.power(w(6000.0)));
        assert!(c > 0.0 && d > 2.0 * c, "{c} {d}");
        assert!((a / c - 1.0).abs() > 0.05, "{a} {c}");
        // the same gear in oil churns far more than in air
        let oil = OilState {
            density: 870.0,
            kinematic_viscosity: 30e-6,
        };
        let mut full = gear();
        full.immersion_depth = 2.0 * full.tip_radius;
        let cfg_s = ChurningConfig {
            model: ChurningModel::Seetharaman,
            ..ChurningConfig::default()
        };
        let churn = GearChurning::new(&cfg_s, &full)
            .unwrap()
            .power(w(3000.0), &oil)
            .total;
        assert!(churn > 100.0 * a);
    }
}
