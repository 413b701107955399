//! Tracking scenarios: the paper's Fig. 9 cases, the experiment-like runs on
//! the travel planner's built-in paths (§5.3), and TOML files — either a
//! tracking scenario (legs of points, a start pose, machine, ground, sensor
//! and loop settings) or a travel scenario of `plan-path`, which is planned
//! with the improved field first.
//!
//! Tracking scenario format (lengths in metres, headings in degrees from +x,
//! counter-clockwise; every table but `[start]` and `[[leg]]` optional):
//! ```toml
//! name = "my-run"
//! speed_mps = 0.5
//! noise = "rtk"                 # or "off": RTK noise and loose-bench slip on or off
//! [start]
//! x_m = 0.0
//! y_m = 1.0
//! heading_deg = 0.0
//! [[leg]]
//! direction = "forward"         # or "reverse"
//! points_m = [[0.0, 0.0], [20.0, 0.0], [30.0, 5.0]]
//! end_heading_deg = 26.6        # optional; default: along the last segment
//! [crawler]                     # CrawlerParams fields
//! gauge_m = 1.5
//! [slip]                        # SlipParams fields
//! [rtk]                         # RtkParams fields
//! [sim]                         # SimParams fields
//! [controller.fuzzy]            # FuzzyParams: the fuzzy tracker's gains
//! alpha = 0.30                  # weight of d0 in e = d + α·d0 [W eq. 23], >= 0
//! k1 = 2.42                     # e_f = k1·e [W eq. 24] (1/m), > 0
//! k2 = 32.1                     # ec_f = k2·ec [W eq. 24] (s/m), > 0
//! k3 = 1.11                     # u = k3·u_f [W eq. 24], > 0
//! ec_filter_s = 0.34            # low-pass time constant on ec (s), >= 0 (0 = none)
//! alpha_curvature_m = 0.0       # α(κ) = alpha + alpha_curvature_m·|κ| [W eq. 23] (m), >= 0
//! universe = "fixed"            # or "variable": contraction–expansion factors [W eq. 24]
//! vu_tau = 0.5                  # variable universe: α(x) = (|x|/E)^τ + ε, τ in (0, 1]
//! vu_epsilon = 0.1              # ε in (0, 1]
//! [controller.pid]              # PidParams: the PID baseline (§5.4)
//! kp = 800.0                    # (rpm/m), >= 0
//! ki = 100.0                    # (rpm/(m·s)), >= 0
//! kd = 300.0                    # (rpm·s/m), >= 0
//! alpha = 0.5                   # weight of d0 in e [W eq. 23], >= 0
//! max_steer_rpm = 2700.0        # output limit (rpm), > 0
//! error = "preview"             # e = d + α·d0; "position": the centroid's d0 alone
//! [controller.pure_pursuit]     # PurePursuitParams
//! lookahead_m = 1.5             # look-ahead at standstill (m), > 0
//! lookahead_gain_s = 1.0        # growth of the look-ahead with speed (s), >= 0
//! max_steer_rpm = 2700.0        # output limit (rpm), > 0
//! [controller.stanley]          # StanleyParams
//! k_per_s = 1.0                 # cross-track gain k (1/s), >= 0
//! softening_mps = 0.3           # softening speed (m/s), > 0
//! heading_time_s = 0.8          # time to close the heading correction (s), > 0
//! max_steer_rpm = 2700.0        # output limit (rpm), > 0
//! ```
//!
//! Every field of the `[controller.*]` tables is optional; the values shown
//! are the defaults ([`ControllerParams::default`]). A value out of range is
//! refused with the file, line and key at fault.

use autoshovel_core::config::{self, line_of_key, TomlFile};
use autoshovel_core::{rad, Pose2, Vec2};
use autoshovel_walk_planner::{
    plan_path, Direction, FieldKind, PlanOptions, Scenario as TravelScenario,
};
use serde::{Deserialize, Serialize};

use crate::controller::ControllerParams;
use crate::error::TrackError;
use crate::geometry::RefLeg;
use crate::plant::{CrawlerParams, SlipParams};
use crate::sensor::RtkParams;
use crate::sim::{Setup, SimParams};

