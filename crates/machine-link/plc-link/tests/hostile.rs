//! Everyone else on the network, as regression tests: the hostile and
//! careless cases of docs/machine-link.md's table. A drive in lockstep is
//! the witness: its trajectory is a pure function of the commands the PLC
//! obeyed, so any effect a bystander had shows as a changed bit.
//!
//! `BYSTANDERS` sets how many connections the bystanders of our own make
//! during the drive (default 1000: bare TCP, GetEndpoints, anonymous reads,
//! garbage and an oversized Hello, a second operator's claims and writes);
//! beside them, python asyncua and node-opcua read anonymously, session
//! after session, until the drive ends.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use autoshovel_plc_link::{
    drive, pki, Clock, DriveOptions, Link, LinkError, LinkParams, PlcServer, Policy,
    HEARTBEAT_TIMEOUT,
};
use autoshovel_walk_tracker::scenario::resolve;
use autoshovel_walk_tracker::sim::Run;
use autoshovel_walk_tracker::{ControllerKind, Setup, TrackCommand};
use tokio::io::AsyncWriteExt;

mod peers;
use peers::{operator, pki_root, rt};

async fn start(setup: &Setup, clock: Clock, port: u16) -> PlcServer {
    peers::plc_sim(setup, clock, Vec::new(), port).await
}

fn anonymous(endpoint: &str) -> LinkParams {
    let mut p = operator(endpoint);
    p.user = None;
    p
}

fn count(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// One bystander's visit, by kind `k`: what it got to do.
async fn visit(k: usize, server: &PlcServer, endpoint: &str) -> &'static str {
    let addr = server.addr();
    match k % 6 {
        0 => {
            // A port scanner: connect, close.
            drop(tokio::net::TcpStream::connect(addr).await);
            "tcp"
        }
        1 => {
            // Garbage, then close.
            if let Ok(mut s) = tokio::net::TcpStream::connect(addr).await {
                let _ = s.write_all(&[0x5a; 64]).await;
            }
            "garbage"
        }
        2 => {
            // An OPC UA Hello announcing a 4 GiB message: the server drops it.
            if let Ok(mut s) = tokio::net::TcpStream::connect(addr).await {
                let mut hello = b"HELF".to_vec();
                hello.extend_from_slice(&32u32.to_le_bytes());
                for v in [0u32, u32::MAX, u32::MAX, u32::MAX, u32::MAX] {
                    hello.extend_from_slice(&v.to_le_bytes());
                }
                let _ = s.write_all(&hello).await;
                tokio::time::sleep(Duration::from_millis(5)).await;
            }
            "oversized"
        }
        3 => {
            // Discovery: GetEndpoints over security None, no session.
            let (_, root, _) = pki_root();
            let client = opcua::client::ClientBuilder::new()
                .application_name("bystander")
                .application_uri("urn:bystander")
                .pki_dir(pki::role_dir(root, pki::Role::Workstation))
                .create_sample_keypair(false)
                .session_retry_limit(0)
                .client()
                .unwrap();
            let _ = client.get_server_endpoints_from_url(endpoint).await;
            "discovery"
        }
        4 => {
            // An HMI: an anonymous session that reads, then goes.
            if let Ok(link) = Link::open(&anonymous(endpoint)).await {
                let _ = link.read_state().await;
                let refused = link
                    .write_setpoints(
                        TrackCommand {
                            left_rpm: 3000.0,
                            right_rpm: -3000.0,
                        },
                        None,
                    )
                    .await;
                assert!(refused.is_err(), "an anonymous write must be refused");
                link.close().await;
            }
            "anonymous"
        }
        _ => {
            // A second operator workstation: claims and commands. While
            // the drive holds control both are refused; once it has
            // released control the claim is granted, and given back.
            if let Ok(link) = Link::open(&operator(endpoint)).await {
                match link.claim().await {
                    Err(LinkError::ControlHeld { .. }) => {
                        let w = link
                            .write_setpoints(
                                TrackCommand {
                                    left_rpm: 2000.0,
                                    right_rpm: -2000.0,
                                },
                                Some(1),
                            )
                            .await;
                        assert!(
                            // BadRequiresLock once the drive has just released it.
                            matches!(&w, Err(LinkError::Refused { status, .. })
                                if status.contains("BadLocked") || status.contains("BadRequiresLock")),
                            "{w:?}"
                        );
                    }
                    Ok(()) => link.release().await.unwrap(),
                    Err(e) => panic!("{e}"),
                }
                link.close().await;
            }
            "operator"
        }
    }
}

