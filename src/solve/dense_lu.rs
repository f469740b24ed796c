//! Dense LU with partial pivoting for the small iteration matrices of lumped networks (tens of
//! states), written for them: one column-major buffer, row swaps recorded, no allocation after
//! `set_sparsity`.
//!
//! diffsol's nalgebra LU goes through nalgebra's generic views (one `icamax`, one column swap and
//! one rank-1 update per pivot, each through a view): measured on the 14-state FZG C scene, its
//! three triangular solves per Rosenbrock step took 14 % of a WLTC and its factorisation 10 %
//! (`perf`). Algorithm: Golub & Van Loan, *Matrix Computations*, 4th ed.,
//! Alg. 3.4.1 (Gaussian elimination with partial pivoting, kji form) and §3.1 (triangular
//! solves).

use diffsol::{MatrixCommon, NalgebraMat, NalgebraVec};
use diffsol_la::{LaError, LinearOp, LinearSolver};

use super::equations::{HostVector, JacobianMatrix};

/// LU of a small dense iteration matrix. Quadrature states (loss and boundary energies: nothing
/// depends on them, so their columns of M = I − γhJ are unit vectors) are eliminated first:
///
/// ```text
/// M = | M_NN  0 |    x_N = M_NN⁻¹ b_N,   x_Q = b_Q − M_QN x_N
///     | M_QN  I |
/// ```
///
/// so only the node block (3–5 nodes in the bundled examples, of 12–37 states) is factorised.
#[derive(Default)]
pub struct SmallDenseLu {
    /// Size of the factorised block.
    n: usize,
    /// L (unit, below the diagonal) and U of M_NN, column-major.
    lu: Vec<f64>,
    piv: Vec<usize>,
    /// 1/U_kk (the back substitution multiplies).
    inv_diag: Vec<f64>,
    /// States of the factorised block, and the quadratures.
    nodes: Vec<usize>,
    quads: Vec<usize>,
    /// True when the factorised block is the leading states `0..n` (solved in place).
    nodes_leading: bool,
    /// Non-zero entries of M_QN: (quadrature state, column in the node block, value).
    m_qn: Vec<(usize, usize, f64)>,
    /// Where the Jacobian entries of [`Self::factorise_entries`] go, for the slots they were
    /// built for: (entry, position in the node block), and the entry of each M_QN value.
    node_entries: Vec<(usize, usize)>,
    quad_entries: Vec<usize>,
    /// Address and length of those slots (the solver serves one equations object per run).
    entry_slots: (usize, usize),
    /// The matrix as the operator writes it.
    a: Option<NalgebraMat<f64>>,
    /// Scratch for x_N.
    x_n: std::cell::RefCell<Vec<f64>>,
    factorised: bool,
}

impl SmallDenseLu {
    /// Split the states of the column-major `n_all`² matrix `m` into quadratures (unit columns)
    /// and the rest, keeping the last split while its quadrature columns are still unit vectors,
    /// and gather M_NN and M_QN.
    fn gather(&mut self, m: &[f64], n_all: usize) {
        let unit = |j: usize| {
            let c = &m[j * n_all..(j + 1) * n_all];
            c[j] == 1.0 && c[..j].iter().chain(&c[j + 1..]).all(|v| *v == 0.0)
        };
        let split_holds = self.nodes.len() + self.quads.len() == n_all && self.quads.iter().all(|&j| unit(j));
        if !split_holds {
            self.nodes.clear();
            self.quads.clear();
            for j in 0..n_all {
                if unit(j) {
                    self.quads.push(j);
                } else {
                    self.nodes.push(j);
                }
            }
        }
        self.set_block_sizes();
        let n = self.n;
        // The entries' destinations (factorise_entries) no longer describe m_qn.
        self.entry_slots = (0, 0);
        self.m_qn.clear();
        for (b, &j) in self.nodes.iter().enumerate() {
            let c = &m[j * n_all..(j + 1) * n_all];
            for (a, &i) in self.nodes.iter().enumerate() {
                self.lu[b * n + a] = c[i];
            }
            for &i in &self.quads {
                if c[i] != 0.0 {
                    self.m_qn.push((i, b, c[i]));
                }
            }
        }
    }

    /// Sizes of the buffers for the current split.
    fn set_block_sizes(&mut self) {
        let n = self.nodes.len();
        self.n = n;
        self.lu.resize(n * n, 0.0);
        self.piv.resize(n, 0);
        self.inv_diag.resize(n, 0.0);
        self.nodes_leading = self.nodes.iter().enumerate().all(|(i, &j)| i == j);
    }