/// The built-in tracking scenarios.
pub const BUILTINS: &[&str] = &[
    "fig9a",
    "fig9b",
    "straight",
    "straight-reverse",
    "curve",
    "curve-reverse",
    "v-shape",
    "tight-curve",
    "long-v-slip",
];

/// Whether a run has sensor noise and slip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Noise {
    /// Exact fixes, ideal tracks.
    Off,
    /// RTK noise (Table 2-like) and loose-bench slip.
    Rtk,
}

impl Noise {
    /// The setting's name, as in a scenario file and the summary.
    pub fn name(self) -> &'static str {
        match self {
            Noise::Off => "off",
            Noise::Rtk => "rtk",
        }
    }
}

/// A named tracking setup.
#[derive(Debug, Clone)]
pub struct TrackScenario {
    /// Name.
    pub name: String,
    /// The run.
    pub setup: Setup,
    /// Noise setting it was built with.
    pub noise: Noise,
    /// The site, when the path was planned on one (for plots).
    pub map: Option<autoshovel_walk_planner::Map>,
    /// The gains of every controller.
    pub controllers: ControllerParams,
}

/// Farthest the start may be from the first leg (m).
pub const MAX_START_OFFSET_M: f64 = 20.0;

/// The built-in tracking scenarios written as tracking-scenario TOML (the
/// others are `plan-path`'s travel scenarios, planned first).
pub const BUILTIN_TOML: &[(&str, &str)] = &[
    ("fig9a", include_str!("../scenarios/fig9a.toml")),
    ("fig9b", include_str!("../scenarios/fig9b.toml")),
    ("tight-curve", include_str!("../scenarios/tight-curve.toml")),
    ("long-v-slip", include_str!("../scenarios/long-v-slip.toml")),
];

/// The TOML text of a built-in (with its comments), to print and edit:
/// Fig. 9's own files, or the travel scenario a built-in plans first.
pub fn builtin_text(name: &str) -> Option<&'static str> {
    BUILTIN_TOML
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .or_else(|| {
            BUILTINS
                .contains(&name)
                .then(|| autoshovel_walk_planner::scenario::builtin_text(name).ok())
                .flatten()
        })
}

/// Builds a built-in scenario, or reads a file. `noise` overrides the
/// scenario's default; `seed` seeds the sensor noise.
pub fn resolve(
    name_or_path: &str,
    noise: Option<Noise>,
    seed: u64,
) -> Result<TrackScenario, TrackError> {
    let with = |noise: Noise, mut setup: Setup| {
        apply_noise(&mut setup, noise, seed);
        setup
    };
    match name_or_path {
        name if BUILTIN_TOML.iter().any(|(n, _)| *n == name) => {
            let text = builtin_text(name_or_path).expect("a built-in");
            from_toml(text, &format!("<builtin {name_or_path}>"), noise, seed)
        }
        name if BUILTINS.contains(&name) => {
            let travel = TravelScenario::builtin(name).expect("built-in travel scenario");
            let noise = noise.unwrap_or(Noise::Rtk);
            let setup = from_travel(&travel, &format!("<builtin {name_or_path}>"))?;
            Ok(TrackScenario {
                name: name_or_path.to_string(),
                setup: with(noise, setup),
                noise,
                map: Some(travel.map),
                controllers: ControllerParams::default(),
            })
        }
        path => {
            let p = std::path::Path::new(path);
            if !p.exists() {
                return Err(TrackError::UnknownScenario {
                    name: path.to_string(),
                    known: BUILTINS.join(", "),
                });
            }
            let text = config::read(p)?;
            from_toml(&text, path, noise, seed)
        }
    }
}

