//! `rating`: the thermal rating of a gear state as transmission engineers use it — at each
//! input speed, the highest input torque (and power) whose equilibrium oil temperature stays at
//! or below a limit, with the losses and temperatures at that point; over a speed sweep, the
//! thermal rating curve (`rating.csv`, `rating.json`, `rating.png`). The search is
//! [`search::search`]; each equilibrium is the steady solver's, checked like `steady`'s.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::scene::{OperatingPoint, RangeLog, RangeWarning, Scene};
use crate::solve::equilibrium::Equilibrium;

use super::envelope::{Envelope, OilRange};
use super::limits::{self, short};
use super::steady::{self, point_scene, SteadyOptions, SteadyResult};
use super::{JobError, Model};
use crate::physics::units::{c_to_k, k_to_c, kmh_to_m_s, rpm_to_rad_s};

mod search;

pub use search::{Status, TOLERANCE_K};

/// Options of a thermal rating (`geartherm rating`, `Model.rating`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RatingOptions {
    /// Gear-state name.
    pub gear: String,
    /// Input speeds, rpm: one value (a rating point) or several (the rating curve).
    pub speed_rpm: Vec<f64>,
    /// Oil temperature limit, °C.
    pub oil_limit_c: f64,
    /// Vehicle speed for h(v) links, km/h.
    #[serde(default)]
    pub vehicle_speed_kmh: f64,
    /// Ambient temperature, °C (None: the model's).
    #[serde(default)]
    pub ambient_c: Option<f64>,
    /// Lowest input torque searched, N·m.
    #[serde(default)]
    pub torque_min_nm: f64,
    /// Highest input torque searched (the ceiling), N·m (None: [`DEFAULT_CEILING_NM`]).
    #[serde(default)]
    pub torque_max_nm: Option<f64>,
}

/// The torque ceiling without `torque_max_nm`: the largest input torque any job accepts (a model
/// file states no torque capacity).
pub const DEFAULT_CEILING_NM: f64 = limits::RATING_TORQUE_MAX_NM.hi;

impl RatingOptions {
    /// The torque ceiling, N·m.
    pub fn ceiling(&self) -> f64 {
        self.torque_max_nm.unwrap_or(DEFAULT_CEILING_NM)
    }

    /// Every range check of the options but the gear, which needs the model.
    pub fn check(&self) -> Result<(), JobError> {
        let n = self.speed_rpm.len();
        if n == 0 || n as f64 > limits::MAP_AXIS_POINTS.hi {
            return Err(JobError::option(
                "speed_rpm",
                n,
                format!("1 to {} speeds", limits::MAP_AXIS_POINTS.hi),
                format!(
                    "speed_rpm: {n} speeds; a rating takes 1 to {} speeds",
                    limits::MAP_AXIS_POINTS.hi
                ),
            ));
        }
        for &s in &self.speed_rpm {
            limits::SPEED_RPM.check(s)?;
        }
        limits::OIL_LIMIT_C.check(self.oil_limit_c)?;
        limits::RATING_TORQUE_MIN_NM.check(self.torque_min_nm)?;
        let hi = limits::RATING_TORQUE_MAX_NM.check(self.ceiling())?;
        if hi <= self.torque_min_nm {
            return Err(JobError::option(
                "torque_max_nm",
                short(hi),
                format!("above torque_min_nm = {}", short(self.torque_min_nm)),
                format!(
                    "torque_max_nm = {} N m: must lie above torque_min_nm = {} N m",
                    short(hi),
                    short(self.torque_min_nm)
                ),
            ));
        }
        steady::check_point(self.vehicle_speed_kmh, self.ambient_c)
    }
}

/// The rating at one input speed.
#[derive(Debug, Clone, Serialize)]
pub struct RatingPoint {
    /// Input speed, rpm.
    pub speed_rpm: f64,
    /// Rated input torque, N·m.
    pub rated_torque_nm: f64,
    /// Rated input power T·ω, W.
    pub rated_power_w: f64,
    /// Equilibrium oil temperature at the rated torque, °C.
    pub oil_temp_c: f64,
    /// Total loss at the rated torque, W (`loss_total_w`, docs/outputs.md).
    #[serde(rename = "loss_total_w")]
    pub total_loss_w: f64,
    /// Efficiency at the rated torque (None at zero power).
    pub efficiency: Option<f64>,
    /// How the rating was found.
    pub status: Status,
    /// The equilibrium oil temperature fell with rising torque somewhere in the search: a
    /// higher torque may also meet the limit.
    pub non_monotonic: bool,
    /// Equilibria solved for this point.
    pub equilibria: usize,
    /// The equilibrium at the rated torque: temperatures, losses per item and source.
    pub equilibrium: SteadyResult,
}

