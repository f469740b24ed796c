//! Forward sensitivities of a transient: the node temperatures T(t) of a [`Scene`] over its input
//! segments and their derivatives S_j = ∂T/∂θ_j with respect to parameters θ_j, integrated by
//! the tangent linear of ROS3 ([`super::rosenbrock::ROS3`], the same tableau and step-size
//! controller).
//!
//! A ROS3 step (transformed form, W = I − γhJ, stage K_i, Hairer & Wanner IV.7):
//!
//! ```text
//! W K_i = γh·f(t + α_i h, y + Σ_j a_ij K_j) + Σ_j γ c_ij K_j + γ γ_i h²·∂f/∂t,
//! y⁺ = y + Σ m_i K_i.
//! ```
//!
//! Differentiating every stage along a parameter θ_j with S = ∂y/∂θ_j (h held fixed: the step
//! sizes are those the error control chose), with dW = −γh·dJ:
//!
//! ```text
//! W dK_i = γh·(df_i + dJ·K_i) + Σ_j γ c_ij dK_j + γ γ_i h²·d(∂f/∂t),
//! S⁺ = S + Σ m_i dK_i,
//! ```
//!
//! where df_i is the derivative of f at stage i along (dY_i, e_j), dY_i = S + Σ a_ij dK_j, and
//! dJ·K_i the derivative of J along (S, e_j) applied to K_i: the second
//! derivatives that make S the exact derivative of the discrete solution (without dJ·K_i the
//! sensitivities would follow a method of lower order). Each of these directional derivatives is
//! a central difference along the combined direction (state δ·S, parameter ±δ): the right-hand
//! side of the scene compiled at θ_j + δ_j evaluated at y + δ_j·S against the scene at θ_j − δ_j
//! at y − δ_j·S (for dJ, the two scenes' Jacobians at those states). A parameter that enters f
//! linearly (a conductance, a loss multiplier) is
//! differenced exactly up to rounding; one that enters smoothly (a capacity through 1/C) with an
//! error O(δ²). The linear systems reuse the nominal step's LU of W.
//!
//! The state integrated is the node temperatures alone: the loss and boundary energies of the
//! scene's state are quadratures that no node row depends on, so leaving them out changes neither
//! the node stages nor their derivatives (the error test then weighs the nodes only).
//!
//! Error control covers the tangents as well as the temperatures, as the tangent linear ROS
//! integrator of FATODE does (`TLM/ROS_TLM/ROS_TLM_f90_Integrator.F90`, `ICNTRL(12) = 1`: the
//! error is the largest of the state's and each tangent's weighted RMS estimate Σ e_i dK_i, each
//! with its own tolerances). Here node i of tangent j is weighed by
//! atol + rtol·max(|T_i|, |T_i⁺|) + [`TANGENT_RTOL`]·max(|S_ij|, |S_ij⁺|): the temperatures'
//! weight (S in K per unit of θ_j: a factor e for a parameter fitted in ln p, 1 K for a
//! temperature) and a tenth of the tangent itself.
//!
//! Why: S is the exact derivative of the discrete step map, and that derivative carries
//! γh·dJ·K_i, a term of the method (it vanishes with h) that the variational equation
//! S' = J S + ∂f/∂θ does not have. Where J changes fast with the state within a step — a node
//! at the edge of a thermostat's band, where the smoothstep's second derivative jumps from 0 to
//! 6/w² — it makes the discrete map expand although the temperatures' estimate passes: on the
//! MM82 inlet node at its cooler's `open_c` (rtol 10⁻⁴, `tests/calibrate_sensitivity_finite.rs`)
//! steps of 32–49 s whose temperature estimates are 0.27–1.0 carry tangent estimates of
//! 180–20 000 times the temperatures' weight, and the tangents grow 3–4× per step, to NaN
//! within the hour. The relative part keeps the test away from ordinary steps: over every run of
//! the `sensitivity*` and `calibrate*` tests the tangent's estimate stays below 6 % of the
//! tangent on 99.9 % of the steps (at most 12 steps of a test above 5 %; where S starts from 0
//! the absolute part governs), while on the expanding steps it is 20–150 %. With the
//! temperatures' weight alone, steps near t = 1280 s of `tests/sensitivity.rs`'s trace on
//! `models/pt6_spur_pair.toml` are cut from 8 s to 0.09 s and that test's replayed difference
//! check then fails (3.5·10⁻⁵ against its 10⁻⁵).
//!
//! [`integrate_fixed`] replays a given step sequence without error control: the same discrete
//! solution as a function of the parameters, so that its central differences check the
//! sensitivities to the differencing error only (`tests/sensitivity.rs`).
//!
//! Controllers that switch (`[[thermal.controls]]`): a step that crosses a switching surface is
//! cut at the switch (located as in [`super::rosenbrock`]), the controller switches there, and
//! the sensitivities jump by the saltation term ([`events`]); the thermostats' band edges are
//! not located here (f is continuous across them: no jump).