/// Plans a travel scenario with the improved field and tracks its legs from its start.
pub fn from_travel(travel: &TravelScenario, file: &str) -> Result<Setup, TrackError> {
    let plan = plan_path(travel, &PlanOptions::new(FieldKind::Improved)).map_err(|source| {
        TrackError::Plan {
            file: file.to_string(),
            source,
        }
    })?;
    let legs = travel.legs();
    let mut out = Vec::new();
    for (i, (leg, (_, to, _))) in plan.path.legs.iter().zip(legs).enumerate() {
        let pts: Vec<Vec2> = leg.points.iter().map(|p| p.pose.position()).collect();
        let leg = RefLeg::new(leg.direction, pts, Some(to.theta)).map_err(|fault| {
            TrackError::PlannedLeg {
                file: file.to_string(),
                leg: i + 1,
                fault,
            }
        })?;
        out.push(leg);
    }
    Ok(Setup {
        legs: out,
        start: travel.start,
        crawler: CrawlerParams::default(),
        slip: SlipParams::none(),
        rtk: RtkParams::ideal(),
        sim: SimParams::default(),
    })
}

/// A tracking scenario file as written (the raw layer of the format in the
/// module docs); [`TomlFile::from_toml`] / [`TomlFile::load`] check every
/// value once, then [`ScenarioFile::into_scenario`] builds the run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// Name (default: the file name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Cruise speed (m/s), overriding `[sim] speed_mps`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_mps: Option<f64>,
    /// RTK noise and loose-bench slip on or off (default off).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<Noise>,
    /// The crawler's true start pose.
    pub start: StartSpec,
    /// The legs, in order (at least one).
    #[serde(default)]
    pub leg: Vec<LegSpec>,
    /// Machine.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crawler: Option<CrawlerParams>,
    /// Ground (overrides the noise setting's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip: Option<SlipParams>,
    /// Sensor (overrides the noise setting's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtk: Option<RtkParams>,
    /// Loop.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sim: Option<SimParams>,
    /// The controllers' gains.
    #[serde(default)]
    pub controller: ControllerParams,
}

/// `[start]` of a tracking scenario.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartSpec {
    /// East (m).
    pub x_m: f64,
    /// North (m).
    pub y_m: f64,
    /// Heading from +x, counter-clockwise (deg).
    pub heading_deg: f64,
}

/// One `[[leg]]` of a tracking scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegSpec {
    /// Forward or reverse.
    pub direction: Direction,
    /// Path points (m).
    #[serde(deserialize_with = "config::xy_list")]
    pub points_m: Vec<[f64; 2]>,
    /// Required heading at the end (deg) (default: along the last segment).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end_heading_deg: Option<f64>,
}

/// Most points a leg of a file may have.
pub const MAX_LEG_POINTS: usize = 1_000_000;

/// A finite value in (0, 1000], for [`config::check_each`].
const RATE: (fn(f64) -> bool, &str) = (
    |v| v.is_finite() && v > 0.0 && v <= 1000.0,
    "a rate in (0, 1000] Hz",
);

/// A slip ratio in [0, 0.9), for [`config::check_each`].
const SLIP: (fn(f64) -> bool, &str) = (
    |v| v.is_finite() && (0.0..0.9).contains(&v),
    "a slip ratio in [0, 0.9)",
);

/// A finite value, for [`config::check_each`].
const FINITE: (fn(f64) -> bool, &str) = (|v| v.is_finite(), "a finite number");

impl ScenarioFile {
    /// The legs, checked; errors name the leg and the line of its points.
    fn legs(&self, text: &str, file: &str) -> Result<Vec<RefLeg>, TrackError> {
        let mut legs = Vec::new();
        for (i, l) in self.leg.iter().enumerate() {
            if l.points_m.len() > MAX_LEG_POINTS {
                return Err(config::invalid(
                    text,
                    file,
                    ("leg", i),
                    "points_m",
                    format!("{} points", l.points_m.len()),
                    format!("at most {MAX_LEG_POINTS} points"),
                )
                .into());
            }
            let end = match l.end_heading_deg {
                Some(h) if !h.is_finite() => {
                    return Err(TrackError::NotFinite {
                        file: file.to_string(),
                        line: line_of_key(text, "leg", i, "end_heading_deg"),
                        key: format!("[[leg]] #{} end_heading_deg", i + 1),
                        value: h,
                    })
                }
                h => h.map(rad),
            };
            let pts: Vec<Vec2> = l.points_m.iter().map(|p| Vec2::new(p[0], p[1])).collect();
            let leg = RefLeg::new(l.direction, pts, end).map_err(|fault| TrackError::Leg {
                file: file.to_string(),
                line: line_of_key(text, "leg", i, "points_m"),
                leg: i + 1,
                fault,
            })?;
            legs.push(leg);
        }
        Ok(legs)
    }

