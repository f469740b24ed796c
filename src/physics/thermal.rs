//! Heat-transfer laws of the lumped thermal network: conduction/convection conductances,
//! radiation, rotating-disc convection correlations and an oil cooler opened by a smooth
//! thermostat. Pure functions in SI units (K, W, m, s); the network assembly lives in
//! `scene::thermal`.

/// Stefan–Boltzmann constant σ, W/(m²·K⁴) (CODATA 2018, exact).
pub const STEFAN_BOLTZMANN: f64 = 5.670_374_419e-8;

/// Radiation exchange between two surfaces: `Q = σ·ε·A·(T_a⁴ − T_b⁴)` (W, from a to b).
///
/// [std] Grey-body exchange with an effective emissivity ε (for a small body in a large enclosure,
/// ε is the body's own emissivity; incropera §13.3).
pub fn radiation_power(sigma_eps_area: f64, t_a: f64, t_b: f64) -> f64 {
    sigma_eps_area * (t_a.powi(4) - t_b.powi(4))
}

/// ∂Q/∂T_a of [`radiation_power`] (the derivative to T_b is its negative with T_b): 4σεA·T_a³.
pub fn radiation_derivative(sigma_eps_area: f64, t: f64) -> f64 {
    4.0 * sigma_eps_area * t.powi(3)
}

/// Convection coefficient against vehicle speed, `h = h0 + h1·v^0.8` (W/m²K, v in m/s).
///
/// \[recalled\] The exponent 0.8 is that of turbulent forced convection over a plate
/// (Nu ∝ Re^0.8, Incropera eq. 7.36); h0 covers natural convection and radiation at rest.
pub fn h_power_law(h0: f64, h1: f64, speed: f64) -> f64 {
    h0 + h1 * speed.max(0.0).powf(0.8)
}

/// Piecewise-linear table h(v), clamped to its end values outside the table.
#[derive(Debug, Clone, PartialEq)]
pub struct HTable {
    speed: Vec<f64>,
    h: Vec<f64>,
}

impl HTable {
    /// Build from increasing speeds (m/s) and coefficients (W/m²K). The caller (model
    /// validation) guarantees equal lengths ≥ 1 and strictly increasing speeds.
    pub fn new(speed: Vec<f64>, h: Vec<f64>) -> Self {
        Self { speed, h }
    }

    /// h at vehicle speed `v` (m/s).
    pub fn at(&self, v: f64) -> f64 {
        let (s, h) = (&self.speed, &self.h);
        if s.len() == 1 || v <= s[0] {
            return h[0];
        }
        let last = s.len() - 1;
        if v >= s[last] {
            return h[last];
        }
        let k = s.partition_point(|&x| x <= v).saturating_sub(1).min(last - 1);
        let f = (v - s[k]) / (s[k + 1] - s[k]);
        h[k] + f * (h[k + 1] - h[k])
    }
}

/// Fluid properties for a convection correlation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FluidProperties {
    /// Thermal conductivity, W/(m·K).
    pub conductivity: f64,
    /// Kinematic viscosity, m²/s.
    pub kinematic_viscosity: f64,
    /// Prandtl number.
    pub prandtl: f64,
}

/// Dry air at 50 °C and 1 atm (Incropera table A.4, interpolated): k = 0.0280 W/mK,
/// ν = 1.80e-5 m²/s, Pr = 0.703. Used for rotating parts in air (temperature dependence of
/// air properties neglected: ±15 % over 0–100 °C, within the correlation's own scatter).
pub const AIR_50C: FluidProperties = FluidProperties {
    conductivity: 0.0280,
    kinematic_viscosity: 1.80e-5,
    prandtl: 0.703,
};

/// Thermal conductivity of gear oils and ATFs, W/(m·K) [recalled: 0.12–0.14 for mineral and
/// PAO oils at 40–100 °C, e.g. Changenet et al. 2006]; taken constant.
pub const OIL_CONDUCTIVITY: f64 = 0.13;

/// Specific heat of gear oils, J/(kg·K) [recalled: 1.9–2.1 kJ/kgK at 40–100 °C]; used only for the
/// Prandtl number of the rotating-part correlation in oil (the heat the circuit's oil carries
/// takes the oil node's own `cp_j_per_kgk`).
pub const OIL_SPECIFIC_HEAT: f64 = 2000.0;

