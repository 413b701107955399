//! The runs of a query among the grid's own points, from the columns
//! round its column, described once for the queries of a column.
//!
//! Queries come in sorted order, a column's points one after another (27
//! of them at k = 21), and each asks for the same few columns round its
//! own. `ColumnGrid::runs` works them out afresh for every query: the box's
//! columns by division, a pass over each row of a block for its heights,
//! the slabs of each column that may hold the box's heights. Here the 3 × 3
//! columns round a query's column are described once, when the queries
//! reach it (where each column's points lie, their heights, whether a
//! column is low enough to be read whole), and a query whose box fits
//! within them (its radius below a column's side, with the margin the
//! filing's rounding needs) only decides which side columns its box
//! reaches: four comparisons, then one run a row wherever the row's
//! columns lie next to each other in memory. A column whose heights span
//! more than [`WHOLE`] sides (a wall, or an outlier high above the scan)
//! and that holds more than [`WHOLE_POINTS`] points is still cut to the
//! box's heights by its slabs. A larger radius (a sparse
//! spot, a far point) goes to `ColumnGrid::runs`. Either way every point within
//! the radius is in some run, so the results are the same, bit for bit.

use super::{block_index, gap, heights_within, ColumnGrid, BLOCK, MARGIN, SLACK};

/// A column is read whole when its heights span at most this many
/// sides, else cut by its slabs ...
pub(super) const WHOLE: f64 = 2.0;

/// ... unless it holds at most this many points: a few vector steps, which
/// cost less than a run of its own (a cut column is one, where whole ones
/// side by side are read as one). On a dense scan whose range noise is
/// several column sides thick (the bench pile at 20 M points: columns of
/// 2.9 cm, a noise of centimetres) most columns span more than [`WHOLE`]
/// sides, and cutting them made twice the runs a query of the 1 M-point
/// scan: the statistical filter there 1.96–2.11 s against 1.77–1.84 s
/// read whole (BENCHMARKS.md, 2026-12-05).
pub(super) const WHOLE_POINTS: u32 = 64;

/// The 3 × 3 columns round one column (see the module docs).
#[derive(Debug, Clone, Default)]
pub(super) struct Near {
    /// The sorted positions of the column described (empty: none yet).
    own: (usize, usize),
    /// The grid's edges either side of it, widened by the margin: a box
    /// reaches the left column when its low x is at or below `left`, the
    /// right one when its high x is at or above `right` (likewise in y
    /// with `down` and `up`).
    left: f64,
    right: f64,
    down: f64,
    up: f64,
    /// Whether each side has a column (not past the grid's edge).
    has: [bool; 4],
    /// Rows cy − 1, cy, cy + 1 by columns cx − 1, cx, cx + 1: the column's
    /// index (for its slabs), its sorted positions, its lowest and highest
    /// height, and whether it is read whole.
    cells: [[Cell; 3]; 3],
}

#[derive(Debug, Clone, Copy, Default)]
struct Cell {
    column: usize,
    span: (usize, usize),
    low: f64,
    top: f64,
    whole: bool,
}

impl ColumnGrid {
    /// The column (numbered by [`block_index`]) and its x and y indices of
    /// sorted position `p`.
    fn column_of(&self, p: usize) -> (usize, usize, usize) {
        // The last column starting at or before p that holds it.
        let c = self.start.partition_point(|&s| s as usize <= p) - 1;
        let (block, inner) = (c / (BLOCK * BLOCK), c % (BLOCK * BLOCK));
        let blocks_x = self.nx.div_ceil(BLOCK);
        let cx = (block % blocks_x) * BLOCK + inner % BLOCK;
        let cy = (block / blocks_x) * BLOCK + inner / BLOCK;
        (c, cx, cy)
    }

    /// Describes the columns round the column of sorted position `p` in
    /// `near`, unless they are already.
    fn near(&self, near: &mut Near, p: usize) {
        if (near.own.0..near.own.1).contains(&p) {
            return;
        }
        let (c, cx, cy) = self.column_of(p);
        let margin = self.h * MARGIN;
        near.own = (self.start[c] as usize, self.start[c + 1] as usize);
        near.left = self.edge(cx, 0) + margin;
        near.right = self.edge(cx + 1, 0) - margin;
        near.down = self.edge(cy, 1) + margin;
        near.up = self.edge(cy + 1, 1) - margin;
        near.has = [cx > 0, cx + 1 < self.nx, cy > 0, cy + 1 < self.ny];
        for (j, row) in near.cells.iter_mut().enumerate() {
            for (i, cell) in row.iter_mut().enumerate() {
                let (x, y) = ((cx + i).checked_sub(1), (cy + j).checked_sub(1));
                *cell = match (x, y) {
                    (Some(x), Some(y)) if x < self.nx && y < self.ny => {
                        let column = block_index(x, y, self.nx);
                        let slabs = &self.slabs[column];
                        let (low, top) = (f64::from(slabs.base), f64::from(slabs.top));
                        let (s, e) = (self.start[column], self.start[column + 1]);
                        Cell {
                            column,
                            span: (s as usize, e as usize),
                            low,
                            top,
                            whole: top - low <= WHOLE * self.h || e - s <= WHOLE_POINTS,
                        }
                    }
                    // Past the grid: no points.
                    _ => Cell::default(),
                };
            }
        }
    }

    /// The widest box (a radius widened by `SLACK`) that the columns round
    /// a query's own answer: points of the columns two away lie more than
    /// h − 2·margin off.
    pub(super) fn near_width(&self) -> f64 {
        self.h * (1.0 - 4.0 * MARGIN)
    }

    /// As [`ColumnGrid::runs`], for the grid's own point at sorted position `p`
    /// (`q` its coordinates), with the columns round it kept in `near`.
    pub(super) fn runs_near(
        &self,
        near: &mut Near,
        p: usize,
        q: [f32; 3],
        r: f64,
        mut visit: impl FnMut(usize, usize) -> bool,
    ) {
        let wide = r * (1.0 + SLACK);
        if wide >= self.near_width() {
            self.runs(q, r, visit);
            return;
        }
        self.near(near, p);
        let (qx, qy, qz) = (f64::from(q[0]), f64::from(q[1]), f64::from(q[2]));
        let [has_left, has_right, has_down, has_up] = near.has;
        let from = if has_left && qx - wide <= near.left {
            0
        } else {
            1
        };
        let to = if has_right && qx + wide >= near.right {
            2
        } else {
            1
        };
        let below = has_down && qy - wide <= near.down;
        let above = has_up && qy + wide >= near.up;
        // For the slabs of a tall column.
        let (lo32, hi32) = heights_within(q[2], wide);
        // The query's own row first (a count may stop there).
        let rows = [Some(1), below.then_some(0), above.then_some(2)];
        for row in rows.into_iter().flatten() {
            // Whole columns next to each other in memory are one run.
            let (mut s, mut e) = (0, 0);
            for cell in &near.cells[row][from..=to] {
                if cell.span.0 == cell.span.1 || gap(qz, cell.low, cell.top) > wide {
                    continue;
                }
                let (cs, ce) = if cell.whole {
                    cell.span
                } else {
                    self.slab_run(&self.slabs[cell.column], lo32, hi32)
                };
                if cs == e {
                    e = ce;
                    continue;
                }
                if s < e && !visit(s, e) {
                    return;
                }
                (s, e) = (cs, ce);
            }
            if s < e && !visit(s, e) {
                return;
            }
        }
    }
}