    fn start(&self) -> Pose2 {
        Pose2::new(self.start.x_m, self.start.y_m, rad(self.start.heading_deg))
    }

    fn sim(&self) -> SimParams {
        let mut sim = self.sim.unwrap_or_default();
        if let Some(v) = self.speed_mps {
            sim.speed_mps = v;
        }
        sim
    }

    /// The run this file describes: `noise` overrides the file's noise
    /// setting (default off), `seed` seeds the sensor noise unless the file
    /// gives `[rtk]`; `text` and `file` locate errors.
    pub fn into_scenario(
        self,
        text: &str,
        file: &str,
        noise: Option<Noise>,
        seed: u64,
    ) -> Result<TrackScenario, TrackError> {
        let legs = self.legs(text, file)?;
        let noise = noise.or(self.noise).unwrap_or(Noise::Off);
        let mut setup = Setup {
            legs,
            start: self.start(),
            crawler: self.crawler.unwrap_or_default(),
            slip: SlipParams::none(),
            rtk: RtkParams::ideal(),
            sim: self.sim(),
        };
        check_work(&setup, text, file)?;
        apply_noise(&mut setup, noise, seed);
        if let Some(slip) = self.slip {
            setup.slip = slip;
        }
        if let Some(rtk) = self.rtk {
            setup.rtk = rtk;
        }
        Ok(TrackScenario {
            name: self.name.unwrap_or_else(|| file.to_string()),
            setup,
            noise,
            map: None,
            controllers: self.controller,
        })
    }

    fn check_controllers(&self, text: &str, file: &str) -> Result<(), TrackError> {
        let (f, p, pp, st) = (
            &self.controller.fuzzy,
            &self.controller.pid,
            &self.controller.pure_pursuit,
            &self.controller.stanley,
        );
        const FUZZY: &str = "controller.fuzzy";
        const PID: &str = "controller.pid";
        const PP: &str = "controller.pure_pursuit";
        const ST: &str = "controller.stanley";
        let positive = [
            (FUZZY, "k1", f.k1),
            (FUZZY, "k2", f.k2),
            (FUZZY, "k3", f.k3),
            (PID, "max_steer_rpm", p.max_steer_rpm),
            (PP, "lookahead_m", pp.lookahead_m),
            (PP, "max_steer_rpm", pp.max_steer_rpm),
            (ST, "softening_mps", st.softening_mps),
            (ST, "heading_time_s", st.heading_time_s),
            (ST, "max_steer_rpm", st.max_steer_rpm),
        ];
        config::check_each(text, file, &positive, config::POSITIVE)?;
        let non_negative = [
            (FUZZY, "alpha", f.alpha),
            (FUZZY, "ec_filter_s", f.ec_filter_s),
            (PID, "kp", p.kp),
            (PID, "ki", p.ki),
            (PID, "kd", p.kd),
            (PID, "alpha", p.alpha),
            (PP, "lookahead_gain_s", pp.lookahead_gain_s),
            (ST, "k_per_s", st.k_per_s),
            (FUZZY, "alpha_curvature_m", f.alpha_curvature_m),
        ];
        config::check_each(text, file, &non_negative, config::NON_NEGATIVE)?;
        for (key, v) in [("vu_tau", f.vu_tau), ("vu_epsilon", f.vu_epsilon)] {
            if !(v.is_finite() && v > 0.0 && v <= 1.0) {
                return Err(config::invalid(
                    text,
                    file,
                    (FUZZY, 0),
                    key,
                    v.to_string(),
                    "a value in (0, 1]",
                )
                .into());
            }
        }
        Ok(())
    }

