//! Dig scenarios: where and how deep to dig, how much, the soil, the planner's
//! settings, the ground line and the buried boulders (which the planner does
//! not see until it meets them) — as TOML.
//!
//! Built-ins (embedded from `scenarios/`): `paper-over` and `paper-under`,
//! the paper's §3 case (start (7, 0), boulder Ø 0.5 m, depth 0.7 m, step
//! 0.05 m, 0.9 m³) with the boulder placed so that the preimage rule passes
//! it over in one and under in the other, and `two-boulders`. Every key is
//! required except `[ground]` (level ground y = 0 when absent), the
//! `[[obstacle]]` tables (none when absent), `[sensing]` and the planner's
//! boulder prior and γ reading (defaults below). Errors name the file, the
//! line and the key.
//!
//! The planner sees only [`Scenario::brief`]: the dig, its settings and the
//! ground. `[soil]`, `[sensing]` and the boulders are the simulator's.
//!
//! ```toml
//! name = "my-dig"
//! description = "what this is"
//!
//! [dig]
//! start_x_m = 7.0            # x_begin; the start is on the ground there
//! depth_m = 0.7              # h
//! step_m = 0.05              # s, of the step search and the forward-search grid
//! target_volume_m3 = 0.9     # V
//! attitude_start_deg = -80.0 # attitude angle φ at the start, the midpoint, the end
//! attitude_mid_deg = -140.0
//! attitude_end_deg = -200.0
//!
//! [soil]
//! cutting_resistance_pa = 60000.0  # k of F = k·b·c
//! normal_ratio = 0.3               # ψ
//! density_kg_m3 = 1800.0
//! rock_friction = 0.3              # μ between tooth and boulder
//!
//! [planner]
//! clearance_m = 0.1          # margin the forward search keeps from envelopes
//! search_window_m = 1.0      # grid reach beyond the inflated envelope
//! speed_fraction = 0.5       # share of the joint speed limits a segment may use
//! min_segment_time_s = 1.0
//! dt_s = 0.01                # simulator step
//! trapezoids = 100           # [HE eq. 2] strips per planned segment
//! max_contacts = 8
//! refine_volume = false      # true: bisect inside the last step for the exact volume
//! max_overdig_m = 0.15       # how far a level-1 path may dip below the dig depth
//! # boulder_radius_m = 0.24  # radius assumed at a first touch (default: 30 % of the bucket)
//! rock_friction_prior = 0.3  # μ the planner assumes, to turn the force into a normal
//! gamma_reading = "clockwise" # or "mirrored" (preimage module)
//!
//! [sensing]                  # optional: the machine's joint-torque readings
//! torque_noise_nm = 1000.0   # standard deviation per joint
//! seed = 0
//!
//! [ground]                   # optional polyline, x increasing
//! points = [[0.0, 0.0], [10.0, 0.0]]
//!
//! [[obstacle]]               # an envelope circle ([HE eq. 10]); repeat per boulder
//! center_m = [6.0, -0.5]
//! radius_m = 0.25
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{ExcavateError, Result};
use crate::ground::Ground;
use crate::kinematics::Backhoe;
use crate::level1::{Level1Request, StepSearch};
use crate::obstacle::Envelope;
use crate::preimage::GammaReading;
use crate::soil::Soil;
use autoshovel_core::config::{self, line_of_key, ConfigError, TomlFile};

/// The built-in scenarios: (name, TOML text).
pub const BUILTINS: [(&str, &str); 3] = [
    ("paper-over", include_str!("../scenarios/paper-over.toml")),
    ("paper-under", include_str!("../scenarios/paper-under.toml")),
    (
        "two-boulders",
        include_str!("../scenarios/two-boulders.toml"),
    ),
];

/// Most points of a forward-search grid. Each holds about
/// [`GRID_POINT_BYTES`] of search state, so 10⁷ is about 180 MB; the
/// built-ins use about 3 000.
pub const MAX_GRID_POINTS: f64 = 1e7;
/// Bytes of search state per forward-search grid point (class, cost,
/// parent, closed flag).
pub const GRID_POINT_BYTES: f64 = 18.0;
/// Most volume strips one level-1 step search may evaluate (the steps
/// from the start to the slew axis times the trapezoids per candidate);
/// 10⁸ takes seconds. The built-ins use about 14 000.
pub const MAX_STEP_SEARCH_STRIPS: f64 = 1e8;
/// Most simulator steps in one dig. Each keeps about [`SIM_STEP_BYTES`]
/// (the sample, the state, the tip), so 10⁶ is about 300 MB; the
/// built-ins take about 2 000.
pub const MAX_SIM_STEPS: f64 = 1e6;
/// Bytes kept per simulator step.
pub const SIM_STEP_BYTES: f64 = 300.0;

