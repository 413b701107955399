//! Closed-loop behaviour against the paper's figures (SPEC §7) and the
//! safety rules: these run the whole simulator.

use autoshovel_core::{Pose2, Vec2};
use autoshovel_walk_planner::Direction;
use autoshovel_walk_tracker::scenario::{resolve, Noise};
use autoshovel_walk_tracker::*;

fn fuzzy() -> FuzzyTracker {
    FuzzyTracker::new(FuzzyParams::default())
}

#[test]
fn fig9_fuzzy_reaches_the_path_within_5_m_and_settles() {
    // SPEC §7: on the path within 5 m of travel; deviation then → 0.
    for name in ["fig9a", "fig9b"] {
        let s = resolve(name, None, 1).unwrap();
        let m = simulate(&s.setup, &mut fuzzy()).metrics;
        assert!(m.completed, "{name}");
        assert!(
            m.reached_distance_m <= 5.0,
            "{name}: reached after {} m",
            m.reached_distance_m
        );
        assert!(
            m.max_centroid_dev_m <= 0.05,
            "{name}: overshoot {} m after reaching",
            m.max_centroid_dev_m
        );
        assert!(
            m.settled_1cm_distance_m <= 7.0,
            "{name}: within 1 cm for good only after {} m",
            m.settled_1cm_distance_m
        );
        assert!(
            m.final_heading_error_deg.abs() < 1.0 && m.final_position_error_m < 0.05,
            "{name}: {m:?}"
        );
    }
}

#[test]
fn experiment_runs_with_rtk_noise_stay_within_10_cm_on_every_seed() {
    // SPEC §7 (§5.3): ≈ 5 cm typical, ≤ 10 cm max, final heading ≤ 2°. Seeds
    // other than the one the gains were tuned on (1) check it is not luck.
    for name in ["straight", "curve", "v-shape"] {
        for seed in 1..=6 {
            let s = resolve(name, Some(Noise::Rtk), seed).unwrap();
            let m = simulate(&s.setup, &mut fuzzy()).metrics;
            assert!(m.completed, "{name} seed {seed}");
            assert!(
                m.max_centroid_dev_m <= 0.10,
                "{name} seed {seed}: max {}",
                m.max_centroid_dev_m
            );
            assert!(
                m.mean_centroid_dev_m <= 0.05,
                "{name} seed {seed}: mean {}",
                m.mean_centroid_dev_m
            );
            assert!(
                m.final_heading_error_deg.abs() <= 2.0,
                "{name} seed {seed}: heading {}",
                m.final_heading_error_deg
            );
        }
    }
}

#[test]
fn same_seed_same_run() {
    let s = resolve("curve", Some(Noise::Rtk), 9).unwrap();
    let a = simulate(&s.setup, &mut fuzzy());
    let b = simulate(&s.setup, &mut fuzzy());
    assert_eq!(a.samples, b.samples);
    let c = simulate(
        &resolve("curve", Some(Noise::Rtk), 10).unwrap().setup,
        &mut fuzzy(),
    );
    assert_ne!(a.samples, c.samples);
}

#[test]
fn v_shape_stops_at_the_cusp_before_reversing_direction() {
    let s = resolve("v-shape", Some(Noise::Rtk), 1).unwrap();
    let run = simulate(&s.setup, &mut fuzzy());
    assert_eq!(run.events.iter().filter(|e| e.kind == "leg-end").count(), 2);
    // Commanded track speeds never jump from one sign to the other between ticks.
    for w in run.samples.windows(2) {
        let (a, b) = (w[0].command, w[1].command);
        let mean = |c: TrackCommand| 0.5 * (c.left_rpm + c.right_rpm);
        assert!(
            mean(a) * mean(b) >= 0.0 || mean(a) == 0.0 || mean(b) == 0.0,
            "direction flipped without a stop at t = {}",
            w[1].t_s
        );
    }
    // Reverse leg: the machine moved backwards (heading opposite to motion).
    let leg0: Vec<&autoshovel_walk_tracker::sim::Sample> =
        run.samples.iter().filter(|s| s.leg == 0).collect();
    assert!(leg0.iter().any(|s| s.speed_ref_mps < -0.1));
}

#[test]
fn commands_never_exceed_the_motor_limits() {
    for c in [
        &mut fuzzy() as &mut dyn Controller,
        &mut Pid::new(PidParams::default()),
        &mut PurePursuit {
            params: PurePursuitParams::default(),
        },
    ] {
        for name in ["fig9a", "curve"] {
            let s = resolve(name, Some(Noise::Rtk), 3).unwrap();
            let run = simulate(&s.setup, c);
            let lim = s.setup.crawler.motor_max_rpm;
            assert!(run
                .samples
                .iter()
                .all(|x| x.command.left_rpm.abs() <= lim && x.command.right_rpm.abs() <= lim));
        }
    }
}

fn straight_setup(rtk: RtkParams) -> Setup {
    let leg = RefLeg::new(
        Direction::Forward,
        vec![Vec2::new(0.0, 0.0), Vec2::new(40.0, 0.0)],
        None,
    )
    .unwrap();
    Setup {
        legs: vec![leg],
        start: Pose2::new(0.0, 0.0, 0.0),
        crawler: CrawlerParams::default(),
        slip: SlipParams::none(),
        rtk,
        sim: SimParams::default(),
    }
}

#[test]
fn a_stale_pose_stops_both_tracks_and_says_so() {
    // Fixes at 2 Hz: every fix is 500 ms old before the next, over the 300 ms limit.
    let run = simulate(
        &straight_setup(RtkParams {
            rate_hz: 2.0,
            ..RtkParams::ideal()
        }),
        &mut fuzzy(),
    );
    assert!(run.events.iter().any(|e| e.kind == "stale-pose"));
    // Every tick whose fix is too old commands zero.
    let stale: Vec<_> = run
        .samples
        .iter()
        .filter(|s| s.speed_ref_mps == 0.0 && s.command == TrackCommand::STOP)
        .collect();
    assert!(!stale.is_empty());
    // Dropouts: long gaps also stop the machine, and it recovers.
    let run = simulate(
        &straight_setup(RtkParams {
            dropouts_per_min: 20.0,
            dropout_s: 1.0,
            ..RtkParams::ideal()
        }),
        &mut fuzzy(),
    );
    assert!(run.events.iter().any(|e| e.kind == "stale-pose"));
    assert!(run.events.iter().any(|e| e.kind == "pose-recovered"));
    assert!(run.metrics.completed);
}

#[test]
fn a_pose_jump_no_machine_can_make_stops_the_run() {
    // Feed the loop a start pose 30 m off the leg's line but the path 0.5 m long: then
    // corrupt by a huge heading offset? Simplest honest jump: position noise of 5 m.
    let run = simulate(
        &straight_setup(RtkParams {
            position_sigma_m: 5.0,
            ..RtkParams::ideal()
        }),
        &mut fuzzy(),
    );
    assert!(
        run.events.iter().any(|e| e.kind == "pose-jump"),
        "{:?}",
        run.events
    );
    assert!(!run.metrics.completed);
    let last = run.samples.last().unwrap();
    assert!(last.travelled_m < 5.0);
}
