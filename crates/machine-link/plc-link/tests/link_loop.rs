//! The closed loop over loopback OPC UA (SignAndEncrypt, the operator's
//! identity) against the same loop in one process, and the safety of the
//! link: cuts at random times stop the machine within 300 ms and it stays
//! stopped until acknowledged; a frozen or dropped RTK zeroes the
//! setpoints once the pose is older than 300 ms.
//!
//! The lockstep tests run in `cargo test`: their results do not depend on
//! the machine's load. The real-time ones assert wall-clock margins, so
//! they are `#[ignore]`d there and run alone, one at a time, in
//! `.ci/run`'s serial step, where nothing else competes for the cores;
//! their latencies are stamped by the PLC's own loop (`Plc::stops`,
//! `Plc::zeroed_at`). `LINK_CUTS` and `STALE_POSES` set how many (default
//! 40 and 16; docs/machine-link.md gives longer runs' figures).

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use autoshovel_plc_link::{
    drive, pki, Clock, DriveOptions, FaultKind, Link, LinkParams, PlcServer, RunLog,
};
use autoshovel_walk_tracker::scenario::resolve;

mod peers;
use autoshovel_walk_tracker::sim::{simulate, Run};
use autoshovel_walk_tracker::{ControllerKind, Noise, Setup};
use peers::rt;
use rand::{Rng, SeedableRng};

async fn start(
    setup: &Setup,
    clock: Clock,
    schedule: Vec<(f64, FaultKind)>,
) -> (PlcServer, LinkParams) {
    let server = peers::plc_sim(setup, clock, schedule, 0).await;
    let params = peers::operator(&server.endpoint());
    (server, params)
}

/// Held by each test on the PLC's real-time clock, so that they run one
/// at a time: the harness runs a binary's tests in parallel, and two
/// real-time loops on a 2-core machine delay each other's cycles (a
/// stale-pose zeroing was seen 1 ms late with the link-cut test beside it).
fn real_time() -> std::sync::MutexGuard<'static, ()> {
    static ONE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    ONE.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// A person at the machine, acknowledging (as `plc-ack` would, from its own session).
fn person() -> autoshovel_plc_link::Caller {
    autoshovel_plc_link::Caller {
        session: u32::MAX,
        user: Some(pki::OPERATOR.into()),
        client: "the test, at the machine".into(),
    }
}

fn over_link(setup: &Setup, clock: Clock) -> Run {
    over_link_logged(setup, clock, None)
}

fn over_link_logged(setup: &Setup, clock: Clock, log: Option<&mut RunLog>) -> Run {
    rt().block_on(async {
        let (server, params) = start(setup, clock, Vec::new()).await;
        let link = Link::open(&params).await.unwrap();
        let mut ctl = ControllerKind::Fuzzy.build(&Default::default());
        let opts = DriveOptions::new(setup, &params);
        let r = drive(&link, setup, ctl.as_mut(), &opts, log).await.unwrap();
        link.close().await;
        server.stop().await;
        assert!(r.truth, "plc-sim offers the simulator's truth");
        r.run
    })
}

#[test]
fn lockstep_drive_reproduces_the_in_process_run() {
    for (name, noise) in [
        ("fig9a", Noise::Off),
        ("straight", Noise::Rtk),
        ("curve", Noise::Rtk),
        ("v-shape", Noise::Rtk),
    ] {
        let sc = resolve(name, Some(noise), 7).unwrap();
        let local = simulate(
            &sc.setup,
            ControllerKind::Fuzzy.build(&sc.controllers).as_mut(),
        );
        let link = over_link(&sc.setup, Clock::Lockstep);
        let (a, b) = (&local.metrics, &link.metrics);
        assert!(a.completed && b.completed, "{name}");
        // Only the RTK heading's trip through degrees and the DateTime's
        // 100 ns ticks differ: the same decisions, to rounding.
        assert!(
            (a.max_centroid_dev_m - b.max_centroid_dev_m).abs() < 1e-6,
            "{name}: {a:?} vs {b:?}"
        );
        assert!(
            (a.mean_centroid_dev_m - b.mean_centroid_dev_m).abs() < 1e-6,
            "{name}"
        );
        assert!(
            (a.final_position_error_m - b.final_position_error_m).abs() < 1e-6,
            "{name}"
        );
        let kinds = |r: &Run| r.events.iter().map(|e| e.kind).collect::<Vec<_>>();
        assert_eq!(kinds(&local), kinds(&link), "{name}: same events");
        assert_eq!(
            local.samples.len(),
            link.samples.len(),
            "{name}: same ticks"
        );
    }
}

