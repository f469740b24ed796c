//! `[[thermal.boundaries]]`: nodes with a given temperature, fixed or a time series; one of them
//! is the ambient air.

use crate::physics::units::c_to_k;
use serde::{Deserialize, Serialize};

use super::common::temp_ok;
use crate::model::problems::Problems;

/// `[[thermal.boundaries]]` as written: a boundary node, fixed temperature or a time series.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    /// Identifier.
    pub name: String,
    /// Fixed temperature, °C.
    #[serde(default)]
    pub temp_c: Option<f64>,
    /// Time series `[[time_s, temp_c], ...]`, linear in between, constant beyond the ends.
    #[serde(default)]
    pub series: Option<Vec<[f64; 2]>>,
    /// The ambient air (set by `--ambient-c`); default: the boundary named `ambient`.
    #[serde(default)]
    pub ambient: Option<bool>,
    /// Where the numbers come from.
    #[serde(default)]
    pub note: Option<String>,
}

/// Temperature of a boundary.
#[derive(Debug, Clone)]
pub enum BoundaryTemp {
    /// Constant, K.
    Fixed(f64),
    /// (time s, K) pairs, strictly increasing time.
    Series(Vec<(f64, f64)>),
}

impl BoundaryTemp {
    /// True when the temperature changes with time.
    pub fn moves(&self) -> bool {
        match self {
            BoundaryTemp::Fixed(_) => false,
            BoundaryTemp::Series(s) => s.windows(2).any(|w| w[0].1 != w[1].1),
        }
    }

    /// dT/dt (K/s) on the piece the series follows just after `t` (a kink at `t` gives the
    /// slope of the piece that starts there); 0 before the first and after the last point.
    pub fn slope_at(&self, t: f64) -> f64 {
        match self {
            BoundaryTemp::Fixed(_) => 0.0,
            BoundaryTemp::Series(s) => {
                let k = s.partition_point(|p| p.0 <= t);
                if k == 0 || k == s.len() {
                    0.0
                } else {
                    let (a, b) = (s[k - 1], s[k]);
                    (b.1 - a.1) / (b.0 - a.0)
                }
            }
        }
    }

    /// Temperature at time `t`, K.
    pub fn at(&self, t: f64) -> f64 {
        self.at_from(t, &mut 0)
    }

    /// [`Self::at`], starting the search for the series piece at `hint` (the index of the first
    /// point after `t` at the last call, updated): a right-hand side asks at times close to the
    /// last, so the piece is usually the same or the next one. The same values as [`Self::at`].
    pub fn at_from(&self, t: f64, hint: &mut usize) -> f64 {
        match self {
            BoundaryTemp::Fixed(v) => *v,
            BoundaryTemp::Series(s) => {
                let after = |k: usize| (k == 0 || s[k - 1].0 <= t) && (k == s.len() || s[k].0 > t);
                let k = match *hint {
                    h if h <= s.len() && after(h) => h,
                    h if h < s.len() && after(h + 1) => h + 1,
                    _ => s.partition_point(|p| p.0 <= t),
                };
                *hint = k;
                if k == 0 {
                    s[0].1
                } else if k == s.len() {
                    s[s.len() - 1].1
                } else {
                    let (a, b) = (s[k - 1], s[k]);
                    a.1 + (t - a.0) / (b.0 - a.0) * (b.1 - a.1)
                }
            }
        }
    }
}

/// A checked boundary node.
#[derive(Debug, Clone)]
pub struct Boundary {
    /// Name.
    pub name: String,
    /// Temperature law.
    pub temp: BoundaryTemp,
    /// True for the ambient air.
    pub ambient: bool,
}

/// Check every boundary (temperature or series) and mark the ambient one (`ambient = true`, at
/// most one; else the boundary named `ambient`). Boundaries with a problem are left out.
pub(crate) fn check_boundaries(specs: &[BoundarySpec], problems: &mut Problems) -> Vec<Boundary> {
    let mut boundaries = Vec::new();
    for (i, b) in specs.iter().enumerate() {
        let p = format!("thermal.boundaries[{i}]");
        let temp = match (&b.temp_c, &b.series) {
            (Some(t), None) => {
                temp_ok(problems, &format!("{p}.temp_c"), *t);
                BoundaryTemp::Fixed(c_to_k(*t))
            }
            (None, Some(s)) if !s.is_empty() => match series(s, &p, problems) {
                Some(s) => s,
                None => continue,
            },
            _ => {
                problems.push(&p, "", "give either temp_c or a non-empty series (not both)");
                continue;
            }
        };
        boundaries.push(Boundary {
            name: b.name.clone(),
            temp,
            ambient: b.ambient.unwrap_or(false),
        });
    }
    if boundaries.iter().filter(|b| b.ambient).count() > 1 {
        problems.push(
            "thermal.boundaries",
            "",
            "at most one boundary may be marked ambient = true",
        );
    }
    if !boundaries.iter().any(|b| b.ambient) {
        if let Some(b) = boundaries.iter_mut().find(|b| b.name == "ambient") {
            b.ambient = true;
        }
    }
    boundaries
}

/// A temperature series `[[time_s, temp_c], ...]`: temperatures in range, times increasing.
fn series(s: &[[f64; 2]], p: &str, problems: &mut Problems) -> Option<BoundaryTemp> {
    let mut ok = true;
    for (k, pt) in s.iter().enumerate() {
        ok &= temp_ok(problems, &format!("{p}.series[{k}][1]"), pt[1]);
        if !pt[0].is_finite() || (k > 0 && pt[0] <= s[k - 1][0]) {
            problems.push(
                format!("{p}.series[{k}][0]"),
                pt[0],
                "times must increase strictly",
            );
            ok = false;
        }
    }
    ok.then(|| BoundaryTemp::Series(s.iter().map(|pt| (pt[0], c_to_k(pt[1]))).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_from_a_hint_is_the_plain_lookup() {
        let b = BoundaryTemp::Series(vec![(0.0, 300.0), (10.0, 310.0), (20.0, 305.0), (30.0, 320.0)]);
        let mut hint = 0;
        // Forward, backward, repeated, outside the series and NaN, each against `at`.
        for t in [
            -5.0,
            0.0,
            3.0,
            10.0,
            12.5,
            12.5,
            29.9,
            30.0,
            45.0,
            1.0,
            25.0,
            f64::NAN,
            15.0,
        ] {
            let (a, b2) = (b.at(t), b.at_from(t, &mut hint));
            assert_eq!(a.to_bits(), b2.to_bits(), "t = {t}");
        }
        assert_eq!(BoundaryTemp::Fixed(290.0).at_from(7.0, &mut hint), 290.0);
    }
}
