//! The crawler plant: differential-drive kinematics of the electric-shovel
//! paper ([W eq. 16]–[W eq. 20]: v_c = (v_r + v_l)/2 [W eq. 17],
//! θ̇ = (v_r − v_l)/B, which [W eq. 18] prints as (v_r + v_l)/2R) driven by two track motors, with the realism the
//! paper's experiment had and a simulation must offer (SPEC §3), each
//! switchable: motor speed and acceleration limits, per-track longitudinal
//! slip, lateral (skid) slip in turns.
//!
//! Motor speed n (rpm) → track speed v = n·2π·r_s/(60·i) (SPEC §3). Each step
//! integrates the exact circular arc of constant v_c and θ̇ over `dt`
//! ([W eq. 19], the integral of [W eq. 18] / [W eq. 20], in closed form).

use autoshovel_core::{wrap_angle, Pose2};
use serde::{Deserialize, Serialize};

/// Below this motor speed (rpm) the machine counts as at rest.
pub const AT_REST_RPM: f64 = 1.0;

/// Machine parameters of the crawler (defaults: SPEC §3, 1:7 prototype).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CrawlerParams {
    /// Track gauge B: distance between the track centre lines (m).
    pub gauge_m: f64,
    /// Drive sprocket radius r_s (m).
    pub sprocket_radius_m: f64,
    /// Gear ratio i between motor and sprocket.
    pub gear_ratio: f64,
    /// Motor speed limit (rpm).
    pub motor_max_rpm: f64,
    /// Motor acceleration limit (rpm/s) (0 = unlimited).
    pub motor_max_accel_rpm_per_s: f64,
}

impl Default for CrawlerParams {
    fn default() -> Self {
        Self {
            gauge_m: 1.5,
            sprocket_radius_m: 0.3,
            gear_ratio: 38.0,
            motor_max_rpm: 3000.0,
            motor_max_accel_rpm_per_s: 6000.0,
        }
    }
}

impl CrawlerParams {
    /// Track speed per motor rpm (m/s per rpm).
    pub fn mps_per_rpm(&self) -> f64 {
        2.0 * std::f64::consts::PI * self.sprocket_radius_m / (60.0 * self.gear_ratio)
    }

    /// Fastest track speed (m/s).
    pub fn max_track_speed_mps(&self) -> f64 {
        self.motor_max_rpm * self.mps_per_rpm()
    }
}

/// Ground interaction (all zero = ideal tracks).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SlipParams {
    /// Longitudinal slip ratio of the left track: ground speed = (1 − s)·track speed.
    pub left: f64,
    /// Longitudinal slip ratio of the right track.
    pub right: f64,
    /// Lateral skid in turns: sideways speed = −gain·v_c·θ̇ (outwards of the turn) (s).
    pub lateral_gain_s: f64,
}

impl Default for SlipParams {
    fn default() -> Self {
        Self::none()
    }
}

impl SlipParams {
    /// Ideal tracks.
    pub fn none() -> Self {
        Self {
            left: 0.0,
            right: 0.0,
            lateral_gain_s: 0.0,
        }
    }

    /// A loose bench: 4 % and 7 % slip (unequal, so the machine drifts) and
    /// some skid in turns; the documented default of `--noise rtk` runs.
    pub fn loose_bench() -> Self {
        Self {
            left: 0.04,
            right: 0.07,
            lateral_gain_s: 0.05,
        }
    }
}

/// Motor speed commands (rpm) (positive drives the machine forward).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TrackCommand {
    /// Left motor (rpm).
    pub left_rpm: f64,
    /// Right motor (rpm).
    pub right_rpm: f64,
}

impl TrackCommand {
    /// Both motors stopped.
    pub const STOP: TrackCommand = TrackCommand {
        left_rpm: 0.0,
        right_rpm: 0.0,
    };