/// The dig the operator asks for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DigSpec {
    /// x_begin (m); the start is on the ground there.
    pub start_x_m: f64,
    /// h: depth of the midpoint below the ground (m).
    pub depth_m: f64,
    /// s: step of the level-1 search and the level-2 grid (m).
    pub step_m: f64,
    /// V (m³).
    pub target_volume_m3: f64,
    /// Attitude angle φ at the start (deg).
    pub attitude_start_deg: f64,
    /// φ at the midpoint (deg).
    pub attitude_mid_deg: f64,
    /// φ at the end (deg).
    pub attitude_end_deg: f64,
}

/// The planner's and simulator's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannerSpec {
    /// Margin the forward search keeps from every envelope (m).
    pub clearance_m: f64,
    /// How far beyond the inflated envelope the search grid reaches (m).
    pub search_window_m: f64,
    /// Share of each joint's speed limit a segment may use at its peak.
    pub speed_fraction: f64,
    /// Shortest segment (s).
    pub min_segment_time_s: f64,
    /// Simulator time step (s).
    pub dt_s: f64,
    /// Trapezoids ([HE eq. 2]) per planned segment.
    pub trapezoids: usize,
    /// Most contacts handled in one pass.
    pub max_contacts: usize,
    /// Bisect inside the step search's last step for the exact volume
    /// (false: the paper's rule, the nearer of the two last candidates).
    pub refine_volume: bool,
    /// How far a level-1 path may dip below the dig depth (or below its
    /// start, where that is deeper) (m).
    pub max_overdig_m: f64,
    /// The radius the planner assumes for a boulder touched once, and the
    /// least it ever estimates (m); absent: the paper's class, a disc across
    /// the bucket holding 30 % of its volume ([`crate::estimate`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub boulder_radius_m: Option<f64>,
    /// μ the planner assumes between tooth and rock, to turn the measured
    /// force into the rock's normal (the simulator's is `[soil] rock_friction`).
    #[serde(default = "default_rock_friction_prior")]
    pub rock_friction_prior: f64,
    /// Which way γ is counted ([`GammaReading`]).
    #[serde(default)]
    pub gamma_reading: GammaReading,
}

fn default_rock_friction_prior() -> f64 {
    0.3
}

/// What the machine's sensors add to the simulator: the joint torques it
/// measures (cylinder pressures through the linkage) carry Gaussian noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensingSpec {
    /// Standard deviation of each measured joint torque (N·m).
    pub torque_noise_nm: f64,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for SensingSpec {
    /// 1 kN·m per joint: about 1 % of the torques a 100 kN digging force
    /// makes at the joints of a 15 t machine.
    fn default() -> Self {
        Self {
            torque_noise_nm: 1000.0,
            seed: 0,
        }
    }
}

/// The planner's view of a scenario ([`Scenario::brief`]): the dig, its
/// settings and the ground line, which a survey gives, and nothing of what is
/// buried or of the soil's and rock's properties, which only the simulator
/// holds.
#[derive(Debug, Clone, Copy)]
pub struct Brief<'a> {
    /// The dig asked for.
    pub dig: &'a DigSpec,
    /// The planner's settings.
    pub planner: &'a PlannerSpec,
    /// The ground line.
    pub ground: &'a Ground,
}

impl<'a> Brief<'a> {
    /// Level 1's request for this dig: start, depth, target and the three
    /// attitudes in radians.
    pub fn level1_request(&self) -> Level1Request {
        let d = self.dig;
        Level1Request {
            start_x_m: d.start_x_m,
            depth_m: d.depth_m,
            target_volume_m3: d.target_volume_m3,
            attitude_rad: [
                d.attitude_start_deg.to_radians(),
                d.attitude_mid_deg.to_radians(),
                d.attitude_end_deg.to_radians(),
            ],
        }
    }

    /// The step-search settings of this dig for `machine` with a bucket
    /// `bucket_width_m` wide, avoiding the `known` envelopes.
    pub fn step_search<'b>(
        &self,
        machine: &'b Backhoe,
        bucket_width_m: f64,
        known: &'b [Envelope],
    ) -> StepSearch<'b>
    where
        'a: 'b,
    {
        let p = self.planner;
        StepSearch {
            machine,
            ground: self.ground,
            bucket_width_m,
            step_m: self.dig.step_m,
            trapezoids: p.trapezoids,
            speed_fraction: p.speed_fraction,
            min_segment_time_s: p.min_segment_time_s,
            known,
            refine: p.refine_volume,
            max_overdig_m: p.max_overdig_m,
        }
    }
}