#[test]
fn replay_of_the_drive_log_gives_the_drive_metrics() {
    let sc = resolve("v-shape", Some(Noise::Rtk), 5).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("drive.mcap");
    let mut log = RunLog::create(&path, &[("scenario", "v-shape".into())], false).unwrap();
    let run = over_link_logged(&sc.setup, Clock::Lockstep, Some(&mut log));
    log.finish().unwrap();
    let r = autoshovel_run_log::replay_mcap(&path).unwrap();
    assert_eq!(r.measured_on, "simulator truth");
    assert_eq!(r.run.samples.len(), run.samples.len());
    let (a, b) = (&run.metrics, &r.run.metrics);
    // JSON carries every f64 to the last bit.
    assert_eq!(a, b);
    // An existing log is never overwritten.
    assert!(RunLog::create(&path, &[], false).is_err());
}

#[test]
#[ignore = "real time: a wall-clock margin, run alone by .ci/run's serial step (cargo test --workspace --test link_loop -- --ignored --test-threads=1)"]
fn real_time_drive_stays_within_a_centimetre_of_the_in_process_run() {
    let _one_at_a_time = real_time();
    let sc = resolve("straight", Some(Noise::Rtk), 3).unwrap();
    let local = simulate(
        &sc.setup,
        ControllerKind::Fuzzy.build(&sc.controllers).as_mut(),
    );
    let link = over_link(&sc.setup, Clock::Scaled(4.0));
    let (a, b) = (&local.metrics, &link.metrics);
    assert!(b.completed, "{b:?}");
    assert!(
        (a.max_centroid_dev_m - b.max_centroid_dev_m).abs() < 0.01,
        "{a:?} vs {b:?}"
    );
    assert!(
        (a.mean_centroid_dev_m - b.mean_centroid_dev_m).abs() < 0.01,
        "{a:?} vs {b:?}"
    );
    assert!(
        link.events.iter().all(|e| !e.is_safety()),
        "{:?}",
        link.events
    );
}

fn count(var: &str, default: usize) -> usize {
    std::env::var(var)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A straight leg far longer than the test needs.
fn long_straight() -> Setup {
    let mut sc = resolve("straight", Some(Noise::Rtk), 11).unwrap();
    let leg = &sc.setup.legs[0];
    let a = leg.points[0];
    let dir = (leg.points[leg.points.len() - 1] - a).normalize();
    sc.setup.legs =
        vec![
            autoshovel_walk_tracker::RefLeg::new(leg.direction, vec![a, a + dir * 5000.0], None)
                .unwrap(),
        ];
    sc.setup
}

fn quantile(xs: &mut [f64], q: f64) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[((q * (xs.len() - 1) as f64).round() as usize).min(xs.len() - 1)]
}

