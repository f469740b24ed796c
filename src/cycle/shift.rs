//! Shift strategy: gear choice from the gearbox input speed with hysteresis and a minimum hold
//! time (physics.md §9, "engine-speed thresholds with hysteresis").
//!
//! Rules, applied once per cycle interval [t_k, t_{k+1}) with that interval's mean vehicle speed:
//! - standstill: the box selects the launch gear (`gears[0]`; an automatic in D coasts down to
//!   first) as soon as the hold time allows; it stays in gear (never neutral);
//! - launch (first moving interval after a standstill, or the first interval): the launch gear,
//!   even if the hold time has not expired;
//! - moving: in gear i, upshift while the input speed in the current candidate gear exceeds
//!   `upshift[i]`, else downshift while it is below `downshift[i−1]`; several gears may be skipped
//!   in one shift; no shift until `min_hold` has passed since the last one;
//! - braking or coasting is not special: the gear follows the input speed (downshifts as the
//!   vehicle slows).
//!
//! The model's check of `[vehicle.shift]` (`crate::model::sections::vehicle`) guarantees
//! `upshift[i]·r(i+1)/r(i) > downshift[i]`: an upshift never lands below the downshift
//! threshold and a downshift never lands above the upshift threshold, so the rules cannot hunt.

use super::error::{CycleError, CycleErrorKind};
use super::gears::GearTable;
use super::vehicle::ShiftStrategy;

/// A shift strategy bound to a gear table: gear-table indices and ratios.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundShift {
    /// Gear-table index of each shift gear, launch gear first.
    pub index: Vec<usize>,
    /// |ratio| ω_in/ω_out of each shift gear.
    pub ratio: Vec<f64>,
    /// Upshift input speeds, rad/s.
    pub upshift: Vec<f64>,
    /// Downshift input speeds, rad/s.
    pub downshift: Vec<f64>,
    /// Minimum hold time, s.
    pub min_hold: f64,
}

impl ShiftStrategy {
    /// Look the shift gears up in `gears` (`source` names the cycle in the error).
    pub fn bind(&self, gears: &GearTable, source: &str) -> Result<BoundShift, CycleError> {
        let mut index = Vec::with_capacity(self.gears.len());
        for g in &self.gears {
            let i = gears.index_of(g).ok_or_else(|| {
                CycleError::new(
                    CycleErrorKind::Config,
                    source,
                    format!(
                        "vehicle.shift.gears names \"{g}\", which is not a gear state ({})",
                        gears.names().join(", ")
                    ),
                )
            })?;
            index.push(i);
        }
        Ok(BoundShift {
            ratio: index.iter().map(|&i| gears.states[i].1.abs()).collect(),
            index,
            upshift: self.upshift.clone(),
            downshift: self.downshift.clone(),
            min_hold: self.min_hold,
        })
    }
}

/// The shift logic's state while walking through a cycle.
#[derive(Debug, Clone)]
pub struct Shifter<'a> {
    s: &'a BoundShift,
    pos: usize,
    last_shift: f64,
    was_moving: bool,
}

impl<'a> Shifter<'a> {
    /// Start in the launch gear, with no shift yet.
    pub fn new(s: &'a BoundShift) -> Self {
        Shifter {
            s,
            pos: 0,
            last_shift: f64::NEG_INFINITY,
            was_moving: false,
        }
    }

