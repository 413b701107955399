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
//! ```

use autoshovel_core::{rad, Pose2, Vec2};
use autoshovel_propel::{plan_path, Direction, FieldKind, PlanOptions, Scenario as TravelScenario};
use serde::Deserialize;

use crate::geometry::RefLeg;
use crate::plant::{CrawlerParams, SlipParams};
use crate::sensor::RtkParams;
use crate::sim::{Setup, SimParams};

/// The built-in tracking scenarios.
pub const BUILTINS: &[&str] = &["fig9a", "fig9b", "straight", "curve", "v-shape"];

/// Whether a run has sensor noise and slip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Noise {
    /// Exact fixes, ideal tracks.
    Off,
    /// RTK noise (Table 2-like) and loose-bench slip.
    Rtk,
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
    pub map: Option<autoshovel_propel::Map>,
}

/// Errors of tracking scenarios.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// Unknown name and no such file.
    #[error("unknown tracking scenario '{name}': not a built-in ({known}) and no such file")]
    Unknown {
        /// What was given.
        name: String,
        /// The built-ins.
        known: String,
    },
    /// The file could not be read.
    #[error("cannot read {path}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// TOML syntax or a wrong field.
    #[error("{file}:{line}:{column}: {message}")]
    Parse {
        /// File.
        file: String,
        /// Line.
        line: usize,
        /// Column.
        column: usize,
        /// What.
        message: String,
    },
    /// A value out of range.
    #[error("{file}: {what}")]
    Invalid {
        /// File.
        file: String,
        /// What, naming the value.
        what: String,
    },
    /// Planning the travel scenario failed.
    #[error("{file}: planning the path failed: {source}")]
    Plan {
        /// File.
        file: String,
        /// The planner's error.
        source: autoshovel_propel::PropelError,
    },
}

/// Farthest the start may be from the first leg [m].
pub const MAX_START_OFFSET_M: f64 = 20.0;

/// The Fig. 9 path: (0, 0) → (30, 30).
fn fig9_leg() -> RefLeg {
    RefLeg::new(
        Direction::Forward,
        vec![Vec2::new(0.0, 0.0), Vec2::new(30.0, 30.0)],
        None,
    )
    .expect("valid")
}

/// Builds a built-in scenario, or reads a file. `noise` overrides the
/// scenario's default; `seed` seeds the sensor noise.
pub fn resolve(
    name_or_path: &str,
    noise: Option<Noise>,
    seed: u64,
) -> Result<TrackScenario, ScenarioError> {
    let with = |noise: Noise, mut setup: Setup| {
        if noise == Noise::Rtk {
            setup.rtk = RtkParams::rtk(seed);
            setup.slip = SlipParams::loose_bench();
        } else {
            setup.rtk = RtkParams::ideal();
            setup.slip = SlipParams::none();
        }
        setup
    };
    match name_or_path {
        "fig9a" | "fig9b" => {
            let (start, v) = if name_or_path == "fig9a" {
                (Pose2::new(2.0, -2.0, std::f64::consts::FRAC_PI_4), 2.0)
            } else {
                (Pose2::new(0.0, 5.0, std::f64::consts::FRAC_PI_4), 1.0)
            };
            let noise = noise.unwrap_or(Noise::Off);
            let setup = Setup {
                legs: vec![fig9_leg()],
                start,
                crawler: CrawlerParams::default(),
                slip: SlipParams::none(),
                rtk: RtkParams::ideal(),
                sim: SimParams {
                    speed_mps: v,
                    ..Default::default()
                },
            };
            Ok(TrackScenario {
                name: name_or_path.to_string(),
                setup: with(noise, setup),
                noise,
                map: None,
            })
        }
        "straight" | "curve" | "v-shape" => {
            let travel = TravelScenario::builtin(name_or_path).expect("built-in travel scenario");
            let noise = noise.unwrap_or(Noise::Rtk);
            let setup = from_travel(&travel, &format!("<builtin {name_or_path}>"))?;
            Ok(TrackScenario {
                name: name_or_path.to_string(),
                setup: with(noise, setup),
                noise,
                map: Some(travel.map),
            })
        }
        path => {
            let p = std::path::Path::new(path);
            if !p.exists() {
                return Err(ScenarioError::Unknown {
                    name: path.to_string(),
                    known: BUILTINS.join(", "),
                });
            }
            let text = std::fs::read_to_string(p).map_err(|source| ScenarioError::Io {
                path: path.to_string(),
                source,
            })?;
            from_toml(&text, path, noise, seed)
        }
    }
}

