//! Cycle → gearbox input schedule: one piecewise-constant [`Interval`] per cycle interval
//! [t_k, t_{k+1}) with gear, input speed and torque (SI).
//!
//! Vehicle cycles \[std + derived\]: the speed is taken linear between rows (the trapezoidal
//! reading of a 1 Hz trace), so over an interval a = (v1−v0)/Δt is constant and the exact means
//! are mean(v) = (v0+v1)/2, mean(v²) = (v0²+v0·v1+v1²)/3, mean(v³) = (v0+v1)(v0²+v1²)/4.
//! The interval's output power is the exact mean of F_w·v (see [`Vehicle::demand`]); the input
//! speed is the mean one, ω_in = mean(v)·i_final·|i_gear|/r_w; the input torque is
//! T_in = P/ω_in, so that T_in·ω_in·Δt is the exact traction energy of the interval. (In force
//! terms it differs from mean(F_w) by f1·Δv²/(12·mean(v)) + f2·Δv²/6, Δv = v1 − v0: negligible,
//! and it keeps the energy balance exact.) Overrun `zero` clips the interval mean at zero (the
//! service brakes take the negative part); `transmit` keeps the sign.
//! Standstill (both end speeds ≤ the threshold): input speed, torque and power are zero.
//!
//! Rig cycles: zero-order hold of each row's input speed, torque and gear over [t_k, t_{k+1});
//! loss-free output power = T_in·ω_in. The last row only closes the last interval.

use super::error::{CycleError, CycleErrorKind};
pub use super::gears::GearTable;
use super::launch::LaunchDevice;
use super::parse::{CycleKind, DriveCycle};
use super::shift::Shifter;
use super::vehicle::{Overrun, Vehicle};

/// Gearbox inputs, constant over [t0, t1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Start, s.
    pub t0: f64,
    /// End, s.
    pub t1: f64,
    /// Mean vehicle speed, m/s (0 for rig cycles).
    pub vehicle_speed: f64,
    /// Gear-table index of the engaged gear state.
    pub gear: usize,
    /// Input speed magnitude, rad/s (≥ 0).
    pub input_speed: f64,
    /// Loss-free input torque, N·m, positive when driving (≥ 0 unless overrun = transmit or a rig
    /// cycle gives negative torque).
    pub input_torque: f64,
    /// Loss-free power at the gearbox output (= input power without losses), W.
    pub output_power: f64,
    /// The gearbox input is at rest.
    pub standstill: bool,
    /// Engine-side (converter impeller) speed, rad/s: the input speed without a launch device;
    /// with one, from the converter characteristic (idle at standstill).
    pub engine_speed: f64,
    /// Engine-side torque into the launch device, N·m (the input torque without one).
    pub engine_torque: f64,
    /// Converter slip loss, W (0 without a launch device).
    pub converter_loss: f64,
    /// The lock-up clutch is closed (false without a launch device).
    pub lockup: bool,
    /// The gear differs from the previous interval's.
    pub shift: bool,
    /// Gear, input speed or input torque differ from the previous interval's (the solver's
    /// restart points). False for the first interval.
    pub jump: bool,
}

/// The whole cycle as gearbox inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    /// One interval per cycle interval, contiguous, in time order.
    pub intervals: Vec<Interval>,
}

impl Schedule {
    /// Start times (s) of the intervals whose inputs jump (`Interval::jump`).
    pub fn jumps(&self) -> Vec<f64> {
        self.intervals.iter().filter(|i| i.jump).map(|i| i.t0).collect()
    }

    /// Number of gear shifts.
    pub fn shift_count(&self) -> usize {
        self.intervals.iter().filter(|i| i.shift).count()
    }

    /// ∫ output_power dt, J.
    pub fn output_energy(&self) -> f64 {
        self.intervals
            .iter()
            .map(|i| i.output_power * (i.t1 - i.t0))
            .sum()
    }

