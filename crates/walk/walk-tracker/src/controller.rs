//! The tracker seam: a controller turns the deviations of [W eq. 21]–[W eq. 22]
//! into the speed difference between the right and left track motors; the
//! gains of every controller ([`ControllerParams`], the `[controller.*]`
//! tables of a tracking scenario), the PID, pure pursuit and Stanley. The
//! fuzzy tracker is in `fuzzy_tracker.rs`, the choice among them in
//! `choice.rs`.
//!
//! Sign convention (SPEC §3): deviations are positive left of the path, and
//! every controller returns `steer_rpm` = n_right − n_left, positive turning
//! the machine left (counter-clockwise). Turning the body turns the direction
//! of motion the same way whether the machine goes forward or in reverse, so
//! no controller needs a special case for reverse legs: the geometry already
//! measures "left" and "ahead" in the direction of motion.

use autoshovel_core::Pose2;

use serde::{Deserialize, Serialize};

use crate::geometry::{Deviations, RefLeg};
use crate::plant::CrawlerParams;

/// What a controller sees at one control tick.
#[derive(Debug, Clone, Copy)]
pub struct ControlInput<'a> {
    /// The leg being tracked.
    pub leg: &'a RefLeg,
    /// Measured pose (RTK, converted to the library's frame).
    pub pose: Pose2,
    /// Deviations at this pose.
    pub dev: &'a Deviations,
    /// Reference centroid speed, signed (negative in reverse) (m/s).
    pub speed_mps: f64,
    /// Time since the previous tick (s).
    pub dt_s: f64,
    /// The machine.
    pub crawler: &'a CrawlerParams,
}

/// A trajectory-tracking controller.
pub trait Controller {
    /// Short name (`fuzzy`, `pid`, `pure-pursuit`).
    fn name(&self) -> &'static str;
    /// Forgets internal state (between legs, after a stop).
    fn reset(&mut self);
    /// Speed difference n_right − n_left (rpm); positive turns left.
    fn step(&mut self, input: &ControlInput) -> f64;
    /// The gains this controller runs with.
    fn gains(&self) -> Gains;
}

/// The gains of one controller, as it reports them (serialised as the
/// parameter struct itself).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Gains {
    /// The fuzzy tracker's.
    Fuzzy(FuzzyParams),
    /// The PID's.
    Pid(PidParams),
    /// Pure pursuit's.
    PurePursuit(PurePursuitParams),
    /// Stanley's.
    Stanley(StanleyParams),
}

/// The gains of every controller: the `[controller.fuzzy]`,
/// `[controller.pid]` and `[controller.pure_pursuit]` tables of a tracking
/// scenario; each field defaults to today's value.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ControllerParams {
    /// The fuzzy tracker (§4.3).
    pub fuzzy: FuzzyParams,
    /// The PID baseline (§5.4).
    pub pid: PidParams,
    /// Pure pursuit.
    pub pure_pursuit: PurePursuitParams,
    /// Stanley.
    pub stanley: StanleyParams,
}

/// Parameters of the fuzzy tracker.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FuzzyParams {
    /// Weight α of the centroid deviation in e [W eq. 23].
    pub alpha: f64,
    /// Scaling factor k1 of e [W eq. 24] (1/m): e_f = k1·e.
    pub k1: f64,
    /// Scaling factor k2 of ec [W eq. 24] (s/m): ec_f = k2·ec.
    pub k2: f64,
    /// Scaling factor k3 of u [W eq. 24]: u = k3·u_f.
    pub k3: f64,
    /// Time constant of the first-order low-pass on ec (s) (0 = none): the
    /// rate of a centimetre-noisy RTK error at 10 Hz is mostly noise.
    pub ec_filter_s: f64,
    /// Growth of α with the path's curvature (m): α(κ) = alpha +
    /// alpha_curvature_m·|κ| [W eq. 23] ("its value is related to the
    /// curvature of the trajectory"). 0 keeps α constant.
    pub alpha_curvature_m: f64,
    /// Fixed scaling factors, or contraction–expansion factors that vary
    /// with the inputs ([`Universe`], [W eq. 24]).
    pub universe: Universe,
    /// τ of the variable universe's factor α(x) = (|x|/E)^τ + ε, in (0, 1].
    pub vu_tau: f64,
    /// ε of the variable universe's factor, in (0, 1]: the narrowest a
    /// universe contracts to, as a share of its full width.
    pub vu_epsilon: f64,
}

