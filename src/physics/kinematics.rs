//! Gear-train kinematics and lossless torques (physics.md §4) [std].
//!
//! A gearbox is described by `n` rotating **members** (shafts, carriers, ring gears, suns...;
//! indices `0..n`, with names used only in diagnostics) and by **constraints**, each one linear
//! equation in the member speeds ω (rad/s):
//!
//! | constraint         | row `A_k · ω = 0`                         |
//! |--------------------|-------------------------------------------|
//! | external mesh      | `z_a ω_a + z_b ω_b = 0`                   |
//! | internal mesh      | `z_p ω_p − z_r ω_r = 0`                   |
//! | simple set         | `z_S (ω_S − ω_C) + z_R (ω_R − ω_C) = 0`   |
//! | double-pinion set  | `z_S (ω_S − ω_C) − z_R (ω_R − ω_C) = 0`   |
//! | engaged clutch     | `ω_a − ω_b = 0`                           |
//! | engaged brake      | `ω = 0`                                   |
//!
//! Gear meshes and planetary sets are *fixed* constraints of a [`GearTrain`]; a gear state adds
//! its *engaged* shift elements (clutches, brakes) and [`GearTrain::solve_state`] returns the
//! speeds and the lossless torques of that state, or a diagnostic saying why the state does not
//! have exactly one degree of freedom.
//!
//! # Speeds
//!
//! All rows are stacked into `A` (m × n, fixed rows first, then engaged rows). A valid state has
//! `rank A = n − 1`: the solution set of `A ω = 0` is one line, spanned by `v`, and the input
//! moves on it (`v_in ≠ 0`). Speeds are returned per unit input speed, `ω = v / v_in`, so the
//! speed ratio is `i = ω_in / ω_out = 1 / ω_out` (negative in reverse).
//!
//! The null space is found by an SVD of `A` with every row scaled to unit norm (row scaling
//! leaves the null space unchanged and makes the rank decision independent of tooth-count
//! magnitudes); singular values below `rank_tol · max(1, σ_max)` count as zero
//! ([`DEFAULT_RANK_TOL`] = 1e-9, configurable).
//!
//! # Torques (virtual work) [std]
//!
//! Constraint `k` applies to member `m` the torque `λ_k · A_km`: the reaction torques of ideal
//! (lossless) constraints are `Aᵀ λ`, because they do no work on any motion the constraints
//! allow (`ωᵀ Aᵀ λ = 0` when `A ω = 0`). Equilibrium of each member (inertia neglected):
//!
//! `T_ext,m + Σ_k λ_k A_km = 0`, with `T_ext = 1` at the input, the unknown `T_out` at the
//! output, 0 elsewhere.
//!
//! This is `n` equations for the `m + 1` unknowns `(λ, T_out)`; it is solved by a minimum-norm
//! least-squares SVD solve of `[Aᵀ | e_out] x = −e_in`. When `rank A = n − 1` and the output
//! moves, the system has a solution and `T_out = −v_in / v_out = −i` (power balance
//! `T_in ω_in + T_out ω_out = 0`) is unique; the `λ` are unique unless rows are redundant (see
//! below).
//!
//! **Sign convention:** every torque in this module is the torque applied **to** a member (by a
//! constraint, or by the outside world for `T_ext`), positive in the member's positive sense of
//! rotation. The torque the gearbox delivers to the load is therefore `−T_out = +i` per unit input
//! torque. Physical meaning of λ: for a mesh row, `λ = F_t · m_t / 2` (tangential tooth force
//! times half the transverse module), since the torque on a gear of z teeth is `F_t m_t z / 2`;
//! for a clutch row, `λ` is the torque the clutch applies to member `a` (and `−λ` to `b`); for a
//! brake row, `λ` is the torque the housing applies to the member through the brake.
//!
//! # Redundant (statically indeterminate) rows
//!
//! Rows that are linear combinations of other rows (the same clutch engaged twice, a clutch
//! joining a member to itself — a zero row —, two brakes on members already locked together...)
//! do not change the kinematics: the state is accepted and
//! [`StateSolution::redundant_rows`] says how many there are (`m − rank A`). Their multipliers are
//! then not determined by statics (the real split depends on compliances); the solver returns the
//! minimum-norm split (in unit-norm row scaling), e.g. two identical clutches each carry half.
//!
//! Planet gears are not members: their spin follows from the set speeds ([`planet_spin`],
//! [`ring_pinion_spin`]) and mesh powers are evaluated in the carrier frame
//! ([`carrier_frame_mesh_power`]).

use nalgebra::{DMatrix, DVector};
use std::fmt;

/// Default relative tolerance for rank decisions: singular values of the unit-row-scaled
/// constraint matrix below `DEFAULT_RANK_TOL · max(1, σ_max)` are treated as zero. Also used
/// as the relative threshold below which a speed counts as zero.
pub const DEFAULT_RANK_TOL: f64 = 1e-9;

/// Maximum number of SVD iterations before giving up (never reached for trains of ≤ 30 members).
const SVD_MAX_ITER: usize = 10_000;

/// Tolerance on the residual of the torque solve, relative to the unit input torque.
const TORQUE_RESIDUAL_TOL: f64 = 1e-8;

/// One linear kinematic constraint between members (indices into the member list).
/// Tooth numbers are counts (dimensionless, > 0, finite; non-integer values are accepted).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Constraint {
    /// Fixed-axis external mesh: `za·ωa + zb·ωb = 0`.
    ExternalMesh {
        /// Member carrying the first gear.
        a: usize,
        /// Member carrying the second gear.
        b: usize,
        /// Tooth count of the first gear.
        za: f64,
        /// Tooth count of the second gear.
        zb: f64,
    },
    /// Fixed-axis internal mesh (pinion inside a ring): `zp·ωp − zr·ωr = 0`.
    InternalMesh {
        /// Member carrying the external pinion.
        pinion: usize,
        /// Member carrying the internal ring gear.
        ring: usize,
        /// Tooth count of the pinion.
        zp: f64,
        /// Tooth count of the ring gear.
        zr: f64,
    },
    /// Simple planetary set (sun – planets – ring): `zs(ωs − ωc) + zr(ωr − ωc) = 0`.
    SimpleSet {
        /// Sun gear member.
        sun: usize,
        /// Ring gear member.
        ring: usize,
        /// Planet carrier member.
        carrier: usize,
        /// Tooth count of the sun.
        zs: f64,
        /// Tooth count of the ring.
        zr: f64,
    },
    /// Double-pinion planetary set (sun – inner pinion – outer pinion – ring):
    /// `zs(ωs − ωc) − zr(ωr − ωc) = 0`.
    DoublePinionSet {
        /// Sun gear member.
        sun: usize,
        /// Ring gear member.
        ring: usize,
        /// Planet carrier member.
        carrier: usize,
        /// Tooth count of the sun.
        zs: f64,
        /// Tooth count of the ring.
        zr: f64,
    },
    /// Engaged clutch: `ωa − ωb = 0`.
    Clutch {
        /// One member the clutch couples.
        a: usize,
        /// The other member.
        b: usize,
    },
    /// Engaged brake (member held by the housing): `ω = 0`.
    Brake {
        /// The member held at rest.
        member: usize,
    },
}

