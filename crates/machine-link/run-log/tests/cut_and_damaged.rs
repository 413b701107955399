//! A run log is evidence: a writer killed mid-run leaves a log that replays
//! up to its last control period and says it was cut; a log with any byte
//! changed is refused, or (where the byte carried nothing replay uses)
//! replays to the same figures, never to different ones.

use std::path::Path;

use autoshovel_core::{Direction, Vec2};
use autoshovel_run_log::{replay_mcap, topic, EventMsg, LegMsg, PathMsg, PoseMsg, RunLog, TickMsg};
use autoshovel_walk_tracker::RefLeg;

/// Ticks in the test log.
const TICKS: usize = 60;

fn tick(i: usize) -> TickMsg {
    let t = i as f64 * 0.1;
    // Along y = 0.02 sin t: deviations that change with every tick.
    let p = PoseMsg {
        x: t * 0.5,
        y: 0.02 * t.sin(),
        theta: 0.0,
    };
    TickMsg {
        t_s: t,
        leg: 0,
        measured: p,
        truth: Some(p),
        travelled_m: t * 0.5,
        d_m: p.y,
        d0_m: p.y,
        speed_ref_mps: 0.5,
        steer_rpm: 0.0,
        left_rpm: 100.0,
        right_rpm: 100.0,
    }
}

/// Writes the log, one control period (a tick) per sync; `at(i, path)` is
/// called after tick `i` is durable, the writer still open.
fn write_log(path: &Path, mut at: impl FnMut(usize, &Path)) {
    let mut log = RunLog::create(path, &[("job", "test".into())], false).unwrap();
    let leg = RefLeg::new(
        Direction::Forward,
        vec![Vec2::new(0.0, 0.0), Vec2::new(30.0, 0.0)],
        None,
    )
    .unwrap();
    log.write(
        topic::PATH,
        0.0,
        &PathMsg {
            legs: vec![LegMsg::of(&leg)],
        },
    )
    .unwrap();
    for i in 0..TICKS {
        let t = tick(i);
        log.write(topic::TICK, t.t_s, &t).unwrap();
        log.sync().unwrap();
        at(i, path);
    }
    let t = log.last_t_s();
    log.write(
        topic::EVENT,
        t,
        &EventMsg {
            t_s: t,
            source: "link".into(),
            kind: "end".into(),
            message: "the test ended it".into(),
        },
    )
    .unwrap();
    log.finish().unwrap();
}

#[test]
fn a_killed_writer_leaves_a_log_that_replays_to_its_last_period() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let cut = dir.path().join("cut.mcap");
    // The bytes on disk after tick 29: what a SIGKILL then would leave.
    write_log(&path, |i, p| {
        if i == 29 {
            std::fs::copy(p, &cut).unwrap();
        }
    });
    let r = replay_mcap(&cut).unwrap();
    assert!(r.cut.is_some(), "a cut log says so");
    assert_eq!(
        r.run.samples.len(),
        30,
        "every tick made durable before the cut"
    );
    assert_eq!(
        r.ended, None,
        "no end event: the writer never got to say why"
    );
    let whole = replay_mcap(&path).unwrap();
    assert_eq!(whole.cut, None);
    assert_eq!(whole.run.samples.len(), TICKS);
    assert_eq!(whole.ended.as_deref(), Some("the test ended it"));
    // The cut log's samples are the whole log's first 30, bit for bit.
    for (a, b) in r.run.samples.iter().zip(&whole.run.samples) {
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
    // A log cut before its first message holds nothing: refused, named.
    let header_only = dir.path().join("empty.mcap");
    std::fs::write(&header_only, &std::fs::read(&path).unwrap()[..40]).unwrap();
    let e = replay_mcap(&header_only).expect_err("refused");
    assert!(e.to_string().contains("empty.mcap"), "{e}");
}

#[test]
fn every_changed_byte_is_refused_or_changes_nothing_replay_uses() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    write_log(&path, |_, _| {});
    let good = std::fs::read(&path).unwrap();
    let want = replay_mcap(&path).unwrap();
    let flipped = dir.path().join("flipped.mcap");
    let (mut refused, mut same) = (0usize, 0usize);
    for at in 0..good.len() {
        let mut bytes = good.clone();
        bytes[at] ^= 0x01;
        std::fs::write(&flipped, &bytes).unwrap();
        match replay_mcap(&flipped) {
            Err(_) => refused += 1,
            Ok(r) => {
                assert_eq!(
                    (r.run.metrics, r.run.samples.len()),
                    (want.run.metrics, want.run.samples.len()),
                    "byte {at} of {}: a changed log replayed to other figures",
                    good.len()
                );
                same += 1;
            }
        }
    }
    eprintln!(
        "{} bytes: {refused} flips refused, {same} replayed to the same figures",
        good.len()
    );
    // The messages' own bytes are under chunk CRCs: most flips are refused.
    assert!(
        refused * 10 >= good.len() * 9,
        "{refused} of {}",
        good.len()
    );
}
