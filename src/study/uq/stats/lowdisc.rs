//! Sobol' low-discrepancy points (I. M. Sobol', 1967) with the direction numbers of S. Joe and
//! F. Y. Kuo, "Constructing Sobol sequences with better two-dimensional projections", SIAM J.
//! Sci. Comput. 30 (2008) 2635–2654, file `new-joe-kuo-6.21201` (dimensions 2 to [`MAX_DIM`]
//! embedded below; dimension 1 is van der Corput's sequence). The rows were read from two public
//! transcriptions of that file (a Python reader's listing of dimensions 2–32 and a JavaScript
//! table of dimensions 2–128, which agree where they overlap).
//!
//! Points are generated in Gray-code order (Antonov & Saleev 1979), the order of Joe and Kuo's
//! reference program and of SciPy's `qmc.Sobol`: the first 2^k points of any power-of-two prefix
//! are a (t, k, s)-net, so each one-dimensional projection of 2^k points has one point in each
//! interval [j 2^-k, (j+1) 2^-k).
//!
//! Randomisation (`seed: Some(_)`): Owen's nested uniform scrambling in base 2 (A. B. Owen,
//! "Randomly permuted (t,m,s)-nets and (t,s)-sequences", 1995), with the random permutation of
//! each node of the binary digit tree drawn from a hash of (seed, dimension, digit position,
//! preceding digits) instead of stored. The scrambled points keep the net property, each is
//! uniform on [0, 1), and they are written as the centre of their 2^-32 cell, so they lie in the
//! open interval (0, 1). Without a seed the raw sequence is returned (its first point is 0).

use super::rng::mix64;

/// The number of dimensions with embedded direction numbers.
pub const MAX_DIM: usize = 64;

/// The most points [`sobol_points`] produces (the digits are 32 bits).
pub const MAX_POINTS: usize = 1 << 31;

