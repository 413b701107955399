//! Round trips on loopback OPC UA (Basic256Sha256 SignAndEncrypt, the
//! operator's session): the workstation's state read (one Read of the 18
//! nodes it needs) and its setpoint write (one Write of both setpoints),
//! N times each (default 2000; `ROUNDTRIPS` sets it), printed as p50 / p99 /
//! max. With `PEER=python` (and `AUTOSHOVEL_PYTHON` a python with asyncua)
//! it then runs the peer, `crates/machine-link/plc-link/peer/asyncua_roundtrip.py`, against
//! the same server in the same run. BENCHMARKS.md keeps the figures;
//! `cargo bench -p autoshovel-plc-link` measures the same calls with criterion.

use std::time::{Duration, Instant};

use autoshovel_plc_link::drive::Quantiles;
use autoshovel_plc_link::{
    pki, Clock, Link, LinkParams, PlcParams, PlcServer, ServeParams, HEARTBEAT_TIMEOUT,
};
use autoshovel_walk_tracker::scenario::resolve;
use autoshovel_walk_tracker::TrackCommand;

fn main() {
    let n: usize = std::env::var("ROUNDTRIPS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2000);
    let dir = std::env::temp_dir().join(format!("autoshovel-roundtrip-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    pki::init(&dir, &[]).expect("pki");
    let pw = pki::read_password(&dir.join(pki::PASSWORD_FILE)).expect("password");
    let sc = resolve("straight", None, 1).expect("built-in");
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("runtime");
    let (read, write, peer) = rt.block_on(async {
        let server = PlcServer::start(
            PlcParams {
                setup: sc.setup.clone(),
                clock: Clock::Scaled(1.0),
                heartbeat_timeout: HEARTBEAT_TIMEOUT,
                auto: false,
                schedule: Vec::new(),
            },
            ServeParams {
                host: "127.0.0.1".into(),
                port: 0,
                pki: dir.clone(),
                insecure: false,
                users: vec![(pki::OPERATOR.into(), pw.clone())],
            },
        )
        .await
        .expect("plc-sim");
        let mut p = LinkParams::new(
            &server.endpoint(),
            dir.clone(),
            Some((pki::OPERATOR.into(), pw.clone())),
        );
        p.connect_timeout = Duration::from_secs(20);
        let link = Link::open(&p).await.expect("session");
        link.claim().await.expect("control");
        let beat = link.keep_heartbeat();
        let mut read = Vec::with_capacity(n);
        let mut write = Vec::with_capacity(n);
        for i in 0..n {
            let t = Instant::now();
            link.read_state().await.expect("read");
            read.push(t.elapsed().as_secs_f64() * 1e3);
            let cmd = TrackCommand {
                left_rpm: (i % 100) as f64,
                right_rpm: 0.0,
            };
            let t = Instant::now();
            link.write_setpoints(cmd, None).await.expect("write");
            write.push(t.elapsed().as_secs_f64() * 1e3);
        }
        beat.abort();
        let _ = link.release().await;
        link.close().await;
        let mut peer = String::new();
        if std::env::var("PEER").as_deref() == Ok("python") {
            let py = std::env::var("AUTOSHOVEL_PYTHON").unwrap_or_else(|_| "python3".into());
            let script =
                std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("peer/asyncua_roundtrip.py");
            let (endpoint, dir, pw, n) = (server.endpoint(), dir.clone(), pw.clone(), n);
            let out = tokio::task::spawn_blocking(move || {
                std::process::Command::new(py)
                    .arg(script)
                    .arg(endpoint)
                    .arg(dir)
                    .arg(pw)
                    .arg(n.to_string())
                    .output()
                    .expect("the peer runs")
            })
            .await
            .expect("peer task");
            peer = String::from_utf8_lossy(&out.stdout).into_owned();
            eprint!("{}", String::from_utf8_lossy(&out.stderr));
        }
        server.stop().await;
        (Quantiles::of(&read), Quantiles::of(&write), peer)
    });
    let _ = std::fs::remove_dir_all(&dir);
    println!("loopback OPC UA, Basic256Sha256 SignAndEncrypt, {n} round trips each");
    println!("| call | p50 [ms] | p99 [ms] | max [ms] |\n|---|---|---|---|");
    for (name, q) in [
        ("state read (18 nodes)", read),
        ("setpoint write (2 nodes)", write),
    ] {
        println!("| {name} | {:.3} | {:.3} | {:.3} |", q.p50, q.p99, q.max);
        assert_eq!(q.n, n);
        // A 10 Hz control loop needs both well inside its 100 ms period.
        assert!(q.p50 < 50.0, "{name}: p50 {:.1} ms", q.p50);
    }
    print!("{peer}");
}
