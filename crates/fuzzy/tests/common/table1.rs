//! Test / example fixture: the crawler trajectory-tracking fuzzy controller
//! of the electric-shovel paper's §4.3 — inputs e [m] ∈ [−0.45, 0.45] and
//! ec ∈ [−30, 30], output u [rpm] ∈ [−2700, 2700], seven evenly spaced
//! triangular terms each, Table 1 (rows ec, columns e). Mamdani inference
//! (Mamdani & Assilian 1975). The tracking crate owns the real controller;
//! this copy only exercises the generic machinery (shared with the example
//! and the bench through `#[path]`).
#![allow(dead_code)]

use autoshovel_fuzzy::{MamdaniSystem, RuleBase, Variable, DEFAULT_RESOLUTION};

/// Term names, NB … PB.
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

/// Universe of e [m].
pub const E_MAX: f64 = 0.45;
/// Universe of ec.
pub const EC_MAX: f64 = 30.0;
/// Universe of u [rpm].
pub const U_MAX: f64 = 2700.0;

/// The Table-1 system at the default output resolution (201 samples).
pub fn system() -> MamdaniSystem {
    system_with_resolution(DEFAULT_RESOLUTION)
}

/// The Table-1 system with `resolution` output samples.
pub fn system_with_resolution(resolution: usize) -> MamdaniSystem {
    let e = Variable::evenly_spaced_triangles("e", -E_MAX, E_MAX, &TERMS).expect("e");
    let ec = Variable::evenly_spaced_triangles("ec", -EC_MAX, EC_MAX, &TERMS).expect("ec");
    let u = Variable::evenly_spaced_triangles("u", -U_MAX, U_MAX, &TERMS).expect("u");
    let rows: Vec<&[&str]> = TABLE1.iter().map(|r| &r[..]).collect();
    let rules = RuleBase::from_table(&e, &ec, &u, &rows).expect("table");
    MamdaniSystem::with_resolution(vec![e, ec], u, rules, resolution).expect("system")
}