    /// First time, s.
    pub fn start_time(&self) -> f64 {
        self.intervals.first().map_or(0.0, |i| i.t0)
    }

    /// Last time, s.
    pub fn end_time(&self) -> f64 {
        self.intervals.last().map_or(0.0, |i| i.t1)
    }
}

/// Turn a cycle into gearbox inputs. Vehicle cycles need `vehicle`; the gear comes from the
/// cycle's gear column if it has one, else from the vehicle's shift strategy, else (a gearbox
/// with a single gear state) that state. Rig cycles ignore `vehicle`. Gear names are checked
/// against `gears` (error with the line number).
pub fn schedule(
    cycle: &DriveCycle,
    vehicle: Option<&Vehicle>,
    gears: &GearTable,
) -> Result<Schedule, CycleError> {
    schedule_with_launch(cycle, vehicle, gears, None)
}

/// [`schedule`] with an optional launch device: each interval's engine side (speed, torque,
/// converter slip loss, lock-up) follows from its gearbox input (= turbine) speed and torque
/// (rig cycles too: their input is the turbine side; their vehicle speed for the lock-up follows
/// from the input speed when a vehicle is given, else it is 0 and the lock-up stays open).
/// Without a launch device the engine side is the gearbox input.
pub fn schedule_with_launch(
    cycle: &DriveCycle,
    vehicle: Option<&Vehicle>,
    gears: &GearTable,
    launch: Option<&LaunchDevice>,
) -> Result<Schedule, CycleError> {
    let src = cycle.source.as_str();
    check_gear_table(gears, src)?;
    // Every row's gear must exist, the last one included (it only closes the last interval, but
    // a name the model does not know is a mistake in the file either way).
    for k in 0..cycle.rows.len() {
        gear_of(cycle, k, gears)?;
    }
    let mut out = match cycle.kind {
        CycleKind::Rig => rig_intervals(cycle, gears)?,
        CycleKind::Vehicle => {
            let v = vehicle.ok_or_else(|| {
                CycleError::new(
                    CycleErrorKind::Config,
                    src,
                    "a vehicle cycle (time_s,speed_kmh) needs a [vehicle] section in the model; \
                     a rig cycle (time_s,input_speed_rpm,input_torque_nm,gear) does not",
                )
            })?;
            vehicle_intervals(cycle, v, gears)?
        }
    };
    if let Some(l) = launch {
        for i in &mut out {
            // Rig cycles have no vehicle speed; with a vehicle it follows from the input speed.
            let v = match (cycle.kind, vehicle) {
                (CycleKind::Rig, Some(veh)) => {
                    veh.wheel_radius * i.input_speed / (veh.final_drive_ratio * gears.states[i.gear].1.abs())
                }
                _ => i.vehicle_speed,
            };
            let e = l.engine_side(i.gear, v, i.input_speed, i.input_torque);
            i.engine_speed = e.impeller_speed;
            i.engine_torque = e.impeller_torque;
            i.converter_loss = e.loss;
            i.lockup = e.locked;
        }
    }
    for k in 1..out.len() {
        let (a, b) = (out[k - 1], out[k]);
        out[k].shift = a.gear != b.gear;
        out[k].jump = a.gear != b.gear || a.input_speed != b.input_speed || a.input_torque != b.input_torque;
    }
    Ok(Schedule { intervals: out })
}

/// At least one gear state, each with a finite non-zero ratio.
fn check_gear_table(gears: &GearTable, src: &str) -> Result<(), CycleError> {
    if gears.states.is_empty() {
        return Err(CycleError::new(
            CycleErrorKind::Config,
            src,
            "the gearbox has no gear state",
        ));
    }
    for (n, r) in &gears.states {
        if !(r.is_finite() && *r != 0.0) {
            return Err(CycleError::new(
                CycleErrorKind::Config,
                src,
                format!("gear state {n} has ratio {r}; a finite non-zero ratio is needed"),
            ));
        }
    }
    Ok(())
}