/// How the fuzzy tracker's universes scale [W eq. 24].
///
/// `Fixed` is eq. 24 as printed: σ_i = n_i·k_i with constant k_i.
/// `Variable` is the variable-universe method of Li Hongxing ("Adaptive
/// fuzzy controllers based on variable universe", Science in China E 42(1),
/// 1999, 10–20): each input's universe [−E, E] contracts and expands with the
/// input itself by the factor α(x) = (|x|/E)^τ + ε (capped at 1), so the rule
/// base sees x/α(x) — fine resolution near zero error, the whole table far
/// from it — and the output universe scales with the error's factor, β =
/// α(e) (Li's simplest output factor).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Universe {
    /// Constant k1, k2, k3 (the default).
    #[default]
    Fixed,
    /// Input-dependent contraction–expansion factors.
    Variable,
}

impl Default for FuzzyParams {
    fn default() -> Self {
        // Tuned by a seeded random search on fig9a/b (noise off) and the
        // straight / curve / V-shape runs with RTK noise (seeds 11–13; the tests
        // check seeds 1–6); see docs/walk-tracker.md.
        Self {
            alpha: 0.30,
            k1: 2.42,
            k2: 32.1,
            k3: 1.11,
            ec_filter_s: 0.34,
            alpha_curvature_m: 0.0,
            universe: Universe::Fixed,
            vu_tau: 0.5,
            vu_epsilon: 0.1,
        }
    }
}

/// PID on the lateral error e = d + α·d0 [W eq. 23], the paper's baseline of
/// §5.4 (kp 800, ki 100, kd 300) in the parallel form of [W eq. 25]
/// (kp = K_P, ki = K_P/T_i, kd = K_P·T_d), with anti-windup by clamping the integral
/// term and not integrating while the output saturates.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PidParams {
    /// Proportional gain (rpm/m).
    pub kp: f64,
    /// Integral gain (rpm/(m·s)).
    pub ki: f64,
    /// Derivative gain (rpm·s/m).
    pub kd: f64,
    /// Weight α of the centroid deviation in e [W eq. 23].
    pub alpha: f64,
    /// Output limit (rpm).
    pub max_steer_rpm: f64,
    /// The error it acts on ([`PidError`]).
    pub error: PidError,
}

/// The error a PID acts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PidError {
    /// e = d + α·d0, the fuzzy tracker's input [W eq. 23] (the default).
    #[default]
    Preview,
    /// The centroid's position error d0 alone, as a PID on the position
    /// error (§5.4's baseline) acts.
    Position,
}

impl Default for PidParams {
    fn default() -> Self {
        Self {
            kp: 800.0,
            ki: 100.0,
            kd: 300.0,
            alpha: 0.5,
            max_steer_rpm: 2700.0,
            error: PidError::Preview,
        }
    }
}

impl PidParams {
    /// The paper's §5.4 baseline: kp 800, ki 100, kd 300 on the position error.
    pub fn paper() -> Self {
        Self {
            error: PidError::Position,
            ..Self::default()
        }
    }
}

/// The PID tracker.
#[derive(Debug, Clone)]
pub struct Pid {
    /// Parameters.
    pub params: PidParams,
    integral: f64,
    prev_e: Option<f64>,
}

impl Pid {
    /// A PID tracker at rest.
    pub fn new(params: PidParams) -> Self {
        Self {
            params,
            integral: 0.0,
            prev_e: None,
        }
    }
}

impl Controller for Pid {
    fn name(&self) -> &'static str {
        "pid"
    }

    fn reset(&mut self) {
        self.integral = 0.0;
        self.prev_e = None;
    }

    fn gains(&self) -> Gains {
        Gains::Pid(self.params)
    }

    fn step(&mut self, input: &ControlInput) -> f64 {
        let p = self.params;
        let e = match p.error {
            // e = d + α·d0 [W eq. 23]
            PidError::Preview => input.dev.d_m + p.alpha * input.dev.d0_m,
            PidError::Position => input.dev.d0_m,
        };
        let de = match self.prev_e {
            Some(prev) if input.dt_s > 0.0 => (e - prev) / input.dt_s,
            _ => 0.0,
        };
        self.prev_e = Some(e);
        let unsat = p.kp * e + p.ki * (self.integral + e * input.dt_s) + p.kd * de;
        if unsat.abs() < p.max_steer_rpm && p.ki > 0.0 {
            self.integral += e * input.dt_s;
            let cap = 0.5 * p.max_steer_rpm / p.ki;
            self.integral = self.integral.clamp(-cap, cap);
        }
        // u = kp·e + ki·∫e dt + kd·de/dt [W eq. 25]
        let u =
            (p.kp * e + p.ki * self.integral + p.kd * de).clamp(-p.max_steer_rpm, p.max_steer_rpm);
        // e > 0: left of the path → turn right → n_r < n_l.
        -u
    }
}

