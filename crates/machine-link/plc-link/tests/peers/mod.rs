//! The peers the link's tests run against, nobody here wrote: python
//! asyncua (PyPI) and node-opcua (npm). `.ci/run` installs both and sets
//! `AUTOSHOVEL_PYTHON` and `AUTOSHOVEL_NODE_MODULES`; with those set, or
//! under CI, a missing peer fails the test. Elsewhere the tests that need
//! one are skipped, saying so.

#![allow(dead_code)] // each test file uses what it needs

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The script `name` under `tests/interop`.
pub fn script(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/interop")
        .join(name)
}

/// A python with asyncua, or None (skipped, said).
pub fn python() -> Option<String> {
    let set = std::env::var("AUTOSHOVEL_PYTHON").ok();
    let py = set.clone().unwrap_or_else(|| "python3".into());
    let ok = Command::new(&py)
        .args(["-c", "import asyncua"])
        .stderr(Stdio::null())
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    match (ok, set) {
        (true, _) => Some(py),
        (false, Some(p)) => panic!("AUTOSHOVEL_PYTHON={p} cannot import asyncua"),
        (false, None) if std::env::var_os("CI").is_some() => {
            panic!("CI: python3 has no asyncua; CI installs the peers (.ci/run sets AUTOSHOVEL_PYTHON)")
        }
        (false, None) => {
            eprintln!(
                "SKIPPED: python3 has no asyncua (pip install asyncua, or run .ci/run, which sets AUTOSHOVEL_PYTHON)"
            );
            None
        }
    }
}

/// node and the node_modules holding node-opcua, or None (skipped, said).
pub fn node() -> Option<(String, PathBuf)> {
    let set = std::env::var_os("AUTOSHOVEL_NODE_MODULES").map(PathBuf::from);
    let modules = set.clone().unwrap_or_else(|| script("node/node_modules"));
    let ok = modules.join("node-opcua").is_dir()
        && Command::new("node")
            .arg("--version")
            .stdout(Stdio::null())
            .status()
            .map(|s| s.success())
            .unwrap_or(false);
    match (ok, set) {
        (true, _) => Some(("node".into(), modules)),
        (false, Some(m)) => panic!(
            "AUTOSHOVEL_NODE_MODULES={} has no node-opcua, or node is missing",
            m.display()
        ),
        (false, None) if std::env::var_os("CI").is_some() => {
            panic!("CI: no node-opcua; .ci/run installs it and sets AUTOSHOVEL_NODE_MODULES")
        }
        (false, None) => {
            eprintln!(
                "SKIPPED: no node-opcua (npm ci in crates/machine-link/plc-link/tests/interop/node, or run .ci/run)"
            );
            None
        }
    }
}