/// A whole scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name.
    pub name: String,
    /// One line on what it shows.
    pub description: String,
    /// The dig.
    pub dig: DigSpec,
    /// The soil.
    pub soil: Soil,
    /// Planner settings.
    pub planner: PlannerSpec,
    /// The ground line (level y = 0 when absent).
    #[serde(default)]
    pub ground: Ground,
    /// Buried boulders, unknown to the planner until met.
    #[serde(default, rename = "obstacle")]
    pub obstacles: Vec<Envelope>,
    /// The machine's sensors (torque noise).
    #[serde(default)]
    pub sensing: SensingSpec,
}

impl Scenario {
    /// What the planner may know of this scenario: no boulders, no soil.
    pub fn brief(&self) -> Brief<'_> {
        Brief {
            dig: &self.dig,
            planner: &self.planner,
            ground: &self.ground,
        }
    }

    /// Level 1's request for this dig ([`Brief::level1_request`]).
    pub fn level1_request(&self) -> Level1Request {
        self.brief().level1_request()
    }

    /// The step-search settings of this dig ([`Brief::step_search`]).
    pub fn step_search<'a>(
        &'a self,
        machine: &'a Backhoe,
        bucket_width_m: f64,
        known: &'a [Envelope],
    ) -> StepSearch<'a> {
        self.brief().step_search(machine, bucket_width_m, known)
    }

    /// Names of the built-ins.
    pub fn builtin_names() -> Vec<&'static str> {
        BUILTINS.iter().map(|(n, _)| *n).collect()
    }

    /// The commented TOML of a built-in.
    pub fn builtin_toml(name: &str) -> Option<&'static str> {
        BUILTINS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
    }

    /// A built-in by name.
    pub fn builtin(name: &str) -> Result<Self> {
        let text = Self::builtin_toml(name).ok_or_else(|| ExcavateError::UnknownScenario {
            name: name.to_string(),
            known: Self::builtin_names().join(", "),
        })?;
        Self::from_toml(text, &format!("<builtin {name}>"))
    }

    /// The paper's case, passed over.
    pub fn paper_over() -> Self {
        Self::builtin("paper-over").expect("the built-in is valid")
    }

    /// The paper's case, passed under.
    pub fn paper_under() -> Self {
        Self::builtin("paper-under").expect("the built-in is valid")
    }

    /// A built-in name, or else a TOML file path.
    pub fn from_name_or_file(arg: &str) -> Result<Self> {
        if Self::builtin_toml(arg).is_some() {
            return Self::builtin(arg);
        }
        let path = Path::new(arg);
        if !path.exists() && !arg.contains('.') && !arg.contains('/') {
            return Err(ExcavateError::UnknownScenario {
                name: arg.to_string(),
                known: Self::builtin_names().join(", "),
            });
        }
        Self::load(path)
    }

    fn check_values(&self, text: &str, file: &str) -> Result<()> {
        let bad = |table: &str, occurrence: usize, key: &str, value: String, expected: &str| {
            ExcavateError::from(if table == "obstacle" {
                // An array of tables: name the entry as well as the key.
                ConfigError::Invalid {
                    file: file.to_string(),
                    line: line_of_key(text, table, occurrence, key),
                    key: format!("[[obstacle]] #{} {key}", occurrence + 1),
                    value,
                    expected: expected.to_string(),
                }
            } else {
                config::invalid(text, file, (table, occurrence), key, value, expected)
            })
        };
        let d = &self.dig;
        let positive = [
            ("dig", "depth_m", d.depth_m),
            ("dig", "target_volume_m3", d.target_volume_m3),
            ("dig", "start_x_m", d.start_x_m),
            ("soil", "density_kg_m3", self.soil.density_kg_m3),
            ("planner", "clearance_m", self.planner.clearance_m),
            ("planner", "search_window_m", self.planner.search_window_m),
            (
                "planner",
                "min_segment_time_s",
                self.planner.min_segment_time_s,
            ),
        ];
        config::check_each(text, file, &positive, config::POSITIVE)?;
        if !(d.step_m.is_finite() && d.step_m > 0.0 && d.step_m <= 0.5) {
            return Err(bad(
                "dig",
                0,
                "step_m",
                d.step_m.to_string(),
                "a step in (0, 0.5] m",
            ));
        }
        for key in ["attitude_start_deg", "attitude_mid_deg", "attitude_end_deg"] {
            let v = match key {
                "attitude_start_deg" => d.attitude_start_deg,
                "attitude_mid_deg" => d.attitude_mid_deg,
                _ => d.attitude_end_deg,
            };
            if !(v.is_finite() && v.abs() <= 360.0) {
                return Err(bad("dig", 0, key, v.to_string(), "an angle within ±360°"));
            }
        }
        let non_negative = [
            (
                "soil",
                "cutting_resistance_pa",
                self.soil.cutting_resistance_pa,
            ),
            ("soil", "normal_ratio", self.soil.normal_ratio),
            ("soil", "rock_friction", self.soil.rock_friction),
        ];
        config::check_each(text, file, &non_negative, config::NON_NEGATIVE)?;
        let p = &self.planner;
        if !(p.speed_fraction > 0.0 && p.speed_fraction <= 1.0) {
            return Err(bad(
                "planner",
                0,
                "speed_fraction",
                p.speed_fraction.to_string(),
                "a share in (0, 1]",
            ));
        }
        if !(p.dt_s > 0.0 && p.dt_s <= 0.1) {
            return Err(bad(
                "planner",
                0,
                "dt_s",
                p.dt_s.to_string(),
                "a step in (0, 0.1] s",
            ));
        }
        if !(10..=10_000).contains(&p.trapezoids) {
            return Err(bad(
                "planner",
                0,
                "trapezoids",
                p.trapezoids.to_string(),
                "between 10 and 10000",
            ));
        }
        if !(1..=100).contains(&p.max_contacts) {
            return Err(bad(
                "planner",
                0,
                "max_contacts",
                p.max_contacts.to_string(),
                "between 1 and 100",
            ));
        }
        if let Some(r) = p.boulder_radius_m {
            if !(r.is_finite() && r > 0.0 && r <= 5.0) {
                return Err(bad(
                    "planner",
                    0,
                    "boulder_radius_m",
                    r.to_string(),
                    "a radius in (0, 5] m",
                ));
            }
        }
        if !(p.rock_friction_prior.is_finite() && (0.0..=2.0).contains(&p.rock_friction_prior)) {
            return Err(bad(
                "planner",
                0,
                "rock_friction_prior",
                p.rock_friction_prior.to_string(),
                "a friction coefficient in [0, 2]",
            ));
        }
        let noise = self.sensing.torque_noise_nm;
        if !(noise.is_finite() && noise >= 0.0) {
            return Err(bad(
                "sensing",
                0,
                "torque_noise_nm",
                noise.to_string(),
                "a standard deviation ≥ 0 N·m",
            ));
        }
        if let Some(why) = self.ground.problem() {
            return Err(bad(
                "ground",
                0,
                "points",
                format!("{:?}", self.ground.points),
                &format!("a polyline with x increasing ({why})"),
            ));
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            if !(o.center_m[0].is_finite() && o.center_m[1].is_finite()) {
                return Err(bad(
                    "obstacle",
                    i,
                    "center_m",
                    format!("{:?}", o.center_m),
                    "a finite point [x, y]",
                ));
            }
            if !(o.radius_m.is_finite() && o.radius_m > 0.0) {
                return Err(bad(
                    "obstacle",
                    i,
                    "radius_m",
                    o.radius_m.to_string(),
                    "a finite radius > 0",
                ));
            }
        }
        self.check_work(text, file)
    }

    /// Points of the forward-search grid round the largest boulder at
    /// `step_m` reaching `window_m` beyond its inflated envelope (0 with no
    /// boulders): the square `forward_search` allocates.
    fn grid_points_at(&self, step_m: f64, window_m: f64) -> f64 {
        let largest = self
            .obstacles
            .iter()
            .map(|o| o.radius_m)
            .fold(0.0, f64::max);
        if self.obstacles.is_empty() {
            return 0.0;
        }
        let side = 2.0 * (largest + self.planner.clearance_m + window_m) / step_m + 5.0;
        side * side
    }

    /// Volume strips one level-1 step search may evaluate.
    fn strips_at(&self, step_m: f64, trapezoids: f64) -> f64 {
        (self.dig.start_x_m / step_m).ceil() * trapezoids
    }

    /// The work the settings imply, against the ceilings
    /// ([`MAX_GRID_POINTS`], [`MAX_STEP_SEARCH_STRIPS`]); the simulator's
    /// steps need the planned duration and are checked by the planner.
    /// A refusal names the setting that breaks the ceiling (the one whose
    /// built-in value would meet it) with the estimate.
    fn check_work(&self, text: &str, file: &str) -> Result<()> {
        // The built-ins' values, to tell which setting is at fault.
        const STEP_M: f64 = 0.05;
        const WINDOW_M: f64 = 1.0;
        const TRAPEZOIDS: f64 = 100.0;
        let (d, p) = (&self.dig, &self.planner);
        let grid = self.grid_points_at(d.step_m, p.search_window_m);
        if grid > MAX_GRID_POINTS {
            let within = |step, window| self.grid_points_at(step, window) <= MAX_GRID_POINTS;
            return Err(config::over_ceiling(
                text,
                file,
                &[
                    ("planner", "search_window_m", p.search_window_m, within(d.step_m, WINDOW_M)),
                    ("dig", "step_m", d.step_m, within(STEP_M, p.search_window_m)),
                ],
                format!(
                    "at most {} forward-search grid points; with step_m = {} m and search_window_m = {} m the grid round the largest boulder would have about {} ({})",
                    config::approx(MAX_GRID_POINTS),
                    config::short(d.step_m),
                    config::short(p.search_window_m),
                    config::approx(grid),
                    config::bytes(grid * GRID_POINT_BYTES)
                ),
            )
            .into());
        }
        let strips = self.strips_at(d.step_m, p.trapezoids as f64);
        if strips > MAX_STEP_SEARCH_STRIPS {
            let within =
                |step, trapezoids| self.strips_at(step, trapezoids) <= MAX_STEP_SEARCH_STRIPS;
            return Err(config::over_ceiling(
                text,
                file,
                &[
                    ("dig", "step_m", d.step_m, within(STEP_M, p.trapezoids as f64)),
                    ("planner", "trapezoids", p.trapezoids as f64, within(d.step_m, TRAPEZOIDS)),
                    ("dig", "start_x_m", d.start_x_m, false),
                ],
                format!(
                    "at most {} volume strips per step search; {} steps of {} m from x = {} m, {} trapezoids each, are about {}",
                    config::approx(MAX_STEP_SEARCH_STRIPS),
                    config::approx((d.start_x_m / d.step_m).ceil()),
                    config::short(d.step_m),
                    config::short(d.start_x_m),
                    p.trapezoids,
                    config::approx(strips)
                ),
            )
            .into());
        }
        Ok(())
    }
}

