//! Published rule bases, ready to use.
//!
//! [`shovel_table1`]: the crawler trajectory-tracking controller of the
//! electric-shovel walking paper §4.3 — inputs e (m) ∈ [−0.45, 0.45] (lateral
//! deviation) and ec ∈ [−30, 30] (its rate), output u (rpm) ∈ [−2700, 2700]
//! (track motor speed difference), seven evenly spaced triangles NB … PB on
//! each, and the 7 × 7 rule table of its Table 1 (rows ec, columns e),
//! Mamdani min / max / centroid (Mamdani & Assilian 1975).

/// The electric-shovel tracking controller of §4.3, Table 1.
pub mod shovel_table1 {
    use crate::{FuzzyError, MamdaniSystem, RuleBase, Variable, DEFAULT_RESOLUTION};

    /// Term names, negative big to positive big.
    pub const TERMS: [&str; 7] = ["NB", "NM", "NS", "ZE", "PS", "PM", "PB"];

    /// Table 1: `TABLE1[r][c]` is u for ec = `TERMS[r]`, e = `TERMS[c]`.
    pub const TABLE1: [[&str; 7]; 7] = [
        ["NB", "NB", "NM", "NM", "NS", "NS", "ZE"],
        ["NB", "NM", "NM", "NS", "NS", "ZE", "PS"],
        ["NM", "NM", "NS", "NS", "ZE", "PS", "PS"],
        ["NM", "NS", "NS", "ZE", "PS", "PS", "PM"],
        ["NS", "NS", "ZE", "PS", "PS", "PM", "PM"],
        ["NS", "ZE", "PS", "PS", "PM", "PM", "PB"],
        ["ZE", "PS", "PS", "PM", "PM", "PB", "PB"],
    ];

    /// Universe of e, ±this (m): the fuzzy universe [−σ1, σ1] of [W eq. 24]
    /// (the tracker maps e into it with k1).
    pub const E_MAX: f64 = 0.45;
    /// Universe of ec, ±this: [−σ2, σ2] of [W eq. 24].
    pub const EC_MAX: f64 = 30.0;
    /// Universe of u, ±this (rpm): [−σ3, σ3] of [W eq. 24].
    pub const U_MAX: f64 = 2700.0;

    /// The system (inputs [e, ec], output u) at the default output
    /// resolution, on the fuzzy universes of [W eq. 24].
    pub fn system() -> Result<MamdaniSystem, FuzzyError> {
        system_with_resolution(DEFAULT_RESOLUTION)
    }

    /// The system with `resolution` output samples.
    pub fn system_with_resolution(resolution: usize) -> Result<MamdaniSystem, FuzzyError> {
        // The fuzzy universes [−σ1, σ1], [−σ2, σ2], [−σ3, σ3] [W eq. 24].
        let e = Variable::evenly_spaced_triangles("e", -E_MAX, E_MAX, &TERMS)?;
        let ec = Variable::evenly_spaced_triangles("ec", -EC_MAX, EC_MAX, &TERMS)?;
        let u = Variable::evenly_spaced_triangles("u", -U_MAX, U_MAX, &TERMS)?;
        let rows: Vec<&[&str]> = TABLE1.iter().map(|r| &r[..]).collect();
        // Columns are the first input (e), rows the second (ec).
        let rules = RuleBase::from_table(&e, &ec, &u, &rows)?;
        MamdaniSystem::with_resolution(vec![e, ec], u, rules, resolution)
    }
}