/// Plans a travel scenario with the improved field and tracks its legs from its start.
pub fn from_travel(travel: &TravelScenario, file: &str) -> Result<Setup, ScenarioError> {
    let plan = plan_path(travel, &PlanOptions::new(FieldKind::Improved)).map_err(|source| {
        ScenarioError::Plan {
            file: file.to_string(),
            source,
        }
    })?;
    let legs = travel.legs();
    let mut out = Vec::new();
    for (leg, (_, to, _)) in plan.path.legs.iter().zip(legs) {
        let pts: Vec<Vec2> = leg.points.iter().map(|p| p.pose.position()).collect();
        let leg = RefLeg::new(leg.direction, pts, Some(to.theta)).map_err(|f| {
            ScenarioError::Invalid {
                file: file.to_string(),
                what: format!("planned path {f}"),
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

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    name: Option<String>,
    speed_mps: Option<f64>,
    noise: Option<Noise>,
    start: StartSpec,
    #[serde(default)]
    leg: Vec<LegSpec>,
    crawler: Option<CrawlerParams>,
    slip: Option<SlipParams>,
    rtk: Option<RtkParams>,
    sim: Option<SimParams>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StartSpec {
    x_m: f64,
    y_m: f64,
    heading_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LegSpec {
    direction: Direction,
    points_m: Vec<[f64; 2]>,
    end_heading_deg: Option<f64>,
}

/// Parses a tracking scenario, or plans a travel scenario (a file with `[site]`).
pub fn from_toml(
    text: &str,
    file: &str,
    noise: Option<Noise>,
    seed: u64,
) -> Result<TrackScenario, ScenarioError> {
    let parse_err = |e: toml::de::Error| {
        let (line, column) = e
            .span()
            .map(|s| {
                let before = &text[..s.start.min(text.len())];
                (
                    before.matches('\n').count() + 1,
                    before.len() - before.rfind('\n').map(|i| i + 1).unwrap_or(0) + 1,
                )
            })
            .unwrap_or((0, 0));
        ScenarioError::Parse {
            file: file.to_string(),
            line,
            column,
            message: e.message().to_string(),
        }
    };
    let table: toml::Table = toml::from_str(text).map_err(parse_err)?;
    let invalid = |what: String| ScenarioError::Invalid {
        file: file.to_string(),
        what,
    };
    if table.contains_key("site") {
        let travel =
            TravelScenario::from_toml(text, file).map_err(|source| ScenarioError::Plan {
                file: file.to_string(),
                source,
            })?;
        let noise = noise.unwrap_or(Noise::Rtk);
        let mut setup = from_travel(&travel, file)?;
        apply_noise(&mut setup, noise, seed);
        return Ok(TrackScenario {
            name: travel.name,
            setup,
            noise,
            map: Some(travel.map),
        });
    }
    let spec: FileSpec = toml::from_str(text).map_err(parse_err)?;
    let s = &spec.start;
    for (k, v) in [
        ("x_m", s.x_m),
        ("y_m", s.y_m),
        ("heading_deg", s.heading_deg),
    ] {
        if !v.is_finite() {
            return Err(invalid(format!("[start] {k} = {v} is not a finite number")));
        }
    }
    if spec.leg.is_empty() {
        return Err(invalid(
            "no [[leg]]: a tracking scenario needs at least one leg of points".into(),
        ));
    }
    let mut legs = Vec::new();
    for (i, l) in spec.leg.iter().enumerate() {
        if l.points_m.len() > 1_000_000 {
            return Err(invalid(format!(
                "leg #{} has {} points; at most 1000000",
                i + 1,
                l.points_m.len()
            )));
        }
        let pts: Vec<Vec2> = l.points_m.iter().map(|p| Vec2::new(p[0], p[1])).collect();
        let end = match l.end_heading_deg {
            Some(h) if !h.is_finite() => {
                return Err(invalid(format!(
                    "leg #{}: end_heading_deg = {h} is not finite",
                    i + 1
                )))
            }
            Some(h) => Some(rad(h)),
            None => None,
        };
        legs.push(
            RefLeg::new(l.direction, pts, end)
                .map_err(|f| invalid(format!("leg #{} {f}", i + 1)))?,
        );
    }
    let start = Pose2::new(s.x_m, s.y_m, rad(s.heading_deg));
    let (a, _, _) = legs[0].nearest(start.position(), f64::NEG_INFINITY, f64::INFINITY);
    let off = (a - start.position()).norm();
    if off > MAX_START_OFFSET_M {
        return Err(invalid(format!("the start is {off:.2} m from the first leg; at most {MAX_START_OFFSET_M} m (plan a path to it first)")));
    }
    let mut sim = spec.sim.unwrap_or_default();
    if let Some(v) = spec.speed_mps {
        sim.speed_mps = v;
    }
    let crawler = spec.crawler.unwrap_or_default();
    let noise = noise.or(spec.noise).unwrap_or(Noise::Off);
    let mut setup = Setup {
        legs,
        start,
        crawler,
        slip: SlipParams::none(),
        rtk: RtkParams::ideal(),
        sim,
    };
    apply_noise(&mut setup, noise, seed);
    if let Some(slip) = spec.slip {
        setup.slip = slip;
    }
    if let Some(rtk) = spec.rtk {
        setup.rtk = rtk;
    }
    validate(&setup).map_err(invalid)?;
    Ok(TrackScenario {
        name: spec.name.unwrap_or_else(|| file.to_string()),
        setup,
        noise,
        map: None,
    })
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

/// Checks every parameter of a setup; the message names the first bad value.
pub fn validate(setup: &Setup) -> Result<(), String> {
    setup
        .crawler
        .validate()
        .map_err(|(k, v)| format!("[crawler] {k} = {v} is impossible"))?;
    setup
        .slip
        .validate()
        .map_err(|(k, v)| format!("[slip] {k} = {v} is out of range"))?;
    setup
        .rtk
        .validate()
        .map_err(|(k, v)| format!("[rtk] {k} = {v} is out of range"))?;
    let s = &setup.sim;
    for (k, v) in [
        ("plant_dt_s", s.plant_dt_s),
        ("accel_mps2", s.accel_mps2),
        ("creep_mps", s.creep_mps),
        ("pose_timeout_s", s.pose_timeout_s),
        ("max_plausible_speed_mps", s.max_plausible_speed_mps),
        ("time_per_m_limit_s", s.time_per_m_limit_s),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("[sim] {k} = {v} must be positive"));
        }
    }
    for (k, v) in [
        ("preview_m", s.preview_m),
        ("preview_gain_s", s.preview_gain_s),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(format!("[sim] {k} = {v} must be zero or positive"));
        }
    }
    if !(s.control_rate_hz.is_finite() && s.control_rate_hz > 0.0 && s.control_rate_hz <= 1000.0) {
        return Err(format!(
            "[sim] control_rate_hz = {} must be in (0, 1000]",
            s.control_rate_hz
        ));
    }
    if s.plant_dt_s > 0.1 {
        return Err(format!(
            "[sim] plant_dt_s = {} is too coarse (at most 0.1 s)",
            s.plant_dt_s
        ));
    }
    let vmax = setup.crawler.max_track_speed_mps();
    if !(s.speed_mps.is_finite() && s.speed_mps > 0.0 && s.speed_mps <= vmax) {
        return Err(format!(
            "speed_mps = {} must be positive and at most the track speed limit {vmax:.3} m/s",
            s.speed_mps
        ));
    }
    if s.creep_mps > s.speed_mps {
        return Err(format!(
            "[sim] creep_mps = {} exceeds speed_mps = {}",
            s.creep_mps, s.speed_mps
        ));
    }
    Ok(())
}
