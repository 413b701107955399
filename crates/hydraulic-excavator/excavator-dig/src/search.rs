//! Forward search round a boulder (paper §2.2, the lower level of the two):
//! grid points of step s are sorted into the free set P and the collision set
//! Q, and a path from the contact to a point past the boulder is searched
//! that never touches Q.
//!
//! The paper names the sets but not the search. Ours:
//! - **Grid.** Step s (the scenario's step, 0.05 m in the paper's case),
//!   anchored at the back-off point b = contact + clearance·n (n the outward
//!   normal at the contact): the bucket first backs off the rock along n.
//!   The grid covers the boulder's envelope inflated by the clearance, plus a
//!   window on every side.
//! - **P and Q.** A point is in Q when it lies within an inflated envelope of
//!   any known boulder (radius r + clearance), on the wrong side of the one
//!   met (the preimage rule's half: over keeps y ≥ y₀ wherever
//!   x₀ − r − clearance ≤ x ≤ x₀, under keeps y ≤ y₀; the band is the far
//!   half of the boulder, so the path may still round its near side to reach
//!   the chosen half, and cannot pass on the other), or where the tooth cannot
//!   go at the held attitude (out of reach, a joint beyond its limit). Points
//!   are classified lazily, when first reached.
//! - **Search.** A* over the 8-neighbours (edge cost = length), goal: any free
//!   point with x ≤ x_goal, a line past the boulder towards the machine;
//!   heuristic max(0, x − x_goal), admissible since no move gains more x than
//!   its length. The shortest way round hugs the inflated envelope, so the
//!   clearance is the margin the smoothing may spend.
//! - **Failure** names the limit met nearest the envelope's pole on the chosen
//!   side (its top for over, bottom for under): that is where the bucket
//!   would have to go.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use autoshovel_core::Vec2;
use serde::Serialize;

use crate::kinematics::Backhoe;
use crate::kinematics::IkError;
use crate::obstacle::Envelope;
use crate::preimage::AvoidSide;

/// Settings of the forward search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchParams {
    /// Grid step s (m).
    pub step_m: f64,
    /// Margin kept from every envelope (m).
    pub clearance_m: f64,
    /// How far beyond the inflated envelope the grid reaches (m).
    pub window_m: f64,
}

/// A way round found.
#[derive(Debug, Clone, Serialize)]
pub struct SearchPath {
    /// Grid waypoints from the back-off point to the goal (m).
    pub waypoints: Vec<[f64; 2]>,
    /// |P|: free points classified.
    pub free_points: usize,
    /// |Q|: colliding points classified.
    pub blocked_points: usize,
    /// Points expanded.
    pub expanded: usize,
}

/// Most points of a forward-search grid (four arrays of them: about
/// 150 MB).
pub const MAX_GRID_POINTS: usize = 8_000_000;

/// Why no way round was found.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchFailure {
    /// Human-readable reason, naming the limit and where.
    pub why: String,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Cell {
    Unknown,
    Free,
    Blocked,
}

#[derive(Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    g: f64,
    idx: usize,
}

