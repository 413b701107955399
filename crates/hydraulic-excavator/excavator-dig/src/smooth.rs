//! Smoothing the forward search's grid path into a detour the bucket can
//! follow, and checking it.
//!
//! The control polygon is the contact point followed by every grid waypoint
//! (the back-off point first); the detour is its clamped cubic B-spline
//! (`autoshovel_core::CubicBSpline`), which starts at the contact heading out
//! along the normal and ends at the goal. A cubic B-spline lies in the convex
//! hull of each four consecutive control points, so with grid waypoints at
//! least r + clearance from every centre it cuts corners by a fraction of a
//! step; the check below does not rely on that: it samples the spline densely
//! and refuses it if any sample enters an envelope (only the contact point
//! itself may touch the one met) or leaves the joint or attitude ranges.

use autoshovel_core::{CubicBSpline, Vec2};

use crate::kinematics::Backhoe;
use crate::obstacle::Envelope;
use crate::segment::DetourMotion;

/// Samples per control point of the check.
const CHECK_DENSITY: usize = 12;

/// Smooth `waypoints` (grid path from the back-off point) into a detour
/// starting at `contact`, at `attitude_rad`; check it against `known`
/// envelopes and the machine's ranges; time it. `Err` says why it failed.
pub fn smooth_detour(
    machine: &Backhoe,
    contact: Vec2,
    waypoints: &[[f64; 2]],
    attitude_rad: f64,
    known: &[Envelope],
    speed_fraction: f64,
    min_time_s: f64,
) -> Result<DetourMotion, String> {
    let mut ctrl = Vec::with_capacity(waypoints.len() + 1);
    ctrl.push(contact);
    ctrl.extend(waypoints.iter().map(|w| Vec2::new(w[0], w[1])));
    let spline = CubicBSpline::clamped(ctrl).ok_or("a detour needs two points")?;
    check_clear(machine, &spline, attitude_rad, known)?;
    DetourMotion::new(machine, spline, attitude_rad, speed_fraction, min_time_s)
        .ok_or_else(|| "the smoothed detour meets a kinematic singularity".to_string())
}

/// The smallest distance from a sampled spline to any envelope, and the
/// first sample outside the machine's ranges.
fn check_clear(
    machine: &Backhoe,
    spline: &CubicBSpline,
    attitude_rad: f64,
    known: &[Envelope],
) -> Result<(), String> {
    let n = spline.control_points().len() * CHECK_DENSITY;
    for k in 0..=n {
        let u = k as f64 / n as f64;
        let p = spline.point(u);
        // The contact point touches the envelope met; allow rounding there.
        let tol = if k == 0 { 1e-9 } else { 0.0 };
        for (i, e) in known.iter().enumerate() {
            if e.signed_distance(p) < -tol {
                return Err(format!(
                    "the smoothed detour enters known envelope {i} at ({:.3}, {:.3}) m",
                    p.x, p.y
                ));
            }
        }
        if let Err(e) = machine.inverse(p, attitude_rad) {
            return Err(format!(
                "the smoothed detour needs ({:.2}, {:.2}) m, where {e}",
                p.x, p.y
            ));
        }
    }
    Ok(())
}
