//! Oil flung out through a rotating planet carrier \[std: Euler's turbomachine equation\].
//!
//! Oil fed through a shaft enters the carrier near its axis without swirl and leaves it at the
//! radius `r` with the carrier's tangential speed ω r. The carrier gives it the angular momentum
//! flux `ṁ ω r²`, so its torque is `ṁ ω r²` and its power
//!
//! `P = ṁ ω² r²`.
//!
//! Half of it is the oil's kinetic energy at exit (dissipated when it hits the ring or the drum
//! around the set), half is dissipated inside the carrier; all of it ends as heat in the oil.
//! Entry swirl (oil already turning with the feeding shaft) would lower the loss by `ṁ ω ω_s r_s²`;
//! it is neglected (r_s ≪ r).
//!
//! Units: SI (kg/s, rad/s, m, W).

/// Power (W) to fling `mass_flow` (kg/s) out to radius `radius` (m) at carrier speed `omega`
/// (rad/s, magnitude used).
pub fn fling_power(mass_flow: f64, omega: f64, radius: f64) -> f64 {
    mass_flow * omega * omega * radius * radius
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fling_power_is_the_angular_momentum_flux_times_the_speed() {
        // 1 L/min of ATF (845 kg/m³) flung out to 60 mm at 3000 rpm.
        let m = 845.0 * 1e-3 / 60.0;
        let w = crate::physics::units::rpm_to_rad_s(3000.0);
        let torque = m * w * 0.06 * 0.06;
        assert!((fling_power(m, w, 0.06) - torque * w).abs() < 1e-12);
        assert_eq!(fling_power(m, -w, 0.06), fling_power(m, w, 0.06));
    }
}
