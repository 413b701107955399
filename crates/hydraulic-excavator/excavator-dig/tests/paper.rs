//! The paper's §3 case (start (7, 0), boulder Ø 0.5 m, depth 0.7 m, step
//! 0.05 m, 0.9 m³; the paper got 0.909 m³ passing over and 0.915 m³ passing
//! under) and the two-boulder example file, against the done criteria: the
//! volume within 2 %, the boulder passed on the preimage rule's side without
//! entering its envelope, and no joint moving faster than its limit between
//! two samples.

use std::path::Path;

use autoshovel_excavator_dig::TomlFile as _;
use autoshovel_excavator_dig::{excavate, AvoidSide, Excavation, MachineProfile, Scenario};

/// The share of the target by which the planner's rock volume was wrong:
/// Σ over the boulders met of |its estimate's volume − its real volume|
/// (discs across the bucket width), over the target. The planner cannot know
/// a boulder's size from a touch, so this much volume error is not its own.
fn size_error(ex: &Excavation, width_m: f64) -> f64 {
    let disc = |r: f64| std::f64::consts::PI * r * r * width_m;
    let mut seen = std::collections::BTreeMap::new();
    for c in &ex.contacts {
        seen.insert(c.estimate, c.obstacle);
    }
    seen.iter()
        .map(|(&est, &obs)| {
            (disc(ex.estimates[est].envelope.radius_m) - disc(ex.obstacles[obs].radius_m)).abs()
        })
        .sum::<f64>()
        / ex.target_volume_m3
}

/// Checks shared by every scenario; returns nothing, panics with the reason.
fn assert_done(ex: &Excavation, profile: &MachineProfile) {
    // The volume within 2 % (the paper's result), beyond what the unknown
    // boulder sizes account for.
    let err = ex.volume_error();
    let allowance = 0.02 + size_error(ex, profile.bucket.width_m);
    assert!(
        err.abs() < allowance,
        "{}: volume {} m³, error {err} beyond {allowance}",
        ex.scenario,
        ex.achieved_volume_m3
    );
    // No sample inside any envelope (the contact sample touches its rim).
    for s in &ex.samples {
        for (i, o) in ex.obstacles.iter().enumerate() {
            let d = ((s.tip_m[0] - o.center_m[0]).powi(2) + (s.tip_m[1] - o.center_m[1]).powi(2))
                .sqrt();
            assert!(
                d >= o.radius_m - 1e-9,
                "{}: t {} inside boulder {i}",
                ex.scenario,
                s.t_s
            );
        }
    }
    // Smooth joints: |Δθ| ≤ θ̇_max·Δt between consecutive samples.
    let limits = [
        profile.speed_limits.boom_deg_s.to_radians(),
        profile.speed_limits.stick_deg_s.to_radians(),
        profile.speed_limits.bucket_deg_s.to_radians(),
    ];
    for w in ex.samples.windows(2) {
        let dt = w[1].t_s - w[0].t_s;
        assert!(dt >= 0.0);
        for (i, limit) in limits.iter().enumerate() {
            let step = (w[1].joints_rad[i] - w[0].joints_rad[i]).abs();
            assert!(
                step <= limit * dt + 1e-12,
                "{}: joint {i} jumps {step} rad in {dt} s at t {}",
                ex.scenario,
                w[0].t_s
            );
        }
        // The tip never jumps either (continuous path).
        let dp = ((w[1].tip_m[0] - w[0].tip_m[0]).powi(2)
            + (w[1].tip_m[1] - w[0].tip_m[1]).powi(2))
        .sqrt();
        assert!(dp <= 2.0 * dt + 1e-12, "{}: tip jumps {dp} m", ex.scenario);
    }
    // The dig ends on the ground, at rest.
    let last = ex.samples.last().unwrap();
    assert!(last.tip_m[1].abs() < 1e-9 && last.joint_rates_rad_s.iter().all(|v| v.abs() < 1e-9));
    // Each boulder met is passed on the side chosen: where the executed path
    // crosses the boulder's vertical centre line after the contact, it is
    // above the envelope for over and below it for under.
    for c in &ex.contacts {
        let o = ex.obstacles[c.obstacle];
        let after: Vec<_> = ex.samples.iter().filter(|s| s.t_s > c.t_s).collect();
        let crossing = after
            .windows(2)
            .find(|w| (w[0].tip_m[0] - o.center_m[0]) * (w[1].tip_m[0] - o.center_m[0]) <= 0.0)
            .unwrap_or_else(|| {
                panic!(
                    "{}: the path never passes boulder {}",
                    ex.scenario, c.obstacle
                )
            });
        let y = crossing[0].tip_m[1];
        match c.decision {
            AvoidSide::Over => assert!(y >= o.center_m[1] + o.radius_m, "{}: at {y}", ex.scenario),
            AvoidSide::Under => assert!(y <= o.center_m[1] - o.radius_m, "{}: at {y}", ex.scenario),
        }
        // γ and the decision agree with the rule.
        assert_eq!(c.decision == AvoidSide::Over, c.gamma_deg <= 180.0);
    }
}

fn run(s: &Scenario) -> Excavation {
    let profile = MachineProfile::default();
    let ex = excavate(s, &profile).unwrap_or_else(|e| panic!("{}: {e}", s.name));
    assert_done(&ex, &profile);
    ex
}