#[test]
#[ignore = "real time: a wall-clock margin, run alone by .ci/run's serial step (cargo test --workspace --test link_loop -- --ignored --test-threads=1)"]
fn link_cuts_stop_the_machine_within_300_ms_and_it_stays_stopped_until_acknowledged() {
    let _one_at_a_time = real_time();
    let n = count("LINK_CUTS", 40);
    let setup = long_straight();
    let latencies = rt().block_on(async {
        let (server, params) = start(&setup, Clock::Scaled(1.0), Vec::new()).await;
        let link = Link::open(&params).await.unwrap();
        let mut ctl = ControllerKind::Fuzzy.build(&Default::default());
        let stop = Arc::new(AtomicBool::new(false));
        let opts = DriveOptions {
            t_limit_s: 1e9,
            ack_timeout: Duration::from_secs(30),
            link_timeout: Duration::from_secs(30),
            stop: stop.clone(),
        };
        let driving = drive(&link, &setup, ctl.as_mut(), &opts, None);
        let plc = server.plc.clone();
        let cutter = async {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2026);
            let mut lat = Vec::with_capacity(n);
            for i in 0..n {
                // Wait until the machine moves again, then cut at a random moment.
                loop {
                    let moving = {
                        let p = plc.lock().unwrap();
                        let (l, r) = p.machine.motors_rpm();
                        p.fault.is_none() && l.abs().max(r.abs()) > 50.0
                    };
                    if moving {
                        break;
                    }
                    tokio::time::sleep(Duration::from_millis(5)).await;
                }
                tokio::time::sleep(Duration::from_millis(rng.gen_range(0..300))).await;
                let stops_before = plc.lock().unwrap().stops.len();
                let cut_at = server.wall_s();
                server.cut(Duration::from_millis(rng.gen_range(350..700)));
                // The PLC latches within its watchdog.
                let latched = loop {
                    {
                        let p = plc.lock().unwrap();
                        if p.stops.len() > stops_before {
                            break p.stops[stops_before];
                        }
                    }
                    assert!(server.wall_s() - cut_at < 2.0, "cut {i}: no stop in 2 s");
                    tokio::time::sleep(Duration::from_millis(1)).await;
                };
                lat.push(latched - cut_at);
                // After the cut the link comes back; the machine stays
                // stopped (no self-restart) until the acknowledgement.
                tokio::time::sleep(Duration::from_millis(800)).await;
                {
                    let p = plc.lock().unwrap();
                    assert!(p.fault.is_some(), "cut {i}: fault still latched");
                    assert!(p.machine.at_rest(), "cut {i}: at rest");
                    assert!(
                        !p.moved_while_faulted(),
                        "cut {i}: never sped up while faulted"
                    );
                }
                plc.lock().unwrap().acknowledge(&person()).unwrap();
            }
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
            lat
        };
        let (r, lat) = tokio::join!(driving, cutter);
        assert!(
            matches!(r, Err(autoshovel_plc_link::LinkError::Interrupted { .. })),
            "{r:?}"
        );
        link.close().await;
        server.stop().await;
        lat
    });
    let mut l = latencies.clone();
    let (p50, p99, max) = (
        quantile(&mut l, 0.5),
        quantile(&mut l, 0.99),
        quantile(&mut l, 1.0),
    );
    eprintln!(
        "link cuts: {n}, stop latency p50 {:.0} ms, p99 {:.0} ms, max {:.0} ms",
        p50 * 1e3,
        p99 * 1e3,
        max * 1e3
    );
    assert!(
        max <= 0.300,
        "every stop within 300 ms of the cut: max {:.0} ms",
        max * 1e3
    );
}