impl RatingPoint {
    /// The flags as written in `rating.csv`: the status, `;non_monotonic` when set,
    /// `;limit_cycle` when a controller cycles at the rated torque (no equilibrium: the oil
    /// temperature is the cycle's mean, its band in `equilibrium.limit_cycle`).
    pub fn flags(&self) -> String {
        let mut f = self.status.as_str().to_string();
        if self.non_monotonic {
            f.push_str(";non_monotonic");
        }
        if self.equilibrium.limit_cycle.is_some() {
            f.push_str(";limit_cycle");
        }
        f
    }
}

/// A thermal rating (the `rating.json` document).
#[derive(Debug, Clone, Serialize)]
pub struct RatingResult {
    /// Model name.
    pub model: String,
    /// Gear-state name.
    pub gear: String,
    /// Oil temperature limit, °C.
    pub oil_limit_c: f64,
    /// The rated torque's equilibrium lies in [limit − tolerance, limit], K.
    pub tolerance_k: f64,
    /// Ambient temperature set by the options, °C (None: the model's).
    pub ambient_c: Option<f64>,
    /// Vehicle speed for h(v) links, km/h.
    pub vehicle_speed_kmh: f64,
    /// Torques searched, N·m.
    pub torque_min_nm: f64,
    /// Torques searched (the ceiling), N·m.
    pub torque_max_nm: f64,
    /// One rating per input speed, in the order given.
    pub points: Vec<RatingPoint>,
    /// Loss models used outside their fitted range at the rated points.
    pub warnings: Vec<RangeWarning>,
    /// Wall time, s.
    pub wall_time_s: f64,
}

impl RatingResult {
    /// The `rating.csv` text: one row per speed.
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "speed_rpm,rated_torque_nm,rated_power_kw,oil_temp_c,loss_total_w,efficiency,flags\n",
        );
        for p in &self.points {
            s.push_str(&format!(
                "{},{},{},{},{},{},{}\n",
                p.speed_rpm,
                p.rated_torque_nm,
                p.rated_power_w / 1e3,
                p.oil_temp_c,
                p.total_loss_w,
                p.efficiency.map_or(String::new(), |e| e.to_string()),
                p.flags()
            ));
        }
        s
    }

    /// The files of a rating's output directory: `rating.csv` and `rating.json`.
    pub fn files(&self) -> Result<Vec<(&'static str, Vec<u8>)>, JobError> {
        let json = serde_json::to_vec_pretty(self)
            .map_err(|e| JobError::numerical(format!("cannot serialise rating.json: {e}")))?;
        Ok(vec![
            ("rating.csv", self.csv().into_bytes()),
            ("rating.json", json),
        ])
    }

    /// The rating curve for `rating.png`.
    pub fn curve(&self) -> crate::report::plots::rating::Curve {
        use crate::report::plots::rating::{Curve, CurvePoint};
        Curve {
            model: self.model.clone(),
            gear: self.gear.clone(),
            oil_limit_c: self.oil_limit_c,
            ambient: self.ambient_c.map_or("the model's ambient".into(), |a| {
                format!("ambient {} °C", short(a))
            }),
            points: self
                .points
                .iter()
                .map(|p| CurvePoint {
                    speed_rpm: p.speed_rpm,
                    torque_nm: p.rated_torque_nm,
                    power_kw: p.rated_power_w / 1e3,
                    ceiling: p.status == Status::Ceiling,
                    at_minimum: p.status == Status::LimitAtMinimum,
                })
                .collect(),
        }
    }
}

/// A checked rating with its compiled scene, ready to solve.
pub struct Prepared {
    scene: Scene,
    state: usize,
}

/// Check the options and compile the scene: everything that can fail as invalid input.
pub fn prepare(m: &Model, o: &RatingOptions) -> Result<Prepared, JobError> {
    o.check()?;
    OilRange::of(&m.gearbox.oil).check_option(&limits::OIL_LIMIT_C, o.oil_limit_c)?;
    let (scene, state) = point_scene(m, &o.gear, o.vehicle_speed_kmh, o.ambient_c)?;
    Ok(Prepared { scene, state })
}