    /// The split of the states for Jacobian entries at column-major positions `slots` of an
    /// `n_all`² matrix: the columns with entries form the node block, the other states are
    /// quadratures (their columns of M are unit vectors). Built once per pattern.
    fn split_for_entries(&mut self, n_all: usize, slots: &[usize]) {
        let mut in_block = vec![false; n_all];
        for &s in slots {
            in_block[s / n_all] = true;
        }
        self.nodes = (0..n_all).filter(|&j| in_block[j]).collect();
        self.quads = (0..n_all).filter(|&j| !in_block[j]).collect();
        let mut local = vec![usize::MAX; n_all];
        for (b, &j) in self.nodes.iter().enumerate() {
            local[j] = b;
        }
        self.set_block_sizes();
        let n = self.n;
        (self.node_entries, self.quad_entries, self.m_qn) = (Vec::new(), Vec::new(), Vec::new());
        for (k, &s) in slots.iter().enumerate() {
            let (r, c) = (s % n_all, local[s / n_all]);
            match local[r] {
                usize::MAX => {
                    self.quad_entries.push(k);
                    self.m_qn.push((r, c, 0.0));
                }
                a => self.node_entries.push((k, c * n + a)),
            }
        }
        self.entry_slots = (slots.as_ptr() as usize, slots.len());
    }

    /// Factorise M = I − γh·J straight from J's entries `vals` at the column-major positions
    /// `slots` of an `n_all`² matrix (repeated positions add up), without forming M: only the
    /// node block and the non-zero entries of M_QN are written. Returns false when the node block
    /// is singular or not finite (the solves then fail).
    pub fn factorise_entries(&mut self, n_all: usize, slots: &[usize], vals: &[f64], gamma_h: f64) -> bool {
        if self.entry_slots != (slots.as_ptr() as usize, slots.len()) {
            self.split_for_entries(n_all, slots);
        }
        let n = self.n;
        self.lu.iter_mut().for_each(|v| *v = 0.0);
        for k in 0..n {
            self.lu[k * n + k] = 1.0;
        }
        for &(k, p) in &self.node_entries {
            self.lu[p] -= gamma_h * vals[k];
        }
        for (m, &k) in self.m_qn.iter_mut().zip(&self.quad_entries) {
            m.2 = -gamma_h * vals[k];
        }
        self.factorised = self.factor();
        self.factorised
    }

    fn factor(&mut self) -> bool {
        // The node blocks of lumped networks are small: a size known at compile time lets the
        // loops unroll (the same operations in the same order, so the same results).
        let (a, piv, inv) = (&mut self.lu[..], &mut self.piv[..], &mut self.inv_diag[..]);
        match self.n {
            1 => factor_sized::<1>(a, piv, inv, 1),
            2 => factor_sized::<2>(a, piv, inv, 2),
            3 => factor_sized::<3>(a, piv, inv, 3),
            4 => factor_sized::<4>(a, piv, inv, 4),
            5 => factor_sized::<5>(a, piv, inv, 5),
            6 => factor_sized::<6>(a, piv, inv, 6),
            n => factor_sized::<0>(a, piv, inv, n),
        }
    }

    fn solve(&self, x: &mut [f64]) {
        let (lu, piv, inv) = (&self.lu[..], &self.piv[..], &self.inv_diag[..]);
        match self.n {
            1 => solve_sized::<1>(lu, piv, inv, x, 1),
            2 => solve_sized::<2>(lu, piv, inv, x, 2),
            3 => solve_sized::<3>(lu, piv, inv, x, 3),
            4 => solve_sized::<4>(lu, piv, inv, x, 4),
            5 => solve_sized::<5>(lu, piv, inv, x, 5),
            6 => solve_sized::<6>(lu, piv, inv, x, 6),
            n => solve_sized::<0>(lu, piv, inv, x, n),
        }
    }
}

/// LU with partial pivoting of the column-major `n`² matrix `a` in place (`N` = n, or 0 for a
/// size known only at run time); pivots into `piv`, 1/U_kk into `inv`. False when a pivot is
/// zero or not finite.
#[inline(always)]
fn factor_sized<const N: usize>(a: &mut [f64], piv: &mut [usize], inv: &mut [f64], n_dyn: usize) -> bool {
    let n = if N > 0 { N } else { n_dyn };
    let (a, piv, inv) = (&mut a[..n * n], &mut piv[..n], &mut inv[..n]);
    for k in 0..n {
        let col = k * n;
        let (mut p, mut big) = (k, 0.0);
        for (i, v) in a[col + k..col + n].iter().enumerate() {
            if v.abs() > big {
                (p, big) = (k + i, v.abs());
            }
        }
        piv[k] = p;
        if !(big > 0.0 && big.is_finite()) {
            return false;
        }
        if p != k {
            for j in 0..n {
                a.swap(j * n + k, j * n + p);
            }
        }
        let d = 1.0 / a[col + k];
        inv[k] = d;
        a[col + k + 1..col + n].iter_mut().for_each(|v| *v *= d);
        // Columns right of k: a_j[k+1..] −= l_k[k+1..] · u_kj.
        let (left, right) = a.split_at_mut((k + 1) * n);
        let l = &left[col + k + 1..col + n];
        for cj in right.chunks_exact_mut(n) {
            let ukj = cj[k];
            if ukj != 0.0 {
                for (x, li) in cj[k + 1..].iter_mut().zip(l) {
                    *x -= li * ukj;
                }
            }
        }
    }
    true
}

