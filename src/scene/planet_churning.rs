//! Churning of planets averaged over the carrier revolution.
//!
//! A planet's axis orbits the set axis at radius R. With the carrier angle φ measured from the
//! lowest orbit position, the planet's immersion is `h(φ) = h_max − R(1 − cos φ)` (h_max: the
//! immersion at the lowest position, as the model file's lubrication section gives it), so it
//! dips only while `cos φ > 1 − h_max/R`, over the wet arc |φ| < φ_w. The churning of the set's
//! N planets, averaged over a carrier turn, is
//!
//! `P̄ = N · (1/2π) ∮ P(h(φ)) dφ = N · (1/π) ∫₀^φ_w P(h(φ)) dφ` \[derived\],
//!
//! integrated here by Gauss–Legendre quadrature on [0, φ_w] with [`ORBIT_NODES`] nodes, one
//! precomputed churning model per node. The orbital motion of the planet through the oil is not
//! modelled (the planet churns at its absolute speed, docs/physics.md §8).
//!
//! **Carrier at rest** (e.g. the Ravigneaux carrier held in 1st and R): the planets stand at
//! angles φ₀ + 2πk/N with φ₀ unknown (the model file does not give it, and it is wherever the
//! carrier stopped). The same orbit average is used: it is the expected value of the set's
//! churning over φ₀ uniformly distributed, so a held carrier and a turning one are charged alike.

use crate::model::gearbox::{Gear, GearMount, Gearbox};
use crate::physics::losses::churning::{ChurningConfig, ChurningError, ChurningGear, GearChurning};

/// Gauss–Legendre nodes on the wet arc.
pub const ORBIT_NODES: usize = 8;

/// Orbit radius (m) of gear `gi` and the number of planets of its set; `None` for a gear that
/// does not orbit.
pub fn planet_orbit(gb: &Gearbox, gi: usize) -> Option<(f64, u32)> {
    let g = &gb.gears[gi];
    let GearMount::Planet { set, .. } = g.mount else {
        return None;
    };
    let s = &gb.planetary_sets[set];
    let axis = s
        .gears
        .iter()
        .find(|&&k| gb.gears[k].mount == GearMount::OnMember)
        .map(|&k| gb.gears[k].centre_height)?;
    let r = axis - g.centre_height;
    (r > 0.0).then_some((r, s.planets))
}

/// Immersion depths and weights of the quadrature of the orbit average, planets included:
/// `P̄ = Σ wᵢ P(hᵢ)`. Empty when the planet never reaches the oil. `h_max` is the immersion at
/// the lowest orbit position, `r` the orbit radius, `ra` the planet's tip radius.
pub fn orbit_samples(h_max: f64, r: f64, ra: f64, planets: u32) -> Vec<(f64, f64)> {
    if h_max <= 0.0 || r <= 0.0 {
        return Vec::new();
    }
    let c = 1.0 - h_max / r;
    let phi_w = if c <= -1.0 { std::f64::consts::PI } else { c.acos() };
    let (x, w) = crate::physics::losses::pocketing::integral::gauss_legendre(ORBIT_NODES);
    x.iter()
        .zip(&w)
        .map(|(&xi, &wi)| {
            let phi = 0.5 * phi_w * (xi + 1.0);
            let h = (h_max - r * (1.0 - phi.cos())).min(2.0 * ra);
            let weight = f64::from(planets) * wi * 0.5 * phi_w / std::f64::consts::PI;
            (h, weight)
        })
        .filter(|&(h, _)| h > 0.0)
        .collect()
}

/// The churning models of gear `gi` with their weights: one model (weight 1) for a gear whose
/// immersion does not change, the orbit quadrature (planets counted) for a planet.
pub fn models(
    cfg: &ChurningConfig,
    gb: &Gearbox,
    gi: usize,
    gear: &ChurningGear,
) -> Result<Vec<(GearChurning, f64)>, ChurningError> {
    match planet_orbit(gb, gi) {
        None => Ok(vec![(GearChurning::new(cfg, gear)?, 1.0)]),
        Some((r, n)) => orbit_samples(gear.immersion_depth, r, gear.tip_radius, n)
            .into_iter()
            .map(|(h, w)| Ok((GearChurning::new(cfg, &at_depth(gear, h))?, w)))
            .collect(),
    }
}