/// Mean heat-transfer coefficient of a disc of radius `r` (m) rotating at `omega` (rad/s) in a
/// fluid, W/m²K.
///
/// \[recalled\] Free rotating disc, mean Nusselt number Nu = h·r/k: laminar
/// Nu_l = 0.36·Re^0.5 (Cobb & Saunders 1956, Re < 2.4e5), turbulent Nu_t = 0.015·Re^0.8
/// (same source), Re = ω·r²/ν, with a Prandtl factor Pr^(1/3) (exact for air, an extension for
/// oil). \[derived\] The two branches are blended as Nu = (Nu_l⁴ + Nu_t⁴)^(1/4) so that h is smooth
/// in speed (no step at the transition; a discontinuous h would stall the stiff solver). At rest
/// the correlation gives 0: natural convection is left to a fixed conductance in parallel.
pub fn rotating_disc_h(omega: f64, radius: f64, fluid: &FluidProperties) -> f64 {
    disc_h_and_re_exponent(omega, radius, fluid).0
}

/// [`rotating_disc_h`] and its temperature derivative dh/dT (W/m²K/K), given the fluid's
/// logarithmic slopes d ln ν/dT (`dln_nu`) and d ln Pr/dT (`dln_pr`); h is bitwise that of
/// [`rotating_disc_h`].
///
/// \[derived\] from the correlation above at fixed ω, r and k: Re ∝ 1/ν, so
/// d ln h/dT = −ε·d ln ν/dT + (1/3)·d ln Pr/dT with the local Reynolds exponent of the blend
/// ε = d ln Nu/d ln Re = (0.5·Nu_l⁴ + 0.8·Nu_t⁴)/(Nu_l⁴ + Nu_t⁴).
pub fn rotating_disc_h_slope(
    omega: f64,
    radius: f64,
    fluid: &FluidProperties,
    dln_nu: f64,
    dln_pr: f64,
) -> (f64, f64) {
    rotating_disc_h_slope_with(omega, radius, fluid, fluid.prandtl.cbrt(), dln_nu, dln_pr)
}

/// [`rotating_disc_h_slope`] with the fluid's Pr^(1/3) `pr_cbrt` given (`fluid.prandtl.cbrt()`,
/// shared by every part turning in the same fluid); the same values.
pub fn rotating_disc_h_slope_with(
    omega: f64,
    radius: f64,
    fluid: &FluidProperties,
    pr_cbrt: f64,
    dln_nu: f64,
    dln_pr: f64,
) -> (f64, f64) {
    let (h, eps) = disc_h_and_re_exponent_with(omega, radius, fluid, pr_cbrt);
    (h, h * (-eps * dln_nu + dln_pr / 3.0))
}

/// h of [`rotating_disc_h`] and the blend's Reynolds exponent ε (0 at rest).
fn disc_h_and_re_exponent(omega: f64, radius: f64, fluid: &FluidProperties) -> (f64, f64) {
    disc_h_and_re_exponent_with(omega, radius, fluid, fluid.prandtl.cbrt())
}

/// [`disc_h_and_re_exponent`] with Pr^(1/3) `pr_cbrt` given.
fn disc_h_and_re_exponent_with(omega: f64, radius: f64, fluid: &FluidProperties, pr_cbrt: f64) -> (f64, f64) {
    let re = omega.abs() * radius * radius / fluid.kinematic_viscosity;
    let nu_l = 0.36 * re.sqrt();
    // Re^0.8 as exp(0.8 ln Re) (Re = 0: ln = −∞, the power 0) and x^(1/4) as √√x: the same
    // values to rounding, at a fraction of powf's cost (this runs per link and RHS).
    let nu_t = 0.015 * (0.8 * re.ln()).exp();
    let (l4, t4) = (nu_l.powi(4), nu_t.powi(4));
    let nu = (l4 + t4).sqrt().sqrt() * pr_cbrt;
    let eps = if l4 + t4 > 0.0 {
        (0.5 * l4 + 0.8 * t4) / (l4 + t4)
    } else {
        0.0
    };
    (nu * fluid.conductivity / radius, eps)
}

/// Opening of a thermostat valve at temperature `t` (K): 0 below `t_open`, 1 above `t_full`,
/// and the C¹ smoothstep 3s² − 2s³ in between (s = (t − t_open)/(t_full − t_open)).
///
/// \[derived\] A smooth ramp instead of a switch: the cooler's heat flow and its derivative stay
/// continuous, so the implicit solver's Newton iteration sees no step (physics.md §8).
/// Returns (opening, d opening / dT).
pub fn thermostat_opening(t: f64, t_open: f64, t_full: f64) -> (f64, f64) {
    if t <= t_open {
        (0.0, 0.0)
    } else if t >= t_full {
        (1.0, 0.0)
    } else {
        let w = t_full - t_open;
        let s = (t - t_open) / w;
        (s * s * (3.0 - 2.0 * s), 6.0 * s * (1.0 - s) / w)
    }
}

