//! `[[thermal.controls]]`: controllers that switch or throttle a part of the network on a node's
//! temperature.
//!
//! - `kind = "two_point"`: on/off with hysteresis. A cooling controller (`on_c > off_c`) switches
//!   on when the sensor node reaches `on_c` and off when it falls to `off_c`; a heating one
//!   (`on_c < off_c`) switches on when the node falls to `on_c` and off when it reaches `off_c`.
//!   It acts on one of: a cooler (`cooler`: its ε·C_min while off is `off_fraction` of the full
//!   value, 0 = off, a capacity-rate step otherwise), a link (`link`: its conductance h·A while off
//!   is `off_fraction` of the full one, a fan), or a heater it defines (`heater_w` into
//!   `heater_node`, default the sensor node).
//! - `kind = "valve"`: a proportional bypass valve on a cooler: the share of the oil through the
//!   cooler is `(T − closed_c)/(open_c − closed_c)` limited to `[min_share, max_share]`; it scales
//!   the cooler's ε·C_min.
//! - `kind = "pi_valve"`: a proportional-integral bypass valve on a cooler: the share through
//!   the cooler is `u = clamp(v, min_share, max_share)` with `v = gain_per_k·(T − set_c) + I`,
//!   and the integral `I` (a state of the solution, in share units) follows
//!   `dI/dt = gain_per_k/integral_time_s·(T − set_c) + (u − v)/integral_time_s`. The last term
//!   (zero while the share is within its limits) is anti-windup by back-calculation (tracking):
//!   at a limit the integral is pulled back by the gap between the limited and the unlimited
//!   output, so it relaxes to the limit with the integral time and never winds up past it. The
//!   tracking time is the integral time (the choice K_aw = 1/T_i of the back-calculation example
//!   read at novasolver.jp/en/tools/anti-windup.html; the scheme is named as a classical one in
//!   Caparroz, Soltesz, Hägglund & Guzmán, "Anti-windup in PID control: review, analysis, and new
//!   tuning directions", arXiv:2606.01959, abstract read; Åström & Hägglund's books were not read
//!   here). Conditional integration (the integral stopped at a limit) was tried and not kept:
//!   there the vector field points into the limit from both sides while the sensor drifts back
//!   toward the set point, and the controller chatters on the limit. `I(0)` is `initial_share`
//!   (default `min_share`).
//!
//! Two-point controllers take optional `min_on_s` and `min_off_s` (s, 0 to
//! [`MIN_TIME_RANGE_S`]'s upper end): a switch requested before the controller has been on
//! (off) that long happens when that time ends.
//!
//! Equal set points (no hysteresis) are refused unless a minimum on or off time is given: the
//! controller would switch at every step (it chatters) and no step size could follow it. With
//! a minimum time, the switches are at least that far apart. A controller with equal set points
//! cools when it acts on a cooler or link and heats when it is a heater.

use serde::{Deserialize, Serialize};

use super::common::{temp_ok, NodeNames, NodeRef};
use super::coolers::Cooler;
use super::links::Link;
use crate::model::choice::{choice, Choice};
use crate::model::problems::Problems;
use crate::physics::units::c_to_k;

/// The kinds of controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ControlKind {
    /// On/off with hysteresis.
    TwoPoint,
    /// Proportional bypass valve on a cooler.
    Valve,
    /// Proportional-integral bypass valve on a cooler.
    PiValve,
}
choice!(ControlKind {
    TwoPoint = "two_point",
    Valve = "valve",
    PiValve = "pi_valve",
});

/// Set points a controller may take, °C: the range in which the solvers evaluate the oil
/// (`solve::equilibrium::OIL_RANGE_C`); a set point outside it could never be reached.
pub const SET_POINT_RANGE_C: (f64, f64) = (-60.0, 200.0);

/// Proportional gains a PI valve may take, 1/K (above 0; 100 per kelvin is a valve that goes
/// from closed to open within 0.01 K, an on/off valve in all but name).
pub const GAIN_RANGE_PER_K: (f64, f64) = (0.0, 100.0);

/// Integral times a PI valve may take, s (above 0, a year at most).
pub const INTEGRAL_TIME_RANGE_S: (f64, f64) = (0.0, 3.156e7);

/// Minimum on or off times a two-point controller may take, s (a year at most).
pub const MIN_TIME_RANGE_S: (f64, f64) = (0.0, 3.156e7);

