//! Plane geometry: the 2-D vector alias and the planar pose (SPEC §1: x east,
//! y north, heading θ from +x counter-clockwise).

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

/// A point or vector in the ground plane (m).
pub type Vec2 = Vector2<f64>;

/// Unit vector of heading `theta_rad` (from +x, counter-clockwise).
pub fn heading_vec(theta_rad: f64) -> Vec2 {
    Vec2::new(theta_rad.cos(), theta_rad.sin())
}

/// The vector rotated by +90° (to its left).
pub fn perp(v: Vec2) -> Vec2 {
    Vec2::new(-v.y, v.x)
}

/// Planar pose of a machine: position (m) and heading (rad).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose2 {
    /// East (m).
    pub x: f64,
    /// North (m).
    pub y: f64,
    /// Heading from +x, counter-clockwise (rad).
    pub theta: f64,
}

impl Pose2 {
    /// A pose from position (m) and heading (rad).
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Self { x, y, theta }
    }

    /// The position as a vector.
    pub fn position(&self) -> Vec2 {
        Vec2::new(self.x, self.y)
    }

    /// Unit vector along the heading.
    pub fn heading(&self) -> Vec2 {
        heading_vec(self.theta)
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.theta.is_finite()
    }
}
