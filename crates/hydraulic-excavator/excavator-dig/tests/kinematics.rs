//! Kinematics against independent references: a hand-written planar chain,
//! and the round trips fk(ik(p)) = p and ik(fk(q)) = q over the workspace.

use approx::assert_relative_eq;
use autoshovel_core::Vec2;
use autoshovel_excavator_dig::{Backhoe, Joints, MachineProfile};
use proptest::prelude::*;

fn machine() -> Backhoe {
    Backhoe::new(&MachineProfile::excavator_15t())
}

/// The chain written out by hand from the SPEC §5 dimensions, without D-H:
/// boom foot (0.15, 1.7), links 4.6, 2.5 and 1.2 m at cumulative angles.
fn hand_chain(q: &Joints) -> (f64, f64) {
    let (a1, a2, a3) = (4.6, 2.5, 1.2);
    let (t1, t12, t123) = (q[0], q[0] + q[1], q[0] + q[1] + q[2]);
    (
        0.15 + a1 * t1.cos() + a2 * t12.cos() + a3 * t123.cos(),
        1.7 + a1 * t1.sin() + a2 * t12.sin() + a3 * t123.sin(),
    )
}

/// Joints inside the profile's joint ranges (the attitude may be outside its own).
fn joints() -> impl Strategy<Value = Joints> {
    let m = machine();
    let (lo, hi) = (m.limits.min_rad, m.limits.max_rad);
    (lo[0]..hi[0], lo[1]..hi[1], lo[2]..hi[2]).prop_map(|(a, b, c)| Joints::new(a, b, c))
}

proptest! {
    #[test]
    fn dh_forward_equals_the_hand_written_chain(q in joints()) {
        let m = machine();
        let dh = m.forward_dh(&q);
        let (x, y) = hand_chain(&q);
        prop_assert!((dh.point.x - x).abs() < 1e-12 && (dh.point.y - y).abs() < 1e-12);
        let fast = m.forward(&q);
        prop_assert!((fast.point - dh.point).norm() < 1e-12);
        // The tip frame's x axis is the bucket link: its angle is the attitude.
        let frame = m.dh_frames(&q)[2];
        let angle = frame[(1, 0)].atan2(frame[(0, 0)]);
        let wrapped = autoshovel_core::angle_diff(angle, q.sum());
        prop_assert!(wrapped.abs() < 1e-12);
    }

    #[test]
    fn fk_of_ik_is_the_identity_over_the_workspace(q in joints()) {
        let m = machine();
        // The workspace: joints and the attitude angle within their ranges.
        prop_assume!(m.check(&q).is_ok());
        let pose = m.forward(&q);
        let back = m.inverse(pose.point, pose.attitude_rad).expect("a pose of in-range joints is reachable");
        let again = m.forward(&back);
        prop_assert!((again.point - pose.point).norm() < 1e-9, "{:?} vs {:?}", again.point, pose.point);
        prop_assert!((again.attitude_rad - pose.attitude_rad).abs() < 1e-9);
        // The stick-folding branch is the only one inside the limits: the joints come back too.
        prop_assert!((back - q).norm() < 1e-9, "{back:?} vs {q:?}");
    }
}

#[test]
fn the_dig_start_of_the_paper_is_reachable_with_an_open_bucket() {
    let m = machine();
    let q = m
        .inverse(Vec2::new(7.0, 0.0), (-80f64).to_radians())
        .unwrap();
    let p = m.forward(&q).point;
    assert_relative_eq!(p, Vec2::new(7.0, 0.0), epsilon = 1e-12);
}
