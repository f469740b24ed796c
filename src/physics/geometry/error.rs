//! Errors of the geometry layer.

use std::fmt;

/// Why a gear or a mesh cannot be built. Every variant names the offending values (SI units)
/// so that the validation layer can report them to the user.
#[derive(Debug, Clone, PartialEq)]
pub enum GeometryError {
    /// A single input is out of its admissible range (non-finite, non-positive, ...).
    InvalidParameter {
        /// Field name (e.g. `"mn"`, `"alpha_n"`).
        name: &'static str,
        /// The value given (SI).
        value: f64,
        /// What is allowed, in words.
        requirement: &'static str,
    },
    /// Two gears of a mesh disagree on a quantity that must be common.
    Mismatch {
        /// The quantity (e.g. `"normal module mn [m]"`).
        quantity: &'static str,
        /// Value on gear 1.
        gear1: f64,
        /// Value on gear 2.
        gear2: f64,
    },
    /// The data are individually valid but together describe an impossible gear or mesh
    /// (root circle below zero, tip circle inside the base circle, pointed tooth, negative
    /// backlash, ...). The message contains the numbers.
    Impossible(String),
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GeometryError::InvalidParameter {
                name,
                value,
                requirement,
            } => write!(f, "invalid gear parameter {name} = {value:e}: {requirement}"),
            GeometryError::Mismatch {
                quantity,
                gear1,
                gear2,
            } => write!(
                f,
                "meshing gears must have the same {quantity}: gear 1 has {gear1:e}, gear 2 has {gear2:e}"
            ),
            GeometryError::Impossible(msg) => write!(f, "impossible gear geometry: {msg}"),
        }
    }
}

impl std::error::Error for GeometryError {}

/// Reject non-finite values.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, GeometryError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(GeometryError::InvalidParameter {
            name,
            value,
            requirement: "must be a finite number",
        })
    }
}

/// Reject non-finite or non-positive values.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, GeometryError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(GeometryError::InvalidParameter {
            name,
            value,
            requirement: "must be a finite number > 0",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_values() {
        let e = GeometryError::Mismatch {
            quantity: "normal module mn [m]",
            gear1: 0.003,
            gear2: 0.0035,
        };
        let s = e.to_string();
        assert!(s.contains("3e-3") && s.contains("3.5e-3"), "{s}");
        assert!(positive("mn", -1.0).is_err());
        assert!(positive("mn", f64::NAN).is_err());
        assert!(finite("x", f64::INFINITY).is_err());
        assert_eq!(finite("x", -0.5), Ok(-0.5));
    }
}
