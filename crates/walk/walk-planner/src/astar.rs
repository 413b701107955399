//! Grid reference planner: the shortest collision-free route for the
//! footprint disc on an 8-connected occupancy grid of the same map, searched
//! with Theta* (A* whose parent pointers may jump along any line of sight,
//! Nash et al. 2007), then shortened once more by line of sight against the
//! exact map, so that potential-field paths can be judged by their length
//! ratio to it. Plain 8-connected A* has many equal-cost routes that wander
//! off the taut string; Theta* does not. It ignores heading: it is a near
//! lower bound on length, not a drivable path.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use autoshovel_core::{polyline_length, Vec2};
use serde::{Deserialize, Serialize};

use crate::error::{NoPathFault, PropelError, Result};
use crate::map::Map;

/// Name of the reference planner, as summaries report it.
pub const REFERENCE_PLANNER: &str = "theta-star";

/// Grid A* parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AstarParams {
    /// Cell size (m).
    pub resolution_m: f64,
    /// Refuse grids larger than this many cells.
    pub max_cells: usize,
}

impl Default for AstarParams {
    fn default() -> Self {
        Self {
            resolution_m: 0.25,
            max_cells: 4_000_000,
        }
    }
}

/// A reference route.
#[derive(Debug, Clone)]
pub struct Route {
    /// Waypoints after line-of-sight shortening (m).
    pub points: Vec<Vec2>,
    /// Length (m).
    pub length_m: f64,
    /// Cells expanded.
    pub expanded: usize,
}

#[derive(Copy, Clone, PartialEq)]
struct Open {
    f: f64,
    idx: usize,
}
impl Eq for Open {}
impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other.f.total_cmp(&self.f).then(other.idx.cmp(&self.idx))
    }
}
impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Whether the straight segment a–b keeps the footprint clear (sampled at a quarter cell).
pub fn segment_free(map: &Map, a: Vec2, b: Vec2, r_fp: f64, step_m: f64) -> bool {
    let n = ((b - a).norm() / step_m).ceil().max(1.0) as usize;
    (0..=n).all(|i| map.is_clear(a + (b - a) * (i as f64 / n as f64), r_fp))
}

/// `v.round() as usize` for `v >= 0` (a cell index along a sight line), with
/// no call: on x86-64 without SSE4.1, `f64::round` is a call into libm, and
/// it was a sixth of a random-road study's time here. `v - trunc(v)` is
/// exact, so the half rounds up (away from zero) as `round` does.
fn round_cell(v: f64) -> usize {
    let t = v as usize;
    if v - t as f64 >= 0.5 {
        t + 1
    } else {
        t
    }
}

