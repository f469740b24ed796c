//! The compiled [`Scene`] as diffsol equations, with its Jacobian assembled entry by entry
//! instead of from one Jacobian–vector product per column.
//!
//! diffsol's closure equations (`OdeBuilder::rhs_implicit`) build the Jacobian at each linear
//! solver setup from N products J·e_j: O(N × (links + N)) work, and for a sparse matrix it needs
//! a column colouring, which the oil node defeats (every node exchanges heat with the oil, so its
//! row is full and no two columns can share a colour). Here the scene writes its entries directly
//! ([`Scene::jacobian_values`]: the network's analytic partials and the finite-difference oil
//! column, O(links + N)), into a dense nalgebra matrix or into a faer sparse matrix whose pattern
//! is [`Scene::jacobian_pattern`].

use std::cell::RefCell;

use diffsol::{
    ConstantOp, FaerSparseMat, FaerVec, Matrix, MatrixCommon, NalgebraMat, NalgebraVec, NonLinearOp,
    NonLinearOpJacobian, OdeEquations, OdeEquationsRef, Op, ParameterisedOp, UnitCallable, Vector,
    VectorCommon,
};
use faer::sparse::{Pair, SymbolicSparseColMat};

use crate::scene::{Scene, Work};

/// A diffsol vector (one batch, on the host) seen as a slice.
pub trait HostVector: Vector<T = f64> {
    /// The values.
    fn host(&self) -> &[f64];
    /// The values, mutable.
    fn host_mut(&mut self) -> &mut [f64];
}

impl HostVector for NalgebraVec<f64> {
    fn host(&self) -> &[f64] {
        self.inner().as_slice()
    }
    fn host_mut(&mut self) -> &mut [f64] {
        self.inner_mut().as_mut_slice()
    }
}

impl HostVector for FaerVec<f64> {
    fn host(&self) -> &[f64] {
        self.inner().col_as_slice(0)
    }
    fn host_mut(&mut self) -> &mut [f64] {
        self.inner_mut().col_as_slice_mut(0)
    }
}

/// A diffsol matrix type the scene's Jacobian can be written into.
pub trait JacobianMatrix: Matrix<T = f64, V: HostVector> {
    /// The sparsity pattern for the entries `pattern` (None for dense matrices).
    fn sparsity_of(n: usize, pattern: &[(usize, usize)]) -> Option<Self::Sparsity>;
    /// Position in [`Self::values`] of entry (row, col) of `m`.
    fn slot(m: &Self, row: usize, col: usize) -> usize;
    /// The stored values (column-major for dense, CSC order for sparse).
    fn values(&mut self) -> &mut [f64];
}

impl JacobianMatrix for NalgebraMat<f64> {
    fn sparsity_of(_n: usize, _pattern: &[(usize, usize)]) -> Option<Self::Sparsity> {
        None
    }
    fn slot(m: &Self, row: usize, col: usize) -> usize {
        row + col * m.nrows()
    }
    fn values(&mut self) -> &mut [f64] {
        self.inner_mut().as_mut_slice()
    }
}

impl JacobianMatrix for FaerSparseMat<f64> {
    fn sparsity_of(n: usize, pattern: &[(usize, usize)]) -> Option<Self::Sparsity> {
        let mut idx: Vec<Pair<usize, usize>> = pattern.iter().map(|&(r, c)| Pair::new(r, c)).collect();
        // The iteration matrix is I − γhJ: keep the diagonal in the pattern.
        idx.extend((0..n).map(|i| Pair::new(i, i)));
        SymbolicSparseColMat::try_new_from_indices(n, n, &idx)
            .ok()
            .map(|(s, _)| s)
    }
    fn slot(m: &Self, row: usize, col: usize) -> usize {
        let s = m.inner()[0].symbolic();
        let (lo, hi) = (s.col_ptr()[col], s.col_ptr()[col + 1]);
        lo + s.row_idx()[lo..hi].partition_point(|&r| r < row)
    }
    fn values(&mut self) -> &mut [f64] {
        self.inner_mut()[0].val_mut()
    }
}

