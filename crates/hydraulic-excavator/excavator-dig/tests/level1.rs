//! Level 1 (paper §1.2): the step search, the quintic joint paths and the
//! checks on every sample.

use approx::assert_relative_eq;
use autoshovel_core::Vec2;
use autoshovel_excavator_dig::ground::Ground;
use autoshovel_excavator_dig::level1::{plan_level1, Level1Request, StepSearch};
use autoshovel_excavator_dig::segment::Motion;
use autoshovel_excavator_dig::volume::swept_area;
use autoshovel_excavator_dig::{Backhoe, MachineProfile, Scenario};
use std::sync::LazyLock;

/// The paper's case (§3): start (7, 0), depth 0.7 m, step 0.05 m, 0.9 m³.
static PAPER: LazyLock<Scenario> = LazyLock::new(Scenario::paper_over);

fn request() -> Level1Request {
    PAPER.level1_request()
}

fn search<'a>(m: &'a Backhoe, g: &'a Ground, refine: bool) -> StepSearch<'a> {
    StepSearch {
        ground: g,
        refine,
        ..PAPER.step_search(m, 1.0, &[])
    }
}

#[test]
fn the_step_search_hits_half_the_volume_within_one_step() {
    let m = Backhoe::new(&MachineProfile::default());
    let g = Ground::flat();
    let plan = plan_level1(&search(&m, &g, false), &request()).unwrap();
    let first = &plan.first;
    // The paper's rule: the nearer of the two candidates around 0.5·V, so the
    // miss is at most half of what that step changed, and certainly one step.
    assert!(first.step_volume_m3 > 0.0 && first.step_volume_m3 < 0.05);
    let miss = (first.volume_m3 - 0.45).abs();
    assert!(
        miss <= 0.5 * first.step_volume_m3 + 1e-12,
        "{miss} vs {}",
        first.step_volume_m3
    );
    // The midpoint is on the step grid at the dig depth.
    let n = (7.0 - plan.mid.x) / 0.05;
    assert_relative_eq!(n, n.round(), epsilon = 1e-9);
    assert_eq!(first.steps, n.round() as usize);
    assert_relative_eq!(plan.mid.y, -0.7, epsilon = 1e-12);
    // The second half aims at V − V_first; the whole dig misses V by at most
    // half a step of the second half.
    let total = plan.volume_m3();
    assert!(
        (total - 0.9).abs() <= 0.5 * plan.second.step_volume_m3 + 1e-12,
        "{total}"
    );
    assert_relative_eq!(plan.end.y, 0.0, epsilon = 1e-12);
    assert!(plan.end.x < plan.mid.x && plan.mid.x < plan.start.x);
}

#[test]
fn refining_inside_the_last_step_hits_the_volume() {
    let m = Backhoe::new(&MachineProfile::default());
    let g = Ground::flat();
    let plan = plan_level1(&search(&m, &g, true), &request()).unwrap();
    assert!(plan.first.refined && plan.second.refined);
    assert_relative_eq!(plan.first.volume_m3, 0.45, max_relative = 1e-5);
    assert_relative_eq!(plan.volume_m3(), 0.9, max_relative = 1e-5);
}

#[test]
fn segments_are_joint_quintics_at_rest_at_the_planned_points() {
    let m = Backhoe::new(&MachineProfile::default());
    let g = Ground::flat();
    let plan = plan_level1(&search(&m, &g, false), &request()).unwrap();
    let points = [plan.start, plan.mid, plan.end];
    for (k, seg) in plan.segments().iter().enumerate() {
        let t = seg.duration_s();
        let (a, b) = (seg.state(&m, 0.0), seg.state(&m, t));
        assert_relative_eq!(a.tip, points[k], epsilon = 1e-9);
        assert_relative_eq!(b.tip, points[k + 1], epsilon = 1e-9);
        for s in [a, b] {
            assert_relative_eq!(s.qd.norm(), 0.0, epsilon = 1e-12);
            assert_relative_eq!(s.qdd.norm(), 0.0, epsilon = 1e-12);
        }
        let Motion::Joint(j) = &seg.motion else {
            panic!("level 1 is joint space")
        };
        // Every sample: joints and attitude within their ranges, joint speeds
        // within half the limits (speed_fraction 0.5).
        let mut bend = 0.0f64;
        let chord = points[k + 1] - points[k];
        for i in 0..=400 {
            let s = seg.state(&m, t * i as f64 / 400.0);
            m.check(&s.q).unwrap();
            for (v, lim) in s.qd.iter().zip(m.limits.speed_rad_s) {
                assert!(v.abs() <= 0.5 * lim + 1e-9);
            }
            // Straight in joint space…
            let along = (s.q - j.q0).norm() / (j.q1 - j.q0).norm();
            assert_relative_eq!(s.q, j.q0 + (j.q1 - j.q0) * along, epsilon = 1e-9);
            // …so the tip leaves the straight line between the points.
            let r = s.tip - points[k];
            bend = bend.max((r.x * chord.y - r.y * chord.x).abs() / chord.norm());
        }
        assert!(bend > 0.05, "segment {k} bends only {bend} m");
    }
}

#[test]
fn the_planned_volume_is_the_area_under_a_dense_path() {
    let m = Backhoe::new(&MachineProfile::default());
    let g = Ground::flat();
    let plan = plan_level1(&search(&m, &g, false), &request()).unwrap();
    let mut dense: Vec<Vec2> = Vec::new();
    for seg in plan.segments() {
        let tips = seg.sample_tips(&m, 4000);
        dense.extend(tips.into_iter().skip(usize::from(!dense.is_empty())));
    }
    assert_relative_eq!(
        swept_area(&g, &dense),
        plan.volume_m3(),
        max_relative = 1e-3
    );
}

#[test]
fn a_sloped_ground_takes_the_depth_below_the_local_surface() {
    let m = Backhoe::new(&MachineProfile::default());
    let g = Ground {
        points: vec![[3.0, -0.4], [8.0, 0.1]],
    };
    let plan = plan_level1(&search(&m, &g, true), &request()).unwrap();
    assert_relative_eq!(plan.start.y, g.height(7.0), epsilon = 1e-12);
    assert_relative_eq!(plan.mid.y, g.height(plan.mid.x) - 0.7, epsilon = 1e-12);
    assert_relative_eq!(plan.end.y, g.height(plan.end.x), epsilon = 1e-12);
    assert_relative_eq!(plan.volume_m3(), 0.9, max_relative = 1e-5);
}