/// Solve (LU) x = b in place with the factors of [`factor_sized`].
#[inline(always)]
fn solve_sized<const N: usize>(lu: &[f64], piv: &[usize], inv: &[f64], x: &mut [f64], n_dyn: usize) {
    let n = if N > 0 { N } else { n_dyn };
    let (lu, piv, inv, x) = (&lu[..n * n], &piv[..n], &inv[..n], &mut x[..n]);
    for (k, &p) in piv.iter().enumerate() {
        x.swap(k, p);
    }
    for (j, cj) in lu.chunks_exact(n).enumerate() {
        let xj = x[j];
        if xj != 0.0 {
            for (xi, l) in x[j + 1..].iter_mut().zip(&cj[j + 1..]) {
                *xi -= l * xj;
            }
        }
    }
    for ((j, cj), d) in lu.chunks_exact(n).enumerate().zip(inv).rev() {
        x[j] *= d;
        let xj = x[j];
        for (xi, u) in x[..j].iter_mut().zip(&cj[..j]) {
            *xi -= u * xj;
        }
    }
}

type Mat = NalgebraMat<f64>;

impl LinearSolver<Mat> for SmallDenseLu {
    fn set_sparsity<C: LinearOp<T = f64, V = NalgebraVec<f64>, M = Mat, C = diffsol::NalgebraContext>>(
        &mut self,
        op: &C,
    ) {
        let n = op.nrows();
        self.n = n;
        self.lu = vec![0.0; n * n];
        self.piv = vec![0; n];
        self.inv_diag = vec![0.0; n];
        self.nodes = Vec::with_capacity(n);
        self.quads = Vec::with_capacity(n);
        self.m_qn = Vec::with_capacity(n * n);
        self.entry_slots = (0, 0);
        self.x_n = std::cell::RefCell::new(vec![0.0; n]);
        self.a = Some(<Mat as diffsol::Matrix>::zeros(n, n, *op.context()));
        self.factorised = false;
    }

    fn set_linearisation<
        C: LinearOp<T = f64, V = NalgebraVec<f64>, M = Mat, C = diffsol::NalgebraContext>,
    >(
        &mut self,
        op: &C,
    ) {
        let Some(a) = self.a.as_mut() else {
            self.factorised = false;
            return;
        };
        op.matrix_inplace(a);
        let n_all = a.nrows();
        let mut a = self.a.take();
        if let Some(m) = a.as_mut() {
            self.gather(<Mat as JacobianMatrix>::values(m), n_all);
        }
        self.a = a;
        self.factorised = self.factor();
    }

    fn solve_in_place(&self, x: &mut NalgebraVec<f64>) -> Result<(), LaError> {
        if !self.factorised {
            return Err(LaError::Other(
                "LU of the iteration matrix failed (singular or not finite)".into(),
            ));
        }
        let x = x.host_mut();
        let n = self.n;
        if self.nodes_leading {
            self.solve(&mut x[..n]);
            for &(q, b, m) in &self.m_qn {
                x[q] -= m * x[b];
            }
            return Ok(());
        }
        let mut x_n = self.x_n.borrow_mut();
        x_n.resize(n, 0.0);
        for (v, &i) in x_n.iter_mut().zip(&self.nodes) {
            *v = x[i];
        }
        self.solve(&mut x_n);
        for (v, &i) in x_n.iter().zip(&self.nodes) {
            x[i] = *v;
        }
        for &(q, b, m) in &self.m_qn {
            x[q] -= m * x_n[b];
        }
        Ok(())
    }