/// The scene's ODE `dy/dt = f(t, y)`, `y(t0) = y0` as diffsol equations (no mass matrix, no
/// outputs; the controllers' switching functions as roots).
pub struct SceneEquations<'s, M: JacobianMatrix> {
    scene: &'s Scene,
    work: &'s RefCell<Work>,
    y0: Vec<f64>,
    n: usize,
    ctx: M::C,
    sparsity: Option<M::Sparsity>,
    /// Matrix position of each entry of the scene's Jacobian pattern.
    slots: Vec<usize>,
    vals: RefCell<Vec<f64>>,
    /// False: build the Jacobian from one Jacobian–vector product per column, as diffsol's
    /// closures do (only to measure what the assembly saves; dense matrices only).
    pub assembled: bool,
}

impl<'s, M: JacobianMatrix> SceneEquations<'s, M> {
    /// The equations of `scene` from `y0`, evaluated with the work area `work`.
    pub fn new(scene: &'s Scene, work: &'s RefCell<Work>, y0: Vec<f64>) -> Self {
        let ctx = M::C::default();
        let n = scene.n_states();
        let pattern = scene.jacobian_pattern();
        let sparsity = M::sparsity_of(n, &pattern);
        let probe = M::new_from_sparsity(n, n, sparsity.clone(), ctx.clone());
        let slots = pattern.iter().map(|&(r, c)| M::slot(&probe, r, c)).collect();
        Self {
            scene,
            work,
            y0,
            n,
            ctx,
            sparsity,
            slots,
            vals: RefCell::new(vec![0.0; pattern.len()]),
            assembled: true,
        }
    }

    /// The sparsity of the Jacobian and iteration matrices (None for dense matrices).
    pub fn matrix_sparsity(&self) -> Option<M::Sparsity> {
        self.sparsity.clone()
    }

    /// The Jacobian at (t, x) into `m`, with the losses' share of the oil column from the slopes
    /// `dq_dt` (∂q_k/∂T_oil, W/K; [`Scene::jacobian_values_with_slopes`]).
    pub fn jacobian_with_slopes(&self, x: &M::V, t: f64, dq_dt: &[f64], m: &mut M) {
        let mut vals = self.vals.borrow_mut();
        self.scene
            .jacobian_values_with_slopes(t, x.host(), &mut self.work.borrow_mut(), dq_dt, &mut vals);
        let mv = m.values();
        mv.iter_mut().for_each(|v| *v = 0.0);
        for (&s, &v) in self.slots.iter().zip(vals.iter()) {
            mv[s] += v;
        }
    }

    /// The Jacobian at (t, x) as entries, with the losses' share of the oil column from the slopes
    /// `dq_dt`: calls `f(slots, values)` with each entry's position in the matrix (repeated
    /// positions add up) and its value, for solvers that read J without a matrix.
    pub fn with_jacobian_entries<R>(
        &self,
        x: &M::V,
        t: f64,
        dq_dt: &[f64],
        f: impl FnOnce(&[usize], &[f64]) -> R,
    ) -> R {
        let mut vals = self.vals.borrow_mut();
        self.scene
            .jacobian_values_with_slopes(t, x.host(), &mut self.work.borrow_mut(), dq_dt, &mut vals);
        f(&self.slots, &vals)
    }

    /// Number of Jacobian entries written per evaluation (repeats included).
    pub fn entries(&self) -> usize {
        self.slots.len()
    }
}

macro_rules! impl_op {
    ($t:ident) => {
        impl<M: JacobianMatrix> Op for $t<'_, '_, M> {
            type T = f64;
            type V = M::V;
            type M = M;
            type C = M::C;
            fn context(&self) -> &Self::C {
                &self.0.ctx
            }
            fn nstates(&self) -> usize {
                self.0.n
            }
            fn nout(&self) -> usize {
                self.0.n
            }
            fn nparams(&self) -> usize {
                0
            }
        }
    };
}

impl<M: JacobianMatrix> Op for SceneEquations<'_, M> {
    type T = f64;
    type V = M::V;
    type M = M;
    type C = M::C;
    fn context(&self) -> &Self::C {
        &self.ctx
    }
    fn nstates(&self) -> usize {
        self.n
    }
    fn nout(&self) -> usize {
        self.n
    }
    fn nparams(&self) -> usize {
        0
    }
}