/// `[[thermal.controls]]` as written.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ControlSpec {
    /// Name (unique among the controls).
    pub name: String,
    /// `two_point` or `valve`.
    pub kind: ControlKind,
    /// Node with capacity whose temperature the controller reads.
    pub sensor: String,
    /// Two-point: switch-on temperature, °C.
    #[serde(default)]
    pub on_c: Option<f64>,
    /// Two-point: switch-off temperature, °C.
    #[serde(default)]
    pub off_c: Option<f64>,
    /// Two-point: on at the start (default: on when the start lies beyond the switch-on
    /// temperature, off otherwise).
    #[serde(default)]
    pub initial_on: Option<bool>,
    /// Two-point: shortest time on, s (default 0): a switch off requested earlier happens when it
    /// ends.
    #[serde(default)]
    pub min_on_s: Option<f64>,
    /// Two-point: shortest time off, s (default 0): a switch on requested earlier happens when it
    /// ends.
    #[serde(default)]
    pub min_off_s: Option<f64>,
    /// Valve: temperature at which the cooler's share reaches 0 (full bypass), °C.
    #[serde(default)]
    pub closed_c: Option<f64>,
    /// Valve: temperature at which it reaches 1 (no bypass), °C.
    #[serde(default)]
    pub open_c: Option<f64>,
    /// PI valve: set point, °C.
    #[serde(default)]
    pub set_c: Option<f64>,
    /// PI valve: proportional gain, share per kelvin (1/K).
    #[serde(default)]
    pub gain_per_k: Option<f64>,
    /// PI valve: integral time, s.
    #[serde(default)]
    pub integral_time_s: Option<f64>,
    /// PI valve: the integral at the start, share (default `min_share`).
    #[serde(default)]
    pub initial_share: Option<f64>,
    /// Valve: lowest share (leakage), 0..1 (default 0).
    #[serde(default)]
    pub min_share: Option<f64>,
    /// Valve: highest share, 0..1 (default 1).
    #[serde(default)]
    pub max_share: Option<f64>,
    /// Target: a `[[thermal.coolers]]` name.
    #[serde(default)]
    pub cooler: Option<String>,
    /// Target: a `[[thermal.links]]` name (two-point only).
    #[serde(default)]
    pub link: Option<String>,
    /// Target: a heater's power while on, W (two-point only).
    #[serde(default)]
    pub heater_w: Option<f64>,
    /// Node the heater heats (default the sensor).
    #[serde(default)]
    pub heater_node: Option<String>,
    /// Two-point on a cooler or link: the share of its conductance while off, 0..1 (default 0).
    #[serde(default)]
    pub off_fraction: Option<f64>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// What a controller acts on.
#[derive(Debug, Clone, PartialEq)]
pub enum ControlTarget {
    /// Cooler index; its conductance while off is `off_fraction` of the full one.
    Cooler {
        /// Index into the coolers.
        cooler: usize,
        /// Share of its conductance while off.
        off_fraction: f64,
    },
    /// Link name (the links of that name: a meshed wall's patches keep it); conductance while off
    /// is `off_fraction` of the full one.
    Link {
        /// Link name.
        link: String,
        /// Share of its conductance while off.
        off_fraction: f64,
    },
    /// Heater of `power` W into `node`.
    Heater {
        /// Node heated.
        node: usize,
        /// Power while on, W.
        power: f64,
    },
}

/// The controller's law (temperatures in K).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ControlLaw {
    /// Two-point: on at `on`, off at `off` (cooling when on > off, heating otherwise);
    /// `initial_on` as given.
    TwoPoint {
        /// Switch-on temperature, K.
        on: f64,
        /// Switch-off temperature, K.
        off: f64,
        /// State at the start, when given.
        initial_on: Option<bool>,
        /// Shortest time on, s (0: none).
        min_on: f64,
        /// Shortest time off, s (0: none).
        min_off: f64,
    },
    /// Proportional valve: share `clamp((T − closed)/(open − closed), min, max)`.
    Valve {
        /// Share 0 at this temperature, K.
        closed: f64,
        /// Share 1 at this temperature, K.
        open: f64,
        /// Lowest share.
        min: f64,
        /// Highest share.
        max: f64,
    },
    /// PI valve: share `clamp(gain·(T − set) + I, min, max)`, dI/dt = gain/ti·(T − set) while
    /// the share is within its limits.
    Pi {
        /// Set point, K.
        set: f64,
        /// Proportional gain, 1/K.
        gain: f64,
        /// Integral time, s.
        ti: f64,
        /// Lowest share.
        min: f64,
        /// Highest share.
        max: f64,
        /// The integral at the start, share.
        initial: f64,
    },
}

/// A checked controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Control {
    /// Name.
    pub name: String,
    /// Sensor node index.
    pub sensor: usize,
    /// Law.
    pub law: ControlLaw,
    /// Target.
    pub target: ControlTarget,
}

