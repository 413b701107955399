//! The parts of a loading cycle the dig planner does not plan (rope-shovel
//! paper §2.1: digging, rotating, unloading, returning) and the walk's
//! energy, each a stated model:
//!
//! - **Swing** (rotating loaded, returning empty): rest to rest at the
//!   machine's swing acceleration α up to its top speed ω, then braking at
//!   α — a trapezoid, or a triangle when the angle is too small to reach
//!   ω: t = θ/ω + ω/α for θ ≥ ω²/α, else 2√(θ/α). Energy is what the
//!   swing motors put in to accelerate, ½·J·ω_peak², with J the upper
//!   works' inertia plus the load's m·r² at the dipper's radius; braking
//!   is taken as not recovered and its energy not counted (a machine that
//!   regenerates spends less). Friction of the swing bearing is left out.
//! - **Dump**: a fixed time to open the door and let the load fall; the
//!   hoist holds the dipper still (no work).
//! - **Walk**: the propel drives work against the crawlers' rolling
//!   resistance, E = c_rr · m · g · distance; turning losses are left out.

use serde::Serialize;

use autoshovel_core::G;

/// The swing drive: rest-to-rest moves at a top speed and a fixed acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SwingDrive {
    /// Top speed ω (rad/s).
    pub speed_rad_s: f64,
    /// Acceleration and braking α (rad/s²).
    pub accel_rad_s2: f64,
    /// Inertia of the upper works and boom, empty dipper (kg·m²).
    pub inertia_kg_m2: f64,
    /// Radius at which the load swings (m).
    pub radius_m: f64,
}

impl SwingDrive {
    /// Time to swing through `angle` (rad), rest to rest (s).
    pub fn time_s(&self, angle: f64) -> f64 {
        let (w, a, th) = (self.speed_rad_s, self.accel_rad_s2, angle.abs());
        if th >= w * w / a {
            th / w + w / a
        } else {
            2.0 * (th / a).sqrt()
        }
    }

    /// The top speed reached on a swing of `angle` (rad/s).
    pub fn peak_speed(&self, angle: f64) -> f64 {
        let (w, a, th) = (self.speed_rad_s, self.accel_rad_s2, angle.abs());
        w.min((th * a).sqrt())
    }

    /// Motoring energy of a swing through `angle` carrying `load_kg` (J)
    /// (module docs).
    pub fn energy_j(&self, angle: f64, load_kg: f64) -> f64 {
        let j = self.inertia_kg_m2 + load_kg * self.radius_m * self.radius_m;
        0.5 * j * self.peak_speed(angle).powi(2)
    }
}

/// Energy the propel drives spend to walk `distance_m` (J) (module docs).
pub fn propel_energy_j(mass_kg: f64, rolling_resistance: f64, distance_m: f64) -> f64 {
    rolling_resistance * mass_kg * G * distance_m
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn drive() -> SwingDrive {
        SwingDrive {
            speed_rad_s: 20f64.to_radians(),
            accel_rad_s2: 12f64.to_radians(),
            inertia_kg_m2: 3e7,
            radius_m: 14.0,
        }
    }

    /// Integrates the bang–coast–bang profile in small steps.
    fn simulate(d: &SwingDrive, angle: f64) -> (f64, f64) {
        let dt = 1e-5;
        let (mut th, mut w, mut t) = (0.0f64, 0.0f64, 0.0);
        loop {
            // Brake when the distance to stop reaches what is left.
            let stop = w * w / (2.0 * d.accel_rad_s2);
            let acc = if stop >= angle - th {
                -d.accel_rad_s2
            } else if w < d.speed_rad_s {
                d.accel_rad_s2
            } else {
                0.0
            };
            let w_next = (w + acc * dt).min(d.speed_rad_s);
            th += 0.5 * (w + w_next) * dt;
            w = w_next;
            t += dt;
            if w <= 0.0 && t > dt {
                return (t, th);
            }
        }
    }

    #[test]
    fn swing_times_match_an_integrated_profile() {
        let d = drive();
        for deg in [10.0f64, 30.0, 90.0, 120.0] {
            let angle = deg.to_radians();
            let (t, th) = simulate(&d, angle);
            assert_relative_eq!(th, angle, max_relative = 2e-3);
            assert_relative_eq!(d.time_s(angle), t, max_relative = 2e-3);
        }
        // 90° at 20°/s and 12°/s²: 4.5 s + 1.67 s.
        assert_relative_eq!(
            d.time_s(90f64.to_radians()),
            90.0 / 20.0 + 20.0 / 12.0,
            max_relative = 1e-12
        );
    }

    #[test]
    fn swing_energy_is_the_kinetic_energy_at_the_top_speed() {
        let d = drive();
        let w = 20f64.to_radians();
        assert_relative_eq!(
            d.energy_j(1.5, 0.0),
            0.5 * 3e7 * w * w,
            max_relative = 1e-12
        );
        let load = 50_000.0;
        assert_relative_eq!(
            d.energy_j(1.5, load),
            0.5 * (3e7 + load * 196.0) * w * w,
            max_relative = 1e-12
        );
        assert_relative_eq!(
            propel_energy_j(1.4e6, 0.08, 10.0),
            0.08 * 1.4e6 * 9.81 * 10.0
        );
    }
}