    /// The command with both motors clamped to ±`max_rpm`, keeping the
    /// speed difference (the steering) where possible by lowering the common part.
    pub fn saturate(self, max_rpm: f64) -> TrackCommand {
        let (l, r) = (self.left_rpm, self.right_rpm);
        if !(l.is_finite() && r.is_finite()) {
            return TrackCommand::STOP;
        }
        let over = l.abs().max(r.abs()) - max_rpm;
        if over <= 0.0 {
            return self;
        }
        let diff = (r - l).clamp(-2.0 * max_rpm, 2.0 * max_rpm);
        let mean = 0.5 * (l + r);
        // Shrink the common part first.
        let room = max_rpm - 0.5 * diff.abs();
        let mean = mean.clamp(-room, room);
        TrackCommand {
            left_rpm: (mean - 0.5 * diff).clamp(-max_rpm, max_rpm),
            right_rpm: (mean + 0.5 * diff).clamp(-max_rpm, max_rpm),
        }
    }
}

/// The crawler's true state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CrawlerState {
    /// Pose of the centroid; θ is the crawler's heading.
    pub pose: Pose2,
    /// Left motor speed (rpm).
    pub left_rpm: f64,
    /// Right motor speed (rpm).
    pub right_rpm: f64,
}

/// The simulated crawler.
#[derive(Debug, Clone)]
pub struct Crawler {
    /// Machine parameters.
    pub params: CrawlerParams,
    /// Ground interaction.
    pub slip: SlipParams,
    /// The state.
    pub state: CrawlerState,
}

impl Crawler {
    /// A crawler at rest at `pose`.
    pub fn new(params: CrawlerParams, slip: SlipParams, pose: Pose2) -> Self {
        Self {
            params,
            slip,
            state: CrawlerState {
                pose,
                left_rpm: 0.0,
                right_rpm: 0.0,
            },
        }
    }

    /// Centroid speed over ground along the heading (m/s).
    pub fn speed_mps(&self) -> f64 {
        let k = self.params.mps_per_rpm();
        0.5 * (self.state.left_rpm * k * (1.0 - self.slip.left)
            + self.state.right_rpm * k * (1.0 - self.slip.right))
    }