mod events;

use nalgebra::{DMatrix, DVector};

use super::rosenbrock::ROS3;
use super::transient::{NumericalFailure, Segment};
use crate::scene::{Scene, Work};

/// Step-size controller of [`super::rosenbrock`] (Hairer & Wanner II, IV.8): safety factor and
/// bounds per step, the same values.
const SAFETY: f64 = 0.9;
const GROW_MAX: f64 = 5.0;
const SHRINK_MIN: f64 = 0.2;

/// Relative part of the tangents' error weights (module doc): a step is refused when a
/// tangent's estimated local error exceeds this fraction of the tangent (beyond the
/// temperatures' own tolerance).
const TANGENT_RTOL: f64 = 0.1;

/// One parameter direction: the scene compiled at θ + δ and at θ − δ, and δ.
pub struct Direction<'s> {
    /// Scene at θ_j + δ_j.
    pub plus: &'s Scene,
    /// Scene at θ_j − δ_j.
    pub minus: &'s Scene,
    /// δ_j (in the parameter's own coordinate, e.g. ln p).
    pub delta: f64,
}

/// Tolerances and budget of a sensitivity run.
#[derive(Debug, Clone)]
pub struct SensitivityOptions {
    /// Relative tolerance of the error test on the node temperatures.
    pub rtol: f64,
    /// Absolute tolerance, K.
    pub atol: f64,
    /// Step budget (accepted and rejected).
    pub max_steps: usize,
    /// Initial node temperatures, K (None: the scene's).
    pub initial: Option<Vec<f64>>,
}

/// Node temperatures and their sensitivities at every segment boundary.
#[derive(Debug, Clone)]
pub struct SensitivityTrajectory {
    /// Output times, s (the segment boundaries, the first segment's start first).
    pub times: Vec<f64>,
    /// Node temperatures at each time, K: `temps[row][node]`.
    pub temps: Vec<Vec<f64>>,
    /// ∂T/∂θ at each time, K per unit θ: `sens[row][node * P + j]`.
    pub sens: Vec<Vec<f64>>,
    /// The accepted step sizes, s, in order (for [`integrate_fixed`]).
    pub steps: Vec<f64>,
    /// Rejected steps.
    pub rejected: usize,
}

impl SensitivityTrajectory {
    /// ∂T_node/∂θ_j at output row `row`.
    pub fn sens_at(&self, row: usize, node: usize, j: usize, p: usize) -> f64 {
        self.sens[row][node * p + j]
    }
}

/// A scene with its work area and full-length state buffers (nodes, then zero energies).
struct Eval<'s> {
    scene: &'s Scene,
    work: Work,
    y: Vec<f64>,
    dy: Vec<f64>,
}

impl<'s> Eval<'s> {
    fn new(scene: &'s Scene, seg: &Segment) -> Self {
        let ns = scene.n_states();
        Eval {
            scene,
            work: scene.work(seg.inputs),
            y: vec![0.0; ns],
            dy: vec![0.0; ns],
        }
    }

    /// Set the node part of the state to `x + s·d`.
    fn set_state(&mut self, x: &[f64], s: f64, d: &[f64]) {
        for ((y, a), b) in self.y.iter_mut().zip(x).zip(d) {
            *y = a + s * b;
        }
    }

    /// f at (t, state) into `self.dy` (node rows used).
    fn rhs(&mut self, t: f64) {
        self.scene.rhs(t, &self.y, &mut self.work, &mut self.dy);
    }

