//! The fitted parameters: key paths of the model with bounds, the coordinate each is fitted in
//! (ln p for a positive value, p itself for a temperature in °C or a range that reaches zero),
//! and their values written into the model as overrides.
//!
//! `KEYPATH[=LO:HI]`: the key path of a number in the model file (`thermal.links["sump-housing"].
//! h_w_per_m2k`, `thermal.nodes["sump"].mass_kg`, `losses.multiplier.churning`,
//! `lubrication.oil_level_mm`, `thermal.nodes["sump"].initial_temp_c`) and its bounds. Without
//! bounds a positive value may move a factor [`DEFAULT_SPAN`] either way; a temperature
//! (`…_c`) ±[`DEFAULT_TEMP_SPAN_K`] K. A key the file does not write starts at the geometric
//! mean of its bounds (the arithmetic mean for a linear coordinate), so it needs them.

use toml::{Table, Value};

use crate::model::overrides::{self, KeyPath, Step};
use crate::model::Override;

/// Default span of a positive parameter without bounds: [p/10, 10·p].
pub const DEFAULT_SPAN: f64 = 10.0;
/// Default span of a temperature parameter without bounds, K.
pub const DEFAULT_TEMP_SPAN_K: f64 = 30.0;

/// One `--fit` argument, parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSpec {
    /// The key path.
    pub path: KeyPath,
    /// Bounds, if given.
    pub bounds: Option<(f64, f64)>,
}

/// A fitted parameter, resolved against the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Key path as written.
    pub path: KeyPath,
    /// Value in the model before the fit.
    pub start: f64,
    /// Least allowed value.
    pub lo: f64,
    /// Greatest allowed value.
    pub hi: f64,
    /// Fitted on ln p (else on p).
    pub log: bool,
    /// The model holds an integer there: written as one (rounded).
    pub integer: bool,
    /// With several traces, the trace whose own value this is (`KEYPATH@TRACE`); None for a
    /// parameter shared by every trace (and for every parameter of a single trace).
    pub owner: Option<String>,
}

/// The key path and the bounds of `KEYPATH[=LO:HI]` (the `=` outside quotes and brackets).
pub fn split_bounds(s: &str) -> (&str, Option<&str>) {
    let (mut in_quotes, mut depth, mut prev) = (false, 0i32, ' ');
    let mut at = None;
    for (k, c) in s.char_indices() {
        match c {
            '"' if prev != '\\' => in_quotes = !in_quotes,
            '[' if !in_quotes => depth += 1,
            ']' if !in_quotes => depth -= 1,
            '=' if !in_quotes && depth == 0 => at = Some(k),
            _ => {}
        }
        prev = c;
    }
    match at {
        Some(k) => (&s[..k], Some(&s[k + 1..])),
        None => (s, None),
    }
}

impl std::str::FromStr for FitSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let (path, bounds) = split_bounds(s.trim());
        let path: KeyPath = path
            .trim()
            .parse()
            .map_err(|e| format!("fit = {s}: bad key path: {e}"))?;
        let bounds = match bounds {
            None => None,
            Some(b) => {
                let bad = || format!("fit = {s}: bounds must be LO:HI, two finite numbers with LO < HI");
                let (lo, hi) = b.split_once(':').ok_or_else(bad)?;
                let lo: f64 = lo.trim().parse().map_err(|_| bad())?;
                let hi: f64 = hi.trim().parse().map_err(|_| bad())?;
                if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                    return Err(bad());
                }
                Some((lo, hi))
            }
        };
        Ok(FitSpec { path, bounds })
    }
}

impl std::fmt::Display for FitSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.bounds {
            Some((lo, hi)) => write!(f, "{}={lo}:{hi}", self.path),
            None => write!(f, "{}", self.path),
        }
    }
}

/// True when the model schema refuses a fractional value at `path` of `doc` (a tooth count):
/// an integer written in the document (`--set losses.multiplier.churning=2`) is fitted as a real
/// number unless the schema holds an integer there.
fn schema_wants_integer(doc: &Table, path: &KeyPath) -> bool {
    let probe = Override {
        path: path.clone(),
        value: Value::Float(0.5),
    };
    crate::model::schema_takes(doc.clone(), &probe).is_err()
}

/// True for a key holding a temperature in °C (fitted on a linear scale).
fn is_temperature(path: &KeyPath) -> bool {
    path.to_string().ends_with("_c")
}

