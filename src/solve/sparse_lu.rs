//! Sparse LU of the Newton iteration matrix `M = I − γhJ` of a large network, exploiting its
//! structure instead of handing it whole to a general sparse LU.
//!
//! Two kinds of rows would fill a general sparse factorisation in (measured with diffsol's
//! `FaerSparseLU` on the AT6 with a 1000-patch wall: 9.5 ms per step, its factors practically
//! dense, the triangular solves on dense supernodes dominating):
//!
//! - the **quadratures** (loss energies, heat into boundaries): their columns of J are zero, so
//!   their columns of M are unit vectors, but the boundary-heat row holds every patch that
//!   touches the air; a row-pivoting LU bounds its factors by the Cholesky factor of MᵀM, which
//!   one such row makes dense;
//! - **hub nodes** (the oil node: it exchanges heat with every wetted patch, body and loss
//!   destination, and through ν(T_oil) its column touches every node): a dense row and column.
//!
//! So the states are split into quadratures Q (column of M = its diagonal), hubs B (row or column
//! with more than `max(16, 10 √n)` entries, the dense-row threshold of SuiteSparse's COLAMD,
//! Davis et al., ACM TOMS 30(3), 2004) and the rest S, and
//!
//! ```text
//!     | A_SS  A_SB  0 |            y   = A_SS⁻¹ b_S,  W = A_SS⁻¹ A_SB (at factorisation)
//! M = | A_BS  A_BB  0 |    solve:  x_B = (A_BB − A_BS W)⁻¹ (b_B − A_BS y)   (Schur complement)
//!     | C_S   C_B   I |            x_S = y − W x_B,   x_Q = b_Q − C x
//! ```
//!
//! with faer's sparse LU (COLAMD ordering, symbolic factorisation once per solve) for A_SS, whose
//! pattern is the wall's 2-D grid and the bodies, and a dense LU for the few-by-few Schur
//! complement (Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed., §14.2, block
//! elimination).

use std::cell::RefCell;

use diffsol::{FaerContext, FaerSparseMat, FaerVec, Matrix, MatrixCommon, Vector};
use diffsol_la::{LaError, LinearOp, LinearSolver};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par};

/// Row/column count above which a non-quadrature state is a hub.
pub fn hub_threshold(n: usize) -> usize {
    16usize.max((10.0 * (n as f64).sqrt()) as usize)
}

#[derive(Clone, Copy)]
enum Kind {
    Q,
    B(usize),
    S(usize),
}

/// Where each stored entry of M goes.
#[derive(Default)]
struct Scatter {
    /// (position in M, position in A_SS's values).
    ss: Vec<(usize, usize)>,
    /// (position in M, local S row, local B column).
    sb: Vec<(usize, usize, usize)>,
    /// (position in M, local B row, local S column).
    bs: Vec<(usize, usize, usize)>,
    /// (position in M, local B row, local B column).
    bb: Vec<(usize, usize, usize)>,
    /// (position in M, quadrature row (global), column (global)), off the diagonal.
    c: Vec<(usize, usize, usize)>,
}

struct Factors {
    /// The last numeric factorisation succeeded.
    factorised: bool,
    m: FaerSparseMat<f64>,
    s_index: Vec<usize>,
    b_index: Vec<usize>,
    scatter: Scatter,
    ass: SparseColMat<usize, f64>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factor_scratch: MemBuffer,
    solve_scratch: RefCell<MemBuffer>,
    /// A_BS entries of the last linearisation: (local B row, local S column, value).
    bs_vals: Vec<(usize, usize, f64)>,
    /// C entries: (row, column, value), global indices.
    c_vals: Vec<(usize, usize, f64)>,
    /// W = A_SS⁻¹ A_SB, column-major n_S × n_B.
    w: Vec<f64>,
    /// LU of the Schur complement (n_B × n_B).
    schur: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    /// Scratch: y (n_S), r (n_B).
    y: RefCell<(Vec<f64>, nalgebra::DVector<f64>)>,
}

/// Block-eliminating sparse LU (quadratures, hub nodes, faer sparse LU for the rest); one batch.
#[derive(Default)]
pub struct NetworkSparseLu {
    f: Option<Factors>,
}

impl NetworkSparseLu {
    /// (rest, hubs, quadratures) the last `set_sparsity` found.
    pub fn split(&self) -> Option<(usize, usize, usize)> {
        self.f.as_ref().map(|f| {
            let n = f.m.nrows();
            (
                f.s_index.len(),
                f.b_index.len(),
                n - f.s_index.len() - f.b_index.len(),
            )
        })
    }
}