impl Constraint {
    /// A Ravigneaux set [std]: large sun + long pinions + ring form a simple set, small sun +
    /// short pinions + long pinions + the same ring a double-pinion set, both on one carrier.
    /// Returns `[SimpleSet (large sun), DoublePinionSet (small sun)]`; add both to the train.
    pub fn ravigneaux(
        large_sun: usize,
        small_sun: usize,
        ring: usize,
        carrier: usize,
        z_large_sun: f64,
        z_small_sun: f64,
        z_ring: f64,
    ) -> [Constraint; 2] {
        [
            Constraint::SimpleSet {
                sun: large_sun,
                ring,
                carrier,
                zs: z_large_sun,
                zr: z_ring,
            },
            Constraint::DoublePinionSet {
                sun: small_sun,
                ring,
                carrier,
                zs: z_small_sun,
                zr: z_ring,
            },
        ]
    }

    /// The row's terms `(member, coefficient)` as written (`len` used entries of 3).
    fn terms(&self) -> ([(usize, f64); 3], usize) {
        match *self {
            Constraint::ExternalMesh { a, b, za, zb } => ([(a, za), (b, zb), (0, 0.0)], 2),
            Constraint::InternalMesh { pinion, ring, zp, zr } => ([(pinion, zp), (ring, -zr), (0, 0.0)], 2),
            Constraint::SimpleSet {
                sun,
                ring,
                carrier,
                zs,
                zr,
            } => ([(sun, zs), (ring, zr), (carrier, -(zs + zr))], 3),
            Constraint::DoublePinionSet {
                sun,
                ring,
                carrier,
                zs,
                zr,
            } => ([(sun, zs), (ring, -zr), (carrier, zr - zs)], 3),
            Constraint::Clutch { a, b } => ([(a, 1.0), (b, -1.0), (0, 0.0)], 2),
            Constraint::Brake { member } => ([(member, 1.0), (0, 0.0), (0, 0.0)], 1),
        }
    }

    /// Coefficients of the row `A_k` as `(member, coefficient)` pairs, in the order the
    /// constraint names them (a member named twice appears twice; the matrix adds them).
    pub fn coefficients(&self) -> Vec<(usize, f64)> {
        let (t, len) = self.terms();
        t[..len].to_vec()
    }

    /// Residual `A_k · ω` of the constraint for the given member speeds (same unit as ω times
    /// teeth). Precondition: every member index of the constraint is `< speeds.len()`.
    pub fn residual(&self, speeds: &[f64]) -> f64 {
        let (t, len) = self.terms();
        t[..len].iter().map(|&(m, c)| c * speeds[m]).sum()
    }

    /// True for shift elements (clutch, brake), false for meshes and planetary sets.
    pub fn is_shift_element(&self) -> bool {
        matches!(self, Constraint::Clutch { .. } | Constraint::Brake { .. })
    }

    fn tooth_counts(&self) -> ([f64; 2], usize) {
        match *self {
            Constraint::ExternalMesh { za, zb, .. } => ([za, zb], 2),
            Constraint::InternalMesh { zp, zr, .. } => ([zp, zr], 2),
            Constraint::SimpleSet { zs, zr, .. } | Constraint::DoublePinionSet { zs, zr, .. } => {
                ([zs, zr], 2)
            }
            Constraint::Clutch { .. } | Constraint::Brake { .. } => ([0.0, 0.0], 0),
        }
    }

    /// Checks member indices (`< n_members`) and tooth counts (finite, > 0).
    fn validate(&self, n_members: usize) -> Result<(), KinematicsError> {
        let (t, len) = self.terms();
        for &(m, _) in &t[..len] {
            if m >= n_members {
                return Err(KinematicsError::InvalidMember { index: m, n_members });
            }
        }
        let (z, nz) = self.tooth_counts();
        for &value in &z[..nz] {
            if !(value.is_finite() && value > 0.0) {
                return Err(KinematicsError::InvalidToothCount { value });
            }
        }
        Ok(())
    }

    /// Human-readable description using member names (for diagnostics).
    /// Precondition: indices are valid for `names` (unknown indices are printed as `#i`).
    pub fn describe(&self, names: &[String]) -> String {
        let name = |i: usize| names.get(i).cloned().unwrap_or_else(|| format!("#{i}"));
        match *self {
            Constraint::ExternalMesh { a, b, za, zb } => {
                format!("external mesh {}({za})–{}({zb})", name(a), name(b))
            }
            Constraint::InternalMesh { pinion, ring, zp, zr } => {
                format!("internal mesh {}({zp})–{}({zr})", name(pinion), name(ring))
            }
            Constraint::SimpleSet {
                sun,
                ring,
                carrier,
                zs,
                zr,
            } => format!(
                "simple set S {}({zs}) R {}({zr}) C {}",
                name(sun),
                name(ring),
                name(carrier)
            ),
            Constraint::DoublePinionSet {
                sun,
                ring,
                carrier,
                zs,
                zr,
            } => format!(
                "double-pinion set S {}({zs}) R {}({zr}) C {}",
                name(sun),
                name(ring),
                name(carrier)
            ),
            Constraint::Clutch { a, b } => format!("clutch {}–{}", name(a), name(b)),
            Constraint::Brake { member } => format!("brake on {}", name(member)),
        }
    }
}

/// An engaged element named in an [`KinematicsError::OverConstrained`] diagnostic.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementRef {
    /// Index into the `engaged` slice passed to [`GearTrain::solve_state`].
    pub index: usize,
    /// Description with member names.
    pub description: String,
}

/// Why a gear state could not be solved.
#[derive(Debug, Clone, PartialEq)]
pub enum KinematicsError {
    /// A train needs at least two members (an input and an output).
    TooFewMembers {
        /// Number of members the train has.
        n_members: usize,
    },
    /// A constraint, the input or the output names a member index `>= n_members`.
    InvalidMember {
        /// The member index named.
        index: usize,
        /// Number of members the train has.
        n_members: usize,
    },
    /// A tooth count is not finite and positive.
    InvalidToothCount {
        /// The tooth count given.
        value: f64,
    },
    /// The rank tolerance is not finite and positive.
    InvalidTolerance {
        /// The relative tolerance given.
        value: f64,
    },
    /// Input and output are the same member.
    InputIsOutput {
        /// Name of that member.
        member: String,
    },
    /// More than one degree of freedom: with the input held, the listed members can still move.
    UnderDetermined {
        /// Members whose speed is not fixed by the input speed.
        free_members: Vec<String>,
        /// Number of degrees of freedom left once the input speed is given (≥ 1).
        dof: usize,
    },
    /// The input cannot rotate (the train is locked, or the input is held).
    OverConstrained {
        /// Members that are at rest in every motion the constraints allow (all members when
        /// the whole train is locked).
        locked_members: Vec<String>,
        /// Engaged elements whose removal alone gives a valid state (one degree of freedom,
        /// input and output moving). Empty if no single removal helps.
        removable_elements: Vec<ElementRef>,
    },
    /// One degree of freedom, but the output is held: no torque can be transmitted.
    OutputAtRest {
        /// Name of the output member.
        output: String,
    },
    /// The SVD did not converge or the torque solve left a residual (should not happen).
    Numerical {
        /// Which computation failed.
        what: &'static str,
    },
}