impl Parameter {
    /// Resolve a spec against the model document (after the base overrides).
    pub fn resolve(spec: &FitSpec, doc: &Table) -> Result<Parameter, String> {
        let name = spec.path.to_string();
        let got = overrides::get(doc, &spec.path);
        let integer = matches!(got, Ok(Value::Integer(_))) && schema_wants_integer(doc, &spec.path);
        let value = match got {
            Ok(Value::Float(x)) => Some(x),
            Ok(Value::Integer(i)) => Some(i as f64),
            Ok(v) => return Err(format!("fit = {name}: the model holds {v} there, not a number")),
            Err(_) => None,
        };
        let temp = is_temperature(&spec.path);
        let (lo, hi) = match (spec.bounds, value) {
            (Some(b), _) => b,
            (None, Some(v)) if temp => (v - DEFAULT_TEMP_SPAN_K, v + DEFAULT_TEMP_SPAN_K),
            (None, Some(v)) if v > 0.0 => (v / DEFAULT_SPAN, v * DEFAULT_SPAN),
            (None, Some(v)) => {
                return Err(format!(
                    "fit = {name}: the model's value {v} is not positive: give bounds KEYPATH=LO:HI"
                ))
            }
            (None, None) => {
                return Err(format!(
                    "fit = {name}: the model file does not write this key: give bounds KEYPATH=LO:HI \
                     (the fit starts at their mean)"
                ))
            }
        };
        let log = !temp && lo > 0.0;
        let start = value.unwrap_or(if log { (lo * hi).sqrt() } else { 0.5 * (lo + hi) });
        if !(lo..=hi).contains(&start) {
            return Err(format!(
                "fit = {}: the model's value {start} lies outside the bounds [{lo}, {hi}]",
                spec
            ));
        }
        Ok(Parameter {
            path: spec.path.clone(),
            start,
            lo,
            hi,
            log,
            integer,
            owner: None,
        })
    }

    /// Coordinate of value p.
    pub fn theta(&self, p: f64) -> f64 {
        if self.log {
            p.ln()
        } else {
            p
        }
    }

    /// Value at coordinate θ.
    pub fn value(&self, theta: f64) -> f64 {
        if self.log {
            theta.exp()
        } else {
            theta
        }
    }

    /// The value written into the model at coordinate θ: the start itself at the start's
    /// coordinate (ln and exp do not return it to the last bit), within the bounds (a
    /// coordinate at its bound's coordinate maps to the bound, not to a value one bit outside),
    /// rounded for an integer.
    pub fn written(&self, theta: f64) -> f64 {
        let v = if theta == self.theta(self.start) {
            self.start
        } else {
            self.value(theta).clamp(self.lo, self.hi)
        };
        if self.integer {
            v.round()
        } else {
            v
        }
    }

    /// The two coordinates of the central difference about θ and its half-step: θ ± δ, the
    /// pair moved inside the bounds when θ lies within δ of one (the model is never evaluated
    /// outside the user's bounds; the difference is then centred up to δ away from θ, an
    /// error of order δ in the derivative), the half-step shrunk to half the bounds' width when
    /// that is narrower than 2δ.
    pub fn difference_pair(&self, theta: f64) -> (f64, f64, f64) {
        let (lo, hi) = self.theta_bounds();
        let d = self.delta().min(0.5 * (hi - lo));
        let c = theta.clamp(lo + d, hi - d);
        ((c + d).min(hi), (c - d).max(lo), d)
    }

    /// Bounds in the coordinate.
    pub fn theta_bounds(&self) -> (f64, f64) {
        (self.theta(self.lo), self.theta(self.hi))
    }

    /// Difference step in the coordinate for the sensitivities: 1e-4 in ln p (a relative change
    /// of 1e-4), 1e-3 K for a temperature or a linear coordinate scaled to the bounds' width.
    pub fn delta(&self) -> f64 {
        if self.log {
            1e-4
        } else if is_temperature(&self.path) {
            1e-3
        } else {
            1e-4 * (self.hi - self.lo)
        }
    }

    /// The override that writes value p.
    pub fn override_at(&self, p: f64) -> Override {
        let value = if self.integer {
            Value::Integer(p.round() as i64)
        } else {
            Value::Float(p)
        };
        Override {
            path: self.path.clone(),
            value,
        }
    }

    /// The key path as text, `@TRACE` appended for a parameter of one trace.
    pub fn name(&self) -> String {
        match &self.owner {
            Some(t) => format!("{}@{t}", self.path),
            None => self.path.to_string(),
        }
    }
}

/// The `@TRACE` of a key path (the last `@` outside quotes and brackets), if any.
pub fn split_owner(path: &str) -> (&str, Option<&str>) {
    let (mut in_quotes, mut depth, mut at) = (false, 0i32, None);
    for (k, c) in path.char_indices() {
        match c {
            '"' => in_quotes = !in_quotes,
            '[' if !in_quotes => depth += 1,
            ']' if !in_quotes => depth -= 1,
            '@' if !in_quotes && depth == 0 => at = Some(k),
            _ => {}
        }
    }
    match at {
        Some(k) => (&path[..k], Some(&path[k + 1..])),
        None => (path, None),
    }
}

