//! Fuzzes the LAS/LAZ reader through `read_from_bytes`, the same code path
//! as `read`: any input must give Ok or an error, never a panic, a hang or
//! a huge allocation (run with -malloc_limit_mb, see fuzz/README.md).
//!
//! The reader runs the `las`/`laz` crates under `catch_unwind`, because
//! `laz` panics on some malformed streams. libFuzzer's panic hook aborts
//! before unwinding, which would report those handled panics as crashes:
//! this target keeps that hook for every panic except those raised inside
//! `las` or `laz` (which unwind into the reader's `catch_unwind`). A panic
//! anywhere else still aborts, and one from `las`/`laz` that escapes the
//! reader is still caught by the harness and aborts.
#![no_main]

use std::sync::Once;

use autoshovel_point_cloud::io::{read_from_bytes, Format};
use libfuzzer_sys::fuzz_target;

static HOOK: Once = Once::new();

fn install_hook() {
    HOOK.call_once(|| {
        let abort_hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let file = info.location().map(|l| l.file()).unwrap_or("");
            // `/vendor/laz/` is our patched copy of `laz` (see ../vendor/README.md)
            let in_las_or_laz = ["/laz-", "/las-", "/vendor/laz/"]
                .iter()
                .any(|crate_dir| file.contains(crate_dir));
            if !in_las_or_laz {
                abort_hook(info);
            }
        }));
    });
}

fuzz_target!(|data: &[u8]| {
    install_hook();
    if let Ok(report) = read_from_bytes(Format::Las, data) {
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
