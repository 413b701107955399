//! The crate's error: loading a scenario and the faults a shift cannot
//! recover from. Faults it can recover from (a scan without a face, a dig
//! the planner cannot make feasible, a stand that cannot be reached, a
//! walk that stalls) are not errors: they are events of the run's
//! timeline ([`crate::Event`]).

/// Everything that can stop a shift before it starts.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShiftError {
    /// A scenario file could not be read, parsed or checked (names the
    /// file, line and key).
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
    /// The dig planner's machine profile is not usable at this scale.
    #[error("machine profile: {0}")]
    Profile(#[from] autoshovel_rope_shovel_dig::DigError),
    /// The machine stands where it cannot: inside the pile or a heap, or
    /// off the world.
    #[error("the machine cannot start at ({x_m:.1}, {y_m:.1}) m: {why}")]
    BadStart {
        /// Swing axis x (m).
        x_m: f64,
        /// Swing axis y (m).
        y_m: f64,
        /// Why.
        why: String,
    },
    /// A run setting out of range (names it).
    #[error("{name} = {value} is out of range: expected {expected}")]
    BadSetting {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: String,
        /// What it may be.
        expected: &'static str,
    },
}

/// The crate's result.
pub type Result<T, E = ShiftError> = std::result::Result<T, E>;