#[test]
fn paper_over_passes_over_and_takes_the_volume() {
    for refine in [false, true] {
        let mut s = Scenario::paper_over();
        s.planner.refine_volume = refine;
        let ex = run(&s);
        assert_eq!(ex.contacts.len(), 1);
        assert_eq!(ex.avoid_direction, Some(AvoidSide::Over));
        let c = &ex.contacts[0];
        assert!(
            c.gamma_deg > 90.0 && c.gamma_deg < 180.0,
            "γ {}",
            c.gamma_deg
        );
        // The paper met its boulder near 1.6 s, while the bucket went in.
        assert!((c.t_s - 1.6).abs() < 0.2, "contact at {} s", c.t_s);
        assert_eq!(
            ex.segments[0].kind,
            autoshovel_excavator_dig::segment::SegmentKind::Descent
        );
        assert!(!ex.segments[0].completed);
        // The boulder counts as dug (the paper's rule).
        assert!((ex.obstacle_volume_m3 - std::f64::consts::PI * 0.0625).abs() < 1e-12);
    }
}

#[test]
fn paper_under_passes_under_and_takes_the_volume() {
    for refine in [false, true] {
        let mut s = Scenario::paper_under();
        s.planner.refine_volume = refine;
        let ex = run(&s);
        assert_eq!(ex.contacts.len(), 1);
        assert_eq!(ex.avoid_direction, Some(AvoidSide::Under));
        let c = &ex.contacts[0];
        assert!(
            c.gamma_deg > 180.0 && c.gamma_deg < 270.0,
            "γ {}",
            c.gamma_deg
        );
        // Counted once although it lies inside the dug area.
        assert!((ex.obstacle_volume_m3 - std::f64::consts::PI * 0.0625).abs() < 1e-12);
        assert!(ex.soil_volume_m3 + ex.obstacle_volume_m3 - ex.achieved_volume_m3 < 1e-12);
    }
}

#[test]
fn the_two_boulder_file_meets_both_and_takes_the_volume() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/two-boulders.toml");
    let s = Scenario::load(&path).unwrap();
    let ex = run(&s);
    assert_eq!(ex.contacts.len(), 2, "{:?}", ex.contacts);
    assert_ne!(ex.contacts[0].obstacle, ex.contacts[1].obstacle);
    assert_eq!(ex.detours.len(), 2);
    let sides: Vec<_> = ex.contacts.iter().map(|c| c.decision).collect();
    assert_eq!(sides, [AvoidSide::Over, AvoidSide::Over]);
    // The second is met while lifting out, after the first re-plan.
    assert_eq!(
        ex.segments[ex.segments.len() - 2].kind,
        autoshovel_excavator_dig::segment::SegmentKind::Detour
    );
    // Both counted as dug.
    let both = std::f64::consts::PI * (0.25f64.powi(2) + 0.2f64.powi(2));
    assert!((ex.obstacle_volume_m3 - both).abs() < 1e-12);
    // With the paper's nearest-step rule the same file still meets both.
    let mut paper_rule = s.clone();
    paper_rule.planner.refine_volume = false;
    let ex = run(&paper_rule);
    assert_eq!(ex.contacts.len(), 2);
}

#[test]
fn without_boulders_the_dig_is_the_level_1_plan() {
    let mut s = Scenario::paper_over();
    s.obstacles.clear();
    let ex = run(&s);
    assert!(ex.contacts.is_empty() && ex.avoid_direction.is_none());
    assert_eq!(ex.segments.len(), 2);
    let planned = ex.level1.first_half_m3 + ex.level1.second_half_m3;
    // Executed at dt = 0.01 s against 100 planned trapezoids per half.
    assert!((ex.achieved_volume_m3 - planned).abs() < 1e-3 * planned);
}

#[test]
fn the_summary_holds_the_cli_fields() {
    let ex = run(&Scenario::paper_under());
    let s = ex.summary();
    assert_eq!(s.target_volume_m3, 0.9);
    assert_eq!(s.avoid_direction, Some(AvoidSide::Under));
    assert_eq!(s.contacts.len(), 1);
    assert!(s.plan_time_ms > 0.0);
    assert!(s.max_joint_step_ratio <= 1.0);
}

#[test]
fn a_boulder_met_during_a_detour_starts_a_new_cycle() {
    // A second, smaller boulder lies on the way over the first.
    let mut s = Scenario::paper_over();
    s.planner.refine_volume = true;
    s.obstacles
        .push(autoshovel_excavator_dig::obstacle::Envelope {
            center_m: [6.35, -0.30],
            radius_m: 0.12,
        });
    let ex = run(&s);
    assert_eq!(ex.contacts.len(), 2);
    use autoshovel_excavator_dig::segment::SegmentKind::Detour;
    // The first detour is cut short by the second contact.
    assert_eq!(
        (ex.segments[1].kind, ex.segments[1].completed),
        (Detour, false)
    );
    assert_eq!(
        (ex.segments[2].kind, ex.segments[2].completed),
        (Detour, true)
    );
}

#[test]
fn a_sloped_ground_works_end_to_end() {
    let mut s = Scenario::paper_over();
    s.planner.refine_volume = true;
    s.ground = autoshovel_excavator_dig::ground::Ground {
        points: vec![[3.0, -0.3], [8.0, 0.2]],
    };
    // Keep the boulder at the same depth below the local surface.
    s.obstacles[0].center_m[1] += s.ground.height(6.64);
    let profile = MachineProfile::default();
    let ex = excavate(&s, &profile).unwrap();
    assert!(ex.volume_error().abs() < 0.02, "{}", ex.achieved_volume_m3);
    assert_eq!(ex.contacts.len(), 1);
    let last = ex.samples.last().unwrap();
    assert!((last.tip_m[1] - s.ground.height(last.tip_m[0])).abs() < 1e-9);
    assert!(ex.min_envelope_distance_m.unwrap() >= -1e-9);
}
