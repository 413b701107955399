//! The direction of travel of a crawler along a leg: the walk planner
//! plans it, the tracker follows it, the run log records it.

use serde::{Deserialize, Serialize};

/// Direction of travel along a leg.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// The machine moves the way it faces.
    Forward,
    /// The machine backs up: it moves opposite to its heading.
    Reverse,
}

impl Direction {
    /// +1 forward, −1 reverse.
    pub fn sign(self) -> f64 {
        match self {
            Direction::Forward => 1.0,
            Direction::Reverse => -1.0,
        }
    }

    /// Heading of motion for a machine heading `theta_rad`.
    pub fn motion_heading(self, theta_rad: f64) -> f64 {
        match self {
            Direction::Forward => theta_rad,
            Direction::Reverse => theta_rad + std::f64::consts::PI,
        }
    }

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Direction::Forward => "forward",
            Direction::Reverse => "reverse",
        }
    }
}
