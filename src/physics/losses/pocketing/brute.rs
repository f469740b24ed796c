//! Independent brute-force re-computation of the pocket geometry (tests only).
//!
//! Profiles are sampled as dense polylines from the polar form of the involute
//! (`θ(r) = θ0 ± (√(r²/r_b² − 1) − acos(r_b/r))`, parameter = tangent length ℓ = √(r² − r_b²)),
//! the gears are placed by rotation, the minimal distance between the two flanks of each side
//! is found by brute force point-to-polyline search (zoomed: a dense global pass then repeated
//! local passes), and the pocket area is the shoelace area of the closed polygon S-space /
//! gap / T-tooth / gap, Richardson-extrapolated in the sampling step (chord error ∝ h²).
//! Nothing here uses the involute distance property, the closed-form integrals or the
//! case logic of `areas.rs`.

use super::areas::PocketFamily;
use super::teeth::PocketTeeth;

type P = [f64; 2];

fn involute_polar(rb: f64, l: f64) -> (f64, f64) {
    let r = (rb * rb + l * l).sqrt();
    (r, l / rb - (rb / r).acos())
}

/// The brute-force view of one family at one angle.
pub struct BruteScene<'a> {
    s: &'a PocketTeeth,
    t: &'a PocketTeeth,
    a: f64,
    u: f64,
    v: f64,
}

impl<'a> BruteScene<'a> {
    pub fn new(f: &'a PocketFamily, phi1: f64) -> Self {
        let (a, k, upp) = f.frame();
        let u = phi1 * upp;
        Self {
            s: &f.space,
            t: &f.tooth,
            a,
            u,
            v: k * u,
        }
    }

    fn l_range(p: &PocketTeeth) -> (f64, f64) {
        let rf = p.r_form();
        (
            (rf * rf - p.r_base * p.r_base).max(0.0).sqrt(),
            (p.r_tip * p.r_tip - p.r_base * p.r_base).sqrt(),
        )
    }

    /// S flank point, side = +1 right, −1 left.
    fn s_flank(&self, side: f64, l: f64) -> P {
        let (r, th) = involute_polar(self.s.r_base, l);
        let c = self.u + side * (self.s.half_space_base + th);
        [r * c.sin(), r * c.cos()]
    }

    /// T flank point (S frame), side = +1 right, −1 left.
    fn t_flank(&self, side: f64, l: f64) -> P {
        let (r, th) = involute_polar(self.t.r_base, l);
        let c = self.v + side * (self.t.half_tooth_base - th);
        [r * c.sin(), self.a - r * c.cos()]
    }

    fn t_tip(&self, c: f64) -> P {
        [self.t.r_tip * c.sin(), self.a - self.t.r_tip * c.cos()]
    }

    /// Minimal distance between the S and T flanks of one side: (distance, ℓ_S, ℓ_T).
    pub fn gap(&self, side: f64) -> (f64, f64, f64) {
        let fa = |l: f64| self.s_flank(side, l);
        let fb = |l: f64| self.t_flank(side, l);
        min_dist(&fa, Self::l_range(self.s), &fb, Self::l_range(self.t))
    }

    /// Closed pocket polygon with `n` segments per smooth piece.
    fn polygon(&self, n: usize, gl: (f64, f64, f64), gr: (f64, f64, f64)) -> Vec<P> {
        let mut pts: Vec<P> = Vec::new();
        let lin = |a: f64, b: f64, i: usize| a + (b - a) * i as f64 / n as f64;
        let (lfs, _) = Self::l_range(self.s);
        let (_, lat) = Self::l_range(self.t);
        // S left flank: gap foot down to the involute start
        for i in 0..=n {
            pts.push(self.s_flank(-1.0, lin(gl.1, lfs, i)));
        }
        // bottom: mirrored right half reversed, then right half, rotated by u
        let half = self.s.right_bottom_points(n);
        let rot = |p: P| {
            let (su, cu) = self.u.sin_cos();
            [p[0] * cu + p[1] * su, p[1] * cu - p[0] * su]
        };
        for p in half.iter().rev() {
            pts.push(rot([-p[0], p[1]]));
        }
        for p in half.iter() {
            pts.push(rot(*p));
        }
        // S right flank up to the gap foot
        for i in 0..=n {
            pts.push(self.s_flank(1.0, lin(lfs, gr.1, i)));
        }
        // T right flank from the gap foot to the tip corner
        for i in 0..=n {
            pts.push(self.t_flank(1.0, lin(gr.2, lat, i)));
        }
        // T tip arc, right corner to left corner
        let half_tip = self.t.half_tooth_base - involute_polar(self.t.r_base, lat).1;
        for i in 0..=n {
            pts.push(self.t_tip(lin(self.v + half_tip, self.v - half_tip, i)));
        }
        // T left flank from the tip corner to the gap foot
        for i in 0..=n {
            pts.push(self.t_flank(-1.0, lin(lat, gl.2, i)));
        }
        pts
    }