#[test]
#[ignore = "real time: a wall-clock margin, run alone by .ci/run's serial step (cargo test --workspace --test link_loop -- --ignored --test-threads=1)"]
fn a_frozen_or_dropped_rtk_zeroes_the_setpoints_once_the_pose_is_300_ms_old() {
    let _one_at_a_time = real_time();
    let n = count("STALE_POSES", 16);
    let setup = long_straight();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(99);
    // Alternate freezes and dropouts, each 0.6 s, 2–3 s of machine time apart.
    let mut t = 3.0;
    let mut schedule = Vec::new();
    for i in 0..n {
        t += rng.gen_range(2.0..3.0);
        let f = if i % 2 == 0 {
            FaultKind::RtkFreeze { duration_s: 0.6 }
        } else {
            FaultKind::RtkDropout { duration_s: 0.6 }
        };
        schedule.push((t, f));
    }
    let end = t + 2.0;
    let ages = rt().block_on(async {
        let (server, params) = start(&setup, Clock::Scaled(1.0), schedule.clone()).await;
        let link = Link::open(&params).await.unwrap();
        let mut ctl = ControllerKind::Fuzzy.build(&Default::default());
        let stop = Arc::new(AtomicBool::new(false));
        let opts = DriveOptions {
            t_limit_s: 1e9,
            ack_timeout: Duration::from_secs(30),
            link_timeout: Duration::from_secs(30),
            stop: stop.clone(),
        };
        let driving = drive(&link, &setup, ctl.as_mut(), &opts, None);
        let plc = server.plc.clone();
        let watcher = async {
            loop {
                tokio::time::sleep(Duration::from_millis(50)).await;
                if plc.lock().unwrap().machine.time_s() > end {
                    break;
                }
            }
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
        };
        let (r, ()) = tokio::join!(driving, watcher);
        assert!(
            matches!(r, Err(autoshovel_plc_link::LinkError::Interrupted { .. })),
            "{r:?}"
        );
        // The PLC never had to step in: the one fault is the drive's own
        // release of control at the end.
        let (stops, fault) = {
            let p = plc.lock().unwrap();
            (p.stops.len(), p.fault.clone())
        };
        assert_eq!(
            (stops, fault.as_ref().map(|f| f.0)),
            (
                1,
                Some(autoshovel_plc_link::model::fault_code::CONTROL_ENDED)
            ),
            "{fault:?}"
        );
        link.close().await;
        server.stop().await;
        let p = plc.lock().unwrap();
        // For each fault: the last good fix (at or before the injection,
        // on the 10 Hz grid) and the first zeroing after it.
        let period = 1.0 / setup.rtk.rate_hz;
        schedule
            .iter()
            .map(|(at, _)| {
                let last_good = (at / period + 1e-9).floor() * period;
                let zero = p
                    .zeroed_at
                    .iter()
                    .copied()
                    .find(|z| *z >= *at - 1e-9)
                    .expect("setpoints zeroed after every fault");
                zero - last_good
            })
            .collect::<Vec<f64>>()
    });
    let mut a = ages.clone();
    let (p50, max) = (quantile(&mut a, 0.5), quantile(&mut a, 1.0));
    eprintln!(
        "stale poses: {n}, pose age when the setpoints went to zero: p50 {:.0} ms, max {:.0} ms",
        p50 * 1e3,
        max * 1e3
    );
    // The workstation stops at 250 ms of age (STALE_MARGIN_S before the
    // 300 ms timeout), so the setpoints are zero before the pose is 300 ms old.
    assert!(
        ages.iter().all(|a| *a > 0.25 - 1e-6),
        "not before 250 ms: {ages:?}"
    );
    assert!(
        max <= 0.3,
        "every zeroing before the pose was 300 ms old: {ages:?}"
    );
}

#[test]
#[ignore = "real time: a wall-clock margin, run alone by .ci/run's serial step (cargo test --workspace --test link_loop -- --ignored --test-threads=1)"]
fn a_delay_fault_holds_the_plcs_replies_back_for_its_length() {
    let _one_at_a_time = real_time();
    let sc = resolve("straight", Some(Noise::Off), 1).unwrap();
    rt().block_on(async {
        let (server, params) = start(&sc.setup, Clock::Scaled(1.0), Vec::new()).await;
        let link = Link::open(&params).await.unwrap();
        async fn time(link: &Link) -> f64 {
            let t = std::time::Instant::now();
            link.read_state().await.unwrap();
            t.elapsed().as_secs_f64()
        }
        let before = time(&link).await;
        server.inject(FaultKind::Delay {
            delay_s: 0.2,
            duration_s: 1.0,
        });
        tokio::time::sleep(Duration::from_millis(20)).await;
        let during = time(&link).await;
        tokio::time::sleep(Duration::from_millis(1500)).await;
        let after = time(&link).await;
        assert!(during >= 0.2, "held back: {during} s");
        assert!(before < 0.1 && after < 0.1, "{before} {after}");
        link.close().await;
        server.stop().await;
    });
}