/// Bystanders visiting at once.
const LANES: usize = 8;

/// The peers' bystanders (python asyncua, node-opcua) reading anonymously
/// at `endpoint` until `stop` exists: each one's name and process.
fn peer_bystanders(
    endpoint: &str,
    stop: &std::path::Path,
) -> Vec<(&'static str, std::process::Child)> {
    let (_, root, _) = pki_root();
    let mut out = Vec::new();
    let piped = |c: &mut std::process::Command| {
        c.stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    if let Some(py) = peers::python() {
        let mut c = std::process::Command::new(py);
        c.arg(peers::script("bystander.py"))
            .arg(endpoint)
            .arg(root)
            .arg("100000")
            .arg(stop);
        out.push(("asyncua", piped(&mut c)));
    }
    if let Some((node, modules)) = peers::node() {
        let mut c = std::process::Command::new(node);
        c.arg(peers::script("node/bystander.js"))
            .arg(endpoint)
            .arg(root)
            .arg("100000")
            .arg(stop)
            .env("NODE_PATH", modules);
        out.push(("node-opcua", piped(&mut c)));
    }
    out
}

/// Visits a peer bystander made (it must have ended well).
fn visits_of(name: &str, child: std::process::Child) -> usize {
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{name}: {}\n{text}",
        String::from_utf8_lossy(&out.stderr)
    );
    text.lines()
        .filter_map(|l| l.trim().trim_start_matches("visits ").parse().ok())
        .next_back()
        .unwrap_or_else(|| panic!("{name} printed no count: {text}"))
}