    /// Pocket area (shoelace, Richardson in h) and the two gaps (trailing/left, leading/right).
    pub fn area_and_gaps(&self, n: usize) -> (f64, f64, f64) {
        let gl = self.gap(-1.0);
        let gr = self.gap(1.0);
        let a1 = shoelace_closed(&self.polygon(n, gl, gr));
        let a2 = shoelace_closed(&self.polygon(2 * n, gl, gr));
        ((4.0 * a2 - a1) / 3.0, gl.0, gr.0)
    }

    /// Smallest distance between the T tooth outline and the S space bottom (interference check).
    pub fn tooth_to_bottom_clearance(&self, n: usize) -> f64 {
        let half = self.s.right_bottom_points(n);
        let rot = |p: P| {
            let (su, cu) = self.u.sin_cos();
            [p[0] * cu + p[1] * su, p[1] * cu - p[0] * su]
        };
        let mut bottom: Vec<P> = half.iter().rev().map(|p| rot([-p[0], p[1]])).collect();
        bottom.extend(half.iter().map(|p| rot(*p)));
        let (_, lat) = Self::l_range(self.t);
        let (lft, _) = Self::l_range(self.t);
        let mut tooth = Vec::new();
        for i in 0..=n {
            tooth.push(self.t_flank(1.0, lft + (lat - lft) * i as f64 / n as f64));
        }
        let half_tip = self.t.half_tooth_base - involute_polar(self.t.r_base, lat).1;
        for i in 0..=n {
            let c = self.v + half_tip - 2.0 * half_tip * i as f64 / n as f64;
            tooth.push(self.t_tip(c));
        }
        for i in 0..=n {
            tooth.push(self.t_flank(-1.0, lat - (lat - lft) * i as f64 / n as f64));
        }
        let mut d = f64::INFINITY;
        for p in &tooth {
            for w in bottom.windows(2) {
                d = d.min(point_segment(*p, w[0], w[1]).0);
            }
        }
        d
    }
}

fn shoelace_closed(p: &[P]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % n]);
            0.5 * (a[0] * b[1] - a[1] * b[0])
        })
        .sum()
}

/// Distance from point p to segment ab, and the segment parameter of the foot in [0, 1].
fn point_segment(p: P, a: P, b: P) -> (f64, f64) {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let ap = [p[0] - a[0], p[1] - a[1]];
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let s = if l2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = [ap[0] - s * ab[0], ap[1] - s * ab[1]];
    (d[0].hypot(d[1]), s)
}

/// Minimal distance between two parametrised curves by brute-force point-to-polyline search,
/// zooming in on the best pair. Returns (distance, parameter on a, parameter on b).
pub fn min_dist(
    fa: &dyn Fn(f64) -> P,
    ra: (f64, f64),
    fb: &dyn Fn(f64) -> P,
    rb: (f64, f64),
) -> (f64, f64, f64) {
    let (mut wa, mut wb) = (ra, rb);
    let mut best = (f64::INFINITY, ra.0, rb.0);
    for level in 0..24 {
        let n = if level == 0 { 200 } else { 24 };
        let pa: Vec<(f64, P)> = (0..=n)
            .map(|i| {
                let s = wa.0 + (wa.1 - wa.0) * i as f64 / n as f64;
                (s, fa(s))
            })
            .collect();
        let pb: Vec<(f64, P)> = (0..=n)
            .map(|i| {
                let s = wb.0 + (wb.1 - wb.0) * i as f64 / n as f64;
                (s, fb(s))
            })
            .collect();
        let mut lvl = (f64::INFINITY, 0.0, 0.0);
        for &(sa, p) in &pa {
            for w in pb.windows(2) {
                let (d, s) = point_segment(p, w[0].1, w[1].1);
                if d < lvl.0 {
                    lvl = (d, sa, w[0].0 + s * (w[1].0 - w[0].0));
                }
            }
        }
        for &(sb, p) in &pb {
            for w in pa.windows(2) {
                let (d, s) = point_segment(p, w[0].1, w[1].1);
                if d < lvl.0 {
                    lvl = (d, w[0].0 + s * (w[1].0 - w[0].0), sb);
                }
            }
        }
        best = lvl;
        let ha = 2.0 * (wa.1 - wa.0) / n as f64;
        let hb = 2.0 * (wb.1 - wb.0) / n as f64;
        wa = ((lvl.1 - ha).max(ra.0), (lvl.1 + ha).min(ra.1));
        wb = ((lvl.2 - hb).max(rb.0), (lvl.2 + hb).min(rb.1));
    }
    best
}