/// Plans the reference route from `start` to `goal` for a footprint of radius `r_fp`.
pub fn astar(map: &Map, start: Vec2, goal: Vec2, r_fp: f64, p: &AstarParams) -> Result<Route> {
    let res = p.resolution_m;
    if !(res.is_finite() && res > 0.0) {
        return Err(PropelError::NoPath {
            fault: NoPathFault::BadResolution { resolution_m: res },
        });
    }
    let span = map.max - map.min;
    let nx = (span.x / res).ceil() as usize + 1;
    let ny = (span.y / res).ceil() as usize + 1;
    if nx.saturating_mul(ny) > p.max_cells {
        return Err(PropelError::NoPath {
            fault: NoPathFault::TooManyCells {
                nx,
                ny,
                max_cells: p.max_cells,
            },
        });
    }
    let center = |i: usize| map.min + Vec2::new((i % nx) as f64 * res, (i / nx) as f64 * res);
    let free: Vec<bool> = (0..nx * ny)
        .map(|i| map.is_clear(center(i), r_fp))
        .collect();
    let cell_of = |q: Vec2| -> usize {
        let ix = (((q.x - map.min.x) / res).round().max(0.0) as usize).min(nx - 1);
        let iy = (((q.y - map.min.y) / res).round().max(0.0) as usize).min(ny - 1);
        iy * nx + ix
    };
    // Snap start and goal to the nearest free cell seen from them.
    let snap = |q: Vec2| -> Option<usize> {
        let c = cell_of(q);
        if free[c] {
            return Some(c);
        }
        let (cx, cy) = ((c % nx) as i64, (c / nx) as i64);
        (1..4i64)
            .flat_map(|r| (-r..=r).flat_map(move |dx| (-r..=r).map(move |dy| (dx, dy))))
            .filter_map(|(dx, dy)| {
                let (x, y) = (cx + dx, cy + dy);
                (x >= 0 && y >= 0 && (x as usize) < nx && (y as usize) < ny)
                    .then(|| y as usize * nx + x as usize)
            })
            .find(|&i| free[i])
    };
    let s = snap(start).ok_or_else(|| PropelError::NoPath {
        fault: NoPathFault::NoFreeCell {
            which: "start",
            x: start.x,
            y: start.y,
        },
    })?;
    let g = snap(goal).ok_or_else(|| PropelError::NoPath {
        fault: NoPathFault::NoFreeCell {
            which: "goal",
            x: goal.x,
            y: goal.y,
        },
    })?;
    let h = |i: usize| {
        let dx = ((i % nx) as f64 - (g % nx) as f64).abs();
        let dy = ((i / nx) as f64 - (g / nx) as f64).abs();
        res * (dx.max(dy) + (std::f64::consts::SQRT_2 - 1.0) * dx.min(dy))
    };
    // Line of sight on the grid: every cell touched by samples a quarter cell apart is free.
    let grid_sight = |a: usize, b: usize| -> bool {
        let (ax, ay) = ((a % nx) as f64, (a / nx) as f64);
        let (bx, by) = ((b % nx) as f64, (b / nx) as f64);
        let n = (((bx - ax).abs().max((by - ay).abs())) * 4.0)
            .ceil()
            .max(1.0) as usize;
        (0..=n).all(|k| {
            let t = k as f64 / n as f64;
            let x = round_cell(ax + (bx - ax) * t);
            let y = round_cell(ay + (by - ay) * t);
            free[y * nx + x]
        })
    };
    let mut cost = vec![f64::INFINITY; nx * ny];
    let mut parent = vec![usize::MAX; nx * ny];
    let mut closed = vec![false; nx * ny];
    let mut open = BinaryHeap::new();
    cost[s] = 0.0;
    open.push(Open { f: h(s), idx: s });
    let mut expanded = 0;
    while let Some(Open { idx, .. }) = open.pop() {
        if closed[idx] {
            continue;
        }
        closed[idx] = true;
        expanded += 1;
        if idx == g {
            break;
        }
        let (x, y) = ((idx % nx) as i64, (idx / nx) as i64);
        for (dx, dy) in [
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (1, -1),
            (-1, 1),
            (-1, -1),
        ] {
            let (xx, yy) = (x + dx, y + dy);
            if xx < 0 || yy < 0 || xx as usize >= nx || yy as usize >= ny {
                continue;
            }
            let j = yy as usize * nx + xx as usize;
            if !free[j] || closed[j] {
                continue;
            }
            // No corner cutting past an occupied cell.
            if dx != 0
                && dy != 0
                && (!free[y as usize * nx + xx as usize] || !free[yy as usize * nx + x as usize])
            {
                continue;
            }
            // Theta*: inherit the grandparent when it sees the neighbour.
            let pa = parent[idx];
            let (from, c) = if pa != usize::MAX && grid_sight(pa, j) {
                (pa, cost[pa] + (center(pa) - center(j)).norm())
            } else {
                let step = if dx != 0 && dy != 0 {
                    res * std::f64::consts::SQRT_2
                } else {
                    res
                };
                (idx, cost[idx] + step)
            };
            if c < cost[j] {
                cost[j] = c;
                parent[j] = from;
                open.push(Open {
                    f: c + h(j),
                    idx: j,
                });
            }
        }
    }
    if !closed[g] {
        return Err(PropelError::NoPath {
            fault: NoPathFault::Unreachable { expanded },
        });
    }
    let mut cells = vec![g];
    while let Some(&c) = cells.last() {
        if c == s {
            break;
        }
        cells.push(parent[c]);
    }
    cells.reverse();
    let mut pts: Vec<Vec2> = cells.iter().map(|&c| center(c)).collect();
    pts[0] = start;
    let last = pts.len() - 1;
    pts[last] = goal;
    // Line-of-sight shortening (greedy: from each kept point, jump to the farthest visible one).
    let mut short = vec![pts[0]];
    let mut i = 0;
    while i < last {
        let mut j = last;
        while j > i + 1 && !segment_free(map, pts[i], pts[j], r_fp, res * 0.25) {
            j -= 1;
        }
        short.push(pts[j]);
        i = j;
    }
    Ok(Route {
        length_m: polyline_length(&short),
        points: short,
        expanded,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::{Obstacle, Shape};
    use approx::assert_relative_eq;

    #[test]
    fn round_cell_is_round_for_cell_coordinates() {
        for v in [
            0.0,
            0.25,
            0.5,
            0.49999999999999994,
            1.5,
            2.5,
            7.499999,
            1e6 + 0.5,
            4503599627370495.5,
        ] {
            assert_eq!(round_cell(v), v.round() as usize, "{v}");
        }
        let mut v = 0.0f64;
        while v < 50.0 {
            assert_eq!(round_cell(v), v.round() as usize, "{v}");
            v += 0.015625 / 3.0;
        }
    }

    #[test]
    fn open_site_gives_the_straight_line() {
        let map = Map::new(Vec2::new(0.0, 0.0), Vec2::new(20.0, 10.0));
        let r = astar(
            &map,
            Vec2::new(2.0, 2.0),
            Vec2::new(18.0, 8.0),
            1.0,
            &AstarParams::default(),
        )
        .unwrap();
        assert_relative_eq!(r.length_m, (16.0f64.powi(2) + 36.0).sqrt(), epsilon = 1e-9);
    }

    #[test]
    fn detour_round_a_disc_is_close_to_the_taut_string_length() {
        // Going round a disc of radius R + r_fp: the shortest path is two tangents and an arc.
        let mut map = Map::new(Vec2::new(-15.0, -15.0), Vec2::new(15.0, 15.0));
        map.obstacles.push(Obstacle {
            name: "pile".into(),
            shape: Shape::Circle {
                center: Vec2::zeros(),
                radius: 3.0,
            },
        });
        let r_fp = 1.0;
        let a = Vec2::new(-10.0, 0.0);
        let b = Vec2::new(10.0, 0.0);
        let route = astar(
            &map,
            a,
            b,
            r_fp,
            &AstarParams {
                resolution_m: 0.1,
                ..Default::default()
            },
        )
        .unwrap();
        let big_r: f64 = 4.0;
        let d: f64 = 10.0;
        let tangent = (d * d - big_r * big_r).sqrt();
        let arc = big_r * (std::f64::consts::PI - 2.0 * (big_r / d).acos());
        let exact = 2.0 * tangent + arc;
        assert!(
            route.length_m >= exact - 1e-6,
            "{} < {exact}",
            route.length_m
        );
        assert!(
            route.length_m <= exact * 1.03,
            "{} vs {exact}",
            route.length_m
        );
    }

    #[test]
    fn a_closed_road_has_no_path() {
        let mut map = Map::new(Vec2::new(0.0, 0.0), Vec2::new(20.0, 6.0));
        map.obstacles.push(Obstacle {
            name: "slide".into(),
            shape: Shape::Circle {
                center: Vec2::new(10.0, 3.0),
                radius: 2.5,
            },
        });
        assert!(matches!(
            astar(
                &map,
                Vec2::new(2.0, 3.0),
                Vec2::new(18.0, 3.0),
                1.0,
                &AstarParams::default()
            ),
            Err(PropelError::NoPath { .. })
        ));
    }
}
