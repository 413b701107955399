//! The crate's error: scenario loading and the two-level planner. It sits
//! above the modules whose values it names (the kinematics' [`IkError`], the
//! preimage rule's [`AvoidSide`]); a machine profile's errors are
//! [`autoshovel_core::config::ConfigError`]s, wrapped here as `Config`.

use crate::kinematics::IkError;
use crate::preimage::AvoidSide;

/// Everything that can go wrong when loading a profile or a scenario, or planning.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExcavateError {
    /// A profile or scenario file could not be read, parsed or checked
    /// (names the file, line and key).
    #[error(transparent)]
    Config(#[from] autoshovel_core::config::ConfigError),
    /// No built-in scenario has this name.
    #[error("unknown scenario `{name}`: the built-ins are {known}, or give a TOML file")]
    UnknownScenario {
        /// The name asked for.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
    /// The bucket cannot put its tip at the start of the dig.
    #[error("the dig start ({x_m:.3}, {y_m:.3}) m is out of reach at attitude {:.1}°: {cause}; move the start nearer the machine or change the attitude", attitude_rad.to_degrees())]
    StartOutOfReach {
        /// Start x (m).
        x_m: f64,
        /// Start y (m).
        y_m: f64,
        /// Attitude angle asked for (rad).
        attitude_rad: f64,
        /// Why.
        cause: IkError,
    },
    /// A buried obstacle encloses the start of the dig.
    #[error(
        "obstacle {index} (centre ({:.3}, {:.3}) m, radius {radius_m:.3} m) encloses the dig \
         start ({:.3}, {:.3}) m; start the dig elsewhere",
        center_m[0], center_m[1], start_m[0], start_m[1]
    )]
    ObstacleEnclosesStart {
        /// Index of the obstacle in the scenario.
        index: usize,
        /// Its centre (m).
        center_m: [f64; 2],
        /// Its radius (m).
        radius_m: f64,
        /// The start (m).
        start_m: [f64; 2],
    },
    /// The reachable ground cannot hold the volume asked for.
    #[error(
        "the target volume cannot be dug: {what} needs {needed_m3:.3} m³ but the most the \
         reachable ground holds is {reachable_m3:.3} m³ (stopped at x = {stopped_at_x_m:.2} m: \
         {why}); lower the target or the depth, or start farther out"
    )]
    TargetVolumeTooLarge {
        /// Which part of the dig (`first half`, `second half`, `re-plan`).
        what: String,
        /// Volume this part needs (m³).
        needed_m3: f64,
        /// The largest volume a feasible candidate held (m³).
        reachable_m3: f64,
        /// The last candidate x tried (m).
        stopped_at_x_m: f64,
        /// Why the search stopped there.
        why: String,
    },
    /// The planned path cannot be executed by the machine (a level-1 candidate
    /// or the start itself breaks a limit).
    #[error("no feasible {what} from ({:.3}, {:.3}) m: {why}", from_m[0], from_m[1])]
    NoFeasiblePath {
        /// What was being planned.
        what: String,
        /// From where (m).
        from_m: [f64; 2],
        /// Why (the last limit met).
        why: String,
    },
    /// The preimage rule chose a side of an obstacle that the machine cannot pass.
    #[error(
        "cannot pass obstacle {index} {side} (contact at ({:.3}, {:.3}) m): {why}",
        contact_m[0], contact_m[1]
    )]
    ObstacleImpassable {
        /// Index of the obstacle in the scenario.
        index: usize,
        /// The side the preimage rule chose.
        side: AvoidSide,
        /// Where the tip met it (m).
        contact_m: [f64; 2],
        /// The limit that blocks the way (joint, reach, attitude) and where.
        why: String,
    },
    /// The soil resists more than the machine can push.
    #[error(
        "the soil resists with {force_n:.0} N at t = {t_s:.2} s (tip depth {depth_m:.2} m), more \
         than the machine's digging force {max_n:.0} N; dig shallower or in softer soil"
    )]
    SoilTooHard {
        /// When (s).
        t_s: f64,
        /// The resistance (N).
        force_n: f64,
        /// The machine's rating (N).
        max_n: f64,
        /// Tip depth below the ground then (m).
        depth_m: f64,
    },
    /// Defensive: an output path would enter an obstacle envelope. Never returned
    /// as a path; reported as this error instead.
    #[error("internal: the executed path enters obstacle {index} at ({:.3}, {:.3}) m", at_m[0], at_m[1])]
    PathThroughObstacle {
        /// Index of the obstacle.
        index: usize,
        /// Where (m).
        at_m: [f64; 2],
    },
    /// More contacts than the planner allows in one pass (each contact costs a
    /// detour and a re-plan).
    #[error("more than {max} obstacle contacts in one pass; the soil is too stony for one dig")]
    TooManyContacts {
        /// The cap.
        max: usize,
    },
    /// A setting sizes more work than the stated ceiling (found once the
    /// work is known, before it is done).
    #[error("{key} = {value} asks too much: {estimate}; the ceiling is {ceiling}")]
    TooMuchWork {
        /// The setting, as written in the scenario (`[planner] dt_s`).
        key: &'static str,
        /// Its value.
        value: String,
        /// The work it implies.
        estimate: String,
        /// The ceiling, and the value that would meet it.
        ceiling: String,
    },
}

/// Shorthand for results of this crate.
pub type Result<T> = std::result::Result<T, ExcavateError>;