/// Drives `setup` in lockstep on a fresh `plc-sim`; `bystanders` visits
/// made meanwhile by [`LANES`] concurrent bystanders of ours, and the
/// peers' own until the drive ends. The run, the visits of ours made while
/// the drive ran, the peers' visits, and the PLC's faults and refused writes.
fn lockstep_drive(
    setup: &Setup,
    bystanders: usize,
) -> (Run, usize, Vec<(&'static str, usize)>, usize, u64) {
    rt().block_on(async {
        let server = start(setup, Clock::Lockstep, 0).await;
        let endpoint = server.endpoint();
        let stop_dir = tempfile::tempdir().unwrap();
        let stop_file = stop_dir.path().join("stop");
        let peer_procs = if bystanders > 0 {
            peer_bystanders(&endpoint, &stop_file)
        } else {
            Vec::new()
        };
        let link = Link::open(&operator(&endpoint)).await.unwrap();
        let mut ctl = ControllerKind::Fuzzy.build(&Default::default());
        let mut opts = DriveOptions::new(setup, &operator(&endpoint));
        opts.t_limit_s = 1e9;
        let done = AtomicBool::new(false);
        let visits = AtomicUsize::new(0);
        let during = AtomicUsize::new(0);
        let driving = async {
            let r = drive(&link, setup, ctl.as_mut(), &opts, None).await;
            done.store(true, Ordering::SeqCst);
            r
        };
        let crowd = async {
            let one = |lane: usize| {
                let (server, endpoint, visits, during, done) =
                    (&server, &endpoint, &visits, &during, &done);
                async move {
                    loop {
                        let k = visits.fetch_add(1, Ordering::SeqCst);
                        if k >= bystanders {
                            break;
                        }
                        visit(k * LANES + lane, server, endpoint).await;
                        if !done.load(Ordering::SeqCst) {
                            during.fetch_add(1, Ordering::SeqCst);
                        }
                    }
                }
            };
            tokio::join!(
                one(0),
                one(1),
                one(2),
                one(3),
                one(4),
                one(5),
                one(6),
                one(7)
            );
        };
        let (r, ()) = tokio::join!(driving, crowd);
        std::fs::write(&stop_file, b"").unwrap();
        let peer_visits = tokio::task::spawn_blocking(move || {
            peer_procs
                .into_iter()
                .map(|(name, child)| (name, visits_of(name, child)))
                .collect::<Vec<_>>()
        })
        .await
        .unwrap();
        let run = r.unwrap();
        link.close().await;
        let (faults, refused) = {
            let p = server.plc.lock().unwrap();
            // The drive's own release latches its one fault at the end.
            (p.stops.len(), p.summary("", 0, "").refused_writes)
        };
        server.stop().await;
        (
            run.run,
            during.load(Ordering::SeqCst),
            peer_visits,
            faults,
            refused,
        )
    })
}

/// A path (80 m) long enough for the bystanders to visit during the drive.
fn long_curve() -> Setup {
    resolve("long-v-slip", None, 4).unwrap().setup
}

#[test]
fn bystanders_never_move_or_stop_a_lockstep_drive() {
    let n = count("BYSTANDERS", 1000);
    let setup = long_curve();
    let (quiet, _, _, quiet_faults, _) = lockstep_drive(&setup, 0);
    assert!(quiet.metrics.completed, "{:?}", quiet.metrics);
    let (busy, during, peer_visits, faults, refused) = lockstep_drive(&setup, n);
    eprintln!(
        "bystanders: {during} of {n} visits while the drive ran, peers {peer_visits:?}; {refused} writes refused"
    );
    for (name, visits) in &peer_visits {
        assert!(*visits > 0, "{name} read during the drive");
    }
    assert!(
        during >= n,
        "only {during} of {n} visits came while the drive ran"
    );
    assert_eq!(faults, quiet_faults, "no fault but the drive's own release");
    assert!(
        refused > 0,
        "the second operator's writes reached the PLC and were refused"
    );
    // Bit for bit: every sample, every event.
    assert_eq!(quiet.samples.len(), busy.samples.len());
    for (a, b) in quiet.samples.iter().zip(&busy.samples) {
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
    assert_eq!(format!("{:?}", quiet.events), format!("{:?}", busy.events));
    assert_eq!(quiet.metrics, busy.metrics);
}

#[test]
fn an_acknowledgement_from_another_session_is_not_undone_by_its_close() {
    let setup = long_curve();
    rt().block_on(async {
        let server = start(&setup, Clock::Scaled(1.0), 0).await;
        let endpoint = server.endpoint();
        // A controller that claims, beats, then goes silent: the fault.
        let ws = Link::open(&operator(&endpoint)).await.unwrap();
        ws.claim().await.unwrap();
        let beat = ws.keep_heartbeat();
        tokio::time::sleep(Duration::from_millis(200)).await;
        beat.abort();
        tokio::time::sleep(HEARTBEAT_TIMEOUT * 2).await;
        assert!(server.plc.lock().unwrap().fault.is_some());
        // plc-ack as a person runs it: its own session, acknowledge, close.
        let ack = Link::open(&operator(&endpoint)).await.unwrap();
        ack.acknowledge().await.unwrap();
        ack.close().await;
        tokio::time::sleep(Duration::from_millis(300)).await;
        {
            let p = server.plc.lock().unwrap();
            assert!(p.fault.is_none(), "{:?}", p.fault);
            assert!(
                p.control.holder().is_none(),
                "the silent controller lost control"
            );
        }
        // The old controller's session closing changes nothing either.
        ws.close().await;
        tokio::time::sleep(Duration::from_millis(300)).await;
        assert!(server.plc.lock().unwrap().fault.is_none());
        server.stop().await;
    });
}

#[test]
fn the_controlling_session_closing_stops_the_machine_at_once() {
    let setup = long_curve();
    rt().block_on(async {
        let server = start(&setup, Clock::Scaled(1.0), 0).await;
        let ws = Link::open(&operator(&server.endpoint())).await.unwrap();
        ws.claim().await.unwrap();
        let beat = ws.keep_heartbeat();
        ws.write_setpoints(
            TrackCommand {
                left_rpm: 1000.0,
                right_rpm: 1000.0,
            },
            None,
        )
        .await
        .unwrap();
        tokio::time::sleep(Duration::from_millis(300)).await;
        let stops = server.plc.lock().unwrap().stops.len();
        ws.close().await;
        beat.abort();
        // CloseSession ends control: the PLC's next cycle latches the fault
        // as the session's end (the heartbeat's timeout would name itself).
        while server.plc.lock().unwrap().stops.len() == stops {
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        let (code, text) = server.plc.lock().unwrap().fault.clone().expect("latched");
        assert_eq!(
            code,
            autoshovel_plc_link::model::fault_code::LINK_DROPPED,
            "{text}"
        );
        assert!(text.contains("controlling session"), "{text}");
        server.stop().await;
    });
}

#[test]
fn a_restarted_plc_is_never_driven_by_the_run_that_knew_the_old_one() {
    let setup = long_curve();
    let e = rt().block_on(async {
        let first = start(&setup, Clock::Scaled(1.0), 0).await;
        let port = first.addr().port();
        let params = operator(&first.endpoint());
        let link = Link::open(&params).await.unwrap();
        let old = link.instance.clone();
        let mut ctl = ControllerKind::Fuzzy.build(&Default::default());
        let opts = DriveOptions::new(&setup, &params);
        let restart = async {
            tokio::time::sleep(Duration::from_secs(2)).await;
            first.stop().await;
            // The same port, a new start: its own instance.
            let second = start(&setup, Clock::Scaled(1.0), port).await;
            assert_ne!(second.instance_id(), old);
            second
        };
        let (r, second) = tokio::join!(drive(&link, &setup, ctl.as_mut(), &opts, None), restart);
        let travelled = second.plc.lock().unwrap().truth().1;
        assert_eq!(travelled, 0.0, "the new PLC's machine never moved");
        second.stop().await;
        link.close().await;
        r.expect_err("refused")
    });
    assert!(matches!(e, LinkError::PlcRestarted { .. }), "{e}");
    assert!(e.to_string().contains("restarted"), "{e}");
}

#[test]
fn a_password_never_travels_over_security_none() {
    let mut p = operator("opc.tcp://127.0.0.1:1/");
    p.policy = Policy::None;
    p.insecure = true;
    let e = rt().block_on(Link::open(&p)).err().expect("refused");
    assert!(matches!(e, LinkError::PasswordInClear { .. }), "{e}");
    assert!(e.to_string().contains("in clear"), "{e}");
}

#[test]
fn readers_cannot_take_the_sessions_kept_for_operators() {
    use autoshovel_plc_link::server::{MAX_SESSIONS, OPERATOR_SESSIONS};
    let setup = long_curve();
    rt().block_on(async {
        let server = start(&setup, Clock::Scaled(1.0), 0).await;
        let endpoint = server.endpoint();
        // Readers take every session they may.
        let mut readers = Vec::new();
        for _ in 0..MAX_SESSIONS - OPERATOR_SESSIONS {
            readers.push(Link::open(&anonymous(&endpoint)).await.unwrap());
        }
        // One more reader is refused...
        let mut p = anonymous(&endpoint);
        p.connect_timeout = Duration::from_secs(3);
        assert!(Link::open(&p).await.is_err(), "a reader past the limit");
        // ... and the operator still gets in, claims control and acknowledges.
        let op = Link::open(&operator(&endpoint)).await.unwrap();
        op.claim().await.unwrap();
        op.release().await.unwrap();
        op.acknowledge().await.unwrap();
        op.close().await;
        for r in readers {
            r.close().await;
        }
        server.stop().await;
    });
}
