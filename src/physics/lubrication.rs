//! The lubrication circuit's flows and what they do to a mesh's pocketing.
//!
//! **Orifices on a common line** \[std: sharp-edged orifice\]: consumer i passes
//! `Q_i = C_d,i A_i √(2p/ρ)` at the line pressure p. When the orifices together ask for more than
//! the source delivers (Q_s), the line pressure falls until they pass what it delivers: every
//! orifice law has the same √p, so the flows keep their ratios and
//! `Q_i = Q_s · C_d,i A_i / Σ C_d,j A_j` \[derived\]. In mass flow: `ṁ_i = k_i √ρ · min(1, Q_s √ρ / K)`
//! with `k_i = C_d,i A_i √(2p)` and `K = Σ k_j`.
//!
//! **Oil fraction of a mesh's pockets** \[derived; the pocketing of "air, oil or an air–oil
//! mixture … as a function of the oil-to-air ratio" is Talbot, Kahraman & Seetharaman 2014's
//! setting (J. Tribol. 136, 021105, abstract)\]: the closing tooth spaces of a mesh expel
//! `Q_swept = z1 ω1/(2π) · (ΔV_1 + ΔV_2)` per second (ΔV the volume one pocket of each family
//! loses while closing). If all the oil delivered to the mesh (Q) passes through the pockets and
//! mixes with the air they hold, its volume fraction there is `φ = min(1, Q/Q_swept)`, and the
//! pumped mixture has the density `ρ_mix = φ ρ_oil + (1 − φ) ρ_air`. The mixture is taken as
//! homogeneous and incompressible (the Bernoulli law of §6 with ρ_mix): with air in the pockets
//! it compresses, so this is an upper bound.
//!
//! Units: SI (m³/s, kg/s, Pa, kg/m³, m³).

/// `√(2p)·C_d A` of an orifice of `cd_area` (m²) at line pressure `pressure` (Pa): its mass flow
/// is this times √ρ, its volume flow this over √ρ.
pub fn orifice_coefficient(cd_area: f64, pressure: f64) -> f64 {
    cd_area * (2.0 * pressure.max(0.0)).sqrt()
}

/// Volume flow (m³/s) of an orifice with coefficient `k` ([`orifice_coefficient`]) on a line whose
/// orifices sum to `k_sum`, fed by a source delivering `supply` (m³/s), in oil of density `rho`:
/// `k/√ρ · min(1, supply √ρ / k_sum)`. And d ln Q/d ln ρ (−½ uncapped, 0 capped).
pub fn orifice_flow(k: f64, k_sum: f64, supply: f64, rho: f64) -> (f64, f64) {
    if k_sum <= 0.0 {
        return (0.0, 0.0);
    }
    let free = k / rho.sqrt();
    let cap = supply * rho.sqrt() / k_sum;
    if cap < 1.0 {
        (free * cap, 0.0)
    } else {
        (free, -0.5)
    }
}

/// Pressure (Pa) ahead of the orifices of a line at nominal `pressure` whose orifices sum to
/// `k_sum` ([`orifice_coefficient`] at that pressure), fed `supply` (m³/s) of oil of density
/// `rho` \[derived from the orifice law above\]: when the orifices would pass more than the source
/// delivers, the line pressure falls until they pass what it delivers; every orifice passes
/// ∝ √p, so `p_delivered = p · min(1, supply √ρ / k_sum)²`. The nominal pressure with no
/// orifice (`k_sum` ≤ 0).
pub fn delivered_pressure(pressure: f64, k_sum: f64, supply: f64, rho: f64) -> f64 {
    if k_sum <= 0.0 {
        return pressure;
    }
    let cap = (supply.max(0.0) * rho.sqrt() / k_sum).min(1.0);
    pressure * cap * cap
}

/// Oil volume fraction of the pockets of a mesh fed `delivered` (m³/s) whose closing pockets expel
/// `swept` (m³/s): `min(1, delivered/swept)` (1 when nothing is swept).
pub fn oil_fraction(delivered: f64, swept: f64) -> f64 {
    if swept <= 0.0 {
        return 1.0;
    }
    (delivered / swept).clamp(0.0, 1.0)
}

/// Density of an oil–air mixture with oil volume fraction `phi`.
pub fn mixture_density(phi: f64, rho_oil: f64, rho_air: f64) -> f64 {
    phi * rho_oil + (1.0 - phi) * rho_air
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orifices_keep_their_ratio_when_the_source_limits_them() {
        let (rho, p) = (850.0, 2e5);
        let k1 = orifice_coefficient(0.6 * 1e-6, p);
        let k2 = orifice_coefficient(0.6 * 3e-6, p);
        // a generous source: each passes C_d A √(2p/ρ)
        let (q1, s1) = orifice_flow(k1, k1 + k2, 1.0, rho);
        assert!((q1 - 0.6e-6 * (2.0 * p / rho).sqrt()).abs() < 1e-15);
        assert_eq!(s1, -0.5);
        // a source of 1 L/min: they split it 1:3 and pass all of it
        let supply = 1e-3 / 60.0;
        let (a, sa) = orifice_flow(k1, k1 + k2, supply, rho);
        let (b, _) = orifice_flow(k2, k1 + k2, supply, rho);
        assert!((a + b - supply).abs() < 1e-15 && (b / a - 3.0).abs() < 1e-12);
        assert_eq!(sa, 0.0);
    }

    #[test]
    fn a_short_source_lowers_the_line_pressure_to_what_its_flow_implies() {
        let (rho, p): (f64, f64) = (850.0, 2e5);
        let k = orifice_coefficient(0.6 * 4e-6, p);
        let free = k / rho.sqrt();
        // a generous source: the nominal pressure
        assert_eq!(delivered_pressure(p, k, 2.0 * free, rho), p);
        // half the flow the orifice asks for: a quarter of the pressure, and the orifice law at
        // that pressure passes exactly the delivered flow
        let pd = delivered_pressure(p, k, 0.5 * free, rho);
        assert!((pd / p - 0.25).abs() < 1e-12);
        let q = orifice_coefficient(0.6 * 4e-6, pd) / rho.sqrt();
        assert!((q / (0.5 * free) - 1.0).abs() < 1e-12);
        assert_eq!(delivered_pressure(p, 0.0, 1.0, rho), p);
    }

    #[test]
    fn mixture_follows_the_delivered_oil() {
        assert_eq!(oil_fraction(1.0, 4.0), 0.25);
        assert_eq!(oil_fraction(5.0, 4.0), 1.0);
        assert_eq!(oil_fraction(1.0, 0.0), 1.0);
        assert!((mixture_density(0.25, 850.0, 1.1) - (0.25 * 850.0 + 0.75 * 1.1)).abs() < 1e-12);
    }
}
