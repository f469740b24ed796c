//! Unit conversions, named once. Each function keeps the operation order of the expression it
//! names (`rpm * π / 30`, not `rpm * (π / 30)`), so that a conversion gives the same bits
//! wherever it is written.

use std::f64::consts::PI;

/// Offset between the Celsius and the Kelvin scales, K.
pub const KELVIN_OFFSET: f64 = 273.15;

/// Metres per millimetre.
pub const M_PER_MM: f64 = 1e-3;

/// Millimetres per metre.
pub const MM_PER_M: f64 = 1e3;

/// Micrometres per metre.
pub const UM_PER_M: f64 = 1e6;

/// N·m per N·mm (a moment in N·mm times this is in N·m).
pub const N_M_PER_N_MM: f64 = 1e-3;

/// mm²/s (cSt) per m²/s.
pub const MM2_S_PER_M2_S: f64 = 1e6;

/// mPa·s (cP) per Pa·s.
pub const MPA_S_PER_PA_S: f64 = 1e3;

/// Kilometres per hour per metre per second; [`m_s_to_kmh`] multiplies by 3.6.
pub const KMH_PER_M_S: f64 = 3.6;

/// Radians per second per revolution per minute (π/30); [`rpm_to_rad_s`] multiplies by π and
/// divides by 30 in that order.
pub const RAD_S_PER_RPM: f64 = PI / 30.0;

/// Metres per second per kilometre per hour (1/3.6); [`kmh_to_m_s`] divides by 3.6.
pub const M_S_PER_KMH: f64 = 1.0 / 3.6;

/// °C → K.
pub fn c_to_k(c: f64) -> f64 {
    c + KELVIN_OFFSET
}

/// K → °C.
pub fn k_to_c(k: f64) -> f64 {
    k - KELVIN_OFFSET
}

/// rpm → rad/s (`rpm * π / 30`).
pub fn rpm_to_rad_s(rpm: f64) -> f64 {
    rpm * PI / 30.0
}

/// rad/s → rpm (`w * 30 / π`).
pub fn rad_s_to_rpm(w: f64) -> f64 {
    w * 30.0 / PI
}

/// m/s → km/h (`v * 3.6`).
pub fn m_s_to_kmh(v: f64) -> f64 {
    v * KMH_PER_M_S
}

/// km/h → m/s (`kmh / 3.6`).
pub fn kmh_to_m_s(kmh: f64) -> f64 {
    kmh / 3.6
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_conversions_are_the_written_expressions_bit_for_bit() {
        for x in [0.0, 1.0, 1450.0, 2999.9, -17.3, 16000.0] {
            assert_eq!(c_to_k(x).to_bits(), (x + 273.15).to_bits());
            assert_eq!(k_to_c(c_to_k(x)), c_to_k(x) - 273.15);
            assert_eq!(
                rpm_to_rad_s(x).to_bits(),
                (x * std::f64::consts::PI / 30.0).to_bits()
            );
            assert_eq!(kmh_to_m_s(x).to_bits(), (x / 3.6).to_bits());
            assert_eq!(m_s_to_kmh(x).to_bits(), (x * 3.6).to_bits());
            assert_eq!(
                rad_s_to_rpm(x).to_bits(),
                (x * 30.0 / std::f64::consts::PI).to_bits()
            );
        }
        assert_eq!(crate::physics::oil::KELVIN_OFFSET, KELVIN_OFFSET);
    }
}