/// The thermal rating at every speed of `o`; `tick` is called once per speed (progress).
pub fn rating(m: &Model, o: &RatingOptions, tick: &(dyn Fn() + Sync)) -> Result<RatingResult, JobError> {
    solve(m, o, &prepare(m, o)?, tick)
}

/// Solve a prepared rating (the second half of [`rating`]). A speed without an equilibrium
/// (other than one too hot for the limit) fails the whole rating, naming the point.
pub fn solve(
    m: &Model,
    o: &RatingOptions,
    p: &Prepared,
    tick: &(dyn Fn() + Sync),
) -> Result<RatingResult, JobError> {
    let start = std::time::Instant::now();
    let limit_k = c_to_k(o.oil_limit_c);
    let (t_min, t_max) = (o.torque_min_nm, o.ceiling());
    let found: Vec<Result<search::Outcome<Equilibrium>, (f64, f64, String)>> = o
        .speed_rpm
        .par_iter()
        .map(|&rpm| {
            let point = search::Point {
                scene: &p.scene,
                state: p.state,
                speed: rpm_to_rad_s(rpm),
                vehicle_speed: kmh_to_m_s(o.vehicle_speed_kmh),
                limit_k,
            };
            let r = search::search(&point, t_min, t_max).map_err(|(t, why)| (rpm, t, why));
            tick();
            r
        })
        .collect();
    let mut points = Vec::with_capacity(found.len());
    let envelope = Envelope::of(&p.scene);
    for (r, &rpm) in found.into_iter().zip(&o.speed_rpm) {
        let s = r.and_then(|s| match steady::check_envelope(&envelope, &s.payload) {
            Ok(()) => Ok(s),
            Err(why) => Err((rpm, s.torque, why)),
        });
        let s = s.map_err(|(rpm, t, why)| {
            JobError::numerical(format!(
                "{}: rating of gear {} at {} rpm failed at {} N m: {why}; nothing written",
                m.label(),
                o.gear,
                short(rpm),
                short(t)
            ))
        })?;
        points.push(point(m, o, p, rpm, s));
    }
    Ok(RatingResult {
        model: m.gearbox.name.clone(),
        gear: o.gear.clone(),
        oil_limit_c: o.oil_limit_c,
        tolerance_k: TOLERANCE_K,
        ambient_c: o.ambient_c,
        vehicle_speed_kmh: o.vehicle_speed_kmh,
        torque_min_nm: t_min,
        torque_max_nm: t_max,
        warnings: warnings(p, &points),
        points,
        wall_time_s: start.elapsed().as_secs_f64(),
    })
}

/// The rating point of a finished search, with its equilibrium as `steady` reports it.
fn point(
    m: &Model,
    o: &RatingOptions,
    p: &Prepared,
    rpm: f64,
    s: search::Outcome<Equilibrium>,
) -> RatingPoint {
    let so = SteadyOptions {
        gear: o.gear.clone(),
        speed_rpm: rpm,
        torque_nm: s.torque,
        vehicle_speed_kmh: o.vehicle_speed_kmh,
        ambient_c: o.ambient_c,
    };
    let eq = steady::result(m, &so, &p.scene, p.state, &s.payload);
    RatingPoint {
        speed_rpm: rpm,
        rated_torque_nm: s.torque,
        rated_power_w: s.payload.power,
        oil_temp_c: k_to_c(s.payload.solution.temperatures[p.scene.thermal().oil]),
        total_loss_w: eq.total_loss_w,
        efficiency: eq.efficiency,
        status: s.status,
        non_monotonic: s.non_monotonic,
        equilibria: s.probes,
        equilibrium: eq,
    }
}

/// The range warnings over every rated point, one per item and range.
fn warnings(p: &Prepared, points: &[RatingPoint]) -> Vec<RangeWarning> {
    let losses = p.scene.losses();
    let mut log = RangeLog::new(losses);
    for r in points {
        log.check(
            losses,
            &OperatingPoint {
                state: p.state,
                input_speed: rpm_to_rad_s(r.speed_rpm),
                input_torque: r.rated_torque_nm,
                oil: p.scene.thermal().oil_properties(c_to_k(r.oil_temp_c)),
            },
        );
    }
    log.warnings(losses)
}