impl Control {
    /// True when the controller reads node `i` or its heater heats it.
    pub fn reads_or_heats(&self, i: usize) -> bool {
        self.sensor == i || matches!(self.target, ControlTarget::Heater { node, .. } if node == i)
    }
}

/// A set point in °C within [`SET_POINT_RANGE_C`].
fn set_point(problems: &mut Problems, path: &str, v: Option<f64>) -> Option<f64> {
    let Some(v) = v else {
        problems.push(path, "", "required for this kind of controller");
        return None;
    };
    let (lo, hi) = SET_POINT_RANGE_C;
    let ok = temp_ok(problems, path, v) && problems.in_range(path, v, lo, hi, " °C (the oil's range)");
    ok.then_some(c_to_k(v))
}

/// A share in [0, 1] (default `default`).
fn share(problems: &mut Problems, path: &str, v: Option<f64>, default: f64) -> f64 {
    let v = v.unwrap_or(default);
    problems.in_range(path, v, 0.0, 1.0, "");
    v
}

/// Keys a kind of controller does not take, given: a problem each.
fn refuse_keys(p: &str, c: &ControlSpec, keys: &[&str], problems: &mut Problems) {
    for &k in keys {
        let given = match k {
            "on_c" => c.on_c.is_some(),
            "off_c" => c.off_c.is_some(),
            "initial_on" => c.initial_on.is_some(),
            "min_on_s" => c.min_on_s.is_some(),
            "min_off_s" => c.min_off_s.is_some(),
            "closed_c" => c.closed_c.is_some(),
            "open_c" => c.open_c.is_some(),
            "min_share" => c.min_share.is_some(),
            "max_share" => c.max_share.is_some(),
            "link" => c.link.is_some(),
            "heater_w" => c.heater_w.is_some(),
            "heater_node" => c.heater_node.is_some(),
            "off_fraction" => c.off_fraction.is_some(),
            "set_c" => c.set_c.is_some(),
            "gain_per_k" => c.gain_per_k.is_some(),
            "integral_time_s" => c.integral_time_s.is_some(),
            "initial_share" => c.initial_share.is_some(),
            _ => false,
        };
        if given {
            problems.push(
                format!("{p}.{k}"),
                "",
                format!("not a key of a {} controller", c.kind.name()),
            );
        }
    }
}

/// A minimum on or off time in [`MIN_TIME_RANGE_S`] (default 0); None when out of range.
fn min_time(problems: &mut Problems, path: &str, v: Option<f64>) -> Option<f64> {
    let v = v.unwrap_or(0.0);
    let (lo, hi) = MIN_TIME_RANGE_S;
    problems.in_range(path, v, lo, hi, " s").then_some(v)
}

/// The two-point law: set points in range, distinct (hysteresis) unless a minimum time is given.
fn two_point_law(p: &str, c: &ControlSpec, problems: &mut Problems) -> Option<ControlLaw> {
    refuse_keys(
        p,
        c,
        &[
            "closed_c",
            "open_c",
            "min_share",
            "max_share",
            "set_c",
            "gain_per_k",
            "integral_time_s",
            "initial_share",
        ],
        problems,
    );
    let on = set_point(problems, &format!("{p}.on_c"), c.on_c);
    let off = set_point(problems, &format!("{p}.off_c"), c.off_c);
    let min_on = min_time(problems, &format!("{p}.min_on_s"), c.min_on_s);
    let min_off = min_time(problems, &format!("{p}.min_off_s"), c.min_off_s);
    let (on, off, min_on, min_off) = (on?, off?, min_on?, min_off?);
    if on == off && min_on == 0.0 && min_off == 0.0 {
        problems.push(
            format!("{p}.off_c"),
            c.off_c.unwrap_or(f64::NAN),
            "must differ from on_c: a two-point controller without hysteresis (and without a \
             minimum on or off time) would switch at every step, chattering",
        );
        return None;
    }
    Some(ControlLaw::TwoPoint {
        on,
        off,
        initial_on: c.initial_on,
        min_on,
        min_off,
    })
}

