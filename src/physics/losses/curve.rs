//! Piecewise-linear characteristic curves y(x) (pump line pressure over torque, converter K factor
//! and torque ratio over speed ratio), held constant beyond the ends. Allocation-free lookup.

/// A curve through points with strictly increasing x, linear in between, constant beyond the ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    x: Vec<f64>,
    y: Vec<f64>,
}

/// Why a curve cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CurveError {
    /// Different numbers of x and y values, or none.
    #[error("needs equally many x and y values, at least one ({0} x, {1} y)")]
    Lengths(usize, usize),
    /// A value is not finite.
    #[error("value {0} is not finite")]
    NotFinite(f64),
    /// x does not increase strictly.
    #[error("x must increase strictly ({0} after {1})")]
    NotIncreasing(f64, f64),
}

impl Curve {
    /// Build from points (x strictly increasing).
    pub fn new(x: Vec<f64>, y: Vec<f64>) -> Result<Curve, CurveError> {
        if x.len() != y.len() || x.is_empty() {
            return Err(CurveError::Lengths(x.len(), y.len()));
        }
        if let Some(v) = x.iter().chain(&y).find(|v| !v.is_finite()) {
            return Err(CurveError::NotFinite(*v));
        }
        if let Some(w) = x.windows(2).find(|w| w[1] <= w[0]) {
            return Err(CurveError::NotIncreasing(w[1], w[0]));
        }
        Ok(Curve { x, y })
    }

    /// y at `x`.
    pub fn at(&self, x: f64) -> f64 {
        let (xs, ys) = (&self.x, &self.y);
        let last = xs.len() - 1;
        if last == 0 || x <= xs[0] {
            return ys[0];
        }
        if x >= xs[last] {
            return ys[last];
        }
        let k = xs.partition_point(|&v| v <= x).saturating_sub(1).min(last - 1);
        let f = (x - xs[k]) / (xs[k + 1] - xs[k]);
        ys[k] + f * (ys[k + 1] - ys[k])
    }

    /// The x values.
    pub fn xs(&self) -> &[f64] {
        &self.x
    }

    /// The y values.
    pub fn ys(&self) -> &[f64] {
        &self.y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_holds_the_ends() {
        let c = Curve::new(vec![0.0, 1.0, 3.0], vec![2.0, 4.0, 0.0]).unwrap();
        assert_eq!(c.at(-1.0), 2.0);
        assert_eq!(c.at(0.5), 3.0);
        assert_eq!(c.at(2.0), 2.0);
        assert_eq!(c.at(9.0), 0.0);
        assert_eq!(c.at(1.0), 4.0);
        assert_eq!(Curve::new(vec![1.0], vec![5.0]).unwrap().at(7.0), 5.0);
        assert!(Curve::new(vec![0.0, 0.0], vec![1.0, 2.0]).is_err());
        assert!(Curve::new(vec![0.0], vec![]).is_err());
        assert!(Curve::new(vec![f64::NAN], vec![1.0]).is_err());
    }
}