impl fmt::Display for KinematicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KinematicsError::TooFewMembers { n_members } => {
                write!(f, "a gear train needs at least 2 members, got {n_members}")
            }
            KinematicsError::InvalidMember { index, n_members } => write!(
                f,
                "member index {index} out of range (the train has {n_members} members)"
            ),
            KinematicsError::InvalidToothCount { value } => {
                write!(f, "tooth count {value} is not a finite positive number")
            }
            KinematicsError::InvalidTolerance { value } => {
                write!(f, "rank tolerance {value} is not a finite positive number")
            }
            KinematicsError::InputIsOutput { member } => {
                write!(f, "input and output are the same member '{member}'")
            }
            KinematicsError::UnderDetermined { free_members, dof } => write!(
                f,
                "under-determined: {dof} degree(s) of freedom left with the input speed given; \
                 free members: {}",
                free_members.join(", ")
            ),
            KinematicsError::OverConstrained {
                locked_members,
                removable_elements,
            } => {
                write!(
                    f,
                    "over-constrained: the input cannot rotate; locked members: {}",
                    locked_members.join(", ")
                )?;
                if !removable_elements.is_empty() {
                    let list: Vec<String> = removable_elements
                        .iter()
                        .map(|e| format!("#{} {}", e.index, e.description))
                        .collect();
                    write!(
                        f,
                        "; releasing any one of these gives a valid state: {}",
                        list.join(", ")
                    )?;
                }
                Ok(())
            }
            KinematicsError::OutputAtRest { output } => write!(
                f,
                "the output '{output}' is held in this state: no torque can be transmitted"
            ),
            KinematicsError::Numerical { what } => write!(f, "numerical failure: {what}"),
        }
    }
}

impl std::error::Error for KinematicsError {}

/// Torques applied by one planetary-set row to its three members (N·m per unit input torque),
/// sign convention of the module (torque applied TO the member).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SetTorques {
    /// Torque on the sun, N·m per N·m of input torque.
    pub sun: f64,
    /// Torque on the ring, N·m per N·m of input torque.
    pub ring: f64,
    /// Torque on the carrier, N·m per N·m of input torque.
    pub carrier: f64,
}

/// Carrier-frame mesh powers of a Ravigneaux set (W per unit input torque × unit input speed):
/// each is `T·(ω − ω_C)` with T the torque the mesh applies to the named central gear.
/// Signed; losses use the magnitude. The short–long pinion mesh carries the same power as the
/// small-sun mesh (the short pinion is in equilibrium and only passes it on).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RavigneauxMeshPowers {
    /// Large sun – long pinion mesh: `T_LS (ω_LS − ω_C)`.
    pub large_sun_long: f64,
    /// Small sun – short pinion mesh: `T_SS (ω_SS − ω_C)`.
    pub small_sun_short: f64,
    /// Short pinion – long pinion mesh (= `small_sun_short`).
    pub short_long: f64,
    /// Long pinion – ring mesh: `(T_R,simple + T_R,double)(ω_R − ω_C)`.
    pub long_ring: f64,
}

/// A gear train: named members and the always-active constraints (meshes, planetary sets,
/// permanent housing connections).
#[derive(Debug, Clone, PartialEq)]
pub struct GearTrain {
    names: Vec<String>,
    fixed: Vec<Constraint>,
    rank_tol: f64,
}

/// Speeds and lossless torques of one gear state, per unit input speed and unit input torque
/// (scale speeds by ω_in in rad/s, torques by T_in in N·m; multipliers scale with T_in).
#[derive(Debug, Clone, PartialEq)]
pub struct StateSolution {
    /// Input member index.
    pub input: usize,
    /// Output member index.
    pub output: usize,
    /// Member speeds per unit input speed (`speeds[input] == 1`).
    pub speeds: Vec<f64>,
    /// The constraint rows used: the train's fixed constraints, then the engaged ones.
    pub constraints: Vec<Constraint>,
    /// Number of fixed rows at the start of `constraints`.
    pub n_fixed: usize,
    /// Lagrange multiplier λ_k of each row (same order as `constraints`) for unit input torque;
    /// row k applies `λ_k · A_km` to member m (see the module docs for the physical meaning).
    pub multipliers: Vec<f64>,
    /// External torque applied to the output member (by the load) for unit input torque:
    /// `−ratio()` for this lossless train. The gearbox delivers `−output_torque` to the load.
    pub output_torque: f64,
    /// Number of redundant rows `m − rank A` (0 for a statically determinate state).
    pub redundant_rows: usize,
    /// Dense row matrix `A` (m × n), unscaled.
    coefficients: DMatrix<f64>,
}

/// Outcome of the mobility analysis of a set of rows.
enum Mobility {
    /// One degree of freedom with input and output moving: speeds per unit input speed.
    Unique(DVector<f64>),
    /// The input cannot move; members at rest in every allowed motion.
    InputLocked { locked: Vec<usize> },
    /// More than one degree of freedom once the input is given.
    Under { free: Vec<usize>, dof: usize },
    /// One degree of freedom, output at rest.
    OutputAtRest,
}

impl GearTrain {
    /// Builds a train from member names and fixed constraints.
    /// Errors: fewer than 2 members, a member index out of range, a bad tooth count.
    pub fn new(member_names: Vec<String>, fixed: Vec<Constraint>) -> Result<Self, KinematicsError> {
        let n = member_names.len();
        if n < 2 {
            return Err(KinematicsError::TooFewMembers { n_members: n });
        }
        for c in &fixed {
            c.validate(n)?;
        }
        Ok(GearTrain {
            names: member_names,
            fixed,
            rank_tol: DEFAULT_RANK_TOL,
        })
    }

    /// Replaces the relative rank tolerance (default [`DEFAULT_RANK_TOL`]).
    pub fn with_rank_tolerance(mut self, tol: f64) -> Result<Self, KinematicsError> {
        if !(tol.is_finite() && tol > 0.0) {
            return Err(KinematicsError::InvalidTolerance { value: tol });
        }
        self.rank_tol = tol;
        Ok(self)
    }

    /// Number of members.
    pub fn n_members(&self) -> usize {
        self.names.len()
    }

    /// Member names, by index.
    pub fn member_names(&self) -> &[String] {
        &self.names
    }

    /// Index of the member with this name, if any.
    pub fn member_index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The fixed constraints.
    pub fn fixed(&self) -> &[Constraint] {
        &self.fixed
    }