/// The key path with every `["name"]` selector replaced by the index of the entry it names in
/// `doc`: two spellings of one key (`thermal.nodes[4].mass_kg`, `thermal.nodes["housing"].
/// mass_kg`) give the same canonical path. A selector that names nothing is kept.
pub fn canonical(path: &KeyPath, doc: &Table) -> KeyPath {
    let mut at: Option<&Value> = None;
    let mut out = Vec::with_capacity(path.0.len());
    for step in &path.0 {
        let step = match (step, at) {
            (Step::Named(n), Some(Value::Array(a))) => a
                .iter()
                .position(|e| e.get("name").and_then(Value::as_str) == Some(n.as_str()))
                .map_or_else(|| step.clone(), Step::Index),
            _ => step.clone(),
        };
        at = match (&step, at) {
            (Step::Key(k), None) => doc.get(k),
            (Step::Key(k), Some(v)) => v.get(k),
            (Step::Index(i), Some(Value::Array(a))) => a.get(*i),
            _ => None,
        };
        out.push(step);
    }
    KeyPath(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse() {
        let s: FitSpec = "thermal.links[\"a=b\"].h_w_per_m2k=10:500".parse().unwrap();
        assert_eq!(s.bounds, Some((10.0, 500.0)));
        assert_eq!(s.path.to_string(), "thermal.links[\"a=b\"].h_w_per_m2k");
        let s: FitSpec = "thermal.nodes[\"sump\"].mass_kg".parse().unwrap();
        assert_eq!(s.bounds, None);
        assert!("a.b=5:1".parse::<FitSpec>().is_err());
        assert!("a.b=x:1".parse::<FitSpec>().is_err());
        assert!("a.b=nan:1".parse::<FitSpec>().is_err());
    }

    #[test]
    fn coordinates() {
        let doc: Table = "[a]\nb = 2.0\nt_c = 20.0\nz = 0.0\n".parse().unwrap();
        let p = Parameter::resolve(&"a.b".parse().unwrap(), &doc).unwrap();
        assert!(p.log && p.lo == 0.2 && p.hi == 20.0);
        assert!((p.value(p.theta(3.0)) - 3.0).abs() < 1e-12);
        let t = Parameter::resolve(&"a.t_c".parse().unwrap(), &doc).unwrap();
        assert!(!t.log && t.lo == -10.0);
        assert!(Parameter::resolve(&"a.z".parse().unwrap(), &doc).is_err());
        assert!(Parameter::resolve(&"a.missing".parse().unwrap(), &doc).is_err());
        let m = Parameter::resolve(&"a.missing=1:4".parse().unwrap(), &doc).unwrap();
        assert_eq!(m.start, 2.0);
        assert!(Parameter::resolve(&"a.b=3:4".parse().unwrap(), &doc).is_err());
    }

    #[test]
    fn an_integer_written_for_a_real_key_is_fitted_as_a_real() {
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/models/fzg_c.toml");
        let mut doc: Table = std::fs::read_to_string(file).unwrap().parse().unwrap();
        doc["lubrication"]["oil_level_mm"] = Value::Integer(150);
        let level = Parameter::resolve(&"lubrication.oil_level_mm=100:200".parse().unwrap(), &doc).unwrap();
        assert!(!level.integer);
        assert_eq!(level.override_at(150.4).value, Value::Float(150.4));
        let teeth = Parameter::resolve(&"gears[0].teeth=14:18".parse().unwrap(), &doc).unwrap();
        assert!(teeth.integer);
    }

    #[test]
    fn written_values_are_the_start_the_bounds_and_integers() {
        let doc: Table = "[a]\nh = 250.0\nteeth = 16\n".parse().unwrap();
        let h = Parameter::resolve(&"a.h=14:1000".parse().unwrap(), &doc).unwrap();
        assert_ne!(h.value(h.theta(250.0)), 250.0);
        assert_eq!(h.written(h.theta(250.0)), 250.0);
        assert_eq!(h.written(h.theta(14.0)), 14.0);
        assert_eq!(h.written(h.theta_bounds().0 - 1.0), 14.0);
        let (up, down, d) = h.difference_pair(h.theta_bounds().1);
        assert!(up <= h.theta_bounds().1 && (up - down - 2.0 * d).abs() < 1e-12);
        let t = Parameter::resolve(&"a.teeth".parse().unwrap(), &doc).unwrap();
        assert!(t.integer && t.written(t.theta(16.0)) == 16.0);
        assert_eq!(
            t.override_at(t.written(t.theta(16.0) + 1e-3)).value,
            Value::Integer(16)
        );
    }
}