/// Joe–Kuo rows for dimensions 2..=64: (s, a, m_1..m_s): degree s of the primitive polynomial,
/// its inner coefficients as the bits of a, the initial direction numbers m_i.
const JOE_KUO: [(u32, u32, &[u32]); MAX_DIM - 1] = [
    (1, 0, &[1]),
    (2, 1, &[1, 3]),
    (3, 1, &[1, 3, 1]),
    (3, 2, &[1, 1, 1]),
    (4, 1, &[1, 1, 3, 3]),
    (4, 4, &[1, 3, 5, 13]),
    (5, 2, &[1, 1, 5, 5, 17]),
    (5, 4, &[1, 1, 5, 5, 5]),
    (5, 7, &[1, 1, 7, 11, 19]),
    (5, 11, &[1, 1, 5, 1, 1]),
    (5, 13, &[1, 1, 1, 3, 11]),
    (5, 14, &[1, 3, 5, 5, 31]),
    (6, 1, &[1, 3, 3, 9, 7, 49]),
    (6, 13, &[1, 1, 1, 15, 21, 21]),
    (6, 16, &[1, 3, 1, 13, 27, 49]),
    (6, 19, &[1, 1, 1, 15, 7, 5]),
    (6, 22, &[1, 3, 1, 15, 13, 25]),
    (6, 25, &[1, 1, 5, 5, 19, 61]),
    (7, 1, &[1, 3, 7, 11, 23, 15, 103]),
    (7, 4, &[1, 3, 7, 13, 13, 15, 69]),
    (7, 7, &[1, 1, 3, 13, 7, 35, 63]),
    (7, 8, &[1, 3, 5, 9, 1, 25, 53]),
    (7, 14, &[1, 3, 1, 13, 9, 35, 107]),
    (7, 19, &[1, 3, 1, 5, 27, 61, 31]),
    (7, 21, &[1, 1, 5, 11, 19, 41, 61]),
    (7, 28, &[1, 3, 5, 3, 3, 13, 69]),
    (7, 31, &[1, 1, 7, 13, 1, 19, 1]),
    (7, 32, &[1, 3, 7, 5, 13, 19, 59]),
    (7, 37, &[1, 1, 3, 9, 25, 29, 41]),
    (7, 41, &[1, 3, 5, 13, 23, 1, 55]),
    (7, 42, &[1, 3, 7, 3, 13, 59, 17]),
    (7, 50, &[1, 3, 1, 3, 5, 53, 69]),
    (7, 55, &[1, 1, 5, 5, 23, 33, 13]),
    (7, 56, &[1, 1, 7, 7, 1, 61, 123]),
    (7, 59, &[1, 1, 7, 9, 13, 61, 49]),
    (7, 62, &[1, 3, 3, 5, 3, 55, 33]),
    (8, 14, &[1, 3, 1, 15, 31, 13, 49, 245]),
    (8, 21, &[1, 3, 5, 15, 31, 59, 63, 97]),
    (8, 22, &[1, 3, 1, 11, 11, 11, 77, 249]),
    (8, 38, &[1, 3, 1, 11, 27, 43, 71, 9]),
    (8, 47, &[1, 1, 7, 15, 21, 11, 81, 45]),
    (8, 49, &[1, 3, 7, 3, 25, 31, 65, 79]),
    (8, 50, &[1, 3, 1, 1, 19, 11, 3, 205]),
    (8, 52, &[1, 1, 5, 9, 19, 21, 29, 157]),
    (8, 56, &[1, 3, 7, 11, 1, 33, 89, 185]),
    (8, 67, &[1, 3, 3, 3, 15, 9, 79, 71]),
    (8, 70, &[1, 3, 7, 11, 15, 39, 119, 27]),
    (8, 84, &[1, 1, 3, 1, 11, 31, 97, 225]),
    (8, 97, &[1, 1, 1, 3, 23, 43, 57, 177]),
    (8, 103, &[1, 3, 7, 7, 17, 17, 37, 71]),
    (8, 115, &[1, 3, 1, 5, 27, 63, 123, 213]),
    (8, 122, &[1, 1, 3, 5, 11, 43, 53, 133]),
    (9, 8, &[1, 3, 5, 5, 29, 17, 47, 173, 479]),
    (9, 13, &[1, 3, 3, 11, 3, 1, 109, 9, 69]),
    (9, 16, &[1, 1, 1, 5, 17, 39, 23, 5, 343]),
    (9, 22, &[1, 3, 1, 5, 25, 15, 31, 103, 499]),
    (9, 25, &[1, 1, 1, 11, 11, 17, 63, 105, 183]),
    (9, 44, &[1, 1, 5, 11, 9, 29, 97, 231, 363]),
    (9, 47, &[1, 1, 5, 15, 19, 45, 41, 7, 383]),
    (9, 52, &[1, 3, 7, 7, 31, 19, 83, 137, 221]),
    (9, 55, &[1, 1, 1, 3, 23, 15, 111, 223, 83]),
    (9, 59, &[1, 1, 5, 13, 31, 15, 55, 25, 161]),
    (9, 62, &[1, 1, 3, 13, 25, 47, 39, 87, 257]),
];

/// The 32 direction numbers v_k (k = 0 the most significant digit) of dimension `j` (0-based):
/// v_k = m_k 2^(31−k) for k < s, then the recurrence of Bratley & Fox (1988) as Joe & Kuo state
/// it: v_k = v_{k−s} ⊕ (v_{k−s} ≫ s) ⊕ ⊕_{i=1}^{s−1} a_i v_{k−i}, a_i the bit s−1−i of a.
fn directions(j: usize) -> [u32; 32] {
    let mut v = [0u32; 32];
    if j == 0 {
        for (k, vk) in v.iter_mut().enumerate() {
            *vk = 1 << (31 - k);
        }
        return v;
    }
    let (s, a, m) = JOE_KUO[j - 1];
    let s = s as usize;
    for k in 0..32 {
        v[k] = if k < s {
            m[k] << (31 - k)
        } else {
            let mut x = v[k - s] ^ (v[k - s] >> s);
            for i in 1..s {
                if (a >> (s - 1 - i)) & 1 == 1 {
                    x ^= v[k - i];
                }
            }
            x
        };
    }
    v
}

/// Owen's nested uniform scramble of the 32 digits of `x` for the dimension key `key`: digit k
/// (from the most significant) is flipped by a random bit drawn from (key, k, digits above k).
fn owen_scramble(x: u32, key: u64) -> u32 {
    let mut out = x;
    for k in 0..32u32 {
        let prefix = if k == 0 { 0 } else { u64::from(x >> (32 - k)) };
        let node = (u64::from(k) << 32) | prefix;
        if mix64(key ^ mix64(node)) & 1 == 1 {
            out ^= 1 << (31 - k);
        }
    }
    out
}