    /// ∂f/∂t at (t, state) into `self.dy`.
    fn time_derivative(&mut self, t: f64) {
        self.scene
            .time_derivative(t, &self.y, &mut self.work, &mut self.dy);
    }
}

/// The nominal scene's Jacobian node block, from its entry pattern.
struct NodeJacobian {
    pattern: Vec<(usize, usize)>,
    vals: Vec<f64>,
}

impl NodeJacobian {
    fn new(scene: &Scene) -> Self {
        let pattern = scene.jacobian_pattern();
        let vals = vec![0.0; pattern.len()];
        NodeJacobian { pattern, vals }
    }

    /// The node block of J at the evaluator's state (its right-hand side just evaluated there,
    /// so that the oil column starts from that heat balance).
    fn matrix(&mut self, e: &mut Eval<'_>, t: f64, n: usize) -> DMatrix<f64> {
        e.scene.jacobian_values(t, &e.y, &mut e.work, &mut self.vals);
        let mut j = DMatrix::<f64>::zeros(n, n);
        for (&(r, c), v) in self.pattern.iter().zip(&self.vals) {
            if r < n && c < n {
                j[(r, c)] += v;
            }
        }
        j
    }

    /// W = I − γh·J at the evaluator's state.
    fn iteration_matrix(&mut self, e: &mut Eval<'_>, t: f64, gamma_h: f64, n: usize) -> DMatrix<f64> {
        let j = self.matrix(e, t, n);
        DMatrix::<f64>::identity(n, n) - j * gamma_h
    }
}

/// What an accepted step leaves for its tangent: the stages, the step, ∂f/∂t switched on.
struct StepStages {
    k: [DVector<f64>; 3],
    h: f64,
    ft_on: bool,
}

type Lu = nalgebra::linalg::LU<f64, nalgebra::Dyn, nalgebra::Dyn>;

/// The integrator over the nominal scene and the parameter directions.
struct Tangent<'s> {
    nominal: Eval<'s>,
    plus: Vec<Eval<'s>>,
    minus: Vec<Eval<'s>>,
    delta: Vec<f64>,
    jac: NodeJacobian,
    /// Jacobian patterns of the scenes at θ ± δ.
    jac_plus: Vec<NodeJacobian>,
    jac_minus: Vec<NodeJacobian>,
    n: usize,
    /// Node temperatures, K.
    y: DVector<f64>,
    /// Sensitivities, n × P.
    s: DMatrix<f64>,
    /// LU of W of the last step.
    lu: Option<Lu>,
    /// The controllers' switching functions and their event bookkeeping.
    ev: events::EventScratch,
}

