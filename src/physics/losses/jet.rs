//! Impulse loss of a lubricating jet at a mesh \[derived: momentum balance\].
//!
//! A jet of mass flow ṁ meets the teeth at the pitch line. Its oil arrives with the velocity
//! component `v_j cos θ` along the teeth's pitch-line velocity `v_p` (θ the angle between the jet
//! and that velocity: 0 with the teeth, 90° radial, 180° against them) and is carried away by
//! the teeth at `v_p`. The tangential force the teeth exert on the oil is `ṁ (v_p − v_j cos θ)`,
//! and the power they spend on it
//!
//! `P = ṁ · v_p · (v_p − v_j cos θ)`.
//!
//! Against the teeth (θ = 180°) this is `ρ Q v_p (v_p + v_j)`, the impulse loss an open
//! implementation of the FVA-style load-independent losses attributes to Ariura (docs/validation.md
//! "Jet impulse"). A jet faster than the teeth along their motion would drive them: the loss is
//! then taken as zero (the oil's excess momentum is not returned to the gear train).
//!
//! Jet speed from the supply pressure p (no nozzle loss) \[std, Bernoulli\]: `v_j = √(2p/ρ)`.
//!
//! Units: SI (kg/s, m/s, rad, Pa, kg/m³, W).

/// Speed of a jet issuing from a line at gauge pressure `pressure` (Pa) into the housing:
/// `√(2p/ρ)`.
pub fn jet_speed(pressure: f64, density: f64) -> f64 {
    (2.0 * pressure.max(0.0) / density).sqrt()
}

/// Impulse power (W) to bring a jet of mass flow `mass_flow` (kg/s), speed `jet_speed` (m/s) at
/// angle `angle` (rad) to the teeth's pitch-line velocity, to the pitch-line speed `pitch_speed`
/// (m/s, magnitude used). Never negative.
pub fn impulse_power(mass_flow: f64, pitch_speed: f64, jet_speed: f64, angle: f64) -> f64 {
    let v = pitch_speed.abs();
    (mass_flow * v * (v - jet_speed * angle.cos())).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn radial_jet_costs_the_kinetic_energy_flux_twice() {
        // Radial: the oil gains ½ṁv² of kinetic energy and as much is dissipated in the
        // inelastic pick-up: ṁ v².
        let p = impulse_power(0.02, 30.0, 10.0, 0.5 * PI);
        assert!((p - 0.02 * 900.0).abs() < 1e-9);
    }

    #[test]
    fn against_the_teeth_is_the_ariura_form() {
        // ρ Q v_t (v_t + v): ρ 820 kg/m³, Q 2.5 L/min, v_t 20 m/s, v 0.4 m/s.
        let (rho, q, vt, v) = (820.0, 2.5e-3 / 60.0, 20.0, 0.4);
        let p = impulse_power(rho * q, vt, v, PI);
        assert!((p - rho * q * vt * (vt + v)).abs() < 1e-9 * p);
    }

    #[test]
    fn a_jet_faster_than_the_teeth_costs_nothing() {
        assert_eq!(impulse_power(0.01, 5.0, 20.0, 0.0), 0.0);
        // ... and one as fast as the teeth neither
        assert_eq!(impulse_power(0.01, 5.0, 5.0, 0.0), 0.0);
    }

    #[test]
    fn jet_speed_from_pressure_is_bernoulli() {
        assert!((jet_speed(2e5, 800.0) - (2.0 * 2e5 / 800.0f64).sqrt()).abs() < 1e-12);
        assert_eq!(jet_speed(-1.0, 800.0), 0.0);
    }
}
