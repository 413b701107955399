//! Membership functions: the degree μ(x) ∈ [0, 1] to which a crisp value x
//! belongs to a linguistic term (Zadeh 1965; the triangular and trapezoidal
//! shapes are those of Mamdani & Assilian 1975, and the triangles are the
//! ones the paper's §4.3 / Fig. 8 draws for e, ec and u).
//!
//! Shoulders: a triangle or trapezoid with a vertical edge (`a == b`, or
//! `b == c` for a triangle / `c == d` for a trapezoid) is open on that side:
//! its degree is 1 at and beyond that edge. That is how the outermost terms
//! (NB, PB) of a controller's partition are drawn, and, together with the
//! clamping of inputs to the universe done by [`crate::Variable`], it makes
//! them saturate: any e below the universe is "fully NB".

use serde::{Deserialize, Serialize};

/// A membership function of one real variable.
///
/// Parameters are in the variable's own unit (e.g. (m) for e, (rpm) for u).
/// Validity (ordering, finiteness, positive width) is checked by
/// [`Membership::check`], which every system constructor calls.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Membership {
    /// Triangle rising from `a` to a peak at `b` and falling to `c`
    /// (`a ≤ b ≤ c`, `a < c`). `a == b` is a left shoulder (μ = 1 for
    /// x ≤ b), `b == c` a right shoulder (μ = 1 for x ≥ b).
    Triangle {
        /// Left foot.
        a: f64,
        /// Peak.
        b: f64,
        /// Right foot.
        c: f64,
    },
    /// Trapezoid rising from `a` to `b`, flat at 1 to `c`, falling to `d`
    /// (`a ≤ b ≤ c ≤ d`, `a < d`). `a == b` is a left shoulder (μ = 1 for
    /// x ≤ c), `c == d` a right shoulder (μ = 1 for x ≥ b).
    Trapezoid {
        /// Left foot.
        a: f64,
        /// Left end of the plateau.
        b: f64,
        /// Right end of the plateau.
        c: f64,
        /// Right foot.
        d: f64,
    },
    /// Gaussian bell `exp(−(x − mean)² / (2 σ²))`, `σ > 0`.
    Gaussian {
        /// Centre (μ = 1).
        mean: f64,
        /// Standard deviation (same unit as x).
        sigma: f64,
    },
}

impl Membership {
    /// Degree of membership of `x`, in `[0, 1]`.
    ///
    /// No clamping happens here (a [`crate::Variable`] clamps to its universe
    /// before calling this); shoulders are open to ±∞ as documented on the
    /// variants. A NaN `x` has degree 0. Never panics.
    pub fn degree(&self, x: f64) -> f64 {
        if x.is_nan() {
            return 0.0;
        }
        match *self {
            Membership::Triangle { a, b, c } => {
                if x < b {
                    rising(x, a, b)
                } else if x > b {
                    falling(x, b, c)
                } else {
                    1.0
                }
            }
            Membership::Trapezoid { a, b, c, d } => {
                if x < b {
                    rising(x, a, b)
                } else if x > c {
                    falling(x, c, d)
                } else {
                    1.0
                }
            }
            Membership::Gaussian { mean, sigma } => {
                let z = (x - mean) / sigma;
                (-0.5 * z * z).exp()
            }
        }
    }

    /// The interval on which the degree is 1 (a point for a triangle or a
    /// Gaussian, the plateau for a trapezoid).
    pub fn core(&self) -> (f64, f64) {
        match *self {
            Membership::Triangle { b, .. } => (b, b),
            Membership::Trapezoid { b, c, .. } => (b, c),
            Membership::Gaussian { mean, .. } => (mean, mean),
        }
    }