    fn solve_transpose_in_place(&self, _x: &mut NalgebraVec<f64>) -> Result<(), LaError> {
        Err(LaError::Other(
            "transpose solves are not supported by the small dense LU".into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_pivoting_system_to_rounding() {
        let n = 7;
        let mut lu = SmallDenseLu {
            n,
            lu: vec![0.0; n * n],
            piv: vec![0; n],
            inv_diag: vec![0.0; n],
            ..SmallDenseLu::default()
        };
        // A zero leading entry forces a row swap; off-diagonals make it non-trivial.
        let a = |i: usize, j: usize| {
            if i == 0 && j == 0 {
                0.0
            } else if i == j {
                3.0 + i as f64
            } else {
                1.0 / (1.0 + (i + 2 * j) as f64)
            }
        };
        for j in 0..n {
            for i in 0..n {
                lu.lu[j * n + i] = a(i, j);
            }
        }
        assert!(lu.factor());
        let x_true: Vec<f64> = (0..n).map(|i| 1.0 + i as f64 * 0.5).collect();
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a(i, j) * x_true[j]).sum())
            .collect();
        lu.solve(&mut b);
        for (x, t) in b.iter().zip(&x_true) {
            assert!((x - t).abs() < 1e-13, "{x} vs {t}");
        }
    }

    #[test]
    fn a_singular_matrix_is_reported_not_solved() {
        let n = 3;
        let mut lu = SmallDenseLu {
            n,
            lu: vec![1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 0.0, 0.0],
            piv: vec![0; n],
            inv_diag: vec![0.0; n],
            ..SmallDenseLu::default()
        };
        assert!(!lu.factor());
    }

    #[test]
    fn quadrature_columns_are_eliminated_exactly() {
        use diffsol::Vector;
        let n = 5;
        // Columns 1 and 3 are unit vectors (quadratures); rows 1 and 3 read the other states.
        let a = |i: usize, j: usize| -> f64 {
            if j == 1 || j == 3 {
                f64::from(u8::from(i == j))
            } else if i == j {
                4.0 + i as f64
            } else {
                0.3 / (1.0 + (i + 2 * j) as f64)
            }
        };
        let mut m = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                m[j * n + i] = a(i, j);
            }
        }
        let mut lu = SmallDenseLu::default();
        lu.gather(&m, n);
        assert_eq!(lu.quads, vec![1, 3]);
        assert_eq!(lu.nodes, vec![0, 2, 4]);
        lu.factorised = lu.factor();
        let x_true: Vec<f64> = (0..n).map(|i| 2.0 - 0.7 * i as f64).collect();
        let mut v = NalgebraVec::<f64>::zeros(n, Default::default());
        for (i, b) in v.host_mut().iter_mut().enumerate() {
            *b = (0..n).map(|j| a(i, j) * x_true[j]).sum();
        }
        lu.solve_in_place(&mut v).unwrap();
        for (x, t) in v.host().iter().zip(&x_true) {
            assert!((x - t).abs() < 1e-13, "{x} vs {t}");
        }
        // A quadrature column that stops being a unit vector is caught at the next gather.
        m[n + 2] = 0.5;
        lu.gather(&m, n);
        assert_eq!(lu.quads, vec![3]);
    }

    /// W = I − γhJ factorised straight from J's entries (repeated positions, node columns
    /// 0, 1, 3 of 6 states, quadrature rows reading them) solves W x = b to rounding, and a new
    /// γh on the same pattern too.
    #[test]
    fn factorising_from_entries_solves_the_iteration_matrix() {
        use diffsol::Vector;
        let n = 6;
        let cols = [0usize, 1, 3];
        // (row, column, value); (1, 1) appears twice and adds up.
        let mut entries = Vec::new();
        for &c in &cols {
            for r in 0..n {
                entries.push((
                    r,
                    c,
                    0.2 + 0.05 * (r + 3 * c) as f64 - if r == c { 1.5 } else { 0.0 },
                ));
            }
        }
        entries.push((1, 1, -0.4));
        let slots: Vec<usize> = entries.iter().map(|&(r, c, _)| c * n + r).collect();
        let vals: Vec<f64> = entries.iter().map(|e| e.2).collect();
        let mut lu = SmallDenseLu::default();
        for gamma_h in [0.3, 2.0] {
            let mut w = vec![0.0; n * n];
            for k in 0..n {
                w[k * n + k] = 1.0;
            }
            for &(r, c, v) in &entries {
                w[c * n + r] -= gamma_h * v;
            }
            assert!(lu.factorise_entries(n, &slots, &vals, gamma_h));
            assert_eq!(lu.nodes, cols);
            let x_true: Vec<f64> = (0..n).map(|i| 1.0 - 0.3 * i as f64).collect();
            let mut v = NalgebraVec::<f64>::zeros(n, Default::default());
            for (i, b) in v.host_mut().iter_mut().enumerate() {
                *b = (0..n).map(|j| w[j * n + i] * x_true[j]).sum();
            }
            lu.solve_in_place(&mut v).unwrap();
            for (x, t) in v.host().iter().zip(&x_true) {
                assert!((x - t).abs() < 1e-13, "γh {gamma_h}: {x} vs {t}");
            }
        }
    }
}
