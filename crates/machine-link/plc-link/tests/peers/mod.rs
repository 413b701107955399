//! What the link's test binaries share: one PKI, the runtime, a `plc-sim`
//! and the operator's parameters; and the peers they run against, nobody
//! here wrote: python asyncua (PyPI) and node-opcua (npm). `.ci/run` installs both and sets
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

/// One PKI (two RSA keys) for a whole test binary: the root and the
/// operator's password.
pub fn pki_root() -> &'static (tempfile::TempDir, PathBuf, String) {
    static PKI: std::sync::OnceLock<(tempfile::TempDir, PathBuf, String)> =
        std::sync::OnceLock::new();
    PKI.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("pki");
        autoshovel_plc_link::pki::init(&root, &[]).unwrap();
        let pw = autoshovel_plc_link::pki::read_password(
            &root.join(autoshovel_plc_link::pki::PASSWORD_FILE),
        )
        .unwrap();
        (dir, root, pw)
    })
}

/// A two-worker runtime, as a 2-core machine runs the link.
pub fn rt() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap()
}

/// A `plc-sim` in auto on `port` (0: any) for `setup`, with the faults of
/// `schedule`, secured with [`pki_root`] and the operator's password.
pub async fn plc_sim(
    setup: &autoshovel_walk_tracker::Setup,
    clock: autoshovel_plc_link::Clock,
    schedule: Vec<(f64, autoshovel_plc_link::FaultKind)>,
    port: u16,
) -> autoshovel_plc_link::PlcServer {
    let (_, root, pw) = pki_root();
    autoshovel_plc_link::PlcServer::start(
        autoshovel_plc_link::PlcParams {
            setup: setup.clone(),
            clock,
            heartbeat_timeout: autoshovel_plc_link::HEARTBEAT_TIMEOUT,
            auto: true,
            schedule,
        },
        autoshovel_plc_link::ServeParams {
            host: "127.0.0.1".into(),
            port,
            pki: root.clone(),
            insecure: false,
            users: vec![(autoshovel_plc_link::pki::OPERATOR.into(), pw.clone())],
        },
    )
    .await
    .unwrap()
}

/// The operator's link parameters for `endpoint` (20 s to connect).
pub fn operator(endpoint: &str) -> autoshovel_plc_link::LinkParams {
    let (_, root, pw) = pki_root();
    let mut p = autoshovel_plc_link::LinkParams::new(
        endpoint,
        root.clone(),
        Some((autoshovel_plc_link::pki::OPERATOR.into(), pw.clone())),
    );
    p.connect_timeout = std::time::Duration::from_secs(20);
    p
}