    /// Checks the parameters: all finite, feet ordered, positive width,
    /// positive σ. Returns the reason on failure (the caller names the term).
    pub fn check(&self) -> Result<(), &'static str> {
        match *self {
            Membership::Triangle { a, b, c } => {
                if !(a.is_finite() && b.is_finite() && c.is_finite()) {
                    Err("triangle parameters must be finite")
                } else if !(a <= b && b <= c) {
                    Err("triangle needs a <= b <= c")
                } else if a >= c {
                    Err("triangle has zero width (a == c)")
                } else {
                    Ok(())
                }
            }
            Membership::Trapezoid { a, b, c, d } => {
                if !(a.is_finite() && b.is_finite() && c.is_finite() && d.is_finite()) {
                    Err("trapezoid parameters must be finite")
                } else if !(a <= b && b <= c && c <= d) {
                    Err("trapezoid needs a <= b <= c <= d")
                } else if a >= d {
                    Err("trapezoid has zero width (a == d)")
                } else {
                    Ok(())
                }
            }
            Membership::Gaussian { mean, sigma } => {
                if !(mean.is_finite() && sigma.is_finite()) {
                    Err("gaussian parameters must be finite")
                } else if sigma <= 0.0 {
                    Err("gaussian needs sigma > 0")
                } else {
                    Ok(())
                }
            }
        }
    }
}

/// Left edge from foot `a` to top `b` (x < b): 1 everywhere for a shoulder.
fn rising(x: f64, a: f64, b: f64) -> f64 {
    if a == b {
        1.0
    } else if x <= a {
        0.0
    } else {
        (x - a) / (b - a)
    }
}

/// Right edge from top `b` to foot `c` (x > b): 1 everywhere for a shoulder.
fn falling(x: f64, b: f64, c: f64) -> f64 {
    if b == c {
        1.0
    } else if x >= c {
        0.0
    } else {
        (c - x) / (c - b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_values() {
        let t = Membership::Triangle {
            a: -1.0,
            b: 0.0,
            c: 2.0,
        };
        assert_eq!(t.degree(-1.0), 0.0);
        assert_eq!(t.degree(-0.5), 0.5);
        assert_eq!(t.degree(0.0), 1.0);
        assert_eq!(t.degree(1.0), 0.5);
        assert_eq!(t.degree(2.0), 0.0);
        assert_eq!(t.degree(5.0), 0.0);
        assert_eq!(t.degree(f64::NAN), 0.0);
    }

    #[test]
    fn shoulders_open_outwards() {
        let left = Membership::Triangle {
            a: 0.0,
            b: 0.0,
            c: 1.0,
        };
        assert_eq!(left.degree(-10.0), 1.0);
        assert_eq!(left.degree(0.0), 1.0);
        assert_eq!(left.degree(0.25), 0.75);
        assert_eq!(left.degree(1.0), 0.0);
        let right = Membership::Triangle {
            a: 0.0,
            b: 1.0,
            c: 1.0,
        };
        assert_eq!(right.degree(f64::INFINITY), 1.0);
        assert_eq!(right.degree(0.5), 0.5);
        assert_eq!(right.degree(-1.0), 0.0);
        let trap = Membership::Trapezoid {
            a: 0.0,
            b: 0.0,
            c: 1.0,
            d: 3.0,
        };
        assert_eq!(trap.degree(-4.0), 1.0);
        assert_eq!(trap.degree(2.0), 0.5);
    }

    #[test]
    fn gaussian_and_checks() {
        let g = Membership::Gaussian {
            mean: 1.0,
            sigma: 2.0,
        };
        assert_eq!(g.degree(1.0), 1.0);
        assert!((g.degree(3.0) - (-0.5f64).exp()).abs() < 1e-15);
        assert!(g.check().is_ok());
        assert!(Membership::Gaussian {
            mean: 0.0,
            sigma: 0.0
        }
        .check()
        .is_err());
        assert!(Membership::Triangle {
            a: 1.0,
            b: 1.0,
            c: 1.0
        }
        .check()
        .is_err());
        assert!(Membership::Triangle {
            a: 0.0,
            b: 2.0,
            c: 1.0
        }
        .check()
        .is_err());
        assert!(Membership::Trapezoid {
            a: 0.0,
            b: f64::NAN,
            c: 1.0,
            d: 2.0
        }
        .check()
        .is_err());
    }
}
