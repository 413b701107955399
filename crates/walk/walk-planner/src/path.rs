//! Planned travel paths: legs with a direction of travel (electric-shovel
//! paper Fig. 1: straight and curve, forward or reverse; V-shape = reverse to
//! a midpoint, stop, then forward).

use autoshovel_core::{Pose2, Vec2};
use serde::{Deserialize, Serialize};

pub use autoshovel_core::Direction;

/// One sample of a smoothed path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PathPoint {
    /// Centroid pose; θ is the *machine* heading (opposite to the motion on a reverse leg).
    pub pose: Pose2,
    /// Arc length from the start of the whole path (m).
    pub s_m: f64,
    /// Signed curvature of the centroid's track, positive turning left in the direction of motion (1/m).
    pub curvature_per_m: f64,
}

/// A leg: a stretch travelled in one direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    /// Forward or reverse.
    pub direction: Direction,
    /// The raw potential-field polyline, start to goal (m).
    pub raw: Vec<Vec2>,
    /// The smoothed, resampled path.
    pub points: Vec<PathPoint>,
}

impl Leg {
    /// Length of the smoothed leg (m).
    pub fn length_m(&self) -> f64 {
        match (self.points.first(), self.points.last()) {
            (Some(a), Some(b)) => b.s_m - a.s_m,
            _ => 0.0,
        }
    }
}

/// A whole travel path: one or more legs, the machine stopping between them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Path {
    /// The legs in travel order.
    pub legs: Vec<Leg>,
}

impl Path {
    /// Total length (m).
    pub fn length_m(&self) -> f64 {
        self.legs.iter().map(Leg::length_m).sum()
    }

    /// Every sample with the direction of its leg, in travel order.
    pub fn samples(&self) -> impl Iterator<Item = (Direction, &PathPoint)> {
        self.legs
            .iter()
            .flat_map(|l| l.points.iter().map(move |p| (l.direction, p)))
    }

    /// The final pose, if any.
    pub fn end_pose(&self) -> Option<Pose2> {
        self.legs
            .last()
            .and_then(|l| l.points.last())
            .map(|p| p.pose)
    }
}
