//! Test / example fixture: the crawler trajectory-tracking fuzzy controller
//! of the electric-shovel paper's §4.3 — inputs e (m) ∈ [−0.45, 0.45] and
//! ec ∈ [−30, 30], output u (rpm) ∈ [−2700, 2700], seven evenly spaced
//! triangular terms each, Table 1 (rows ec, columns e). Mamdani inference
//! (Mamdani & Assilian 1975). The tracking crate owns the real controller;
//! this copy only exercises the generic machinery (shared with the example
//! and the bench through `#[path]`).
#![allow(dead_code)]

use autoshovel_fuzzy::presets::shovel_table1;
use autoshovel_fuzzy::MamdaniSystem;

#[allow(unused_imports)]
pub use shovel_table1::{EC_MAX, E_MAX, TABLE1, TERMS, U_MAX};

/// The Table-1 system at the default output resolution (201 samples).
pub fn system() -> MamdaniSystem {
    shovel_table1::system().expect("Table 1")
}

/// The Table-1 system with `resolution` output samples.
pub fn system_with_resolution(resolution: usize) -> MamdaniSystem {
    shovel_table1::system_with_resolution(resolution).expect("Table 1")
}
