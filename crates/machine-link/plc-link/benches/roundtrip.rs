//! Criterion: the workstation's state read and setpoint write over loopback
//! OPC UA (Basic256Sha256 SignAndEncrypt). `cargo run --release -p
//! autoshovel-plc-link --example roundtrip` prints their p50 / p99.

use std::time::Duration;

use autoshovel_plc_link::{
    pki, Clock, Link, LinkParams, PlcParams, PlcServer, ServeParams, HEARTBEAT_TIMEOUT,
};
use autoshovel_walk_tracker::scenario::resolve;
use autoshovel_walk_tracker::TrackCommand;
use criterion::{criterion_group, criterion_main, Criterion};

fn roundtrip(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("autoshovel-bench-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    pki::init(&dir, &[]).unwrap();
    let pw = pki::read_password(&dir.join(pki::PASSWORD_FILE)).unwrap();
    let sc = resolve("straight", None, 1).unwrap();
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap();
    let (server, link) = rt.block_on(async {
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
        .unwrap();
        let mut p = LinkParams::new(
            &server.endpoint(),
            dir.clone(),
            Some((pki::OPERATOR.into(), pw)),
        );
        p.connect_timeout = Duration::from_secs(20);
        let link = Link::open(&p).await.unwrap();
        link.claim().await.unwrap();
        let _beat = link.keep_heartbeat();
        (server, link)
    });
    let mut g = c.benchmark_group("opcua_loopback");
    g.bench_function("state_read", |b| {
        b.iter(|| rt.block_on(link.read_state()).unwrap())
    });
    g.bench_function("setpoint_write", |b| {
        b.iter(|| {
            rt.block_on(link.write_setpoints(
                TrackCommand {
                    left_rpm: 10.0,
                    right_rpm: 0.0,
                },
                None,
            ))
            .unwrap()
        })
    });
    g.finish();
    rt.block_on(async {
        link.close().await;
        server.stop().await;
    });
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, roundtrip);
criterion_main!(benches);