impl<'s> Tangent<'s> {
    fn new(scene: &'s Scene, dirs: &[Direction<'s>], seg: &Segment, initial: Option<&[f64]>) -> Self {
        let n = scene.nodes();
        let y0: Vec<f64> = match initial {
            Some(v) => v.to_vec(),
            None => scene.initial_state(None)[..n].to_vec(),
        };
        // S(0) = ∂T(0)/∂θ: non-zero for a parameter that sets an initial temperature.
        let mut s = DMatrix::<f64>::zeros(n, dirs.len());
        if initial.is_none() {
            for (j, d) in dirs.iter().enumerate() {
                let (a, b) = (d.plus.initial_state(None), d.minus.initial_state(None));
                for i in 0..n {
                    s[(i, j)] = (a[i] - b[i]) / (2.0 * d.delta);
                }
            }
        }
        let mut t = Tangent {
            nominal: Eval::new(scene, seg),
            plus: dirs.iter().map(|d| Eval::new(d.plus, seg)).collect(),
            minus: dirs.iter().map(|d| Eval::new(d.minus, seg)).collect(),
            delta: dirs.iter().map(|d| d.delta).collect(),
            jac: NodeJacobian::new(scene),
            jac_plus: dirs.iter().map(|d| NodeJacobian::new(d.plus)).collect(),
            jac_minus: dirs.iter().map(|d| NodeJacobian::new(d.minus)).collect(),
            n,
            y: DVector::from_vec(y0),
            s,
            lu: None,
            ev: events::EventScratch::new(scene),
        };
        t.start_modes();
        t
    }

    fn switch_inputs(&mut self, seg: &Segment) {
        for e in std::iter::once(&mut self.nominal)
            .chain(self.plus.iter_mut())
            .chain(self.minus.iter_mut())
        {
            e.scene.set_inputs(seg.inputs, &mut e.work);
        }
    }

    fn nominal_f(&mut self, t: f64, x: &DVector<f64>) -> DVector<f64> {
        let n = self.n;
        self.nominal.set_state(x.as_slice(), 0.0, x.as_slice());
        self.nominal.rhs(t);
        DVector::from_column_slice(&self.nominal.dy[..n])
    }

    /// One ROS3 step of size h from (t, y): the stages and the weighted RMS error estimate
    /// (infinite when W is singular or a value is not finite).
    fn step(&mut self, t: f64, h: f64, rtol: f64, atol: f64) -> (StepStages, f64) {
        let (n, tab) = (self.n, &ROS3);
        let gh = tab.gamma * h;
        let y = self.y.clone();
        let f1 = self.nominal_f(t, &y);
        let w = self.jac.iteration_matrix(&mut self.nominal, t, gh, n);
        let thermal = self.nominal.scene.thermal();
        let ft_on = thermal.boundaries_move() && !thermal.boundaries_still_at(t);
        let ft = if ft_on {
            self.nominal.time_derivative(t);
            DVector::from_column_slice(&self.nominal.dy[..n])
        } else {
            DVector::zeros(n)
        };
        let zero = DVector::<f64>::zeros(n);
        let lu = w.lu();
        if !lu.is_invertible() {
            let k = [zero.clone(), zero.clone(), zero];
            return (StepStages { k, h, ft_on }, f64::INFINITY);
        }
        let g = |i: usize| gh * tab.gamma_sum[i] * h;
        let c = |i: usize, j: usize| tab.c[i][j] * tab.gamma;
        let solve = |b: DVector<f64>| lu.solve(&b).unwrap_or_else(|| DVector::from_element(n, f64::NAN));
        let k1 = solve(&f1 * gh + &ft * g(0));
        let f2 = self.nominal_f(t + tab.alpha[1] * h, &(&y + &k1));
        let k2 = solve(&f2 * gh + &k1 * c(1, 0) + &ft * g(1));
        let k3 = solve(&f2 * gh + &k1 * c(2, 0) + &k2 * c(2, 1) + &ft * g(2));
        let mut sum = 0.0;
        for i in 0..n {
            let y1 = y[i] + tab.m[0] * k1[i] + tab.m[1] * k2[i] + tab.m[2] * k3[i];
            let err = tab.e[0] * k1[i] + tab.e[1] * k2[i] + tab.e[2] * k3[i];
            let r = err / (atol + rtol * y[i].abs().max(y1.abs()));
            sum += r * r;
        }
        let err = (sum / n as f64).sqrt();
        self.lu = Some(lu);
        let err = if err.is_finite() { err } else { f64::INFINITY };
        (
            StepStages {
                k: [k1, k2, k3],
                h,
                ft_on,
            },
            err,
        )
    }

    /// Accept the step: y⁺ = y + Σ m_i K_i, and the tangent S⁺ of every parameter (from the
    /// stage derivatives `dk` when the error test computed them for this step).
    fn accept(&mut self, t: f64, st: &StepStages, dk: Option<Vec<[DVector<f64>; 3]>>) {
        let tab = &ROS3;
        let dk = dk.unwrap_or_else(|| self.tangents(t, st));
        for (j, d) in dk.iter().enumerate() {
            let mut col = self.s.column_mut(j);
            col += &d[0] * tab.m[0] + &d[1] * tab.m[1] + &d[2] * tab.m[2];
        }
        let k = &st.k;
        self.y += &k[0] * tab.m[0] + &k[1] * tab.m[1] + &k[2] * tab.m[2];
    }

    /// The stage derivatives of every parameter over the step from t.
    fn tangents(&mut self, t: f64, st: &StepStages) -> Vec<[DVector<f64>; 3]> {
        (0..self.delta.len())
            .map(|j| self.tangent_stages(t, st, j))
            .collect()
    }

    /// The largest over the parameters of the tangent's weighted RMS error estimate
    /// Σ e_i dK_i. Node i of parameter j is weighed by atol + rtol·max(|T_i|, |T_i⁺|) (the
    /// temperatures' own weight: S counted in K per unit of the parameter's coordinate) plus
    /// [`TANGENT_RTOL`]·max(|S_ij|, |S_ij⁺|). Infinite when a value is not finite.
    fn tangent_error(&self, st: &StepStages, dk: &[[DVector<f64>; 3]], rtol: f64, atol: f64) -> f64 {
        let (tab, k, n) = (&ROS3, &st.k, self.n);
        let y1 = &self.y + &k[0] * tab.m[0] + &k[1] * tab.m[1] + &k[2] * tab.m[2];
        let w = DVector::from_fn(n, |i, _| atol + rtol * self.y[i].abs().max(y1[i].abs()));
        dk.iter().enumerate().fold(0.0f64, |worst, (j, d)| {
            let s0 = self.s.column(j);
            let s1 = s0 + &d[0] * tab.m[0] + &d[1] * tab.m[1] + &d[2] * tab.m[2];
            let est = &d[0] * tab.e[0] + &d[1] * tab.e[1] + &d[2] * tab.e[2];
            let sum: f64 = (0..n)
                .map(|i| {
                    let wi = w[i] + TANGENT_RTOL * s0[i].abs().max(s1[i].abs());
                    (est[i] / wi).powi(2)
                })
                .sum();
            let e = (sum / n as f64).sqrt();
            if e.is_finite() {
                worst.max(e)
            } else {
                f64::INFINITY
            }
        })
    }

    /// Central difference along (d, e_j) at (t, x) of f: (f⁺(x + δd) − f⁻(x − δd)) / 2δ.
    fn dir_rhs(&mut self, j: usize, t: f64, x: &DVector<f64>, d: &DVector<f64>) -> DVector<f64> {
        let (n, dl) = (self.n, self.delta[j]);
        let (p, m) = (&mut self.plus[j], &mut self.minus[j]);
        p.set_state(x.as_slice(), dl, d.as_slice());
        m.set_state(x.as_slice(), -dl, d.as_slice());
        p.rhs(t);
        m.rhs(t);
        DVector::from_fn(n, |i, _| (p.dy[i] - m.dy[i]) / (2.0 * dl))
    }

    /// Central difference of J along (S, e_j) at the states `dir_rhs` left: (J⁺ − J⁻) / 2δ.
    fn dir_jacobian(&mut self, j: usize, t: f64) -> DMatrix<f64> {
        let (n, dl) = (self.n, self.delta[j]);
        let jp = self.jac_plus[j].matrix(&mut self.plus[j], t, n);
        let jm = self.jac_minus[j].matrix(&mut self.minus[j], t, n);
        (jp - jm) / (2.0 * dl)
    }

    /// Central difference of ∂f/∂t at the states `dir_rhs` left.
    fn dir_time_derivative(&mut self, j: usize, t: f64) -> DVector<f64> {
        let (n, dl) = (self.n, self.delta[j]);
        let (p, m) = (&mut self.plus[j], &mut self.minus[j]);
        p.time_derivative(t);
        m.time_derivative(t);
        DVector::from_fn(n, |i, _| (p.dy[i] - m.dy[i]) / (2.0 * dl))
    }

    /// The stage derivatives dK_1..3 of parameter j over the accepted step from t.
    fn tangent_stages(&mut self, t: f64, st: &StepStages, j: usize) -> [DVector<f64>; 3] {
        let (n, tab, h) = (self.n, &ROS3, st.h);
        let gh = tab.gamma * h;
        let g = |i: usize| gh * tab.gamma_sum[i] * h;
        let c = |i: usize, k: usize| tab.c[i][k] * tab.gamma;
        let (y, sj) = (self.y.clone(), self.s.column(j).into_owned());
        // Stage 1 point and the derivative of J·K_i there (W is J at the step's start).
        let df1 = self.dir_rhs(j, t, &y, &sj);
        let dj = self.dir_jacobian(j, t);
        let djk: Vec<DVector<f64>> = st.k.iter().map(|k| &dj * k).collect();
        let dft = if st.ft_on {
            self.dir_time_derivative(j, t)
        } else {
            DVector::zeros(n)
        };
        let lu = self.lu.as_ref().expect("a step was taken before its tangent");
        let solve = |b: DVector<f64>| lu.solve(&b).unwrap_or_else(|| DVector::from_element(n, f64::NAN));
        let dk1 = solve((&df1 + &djk[0]) * gh + &dft * g(0));
        let y2 = &y + &st.k[0];
        let dy2 = &sj + &dk1;
        let df2 = self.dir_rhs(j, t + tab.alpha[1] * h, &y2, &dy2);
        let lu = self.lu.as_ref().expect("a step was taken before its tangent");
        let solve = |b: DVector<f64>| lu.solve(&b).unwrap_or_else(|| DVector::from_element(n, f64::NAN));
        let dk2 = solve((&df2 + &djk[1]) * gh + &dk1 * c(1, 0) + &dft * g(1));
        let dk3 = solve((&df2 + &djk[2]) * gh + &dk1 * c(2, 0) + &dk2 * c(2, 1) + &dft * g(2));
        [dk1, dk2, dk3]
    }

    /// The output row at time t.
    fn record(&self, out: &mut SensitivityTrajectory, t: f64) {
        let (n, p) = (self.n, self.delta.len());
        out.times.push(t);
        out.temps.push(self.y.iter().copied().collect());
        let mut row = vec![0.0; n * p];
        for i in 0..n {
            for j in 0..p {
                row[i * p + j] = self.s[(i, j)];
            }
        }
        out.sens.push(row);
    }

    fn failure(&self, t: f64, message: String) -> NumericalFailure {
        let th = self.nominal.scene.thermal();
        let node = self.y.iter().position(|v| !v.is_finite()).unwrap_or(th.oil);
        NumericalFailure {
            time: t,
            node: th.names[node].clone(),
            item: None,
            message,
        }
    }
}

