//! The ground line of the dig plane: y = 0 (the paper's case) or a polyline
//! with increasing x, extended flat beyond its ends.

use serde::{Deserialize, Serialize};

/// The ground surface in the dig plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ground {
    /// Vertices (x, y) (m), x strictly increasing; empty for the level ground y = 0.
    pub points: Vec<[f64; 2]>,
}

impl Default for Ground {
    fn default() -> Self {
        Self::flat()
    }
}

impl Ground {
    /// Level ground at y = 0.
    pub fn flat() -> Self {
        Self { points: Vec::new() }
    }

    /// Height of the ground at x (m).
    #[inline]
    pub fn height(&self, x: f64) -> f64 {
        let p = &self.points;
        match p.len() {
            0 => 0.0,
            1 => p[0][1],
            n => {
                if x <= p[0][0] {
                    return p[0][1];
                }
                if x >= p[n - 1][0] {
                    return p[n - 1][1];
                }
                // Few vertices: a linear scan.
                let i = p.windows(2).position(|w| x <= w[1][0]).unwrap_or(n - 2);
                let (a, b) = (p[i], p[i + 1]);
                a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0])
            }
        }
    }

    /// Depth of a point below the ground (negative above it) (m).
    #[inline]
    pub fn depth(&self, x: f64, y: f64) -> f64 {
        self.height(x) - y
    }

    /// Why the vertices are unusable, if they are.
    pub fn problem(&self) -> Option<String> {
        for (i, p) in self.points.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Some(format!("vertex {i} is not finite"));
            }
        }
        for (i, w) in self.points.windows(2).enumerate() {
            if w[1][0] <= w[0][0] {
                return Some(format!(
                    "x must increase: vertex {} (x = {}) is not right of vertex {i} (x = {})",
                    i + 1,
                    w[1][0],
                    w[0][0]
                ));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_polyline_interpolates_and_extends_flat() {
        let g = Ground {
            points: vec![[0.0, 0.0], [4.0, 0.0], [8.0, 1.0]],
        };
        assert_eq!(g.height(-1.0), 0.0);
        assert_eq!(g.height(2.0), 0.0);
        assert!((g.height(6.0) - 0.5).abs() < 1e-15);
        assert_eq!(g.height(9.0), 1.0);
        assert!((g.depth(6.0, -0.2) - 0.7).abs() < 1e-15);
        assert_eq!(Ground::flat().height(3.0), 0.0);
        assert!(Ground {
            points: vec![[1.0, 0.0], [1.0, 2.0]]
        }
        .problem()
        .is_some());
    }
}
