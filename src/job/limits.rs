//! The allowed range of every numeric job option, written once. A message names the option as
//! study files and Python do (`speed_rpm`); the command line adds its flag
//! ([`super::options::spelled_for_cli`]).

use super::JobError;
use crate::solve::equilibrium::OIL_RANGE_C;

/// A closed range of a numeric option.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    /// The option's name in study files and Python (`speed_rpm`).
    pub name: &'static str,
    /// Least allowed value.
    pub lo: f64,
    /// Greatest allowed value.
    pub hi: f64,
    /// Unit as printed after a value (empty for none).
    pub unit: &'static str,
}

impl Limit {
    /// `[lo, hi] unit`.
    pub fn allowed(&self) -> String {
        format!("[{}, {}]{}", short(self.lo), short(self.hi), self.unit_suffix())
    }

    fn unit_suffix(&self) -> String {
        if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        }
    }

    /// `v` if it is finite and inside the range, else the option error naming it.
    pub fn check(&self, v: f64) -> Result<f64, JobError> {
        if v.is_finite() && (self.lo..=self.hi).contains(&v) {
            return Ok(v);
        }
        Err(JobError::option(
            self.name,
            short(v),
            self.allowed(),
            format!(
                "{} = {}{}: must lie in {}",
                self.name,
                short(v),
                self.unit_suffix(),
                self.allowed()
            ),
        ))
    }

    /// Check an optional value.
    pub fn check_opt(&self, v: Option<f64>) -> Result<Option<f64>, JobError> {
        v.map(|x| self.check(x)).transpose()
    }
}

/// A number as a user typed it: plain in the usual range, in exponent form outside it (so that
/// 1e-300 is not printed with 300 zeros).
pub fn short(x: f64) -> String {
    if x == 0.0 || (1e-4..1e9).contains(&x.abs()) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Input shaft speed, rpm (the cycle parser holds input speeds to the same bound).
pub const SPEED_RPM: Limit = Limit {
    name: "speed_rpm",
    lo: 0.0,
    hi: 50_000.0,
    unit: "rpm",
};

/// Input torque of an equilibrium, N·m (negative: overrun).
pub const TORQUE_NM: Limit = Limit {
    name: "torque_nm",
    lo: -1e6,
    hi: 1e6,
    unit: "N m",
};

/// Input torque of a loss evaluation, N·m (drive only: the loss report's efficiency assumes
/// power flows from input to output).
pub const DRIVE_TORQUE_NM: Limit = Limit {
    name: "torque_nm",
    lo: 0.0,
    hi: 1e6,
    unit: "N m",
};

/// Oil temperature of a loss evaluation, °C: the widest oil range of the envelope
/// ([`OIL_RANGE_C`]); each job narrows it to its oil's range
/// ([`super::envelope::OilRange`]), where the Walther fit holds.
pub const OIL_TEMP_C: Limit = Limit {
    name: "oil_temp_c",
    lo: OIL_RANGE_C.0,
    hi: OIL_RANGE_C.1,
    unit: "°C",
};

/// Initial temperature of every node (the oil's among them), °C: as [`OIL_TEMP_C`].
pub const INITIAL_TEMP_C: Limit = Limit {
    name: "initial_temp_c",
    lo: OIL_RANGE_C.0,
    hi: OIL_RANGE_C.1,
    unit: "°C",
};

/// Ambient temperature, °C: arctic cold to an engine bay's hottest air.
pub const AMBIENT_C: Limit = Limit {
    name: "ambient_c",
    lo: -60.0,
    hi: 150.0,
    unit: "°C",
};

/// Temperature at which the oil properties are frozen, °C: as [`OIL_TEMP_C`].
pub const FROZEN_VISCOSITY_C: Limit = Limit {
    name: "frozen_viscosity_c",
    lo: OIL_RANGE_C.0,
    hi: OIL_RANGE_C.1,
    unit: "°C",
};

/// Relative tolerance of the transient solvers.
pub const RTOL: Limit = Limit {
    name: "rtol",
    lo: 1e-14,
    hi: 1e-1,
    unit: "",
};

/// Absolute tolerance on temperatures, K.
pub const ATOL: Limit = Limit {
    name: "atol",
    lo: 1e-14,
    hi: 1.0,
    unit: "K",
};

/// Vehicle speed for h(v) links at an equilibrium, km/h.
pub const VEHICLE_SPEED_KMH: Limit = Limit {
    name: "vehicle_speed_kmh",
    lo: 0.0,
    hi: 400.0,
    unit: "km/h",
};

/// Step budget of a transient run.
pub const MAX_STEPS: Limit = Limit {
    name: "max_steps",
    lo: 1.0,
    hi: 1e9,
    unit: "",
};

/// Tightest tolerance of the work-precision sweep.
pub const MIN_RTOL: Limit = Limit {
    name: "min_rtol",
    lo: 1e-13,
    hi: 1e-3,
    unit: "",
};

/// Repeats per work-precision point (the median wall time is kept).
pub const REPEATS: Limit = Limit {
    name: "repeats",
    lo: 1.0,
    hi: 1000.0,
    unit: "",
};

/// Oil temperature limit of a thermal rating, °C: the steady solver's valid oil range
/// (`solve::equilibrium::OIL_RANGE_C`; above it an equilibrium is not sought).
pub const OIL_LIMIT_C: Limit = Limit {
    name: "oil_limit_c",
    lo: -60.0,
    hi: 200.0,
    unit: "°C",
};

/// Lowest input torque a thermal rating searches, N·m (drive only).
pub const RATING_TORQUE_MIN_NM: Limit = Limit {
    name: "torque_min_nm",
    lo: 0.0,
    hi: 1e6,
    unit: "N m",
};

/// Highest input torque a thermal rating searches (its ceiling), N·m.
pub const RATING_TORQUE_MAX_NM: Limit = Limit {
    name: "torque_max_nm",
    lo: 0.0,
    hi: 1e6,
    unit: "N m",
};

/// Every limit, for tables and tests.
pub const ALL: [Limit; 18] = [
    THREADS,
    SPEED_RPM,
    TORQUE_NM,
    DRIVE_TORQUE_NM,
    OIL_TEMP_C,
    INITIAL_TEMP_C,
    AMBIENT_C,
    FROZEN_VISCOSITY_C,
    RTOL,
    ATOL,
    VEHICLE_SPEED_KMH,
    MAX_STEPS,
    MIN_RTOL,
    REPEATS,
    MAP_AXIS_POINTS,
    OIL_LIMIT_C,
    RATING_TORQUE_MIN_NM,
    RATING_TORQUE_MAX_NM,
];

/// Threads of one batch of study cases in Python (`threads_per_task`): one per core is the
/// most that helps (more only share the same cores, each with its own stack); 1024 covers the
/// largest machines; a million would each be started before the first case runs.
pub const THREADS: Limit = Limit {
    name: "threads_per_task",
    lo: 1.0,
    hi: 1024.0,
    unit: "",
};

/// Points per map axis.
pub const MAP_AXIS_POINTS: Limit = Limit {
    name: "map_axis_points",
    lo: 1.0,
    hi: 2000.0,
    unit: "",
};

/// Most points of a map (N_speed × N_torque): each equilibrium keeps its losses and solver
/// state (about 5 kB), and a 2-core machine solves about 1000 points per second; beyond this a
/// map is a study (`geartherm study`), not a map.
pub const MAX_MAP_POINTS: usize = 40_000;