/// `n` Sobol' points in `dim` dimensions, one row per point. `seed: None` gives the raw
/// sequence (values k/2^32 in [0, 1), starting at the origin), `Some(s)` an Owen-scrambled
/// sequence in (0, 1). Refuses `dim` = 0 or above [`MAX_DIM`] and `n` above [`MAX_POINTS`].
pub fn sobol_points(n: usize, dim: usize, seed: Option<u64>) -> Result<Vec<Vec<f64>>, String> {
    if dim == 0 || dim > MAX_DIM {
        return Err(format!(
            "{dim} dimensions: the Sobol' sequence here has 1 to {MAX_DIM} (Joe–Kuo direction numbers embedded)"
        ));
    }
    if n > MAX_POINTS {
        return Err(format!("{n} points: at most {MAX_POINTS}"));
    }
    let v: Vec<[u32; 32]> = (0..dim).map(directions).collect();
    let keys: Vec<u64> = (0..dim)
        .map(|j| seed.map_or(0, |s| mix64(s ^ mix64(j as u64 + 1))))
        .collect();
    let scale = 1.0 / 4_294_967_296.0;
    let mut x = vec![0u32; dim];
    let mut rows = Vec::with_capacity(n);
    for i in 0..n {
        if i > 0 {
            let c = i.trailing_zeros() as usize;
            for (xj, vj) in x.iter_mut().zip(&v) {
                *xj ^= vj[c];
            }
        }
        let row = match seed {
            None => x.iter().map(|&xj| f64::from(xj) * scale).collect(),
            Some(_) => x
                .iter()
                .zip(&keys)
                .map(|(&xj, &key)| (f64::from(owen_scramble(xj, key)) + 0.5) * scale)
                .collect(),
        };
        rows.push(row);
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first ten points in three dimensions as listed with Joe and Kuo's reference program
    /// (the same in SciPy's unscrambled `qmc.Sobol`).
    #[test]
    fn first_points_match_the_published_sequence() {
        let want = [
            [0.0, 0.0, 0.0],
            [0.5, 0.5, 0.5],
            [0.75, 0.25, 0.25],
            [0.25, 0.75, 0.75],
            [0.375, 0.375, 0.625],
            [0.875, 0.875, 0.125],
            [0.625, 0.125, 0.875],
            [0.125, 0.625, 0.375],
            [0.1875, 0.3125, 0.9375],
            [0.6875, 0.8125, 0.4375],
        ];
        let got = sobol_points(10, 3, None).unwrap();
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g.as_slice(), w.as_slice());
        }
    }

    /// Each 1-D projection of the first 2^k points has one point per cell of width 2^-k, in every
    /// dimension, raw and scrambled.
    #[test]
    fn each_projection_is_stratified() {
        for seed in [None, Some(7)] {
            let k = 10;
            let pts = sobol_points(1 << k, MAX_DIM, seed).unwrap();
            for j in 0..MAX_DIM {
                let mut seen = vec![false; 1 << k];
                for p in &pts {
                    assert!(seed.is_none() || (p[j] > 0.0 && p[j] < 1.0));
                    let cell = (p[j] * f64::from(1u32 << k)) as usize;
                    assert!(!seen[cell], "dimension {j}, seed {seed:?}: cell {cell} twice");
                    seen[cell] = true;
                }
            }
        }
    }

    /// Joe and Kuo's property: the 2-D projections of 2^k points, for dimension pairs, are
    /// (0, k, 2)-nets for small k; here the weaker check that the first 2^(2m) points of
    /// dimensions 1 and 2 put one point in each 2^-m × 2^-m box (a (0, 2m, 2)-net).
    #[test]
    fn first_two_dimensions_form_a_net() {
        let m = 4;
        let pts = sobol_points(1 << (2 * m), 2, None).unwrap();
        let mut seen = vec![false; 1 << (2 * m)];
        for p in &pts {
            let (a, b) = ((p[0] * 16.0) as usize, (p[1] * 16.0) as usize);
            assert!(!seen[a * 16 + b]);
            seen[a * 16 + b] = true;
        }
    }

    #[test]
    fn scrambling_depends_on_the_seed_and_refuses_too_many_dimensions() {
        let a = sobol_points(4, 2, Some(1)).unwrap();
        let b = sobol_points(4, 2, Some(2)).unwrap();
        assert_ne!(a, b);
        assert_eq!(a, sobol_points(4, 2, Some(1)).unwrap());
        let e = sobol_points(4, MAX_DIM + 1, None).unwrap_err();
        assert!(e.contains("1 to 64"), "{e}");
    }
}