/// The valve law: closed below open, shares in [0, 1] with min < max.
fn valve_law(p: &str, c: &ControlSpec, problems: &mut Problems) -> Option<ControlLaw> {
    refuse_keys(p, c, &NOT_VALVE_KEYS, problems);
    refuse_keys(
        p,
        c,
        &["set_c", "gain_per_k", "integral_time_s", "initial_share"],
        problems,
    );
    let closed = set_point(problems, &format!("{p}.closed_c"), c.closed_c);
    let open = set_point(problems, &format!("{p}.open_c"), c.open_c);
    let min = share(problems, &format!("{p}.min_share"), c.min_share, 0.0);
    let max = share(problems, &format!("{p}.max_share"), c.max_share, 1.0);
    let (closed, open) = (closed?, open?);
    let mut ok = true;
    if open <= closed {
        problems.push(
            format!("{p}.open_c"),
            c.open_c.unwrap_or(f64::NAN),
            "must be above closed_c (the valve opens the cooler as the oil warms)",
        );
        ok = false;
    }
    if min.is_finite() && max.is_finite() && min >= max {
        problems.push(format!("{p}.max_share"), max, "must be above min_share");
        ok = false;
    }
    ok.then_some(ControlLaw::Valve {
        closed,
        open,
        min,
        max,
    })
}

/// The keys a valve does not take (either kind).
const NOT_VALVE_KEYS: [&str; 9] = [
    "on_c",
    "off_c",
    "initial_on",
    "min_on_s",
    "min_off_s",
    "link",
    "heater_w",
    "heater_node",
    "off_fraction",
];

/// A value in the half-open range (lo, hi] (a gain or a time that must be positive).
fn positive(
    problems: &mut Problems,
    path: &str,
    v: Option<f64>,
    range: (f64, f64),
    unit: &str,
) -> Option<f64> {
    let Some(v) = v else {
        problems.push(path, "", "required for this kind of controller");
        return None;
    };
    let (lo, hi) = range;
    if v.is_finite() && v > lo && v <= hi {
        Some(v)
    } else {
        problems.push(path, v, format!("must lie in ({lo}, {hi}]{unit}"));
        None
    }
}

/// The PI valve law: set point in the oil's range, gain and integral time positive, shares in
/// [0, 1] with min < max, the initial integral within them.
fn pi_law(p: &str, c: &ControlSpec, problems: &mut Problems) -> Option<ControlLaw> {
    refuse_keys(p, c, &NOT_VALVE_KEYS, problems);
    refuse_keys(p, c, &["closed_c", "open_c"], problems);
    let set = set_point(problems, &format!("{p}.set_c"), c.set_c);
    let gain = positive(
        problems,
        &format!("{p}.gain_per_k"),
        c.gain_per_k,
        GAIN_RANGE_PER_K,
        " 1/K (share per kelvin)",
    );
    let ti = positive(
        problems,
        &format!("{p}.integral_time_s"),
        c.integral_time_s,
        INTEGRAL_TIME_RANGE_S,
        " s",
    );
    let min = share(problems, &format!("{p}.min_share"), c.min_share, 0.0);
    let max = share(problems, &format!("{p}.max_share"), c.max_share, 1.0);
    let mut ok = true;
    if min.is_finite() && max.is_finite() && min >= max {
        problems.push(format!("{p}.max_share"), max, "must be above min_share");
        ok = false;
    }
    let initial = c.initial_share.unwrap_or(min);
    if ok
        && !problems.in_range(
            &format!("{p}.initial_share"),
            initial,
            min,
            max,
            " (min_share to max_share)",
        )
    {
        ok = false;
    }
    let (set, gain, ti) = (set?, gain?, ti?);
    ok.then_some(ControlLaw::Pi {
        set,
        gain,
        ti,
        min,
        max,
        initial,
    })
}

/// A capacity node named `name` at `path`.
fn capacity_node(names: &NodeNames<'_>, problems: &mut Problems, path: &str, name: &str) -> Option<usize> {
    match names.resolve(problems, path, name)? {
        NodeRef::Node(i) => Some(i),
        NodeRef::Boundary(_) => {
            problems.push(path, name, "must be a node with capacity, not a boundary");
            None
        }
    }
}