/// The share of a carrier turn during which one planet dips (0..1).
pub fn wet_share(h_max: f64, r: f64) -> f64 {
    if h_max <= 0.0 || r <= 0.0 {
        return 0.0;
    }
    let c = (1.0 - h_max / r).max(-1.0);
    c.acos() / std::f64::consts::PI
}

/// Planet `g` with its immersion replaced by `h` (for building one model per quadrature node).
pub fn at_depth(g: &ChurningGear, h: f64) -> ChurningGear {
    ChurningGear {
        immersion_depth: h,
        ..*g
    }
}

/// True when `g` is a planet (its immersion varies over the carrier turn).
pub fn is_planet(g: &Gear) -> bool {
    matches!(g.mount, GearMount::Planet { .. })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::losses::churning::OilState;

    fn planet(h: f64) -> ChurningGear {
        ChurningGear::from_basic_rack(
            17,
            1.75e-3,
            20f64.to_radians(),
            20f64.to_radians(),
            0.0,
            20e-3,
            h,
            None,
            None,
        )
        .unwrap()
    }

    /// Brute-force orbit average: midpoint rule over 20 000 carrier angles.
    fn brute(cfg: &ChurningConfig, h_max: f64, r: f64, n: u32, w: f64, oil: &OilState) -> f64 {
        let k = 20_000;
        let mut s = 0.0;
        for i in 0..k {
            let phi = (i as f64 + 0.5) / k as f64 * 2.0 * std::f64::consts::PI;
            let h = h_max - r * (1.0 - phi.cos());
            if h > 0.0 {
                s += GearChurning::new(cfg, &planet(h)).unwrap().power(w, oil).total;
            }
        }
        f64::from(n) * s / k as f64
    }

    #[test]
    fn orbit_average_matches_brute_force_for_every_model() {
        let oil = OilState {
            density: 850.0,
            kinematic_viscosity: 20e-6,
        };
        for model in [
            crate::physics::losses::churning::ChurningModel::Changenet,
            crate::physics::losses::churning::ChurningModel::Seetharaman,
            crate::physics::losses::churning::ChurningModel::Stavytskyi,
        ] {
            let cfg = ChurningConfig {
                model,
                ..Default::default()
            };
            for (h_max, r) in [(0.008, 0.0475), (0.02, 0.05)] {
                let q: f64 = orbit_samples(h_max, r, planet(0.0).tip_radius, 4)
                    .iter()
                    .map(|&(h, wt)| {
                        wt * GearChurning::new(&cfg, &planet(h))
                            .unwrap()
                            .power(300.0, &oil)
                            .total
                    })
                    .sum();
                let b = brute(&cfg, h_max, r, 4, 300.0, &oil);
                assert!((q / b - 1.0).abs() < 0.01, "{model:?} h {h_max}: {q} vs {b}");
                // far below N × the churning at the deepest position
                let deepest = 4.0
                    * GearChurning::new(&cfg, &planet(h_max))
                        .unwrap()
                        .power(300.0, &oil)
                        .total;
                assert!(q < 0.5 * deepest, "{q} {deepest}");
            }
        }
    }

    #[test]
    fn wet_share_of_the_turn() {
        assert_eq!(wet_share(0.0, 0.05), 0.0);
        assert!((wet_share(0.05, 0.05) - 0.5).abs() < 1e-12);
        assert_eq!(wet_share(0.2, 0.05), 1.0);
        // always wet: every node counts, weights sum to N
        let s: f64 = orbit_samples(0.2, 0.05, 0.02, 3).iter().map(|x| x.1).sum();
        assert!((s - 3.0).abs() < 1e-12);
    }
}
