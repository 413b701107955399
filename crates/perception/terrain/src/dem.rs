//! A gridded height model of a scan (a DEM, as PDAL's `writers.gdal` makes
//! one with `output_type = "mean"`): square cells over the cleaned points,
//! each the mean height of its points, empty cells left as holes and
//! counted. It holds real terrain, which an 8 × 8 sample of a low-degree
//! polynomial ([RS eq. 21]) cannot: what it misses is stated as the RMS of
//! the points' heights less the model's, bilinear between cell centres.
//!
//! Volumes are sums over cells: `V = Σ max(z_cell − base, 0) · cell²` above
//! a base (a height, or another scan's grid: a stockpile on its pad, a bin
//! over its empty floor), and the change between two scans as fill and cut.
//! Holes add nothing; the share of the area they cover is reported beside.

use autoshovel_point_cloud::PointCloud;
use serde::Serialize;

use crate::error::{Result, SurfaceError};

/// Most cells a grid may have (a 4096 × 4096 model, 128 MiB of f64
/// heights and counts); a finer cell is refused with the count it implies.
pub const MAX_CELLS: usize = 1 << 24;

/// A height model: mean height a cell, NaN where no point fell.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightGrid {
    /// x, y of the lower corner, in the cloud's frame (relative to its
    /// origin).
    pub corner: [f64; 2],
    /// Cell edge.
    pub cell: f64,
    /// Cells along x and y.
    pub size: [usize; 2],
    /// Height of each cell, row-major (x fastest); NaN for a hole.
    pub z: Vec<f64>,
    /// Points in each cell.
    pub count: Vec<u32>,
}

/// What a height model is, in a job's summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridSummary {
    /// Cell edge (the cloud's unit).
    pub cell_m: f64,
    /// Cells along x and y.
    pub size: [usize; 2],
    /// Cells with no point (holes).
    pub holes: usize,
    /// Holes over all cells.
    pub hole_share: f64,
    /// RMS of the points' heights less the model's (bilinear), the
    /// cloud's unit.
    pub rms_residual_m: f64,
    /// Largest such difference.
    pub max_residual_m: f64,
}

/// Fill and cut between two height models over the cells both have.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Change {
    /// Volume where the later scan is higher.
    pub fill_m3: f64,
    /// Volume where it is lower.
    pub cut_m3: f64,
    /// Fill less cut.
    pub net_m3: f64,
    /// Cells both models have.
    pub cells_compared: usize,
}

impl HeightGrid {
    /// The model of `cloud` on cells `cell` wide over its x–y bounds
    /// (refused past [`MAX_CELLS`]).
    pub fn of(cloud: &PointCloud, cell: f64) -> Result<Self> {
        let (lo, hi) = cloud.bounds().ok_or(SurfaceError::NoFinitePoints {
            non_finite_dropped: 0,
        })?;
        let lo = [f64::from(lo[0]), f64::from(lo[1])];
        let hi = [f64::from(hi[0]), f64::from(hi[1])];
        Self::over(cloud, lo, hi, cell)
    }

    /// The model of `cloud` on the cells of `like` (the same corner, cell
    /// and size), for comparing two scans cell by cell.
    pub fn like(cloud: &PointCloud, like: &HeightGrid) -> Result<Self> {
        let mut g = Self::empty(like.corner, like.cell, like.size);
        g.fill(cloud);
        Ok(g)
    }

    fn over(cloud: &PointCloud, lo: [f64; 2], hi: [f64; 2], cell: f64) -> Result<Self> {
        if !(cell.is_finite() && cell > 0.0) {
            return Err(SurfaceError::BadParameter {
                name: "height model cell",
                value: cell,
                expected: "a finite length > 0",
            });
        }
        let size = [0, 1].map(|a| (((hi[a] - lo[a]) / cell).floor() as usize).saturating_add(1));
        let cells = size[0].saturating_mul(size[1]);
        if cells > MAX_CELLS {
            return Err(SurfaceError::TooMuchWork {
                key: "[model] cell_spacings".into(),
                value: autoshovel_core::config::short(cell),
                estimate: format!(
                    "{} × {} = {} cells over the scan's {} × {} extent",
                    size[0],
                    size[1],
                    autoshovel_core::config::approx(cells as f64),
                    autoshovel_core::config::approx(hi[0] - lo[0]),
                    autoshovel_core::config::approx(hi[1] - lo[1])
                ),
                ceiling: format!(
                    "{} cells",
                    autoshovel_core::config::approx(MAX_CELLS as f64)
                ),
            });
        }
        let mut g = Self::empty(lo, cell, size);
        g.fill(cloud);
        Ok(g)
    }