    /// Solves one gear state: the fixed constraints plus the `engaged` ones, unit input speed
    /// and unit input torque at member `input`, load at member `output`.
    ///
    /// Errors: invalid indices or tooth counts, `input == output`, [`KinematicsError::UnderDetermined`],
    /// [`KinematicsError::OverConstrained`], [`KinematicsError::OutputAtRest`].
    pub fn solve_state(
        &self,
        engaged: &[Constraint],
        input: usize,
        output: usize,
    ) -> Result<StateSolution, KinematicsError> {
        let n = self.names.len();
        for &i in &[input, output] {
            if i >= n {
                return Err(KinematicsError::InvalidMember {
                    index: i,
                    n_members: n,
                });
            }
        }
        if input == output {
            return Err(KinematicsError::InputIsOutput {
                member: self.names[input].clone(),
            });
        }
        for c in engaged {
            c.validate(n)?;
        }
        let rows: Vec<Constraint> = self.fixed.iter().chain(engaged).copied().collect();
        let a = row_matrix(&rows, n);
        let (a_norm, scale) = normalise_rows(&a);

        let (mobility, rank) = self.mobility(&a_norm, input, output)?;
        let speeds = match mobility {
            Mobility::Unique(s) => s,
            Mobility::Under { free, dof } => {
                return Err(KinematicsError::UnderDetermined {
                    free_members: self.names_of(&free),
                    dof,
                })
            }
            Mobility::OutputAtRest => {
                return Err(KinematicsError::OutputAtRest {
                    output: self.names[output].clone(),
                })
            }
            Mobility::InputLocked { locked } => {
                let removable = self.removable_elements(&a_norm, engaged, input, output)?;
                return Err(KinematicsError::OverConstrained {
                    locked_members: self.names_of(&locked),
                    removable_elements: removable,
                });
            }
        };

        // Torques: [A_normᵀ | e_out] x = −e_in, minimum-norm least squares.
        let m = rows.len();
        let mut mat = DMatrix::<f64>::zeros(n, m + 1);
        mat.view_mut((0, 0), (n, m)).copy_from(&a_norm.transpose());
        mat[(output, m)] = 1.0;
        let mut rhs = DVector::<f64>::zeros(n);
        rhs[input] = -1.0;
        let svd = mat
            .clone()
            .try_svd(true, true, f64::EPSILON, SVD_MAX_ITER)
            .ok_or(KinematicsError::Numerical {
                what: "SVD of the equilibrium matrix did not converge",
            })?;
        let smax = svd.singular_values.max();
        let x = svd
            .solve(&rhs, self.rank_tol * smax.max(1.0))
            .map_err(|what| KinematicsError::Numerical { what })?;
        let residual = (&mat * &x - &rhs).amax();
        if residual.is_nan() || residual > TORQUE_RESIDUAL_TOL {
            return Err(KinematicsError::Numerical {
                what: "torque equilibrium has no solution",
            });
        }
        let multipliers: Vec<f64> = (0..m).map(|k| x[k] * scale[k]).collect();
        Ok(StateSolution {
            input,
            output,
            speeds: speeds.iter().copied().collect(),
            constraints: rows,
            n_fixed: self.fixed.len(),
            multipliers,
            output_torque: x[m],
            redundant_rows: m.saturating_sub(rank),
            coefficients: a,
        })
    }

    fn names_of(&self, idx: &[usize]) -> Vec<String> {
        idx.iter().map(|&i| self.names[i].clone()).collect()
    }

    /// Null-space analysis of the (row-normalised) matrix; returns the mobility and rank.
    fn mobility(
        &self,
        a_norm: &DMatrix<f64>,
        input: usize,
        output: usize,
    ) -> Result<(Mobility, usize), KinematicsError> {
        let (v, rank) = self.null_space(a_norm)?;
        let n = a_norm.ncols();
        let d = v.ncols();
        let tol = self.rank_tol;
        // Input component of the null-space basis.
        let r = v.row(input).transpose();
        let rnorm = r.norm();
        if rnorm <= tol {
            // The input cannot move: members at rest in every motion: ‖V_i‖ ≈ 0.
            let locked = (0..n).filter(|&i| v.row(i).norm() <= tol).collect();
            return Ok((Mobility::InputLocked { locked }, rank));
        }
        if d > 1 {
            // Motions with the input held: N0 = {V c : r·c = 0}; projector V (I − r̂ r̂ᵀ) Vᵀ.
            let rhat = &r / rnorm;
            let free = (0..n)
                .filter(|&i| {
                    let vi = v.row(i).transpose();
                    let p = vi.norm_squared() - vi.dot(&rhat).powi(2);
                    p.max(0.0).sqrt() > tol
                })
                .collect();
            return Ok((Mobility::Under { free, dof: d - 1 }, rank));
        }
        let col = v.column(0);
        let speeds: DVector<f64> = col / col[input];
        let wmax = speeds.amax().max(1.0);
        if speeds[output].abs() <= tol * wmax {
            return Ok((Mobility::OutputAtRest, rank));
        }
        Ok((Mobility::Unique(speeds), rank))
    }

    /// Orthonormal basis (n × d) of the null space of `a_norm`, and its rank.
    fn null_space(&self, a_norm: &DMatrix<f64>) -> Result<(DMatrix<f64>, usize), KinematicsError> {
        let (m, n) = a_norm.shape();
        // Pad with zero rows so that the SVD returns the full n × n V (zero rows do not change
        // the null space).
        let mut padded = DMatrix::<f64>::zeros(m.max(n), n);
        padded.view_mut((0, 0), (m, n)).copy_from(a_norm);
        let svd =
            padded
                .try_svd(false, true, f64::EPSILON, SVD_MAX_ITER)
                .ok_or(KinematicsError::Numerical {
                    what: "SVD of the constraint matrix did not converge",
                })?;
        let v_t = svd.v_t.ok_or(KinematicsError::Numerical {
            what: "SVD did not return V",
        })?;
        let sv = &svd.singular_values;
        let smax = sv.max();
        let thresh = self.rank_tol * smax.max(1.0);
        let null_idx: Vec<usize> = (0..sv.len()).filter(|&i| sv[i] <= thresh).collect();
        let rank = n - null_idx.len();
        let mut basis = DMatrix::<f64>::zeros(n, null_idx.len());
        for (j, &i) in null_idx.iter().enumerate() {
            basis.set_column(j, &v_t.row(i).transpose());
        }
        Ok((basis, rank))
    }

    /// Engaged elements whose removal alone yields a valid state.
    fn removable_elements(
        &self,
        a_norm: &DMatrix<f64>,
        engaged: &[Constraint],
        input: usize,
        output: usize,
    ) -> Result<Vec<ElementRef>, KinematicsError> {
        let nf = self.fixed.len();
        let mut out = Vec::new();
        for (j, c) in engaged.iter().enumerate() {
            let reduced = a_norm.clone().remove_row(nf + j);
            let (mob, _) = self.mobility(&reduced, input, output)?;
            if matches!(mob, Mobility::Unique(_)) {
                out.push(ElementRef {
                    index: j,
                    description: c.describe(&self.names),
                });
            }
        }
        Ok(out)
    }
}