#[cfg(test)]
mod tests {
    use super::super::areas::{PocketFamily, PocketFamilyKind};
    use super::super::cases;
    use super::*;

    #[test]
    fn analytic_geometry_matches_brute_force() {
        let mut worst_area: f64 = 0.0;
        let mut worst_gap: f64 = 0.0;
        let mut count = 0;
        for inp in [cases::fzg_c(), cases::seed004(), cases::unequal_with_backlash()] {
            for kind in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1] {
                let f = PocketFamily::new(&inp, kind).unwrap();
                let pm = f.phase_limit();
                let n_ang = 26;
                for i in 0..n_ang {
                    // angles spread over the whole phase, avoiding the exact ends
                    let phi = -pm * 0.999 + 2.0 * pm * 0.999 * (i as f64 + 0.37) / n_ang as f64;
                    let st = f.state(phi).unwrap();
                    let bs = BruteScene::new(&f, phi);
                    let (area, g1, g2) = bs.area_and_gaps(1500);
                    let ea = (area - st.area).abs() / st.area;
                    let eg = (g1 - st.gap1).abs().max((g2 - st.gap2).abs()) / inp.module;
                    worst_area = worst_area.max(ea);
                    worst_gap = worst_gap.max(eg);
                    assert!(ea < 1e-6, "{kind:?} φ={phi}: area {area} vs {}", st.area);
                    assert!(
                        eg < 1e-6,
                        "{kind:?} φ={phi}: gaps ({g1},{g2}) vs ({},{})",
                        st.gap1,
                        st.gap2
                    );
                    count += 1;
                }
            }
        }
        assert!(count >= 50);
        eprintln!("brute force: worst rel. area error {worst_area:.2e}, worst gap error {worst_gap:.2e} m_n");
    }

    #[test]
    fn brute_force_symmetry_and_no_interference() {
        for inp in [
            cases::fzg_c(),
            cases::seed004(),
            cases::unequal_with_backlash(),
            cases::helical(&cases::fzg_c(), 25f64.to_radians()),
        ] {
            for kind in [PocketFamilyKind::SpaceOfGear2, PocketFamilyKind::SpaceOfGear1] {
                let f = PocketFamily::new(&inp, kind).unwrap();
                let pm = f.phase_limit();
                for i in 0..8 {
                    let phi = pm * (i as f64 + 0.5) / 8.0;
                    let (ap, g1p, g2p) = BruteScene::new(&f, phi).area_and_gaps(400);
                    let (am, g1m, g2m) = BruteScene::new(&f, -phi).area_and_gaps(400);
                    assert!((ap - am).abs() < 1e-8 * ap);
                    assert!((g1p - g2m).abs() < 1e-9 * inp.module);
                    assert!((g2p - g1m).abs() < 1e-9 * inp.module);
                    let c = BruteScene::new(&f, phi).tooth_to_bottom_clearance(300);
                    assert!(c > 1e-3 * inp.module, "{kind:?} φ={phi}: clearance {c}");
                    // the entering tooth is never closer to the space's root fillet than to
                    // its involute flanks: the gaps, found on the involutes only, are the
                    // narrowest passages (the fillet of the generated profile never binds)
                    let g = g1p.min(g2p);
                    assert!(
                        c >= g - 1e-6 * inp.module,
                        "{kind:?} φ={phi}: fillet {c} < gap {g}"
                    );
                }
            }
        }
    }
}
