//! Options of a transient run: the integration method, the linear algebra of the implicit
//! methods, the restart policy, the tolerances and the pitfall guards (docs/numerics.md).

/// Linear algebra of the implicit methods' Newton iterations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinearAlgebra {
    /// Dense below [`SPARSE_FROM_STATES`] states, sparse from there on.
    Auto,
    /// Dense matrices and LU (nalgebra).
    Dense,
    /// Compressed-column matrices and faer's sparse LU (fill-reducing ordering, symbolic
    /// factorisation once per solve).
    Sparse,
}

/// State count from which [`LinearAlgebra::Auto`] uses the sparse LU (the measured crossover,
/// docs/performance.md "Sparse networks and the integration floor").
pub const SPARSE_FROM_STATES: usize = 50;

impl LinearAlgebra {
    /// True when a solve of `states` states uses the sparse LU.
    pub fn is_sparse(self, states: usize) -> bool {
        match self {
            LinearAlgebra::Auto => states >= SPARSE_FROM_STATES,
            LinearAlgebra::Dense => false,
            LinearAlgebra::Sparse => true,
        }
    }
}

/// Integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Variable-order BDF (1–5), implicit multistep.
    Bdf,
    /// ESDIRK3(4), L-stable singly diagonally implicit Runge–Kutta.
    Esdirk34,
    /// TR-BDF2, L-stable one-step method of order 2.
    TrBdf2,
    /// Tsitouras 5(4), explicit (not for stiff networks).
    Tsit45,
    /// ROS3, three-stage Rosenbrock method of order 3, L-stable, two evaluations of f per step
    /// ([`super::rosenbrock::ROS3`]).
    Ros3,
    /// ROS3 for networks of up to [`ROS3_MAX_NODES`] nodes, TR-BDF2 above (the default).
    Auto,
}

/// Largest network (capacity nodes) [`Method::Auto`] integrates with ROS3. ROS3 factorises the
/// node block at every step, TR-BDF2 keeps its LU over ≈ 7 steps: measured on the AT6 with a
/// meshed housing over the WLTC (docs/numerics.md, "ROS3"), ROS3 is 1.2–1.3× faster up to 15
/// nodes, the two tie at 20–25 nodes, and TR-BDF2 wins above (1.15× at 30–35 nodes, 4× at 1005).
pub const ROS3_MAX_NODES: usize = 24;

impl Method {
    /// All methods.
    pub const ALL: [Method; 6] = [
        Method::Bdf,
        Method::Esdirk34,
        Method::TrBdf2,
        Method::Tsit45,
        Method::Ros3,
        Method::Auto,
    ];

    /// Command-line name.
    pub const fn name(self) -> &'static str {
        match self {
            Method::Bdf => "bdf",
            Method::Esdirk34 => "esdirk34",
            Method::TrBdf2 => "tr-bdf2",
            Method::Tsit45 => "tsit45",
            Method::Ros3 => "ros3",
            Method::Auto => "auto",
        }
    }

    /// Parse a command-line name.
    pub fn parse(s: &str) -> Option<Method> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s || m.name().replace('-', "_") == s)
    }

    /// True for implicit methods.
    pub fn is_implicit(self) -> bool {
        self != Method::Tsit45
    }

    /// The method used for a network of `nodes` capacity nodes ([`Method::Auto`] resolved).
    pub fn resolve(self, nodes: usize) -> Method {
        match self {
            Method::Auto if nodes <= ROS3_MAX_NODES => Method::Ros3,
            Method::Auto => Method::TrBdf2,
            m => m,
        }
    }
}

/// When the integrator is restarted at a segment boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Restart {
    /// Only where the inputs change.
    AtJumps,
    /// At every segment boundary.
    EveryInterval,
    /// Never: the error control alone handles input jumps.
    Never,
}

/// Options of a transient run.
#[derive(Debug, Clone)]
pub struct TransientOptions {
    /// Method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance on temperatures, K (energies get `atol` × the mean node capacity, J).
    pub atol: f64,
    /// Restart policy.
    pub restart: Restart,
    /// Step budget for the whole run (the run fails with a clear message beyond it).
    pub max_steps: usize,
    /// Initial temperature of every node, K (None: the model's).
    pub initial_temp: Option<f64>,
    /// Guards against the diffsol pitfalls of docs/numerics.md (all on by default; the tests
    /// switch each off to show what it prevents).
    pub guards: Guards,
    /// Evaluate and keep the loss of every item at every output time (`Trajectory::losses`, for
    /// timeseries.csv and the plots); off when those outputs are not asked for.
    pub record_losses: bool,
    /// Dense or sparse linear algebra (default: by size).
    pub linear_algebra: LinearAlgebra,
    /// Assemble the Jacobian entry by entry (default). Off: one Jacobian–vector product per
    /// column (dense only; for measuring the difference).
    pub assembled_jacobian: bool,
}

/// Pitfall guards of the driver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Guards {
    /// Pitfall 1: raise `max_nonlinear_solver_failures` (a lifetime count in diffsol).
    pub raise_failure_limit: bool,
    /// Pitfall 4: re-estimate the step size at a restart.
    pub reset_step: bool,
    /// Pitfall 6: set `dy = f(t⁺, y)` at a restart.
    pub refresh_derivative: bool,
}

impl Default for Guards {
    fn default() -> Self {
        Self {
            raise_failure_limit: true,
            reset_step: true,
            refresh_derivative: true,
        }
    }
}

/// Default method (ROS3 on lumped networks, TR-BDF2 on large ones: docs/numerics.md "ROS3").
pub const DEFAULT_METHOD: Method = Method::Auto;
/// Default relative tolerance (docs/numerics.md).
pub const DEFAULT_RTOL: f64 = 1e-4;
/// Default absolute tolerance on temperatures, K.
pub const DEFAULT_ATOL: f64 = 1e-6;

impl Default for TransientOptions {
    fn default() -> Self {
        Self {
            method: DEFAULT_METHOD,
            rtol: DEFAULT_RTOL,
            atol: DEFAULT_ATOL,
            restart: Restart::AtJumps,
            max_steps: 5_000_000,
            initial_temp: None,
            guards: Guards::default(),
            record_losses: true,
            linear_algebra: LinearAlgebra::Auto,
            assembled_jacobian: true,
        }
    }
}
