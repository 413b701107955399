//! The layout both height grids of a shift share — the simulator's pit
//! ([`crate::World`]) and the machine's model of it
//! ([`crate::machine::PileModel`]): square cells from a corner, x fastest
//! — and what is done the same way on either: finding a cell, its centre,
//! the volume held, and the dipper's cut ([`Cut`]).

/// Square cells of `cell_m` from `origin`, `size` along x and y, numbered x fastest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Lower-left corner (m).
    pub origin: [f64; 2],
    /// Cell edge (m).
    pub cell_m: f64,
    /// Cells along x and y.
    pub size: [usize; 2],
}

impl Layout {
    /// The cells of edge `cell_m` (at least one each way) covering `min`–`max`.
    pub fn over(min: [f64; 2], max: [f64; 2], cell_m: f64) -> Self {
        Self {
            origin: min,
            cell_m,
            size: [0, 1].map(|a| ((max[a] - min[a]) / cell_m).ceil().max(1.0) as usize),
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.size[0] * self.size[1]
    }

    /// Whether there are no cells (never, for a layout made by [`Layout::over`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cell of (x, y), if inside.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<usize> {
        let i = ((x - self.origin[0]) / self.cell_m).floor();
        let j = ((y - self.origin[1]) / self.cell_m).floor();
        (i >= 0.0 && j >= 0.0 && (i as usize) < self.size[0] && (j as usize) < self.size[1])
            .then(|| j as usize * self.size[0] + i as usize)
    }

    /// The centre (x, y) of cell `k`.
    pub fn centre(&self, k: usize) -> [f64; 2] {
        [
            self.origin[0] + ((k % self.size[0]) as f64 + 0.5) * self.cell_m,
            self.origin[1] + ((k / self.size[0]) as f64 + 0.5) * self.cell_m,
        ]
    }

    /// What heights `z` (one a cell) hold above the floor (m³), each cell a
    /// prism; NaN cells (never seen) count nothing.
    pub fn volume_m3(&self, z: &[f64]) -> f64 {
        z.iter().filter(|z| z.is_finite()).sum::<f64>() * self.cell_m * self.cell_m
    }

    /// Takes the material above `cut`'s tooth path within its width out of
    /// heights `z` (never below the floor) and returns its volume (m³):
    /// each cell the swept strip covers is lowered to the path, one it
    /// covers in part by that share of its height above the path; a NaN
    /// cell is left as it is.
    pub fn cut(&self, z: &mut [f64], cut: &Cut) -> f64 {
        let xs = cut.path.iter().map(|p| p[0]);
        let (x_lo, x_hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        if !(x_lo.is_finite() && x_hi > x_lo) {
            return 0.0;
        }
        let (c, s) = (cut.heading.cos(), cut.heading.sin());
        let corners = [
            cut.world(x_lo, -cut.half_width_m),
            cut.world(x_lo, cut.half_width_m),
            cut.world(x_hi, -cut.half_width_m),
            cut.world(x_hi, cut.half_width_m),
        ];
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in corners {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let cell = self.cell_m;
        let index = |v: f64, a: usize| ((v - self.origin[a]) / cell).floor();
        let range = |a: usize| {
            let i0 = index(lo[a], a).max(0.0) as usize;
            let i1 = (index(hi[a], a) + 1.0).clamp(0.0, self.size[a] as f64) as usize;
            i0..i1
        };
        let mut removed = 0.0;
        for j in range(1) {
            for i in range(0) {
                let k = j * self.size[0] + i;
                let [x, y] = self.centre(k);
                let (dx, dy) = (x - cut.origin[0], y - cut.origin[1]);
                let along = dx * c + dy * s - cut.toe_s_m;
                let across = -dx * s + dy * c;
                // The share of the cell's width the strip covers (the cell
                // taken square to the strip): a cell half inside gives up
                // half of what lies above the path, so the volume taken is
                // the strip's, not the cells' whose centres it holds.
                let share = ((cut.half_width_m - (across.abs() - 0.5 * cell)).min(cell) / cell)
                    .clamp(0.0, 1.0);
                if share == 0.0 {
                    continue;
                }
                if let Some(floor) = cut.floor_at(along) {
                    let floor = floor.max(0.0);
                    if z[k] > floor {
                        let taken = share * (z[k] - floor);
                        removed += taken;
                        z[k] -= taken;
                    }
                }
            }
        }
        removed * cell * cell
    }
}

/// A straight cut: the dipper's tooth path in the vertical plane through
/// `origin` along `heading`, its dig frame's x measured from `toe_s_m`
/// along the line, y up from the floor; `half_width_m` each side.
#[derive(Debug, Clone, PartialEq)]
pub struct Cut {
    /// A point of the dig line (the swing axis) (m).
    pub origin: [f64; 2],
    /// Direction of the line (rad from +x).
    pub heading: f64,
    /// Distance along the line to the dig frame's origin (the toe) (m).
    pub toe_s_m: f64,
    /// Half the dipper's width (m).
    pub half_width_m: f64,
    /// The tooth path in the dig frame (x along, y up) (m).
    pub path: Vec<[f64; 2]>,
}

impl Cut {
    /// The lowest point of the path over dig-frame `x` (the tooth's lower
    /// envelope), or `None` where the path does not pass.
    pub fn floor_at(&self, x: f64) -> Option<f64> {
        let mut lowest: Option<f64> = None;
        for w in self.path.windows(2) {
            let ([x0, y0], [x1, y1]) = (w[0], w[1]);
            let (lo, hi) = if x0 <= x1 { (x0, x1) } else { (x1, x0) };
            if x < lo || x > hi {
                continue;
            }
            let y = if hi > lo {
                y0 + (y1 - y0) * (x - x0) / (x1 - x0)
            } else {
                y0.min(y1)
            };
            lowest = Some(lowest.map_or(y, |l: f64| l.min(y)));
        }
        lowest
    }

    /// World (x, y) of dig-frame x at lateral offset `w` (left positive).
    pub fn world(&self, x: f64, w: f64) -> [f64; 2] {
        let (c, s) = (self.heading.cos(), self.heading.sin());
        let along = self.toe_s_m + x;
        [
            self.origin[0] + along * c - w * s,
            self.origin[1] + along * s + w * c,
        ]
    }
}