impl Eq for Open {}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        // Min-heap on f, ties to the larger g (deeper along the way).
        other
            .f
            .total_cmp(&self.f)
            .then_with(|| self.g.total_cmp(&other.g))
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Search a way round `met` on `side`, from the `contact` point with outward
/// normal `normal`, to the line x = `goal_x`, avoiding every envelope in
/// `known` (which includes `met`), with the tooth at `attitude_rad`.
#[allow(clippy::too_many_arguments)]
pub fn forward_search(
    machine: &Backhoe,
    attitude_rad: f64,
    contact: Vec2,
    normal: Vec2,
    met: &Envelope,
    side: AvoidSide,
    known: &[Envelope],
    goal_x: f64,
    params: &SearchParams,
) -> Result<SearchPath, SearchFailure> {
    let s = params.step_m;
    let c = met.center();
    let big_r = met.radius_m + params.clearance_m;
    let back_off = contact + normal * params.clearance_m;
    // Grid bounds, in steps from the back-off point.
    let reach = big_r + params.window_m;
    let lo_x = ((c.x - reach).min(goal_x - 2.0 * s) - back_off.x) / s;
    let hi_x = ((c.x + reach).max(back_off.x + 2.0 * s) - back_off.x) / s;
    let lo_y = ((c.y - reach).min(back_off.y - 2.0 * s) - back_off.y) / s;
    let hi_y = ((c.y + reach).max(back_off.y + 2.0 * s) - back_off.y) / s;
    // A grid past MAX_GRID_POINTS (a rock estimated far larger than the
    // step, or a step far finer than the rock) is refused before it is
    // allocated: four arrays of that many points would not fit.
    let span = (hi_x - lo_x + 1.0) * (hi_y - lo_y + 1.0);
    if !(span.is_finite() && span <= MAX_GRID_POINTS as f64) {
        return Err(SearchFailure {
            why: format!(
                "the search grid round the rock (radius {:.3} m + window {:.3} m at steps of {:.4} m) would have {} points, more than {}",
                met.radius_m,
                params.window_m,
                s,
                autoshovel_core::config::approx(span),
                autoshovel_core::config::approx(MAX_GRID_POINTS as f64)
            ),
        });
    }
    let (i0, i1) = (lo_x.floor() as i64, hi_x.ceil() as i64);
    let (j0, j1) = (lo_y.floor() as i64, hi_y.ceil() as i64);
    let nx = (i1 - i0 + 1) as usize;
    let ny = (j1 - j0 + 1) as usize;
    let point = |idx: usize| {
        let (i, j) = ((idx % nx) as i64 + i0, (idx / nx) as i64 + j0);
        back_off + Vec2::new(i as f64 * s, j as f64 * s)
    };
    let start = ((-j0) as usize) * nx + (-i0) as usize;

    let mut cells = vec![Cell::Unknown; nx * ny];
    let mut g_cost = vec![f64::INFINITY; nx * ny];
    let mut parent = vec![usize::MAX; nx * ny];
    let mut closed = vec![false; nx * ny];
    let (mut free, mut blocked, mut expanded) = (0usize, 0usize, 0usize);
    // The kinematic refusal nearest the pole of the chosen side.
    let pole = c + Vec2::new(
        0.0,
        match side {
            AvoidSide::Over => big_r,
            AvoidSide::Under => -big_r,
        },
    );
    let mut nearest_refusal: Option<(f64, Vec2, IkError)> = None;

    let classify = |idx: usize, nearest_refusal: &mut Option<(f64, Vec2, IkError)>| -> bool {
        let p = point(idx);
        let mut ok = known
            .iter()
            .all(|e| (p - e.center()).norm() >= e.radius_m + params.clearance_m - 1e-9);
        if ok && idx != start && p.x <= c.x && p.x >= c.x - big_r {
            ok = match side {
                AvoidSide::Over => p.y >= c.y,
                AvoidSide::Under => p.y <= c.y,
            };
        }
        if ok {
            if let Err(e) = machine.inverse(p, attitude_rad) {
                ok = false;
                let d = (p - pole).norm();
                let nearer = match nearest_refusal {
                    Some((best, _, _)) => d < *best,
                    None => true,
                };
                if nearer {
                    *nearest_refusal = Some((d, p, e));
                }
            }
        }
        ok
    };

    if !classify(start, &mut nearest_refusal) {
        let why = match nearest_refusal {
            Some((_, p, e)) => format!("backing off the rock to ({:.2}, {:.2}) m: {e}", p.x, p.y),
            None => "the back-off point is inside another known envelope".to_string(),
        };
        return Err(SearchFailure { why });
    }
    cells[start] = Cell::Free;
    free += 1;
    g_cost[start] = 0.0;
    let h = |p: Vec2| (p.x - goal_x).max(0.0);
    let mut open = BinaryHeap::new();
    open.push(Open {
        f: h(back_off),
        g: 0.0,
        idx: start,
    });
    let diag = s * std::f64::consts::SQRT_2;
    while let Some(Open { g, idx, .. }) = open.pop() {
        if closed[idx] {
            continue;
        }
        closed[idx] = true;
        expanded += 1;
        let p = point(idx);
        if p.x <= goal_x + 1e-9 {
            let mut waypoints = Vec::new();
            let mut k = idx;
            while k != usize::MAX {
                let q = point(k);
                waypoints.push([q.x, q.y]);
                k = parent[k];
            }
            waypoints.reverse();
            return Ok(SearchPath {
                waypoints,
                free_points: free,
                blocked_points: blocked,
                expanded,
            });
        }
        let (ci, cj) = ((idx % nx) as i64, (idx / nx) as i64);
        for (di, dj) in [
            (-1, 0),
            (-1, -1),
            (-1, 1),
            (0, -1),
            (0, 1),
            (1, -1),
            (1, 0),
            (1, 1),
        ] {
            let (ni, nj) = (ci + di, cj + dj);
            if ni < 0 || nj < 0 || ni >= nx as i64 || nj >= ny as i64 {
                continue;
            }
            let n = nj as usize * nx + ni as usize;
            if closed[n] {
                continue;
            }
            if cells[n] == Cell::Unknown {
                if classify(n, &mut nearest_refusal) {
                    cells[n] = Cell::Free;
                    free += 1;
                } else {
                    cells[n] = Cell::Blocked;
                    blocked += 1;
                }
            }
            if cells[n] == Cell::Blocked {
                continue;
            }
            let step = if di != 0 && dj != 0 { diag } else { s };
            let ng = g + step;
            if ng < g_cost[n] {
                g_cost[n] = ng;
                parent[n] = idx;
                open.push(Open {
                    f: ng + h(point(n)),
                    g: ng,
                    idx: n,
                });
            }
        }
    }
    let why = match nearest_refusal {
        Some((_, p, e)) => format!(
            "no free grid point leads past it ({free} free, {blocked} colliding); \
             nearest the {side} pole the tooth would need ({:.2}, {:.2}) m, where {e}",
            p.x, p.y
        ),
        None => format!(
            "no free grid point leads past it within the search window \
             ({free} free, {blocked} colliding): other boulders block the way"
        ),
    };
    Err(SearchFailure { why })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::MachineProfile;

    #[test]
    fn a_grid_too_large_to_allocate_is_refused_by_name() {
        // The paper's contact with the rock estimated a thousand times too
        // large (a fuzzed profile made one): 10¹¹ points at 5 cm.
        let m = Backhoe::new(&MachineProfile::default());
        let rock = Envelope::new(Vec2::new(6.64, -0.60), 2.5e3);
        let contact = Vec2::new(6.6812, -0.3534);
        let normal = Vec2::new(0.0, 1.0);
        let params = SearchParams {
            step_m: 0.05,
            clearance_m: 0.1,
            window_m: 1.0,
        };
        let e = forward_search(
            &m,
            -1.73,
            contact,
            normal,
            &rock,
            AvoidSide::Over,
            &[rock],
            6.24,
            &params,
        )
        .unwrap_err();
        assert!(
            e.why.contains("search grid") && e.why.contains("points"),
            "{}",
            e.why
        );
    }
}