/// How step sizes are chosen.
enum Steps<'a> {
    /// Error control at the options' tolerances.
    Adaptive,
    /// A recorded sequence, replayed.
    Fixed(std::slice::Iter<'a, f64>),
}

/// Integrate the nominal scene and the sensitivities of every direction over `segments`, with
/// error control on the node temperatures.
pub fn integrate_sensitivities(
    scene: &Scene,
    dirs: &[Direction<'_>],
    segments: &[Segment],
    opts: &SensitivityOptions,
) -> Result<SensitivityTrajectory, NumericalFailure> {
    drive(scene, dirs, segments, opts, Steps::Adaptive)
}

/// Replay the step sizes `steps` (a [`SensitivityTrajectory::steps`]) without error control.
pub fn integrate_fixed(
    scene: &Scene,
    dirs: &[Direction<'_>],
    segments: &[Segment],
    opts: &SensitivityOptions,
    steps: &[f64],
) -> Result<SensitivityTrajectory, NumericalFailure> {
    drive(scene, dirs, segments, opts, Steps::Fixed(steps.iter()))
}

/// Starting step (Hairer, Nørsett & Wanner I, II.4), at most the segment length.
fn start_step(y: &DVector<f64>, f: &DVector<f64>, opts: &SensitivityOptions, len: f64) -> f64 {
    let (mut d0, mut d1) = (0.0, 0.0);
    for (yi, fi) in y.iter().zip(f.iter()) {
        let w = opts.atol + opts.rtol * yi.abs();
        d0 += (yi / w).powi(2);
        d1 += (fi / w).powi(2);
    }
    let k = y.len() as f64;
    let (d0, d1) = ((d0 / k).sqrt(), (d1 / k).sqrt());
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    h0.min(len).max(1e-10)
}

fn drive(
    scene: &Scene,
    dirs: &[Direction<'_>],
    segments: &[Segment],
    opts: &SensitivityOptions,
    mut steps: Steps<'_>,
) -> Result<SensitivityTrajectory, NumericalFailure> {
    let first = segments.first().ok_or_else(|| NumericalFailure {
        time: 0.0,
        node: scene.thermal().names[scene.thermal().oil].clone(),
        item: None,
        message: "empty input: no segment to integrate".into(),
    })?;
    if let Some(c) = scene.thermal().controls.iter().find(|c| c.is_pi()) {
        return Err(NumericalFailure {
            time: first.t0,
            node: scene.thermal().names[c.sensor].clone(),
            item: None,
            message: format!(
                "controller {} is a PI valve: its integral is a state the node temperatures \
                 depend on, and the sensitivity integrator carries the node temperatures alone \
                 (not implemented); a calibration cannot fit through it — give the cooler a \
                 proportional valve or no controller to compute sensitivities",
                c.name
            ),
        });
    }
    let mut r = Tangent::new(scene, dirs, first, opts.initial.as_deref());
    let mut out = SensitivityTrajectory {
        times: Vec::with_capacity(segments.len() + 1),
        temps: Vec::with_capacity(segments.len() + 1),
        sens: Vec::with_capacity(segments.len() + 1),
        steps: Vec::new(),
        rejected: 0,
    };
    r.record(&mut out, first.t0);
    let y0 = r.y.clone();
    let f0 = r.nominal_f(first.t0, &y0);
    let mut h = start_step(&y0, &f0, opts, first.t1 - first.t0);
    for (k, seg) in segments.iter().enumerate() {
        if k > 0 && seg.inputs != segments[k - 1].inputs {
            r.switch_inputs(seg);
        }
        h = integrate_segment(&mut r, seg, h, opts, &mut steps, &mut out)?;
        r.record(&mut out, seg.t1);
    }
    Ok(out)
}

/// Steps from seg.t0 to seg.t1; returns the next step-size proposal.
fn integrate_segment(
    r: &mut Tangent<'_>,
    seg: &Segment,
    mut h: f64,
    opts: &SensitivityOptions,
    steps: &mut Steps<'_>,
    out: &mut SensitivityTrajectory,
) -> Result<f64, NumericalFailure> {
    let mut t = seg.t0;
    let expo = -1.0 / ROS3.elo;
    while t < seg.t1 {
        if out.steps.len() + out.rejected >= opts.max_steps {
            let why = format!("step budget of {} exceeded", opts.max_steps);
            return Err(r.failure(t, why));
        }
        let rest = seg.t1 - t;
        let h_try = match steps {
            Steps::Adaptive if h >= rest * (1.0 - 1e-9) => rest,
            Steps::Adaptive => h,
            Steps::Fixed(it) => *it
                .next()
                .ok_or_else(|| r.failure(t, "the replayed step sequence ended early".into()))?,
        };
        let (st, err) = r.step(t, h_try, opts.rtol, opts.atol);
        // The tangents in the error test (module doc): only a step whose temperatures pass.
        let (dk, err) = match steps {
            Steps::Adaptive if err <= 1.0 && !r.delta.is_empty() => {
                let dk = r.tangents(t, &st);
                let es = r.tangent_error(&st, &dk, opts.rtol, opts.atol);
                (Some(dk), err.max(es))
            }
            _ => (None, err),
        };
        let accept = match steps {
            Steps::Adaptive => err <= 1.0,
            Steps::Fixed(_) => err.is_finite(),
        };
        if accept {
            let (st, h_step, dk) = match r.locate_event(t, &st, opts) {
                Some((located, h)) => (located, h, None),
                None => (st, h_try, dk),
            };
            r.accept(t, &st, dk);
            out.steps.push(h_step);
            t = if h_step >= rest * (1.0 - 1e-9) {
                seg.t1
            } else {
                t + h_step
            };
            h = h_try * (SAFETY * err.max(1e-10).powf(expo)).min(GROW_MAX);
            if r.ev.due {
                h = r.switch_with_saltation(t, h, opts, seg.t1 - t)?;
            }
            if let Some(i) = r.y.iter().position(|v| !v.is_finite()) {
                return Err(r.failure(t, format!("node {i} is not finite")));
            }
        } else {
            out.rejected += 1;
            let fac = if err.is_finite() {
                (SAFETY * err.powf(expo)).clamp(SHRINK_MIN, 1.0)
            } else {
                0.25
            };
            h = h_try * fac;
            if h < 1e-10 * t.abs().max(1.0) || matches!(steps, Steps::Fixed(_)) {
                let why = format!("step size {h:.3e} s too small: the error test keeps failing");
                return Err(r.failure(t, why));
            }
        }
    }
    Ok(h)
}
