//! Efficiency of power transmission, one definition for every output.
//!
//! η = P_out / (P_out + P_loss) (physics spec §9: the input supplies the transmitted power and
//! the losses, P_in = P_out + P_loss). Defined only while power flows to the output
//! (P_out > 0); the losses are ≥ 0, so η lies in (0, 1]. Over a cycle the energy-weighted
//! figure is ∫P_out dt / ∫P_in dt over the driving time, the same formula on energies
//! ([`efficiency`] of the two integrals).

/// η = P_out / (P_out + P_loss) in [0, 1]; `None` when no power is transmitted (P_out ≤ 0) or an
/// input is not finite. Negative losses (which no loss model produces) are taken as zero so the
/// result can never exceed 1.
pub fn efficiency(p_out: f64, p_loss: f64) -> Option<f64> {
    if !(p_out.is_finite() && p_loss.is_finite()) || p_out <= 0.0 {
        return None;
    }
    let eta = p_out / (p_out + p_loss.max(0.0));
    eta.is_finite().then_some(eta.clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn losses_larger_than_the_power_give_a_small_positive_efficiency() {
        // FZG C at 1450 rpm, 0.1 N·m: 15.2 W transmitted, 41.9 W lost. (P_in − P_loss)/P_in
        // gave −1.76; the definition gives 15.2 / 57.1.
        let eta = efficiency(15.2, 41.9).unwrap();
        assert!((eta - 15.2 / 57.1).abs() < 1e-12);
        assert!((0.0..=1.0).contains(&eta));
    }

    #[test]
    fn undefined_without_output_power_or_with_non_finite_inputs() {
        assert_eq!(efficiency(0.0, 3.0), None);
        assert_eq!(efficiency(-5.0, 3.0), None);
        assert_eq!(efficiency(f64::NAN, 3.0), None);
        assert_eq!(efficiency(1.0, f64::INFINITY), None);
        assert_eq!(efficiency(1.0, 0.0), Some(1.0));
        assert_eq!(efficiency(1e-300, 1e300), Some(0.0));
    }
}
