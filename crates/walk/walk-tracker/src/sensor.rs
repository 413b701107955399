//! RTK sensing (electric-shovel paper §5, Table 2; SPEC §3): fixes at a set
//! rate with seeded centimetre position noise, sub-degree heading noise, a
//! constant heading offset between the upper works (where the antenna is) and
//! the crawler, and dropouts. The receiver reports a north-referenced,
//! clockwise heading ϕ; [`RtkFix::to_pose`] converts it once, here at the
//! sensor boundary (θ = π/2 − ϕ, SPEC §1).

use autoshovel_core::{wrap_angle, Pose2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

/// RTK receiver model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RtkParams {
    /// Fix rate (Hz).
    pub rate_hz: f64,
    /// Position noise, standard deviation per axis (m).
    pub position_sigma_m: f64,
    /// Heading noise, standard deviation (deg); draws are truncated at 3σ.
    pub heading_sigma_deg: f64,
    /// Constant offset of the reported heading from the crawler's (deg)
    /// (upper works not square to the crawler, §5.3).
    pub heading_offset_deg: f64,
    /// Mean number of dropouts per minute (0 = none).
    pub dropouts_per_min: f64,
    /// Length of each dropout (s).
    pub dropout_s: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for RtkParams {
    fn default() -> Self {
        Self::ideal()
    }
}

impl RtkParams {
    /// Noise off: exact fixes at 10 Hz.
    pub fn ideal() -> Self {
        Self {
            rate_hz: 10.0,
            position_sigma_m: 0.0,
            heading_sigma_deg: 0.0,
            heading_offset_deg: 0.0,
            dropouts_per_min: 0.0,
            dropout_s: 0.0,
            seed: 1,
        }
    }

    /// Table 2-like RTK: 10 Hz, 1 cm position noise, heading noise within
    /// 0.2° (σ = 0.067°, truncated at 3σ), a 0.3° mounting offset, no dropouts.
    pub fn rtk(seed: u64) -> Self {
        Self {
            rate_hz: 10.0,
            position_sigma_m: 0.01,
            heading_sigma_deg: 0.2 / 3.0,
            heading_offset_deg: 0.3,
            dropouts_per_min: 0.0,
            dropout_s: 0.0,
            seed,
        }
    }
}

/// One RTK fix, in the receiver's own terms.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RtkFix {
    /// Time of the fix (s).
    pub time_s: f64,
    /// East (m).
    pub east_m: f64,
    /// North (m).
    pub north_m: f64,
    /// Heading from north, clockwise (rad).
    pub heading_north_cw_rad: f64,
}

impl RtkFix {
    /// The pose in the library's frame (θ from +x, counter-clockwise).
    pub fn to_pose(&self) -> Pose2 {
        Pose2::new(
            self.east_m,
            self.north_m,
            wrap_angle(std::f64::consts::FRAC_PI_2 - self.heading_north_cw_rad),
        )
    }
}

/// A simulated RTK receiver.
#[derive(Debug, Clone)]
pub struct Rtk {
    /// Parameters.
    pub params: RtkParams,
    rng: ChaCha8Rng,
    dropout_until_s: f64,
    next_fix_s: f64,
}

impl Rtk {
    /// A receiver with its own seeded noise.
    pub fn new(params: RtkParams) -> Self {
        Self {
            params,
            rng: ChaCha8Rng::seed_from_u64(params.seed),
            dropout_until_s: f64::NEG_INFINITY,
            next_fix_s: 0.0,
        }
    }

    /// Period between fixes (s).
    pub fn period_s(&self) -> f64 {
        1.0 / self.params.rate_hz
    }

    fn gauss(&mut self, sigma: f64) -> f64 {
        if sigma <= 0.0 {
            return 0.0;
        }
        let n = Normal::new(0.0, sigma).expect("sigma is positive and finite");
        let v: f64 = n.sample(&mut self.rng);
        v.clamp(-3.0 * sigma, 3.0 * sigma)
    }