/// The right-hand side operator.
pub struct SceneRhs<'a, 's, M: JacobianMatrix>(&'a SceneEquations<'s, M>);
/// The initial state.
pub struct SceneInit<'a, 's, M: JacobianMatrix>(&'a SceneEquations<'s, M>);
impl_op!(SceneRhs);
impl_op!(SceneInit);

/// The controllers' switching functions (diffsol's root function): one root per function
/// turning positive ([`Scene::switching_functions`]).
pub struct SceneRoot<'a, 's, M: JacobianMatrix>(&'a SceneEquations<'s, M>);

impl<M: JacobianMatrix> Op for SceneRoot<'_, '_, M> {
    type T = f64;
    type V = M::V;
    type M = M;
    type C = M::C;
    fn context(&self) -> &Self::C {
        &self.0.ctx
    }
    fn nstates(&self) -> usize {
        self.0.n
    }
    fn nout(&self) -> usize {
        self.0.scene.switching_count()
    }
    fn nparams(&self) -> usize {
        0
    }
}

impl<M: JacobianMatrix> NonLinearOp for SceneRoot<'_, '_, M> {
    fn call_inplace(&self, x: &M::V, t: f64, y: &mut M::V) {
        let e = self.0;
        e.scene
            .switching_functions_at(t, x.host(), &e.work.borrow(), y.host_mut());
    }
}

impl<M: JacobianMatrix> ConstantOp for SceneInit<'_, '_, M> {
    fn call_inplace(&self, _t: f64, y: &mut M::V) {
        y.host_mut().copy_from_slice(&self.0.y0);
    }
}

impl<M: JacobianMatrix> NonLinearOp for SceneRhs<'_, '_, M> {
    fn call_inplace(&self, x: &M::V, t: f64, y: &mut M::V) {
        let e = self.0;
        e.scene.rhs(t, x.host(), &mut e.work.borrow_mut(), y.host_mut());
    }
}

impl<M: JacobianMatrix> NonLinearOpJacobian for SceneRhs<'_, '_, M> {
    fn jac_mul_inplace(&self, x: &M::V, t: f64, v: &M::V, y: &mut M::V) {
        let e = self.0;
        e.scene
            .jvp(t, x.host(), v.host(), &mut e.work.borrow_mut(), y.host_mut());
    }

    fn jacobian_sparsity(&self) -> Option<M::Sparsity> {
        self.0.sparsity.clone()
    }

    fn jacobian_inplace(&self, x: &M::V, t: f64, y: &mut M) {
        let e = self.0;
        if !e.assembled && e.sparsity.is_none() {
            self._default_jacobian_inplace(x, t, y);
            return;
        }
        let mut vals = e.vals.borrow_mut();
        e.scene
            .jacobian_values(t, x.host(), &mut e.work.borrow_mut(), &mut vals);
        let m = y.values();
        m.iter_mut().for_each(|v| *v = 0.0);
        for (&s, &v) in e.slots.iter().zip(vals.iter()) {
            m[s] += v;
        }
    }
}

type Unit<'a, M> = ParameterisedOp<'a, UnitCallable<M>>;

impl<'a, M: JacobianMatrix> OdeEquationsRef<'a> for SceneEquations<'_, M> {
    type Rhs = SceneRhs<'a, 'a, M>;
    type Mass = Unit<'a, M>;
    type Init = SceneInit<'a, 'a, M>;
    type Out = Unit<'a, M>;
    type Root = SceneRoot<'a, 'a, M>;
    type Reset = Unit<'a, M>;
}

impl<M: JacobianMatrix> OdeEquations for SceneEquations<'_, M> {
    fn rhs(&self) -> SceneRhs<'_, '_, M> {
        SceneRhs(self)
    }
    fn mass(&self) -> Option<Unit<'_, M>> {
        None
    }
    fn init(&self) -> SceneInit<'_, '_, M> {
        SceneInit(self)
    }
    fn root(&self) -> Option<SceneRoot<'_, '_, M>> {
        (self.scene.switching_count() > 0).then_some(SceneRoot(self))
    }
    fn set_params(&mut self, _p: &M::V) {}
    fn get_params(&self, _p: &mut M::V) {}
}
