//! The k nearest distances of a point far from the scan (an outlier high
//! above it), for `ColumnGrid::map_k_nearest_distances`: blocks of columns and
//! columns searched nearest box first.

use super::within;
use super::{gap, ColumnGrid, Scratch, BLOCK, MARGIN, SLACK};

impl ColumnGrid {
    /// The k nearest squared distances of a point far from the rest, as
    /// `k_nearest`: blocks of columns are opened nearest first by the
    /// distance from q to their boxes (their span of x and y, their
    /// points' heights), ring by ring round q's as they are needed, and a
    /// block's columns nearest first by their own boxes, keeping the k
    /// nearest so far, until the next box lies beyond the k-th. (Columns
    /// kept in one queue with the blocks cost more in its upkeep than
    /// they save: a far point on the bench pile pushed 306 columns and
    /// opened 82.) For a point high above the scan that is the
    /// few columns below it; a radius grown until it holds k would
    /// overshoot, and a ball of a little more than the k-th distance cuts
    /// deep into the surface beneath (thousands of points where k are
    /// wanted).
    pub(super) fn far_k_nearest(&self, q: [f32; 3], k: usize, scratch: &mut Scratch) -> f32 {
        use std::cmp::Reverse;
        let (qx, qy, qz) = (f64::from(q[0]), f64::from(q[1]), f64::from(q[2]));
        let (bx, by) = (self.column_at(qx, 0) / BLOCK, self.column_at(qy, 1) / BLOCK);
        let (blocks_x, blocks_y) = (self.nx.div_ceil(BLOCK), self.ny.div_ceil(BLOCK));
        let margin = self.h * MARGIN;
        let edge = |c: usize, a: usize| self.edge(c, a);
        // The squared distance from q to the box of columns x0..x1, y0..y1
        // (past the last) whose heights are `low..=top`.
        let reach = |x0: usize, x1: usize, y0: usize, y1: usize, (low, top): (f32, f32)| {
            let dx = self.off_columns(qx, x0, x1, 0);
            let dy = self.off_columns(qy, y0, y1, 1);
            let dz = gap(qz, f64::from(low), f64::from(top));
            dx * dx + dy * dy + dz * dz
        };
        // Blocks waiting, nearest first (squared distances ≥ 0 order as
        // their bits), by index; the columns of the block being opened.
        let (waiting, columns) = (&mut scratch.waiting, &mut scratch.columns);
        let (bits, best) = (&mut scratch.bits, &mut scratch.best);
        waiting.clear();
        best.clear();
        let mut cap = f32::INFINITY;
        // Boxes nearer than this may hold points within the k-th so far.
        let limit_of = |cap: f32| f64::from(cap) * (1.0 + SLACK);
        // The k nearest of `best` kept, the k-th last; returns the k-th.
        let pick = |best: &mut Vec<u32>| {
            within::smallest(self.isa, best, k);
            best.truncate(k);
            f32::from_bits(best[k - 1])
        };
        let mut ring = 0;
        loop {
            let limit = limit_of(cap);
            // Beyond the rings of blocks so far (0 to ring − 1), every
            // box lies at least `outside` from q (no side: the grid's edge).
            let sides = [
                (bx >= ring).then(|| qx - edge((bx + 1 - ring) * BLOCK, 0)),
                (bx + ring < blocks_x).then(|| edge((bx + ring) * BLOCK, 0) - qx),
                (by >= ring).then(|| qy - edge((by + 1 - ring) * BLOCK, 1)),
                (by + ring < blocks_y).then(|| edge((by + ring) * BLOCK, 1) - qy),
            ];
            let outside = sides.iter().flatten().fold(f64::INFINITY, |m, &d| m.min(d)) - margin;
            let outside = outside.max(0.0).powi(2);
            let next = waiting.peek().map(|Reverse((d, _))| f64::from_bits(*d));
            if outside.is_finite() && outside <= limit && next.is_none_or(|d| outside < d) {
                // The next ring of blocks round q's.
                let (x0, x1) = (bx.saturating_sub(ring), (bx + ring).min(blocks_x - 1));
                let (y0, y1) = (by.saturating_sub(ring), (by + ring).min(blocks_y - 1));
                for y in y0..=y1 {
                    let row_edge = y + ring == by || y == by + ring;
                    for x in x0..=x1 {
                        if !(row_edge || x + ring == bx || x == bx + ring) {
                            continue;
                        }
                        let b = y * blocks_x + x;
                        let heights = self.block_heights[b];
                        if heights.0 > heights.1 {
                            continue;
                        }
                        let (cx, cy) = (x * BLOCK, y * BLOCK);
                        let d = reach(cx, cx + BLOCK, cy, cy + BLOCK, heights);
                        if d <= limit {
                            waiting.push(Reverse((d.to_bits(), b)));
                        }
                    }
                }
                ring += 1;
                continue;
            }
            if next.is_none_or(|d| d > limit) {
                break;
            }
            let Some(Reverse((_, i))) = waiting.pop() else {
                unreachable!("peeked")
            };
            // The block's columns (numbered in a run, see `block_index`)
            // within the limit, nearest first. Its sides apart along x
            // and y are the same for a row or a column of them.
            let (x0, y0) = ((i % blocks_x) * BLOCK, (i / blocks_x) * BLOCK);
            let off = |c0: usize, a: usize| -> [f64; BLOCK] {
                let v = [qx, qy][a];
                std::array::from_fn(|j| self.off_columns(v, c0 + j, c0 + j + 1, a).powi(2))
            };
            let (dx2, dy2) = (off(x0, 0), off(y0, 1));
            columns.clear();
            for j in 0..BLOCK * BLOCK {
                let (x, y) = (x0 + j % BLOCK, y0 + j / BLOCK);
                let c = i * BLOCK * BLOCK + j;
                if x >= self.nx || y >= self.ny || self.slabs[c].count == 0 {
                    continue;
                }
                let slabs = &self.slabs[c];
                let dz = gap(qz, f64::from(slabs.base), f64::from(slabs.top));
                let d = dx2[j % BLOCK] + dy2[j / BLOCK] + dz * dz;
                if d <= limit {
                    columns.push((d.to_bits(), c));
                }
            }
            columns.sort_unstable();
            for &(d, c) in columns.iter() {
                if f64::from_bits(d) > limit_of(cap) {
                    break;
                }
                // Its points nearer than the k-th so far.
                let (s, e) = (self.start[c] as usize, self.start[c + 1] as usize);
                within::keep_distances(self.isa, q, self.run(s, e), cap, best);
                // The k nearest so far: picked out when the first k are
                // in, then each time the kept have grown past twice k
                // (cheaper than a heap kept in order at every point; the
                // k-th of the last pick bounds the search meanwhile).
                if best.len() >= k && (cap.is_infinite() || best.len() >= 2 * k) {
                    cap = pick(best);
                }
            }
        }
        // The k (the grid holds more than k points), the k-th last.
        if best.len() > k {
            cap = pick(best);
        }
        bits.clear();
        bits.extend_from_slice(best);
        cap
    }
}