/// Pure pursuit (Coulter 1992): steer onto the circle through the machine
/// and the path point a look-ahead distance on; in reverse, the circle is
/// taken in the direction of motion.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PurePursuitParams {
    /// Look-ahead at standstill (m).
    pub lookahead_m: f64,
    /// Look-ahead growth with speed (s).
    pub lookahead_gain_s: f64,
    /// Output limit (rpm).
    pub max_steer_rpm: f64,
}

impl Default for PurePursuitParams {
    fn default() -> Self {
        Self {
            lookahead_m: 1.5,
            lookahead_gain_s: 1.0,
            max_steer_rpm: 2700.0,
        }
    }
}

/// The pure-pursuit tracker.
#[derive(Debug, Clone)]
pub struct PurePursuit {
    /// Parameters.
    pub params: PurePursuitParams,
}

impl Controller for PurePursuit {
    fn name(&self) -> &'static str {
        "pure-pursuit"
    }

    fn reset(&mut self) {}

    fn gains(&self) -> Gains {
        Gains::PurePursuit(self.params)
    }

    fn step(&mut self, input: &ControlInput) -> f64 {
        let p = self.params;
        let ld = p.lookahead_m + p.lookahead_gain_s * input.speed_mps.abs();
        // Past the end the look-ahead point runs on along the last tangent, so
        // the machine is not pulled round onto the end point as it arrives.
        let s_target = input.dev.s_a_m + ld;
        let (end_point, end_tangent) = input.leg.point_at(input.leg.length_m());
        let target = if s_target > input.leg.length_m() {
            end_point + end_tangent * (s_target - input.leg.length_m())
        } else {
            input.leg.point_at(s_target).0
        };
        let motion = input.leg.direction.motion_heading(input.pose.theta);
        let rel = target - input.pose.position();
        let (c, s) = (motion.cos(), motion.sin());
        let y_left = -s * rel.x + c * rel.y;
        let dist2 = rel.norm_squared().max(1e-6);
        let curvature = 2.0 * y_left / dist2;
        let omega = curvature * input.speed_mps.abs();
        let dv = omega * input.crawler.gauge_m;
        (dv / input.crawler.mps_per_rpm()).clamp(-p.max_steer_rpm, p.max_steer_rpm)
    }
}

/// Stanley's steering law (Hoffmann, Tomlin, Montemerlo & Thrun, "Autonomous
/// automobile trajectory tracking for off-road driving", ACC 2007), for a
/// skid-steered crawler: the heading correction
/// δ = θ_e + atan(k·e / (v_s + |v|)), with θ_e the path's heading minus the
/// heading of motion and e the centroid's cross-track error (right of the
/// path positive, so −d0), becomes a yaw rate ω = |v|·κ + δ/τ (the path's
/// curvature as feed-forward, δ closed in τ), and the speed difference
/// n_r − n_l = ω·B / (m/s per rpm).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StanleyParams {
    /// k, the cross-track gain (1/s).
    pub k_per_s: f64,
    /// v_s, the softening speed that keeps the law finite at rest (m/s).
    pub softening_mps: f64,
    /// τ, the time in which the heading correction is closed (s).
    pub heading_time_s: f64,
    /// Output limit (rpm).
    pub max_steer_rpm: f64,
}

impl Default for StanleyParams {
    fn default() -> Self {
        Self {
            k_per_s: 1.0,
            softening_mps: 0.3,
            heading_time_s: 0.8,
            max_steer_rpm: 2700.0,
        }
    }
}

/// The Stanley tracker.
#[derive(Debug, Clone)]
pub struct Stanley {
    /// Parameters.
    pub params: StanleyParams,
}

impl Controller for Stanley {
    fn name(&self) -> &'static str {
        "stanley"
    }

    fn reset(&mut self) {}

    fn gains(&self) -> Gains {
        Gains::Stanley(self.params)
    }

    fn step(&mut self, input: &ControlInput) -> f64 {
        let p = self.params;
        let v = input.speed_mps.abs();
        let theta_e = -input.dev.heading_error_rad;
        let delta = theta_e + (-p.k_per_s * input.dev.d0_m).atan2(p.softening_mps + v);
        let kappa = input.leg.curvature_at(input.dev.s_a_m, CURVATURE_WINDOW_M);
        let omega = v * kappa + delta / p.heading_time_s;
        (omega * input.crawler.gauge_m / input.crawler.mps_per_rpm())
            .clamp(-p.max_steer_rpm, p.max_steer_rpm)
    }
}

/// Half the arc over which a controller measures the path's curvature (m):
/// wider than the planner's point spacing, narrower than the tightest turn.
pub const CURVATURE_WINDOW_M: f64 = 0.5;
