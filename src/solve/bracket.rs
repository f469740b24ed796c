//! The Illinois variant of regula falsi on a bracket [a, b] with f(a) ≤ 0 < f(b): the trial
//! point is the secant's root (bisection when the secant leaves the bracket or is flat), and
//! the function value kept at an end that stays twice in a row is halved, so that the bracket
//! closes from both sides (Dowell & Jarratt, "A modified regula falsi method for computing the
//! root of an equation", BIT 11, 1971, 168–174). Used on the size of an integrator's step to
//! find the instant a controller's switching function crosses zero.

/// Times closer than this, relative to max(1, |t|), end the search.
pub(crate) const EVENT_TIME_TOL: f64 = 1e-13;

/// Most trial points per located event.
pub(crate) const EVENT_MAX_ITER: usize = 100;

/// A bracket of the root and which end moved last.
pub(crate) struct Bracket {
    /// Inside end (f ≤ 0) and its value.
    pub(crate) a: f64,
    fa: f64,
    /// Outside end (f > 0) and its value.
    pub(crate) b: f64,
    fb: f64,
    /// −1: b moved last; 1: a moved last; 0: neither yet.
    side: i8,
}

impl Bracket {
    /// The bracket [a, b] with f(a) = `fa` ≤ 0 < f(b) = `fb`.
    pub(crate) fn new(a: f64, fa: f64, b: f64, fb: f64) -> Bracket {
        Bracket {
            a,
            fa,
            b,
            fb,
            side: 0,
        }
    }

    /// The next trial point, strictly inside the bracket.
    pub(crate) fn trial(&self) -> f64 {
        let (a, b) = (self.a, self.b);
        let c = if self.fb != self.fa {
            b - self.fb * (b - a) / (self.fb - self.fa)
        } else {
            0.5 * (a + b)
        };
        if c > a && c < b {
            c
        } else {
            0.5 * (a + b)
        }
    }

    /// Narrow the bracket with f(c) = `fc`.
    pub(crate) fn update(&mut self, c: f64, fc: f64) {
        if fc > 0.0 {
            (self.b, self.fb) = (c, fc);
            if self.side == -1 {
                self.fa *= 0.5;
            }
            self.side = -1;
        } else {
            (self.a, self.fa) = (c, fc);
            if self.side == 1 {
                self.fb *= 0.5;
            }
            self.side = 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x) = x³ − 0.3 (root 0.3^(1/3)): the bracket closes to the tolerance within the budget,
    /// from both sides (plain regula falsi keeps one end fixed on a convex function).
    #[test]
    fn closes_on_a_convex_function() {
        let f = |x: f64| x * x * x - 0.3;
        let mut br = Bracket::new(0.0, f(0.0), 1.0, f(1.0));
        let mut n = 0;
        while br.b - br.a > EVENT_TIME_TOL && n < EVENT_MAX_ITER {
            let c = br.trial();
            br.update(c, f(c));
            n += 1;
        }
        let root = 0.3f64.cbrt();
        assert!(br.b - br.a <= EVENT_TIME_TOL, "{n} trials, [{}, {}]", br.a, br.b);
        assert!(br.a <= root && root <= br.b + 1e-15, "{n} trials");
        // Plain regula falsi (no halving) on the same bracket keeps b = 1 and does not close.
        let (mut a, mut b) = (0.0f64, 1.0f64);
        for _ in 0..EVENT_MAX_ITER {
            let c = b - f(b) * (b - a) / (f(b) - f(a));
            if f(c) > 0.0 {
                b = c;
            } else {
                a = c;
            }
        }
        assert!(b - a > 0.1, "plain regula falsi closed to [{a}, {b}]");
    }
}