    fn check_machine(&self, text: &str, file: &str) -> Result<(), TrackError> {
        if let Some(c) = &self.crawler {
            let positive = [
                ("crawler", "gauge_m", c.gauge_m),
                ("crawler", "sprocket_radius_m", c.sprocket_radius_m),
                ("crawler", "gear_ratio", c.gear_ratio),
                ("crawler", "motor_max_rpm", c.motor_max_rpm),
            ];
            config::check_each(text, file, &positive, config::POSITIVE)?;
            let accel = [(
                "crawler",
                "motor_max_accel_rpm_per_s",
                c.motor_max_accel_rpm_per_s,
            )];
            config::check_each(text, file, &accel, config::NON_NEGATIVE)?;
        }
        if let Some(s) = &self.slip {
            config::check_each(
                text,
                file,
                &[("slip", "left", s.left), ("slip", "right", s.right)],
                SLIP,
            )?;
            let lateral = [("slip", "lateral_gain_s", s.lateral_gain_s)];
            config::check_each(text, file, &lateral, config::NON_NEGATIVE)?;
        }
        if let Some(r) = &self.rtk {
            config::check_each(text, file, &[("rtk", "rate_hz", r.rate_hz)], RATE)?;
            let non_negative = [
                ("rtk", "position_sigma_m", r.position_sigma_m),
                ("rtk", "heading_sigma_deg", r.heading_sigma_deg),
                ("rtk", "dropouts_per_min", r.dropouts_per_min),
                ("rtk", "dropout_s", r.dropout_s),
            ];
            config::check_each(text, file, &non_negative, config::NON_NEGATIVE)?;
            let offset = [("rtk", "heading_offset_deg", r.heading_offset_deg)];
            config::check_each(text, file, &offset, FINITE)?;
        }
        Ok(())
    }

    fn check_sim(&self, text: &str, file: &str) -> Result<(), TrackError> {
        let s = self.sim();
        let positive = [
            ("sim", "plant_dt_s", s.plant_dt_s),
            ("sim", "accel_mps2", s.accel_mps2),
            ("sim", "creep_mps", s.creep_mps),
            ("sim", "pose_timeout_s", s.pose_timeout_s),
            ("sim", "max_plausible_speed_mps", s.max_plausible_speed_mps),
            ("sim", "time_per_m_limit_s", s.time_per_m_limit_s),
        ];
        config::check_each(text, file, &positive, config::POSITIVE)?;
        let non_negative = [
            ("sim", "preview_m", s.preview_m),
            ("sim", "preview_gain_s", s.preview_gain_s),
            ("sim", "terminal_preview_m", s.terminal_preview_m),
            ("sim", "terminal_zone_m", s.terminal_zone_m),
        ];
        config::check_each(text, file, &non_negative, config::NON_NEGATIVE)?;
        config::check_each(
            text,
            file,
            &[("sim", "control_rate_hz", s.control_rate_hz)],
            RATE,
        )?;
        if s.plant_dt_s > 0.1 {
            return Err(config::invalid(
                text,
                file,
                ("sim", 0),
                "plant_dt_s",
                s.plant_dt_s,
                "a step of at most 0.1 s",
            )
            .into());
        }
        let vmax = self.crawler.unwrap_or_default().max_track_speed_mps();
        let speed_at = if self.speed_mps.is_some() {
            ("", 0)
        } else {
            ("sim", 0)
        };
        if !(s.speed_mps.is_finite() && s.speed_mps > 0.0 && s.speed_mps <= vmax) {
            return Err(config::invalid(
                text,
                file,
                speed_at,
                "speed_mps",
                s.speed_mps,
                format!("a speed > 0 and at most the track speed limit {vmax:.3} m/s"),
            )
            .into());
        }
        if s.creep_mps > s.speed_mps {
            return Err(config::invalid(
                text,
                file,
                ("sim", 0),
                "creep_mps",
                s.creep_mps,
                format!("at most speed_mps = {}", s.speed_mps),
            )
            .into());
        }
        Ok(())
    }
}

impl TomlFile for ScenarioFile {
    type Error = TrackError;