/// Lowest air temperature (K) at which [`fixed_fan_density_factor`] follows 1/T; below it the
/// factor is held (no air the model meets is that cold; a Newton iterate can pass there).
pub const FAN_AIR_FLOOR_K: f64 = 100.0;

/// Capacity-rate factor of an air stream moved by a fan at fixed speed, at air temperature
/// `t_air` (K) relative to the air temperature `t_ref` (K) at which the capacity rate is
/// stated: `T_ref / T_air`. Returns (factor, d factor / dT_air = −T_ref / T_air²).
///
/// A fan at fixed speed is a constant-volume machine: its volume flow does not change with the
/// air's density (Process Heating, "Fan laws and formulas",
/// <https://www.process-heating.com/articles/87634-fan-laws-and-formulas>: "the fan is
/// essentially a constant volume machine when run at a constant speed, the volume will not
/// vary with a change in density"; the fan affinity laws' density change, Q₂ = Q₁). Its mass
/// flow ṁ = ρ·V̇ is then proportional to the density, and at constant pressure the ideal gas
/// law gives ρ = p/(R·T) ∝ 1/T; with c_p of air taken constant, the air's capacity rate ṁ·c_p
/// scales as T_ref/T_air. \[derived\] The effectiveness ε is held: the change of the air-side
/// heat-transfer coefficient and of NTU with the mass flow is not modelled. Below
/// [`FAN_AIR_FLOOR_K`] the factor is held at its value there (slope 0), so it stays finite.
pub fn fixed_fan_density_factor(t_air: f64, t_ref: f64) -> (f64, f64) {
    if t_air < FAN_AIR_FLOOR_K {
        return (t_ref / FAN_AIR_FLOOR_K, 0.0);
    }
    let f = t_ref / t_air;
    (f, -f / t_air)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fan's density factor: 1 at the reference, −5 % from 10 to 25 °C (283.15/298.15),
    /// its slope against a central difference, held below the floor.
    #[test]
    fn fixed_fan_density_factor_is_t_ref_over_t() {
        let (f, _) = fixed_fan_density_factor(288.15, 288.15);
        assert_eq!(f, 1.0);
        let (a, _) = fixed_fan_density_factor(283.15, 288.15);
        let (b, _) = fixed_fan_density_factor(298.15, 288.15);
        assert!((b / a - 283.15 / 298.15).abs() < 1e-15);
        assert!((b / a - 0.9497).abs() < 1e-4, "{}", b / a);
        for t in [250.0, 290.0, 330.0] {
            let (_, d) = fixed_fan_density_factor(t, 288.15);
            let h = 1e-4;
            let fd = (fixed_fan_density_factor(t + h, 288.15).0 - fixed_fan_density_factor(t - h, 288.15).0)
                / (2.0 * h);
            assert!((d - fd).abs() < 1e-9 * d.abs(), "{t}: {d} vs {fd}");
        }
        assert_eq!(
            fixed_fan_density_factor(-5.0, 288.15),
            (288.15 / FAN_AIR_FLOOR_K, 0.0)
        );
    }

    #[test]
    fn table_interpolates_and_clamps() {
        let t = HTable::new(vec![0.0, 10.0, 30.0], vec![10.0, 30.0, 50.0]);
        assert_eq!(t.at(-1.0), 10.0);
        assert!((t.at(5.0) - 20.0).abs() < 1e-12);
        assert!((t.at(20.0) - 40.0).abs() < 1e-12);
        assert_eq!(t.at(10.0), 30.0);
        assert_eq!(t.at(100.0), 50.0);
        let one = HTable::new(vec![3.0], vec![7.0]);
        assert_eq!(one.at(0.0), 7.0);
        assert_eq!(one.at(9.0), 7.0);
    }

    /// The analytic dh/dT of the rotating disc in oil against a central difference of h through
    /// the oil's properties, across the laminar–turbulent blend (1 to 1e4 rad/s), and h bitwise
    /// that of `rotating_disc_h`.
    #[test]
    fn rotating_disc_slope_matches_a_central_difference() {
        use crate::physics::oil::{Oil, WaltherVariant, CST};
        let oil = Oil::new(
            "FVA 3A",
            WaltherVariant::C06,
            90.02 * CST,
            10.41 * CST,
            884.1,
            crate::physics::oil::ALPHA_T_MINERAL,
        )
        .unwrap();
        let fluid = |t: f64| {
            let p = oil.properties(t);
            FluidProperties {
                conductivity: OIL_CONDUCTIVITY,
                kinematic_viscosity: p.nu,
                prandtl: p.mu * OIL_SPECIFIC_HEAT / OIL_CONDUCTIVITY,
            }
        };
        for t in [300.0, 340.0, 390.0] {
            let (_, s) = oil.properties_and_slopes(t);
            for w in [0.0, 1.0, 30.0, 300.0, 3000.0, 1e4] {
                let (h, dh) = rotating_disc_h_slope(w, 0.08, &fluid(t), s.nu, s.nu + s.rho);
                assert_eq!(h.to_bits(), rotating_disc_h(w, 0.08, &fluid(t)).to_bits());
                let d = 1e-3;
                let fd = (rotating_disc_h(w, 0.08, &fluid(t + d)) - rotating_disc_h(w, 0.08, &fluid(t - d)))
                    / (2.0 * d);
                assert!(
                    (dh - fd).abs() <= 1e-6 * fd.abs().max(1e-12),
                    "T {t} ω {w}: {dh} vs {fd}"
                );
            }
        }
    }

    #[test]
    fn thermostat_is_c1_and_monotone() {
        let (a, b) = (348.15, 358.15);
        let mut last = -1.0;
        for k in 0..=200 {
            let t = a - 5.0 + 0.1 * f64::from(k);
            let (x, dx) = thermostat_opening(t, a, b);
            assert!((0.0..=1.0).contains(&x) && x >= last);
            last = x;
            let h = 1e-6;
            let fd = (thermostat_opening(t + h, a, b).0 - thermostat_opening(t - h, a, b).0) / (2.0 * h);
            assert!((fd - dx).abs() < 1e-6, "t={t} fd={fd} dx={dx}");
        }
        assert_eq!(thermostat_opening(0.5 * (a + b), a, b).0, 0.5);
    }

    #[test]
    fn rotating_disc_limits_and_smoothness() {
        // Far below the transition the blend equals the laminar law, far above the turbulent one.
        let r = 0.1;
        let nu = AIR_50C.kinematic_viscosity;
        let pr = AIR_50C.prandtl.cbrt();
        let omega_lo = 1e2 * nu / (r * r);
        let h_lo = rotating_disc_h(omega_lo, r, &AIR_50C);
        let lam = 0.36 * 1e2f64.sqrt() * pr * AIR_50C.conductivity / r;
        assert!((h_lo / lam - 1.0).abs() < 1e-3);
        let omega_hi = 1e8 * nu / (r * r);
        let turb = 0.015 * 1e8f64.powf(0.8) * pr * AIR_50C.conductivity / r;
        assert!((rotating_disc_h(omega_hi, r, &AIR_50C) / turb - 1.0).abs() < 1e-3);
        // Monotone in speed, symmetric in direction.
        let mut last = 0.0;
        for k in 1..400 {
            let w = f64::from(k) * 5.0;
            let h = rotating_disc_h(w, r, &AIR_50C);
            assert!(h > last);
            last = h;
            assert_eq!(h, rotating_disc_h(-w, r, &AIR_50C));
        }
    }

    #[test]
    fn radiation_derivative_matches_difference() {
        let k = STEFAN_BOLTZMANN * 0.9 * 0.5;
        let (ta, tb) = (360.0, 295.0);
        let h = 1e-4;
        let fd = (radiation_power(k, ta + h, tb) - radiation_power(k, ta - h, tb)) / (2.0 * h);
        assert!((fd / radiation_derivative(k, ta) - 1.0).abs() < 1e-9);
        // 0.5 m² at ε 0.9, 360 K to 295 K: σ·0.45·(360⁴ − 295⁴) = 235.3 W.
        let q = radiation_power(k, ta, tb);
        assert!((q - 235.34).abs() < 0.01, "{q}");
    }

    #[test]
    fn power_law_grows_with_speed() {
        assert_eq!(h_power_law(12.0, 4.0, 0.0), 12.0);
        assert!((h_power_law(12.0, 4.0, 10.0) - (12.0 + 4.0 * 10f64.powf(0.8))).abs() < 1e-12);
        assert_eq!(h_power_law(12.0, 4.0, -3.0), 12.0);
    }
}