/// Dense row matrix (m × n); repeated members in one constraint add up.
fn row_matrix(rows: &[Constraint], n: usize) -> DMatrix<f64> {
    let mut a = DMatrix::<f64>::zeros(rows.len(), n);
    for (k, c) in rows.iter().enumerate() {
        let (t, len) = c.terms();
        for &(m, coef) in &t[..len] {
            a[(k, m)] += coef;
        }
    }
    a
}

/// Scales every non-zero row to unit Euclidean norm; returns the matrix and the factors
/// `s_k = 1/‖A_k‖` (1 for zero rows), so that `A_norm = diag(s) A`.
fn normalise_rows(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>) {
    let mut out = a.clone();
    let mut scale = vec![1.0; a.nrows()];
    for (k, s) in scale.iter_mut().enumerate() {
        let norm = a.row(k).norm();
        if norm > 0.0 {
            *s = 1.0 / norm;
            out.row_mut(k).scale_mut(*s);
        }
    }
    (out, scale)
}

impl StateSolution {
    /// Speed ratio `i = ω_in / ω_out` (negative for reverse). Finite: states with the output at
    /// rest are rejected by the solver.
    pub fn ratio(&self) -> f64 {
        self.speeds[self.input] / self.speeds[self.output]
    }

    /// Input torque the solution is normalised to (1, applied to the input member).
    pub fn input_torque(&self) -> f64 {
        1.0
    }

    /// External torque applied to member `m`: 1 at the input, `output_torque` at the output,
    /// 0 elsewhere. Precondition: `m < n_members`.
    pub fn external_torque(&self, m: usize) -> f64 {
        if m == self.input {
            self.input_torque()
        } else if m == self.output {
            self.output_torque
        } else {
            0.0
        }
    }

    /// Torque applied by constraint row `k` to member `m`: `λ_k · A_km`.
    /// Precondition: `k < constraints.len()`, `m < n_members`.
    pub fn torque_on(&self, k: usize, m: usize) -> f64 {
        self.multipliers[k] * self.coefficients[(k, m)]
    }

    /// Torques applied by row `k` to each member it touches, `(member, torque)`.
    /// Precondition: `k < constraints.len()`.
    pub fn constraint_torques(&self, k: usize) -> Vec<(usize, f64)> {
        (0..self.coefficients.ncols())
            .filter(|&m| self.coefficients[(k, m)] != 0.0)
            .map(|m| (m, self.torque_on(k, m)))
            .collect()
    }

    /// Sum of the constraint torques on member `m` (equals `−external_torque(m)`).
    pub fn constraint_torque_on_member(&self, m: usize) -> f64 {
        (0..self.multipliers.len()).map(|k| self.torque_on(k, m)).sum()
    }

    /// Torque carried by engaged element `j` (index into the `engaged` slice): for a clutch the
    /// torque it applies to member `a` (it applies the opposite to `b`); for a brake the torque
    /// the housing applies to the member; for another constraint its multiplier λ.
    /// Precondition: `j < constraints.len() − n_fixed`.
    pub fn element_torque(&self, j: usize) -> f64 {
        self.multipliers[self.n_fixed + j]
    }

    /// Torques of planetary-set row `k` on sun, ring and carrier (None if row `k` is not a set).
    /// Simple set: `T_S : T_R : T_C = z_S : z_R : −(z_S + z_R)`; double-pinion set:
    /// `z_S : −z_R : (z_R − z_S)`. They sum to zero.
    pub fn set_torques(&self, k: usize) -> Option<SetTorques> {
        match *self.constraints.get(k)? {
            Constraint::SimpleSet { zs, zr, .. } => {
                let l = self.multipliers[k];
                Some(SetTorques {
                    sun: l * zs,
                    ring: l * zr,
                    carrier: -l * (zs + zr),
                })
            }
            Constraint::DoublePinionSet { zs, zr, .. } => {
                let l = self.multipliers[k];
                Some(SetTorques {
                    sun: l * zs,
                    ring: -l * zr,
                    carrier: l * (zr - zs),
                })
            }
            _ => None,
        }
    }

    /// Carrier-frame powers `(sun mesh, ring mesh)` of planetary-set row `k`:
    /// `T_S (ω_S − ω_C)` and `T_R (ω_R − ω_C)` (W per unit input torque and speed). They are
    /// opposite (the planets pass the power on). None if row `k` is not a set.
    pub fn set_mesh_powers(&self, k: usize) -> Option<(f64, f64)> {
        let t = self.set_torques(k)?;
        let (sun, ring, carrier) = match self.constraints[k] {
            Constraint::SimpleSet {
                sun, ring, carrier, ..
            }
            | Constraint::DoublePinionSet {
                sun, ring, carrier, ..
            } => (sun, ring, carrier),
            _ => return None,
        };
        let wc = self.speeds[carrier];
        Some((
            carrier_frame_mesh_power(t.sun, self.speeds[sun], wc),
            carrier_frame_mesh_power(t.ring, self.speeds[ring], wc),
        ))
    }

    /// Carrier-frame mesh powers of a Ravigneaux set given its simple-set row `k_simple` and
    /// double-pinion row `k_double` (as built by [`Constraint::ravigneaux`]). None if the rows
    /// are not a simple and a double-pinion set sharing ring and carrier.
    pub fn ravigneaux_mesh_powers(&self, k_simple: usize, k_double: usize) -> Option<RavigneauxMeshPowers> {
        let (ls, ring1, c1) = match *self.constraints.get(k_simple)? {
            Constraint::SimpleSet {
                sun, ring, carrier, ..
            } => (sun, ring, carrier),
            _ => return None,
        };
        let (ss, ring2, c2) = match *self.constraints.get(k_double)? {
            Constraint::DoublePinionSet {
                sun, ring, carrier, ..
            } => (sun, ring, carrier),
            _ => return None,
        };
        if ring1 != ring2 || c1 != c2 {
            return None;
        }
        let t1 = self.set_torques(k_simple)?;
        let t2 = self.set_torques(k_double)?;
        let wc = self.speeds[c1];
        let small = carrier_frame_mesh_power(t2.sun, self.speeds[ss], wc);
        Some(RavigneauxMeshPowers {
            large_sun_long: carrier_frame_mesh_power(t1.sun, self.speeds[ls], wc),
            small_sun_short: small,
            short_long: small,
            long_ring: carrier_frame_mesh_power(t1.ring + t2.ring, self.speeds[ring1], wc),
        })
    }
}

/// Planet spin relative to the carrier for a planet (tooth count `zp`) meshing a sun (`zs`)
/// externally [std]: `ω_P − ω_C = −(z_S/z_P)(ω_S − ω_C)` (rad/s in, rad/s out). Also valid for
/// any external mesh in the carrier frame (e.g. long pinion driven by short pinion: pass the
/// short pinion's tooth count and absolute speed as `zs`, `ws`).
pub fn planet_spin(zs: f64, zp: f64, ws: f64, wc: f64) -> f64 {
    -(zs / zp) * (ws - wc)
}

/// Spin relative to the carrier of a pinion (`zp`) meshing a ring (`zr`) internally [std]:
/// `ω_P − ω_C = (z_R/z_P)(ω_R − ω_C)` (the outer pinion of a double-pinion set, the long pinion
/// of a Ravigneaux set, or the planet of a simple set seen from the ring).
pub fn ring_pinion_spin(zr: f64, zp: f64, wr: f64, wc: f64) -> f64 {
    (zr / zp) * (wr - wc)
}

