//! Physical constants every model shares, defined once.

/// Gravitational acceleration (m/s²): 9.81, the value the rope-shovel and
/// hydraulic-excavator papers compute with (not the standard 9.80665), so
/// the dynamics, the dig planners' forces and the shift's energy all use
/// the same number.
pub const G: f64 = 9.81;