/// The target: exactly one of cooler, link, heater.
fn target(
    p: &str,
    c: &ControlSpec,
    sensor: Option<usize>,
    net: (&NodeNames<'_>, &[Cooler], &[Link]),
    problems: &mut Problems,
) -> Option<ControlTarget> {
    let (names, coolers, links) = net;
    let given = [c.cooler.is_some(), c.link.is_some(), c.heater_w.is_some()];
    if given.iter().filter(|g| **g).count() != 1 {
        problems.push(
            p.to_string(),
            &c.name,
            "give exactly one target: cooler, link or heater_w",
        );
        return None;
    }
    if c.heater_w.is_none() && c.heater_node.is_some() {
        problems.push(format!("{p}.heater_node"), "", "only with heater_w");
    }
    let off_fraction = share(problems, &format!("{p}.off_fraction"), c.off_fraction, 0.0);
    if let Some(name) = &c.cooler {
        let Some(i) = coolers.iter().position(|x| &x.name == name) else {
            let known: Vec<&str> = coolers.iter().map(|x| x.name.as_str()).collect();
            let msg = format!("unknown cooler; coolers: {}", known.join(", "));
            problems.push(format!("{p}.cooler"), name, msg);
            return None;
        };
        if coolers[i].thermostat.is_some() {
            problems.push(
                format!("{p}.cooler"),
                name,
                "this cooler has its own thermostat: give the cooler no thermostat, or no controller",
            );
            return None;
        }
        return Some(ControlTarget::Cooler {
            cooler: i,
            off_fraction,
        });
    }
    if let Some(name) = &c.link {
        return link_target(p, name, links, off_fraction, problems);
    }
    let power = c.heater_w.unwrap_or(f64::NAN);
    let power_ok = problems.in_range(&format!("{p}.heater_w"), power, 0.0, 1e7, " W");
    let node = match &c.heater_node {
        Some(n) => capacity_node(names, problems, &format!("{p}.heater_node"), n),
        None => sensor,
    };
    power_ok.then_some(ControlTarget::Heater { node: node?, power })
}

/// A link target: a link of that name with a fixed or operating-point conductance law.
fn link_target(
    p: &str,
    name: &str,
    links: &[Link],
    off_fraction: f64,
    problems: &mut Problems,
) -> Option<ControlTarget> {
    use super::links::{Fluid, LinkLaw};
    let Some(l) = links.iter().find(|l| l.name == name) else {
        let known: Vec<&str> = links.iter().map(|x| x.name.as_str()).collect();
        let msg = format!("unknown link; links: {}", known.join(", "));
        problems.push(format!("{p}.link"), name, msg);
        return None;
    };
    let switchable = match &l.law {
        LinkLaw::Radiation(_) => false,
        LinkLaw::Rotating { fluid, .. } => *fluid == Fluid::Air,
        _ => true,
    };
    if !switchable {
        problems.push(
            format!("{p}.link"),
            name,
            "a controller switches a conduction or convection link (h·A), not radiation or a part rotating in oil",
        );
        return None;
    }
    Some(ControlTarget::Link {
        link: name.to_string(),
        off_fraction,
    })
}

/// Check every controller: name, kind's keys, set points, sensor, target; one controller per
/// cooler, link or heater node is allowed for a cooler or link only once.
pub(crate) fn check_controls(
    specs: &[ControlSpec],
    names: &NodeNames<'_>,
    coolers: &[Cooler],
    links: &[Link],
    problems: &mut Problems,
) -> Vec<Control> {
    let mut out: Vec<Control> = Vec::new();
    for (i, c) in specs.iter().enumerate() {
        let p = format!("thermal.controls[{i}]");
        if specs[..i].iter().any(|o| o.name == c.name) {
            problems.push(format!("{p}.name"), &c.name, "duplicate controller name");
        }
        let sensor = capacity_node(names, problems, &format!("{p}.sensor"), &c.sensor);
        let law = match c.kind {
            ControlKind::TwoPoint => two_point_law(&p, c, problems),
            ControlKind::Valve => valve_law(&p, c, problems),
            ControlKind::PiValve => pi_law(&p, c, problems),
        };
        if c.kind != ControlKind::TwoPoint && c.cooler.is_none() {
            problems.push(format!("{p}.cooler"), "", "a valve needs the cooler it bypasses");
            continue;
        }
        let target = target(&p, c, sensor, (names, coolers, links), problems);
        if let Some(t) = &target {
            let clash = out.iter().find(|o| match (&o.target, t) {
                (ControlTarget::Cooler { cooler: a, .. }, ControlTarget::Cooler { cooler: b, .. }) => a == b,
                (ControlTarget::Link { link: a, .. }, ControlTarget::Link { link: b, .. }) => a == b,
                _ => false,
            });
            if let Some(o) = clash {
                let what = if c.cooler.is_some() { "cooler" } else { "link" };
                let name = c.cooler.as_ref().or(c.link.as_ref()).cloned().unwrap_or_default();
                problems.push(
                    format!("{p}.{what}"),
                    name,
                    format!(
                        "controller {} already acts on it: one controller per {what}",
                        o.name
                    ),
                );
                continue;
            }
        }
        if let (Some(sensor), Some(law), Some(target)) = (sensor, law, target) {
            out.push(Control {
                name: c.name.clone(),
                sensor,
                law,
                target,
            });
        }
    }
    out
}