    /// Advances by `dt_s`: motors move towards the (saturated) command within
    /// their acceleration limit, then the pose follows the exact arc of
    /// v_c = (v_r + v_l)/2 [W eq. 17] and θ̇ = (v_r − v_l)/B [W eq. 18],
    /// integrated in closed form [W eq. 19].
    pub fn step(&mut self, cmd: TrackCommand, dt_s: f64) {
        let p = &self.params;
        let cmd = cmd.saturate(p.motor_max_rpm);
        let ramp = |now: f64, want: f64| {
            if p.motor_max_accel_rpm_per_s > 0.0 {
                let dn = p.motor_max_accel_rpm_per_s * dt_s;
                now + (want - now).clamp(-dn, dn)
            } else {
                want
            }
        };
        let s = &mut self.state;
        s.left_rpm = ramp(s.left_rpm, cmd.left_rpm);
        s.right_rpm = ramp(s.right_rpm, cmd.right_rpm);
        let k = p.mps_per_rpm();
        let vl = s.left_rpm * k * (1.0 - self.slip.left);
        let vr = s.right_rpm * k * (1.0 - self.slip.right);
        // v_c = (v_r + v_l)/2 [W eq. 17]
        let v = 0.5 * (vr + vl);
        // θ̇ = (v_r − v_l)/B [W eq. 18] (printed there as (v_r + v_l)/2R)
        let w = (vr - vl) / p.gauge_m;
        let th = s.pose.theta;
        // x = ∫ v_c cos θ dt, y = ∫ v_c sin θ dt over the arc [W eq. 19]
        let (dx, dy) = if (w * dt_s).abs() < 1e-9 {
            (v * dt_s * th.cos(), v * dt_s * th.sin())
        } else {
            let r = v / w;
            (
                r * ((th + w * dt_s).sin() - th.sin()),
                -r * ((th + w * dt_s).cos() - th.cos()),
            )
        };
        // Skid: sideways, outwards of the turn.
        let lat = -self.slip.lateral_gain_s * v * w * dt_s;
        let mid = th + 0.5 * w * dt_s;
        s.pose.x += dx - lat * mid.sin();
        s.pose.y += dy + lat * mid.cos();
        s.pose.theta = wrap_angle(th + w * dt_s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn equal_tracks_drive_straight_at_the_rpm_speed() {
        let mut c = Crawler::new(
            CrawlerParams {
                motor_max_accel_rpm_per_s: 0.0,
                ..Default::default()
            },
            SlipParams::none(),
            Pose2::new(0.0, 0.0, 0.3),
        );
        let cmd = TrackCommand {
            left_rpm: 1000.0,
            right_rpm: 1000.0,
        };
        for _ in 0..1000 {
            c.step(cmd, 0.001);
        }
        let v = 1000.0 * c.params.mps_per_rpm();
        assert_relative_eq!(c.state.pose.x, v * 0.3f64.cos(), epsilon = 1e-9);
        assert_relative_eq!(c.state.pose.y, v * 0.3f64.sin(), epsilon = 1e-9);
        assert_relative_eq!(c.state.pose.theta, 0.3, epsilon = 1e-12);
    }

    #[test]
    fn unequal_tracks_drive_a_circle_of_the_closed_form_radius() {
        // R = B(v_r + v_l) / (2(v_r − v_l)) [W eq. 17]; a full turn returns to the start.
        let p = CrawlerParams {
            motor_max_accel_rpm_per_s: 0.0,
            ..Default::default()
        };
        let mut c = Crawler::new(p, SlipParams::none(), Pose2::new(0.0, 0.0, 0.0));
        let (nl, nr) = (800.0, 1200.0);
        let k = p.mps_per_rpm();
        let (vl, vr) = (nl * k, nr * k);
        let r = p.gauge_m * (vr + vl) / (2.0 * (vr - vl));
        let w = (vr - vl) / p.gauge_m;
        let period = 2.0 * std::f64::consts::PI / w;
        let dt = period / 10_000.0;
        let mut max_dist_from_centre: f64 = 0.0;
        for _ in 0..10_000 {
            c.step(
                TrackCommand {
                    left_rpm: nl,
                    right_rpm: nr,
                },
                dt,
            );
            let d = (c.state.pose.x.powi(2) + (c.state.pose.y - r).powi(2)).sqrt();
            max_dist_from_centre = max_dist_from_centre.max((d - r).abs());
        }
        assert!(max_dist_from_centre < 1e-9, "{max_dist_from_centre}");
        assert_relative_eq!(c.state.pose.x, 0.0, epsilon = 1e-8);
        assert_relative_eq!(c.state.pose.y, 0.0, epsilon = 1e-8);
    }

    #[test]
    fn motors_obey_speed_and_acceleration_limits() {
        let p = CrawlerParams::default();
        let mut c = Crawler::new(p, SlipParams::none(), Pose2::new(0.0, 0.0, 0.0));
        c.step(
            TrackCommand {
                left_rpm: 1e9,
                right_rpm: -1e9,
            },
            0.01,
        );
        assert_relative_eq!(c.state.left_rpm, p.motor_max_accel_rpm_per_s * 0.01);
        for _ in 0..1000 {
            c.step(
                TrackCommand {
                    left_rpm: 1e9,
                    right_rpm: -1e9,
                },
                0.01,
            );
        }
        assert!(c.state.left_rpm <= p.motor_max_rpm && c.state.right_rpm >= -p.motor_max_rpm);
        assert_eq!(
            TrackCommand {
                left_rpm: f64::NAN,
                right_rpm: 1.0
            }
            .saturate(3000.0),
            TrackCommand::STOP
        );
    }

    #[test]
    fn saturation_keeps_the_steering_difference() {
        let c = TrackCommand {
            left_rpm: 2500.0,
            right_rpm: 3500.0,
        }
        .saturate(3000.0);
        assert_relative_eq!(c.right_rpm - c.left_rpm, 1000.0);
        assert!(c.right_rpm <= 3000.0);
    }

    #[test]
    fn unequal_slip_makes_a_straight_command_curve_towards_the_slipping_side() {
        let mut c = Crawler::new(
            CrawlerParams::default(),
            SlipParams {
                left: 0.0,
                right: 0.1,
                lateral_gain_s: 0.0,
            },
            Pose2::new(0.0, 0.0, 0.0),
        );
        for _ in 0..2000 {
            c.step(
                TrackCommand {
                    left_rpm: 1000.0,
                    right_rpm: 1000.0,
                },
                0.001,
            );
        }
        assert!(
            c.state.pose.theta < 0.0,
            "right track slips more: turns right"
        );
    }
}