    /// Called by a control loop at any rate: a fix when one is due at
    /// `time_s` (every 1/rate seconds) and not in a dropout, else `None`.
    pub fn poll(&mut self, truth: Pose2, time_s: f64) -> Option<RtkFix> {
        if time_s + 1e-9 < self.next_fix_s {
            return None;
        }
        let period = self.period_s();
        while self.next_fix_s <= time_s + 1e-9 {
            self.next_fix_s += period;
        }
        self.measure(truth, time_s)
    }

    /// Measures the true crawler pose at `time_s`; `None` during a dropout.
    pub fn measure(&mut self, truth: Pose2, time_s: f64) -> Option<RtkFix> {
        let p = self.params;
        if p.dropouts_per_min > 0.0 && time_s >= self.dropout_until_s {
            // Poisson arrivals: chance of a dropout starting in this period.
            let chance = p.dropouts_per_min / 60.0 / p.rate_hz;
            if self.rng.gen_bool(chance.clamp(0.0, 1.0)) {
                self.dropout_until_s = time_s + p.dropout_s;
            }
        }
        if time_s < self.dropout_until_s {
            return None;
        }
        let theta = truth.theta
            + p.heading_offset_deg.to_radians()
            + self.gauss(p.heading_sigma_deg.to_radians());
        Some(RtkFix {
            time_s,
            east_m: truth.x + self.gauss(p.position_sigma_m),
            north_m: truth.y + self.gauss(p.position_sigma_m),
            heading_north_cw_rad: wrap_angle(std::f64::consts::FRAC_PI_2 - theta),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn north_clockwise_heading_converts_once() {
        // Facing north: ϕ = 0 → θ = π/2; facing east: ϕ = π/2 → θ = 0.
        let f = RtkFix {
            time_s: 0.0,
            east_m: 1.0,
            north_m: 2.0,
            heading_north_cw_rad: 0.0,
        };
        assert_relative_eq!(f.to_pose().theta, std::f64::consts::FRAC_PI_2);
        let f = RtkFix {
            heading_north_cw_rad: std::f64::consts::FRAC_PI_2,
            ..f
        };
        assert_relative_eq!(f.to_pose().theta, 0.0, epsilon = 1e-15);
        // Round trip through the receiver with noise off.
        let mut r = Rtk::new(RtkParams::ideal());
        let truth = Pose2::new(3.0, -4.0, 2.5);
        let p = r.measure(truth, 0.0).unwrap().to_pose();
        assert_relative_eq!(p.theta, 2.5, epsilon = 1e-12);
    }

    #[test]
    fn noise_has_the_set_spread_bound_and_seed() {
        let mut r = Rtk::new(RtkParams {
            heading_offset_deg: 0.0,
            ..RtkParams::rtk(7)
        });
        let truth = Pose2::new(0.0, 0.0, 0.0);
        let fixes: Vec<Pose2> = (0..20_000)
            .map(|i| r.measure(truth, i as f64 * 0.1).unwrap().to_pose())
            .collect();
        let n = fixes.len() as f64;
        let sx = (fixes.iter().map(|p| p.x * p.x).sum::<f64>() / n).sqrt();
        assert!((sx - 0.01).abs() < 0.0005, "sigma x {sx}");
        let max_h = fixes
            .iter()
            .map(|p| p.theta.abs().to_degrees())
            .fold(0.0, f64::max);
        assert!(max_h <= 0.2 + 1e-9, "heading noise {max_h}");
        let mut again = Rtk::new(RtkParams {
            heading_offset_deg: 0.0,
            ..RtkParams::rtk(7)
        });
        assert_eq!(again.measure(truth, 0.0).unwrap().to_pose(), fixes[0]);
    }

    #[test]
    fn dropouts_withhold_fixes_for_their_length() {
        let mut r = Rtk::new(RtkParams {
            dropouts_per_min: 6.0,
            dropout_s: 1.0,
            ..RtkParams::ideal()
        });
        let got: Vec<bool> = (0..6000)
            .map(|i| {
                r.measure(Pose2::new(0.0, 0.0, 0.0), i as f64 * 0.1)
                    .is_some()
            })
            .collect();
        let missing = got.iter().filter(|g| !**g).count();
        // About 6 per minute over 10 minutes, 10 fixes each: tens to a few hundred missing.
        assert!(missing > 100 && missing < 1200, "{missing}");
    }
}
