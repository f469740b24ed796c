//! Constants of the bearing friction models that the catalogue does not carry: SKF's μ values,
//! the drag-term V_M and the seal constants (sources at each).

use crate::model::bearing_catalogue::BearingType;

/// μ_bl of the SKF sliding term (both peers of docs/physics.md §Bearings).
pub(crate) const MU_BL: f64 = 0.12;

/// μ_EHL for mineral oils (the SKF online calculator's value, as the MATLAB peer notes; the SKF
/// catalogue text gives 0.05 for mineral oils, "other bearings").
pub(crate) const MU_EHL: f64 = 0.05;

/// μ_EHL of cylindrical roller bearings (SKF catalogue friction chapter, as shown at
/// yumpu.com/en/document/view/55668573/skf-rolling-bearings/105; the same in peer [P5]).
pub(crate) const MU_EHL_CYLINDRICAL: f64 = 0.02;

/// μ_EHL of tapered roller bearings (same source).
pub(crate) const MU_EHL_TAPERED: f64 = 0.002;

/// V_M of the roller drag term against H/d_m: SKF's diagram as digitised by peer [P5]
/// (`drag.py`, "graph digitization" — numbers read from a figure), linear in between, constant
/// beyond 1.2.
pub(crate) const DRAG_VM_ROLLER: [(f64, f64); 14] = [
    (0.0, 0.0),
    (0.025, 5e-6),
    (0.05, 3.0e-5),
    (0.075, 6.0e-5),
    (0.10, 1.0e-4),
    (0.125, 1.5e-4),
    (0.15, 2.1e-4),
    (0.175, 2.6e-4),
    (0.20, 3.0e-4),
    (0.30, 4.8e-4),
    (0.50, 6.8e-4),
    (0.80, 1.0e-3),
    (1.00, 1.25e-3),
    (1.20, 1.5e-3),
];

/// V_M of a roller bearing at oil height `h_over_dm` (H/d_m).
pub(crate) fn drag_vm_roller(h_over_dm: f64) -> f64 {
    let x = h_over_dm.clamp(0.0, 1.2);
    DRAG_VM_ROLLER
        .windows(2)
        .find(|w| x <= w[1].0)
        .map_or(DRAG_VM_ROLLER[13].1, |w| {
            w[0].1 + (w[1].1 - w[0].1) * (x - w[0].0) / (w[1].0 - w[0].0)
        })
}

/// V_M of the SKF drag term, read from the SKF diagram at full immersion by the Python
/// deep-groove peer (a number read from a figure), used for any immersion depth.
pub(crate) const DRAG_VM: f64 = 0.0012;

/// SKF seal constants (K_S1, K_S2, β) by type and outside diameter D (mm): SKF, as listed by
/// thermca `bearing.seal_heat_loss` [SKF06] (the 62 < D ≤ 80 mm row agrees with the
/// eMotres catalogue).
pub(crate) fn seal_constants(kind: BearingType, outside_mm: f64) -> Option<(f64, f64, f64)> {
    match kind {
        BearingType::DeepGrooveBall => Some(if outside_mm <= 62.0 {
            (0.023, 2.0, 2.25)
        } else if outside_mm <= 80.0 {
            (0.018, 20.0, 2.25)
        } else if outside_mm <= 100.0 {
            (0.018, 15.0, 2.25)
        } else {
            (0.018, 0.0, 2.25)
        }),
        BearingType::AngularContactBall => Some((0.014, 10.0, 2.0)),
        BearingType::CylindricalRoller => Some((0.032, 50.0, 2.0)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::drag_vm_roller;

    /// The roller V_M curve as the peer P5 interpolates it (its printed values,
    /// docs/validation.md §Bearings).
    #[test]
    fn roller_vm_interpolates_like_the_p5_peer() {
        for (x, want) in [(0.75, 9.466667e-4), (1.2, 1.5e-3), (10.0 / 46.0, 3.313043e-4)] {
            assert!((drag_vm_roller(x) / want - 1.0).abs() < 1e-6, "{x}");
        }
        assert_eq!(drag_vm_roller(-1.0), 0.0);
        assert_eq!(drag_vm_roller(5.0), 1.5e-3);
    }
}