/// The gear-table index of row `k`'s gear column (None without one), with the file line in the
/// error.
fn gear_of(cycle: &DriveCycle, k: usize, gears: &GearTable) -> Result<Option<usize>, CycleError> {
    let row = &cycle.rows[k];
    match &row.gear {
        None => Ok(None),
        Some(g) => gears.index_of(g).map(Some).ok_or_else(|| {
            CycleError::new(
                CycleErrorKind::UnknownGear,
                &cycle.source,
                format!("not a gear state of the model ({})", gears.names().join(", ")),
            )
            .at_line(row.line)
            .at_value("gear", g.clone())
        }),
    }
}

/// An interval whose engine side is its gearbox input (no launch device yet).
fn direct(t0: f64, t1: f64, vehicle_speed: f64, gear: usize, w: f64, torque: f64, power: f64) -> Interval {
    Interval {
        t0,
        t1,
        vehicle_speed,
        gear,
        input_speed: w,
        input_torque: torque,
        output_power: power,
        standstill: false,
        engine_speed: w,
        engine_torque: torque,
        converter_loss: 0.0,
        lockup: false,
        shift: false,
        jump: false,
    }
}

/// Rig cycle: each row's input speed, torque and gear held until the next row.
fn rig_intervals(cycle: &DriveCycle, gears: &GearTable) -> Result<Vec<Interval>, CycleError> {
    let n = cycle.rows.len().saturating_sub(1);
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let (r0, r1) = (&cycle.rows[k], &cycle.rows[k + 1]);
        let gear = gear_of(cycle, k, gears)?.unwrap_or(0);
        let (w, t) = (r0.input_speed, r0.input_torque);
        out.push(Interval {
            standstill: w <= 0.0,
            ..direct(r0.time, r1.time, 0.0, gear, w, t, t * w)
        });
    }
    Ok(out)
}

