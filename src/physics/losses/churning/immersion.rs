//! Immersion geometry of a gear (disc of radius r_a) dipping to depth h (physics.md §5).
//!
//! - immersion half-angle [std]: `θ = acos(1 − h/r_a)`, h clamped to [0, 2 r_a] (θ = π fully
//!   immersed, 0 dry);
//! - wetted area of one face (circular segment) [std]: `A_f = r_a²·(θ − sin θ cos θ)`; it equals
//!   seed 000's `r_a²·(π/2 − asin(1 − h̄) − (1 − h̄)·√(h̄(2 − h̄)))` (test below);
//! - wetted periphery arc `2 θ r_a`;
//! - wetted chord: the largest horizontal extent of the wetted segment, `L = 2 r_a sin θ` for
//!   θ ≤ π/2 and `L = 2 r_a` (the diameter) for θ > π/2 \[derived\]. Seed 000 uses `2 r_a sin θ`
//!   throughout, which goes to 0 at full immersion and makes the face Reynolds number vanish and the
//!   face drag (∝ (sin θ)^(−1/2) or ^(−1/7)) diverge at θ = π. The bound is continuous in h (with a
//!   kink at h = r_a) and finite at full immersion.

use std::f64::consts::PI;

/// Immersion of one gear, precomputed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Immersion {
    /// Depth h of the lowest point below the oil level as given, m (may be ≤ 0 or > 2 r_a).
    pub depth: f64,
    /// Relative depth h̄ = h/r_a clamped to [0, 2].
    pub h_bar: f64,
    /// Immersion half-angle θ, rad, in [0, π].
    pub theta: f64,
    /// Wetted area of one face, m².
    pub face_area: f64,
    /// Wetted chord L (bounded at the diameter), m.
    pub chord: f64,
}

impl Immersion {
    /// Immersion of a disc of radius `tip_radius` (> 0) whose lowest point is `depth` below the level.
    pub fn new(depth: f64, tip_radius: f64) -> Self {
        let h_bar = (depth / tip_radius).clamp(0.0, 2.0);
        let theta = immersion_angle(h_bar);
        Immersion {
            depth,
            h_bar,
            theta,
            face_area: segment_area(tip_radius, theta),
            chord: wetted_chord(tip_radius, theta),
        }
    }

    /// True when h > 0.
    pub fn is_immersed(&self) -> bool {
        self.depth > 0.0
    }
}

/// `θ = acos(1 − h̄)`, h̄ clamped to [0, 2].
pub fn immersion_angle(h_bar: f64) -> f64 {
    (1.0 - h_bar.clamp(0.0, 2.0)).acos()
}

/// Circular segment of half-angle θ: `r²·(θ − sin θ cos θ)`.
pub fn segment_area(r: f64, theta: f64) -> f64 {
    r * r * (theta - theta.sin() * theta.cos())
}

/// Largest horizontal chord of the wetted segment: `2 r sin θ` (θ ≤ π/2), `2 r` beyond.
pub fn wetted_chord(r: f64, theta: f64) -> f64 {
    2.0 * r * if theta <= 0.5 * PI { theta.sin() } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_and_limits() {
        let r = 0.06;
        assert_eq!(Immersion::new(0.0, r).theta, 0.0);
        assert!(!Immersion::new(0.0, r).is_immersed());
        assert!((Immersion::new(r, r).theta - 0.5 * PI).abs() < 1e-15);
        assert!((Immersion::new(2.0 * r, r).theta - PI).abs() < 1e-15);
        assert!((Immersion::new(5.0 * r, r).theta - PI).abs() < 1e-15);
        assert!((Immersion::new(r, r).face_area - 0.5 * PI * r * r).abs() < 1e-15);
        assert!((Immersion::new(3.0 * r, r).face_area - PI * r * r).abs() < 1e-15);
        assert!((Immersion::new(3.0 * r, r).chord - 2.0 * r).abs() < 1e-15);
        assert_eq!(Immersion::new(-1.0, r).face_area, 0.0);
    }

    #[test]
    fn segment_area_matches_seed_form_and_quadrature() {
        let r = 0.05;
        for i in 1..40 {
            let h = 2.0 * r * f64::from(i) / 40.0;
            let hb: f64 = h / r;
            let im = Immersion::new(h, r);
            let seed = r * r * (0.5 * PI - (1.0 - hb).asin() - (1.0 - hb) * (hb * (2.0 - hb)).sqrt());
            assert!((im.face_area - seed).abs() < 1e-14, "seed form at h̄ {hb}");
            // midpoint quadrature of the chord width 2√(r² − y²) over y ∈ [−r, −r + h]
            let n = 20000;
            let dy = h / f64::from(n);
            let q: f64 = (0..n)
                .map(|j| {
                    let y = -r + (f64::from(j) + 0.5) * dy;
                    2.0 * (r * r - y * y).max(0.0).sqrt() * dy
                })
                .sum();
            assert!((im.face_area - q).abs() < 1e-6 * r * r, "quadrature at h̄ {hb}");
            // chord: the widest horizontal line inside the wetted segment
            let widest = if h <= r {
                2.0 * (r * r - (r - h) * (r - h)).sqrt()
            } else {
                2.0 * r
            };
            assert!((im.chord - widest).abs() < 1e-14);
        }
    }

    #[test]
    fn continuous_in_depth() {
        let r = 0.05;
        let mut prev = Immersion::new(0.0, r);
        for i in 1..=2000 {
            let im = Immersion::new(2.0 * r * f64::from(i) / 2000.0, r);
            assert!(im.theta > prev.theta && im.face_area > prev.face_area && im.chord >= prev.chord);
            assert!(im.theta - prev.theta < 0.05 && im.chord - prev.chord < 0.1 * r);
            prev = im;
        }
    }
}