    fn check(&self, text: &str, file: &str) -> Result<(), TrackError> {
        let s = &self.start;
        for (k, v) in [
            ("x_m", s.x_m),
            ("y_m", s.y_m),
            ("heading_deg", s.heading_deg),
        ] {
            if !v.is_finite() {
                return Err(TrackError::NotFinite {
                    file: file.to_string(),
                    line: line_of_key(text, "start", 0, k),
                    key: format!("[start] {k}"),
                    value: v,
                });
            }
        }
        if self.leg.is_empty() {
            return Err(config::invalid(
                text,
                file,
                ("", 0),
                "[[leg]]",
                "none",
                "at least one [[leg]] of points",
            )
            .into());
        }
        let legs = self.legs(text, file)?;
        let start = self.start();
        let (a, _, _) = legs[0].nearest(start.position(), f64::NEG_INFINITY, f64::INFINITY);
        let off = (a - start.position()).norm();
        if off > MAX_START_OFFSET_M {
            return Err(TrackError::StartOffPath {
                file: file.to_string(),
                line: line_of_key(text, "start", 0, "x_m"),
                distance_m: off,
                max_m: MAX_START_OFFSET_M,
            });
        }
        self.check_machine(text, file)?;
        self.check_sim(text, file)?;
        self.check_controllers(text, file)
    }
}

/// Reads a tracking scenario, or plans a travel scenario (a file with
/// `[site]`); `file` names it in errors.
pub fn from_toml(
    text: &str,
    file: &str,
    noise: Option<Noise>,
    seed: u64,
) -> Result<TrackScenario, TrackError> {
    let table: toml::Table = config::parse(text, file)?;
    if table.contains_key("site") {
        let travel = TravelScenario::from_toml(text, file).map_err(TrackError::Travel)?;
        let noise = noise.unwrap_or(Noise::Rtk);
        let mut setup = from_travel(&travel, file)?;
        apply_noise(&mut setup, noise, seed);
        return Ok(TrackScenario {
            name: travel.name,
            setup,
            noise,
            map: Some(travel.map),
            controllers: ControllerParams::default(),
        });
    }
    ScenarioFile::from_toml(text, file)?.into_scenario(text, file, noise, seed)
}

/// Refuses a run whose worst case ([`crate::sim::worst_case`]: the time
/// limit at the plant and control rates) passes the ceilings, naming the
/// `[sim]` setting at fault (the one whose default would meet it) with
/// the estimate.
fn check_work(setup: &Setup, text: &str, file: &str) -> Result<(), TrackError> {
    use crate::sim::{worst_case, MAX_CONTROL_STEPS, MAX_PLANT_STEPS, SAMPLE_BYTES};
    let (t_limit, plant, control) = worst_case(setup);
    let (d, sim) = (SimParams::default(), setup.sim);
    // The work with one setting back at its default: (plant, control) steps.
    let with = |sim: SimParams| {
        let (_, plant, control) = worst_case(&Setup {
            sim,
            ..setup.clone()
        });
        (plant, control)
    };
    let restored = [
        with(SimParams {
            plant_dt_s: d.plant_dt_s,
            ..sim
        }),
        with(SimParams {
            control_rate_hz: d.control_rate_hz,
            ..sim
        }),
        with(SimParams {
            time_per_m_limit_s: d.time_per_m_limit_s,
            ..sim
        }),
    ];
    let settings = |within: &dyn Fn((f64, f64)) -> bool| {
        [
            ("sim", "plant_dt_s", sim.plant_dt_s, within(restored[0])),
            (
                "sim",
                "control_rate_hz",
                sim.control_rate_hz,
                within(restored[1]),
            ),
            (
                "sim",
                "time_per_m_limit_s",
                sim.time_per_m_limit_s,
                within(restored[2]),
            ),
        ]
    };
    if plant > MAX_PLANT_STEPS {
        return Err(config::over_ceiling(
            text,
            file,
            &settings(&|(p, _)| p <= MAX_PLANT_STEPS),
            format!(
                "at most {} plant steps per run; the time limit of {} s at plant_dt_s = {} s and control_rate_hz = {} is about {}",
                config::approx(MAX_PLANT_STEPS),
                config::approx(t_limit),
                config::short(sim.plant_dt_s),
                config::short(sim.control_rate_hz),
                config::approx(plant)
            ),
        )
        .into());
    }
    if control > MAX_CONTROL_STEPS {
        return Err(config::over_ceiling(
            text,
            file,
            &settings(&|(_, c)| c <= MAX_CONTROL_STEPS),
            format!(
                "at most {} control steps per run; the time limit of {} s at {} Hz is about {} ({})",
                config::approx(MAX_CONTROL_STEPS),
                config::approx(t_limit),
                config::short(sim.control_rate_hz),
                config::approx(control),
                config::bytes(control * SAMPLE_BYTES)
            ),
        )
        .into());
    }
    Ok(())
}

