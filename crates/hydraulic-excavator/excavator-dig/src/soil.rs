//! The digging resistance of the soil and the reaction of a boulder.
//!
//! The paper measures a jump in the digging resistance when the bucket meets
//! a boulder (§2.2) but gives no resistance model. We use the cutting model of
//! Zelenin/Dombrovskii (as SPEC §4.2 does for the rope shovel):
//!
//! ```text
//!     F_τ = k·b·c        against the tip's direction of motion v̂
//!     F_n = ψ·F_τ        along n̂ = v̂ turned 90° clockwise, the upper side of the motion
//! ```
//!
//! with the specific cutting resistance k (Pa), the bucket width b = h_b and
//! the cut thickness c, here the depth of the tooth below the ground (in one
//! pass the bucket takes the whole slice above its tip, which is [HE eq. 2]'s
//! volume model). F_n pushes the tooth out of the uncut bank, towards the
//! surface. The force does not depend on speed, so the direction of motion is
//! the path's tangent even where the tip is at rest at a segment end.
//!
//! A boulder stalls the bucket: on contact the tip stops and the boulder pushes
//! back with the machine's full digging force F_max, along the envelope's
//! outward normal n at the contact point, tilted by Coulomb friction μ against
//! the tip's sliding direction t̂ (the tangential part of its velocity):
//! F_f = F_max (n − μ t̂)/|n − μ t̂|. That is the force jump the simulator
//! reports, and its direction drives the preimage rule (`preimage`).

use autoshovel_core::Vec2;
use serde::{Deserialize, Serialize};

use crate::ground::Ground;

/// Soil and rock parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Soil {
    /// k of F_τ = k·b·c (Pa). Loam ≈ 40–100 kPa, clay ≈ 100–250 kPa.
    pub cutting_resistance_pa: f64,
    /// ψ of F_n = ψ·F_τ.
    pub normal_ratio: f64,
    /// Bank density of the dug soil, carried in the bucket (kg/m³).
    pub density_kg_m3: f64,
    /// μ: Coulomb friction between the tooth and a boulder.
    pub rock_friction: f64,
}

impl Soil {
    /// Resistance on the tooth at `tip` moving along `direction` (need not be
    /// unit), for a bucket `width_m` wide (N). Zero above the ground or when
    /// the direction is undefined.
    #[inline]
    pub fn resistance(&self, ground: &Ground, tip: Vec2, direction: Vec2, width_m: f64) -> Vec2 {
        let c = ground.depth(tip.x, tip.y);
        let n = direction.norm();
        if c <= 0.0 || n <= 0.0 {
            return Vec2::zeros();
        }
        let v = direction / n;
        let up_side = Vec2::new(v.y, -v.x);
        let f_tau = self.cutting_resistance_pa * width_m * c;
        (-v + up_side * self.normal_ratio) * f_tau
    }

    /// The boulder's push on a tooth that meets its envelope at a point with
    /// outward normal `normal`, moving with velocity (or direction) `velocity`,
    /// for a machine of digging force `max_force_n` (N) (module docs).
    pub fn contact_force(&self, normal: Vec2, velocity: Vec2, max_force_n: f64) -> Vec2 {
        let tangential = velocity - normal * velocity.dot(&normal);
        let t = tangential.norm();
        let mut dir = normal;
        if t > 1e-12 * velocity.norm().max(1e-300) {
            dir -= tangential / t * self.rock_friction;
        }
        dir.normalize() * max_force_n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn soil() -> Soil {
        Soil {
            cutting_resistance_pa: 60_000.0,
            normal_ratio: 0.3,
            density_kg_m3: 1800.0,
            rock_friction: 0.3,
        }
    }

    #[test]
    fn cutting_resistance_is_k_b_c_against_the_motion_with_a_push_upwards() {
        let f = soil().resistance(
            &Ground::flat(),
            Vec2::new(5.0, -0.5),
            Vec2::new(-2.0, 0.0),
            1.0,
        );
        assert_relative_eq!(f.x, 30_000.0, epsilon = 1e-9);
        assert_relative_eq!(f.y, 9_000.0, epsilon = 1e-9);
        let above = soil().resistance(
            &Ground::flat(),
            Vec2::new(5.0, 0.1),
            Vec2::new(-1.0, 0.0),
            1.0,
        );
        assert_eq!(above, Vec2::zeros());
    }

    #[test]
    fn a_boulder_pushes_along_its_normal_tilted_against_the_sliding() {
        let s = soil();
        let n = Vec2::new(0.0, 1.0);
        let f = s.contact_force(n, Vec2::new(-1.0, -1.0), 100_000.0);
        assert_relative_eq!(f.norm(), 100_000.0, epsilon = 1e-6);
        // Sliding towards −x: friction pushes towards +x.
        assert_relative_eq!(f.x / f.y, 0.3, epsilon = 1e-12);
        let head_on = s.contact_force(n, Vec2::new(0.0, -1.0), 1.0);
        assert_relative_eq!(head_on, n, epsilon = 1e-15);
    }
}
