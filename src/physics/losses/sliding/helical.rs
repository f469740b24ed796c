//! Helical meshes: contact lines in the plane of action, Niemann–Richer load distribution and
//! face-width slices (physics.md §7; seed 003 eq. 3.1 and fig. 4.4–4.7).
//!
//! In the plane of action the contact lines are inclined by β_b to the axis. A line whose leading
//! end (face y = 0) is at transverse position s_lead covers s = s_lead − y·tan β_b, y ∈ [0, b]; the
//! part with s_A ≤ s ≤ s_E is in contact, and a line element dy has length dy/cos β_b.
//!
//! **Contact length of one tooth (seed 003, fig. 4.4 step 2.1)**, K = AK the leading end's distance
//! from A, A'C = b tan β_b, A'B = g_α:
//! 1. entering, AK ≤ A'C: `L = AK / sin β_b`;
//! 2. full, A'C < AK ≤ A'B: `L = A'C / sin β_b = b / cos β_b`;
//! 3. leaving, A'B < AK ≤ A'B + A'C: `L = (A'B + A'C − AK) / sin β_b`.
//!
//! These assume A'C ≤ A'B (ε_β ≤ ε_α). The general form used by the tables is the overlap
//! `L = |[AK − A'C, AK] ∩ [0, A'B]| / sin β_b`, which equals the three cases when they apply and adds
//! the fourth (A'B < AK ≤ A'C: the line spans the whole field, `L = A'B / sin β_b`).
//!
//! **Niemann–Richer [seed 003 eq. 3.1]:** line load `w(x) = w̄ (1 + c cos 2β_b cos πx)`, c = 0.4,
//! x = (s − s_mid)/(g_α/2) ∈ [−1, 1] (x = 0 mid-path; seed 003 uses x = n/n_A, identical for its
//! symmetric gears). At every instant w̄ is set so that the load integrated over all lines in
//! contact equals the normal force F_bn = T1/(r_b1 cos β_b). Seed 003 gives w̄ in kgf/mm; here N/m.

use super::contact::{ContactElement, ContactPath, ElementFrame, Sample};

/// Load distribution along the contact lines of a helical mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HelicalDistribution {
    /// Constant load per unit line length at each instant (w = F_bn/L_total) [std].
    Uniform,
    /// Niemann–Richer, `w ∝ 1 + coefficient·cos 2β_b·cos πx` (seed 003: coefficient 0.4).
    NiemannRicher {
        /// Amplitude coefficient (0.4).
        coefficient: f64,
    },
}

impl Default for HelicalDistribution {
    fn default() -> Self {
        HelicalDistribution::NiemannRicher { coefficient: 0.4 }
    }
}

impl HelicalDistribution {
    /// Shape factor w/w̄ at x ∈ [−1, 1] for base helix angle β_b.
    pub fn shape(self, x: f64, beta_b: f64) -> f64 {
        match self {
            HelicalDistribution::Uniform => 1.0,
            HelicalDistribution::NiemannRicher { coefficient } => {
                1.0 + coefficient * (2.0 * beta_b).cos() * (std::f64::consts::PI * x).cos()
            }
        }
    }
}

/// Seed 003's three-case contact length of one tooth (m); `ak` = AK, `ab` = A'B = g_α,
/// `ac` = A'C = b tan β_b. Valid for ac ≤ ab and 0 ≤ ak ≤ ab + ac.
pub fn seed_contact_length(ak: f64, ab: f64, ac: f64, beta_b: f64) -> f64 {
    let sb = beta_b.sin();
    if ak <= ac {
        ak / sb
    } else if ak <= ab {
        ac / sb
    } else {
        ((ab + ac) - ak) / sb
    }
}

/// General contact length of one tooth (m): overlap of the line's transverse extent
/// [AK − A'C, AK] with the field [0, A'B], divided by sin β_b. β_b > 0.
pub fn contact_length(ak: f64, ab: f64, ac: f64, beta_b: f64) -> f64 {
    let lo = (ak - ac).max(0.0);
    let hi = ak.min(ab);
    (hi - lo).max(0.0) / beta_b.sin()
}