fn apply_noise(setup: &mut Setup, noise: Noise, seed: u64) {
    match noise {
        Noise::Rtk => {
            setup.rtk = RtkParams::rtk(seed);
            setup.slip = SlipParams::loose_bench();
        }
        Noise::Off => {
            setup.rtk = RtkParams::ideal();
            setup.slip = SlipParams::none();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "speed_mps = 0.5\n[start]\nx_m = 0.0\ny_m = 0.3\nheading_deg = 0.0\n\
        [[leg]]\ndirection = \"forward\"\npoints_m = [[0.0, 0.0], [10.0, 0.0]]\n\
        [controller.fuzzy]\nk1 = 1.5\n";

    /// Runs whose worst case passes the ceilings are refused before they
    /// start, naming the setting at fault (the settings fuzzer hung on the
    /// first: 1.8e19 plant steps in one control step).
    #[test]
    fn runs_sized_beyond_the_ceilings_are_refused_naming_the_setting() {
        // 10 m path: time limit 30 + 20·10 = 230 s.
        for (sim, key, estimate) in [
            (
                "control_rate_hz = 1e-300",
                "[sim] control_rate_hz",
                "plant steps",
            ),
            ("plant_dt_s = 1e-9", "[sim] plant_dt_s", "2.30e11"),
            (
                "time_per_m_limit_s = 1e308",
                "[sim] time_per_m_limit_s",
                "plant steps",
            ),
            (
                "control_rate_hz = 1000.0\ntime_per_m_limit_s = 1000.0",
                "[sim] control_rate_hz",
                "1.00e7",
            ),
        ] {
            let text = format!("{TEXT}[sim]\n{sim}\n");
            let msg = match from_toml(&text, "t.toml", None, 1) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("{sim}: accepted"),
            };
            assert!(
                msg.starts_with("t.toml:") && msg.contains(key) && msg.contains(estimate),
                "{sim}: {msg}"
            );
        }
        // The ceilings leave room: 1 kHz control over the default limit.
        let text = format!("{TEXT}[sim]\ncontrol_rate_hz = 1000.0\n");
        assert!(from_toml(&text, "t.toml", None, 1).is_ok());
    }

    #[test]
    fn gains_load_with_defaults_beside_them_and_round_trip() {
        let f = ScenarioFile::from_toml(TEXT, "t.toml").unwrap();
        assert_eq!(f.controller.fuzzy.k1, 1.5);
        assert_eq!(
            f.controller.fuzzy.k2,
            crate::FuzzyParams::default().k2,
            "unset gains keep their defaults"
        );
        assert_eq!(f.controller.pid, crate::PidParams::default());
        let back = ScenarioFile::from_toml(&f.to_toml(), "t.toml").unwrap();
        assert_eq!(f, back);
        let s = f.into_scenario(TEXT, "t.toml", None, 1).unwrap();
        assert_eq!(s.controllers.fuzzy.k1, 1.5);
        assert_eq!(s.name, "t.toml");
    }

    #[test]
    fn a_bad_gain_names_its_table_key_and_line() {
        let text = TEXT.replace("k1 = 1.5", "k1 = 0.0");
        let e = ScenarioFile::from_toml(&text, "t.toml").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.toml:10: [controller.fuzzy] k1 = 0 is invalid: expected a finite value > 0"
        );
    }
}
