//! Validation problems: every problem found in a model file, each with its key path, the value
//! found and what is allowed.

use std::fmt;

/// One problem in a model file.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Problem {
    /// Key path in the file, e.g. `gears[3].module_mm` (empty for whole-file syntax errors).
    pub path: String,
    /// The offending value as written (or a short description).
    pub value: String,
    /// What is allowed / what went wrong.
    pub allowed: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.path.is_empty(), self.value.is_empty()) {
            (true, _) => write!(f, "{}", self.allowed),
            (false, true) => write!(f, "{}: {}", self.path, self.allowed),
            (false, false) => write!(f, "{} = {}: {}", self.path, self.value, self.allowed),
        }
    }
}

/// Collects problems while validating.
#[derive(Debug, Default, Clone)]
pub struct Problems {
    list: Vec<Problem>,
}

impl Problems {
    /// Record a problem.
    pub fn push(&mut self, path: impl Into<String>, value: impl fmt::Display, allowed: impl Into<String>) {
        self.list.push(Problem {
            path: path.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        });
    }

    /// `value` must be finite and > 0.
    pub fn positive(&mut self, path: &str, value: f64) -> bool {
        if value.is_finite() && value > 0.0 {
            true
        } else {
            self.push(path, value, "must be a positive finite number");
            false
        }
    }

    /// `value` must be finite and within `[lo, hi]`.
    pub fn in_range(&mut self, path: &str, value: f64, lo: f64, hi: f64, unit: &str) -> bool {
        if value.is_finite() && (lo..=hi).contains(&value) {
            true
        } else {
            self.push(path, value, format!("must lie in [{lo}, {hi}]{unit}"));
            false
        }
    }

    /// True when nothing was recorded.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Number of problems.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// The problems, in the order found.
    pub fn into_vec(self) -> Vec<Problem> {
        self.list
    }

    /// Problems recorded so far.
    pub fn as_slice(&self) -> &[Problem] {
        &self.list
    }
}