fn classify(sym: &SymbolicSparseColMat<usize>) -> (Vec<Kind>, Vec<usize>, Vec<usize>) {
    let n = sym.ncols();
    let (cp, ri) = (sym.col_ptr(), sym.row_idx());
    let is_q: Vec<bool> = (0..n)
        .map(|j| ri[cp[j]..cp[j + 1]].iter().all(|&r| r == j))
        .collect();
    let (mut rows, mut cols) = (vec![0usize; n], vec![0usize; n]);
    for j in (0..n).filter(|&j| !is_q[j]) {
        for &r in &ri[cp[j]..cp[j + 1]] {
            if !is_q[r] {
                rows[r] += 1;
                cols[j] += 1;
            }
        }
    }
    let nodes = is_q.iter().filter(|q| !**q).count();
    let th = hub_threshold(nodes);
    let mut hub: Vec<bool> = (0..n)
        .map(|i| !is_q[i] && (rows[i] > th || cols[i] > th))
        .collect();
    if hub.iter().filter(|h| **h).count() >= nodes {
        hub.iter_mut().for_each(|h| *h = false);
    }
    let (mut kind, mut s_index, mut b_index) = (Vec::with_capacity(n), Vec::new(), Vec::new());
    for i in 0..n {
        kind.push(if is_q[i] {
            Kind::Q
        } else if hub[i] {
            b_index.push(i);
            Kind::B(b_index.len() - 1)
        } else {
            s_index.push(i);
            Kind::S(s_index.len() - 1)
        });
    }
    (kind, s_index, b_index)
}

