//! Fuzzes the PLY reader through `read_from_bytes`, the same code path as
//! `read`: any input must give Ok or an error, never a panic, a hang or a
//! huge allocation (run with -malloc_limit_mb, see fuzz/README.md).
#![no_main]

use autoshovel_point_cloud::io::{read_from_bytes, Format};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(report) = read_from_bytes(Format::Ply, data) {
        assert_eq!(
            report
                .cloud
                .points
                .iter()
                .filter(|p| p.iter().any(|v| !v.is_finite()))
                .count(),
            0
        );
    }
});
