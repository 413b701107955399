//! Buried obstacles as envelope circles (paper §2.1, [HE eq. 10]):
//! S = {(x, y) | (x − x₀)² + (y − y₀)² ≤ r₀²}. The paper envelops each hard
//! block larger than 30 % of the bucket volume by a circle, which enlarges it
//! but makes collision tests one distance comparison.

use autoshovel_core::Vec2;
use serde::{Deserialize, Serialize};

/// An envelope circle S(p₀, r₀) in the dig plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Envelope {
    /// Centre p₀ = (x₀, y₀) (m).
    pub center_m: [f64; 2],
    /// r₀ (m).
    pub radius_m: f64,
}

impl Envelope {
    /// A circle.
    pub fn new(center: Vec2, radius_m: f64) -> Self {
        Self {
            center_m: [center.x, center.y],
            radius_m,
        }
    }

    /// p₀.
    #[inline]
    pub fn center(&self) -> Vec2 {
        Vec2::new(self.center_m[0], self.center_m[1])
    }

    /// Signed distance of a point from the circle (negative inside, i.e. in
    /// S of [HE eq. 10]) (m).
    #[inline]
    pub fn signed_distance(&self, p: Vec2) -> f64 {
        (p - self.center()).norm() - self.radius_m // [HE eq. 10], as a distance
    }

    /// True when p ∈ S ([HE eq. 10]).
    #[inline]
    pub fn contains(&self, p: Vec2) -> bool {
        (p - self.center()).norm_squared() <= self.radius_m * self.radius_m // [HE eq. 10]
    }

    /// Outward unit normal at the point of the circle nearest p.
    #[inline]
    pub fn outward_normal(&self, p: Vec2) -> Vec2 {
        let r = p - self.center();
        let n = r.norm();
        if n > 0.0 {
            r / n
        } else {
            Vec2::new(0.0, 1.0)
        }
    }

    /// Area of the circle (m²).
    pub fn area_m2(&self) -> f64 {
        std::f64::consts::PI * self.radius_m * self.radius_m
    }

    /// True when the segment a–b meets the circle.
    pub fn meets_segment(&self, a: Vec2, b: Vec2) -> bool {
        let c = self.center();
        let ab = b - a;
        let len2 = ab.norm_squared();
        let t = if len2 > 0.0 {
            ((c - a).dot(&ab) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + ab * t - c).norm_squared() <= self.radius_m * self.radius_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq_10_membership_distance_and_normal() {
        let s = Envelope::new(Vec2::new(6.0, -0.5), 0.25);
        assert!(s.contains(Vec2::new(6.1, -0.4)));
        assert!(!s.contains(Vec2::new(6.3, -0.5)));
        assert!((s.signed_distance(Vec2::new(6.0, 0.0)) - 0.25).abs() < 1e-15);
        let n = s.outward_normal(Vec2::new(6.0, -0.2));
        assert!((n - Vec2::new(0.0, 1.0)).norm() < 1e-15);
        assert!(s.meets_segment(Vec2::new(5.0, -0.5), Vec2::new(7.0, -0.5)));
        assert!(!s.meets_segment(Vec2::new(5.0, 0.0), Vec2::new(7.0, 0.0)));
    }
}