/// Carrier-frame mesh power [std]: `P = T·(ω − ω_C)` with T the torque the mesh applies to the
/// central gear (sun or ring, N·m), ω its speed and ω_C the carrier speed (rad/s); W.
/// Counted once for the set (all planets together carry T).
pub fn carrier_frame_mesh_power(torque: f64, w: f64, wc: f64) -> f64 {
    torque * (w - wc)
}

#[cfg(test)]
mod tests {
    use super::*;

    // 6HP26 member indices.
    const INPUT: usize = 0;
    const SUN1: usize = 1;
    const CARRIER1: usize = 2;
    const LARGE_SUN: usize = 3;
    const SMALL_SUN: usize = 4;
    const RAV_CARRIER: usize = 5;
    const OUTPUT: usize = 6;

    fn zf6hp26() -> GearTrain {
        let names = [
            "input",
            "sun1",
            "carrier1",
            "large_sun",
            "small_sun",
            "ravigneaux_carrier",
            "output",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let mut fixed = vec![
            Constraint::SimpleSet {
                sun: SUN1,
                ring: INPUT,
                carrier: CARRIER1,
                zs: 37.0,
                zr: 71.0,
            },
            Constraint::Brake { member: SUN1 }, // sun1 is part of the housing
        ];
        fixed.extend(Constraint::ravigneaux(
            LARGE_SUN,
            SMALL_SUN,
            OUTPUT,
            RAV_CARRIER,
            38.0,
            31.0,
            85.0,
        ));
        GearTrain::new(names, fixed).unwrap()
    }

    const A: Constraint = Constraint::Clutch {
        a: CARRIER1,
        b: SMALL_SUN,
    };
    const B: Constraint = Constraint::Clutch {
        a: CARRIER1,
        b: LARGE_SUN,
    };
    const C: Constraint = Constraint::Brake { member: LARGE_SUN };
    const D: Constraint = Constraint::Brake { member: RAV_CARRIER };
    const E: Constraint = Constraint::Clutch {
        a: INPUT,
        b: RAV_CARRIER,
    };

    /// (name, elements, published ratio, closed form from the tooth counts).
    fn states() -> Vec<(&'static str, Vec<Constraint>, f64, f64)> {
        let c = 71.0 / 108.0; // carrier1 speed per unit input speed
        vec![
            ("1", vec![A, D], 4.171, 85.0 / (31.0 * c)),
            ("2", vec![A, C], 2.340, 85.0 * 69.0 / (123.0 * 31.0 * c)),
            ("3", vec![A, B], 1.521, 1.0 / c),
            ("4", vec![A, E], 1.143, 9180.0 / 8033.0),
            ("5", vec![B, E], 0.867, 9180.0 / 10586.0),
            ("6", vec![C, E], 0.691, 85.0 / 123.0),
            ("R", vec![B, D], -3.403, -85.0 / (38.0 * c)),
        ]
    }

    #[test]
    fn zf6hp26_ratios() {
        let t = zf6hp26();
        for (name, el, published, exact) in states() {
            let s = t.solve_state(&el, INPUT, OUTPUT).unwrap();
            let r = s.ratio();
            // Published values are given to 3 decimals (4 significant digits): within half a unit.
            assert!((r - published).abs() <= 5e-4, "gear {name}: {r} vs {published}");
            assert!(
                ((r - exact) / exact).abs() < 1e-12,
                "gear {name}: {r} vs closed form {exact}"
            );
            assert_eq!(s.redundant_rows, 0);
            assert!((s.speeds[INPUT] - 1.0).abs() < 1e-15);
            for c in &s.constraints {
                assert!(c.residual(&s.speeds).abs() < 1e-12);
            }
        }
        let first = t.solve_state(&[A, D], INPUT, OUTPUT).unwrap().ratio();
        let exact = (108.0 / 71.0) * (85.0 / 31.0);
        assert!((first - exact).abs() < 1e-12);
    }

    #[test]
    fn zf6hp26_torques() {
        let t = zf6hp26();
        for (name, el, _, _) in states() {
            let s = t.solve_state(&el, INPUT, OUTPUT).unwrap();
            // Power balance, lossless: T_in ω_in + T_out ω_out = 0.
            let p = s.input_torque() * s.speeds[INPUT] + s.output_torque * s.speeds[OUTPUT];
            assert!(p.abs() < 1e-12, "gear {name}: power residual {p}");
            assert!((s.output_torque + s.ratio()).abs() < 1e-12);
            // Equilibrium of every member.
            for m in 0..t.n_members() {
                let res = s.external_torque(m) + s.constraint_torque_on_member(m);
                assert!(res.abs() < 1e-12, "gear {name}, member {m}: {res}");
            }
            // Each set row is in equilibrium and has the tooth-count ratios.
            for k in 0..s.constraints.len() {
                let sum: f64 = s.constraint_torques(k).iter().map(|&(_, t)| t).sum();
                if let Some(st) = s.set_torques(k) {
                    assert!((st.sun + st.ring + st.carrier).abs() < 1e-12);
                    assert!(sum.abs() < 1e-12);
                    if let Constraint::SimpleSet { zs, zr, .. } = s.constraints[k] {
                        assert!((st.sun * zr - st.ring * zs).abs() < 1e-12);
                    }
                    // Carrier-frame powers of sun and ring mesh are opposite.
                    let (ps, pr) = s.set_mesh_powers(k).unwrap();
                    assert!((ps + pr).abs() < 1e-12);
                }
                if let Constraint::Clutch { .. } = s.constraints[k] {
                    assert!(sum.abs() < 1e-12); // a clutch transmits, it does not react
                }
            }
            // Housing reaction: Σ brake torques = −(T_in + T_out) = ratio − 1.
            let brakes: f64 = (0..s.constraints.len())
                .filter(|&k| matches!(s.constraints[k], Constraint::Brake { .. }))
                .map(|k| s.multipliers[k])
                .sum();
            assert!((brakes - (s.ratio() - 1.0)).abs() < 1e-12, "gear {name}");
            // Ravigneaux carrier-frame powers sum to zero (carrier frame: carrier does no work).
            let rp = s.ravigneaux_mesh_powers(2, 3).unwrap();
            let sum = rp.large_sun_long + rp.small_sun_short + rp.long_ring;
            assert!(sum.abs() < 1e-12, "gear {name}: {sum}");
        }
    }

    #[test]
    fn zf6hp26_element_torques_analytic() {
        let t = zf6hp26();
        // 1st (A+D): no E, so the whole input torque enters the simple-set ring:
        // sun1 brake reacts z_S/z_R, clutch A carries (z_S + z_R)/z_R = 108/71 into small sun.
        let s = t.solve_state(&[A, D], INPUT, OUTPUT).unwrap();
        assert!((s.multipliers[1] - 37.0 / 71.0).abs() < 1e-12);
        // Clutch A applies λ to carrier1 (member a): carrier1 gets −108/71 from the clutch.
        assert!((s.element_torque(0) + 108.0 / 71.0).abs() < 1e-12);
        // Clutch A applies +108/71 to the small sun; the double-pinion row balances it with
        // −108/71 and applies (85/31)·(108/71) = +ratio to the ring, balanced by the load.
        let st = s.set_torques(3).unwrap();
        assert!((st.sun + 108.0 / 71.0).abs() < 1e-12);
        assert!((st.ring - s.ratio()).abs() < 1e-12);
        // The simple Ravigneaux row carries nothing (large sun free), so brake D takes the rest:
        // Σ brakes = ratio − 1.
        assert!(s.multipliers[2].abs() < 1e-12);
        let d = s.element_torque(1);
        assert!((d + 37.0 / 71.0 - (s.ratio() - 1.0)).abs() < 1e-12);
        // 3rd (A+B): block rotation, ratio 108/71; A and B share 108/71 (no redundancy).
        let s = t.solve_state(&[A, B], INPUT, OUTPUT).unwrap();
        let total = s.element_torque(0) + s.element_torque(1);
        assert!((total + 108.0 / 71.0).abs() < 1e-12);
        // Small sun equilibrium: clutch A applies −λ_A to it (member b), the double-pinion row
        // balances it.
        let st = s.set_torques(3).unwrap();
        assert!((st.sun - s.element_torque(0)).abs() < 1e-12);
    }

    #[test]
    fn two_gear_external_mesh() {
        let names = vec!["pinion".to_string(), "wheel".to_string()];
        let (z1, z2) = (20.0, 50.0);
        let t = GearTrain::new(
            names,
            vec![Constraint::ExternalMesh {
                a: 0,
                b: 1,
                za: z1,
                zb: z2,
            }],
        )
        .unwrap();
        let s = t.solve_state(&[], 0, 1).unwrap();
        assert!((s.ratio() + z2 / z1).abs() < 1e-14);
        assert!((s.speeds[1] + z1 / z2).abs() < 1e-14);
        // Torque on the wheel from the mesh = −(z2/z1)·T_in; load torque = +z2/z1.
        assert!((s.torque_on(0, 1) + z2 / z1).abs() < 1e-14);
        assert!((s.torque_on(0, 0) + 1.0).abs() < 1e-14);
        assert!((s.output_torque - z2 / z1).abs() < 1e-14);
        // λ = F_t·m/2: tooth force on the pinion = T/r = −1/(m z1/2) → λ = −1/z1.
        assert!((s.multipliers[0] + 1.0 / z1).abs() < 1e-15);
        // Scaling both tooth counts by k changes nothing but λ (by 1/k).
        let k = 3.0;
        let t2 = GearTrain::new(
            t.member_names().to_vec(),
            vec![Constraint::ExternalMesh {
                a: 0,
                b: 1,
                za: k * z1,
                zb: k * z2,
            }],
        )
        .unwrap();
        let s2 = t2.solve_state(&[], 0, 1).unwrap();
        assert!((s2.ratio() - s.ratio()).abs() < 1e-14);
        assert!((s2.multipliers[0] * k - s.multipliers[0]).abs() < 1e-15);
    }

    #[test]
    fn internal_mesh_and_simple_set_with_brake() {
        // Pinion inside ring: ratio ω_p/ω_r = z_r/z_p, same sense.
        let names = vec!["p".to_string(), "r".to_string()];
        let t = GearTrain::new(
            names,
            vec![Constraint::InternalMesh {
                pinion: 0,
                ring: 1,
                zp: 17.0,
                zr: 71.0,
            }],
        )
        .unwrap();
        let s = t.solve_state(&[], 0, 1).unwrap();
        assert!((s.ratio() - 71.0 / 17.0).abs() < 1e-13);
        // Simple set, ring held, sun in, carrier out: 1 + zr/zs.
        let names = ["s", "r", "c"].iter().map(|s| s.to_string()).collect();
        let set = Constraint::SimpleSet {
            sun: 0,
            ring: 1,
            carrier: 2,
            zs: 30.0,
            zr: 72.0,
        };
        let t = GearTrain::new(names, vec![set]).unwrap();
        let s = t.solve_state(&[Constraint::Brake { member: 1 }], 0, 2).unwrap();
        assert!((s.ratio() - (1.0 + 72.0 / 30.0)).abs() < 1e-13);
        let st = s.set_torques(0).unwrap();
        // Torques applied BY the set: it resists the unit input torque on the sun.
        assert!((st.sun + 1.0).abs() < 1e-13);
        assert!((st.ring + 72.0 / 30.0).abs() < 1e-13);
        assert!((st.carrier - 102.0 / 30.0).abs() < 1e-13);
        assert!((s.output_torque + 102.0 / 30.0).abs() < 1e-13);
        // The brake holds the ring against the set's torque.
        assert!((s.element_torque(0) - 72.0 / 30.0).abs() < 1e-13);
        // Double-pinion set, ring held, sun in, carrier out: ω_c = −zs/(zr − zs) ω_s.
        let names = ["s", "r", "c"].iter().map(|s| s.to_string()).collect();
        let set = Constraint::DoublePinionSet {
            sun: 0,
            ring: 1,
            carrier: 2,
            zs: 30.0,
            zr: 72.0,
        };
        let t = GearTrain::new(names, vec![set]).unwrap();
        let s = t.solve_state(&[Constraint::Brake { member: 1 }], 0, 2).unwrap();
        assert!((s.ratio() + 42.0 / 30.0).abs() < 1e-13);
    }

    #[test]
    fn planet_spin_consistency() {
        // Simple set: planet spin from the sun and from the ring agree (z_R = z_S + 2 z_P).
        let (zs, zr): (f64, f64) = (37.0, 71.0);
        let zp = (zr - zs) / 2.0;
        let (ws, wc): (f64, f64) = (0.0, 71.0 / 108.0);
        let wr = 1.0;
        assert!((zs * (ws - wc) + zr * (wr - wc)).abs() < 1e-14, "set row holds");
        let a = planet_spin(zs, zp, ws, wc);
        let b = ring_pinion_spin(zr, zp, wr, wc);
        assert!((a - b).abs() < 1e-14);
        // Double pinion: sun → short → long must agree with ring → long, for any tooth counts.
        let t = zf6hp26();
        let s = t.solve_state(&[A, C], INPUT, OUTPUT).unwrap();
        let w = &s.speeds;
        let (z_short, z_long) = (19.0, 24.0);
        let wc = w[RAV_CARRIER];
        let short_rel = planet_spin(31.0, z_short, w[SMALL_SUN], wc);
        let long_from_short = planet_spin(z_short, z_long, short_rel + wc, wc);
        let long_from_ring = ring_pinion_spin(85.0, z_long, w[OUTPUT], wc);
        let long_from_large_sun = planet_spin(38.0, z_long, w[LARGE_SUN], wc);
        assert!((long_from_short - long_from_ring).abs() < 1e-13);
        assert!((long_from_large_sun - long_from_ring).abs() < 1e-13);
        assert_eq!(carrier_frame_mesh_power(2.0, 3.0, 1.0), 4.0);
    }

    #[test]
    fn under_determined_names_free_members() {
        let t = zf6hp26();
        match t.solve_state(&[A], INPUT, OUTPUT) {
            Err(KinematicsError::UnderDetermined { free_members, dof }) => {
                assert_eq!(dof, 1);
                assert_eq!(free_members, vec!["large_sun", "ravigneaux_carrier", "output"]);
            }
            other => panic!("expected UnderDetermined, got {other:?}"),
        }
        // Neutral (nothing engaged): two free DOF in the Ravigneaux.
        match t.solve_state(&[], INPUT, OUTPUT) {
            Err(KinematicsError::UnderDetermined { free_members, dof }) => {
                assert_eq!(dof, 2);
                assert_eq!(free_members.len(), 4);
            }
            other => panic!("expected UnderDetermined, got {other:?}"),
        }
        let msg = t.solve_state(&[A], INPUT, OUTPUT).unwrap_err().to_string();
        assert!(msg.contains("ravigneaux_carrier"));
    }

    #[test]
    fn over_constrained_names_elements() {
        let t = zf6hp26();
        match t.solve_state(&[A, D, C], INPUT, OUTPUT) {
            Err(KinematicsError::OverConstrained {
                locked_members,
                removable_elements,
            }) => {
                assert_eq!(locked_members.len(), 7);
                // Releasing D gives 2nd, releasing C gives 1st; releasing A holds the output.
                let idx: Vec<usize> = removable_elements.iter().map(|e| e.index).collect();
                assert_eq!(idx, vec![1, 2]);
                assert!(removable_elements[1].description.contains("large_sun"));
            }
            other => panic!("expected OverConstrained, got {other:?}"),
        }
        // Input held by a brake while the rest could still move: input locked.
        let err = t
            .solve_state(&[Constraint::Brake { member: INPUT }], INPUT, OUTPUT)
            .unwrap_err();
        match err {
            KinematicsError::OverConstrained { locked_members, .. } => {
                assert!(locked_members.contains(&"input".to_string()));
                assert!(locked_members.contains(&"carrier1".to_string()));
                assert!(!locked_members.contains(&"output".to_string()));
            }
            other => panic!("expected OverConstrained, got {other:?}"),
        }
        // Output held (C + D lock the Ravigneaux set).
        assert_eq!(
            t.solve_state(&[C, D], INPUT, OUTPUT).unwrap_err(),
            KinematicsError::OutputAtRest {
                output: "output".into()
            }
        );
    }

    #[test]
    fn degenerate_and_redundant_elements() {
        let t = zf6hp26();
        // Clutch joining a member to itself: a zero row, harmless.
        let selfc = Constraint::Clutch {
            a: CARRIER1,
            b: CARRIER1,
        };
        let s = t.solve_state(&[A, D, selfc], INPUT, OUTPUT).unwrap();
        assert_eq!(s.redundant_rows, 1);
        assert!(s.element_torque(2).abs() < 1e-12);
        assert!(s.constraint_torques(s.n_fixed + 2).is_empty());
        assert!(matches!(
            t.solve_state(&[A, selfc], INPUT, OUTPUT),
            Err(KinematicsError::UnderDetermined { dof: 1, .. })
        ));
        // The same clutch twice: same kinematics, torque split between the two copies.
        let single = t.solve_state(&[A, D], INPUT, OUTPUT).unwrap();
        let double = t.solve_state(&[A, A, D], INPUT, OUTPUT).unwrap();
        assert_eq!(double.redundant_rows, 1);
        assert!((double.ratio() - single.ratio()).abs() < 1e-12);
        let sum = double.element_torque(0) + double.element_torque(1);
        assert!((sum - single.element_torque(0)).abs() < 1e-12);
        assert!((double.element_torque(0) - double.element_torque(1)).abs() < 1e-12);
        let p = double.speeds[INPUT] + double.output_torque * double.speeds[OUTPUT];
        assert!(p.abs() < 1e-12);
    }

    #[test]
    fn invalid_input_is_reported() {
        let t = zf6hp26();
        assert!(matches!(
            t.solve_state(&[Constraint::Brake { member: 9 }], INPUT, OUTPUT),
            Err(KinematicsError::InvalidMember { index: 9, .. })
        ));
        assert!(matches!(
            t.solve_state(&[A, D], INPUT, 7),
            Err(KinematicsError::InvalidMember { index: 7, .. })
        ));
        assert!(matches!(
            t.solve_state(&[A, D], OUTPUT, OUTPUT),
            Err(KinematicsError::InputIsOutput { .. })
        ));
        let bad = Constraint::ExternalMesh {
            a: 0,
            b: 1,
            za: f64::NAN,
            zb: 10.0,
        };
        assert!(matches!(
            GearTrain::new(vec!["a".into(), "b".into()], vec![bad]),
            Err(KinematicsError::InvalidToothCount { .. })
        ));
        assert!(matches!(
            GearTrain::new(vec!["a".into()], vec![]),
            Err(KinematicsError::TooFewMembers { n_members: 1 })
        ));
        assert!(t.clone().with_rank_tolerance(0.0).is_err());
        assert_eq!(t.member_index("output"), Some(OUTPUT));
    }

    #[test]
    fn member_order_does_not_matter() {
        // Permute the members of the 6HP26 model: the ratios must not change.
        let t = zf6hp26();
        let n = t.n_members();
        let perm = [4usize, 6, 0, 2, 5, 1, 3]; // old index → new index
        let map = |c: &Constraint| -> Constraint {
            match *c {
                Constraint::SimpleSet {
                    sun,
                    ring,
                    carrier,
                    zs,
                    zr,
                } => Constraint::SimpleSet {
                    sun: perm[sun],
                    ring: perm[ring],
                    carrier: perm[carrier],
                    zs,
                    zr,
                },
                Constraint::DoublePinionSet {
                    sun,
                    ring,
                    carrier,
                    zs,
                    zr,
                } => Constraint::DoublePinionSet {
                    sun: perm[sun],
                    ring: perm[ring],
                    carrier: perm[carrier],
                    zs,
                    zr,
                },
                Constraint::Clutch { a, b } => Constraint::Clutch {
                    a: perm[a],
                    b: perm[b],
                },
                Constraint::Brake { member } => Constraint::Brake { member: perm[member] },
                other => other,
            }
        };
        let mut names = vec![String::new(); n];
        for (old, name) in t.member_names().iter().enumerate() {
            names[perm[old]] = name.clone();
        }
        let tp = GearTrain::new(names, t.fixed().iter().map(map).collect()).unwrap();
        for (name, el, _, _) in states() {
            let r0 = t.solve_state(&el, INPUT, OUTPUT).unwrap().ratio();
            let elp: Vec<Constraint> = el.iter().map(map).collect();
            let r1 = tp.solve_state(&elp, perm[INPUT], perm[OUTPUT]).unwrap().ratio();
            assert!((r0 - r1).abs() < 1e-12 * r0.abs(), "gear {name}");
        }
    }
}
