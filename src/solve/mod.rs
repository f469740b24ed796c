//! Solvers: the transient driver (diffsol) and the steady-state equilibrium search.
pub mod dense_lu;
pub mod drive;
pub(crate) mod driver;
pub mod equations;
pub mod equilibrium;
pub(crate) mod events;
pub mod limit_cycle;
pub mod rosenbrock;
pub mod rows;
pub mod sensitivity;
pub mod sparse_lu;
pub mod steady;
pub mod sweep;
pub mod trajectory;
pub mod transient;
pub mod transient_options;
pub mod work_precision;
