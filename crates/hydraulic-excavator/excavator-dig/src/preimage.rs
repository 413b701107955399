//! Preimage planning (paper §2.2): which side of a boulder to pass, from the
//! angle γ between the tip velocity V_c and the contact force F_f.
//!
//! The paper: γ ∈ (0°, 180°) → pass along the upper half, γ ∈ (180°, 360°) →
//! the lower half. Its Fig. 3 has the machine on the right, so digging moves
//! towards +x there and γ counted counter-clockwise from V_c puts F_f on the
//! upper side of the motion for γ ∈ (0°, 180°). Our frame (SPEC §1) has the
//! machine at x = 0 and digging moves towards −x, which mirrors the figure.
//! We therefore count γ **clockwise** from V_c to F_f in our frame — the
//! paper's counter-clockwise angle in its mirrored frame — so that the rule
//! keeps its meaning: a force pushing the tip to the upper side of its motion
//! (the tooth met the boulder's upper part) means "over", one pushing it to the
//! lower side means "under":
//!
//! ```text
//!     γ = atan2(−(V × F), V · F) mod 360°,   V × F = V_x F_y − V_y F_x
//! ```
//!
//! The boundary cases γ = 0° and 180° (a head-on hit through the centre,
//! which the paper leaves open) choose "over": lifting out costs no depth.
//!
//! **This reading is an assumption.** Fig. 3, which fixes the sense of γ, is
//! not in the text we have; the text says only which interval means which
//! half. [`GammaReading::Clockwise`] (the default) is the reading above: a
//! boulder that pushes the tip up, to the upper side of its motion, is passed
//! over, one that pushes it down is passed under (tested on both paper cases
//! in `tests/paper.rs`). [`GammaReading::Mirrored`] counts γ
//! counter-clockwise in our frame — the figure read without the mirror — and
//! so swaps the two: the bucket then dives under a boulder it met on top.

use std::fmt;

use autoshovel_core::Vec2;
use serde::{Deserialize, Serialize};

/// The side of an obstacle the bucket passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AvoidSide {
    /// Along the upper half of the envelope.
    Over,
    /// Along the lower half.
    Under,
}

impl fmt::Display for AvoidSide {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            AvoidSide::Over => "over",
            AvoidSide::Under => "under",
        })
    }
}

/// Which way γ is counted in our frame (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GammaReading {
    /// Clockwise from V_c to F_f: the paper's counter-clockwise angle in its
    /// mirrored Fig. 3 (the default).
    #[default]
    Clockwise,
    /// Counter-clockwise from V_c to F_f in our frame.
    Mirrored,
}

impl GammaReading {
    /// γ (rad) in [0, 2π) from the tip velocity to the contact force.
    pub fn gamma_rad(self, velocity: Vec2, force: Vec2) -> f64 {
        let g = gamma_rad(velocity, force);
        match self {
            GammaReading::Clockwise => g,
            GammaReading::Mirrored => (std::f64::consts::TAU - g) % std::f64::consts::TAU,
        }
    }
}

/// γ (rad) in [0, 2π): clockwise angle from the tip velocity to the contact force (module docs).
pub fn gamma_rad(velocity: Vec2, force: Vec2) -> f64 {
    let cross = velocity.x * force.y - velocity.y * force.x;
    let dot = velocity.dot(&force);
    let g = (-cross).atan2(dot);
    if g < 0.0 {
        g + std::f64::consts::TAU
    } else {
        g
    }
}

/// The preimage rule: γ ∈ [0°, 180°] → over, (180°, 360°) → under.
pub fn decide(gamma_rad: f64) -> AvoidSide {
    if gamma_rad <= std::f64::consts::PI {
        AvoidSide::Over
    } else {
        AvoidSide::Under
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn a_force_to_the_upper_side_of_the_motion_means_over() {
        // Moving towards the machine, pushed up: γ = 90°.
        let g = gamma_rad(Vec2::new(-1.0, 0.0), Vec2::new(0.0, 1.0));
        assert_relative_eq!(g.to_degrees(), 90.0, epsilon = 1e-12);
        assert_eq!(decide(g), AvoidSide::Over);
        // Pushed back and down: γ = 225°.
        let g = gamma_rad(Vec2::new(-1.0, 0.0), Vec2::new(1.0, -1.0));
        assert_relative_eq!(g.to_degrees(), 225.0, epsilon = 1e-12);
        assert_eq!(decide(g), AvoidSide::Under);
        // Head-on.
        assert_eq!(
            decide(gamma_rad(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0))),
            AvoidSide::Over
        );
    }

    #[test]
    fn the_mirrored_reading_swaps_the_sides() {
        let (v, up, down) = (
            Vec2::new(-1.0, -0.5),
            Vec2::new(0.4, 1.0),
            Vec2::new(0.6, -1.0),
        );
        let side = |r: GammaReading, f| decide(r.gamma_rad(v, f));
        assert_eq!(side(GammaReading::Clockwise, up), AvoidSide::Over);
        assert_eq!(side(GammaReading::Clockwise, down), AvoidSide::Under);
        assert_eq!(side(GammaReading::Mirrored, up), AvoidSide::Under);
        assert_eq!(side(GammaReading::Mirrored, down), AvoidSide::Over);
    }

    #[test]
    fn mirroring_the_frame_gives_the_papers_counter_clockwise_angle() {
        // The paper's Fig. 3: machine on the right, motion towards +x.
        let mirror = |v: Vec2| Vec2::new(-v.x, v.y);
        for (v, f) in [
            (Vec2::new(-1.0, -0.4), Vec2::new(0.3, 1.0)),
            (Vec2::new(-0.2, -1.0), Vec2::new(0.9, -0.1)),
            (Vec2::new(-1.0, 0.3), Vec2::new(0.5, -0.8)),
        ] {
            let (pv, pf) = (mirror(v), mirror(f));
            let ccw = (pv.x * pf.y - pv.y * pf.x)
                .atan2(pv.dot(&pf))
                .rem_euclid(std::f64::consts::TAU);
            assert_relative_eq!(gamma_rad(v, f), ccw, epsilon = 1e-12);
        }
    }
}