/// Vehicle cycle: the mean demand of each interval through the gear of the cycle's gear column,
/// the shift strategy, or the only gear state.
fn vehicle_intervals(
    cycle: &DriveCycle,
    v: &Vehicle,
    gears: &GearTable,
) -> Result<Vec<Interval>, CycleError> {
    let src = cycle.source.as_str();
    let bound = match (&v.shift, cycle.has_gear) {
        (_, true) => None,
        (Some(s), false) => Some(s.bind(gears, src)?),
        (None, false) if gears.states.len() == 1 => None,
        (None, false) => {
            return Err(CycleError::new(
                CycleErrorKind::Config,
                src,
                "the cycle has no gear column and the model has no [vehicle.shift] strategy \
                 (needed when the gearbox has more than one gear state)",
            ));
        }
    };
    let mut shifter = bound.as_ref().map(Shifter::new);
    let n = cycle.rows.len().saturating_sub(1);
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let (r0, r1) = (&cycle.rows[k], &cycle.rows[k + 1]);
        let (v0, v1) = (r0.vehicle_speed, r1.vehicle_speed);
        let dt = r1.time - r0.time;
        let standstill = v0 <= v.standstill_speed && v1 <= v.standstill_speed;
        let d = v.demand(v0, v1, dt);
        let w_out = v.output_speed(d.mean_speed);
        let gear = match (&mut shifter, &bound) {
            (Some(s), Some(b)) => b.index[s.step(r0.time, w_out, standstill)],
            _ => gear_of(cycle, k, gears)?.unwrap_or(0),
        };
        let ratio = gears.states[gear].1.abs();
        let (w_in, torque, power) = if standstill {
            (0.0, 0.0, 0.0)
        } else {
            let p = match v.overrun {
                Overrun::Zero => d.mean_power.max(0.0),
                Overrun::Transmit => d.mean_power,
            };
            let w_in = w_out * ratio;
            (w_in, p / w_in, p)
        };
        out.push(Interval {
            standstill,
            ..direct(r0.time, r1.time, d.mean_speed, gear, w_in, torque, power)
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycle::parse::KMH;
    use crate::cycle::vehicle::tests::{at6, at6_gears};
    use crate::cycle::vehicle::RoadLoad;
    use approx::assert_relative_eq;

    fn wltc() -> DriveCycle {
        DriveCycle::bundled("wltc").unwrap()
    }

    fn transmit(mut v: Vehicle) -> Vehicle {
        v.overrun = Overrun::Transmit;
        v
    }

    /// ∫ F_road(v)·v dt over the piecewise-linear trace, by Simpson's rule per interval (exact
    /// for the cubic integrand), independent of the schedule's closed-form means.
    fn road_energy(c: &DriveCycle, v: &Vehicle) -> f64 {
        c.rows
            .windows(2)
            .map(|w| {
                let (v0, v1, dt) = (w[0].vehicle_speed, w[1].vehicle_speed, w[1].time - w[0].time);
                let p = |x: f64| v.road_load.force(x) * x;
                dt / 6.0 * (p(v0) + 4.0 * p(0.5 * (v0 + v1)) + p(v1))
            })
            .sum()
    }

    #[test]
    fn transmit_energy_equals_road_load_energy_on_every_bundled_cycle() {
        let mut v = transmit(at6());
        v.standstill_speed = 0.0; // no interval lost to the standstill threshold
        for name in crate::cycle::bundled::bundled_names() {
            let c = DriveCycle::bundled(name).unwrap();
            assert_relative_eq!(c.rows[0].vehicle_speed, 0.0);
            assert_relative_eq!(c.rows[c.len() - 1].vehicle_speed, 0.0);
            let s = schedule(&c, Some(&v), &at6_gears()).unwrap();
            assert_eq!(s.intervals.len(), c.len() - 1);
            let e = s.output_energy();
            let r = road_energy(&c, &v);
            assert!(((e - r) / r).abs() < 1e-9, "{name}: {e} vs {r}");
            // power = torque × speed in every interval
            for i in &s.intervals {
                assert!(
                    (i.output_power - i.input_torque * i.input_speed).abs()
                        <= 1e-9 * i.output_power.abs().max(1.0)
                );
            }
        }
    }

    #[test]
    fn overrun_zero_gives_no_negative_torque_and_more_energy_than_road_load() {
        let v = at6();
        let c = wltc();
        let s = schedule(&c, Some(&v), &at6_gears()).unwrap();
        assert!(s
            .intervals
            .iter()
            .all(|i| i.input_torque >= 0.0 && i.output_power >= 0.0));
        let braking = s
            .intervals
            .iter()
            .filter(|i| !i.standstill && i.input_torque == 0.0)
            .count();
        assert!(braking > 100, "WLTC has long decelerations: {braking}");
        let st = schedule(&c, Some(&transmit(v.clone())), &at6_gears()).unwrap();
        assert!(st.intervals.iter().any(|i| i.input_torque < 0.0));
        // positive part: same where transmit is positive, zero elsewhere
        for (a, b) in s.intervals.iter().zip(&st.intervals) {
            assert_relative_eq!(a.output_power, b.output_power.max(0.0), epsilon = 1e-9);
        }
        assert!(s.output_energy() > st.output_energy());
        // WLTC 3b positive traction energy of a 1.9 t sedan: a few kWh (3.8 kWh here; sanity band)
        let kwh = s.output_energy() / 3.6e6;
        assert!((1.5..5.0).contains(&kwh), "{kwh} kWh");
    }

    #[test]
    fn standstill_has_zero_speed_and_torque() {
        let v = at6();
        let s = schedule(&wltc(), Some(&v), &at6_gears()).unwrap();
        let st: Vec<_> = s.intervals.iter().filter(|i| i.standstill).collect();
        assert!(st.len() > 100, "WLTC idles: {}", st.len());
        for i in &st {
            assert_eq!((i.input_speed, i.input_torque, i.output_power), (0.0, 0.0, 0.0));
        }
        for i in s.intervals.iter().filter(|i| !i.standstill) {
            assert!(i.input_speed > 0.0 && i.vehicle_speed > 0.0);
        }
        // first interval of WLTC is at rest, in first gear
        assert!(s.intervals[0].standstill);
        assert_eq!(s.intervals[0].gear, 0);
    }

    #[test]
    fn wltc_shifting_is_plausible_and_does_not_hunt() {
        let v = at6();
        let s = schedule(&wltc(), Some(&v), &at6_gears()).unwrap();
        let hold = v.shift.as_ref().unwrap().min_hold;
        let shifts: Vec<(f64, usize, usize)> = s
            .intervals
            .windows(2)
            .filter(|w| w[1].shift)
            .map(|w| (w[1].t0, w[0].gear, w[1].gear))
            .collect();
        // consecutive shifts are at least min_hold apart, and none is a quick shift back
        for w in shifts.windows(2) {
            assert!(w[1].0 - w[0].0 >= hold - 1e-9, "{w:?}");
        }
        let quick_back = shifts
            .windows(2)
            .filter(|w| w[1].2 == w[0].1 && w[1].0 - w[0].0 < 2.0 * hold)
            .count();
        let n = shifts.len();
        assert!(quick_back * 10 < n, "{quick_back} quick shift-backs out of {n}");
        // plausible count: tens to a few hundred on 1800 s, every forward gear used, no reverse
        assert!((50..400).contains(&n), "{n} shifts");
        for g in 0..6 {
            assert!(s.intervals.iter().any(|i| i.gear == g), "gear index {g} unused");
        }
        assert!(s.intervals.iter().all(|i| i.gear < 6));
        // input speed stays in an engine-like band while moving above 20 km/h
        for i in s.intervals.iter().filter(|i| i.vehicle_speed > 20.0 / 3.6) {
            let rpm = crate::physics::units::rad_s_to_rpm(i.input_speed);
            assert!((900.0..3500.0).contains(&rpm), "{rpm} rpm at t = {}", i.t0);
        }
        // 6th gear at the 131 km/h top speed
        let top = s
            .intervals
            .iter()
            .max_by(|a, b| a.vehicle_speed.total_cmp(&b.vehicle_speed))
            .unwrap();
        assert_eq!(top.gear, 5);
    }

    #[test]
    fn monotone_ramp_gives_monotone_upshifts_through_all_gears() {
        let mut text = String::from("time_s,speed_kmh\n");
        for k in 0..=140 {
            text.push_str(&format!("{k},{}\n", k as f64));
        }
        let c = DriveCycle::parse(&text, "ramp").unwrap();
        let s = schedule(&c, Some(&at6()), &at6_gears()).unwrap();
        let g: Vec<usize> = s.intervals.iter().map(|i| i.gear).collect();
        assert!(g.windows(2).all(|w| w[1] >= w[0]), "{g:?}");
        assert_eq!(*g.last().unwrap(), 5);
        assert_eq!(s.shift_count(), 5, "one shift per gear: {g:?}");
        // upshift speeds follow the thresholds: 1→2 where the mean input speed first exceeds 2200 rpm
        let first2 = s.intervals.iter().find(|i| i.gear == 1).unwrap();
        let v = at6();
        let rpm_in_1st = crate::physics::units::rad_s_to_rpm(v.output_speed(first2.vehicle_speed) * 4.171);
        assert!(rpm_in_1st > 2200.0 && rpm_in_1st - 2200.0 < 200.0, "{rpm_in_1st}");
    }

    #[test]
    fn interval_values_by_hand() {
        // one interval 36 → 54 km/h in 2 s, in the only gear (ratio 2), transmit.
        let gears = GearTable::new(vec![("D".into(), 2.0)]);
        let v = Vehicle {
            mass: 1000.0,
            effective_mass: 1000.0,
            wheel_radius: 0.5,
            final_drive_ratio: 4.0,
            road_load: RoadLoad {
                f0: 100.0,
                f1: 0.0,
                f2: 0.0,
            },
            overrun: Overrun::Transmit,
            standstill_speed: 0.1 * KMH,
            shift: None,
        };
        let c = DriveCycle::parse("time_s,speed_kmh\n0,36\n2,54\n", "x").unwrap();
        let sch = schedule(&c, Some(&v), &gears).unwrap();
        let i = sch.intervals[0];
        // a = 2.5 m/s², F = 2500 + 100 N, mean v = 12.5 m/s, P = 2600·12.5 W
        assert_relative_eq!(i.vehicle_speed, 12.5, epsilon = 1e-12);
        assert_relative_eq!(i.output_power, 2600.0 * 12.5, epsilon = 1e-9);
        // ω_in = 12.5·4·2/0.5 = 200 rad/s; T_in = r_w·F/(i_f·i_g) = 0.5·2600/8
        assert_relative_eq!(i.input_speed, 200.0, epsilon = 1e-12);
        assert_relative_eq!(i.input_torque, 0.5 * 2600.0 / 8.0, epsilon = 1e-9);
        assert_eq!((i.t0, i.t1, i.gear, i.shift, i.jump), (0.0, 2.0, 0, false, false));
    }

    #[test]
    fn gear_column_is_used_and_checked() {
        let v = at6();
        let c = DriveCycle::parse(
            "time_s,speed_kmh,gear\n0,0,1\n1,10,1\n2,20,2\n3,20,R\n4,0,1\n",
            "g.csv",
        )
        .unwrap();
        let s = schedule(&c, Some(&v), &at6_gears()).unwrap();
        let g: Vec<usize> = s.intervals.iter().map(|i| i.gear).collect();
        assert_eq!(g, vec![0, 0, 1, 6]);
        assert_eq!(s.shift_count(), 2);
        // reverse: speed magnitude with |ratio|
        let i = s.intervals[3];
        assert_relative_eq!(
            i.input_speed,
            v.output_speed(i.vehicle_speed) * 3.403,
            epsilon = 1e-9
        );
        let c = DriveCycle::parse("time_s,speed_kmh,gear\n0,0,1\n1,10,1\n2,20,7\n3,0,1\n", "g.csv").unwrap();
        let e = schedule(&c, Some(&v), &at6_gears()).unwrap_err();
        assert_eq!(
            (e.kind, e.line, e.value.as_deref()),
            (CycleErrorKind::UnknownGear, Some(4), Some("7"))
        );
        assert!(
            e.to_string()
                .starts_with("g.csv, line 4: column gear = \"7\": not a gear state"),
            "{e}"
        );
    }

    #[test]
    fn rig_cycle_zero_order_hold() {
        let c = DriveCycle::parse(
            "time_s,input_speed_rpm,input_torque_nm,gear\n0,0,0,1\n10,1000,100,1\n20,1000,100,3\n30,2000,-20,3\n\
             40,0,0,1\n",
            "rig.csv",
        )
        .unwrap();
        let s = schedule(&c, None, &at6_gears()).unwrap();
        assert_eq!(s.intervals.len(), 4);
        let w = crate::physics::units::rpm_to_rad_s(1000.0);
        let i = s.intervals[1];
        assert_eq!((i.t0, i.t1, i.gear, i.standstill), (10.0, 20.0, 0, false));
        assert_relative_eq!(i.input_speed, w);
        assert_relative_eq!(i.output_power, 100.0 * w);
        assert!(s.intervals[0].standstill);
        assert!(s.intervals[2].shift && !s.intervals[3].shift);
        assert_relative_eq!(s.intervals[3].input_torque, -20.0);
        assert_eq!(s.jumps(), vec![10.0, 20.0, 30.0]);
        // the last row only closes the last interval: its gear "1" is not used, nor checked
        assert_relative_eq!(s.end_time(), 40.0);
        let c = DriveCycle::parse(
            "time_s,input_speed_rpm,input_torque_nm,gear\n0,0,0,1\n3,0,0,9\n5,0,0,1\n",
            "r",
        )
        .unwrap();
        let e = schedule(&c, None, &at6_gears()).unwrap_err();
        assert_eq!((e.kind, e.line), (CycleErrorKind::UnknownGear, Some(3)));
    }

    #[test]
    fn jumps_flag_every_change() {
        let s = schedule(&wltc(), Some(&at6()), &at6_gears()).unwrap();
        for w in s.intervals.windows(2) {
            let changed = w[0].gear != w[1].gear
                || w[0].input_speed != w[1].input_speed
                || w[0].input_torque != w[1].input_torque;
            assert_eq!(w[1].jump, changed);
            assert_eq!(w[0].t1, w[1].t0, "contiguous");
        }
        // idle stretches do not jump
        let idle_pairs = s
            .intervals
            .windows(2)
            .filter(|w| w[0].standstill && w[1].standstill)
            .count();
        assert!(idle_pairs > 0);
        assert!(s
            .intervals
            .windows(2)
            .filter(|w| w[0].standstill && w[1].standstill)
            .all(|w| !w[1].jump));
        assert_eq!(s.jumps().len(), s.intervals.iter().filter(|i| i.jump).count());
    }

    #[test]
    fn launch_device_sets_the_engine_side() {
        let v = at6();
        let l = crate::cycle::launch::tests::launch();
        let plain = schedule(&wltc(), Some(&v), &at6_gears()).unwrap();
        let s = schedule_with_launch(&wltc(), Some(&v), &at6_gears(), Some(&l)).unwrap();
        assert_eq!(plain.intervals.len(), s.intervals.len());
        let idle = l.idle_speed;
        for (a, b) in plain.intervals.iter().zip(&s.intervals) {
            // the gearbox side is unchanged
            assert_eq!(
                (a.gear, a.input_speed, a.input_torque),
                (b.gear, b.input_speed, b.input_torque)
            );
            assert_eq!(
                (a.engine_speed, a.converter_loss, a.lockup),
                (a.input_speed, 0.0, false)
            );
            // the engine never runs below idle, and never below the turbine
            assert!(b.engine_speed >= idle - 1e-9 && b.engine_speed >= b.input_speed - 1e-9);
            assert!(b.converter_loss >= 0.0);
            if b.standstill {
                assert_eq!(b.engine_speed, idle);
                assert!(b.converter_loss > 0.0 && !b.lockup);
            }
            if b.lockup {
                assert!(b.gear >= 2 && b.vehicle_speed > 40.0 / 3.6);
            }
        }
        assert!(s.intervals.iter().any(|i| i.lockup));
        assert!(s
            .intervals
            .iter()
            .any(|i| !i.lockup && !i.standstill && i.converter_loss > 0.0));
    }

    #[test]
    fn configuration_errors() {
        let c = wltc();
        let e = schedule(&c, None, &at6_gears()).unwrap_err();
        assert_eq!(e.kind, CycleErrorKind::Config);
        assert!(e.to_string().contains("[vehicle]"));
        let mut v = at6();
        v.shift = None;
        let e = schedule(&c, Some(&v), &at6_gears()).unwrap_err();
        assert!(e.to_string().contains("[vehicle.shift]"), "{e}");
        // single-state box needs no strategy
        let one = GearTable::new(vec![("1".into(), 8.0)]);
        let s = schedule(&c, Some(&v), &one).unwrap();
        assert!(s.intervals.iter().all(|i| i.gear == 0) && s.shift_count() == 0);
        // a strategy naming states the table lacks
        let v = at6();
        let e = schedule(&c, Some(&v), &one).unwrap_err();
        assert_eq!(e.kind, CycleErrorKind::Config);
        let bad = GearTable::new(vec![("1".into(), 0.0)]);
        assert!(schedule(&c, Some(&v), &bad).is_err());
    }
}