impl LinearSolver<FaerSparseMat<f64>> for NetworkSparseLu {
    fn set_sparsity<C: LinearOp<T = f64, V = FaerVec<f64>, M = FaerSparseMat<f64>, C = FaerContext>>(
        &mut self,
        op: &C,
    ) {
        let n = op.ncols();
        let m = FaerSparseMat::<f64>::new_from_sparsity(op.nrows(), n, op.sparsity(), *op.context());
        let sym = m.inner()[0]
            .symbolic()
            .to_owned()
            .expect("pattern of the iteration matrix");
        let (kind, s_index, b_index) = classify(&sym);
        let (cp, ri) = (sym.col_ptr(), sym.row_idx());
        let mut sc = Scatter::default();
        // A_SS in CSC: local maps are increasing, so the entries arrive in order.
        let mut ss_cp = vec![0usize; s_index.len() + 1];
        let mut ss_ri = Vec::new();
        for j in 0..n {
            for (p, &r) in ri.iter().enumerate().take(cp[j + 1]).skip(cp[j]) {
                match (kind[r], kind[j]) {
                    (Kind::S(a), Kind::S(_)) => {
                        sc.ss.push((p, ss_ri.len()));
                        ss_ri.push(a);
                    }
                    (Kind::S(a), Kind::B(b)) => sc.sb.push((p, a, b)),
                    (Kind::B(a), Kind::S(b)) => sc.bs.push((p, a, b)),
                    (Kind::B(a), Kind::B(b)) => sc.bb.push((p, a, b)),
                    (Kind::Q, Kind::Q) => {}
                    (Kind::Q, _) => sc.c.push((p, r, j)),
                    (_, Kind::Q) => unreachable!("a quadrature column holds only its diagonal"),
                }
            }
            if let Kind::S(b) = kind[j] {
                ss_cp[b + 1] = ss_ri.len();
            }
        }
        let ns = s_index.len();
        let ss_sym = SymbolicSparseColMat::new_checked(ns, ns, ss_cp, None, ss_ri);
        let nnz = ss_sym.row_idx().len();
        let symbolic = factorize_symbolic_lu(ss_sym.as_ref(), lu_params(ns)).expect("symbolic LU");
        let factor_scratch =
            MemBuffer::new(symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()));
        let solve_scratch = RefCell::new(MemBuffer::new(
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ));
        let nb = b_index.len();
        self.f = Some(Factors {
            m,
            ass: SparseColMat::new(ss_sym, vec![0.0; nnz]),
            symbolic,
            numeric: NumericLu::new(),
            factor_scratch,
            solve_scratch,
            bs_vals: Vec::with_capacity(sc.bs.len()),
            c_vals: Vec::with_capacity(sc.c.len()),
            w: vec![0.0; ns * nb],
            schur: None,
            y: RefCell::new((vec![0.0; ns], nalgebra::DVector::zeros(nb))),
            scatter: sc,
            s_index,
            b_index,
            factorised: false,
        });
    }

    fn set_linearisation<C: LinearOp<T = f64, V = FaerVec<f64>, M = FaerSparseMat<f64>, C = FaerContext>>(
        &mut self,
        op: &C,
    ) {
        let f = self.f.as_mut().expect("set_sparsity before set_linearisation");
        op.matrix_inplace(&mut f.m);
        let mv = f.m.inner()[0].val();
        let sc = &f.scatter;
        {
            let av = f.ass.val_mut();
            for &(p, q) in &sc.ss {
                av[q] = mv[p];
            }
        }
        // A singular or non-finite iteration matrix (a Newton trial off the physical range) is
        // not a panic: the next solve reports it and diffsol cuts the step, as with its own LUs.
        f.factorised = f
            .symbolic
            .factorize_numeric_lu(
                &mut f.numeric,
                f.ass.as_ref(),
                Par::Seq,
                MemStack::new(&mut f.factor_scratch),
                Default::default(),
            )
            .is_ok();
        if !f.factorised {
            f.schur = None;
            return;
        }
        let (ns, nb) = (f.s_index.len(), f.b_index.len());
        f.bs_vals.clear();
        f.bs_vals.extend(sc.bs.iter().map(|&(p, a, b)| (a, b, mv[p])));
        f.c_vals.clear();
        f.c_vals.extend(sc.c.iter().map(|&(p, r, j)| (r, j, mv[p])));
        if nb == 0 {
            return;
        }
        f.w.iter_mut().for_each(|x| *x = 0.0);
        for &(p, a, b) in &sc.sb {
            f.w[b * ns + a] = mv[p];
        }
        let lu = LuRef::new_unchecked(&f.symbolic, &f.numeric);
        let mut scratch = f.solve_scratch.borrow_mut();
        for b in 0..nb {
            let col = MatMut::from_column_major_slice_mut(&mut f.w[b * ns..(b + 1) * ns], ns, 1);
            lu.solve_in_place_with_conj(Conj::No, col, Par::Seq, MemStack::new(&mut scratch));
        }
        let mut s = nalgebra::DMatrix::<f64>::zeros(nb, nb);
        for &(p, a, b) in &sc.bb {
            s[(a, b)] += mv[p];
        }
        for &(a, j, v) in &f.bs_vals {
            for b in 0..nb {
                s[(a, b)] -= v * f.w[b * ns + j];
            }
        }
        f.schur = Some(s.lu());
    }

    fn solve_in_place(&self, x: &mut FaerVec<f64>) -> Result<(), LaError> {
        let f = self
            .f
            .as_ref()
            .ok_or_else(|| LaError::Other("sparse LU used before its factorisation".into()))?;
        if !f.factorised {
            return Err(LaError::Other(
                "numeric LU of the iteration matrix failed (singular or not finite)".into(),
            ));
        }
        let xs = x.inner_mut().col_as_slice_mut(0);
        let ns = f.s_index.len();
        let mut guard = f.y.borrow_mut();
        let (y, r) = &mut *guard;
        for (yk, &i) in y.iter_mut().zip(&f.s_index) {
            *yk = xs[i];
        }
        let lu = LuRef::new_unchecked(&f.symbolic, &f.numeric);
        {
            let mut scratch = f.solve_scratch.borrow_mut();
            let col = MatMut::from_column_major_slice_mut(&mut y[..], ns, 1);
            lu.solve_in_place_with_conj(Conj::No, col, Par::Seq, MemStack::new(&mut scratch));
        }
        if let Some(schur) = &f.schur {
            for (rb, &i) in r.iter_mut().zip(&f.b_index) {
                *rb = xs[i];
            }
            for &(a, j, v) in &f.bs_vals {
                r[a] -= v * y[j];
            }
            if !schur.solve_mut(r) {
                return Err(LaError::Other(
                    "singular Schur complement of the hub nodes".into(),
                ));
            }
            for (b, &i) in f.b_index.iter().enumerate() {
                xs[i] = r[b];
                let w = &f.w[b * ns..(b + 1) * ns];
                for (yk, wk) in y.iter_mut().zip(w) {
                    *yk -= wk * r[b];
                }
            }
        }
        for (yk, &i) in y.iter().zip(&f.s_index) {
            xs[i] = *yk;
        }
        for &(q, j, v) in &f.c_vals {
            xs[q] -= v * xs[j];
        }
        Ok(())
    }

    fn solve_transpose_in_place(&self, _x: &mut FaerVec<f64>) -> Result<(), LaError> {
        Err(LaError::Other(
            "transpose solves (adjoint sensitivities) are not supported by the network LU".into(),
        ))
    }
}

/// Rest-block size from which faer's supernodal numeric LU is used instead of its simplicial one.
/// faer's own flop-ratio choice picked simplicial for the 1000-patch AT6 wall; measured over the
/// WLTC (TR-BDF2, CPU time of two runs each, docs/performance.md "Large networks"): 513 states
/// simplicial 0.39–0.41 s vs supernodal 0.43–0.47 s; 1013 states simplicial 0.94–0.99 s vs
/// supernodal 0.77–0.81 s.
pub const SUPERNODAL_FROM: usize = 750;

/// Symbolic LU parameters for a rest block of `n` states.
fn lu_params(n: usize) -> LuSymbolicParams<'static> {
    LuSymbolicParams {
        supernodal_flop_ratio_threshold: if n >= SUPERNODAL_FROM {
            SupernodalThreshold::FORCE_SUPERNODAL
        } else {
            SupernodalThreshold::FORCE_SIMPLICIAL
        },
        ..LuSymbolicParams::default()
    }
}