    /// Gear (position in the shift list, 0 = launch gear) for the interval starting at `t0` (s)
    /// with mean gearbox output speed `output_speed` (rad/s) and the interval's standstill flag.
    pub fn step(&mut self, t0: f64, output_speed: f64, standstill: bool) -> usize {
        let s = self.s;
        let held = t0 - self.last_shift >= s.min_hold - 1e-9;
        let mut target = self.pos;
        if standstill {
            if held {
                target = 0;
            }
        } else if !self.was_moving {
            target = 0; // launch
        } else if held {
            let w = |g: usize| output_speed * s.ratio[g];
            let mut g = self.pos;
            if g + 1 < s.ratio.len() && w(g) > s.upshift[g] {
                while g + 1 < s.ratio.len() && w(g) > s.upshift[g] {
                    g += 1;
                }
            } else {
                while g > 0 && w(g) < s.downshift[g - 1] {
                    g -= 1;
                }
            }
            target = g;
        }
        if target != self.pos {
            self.pos = target;
            self.last_shift = t0;
        }
        self.was_moving = !standstill;
        self.pos
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycle::parse::RPM;

    fn bound() -> BoundShift {
        BoundShift {
            index: vec![0, 1, 2],
            ratio: vec![3.0, 2.0, 1.0],
            upshift: vec![3000.0 * RPM, 3000.0 * RPM],
            downshift: vec![1500.0 * RPM, 1200.0 * RPM],
            min_hold: 2.0,
        }
    }

    #[test]
    fn ramp_up_and_down_with_hysteresis() {
        let b = bound();
        let mut s = Shifter::new(&b);
        // output speed ramps 0 → 3000 rpm over 300 s, then back down.
        let mut gears = Vec::new();
        for k in 0..600 {
            let t = k as f64;
            let w = if k < 300 { 10.0 * t } else { 10.0 * (600.0 - t) } * RPM;
            gears.push(s.step(t, w, false));
        }
        let up = &gears[..300];
        assert!(up.windows(2).all(|w| w[1] >= w[0]), "monotone upshifts");
        let down = &gears[300..];
        assert!(down.windows(2).all(|w| w[1] <= w[0]), "monotone downshifts");
        // 1→2 when 3·w > 3000 rpm, i.e. w > 1000 rpm (t > 100 s)
        assert_eq!(gears[100], 0);
        assert_eq!(gears[101], 1);
        // 2→3 when 2·w > 3000 → w > 1500 rpm (t > 150)
        assert_eq!(gears[150], 1);
        assert_eq!(gears[151], 2);
        // down 3→2 when 1·w < 1200 rpm: t = 600 − 120 = 480 → w = 1200 (not below), 481 below
        assert_eq!(gears[480], 2);
        assert_eq!(gears[481], 1);
        // 2→1 when 2·w < 1500 → w < 750 rpm → t > 525
        assert_eq!(gears[525], 1);
        assert_eq!(gears[526], 0);
    }

    #[test]
    fn min_hold_delays_shifts_and_skip_shifts_happen() {
        let b = bound();
        let mut s = Shifter::new(&b);
        assert_eq!(s.step(0.0, 1100.0 * RPM, false), 0); // launch
        assert_eq!(s.step(1.0, 1100.0 * RPM, false), 1); // hold from -inf: shift at once
        assert_eq!(s.step(2.0, 2000.0 * RPM, false), 1); // held (1 s < 2 s)
        assert_eq!(s.step(3.0, 2000.0 * RPM, false), 2);
        // sudden drop: skip-downshift 3 → 1 in one shift once the hold allows
        assert_eq!(s.step(4.0, 100.0 * RPM, false), 2);
        assert_eq!(s.step(5.0, 100.0 * RPM, false), 0);
    }

    #[test]
    fn standstill_and_launch() {
        let b = bound();
        let mut s = Shifter::new(&b);
        for k in 0..10 {
            s.step(k as f64, 2000.0 * RPM, false);
        }
        assert_eq!(s.step(10.0, 2000.0 * RPM, false), 2);
        // stop: first at rest once the hold allows
        assert_eq!(s.step(11.0, 0.0, true), 0);
        assert_eq!(s.step(12.0, 0.0, true), 0);
        // launch in first
        assert_eq!(s.step(13.0, 50.0 * RPM, false), 0);
        // stop right after a shift: stays in gear until hold, then launch forces first
        let mut s = Shifter::new(&b);
        s.step(0.0, 2000.0 * RPM, false);
        assert_eq!(s.step(1.0, 2000.0 * RPM, false), 2);
        assert_eq!(s.step(2.0, 0.0, true), 2);
        assert_eq!(s.step(3.0, 10.0 * RPM, false), 0);
    }
}