impl TomlFile for Scenario {
    type Error = ExcavateError;

    fn check(&self, text: &str, file: &str) -> Result<()> {
        self.check_values(text, file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_builtins_load_and_round_trip_through_toml() {
        for name in Scenario::builtin_names() {
            let s = Scenario::builtin(name).unwrap();
            assert_eq!(s.name, name);
            let back = Scenario::from_toml(&s.to_toml(), "x").unwrap();
            assert_eq!(s, back);
        }
        let err = Scenario::builtin("nope").unwrap_err().to_string();
        assert!(
            err.contains("paper-over") && err.contains("paper-under"),
            "{err}"
        );
    }

    #[test]
    fn the_paper_cases_are_section_3() {
        for s in [Scenario::paper_over(), Scenario::paper_under()] {
            assert_eq!(s.dig.start_x_m, 7.0);
            assert_eq!(s.dig.depth_m, 0.7);
            assert_eq!(s.dig.step_m, 0.05);
            assert_eq!(s.dig.target_volume_m3, 0.9);
            assert_eq!(s.obstacles.len(), 1);
            assert_eq!(s.obstacles[0].radius_m, 0.25);
            assert!(s.ground.points.is_empty());
        }
    }

    #[test]
    fn errors_name_file_line_and_key() {
        let text = Scenario::builtin_toml("two-boulders").unwrap();
        let bad = text.replacen("radius_m = 0.2", "radius_m = -0.2", 1);
        let err = Scenario::from_toml(&bad, "s.toml").unwrap_err().to_string();
        let line = bad
            .lines()
            .position(|l| l.contains("radius_m = -0.2"))
            .unwrap()
            + 1;
        assert!(err.starts_with(&format!("s.toml:{line}:")), "{err}");
        assert!(err.contains("[[obstacle]] #"), "{err}");

        let bad = text.replacen("dt_s = ", "dt_s = 5.0 #", 1);
        let err = Scenario::from_toml(&bad, "s.toml").unwrap_err().to_string();
        assert!(err.contains("[planner] dt_s = 5"), "{err}");

        let missing = text.replacen("depth_m = ", "# depth_m = ", 1);
        let err = Scenario::from_toml(&missing, "s.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("s.toml:") && err.contains("depth_m"), "{err}");

        let unknown = text.replacen("[soil]", "[soil]\nhardness = 3", 1);
        let err = Scenario::from_toml(&unknown, "s.toml")
            .unwrap_err()
            .to_string();
        assert!(err.contains("hardness"), "{err}");
    }
}