    fn empty(corner: [f64; 2], cell: f64, size: [usize; 2]) -> Self {
        let cells = size[0] * size[1];
        Self {
            corner,
            cell,
            size,
            z: vec![f64::NAN; cells],
            count: vec![0; cells],
        }
    }

    fn fill(&mut self, cloud: &PointCloud) {
        let mut sum = vec![0.0_f64; self.z.len()];
        for p in &cloud.points {
            if let Some(i) = self.cell_of(f64::from(p[0]), f64::from(p[1])) {
                sum[i] += f64::from(p[2]);
                self.count[i] += 1;
            }
        }
        for (i, s) in sum.into_iter().enumerate() {
            if self.count[i] > 0 {
                self.z[i] = s / f64::from(self.count[i]);
            }
        }
    }

    /// The cell holding (x, y), if inside.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<usize> {
        let ix = ((x - self.corner[0]) / self.cell).floor();
        let iy = ((y - self.corner[1]) / self.cell).floor();
        (ix >= 0.0 && iy >= 0.0 && (ix as usize) < self.size[0] && (iy as usize) < self.size[1])
            .then(|| iy as usize * self.size[0] + ix as usize)
    }

    /// Cells with no point.
    pub fn holes(&self) -> usize {
        self.count.iter().filter(|&&c| c == 0).count()
    }

    /// The model's height at (x, y): bilinear between the four nearest
    /// cell centres that are not holes (weights renormalised over those
    /// present), the cell's own where none of the four is present.
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let fx = (x - self.corner[0]) / self.cell - 0.5;
        let fy = (y - self.corner[1]) / self.cell - 0.5;
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let (mut sum, mut weight) = (0.0, 0.0);
        for (dx, dy, w) in [
            (0.0, 0.0, (1.0 - tx) * (1.0 - ty)),
            (1.0, 0.0, tx * (1.0 - ty)),
            (0.0, 1.0, (1.0 - tx) * ty),
            (1.0, 1.0, tx * ty),
        ] {
            let (ix, iy) = (x0 + dx, y0 + dy);
            if ix < 0.0 || iy < 0.0 {
                continue;
            }
            let (ix, iy) = (ix as usize, iy as usize);
            if ix >= self.size[0] || iy >= self.size[1] {
                continue;
            }
            let z = self.z[iy * self.size[0] + ix];
            if z.is_finite() && w > 0.0 {
                sum += w * z;
                weight += w;
            }
        }
        if weight > 0.0 {
            sum / weight
        } else {
            self.cell_of(x, y).map_or(f64::NAN, |i| self.z[i])
        }
    }

    /// The model's summary, its residuals measured on `cloud`.
    pub fn summary(&self, cloud: &PointCloud) -> GridSummary {
        use rayon::prelude::*;
        // In parallel chunks, summed in chunk order: the same sums on any
        // number of threads.
        let parts: Vec<(f64, f64, usize)> = cloud
            .points
            .par_chunks(1 << 14)
            .map(|chunk| {
                let (mut sum2, mut max, mut n) = (0.0_f64, 0.0_f64, 0_usize);
                for p in chunk {
                    let d = f64::from(p[2]) - self.height(f64::from(p[0]), f64::from(p[1]));
                    if d.is_finite() {
                        sum2 += d * d;
                        max = max.max(d.abs());
                        n += 1;
                    }
                }
                (sum2, max, n)
            })
            .collect();
        let (sum2, max, n) = parts.into_iter().fold((0.0, 0.0_f64, 0), |a, b| {
            (a.0 + b.0, a.1.max(b.1), a.2 + b.2)
        });
        let holes = self.holes();
        GridSummary {
            cell_m: self.cell,
            size: self.size,
            holes,
            hole_share: holes as f64 / self.z.len().max(1) as f64,
            rms_residual_m: (sum2 / n.max(1) as f64).sqrt(),
            max_residual_m: max,
        }
    }

    /// Volume above the height `base` (the cloud's frame): each cell's
    /// height above it times the cell's area; holes add nothing.
    pub fn volume_above(&self, base: f64) -> f64 {
        let area = self.cell * self.cell;
        self.z
            .iter()
            .filter(|z| z.is_finite())
            .map(|z| (z - base).max(0.0) * area)
            .sum()
    }

    /// Fill and cut from `before` to this model (the same cells: made with
    /// [`HeightGrid::like`]), over the cells both saw.
    pub fn change_from(&self, before: &HeightGrid) -> Change {
        let area = self.cell * self.cell;
        let (mut fill, mut cut, mut cells) = (0.0, 0.0, 0);
        for (a, b) in self.z.iter().zip(&before.z) {
            if a.is_finite() && b.is_finite() {
                let d = (a - b) * area;
                if d > 0.0 {
                    fill += d;
                } else {
                    cut -= d;
                }
                cells += 1;
            }
        }
        Change {
            fill_m3: fill,
            cut_m3: cut,
            net_m3: fill - cut,
            cells_compared: cells,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_cloud(f: impl Fn(f64, f64) -> f64, n: usize, step: f64) -> PointCloud {
        let mut pts = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (i as f64 * step, j as f64 * step);
                pts.push([x as f32, y as f32, f(x, y) as f32]);
            }
        }
        PointCloud::new(pts)
    }

    #[test]
    fn a_plane_has_no_residual_and_its_prism_volume() {
        // z = 1 + 0.2 x on [0, 9.9]²: every cell of 1 holds 10 × 10 points.
        let c = grid_cloud(|x, _| 1.0 + 0.2 * x, 100, 0.1);
        let g = HeightGrid::of(&c, 1.0).unwrap();
        assert_eq!(g.size, [10, 10]);
        assert_eq!(g.holes(), 0);
        let s = g.summary(&c);
        // Bilinear between cell means of a plane is the plane, inside the
        // outer half-cells; at the rim the nearest centres extrapolate flat.
        assert!(s.rms_residual_m < 0.05, "{s:?}");
        // Cell means are the plane at the cells' centres: the volume above
        // 0 over the 10 × 10 area is 10 · Σ(1 + 0.2 x_c) = 100 + 2·10·Σ x_c/10.
        let want: f64 = (0..10)
            .map(|i| (1.0 + 0.2 * (i as f64 + 0.45)) * 10.0)
            .sum();
        assert!(
            (g.volume_above(0.0) - want).abs() < 1e-3,
            "{}",
            g.volume_above(0.0)
        );
    }

    #[test]
    fn holes_are_counted_and_add_no_volume_and_change_is_fill_less_cut() {
        let before = grid_cloud(|_, _| 0.0, 50, 0.2);
        let mut after = grid_cloud(|x, _| if x < 5.0 { 1.0 } else { -0.5 }, 50, 0.2);
        // A hole: drop the points of one cell.
        after.points.retain(|p| !(p[0] < 1.0 && p[1] < 1.0));
        let b = HeightGrid::of(&before, 1.0).unwrap();
        let a = HeightGrid::like(&after, &b).unwrap();
        assert_eq!(a.holes(), 1);
        let ch = a.change_from(&b);
        assert_eq!(ch.cells_compared, b.z.len() - 1);
        // 49 of the 50 cells on the raised side (one a hole) up by 1 m, the
        // other 50 down by 0.5 m; cells of 1 m².
        assert!((ch.fill_m3 - 49.0).abs() < 1e-6, "{ch:?}");
        assert!((ch.cut_m3 - 25.0).abs() < 1e-6, "{ch:?}");
        assert!((ch.net_m3 - 24.0).abs() < 1e-6);
        // A finer cell than the ceiling allows is refused with the count.
        let e = HeightGrid::of(&before, 1e-6).unwrap_err().to_string();
        assert!(e.contains("cells"), "{e}");
    }
}