/// Build the helical contact table: `time_samples` uniform samples of the reference tooth's leading
/// end over one base pitch (midpoint rule, weight 1/N), each contact line cut into `slices` face-width
/// slices; an element's length is the exact part of its slice inside the field of action and its
/// position the midpoint of that part. Element forces per unit |T1| follow `dist`, normalised at
/// every sample so that Σ force = 1/(r_b1 cos β_b) (= F_bn/T1).
pub(crate) fn build_helical(
    path: &ContactPath,
    frame: &ElementFrame,
    dist: HelicalDistribution,
    beta_b: f64,
    b: f64,
    time_samples: usize,
    slices: usize,
) -> (Vec<Sample>, Vec<ContactElement>) {
    let p = path.p_bt;
    let tb = beta_b.tan();
    let span = b * tb; // A'C
    let dy = b / slices as f64;
    let s_mid = 0.5 * (path.s_a + path.s_e);
    let half = 0.5 * path.length();
    let f_bn = 1.0 / (frame.rb1 * frame.cos_bb);
    let weight = 1.0 / time_samples as f64;
    let per_sample = slices * ((path.length() + span) / p).ceil() as usize + slices;
    let mut samples = Vec::with_capacity(time_samples);
    let mut elements = Vec::with_capacity(time_samples * per_sample);
    for i in 0..time_samples {
        let s_ref = path.s_a + (i as f64 + 0.5) * p * weight;
        let first = elements.len();
        // raw (unnormalised) load weights: shape(x)·length
        let mut total = 0.0;
        let mut k = 0.0;
        loop {
            let s_lead = s_ref + k * p;
            if s_lead - span > path.s_e {
                break;
            }
            for j in 0..slices {
                let y0 = j as f64 * dy;
                let y1 = y0 + dy;
                let (ylo, yhi) = if tb > 0.0 {
                    (y0.max((s_lead - path.s_e) / tb), y1.min((s_lead - path.s_a) / tb))
                } else if s_lead <= path.s_e {
                    (y0, y1)
                } else {
                    (0.0, 0.0)
                };
                if yhi <= ylo {
                    continue;
                }
                let len = (yhi - ylo) / frame.cos_bb;
                let s = s_lead - tb * 0.5 * (ylo + yhi);
                let x = ((s - s_mid) / half).clamp(-1.0, 1.0);
                let raw = dist.shape(x, beta_b) * len;
                total += raw;
                // store raw weight for now; normalised below
                elements.push(frame.element(path, s, len, (raw, raw), weight));
            }
            k += 1.0;
        }
        let scale = f_bn / total;
        for e in &mut elements[first..] {
            let f = e.force_fwd * scale;
            *e = frame.element(path, e.s, e.length, (f, f), weight);
        }
        samples.push(Sample {
            s_ref,
            weight,
            first,
            count: elements.len() - first,
        });
    }
    (samples, elements)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::losses::sliding::SlidingMeshInput;

    /// Seed 003 helical example: z 30/30, m 3 mm (seed: R_p = m z/2), α 20°, β 33.5°, b 20 mm.
    fn seed_helical(beta: f64) -> (SlidingMeshInput, f64) {
        let inp =
            crate::physics::losses::sliding::cases::equal_pair(30, 0.003, 20f64.to_radians(), beta, 0.825e-6);
        let beta_b = inp.base_helix_angle;
        (inp, beta_b)
    }

    #[test]
    fn seed003_three_contact_lengths_41_3_mm() {
        // seed 003 fig. 4.6: at one meshing position teeth 1, 2, 3 have 8.3, 23.6, 9.4 mm, total 41.3 mm
        let (inp, bb) = seed_helical(33.5f64.to_radians());
        let path = ContactPath::new(&inp).unwrap();
        let (ab, ac) = (path.length(), inp.face_width * bb.tan());
        let p = path.p_bt;
        // place the entering tooth 3 so that its length is 9.4 mm, then the others follow one pitch apart
        let ak3 = 9.4e-3 * bb.sin();
        let l3 = seed_contact_length(ak3, ab, ac, bb);
        let l2 = seed_contact_length(ak3 + p, ab, ac, bb);
        let l1 = seed_contact_length(ak3 + 2.0 * p, ab, ac, bb);
        assert!((l2 * 1e3 - 23.6).abs() < 0.05, "tooth 2: {}", l2 * 1e3);
        assert!((l1 * 1e3 - 8.3).abs() < 0.06, "tooth 1: {}", l1 * 1e3);
        assert!(((l1 + l2 + l3) * 1e3 - 41.3).abs() < 0.06);
        assert!(ak3 + 3.0 * p > ab + ac); // no fourth tooth
    }

    #[test]
    fn general_length_equals_three_cases() {
        let (inp, bb) = seed_helical(33.5f64.to_radians());
        let path = ContactPath::new(&inp).unwrap();
        let (ab, ac) = (path.length(), inp.face_width * bb.tan());
        assert!(ac <= ab);
        for i in 0..=1000 {
            let ak = (ab + ac) * i as f64 / 1000.0;
            let a = seed_contact_length(ak, ab, ac, bb);
            let g = contact_length(ak, ab, ac, bb);
            assert!((a - g).abs() < 1e-15, "ak={ak}");
        }
        // fourth case (ε_β > ε_α): the seed's first case overshoots, the overlap form does not
        let ac_big = 2.0 * ab;
        let ak = 1.5 * ab;
        assert!((contact_length(ak, ab, ac_big, bb) - ab / bb.sin()).abs() < 1e-15);
        assert!(seed_contact_length(ak, ab, ac_big, bb) > ab / bb.sin());
    }

    fn frame(inp: &SlidingMeshInput) -> ElementFrame {
        ElementFrame {
            rb1: inp.base_radius1,
            cos_bb: inp.base_helix_angle.cos(),
        }
    }

    #[test]
    fn niemann_richer_normalisation_and_exact_lengths() {
        let (inp, bb) = seed_helical(33.5f64.to_radians());
        let path = ContactPath::new(&inp).unwrap();
        let fr = frame(&inp);
        let dist = HelicalDistribution::default();
        let (samples, el) = build_helical(&path, &fr, dist, bb, inp.face_width, 24, 150);
        let ac = inp.face_width * bb.tan();
        let f_bn = 1.0 / (inp.base_radius1 * bb.cos());
        for smp in &samples {
            let es = &el[smp.first..smp.first + smp.count];
            // integral of the load over all lines in contact = F_bn (per unit torque), to 1e-9
            let tot: f64 = es.iter().map(|e| e.force_fwd).sum();
            assert!((tot / f_bn - 1.0).abs() < 1e-9);
            // the line load of each element is w = w̄·shape(x)
            let wbar = es[0].q_fwd
                / dist.shape(
                    (es[0].s - 0.5 * (path.s_a + path.s_e)) / (0.5 * path.length()),
                    bb,
                );
            for e in es {
                let x = (e.s - 0.5 * (path.s_a + path.s_e)) / (0.5 * path.length());
                assert!((e.q_fwd / (wbar * dist.shape(x, bb)) - 1.0).abs() < 1e-12);
            }
            // total length = Σ over teeth of the general (three-case) length, exactly
            let len: f64 = es.iter().map(|e| e.length).sum();
            let mut exact = 0.0;
            for k in 0..6 {
                let ak = smp.s_ref + k as f64 * path.p_bt - path.s_a;
                exact += contact_length(ak, path.length(), ac, bb);
            }
            assert!((len - exact).abs() < 1e-12 * exact, "{len} {exact}");
        }
        // continuous Niemann–Richer integral (closed form per line) vs the slice sum: converges
        let smp = samples[5];
        let es = &el[smp.first..smp.first + smp.count];
        let raw_discrete: f64 = es
            .iter()
            .map(|e| dist.shape((e.s - 0.5 * (path.s_a + path.s_e)) / (0.5 * path.length()), bb) * e.length)
            .sum();
        let mut raw_exact = 0.0;
        let (smid, half) = (0.5 * (path.s_a + path.s_e), 0.5 * path.length());
        let amp = 0.4 * (2.0 * bb).cos();
        for k in 0..6 {
            let hi = (smp.s_ref + k as f64 * path.p_bt).min(path.s_e);
            let lo = (smp.s_ref + k as f64 * path.p_bt - ac).max(path.s_a);
            if hi > lo {
                let xs = |s: f64| (s - smid) / half;
                let pi = std::f64::consts::PI;
                raw_exact +=
                    ((hi - lo) + amp * half / pi * ((pi * xs(hi)).sin() - (pi * xs(lo)).sin())) / bb.sin();
            }
        }
        assert!(
            (raw_discrete / raw_exact - 1.0).abs() < 2e-5,
            "{raw_discrete} {raw_exact}"
        );
    }

    #[test]
    fn uniform_load_when_base_helix_is_45_degrees() {
        let (mut inp, _) = seed_helical(33.5f64.to_radians());
        let bb = std::f64::consts::FRAC_PI_4;
        inp.base_helix_angle = bb;
        let path = ContactPath::new(&inp).unwrap();
        let (samples, el) = build_helical(
            &path,
            &frame(&inp),
            HelicalDistribution::default(),
            bb,
            inp.face_width,
            16,
            150,
        );
        for smp in &samples {
            let es = &el[smp.first..smp.first + smp.count];
            let w0 = es[0].q_fwd;
            assert!(es.iter().all(|e| (e.q_fwd / w0 - 1.0).abs() < 1e-12));
        }
        // and the load is not uniform at β_b = 31.9° (seed 003)
        let bb2 = (33.5f64.to_radians().tan() * 20f64.to_radians().cos()).atan();
        inp.base_helix_angle = bb2;
        let (samples, el) = build_helical(
            &path,
            &frame(&inp),
            HelicalDistribution::default(),
            bb2,
            inp.face_width,
            4,
            150,
        );
        let es = &el[samples[0].first..samples[0].first + samples[0].count];
        let (mn, mx) = es
            .iter()
            .fold((f64::MAX, 0.0_f64), |(a, b), e| (a.min(e.q_fwd), b.max(e.q_fwd)));
        assert!(mx / mn > 1.2);
    }
}
