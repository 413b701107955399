//! The 8 × 8 sample grid of the rope-shovel paper §3.2: "eight points with
//! equal intervals were selected in the X axial direction of the point cloud
//! and another eight points with equal intervals in the Y axial direction",
//! 64 points for the fit of [RS eq. 21].
//!
//! The paper does not say how a grid node gets its height; this is the
//! documented choice:
//!
//! - **Extent.** The x and y range of the cloud, trimmed by
//!   [`SampleParams::trim_fraction`] of the points at each end so that a few
//!   isolated outliers do not stretch the grid (or an explicit [`Extent`]).
//! - **Nodes.** The extent is cut into nx × ny equal cells; the nodes are the
//!   cell centres, so they are equally spaced (spacing Δx = range/nx) and lie
//!   Δx/2 inside the extent.
//! - **Height.** Of the points in a node's cell, the
//!   [`SampleParams::neighbours`] nearest to the node in (x, y) are taken. A
//!   local plane through them gives the height: its slope by least squares,
//!   its height by the **median** of the slope-corrected z, with the points
//!   beyond 3 robust standard deviations dropped first (from a plain median,
//!   then from the plane, before the final fit). This is
//!   exact on a plane, robust to the few per cent of outliers a filtered scan
//!   still holds, and, unlike a plain median of z, not biased by the slope
//!   when the neighbours sit unevenly around the node. On a curved surface
//!   it is biased by about ½ f'' · r² (r: the neighbourhood radius).
//! - **Where.** At the node when its neighbours surround it (their centroid
//!   within half their RMS radius of it); at the edge of the data (the toe
//!   after the floor is cut away, a ragged side) at the neighbours'
//!   centroid, so the height is not extrapolated to a node with no data
//!   under it. Such a sample is not exactly on the equally spaced grid.
//! - **Empty cells** (fewer than [`SampleParams::min_cell_points`] points, or
//!   than [`SampleParams::min_cell_share`] of the median non-empty cell's
//!   count: stray points, not a surface) are skipped: a fit may use fewer
//!   than 64 samples.

use autoshovel_point_cloud::PointCloud;
use rayon::prelude::*;

use crate::error::{Result, SurfaceError};

/// A rectangle in the (x, y) plane (m).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Extent {
    /// Smallest x (m).
    pub x_min_m: f64,
    /// Largest x (m).
    pub x_max_m: f64,
    /// Smallest y (m).
    pub y_min_m: f64,
    /// Largest y (m).
    pub y_max_m: f64,
}

impl Extent {
    /// Whether (x, y) lies inside (edges included).
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x_min_m && x <= self.x_max_m && y >= self.y_min_m && y <= self.y_max_m
    }

    /// Width along x (m).
    pub fn x_span_m(&self) -> f64 {
        self.x_max_m - self.x_min_m
    }

    /// Width along y (m).
    pub fn y_span_m(&self) -> f64 {
        self.y_max_m - self.y_min_m
    }
}

/// How the grid samples are taken (see the module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SampleParams {
    /// Nodes along x and y. Default `[8, 8]` (paper §3.2).
    pub grid: [usize; 2],
    /// Points nearest to a node that give its height. Default 25.
    pub neighbours: usize,
    /// Fewest points in a cell for it to give a sample. Default 3.
    pub min_cell_points: usize,
    /// Fewest points in a cell as a share of the median count of the
    /// non-empty cells, in [0, 1): sparser cells hold only stray points (e.g.
    /// dust above the floor after the pass-through) and are skipped.
    /// Default 0.05.
    pub min_cell_share: f64,
    /// Share of the points ignored at each end of x and of y when finding
    /// the extent, in [0, 0.25). Default 0.005.
    pub trim_fraction: f64,
    /// Use this extent instead of the cloud's. Default `None`.
    pub extent: Option<Extent>,
}

impl Default for SampleParams {
    fn default() -> Self {
        Self {
            grid: [8, 8],
            neighbours: 25,
            min_cell_points: 3,
            min_cell_share: 0.05,
            trim_fraction: 0.005,
            extent: None,
        }
    }
}

impl SampleParams {
    /// Check the ranges once, at the edge.
    pub fn validate(&self) -> Result<()> {
        for (name, n) in [
            ("SampleParams.grid[0]", self.grid[0]),
            ("SampleParams.grid[1]", self.grid[1]),
        ] {
            if n < 2 {
                return Err(SurfaceError::BadParameter {
                    name,
                    value: n as f64,
                    expected: "at least 2 nodes",
                });
            }
        }
        if self.neighbours == 0 {
            return Err(SurfaceError::BadParameter {
                name: "SampleParams.neighbours",
                value: 0.0,
                expected: "at least 1",
            });
        }
        if self.min_cell_points == 0 {
            return Err(SurfaceError::BadParameter {
                name: "SampleParams.min_cell_points",
                value: 0.0,
                expected: "at least 1",
            });
        }
        if !(self.min_cell_share >= 0.0 && self.min_cell_share < 1.0) {
            return Err(SurfaceError::BadParameter {
                name: "SampleParams.min_cell_share",
                value: self.min_cell_share,
                expected: "a share in [0, 1)",
            });
        }
        if !(self.trim_fraction >= 0.0 && self.trim_fraction < 0.25) {
            return Err(SurfaceError::BadParameter {
                name: "SampleParams.trim_fraction",
                value: self.trim_fraction,
                expected: "a share in [0, 0.25)",
            });
        }
        if let Some(e) = self.extent {
            if !(e.x_span_m() > 0.0 && e.y_span_m() > 0.0) {
                return Err(SurfaceError::BadParameter {
                    name: "SampleParams.extent",
                    value: e.x_span_m().min(e.y_span_m()),
                    expected: "a rectangle of positive width in x and y",
                });
            }
        }
        Ok(())
    }
}

/// One grid sample.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GridSample {
    /// Node column (0-based, along x).
    pub ix: usize,
    /// Node row (0-based, along y).
    pub iy: usize,
    /// x of the sample (m) (the node's, or the centroid of its points near an edge).
    pub x_m: f64,
    /// y of the sample (m).
    pub y_m: f64,
    /// Height: robust local plane through the points used (m).
    pub z_m: f64,
    /// Points used.
    pub points: usize,
}

/// The samples of a cloud and the extent they were taken over.
#[derive(Debug, Clone, PartialEq)]
pub struct Samples {
    /// The extent of the grid.
    pub extent: Extent,
    /// Up to nx · ny samples, row by row (iy, then ix).
    pub samples: Vec<GridSample>,
}

/// Take the grid samples of a cloud (see the module docs).
pub fn sample_grid(cloud: &PointCloud, params: &SampleParams) -> Result<Samples> {
    params.validate()?;
    if cloud.is_empty() {
        return Err(SurfaceError::TooFewPoints {
            stage: "surface sampling",
            points: 0,
            required: 1,
            hint: "",
        });
    }
    let extent = match params.extent {
        Some(e) => e,
        None => trimmed_extent(cloud, params.trim_fraction),
    };
    if !(extent.x_span_m() > 0.0 && extent.y_span_m() > 0.0) {
        return Err(SurfaceError::BadParameter {
            name: "cloud extent",
            value: extent.x_span_m().min(extent.y_span_m()),
            expected: "points spread over an area in x and y",
        });
    }
    let [nx, ny] = params.grid;
    let dx = extent.x_span_m() / nx as f64;
    let dy = extent.y_span_m() / ny as f64;
    let mut cells: Vec<Vec<[f64; 3]>> = vec![Vec::new(); nx * ny];
    for p in &cloud.points {
        let (x, y) = (f64::from(p[0]), f64::from(p[1]));
        if !extent.contains(x, y) {
            continue;
        }
        let ix = (((x - extent.x_min_m) / dx) as usize).min(nx - 1);
        let iy = (((y - extent.y_min_m) / dy) as usize).min(ny - 1);
        cells[iy * nx + ix].push([x, y, f64::from(p[2])]);
    }
    let mut counts: Vec<usize> = cells.iter().map(Vec::len).filter(|&c| c > 0).collect();
    let median_count = if counts.is_empty() {
        0
    } else {
        let mid = counts.len() / 2;
        *counts.select_nth_unstable(mid).1
    };
    let min_points = params
        .min_cell_points
        .max((params.min_cell_share * median_count as f64).ceil() as usize);
    // The cells one by one in parallel (each its own nearest and robust
    // height), in their order.
    let samples: Vec<GridSample> = cells
        .par_iter_mut()
        .enumerate()
        .filter_map(|(c, cell)| {
            let (ix, iy) = (c % nx, c / nx);
            if cell.len() < min_points {
                return None;
            }
            let node_x = extent.x_min_m + (ix as f64 + 0.5) * dx;
            let node_y = extent.y_min_m + (iy as f64 + 0.5) * dy;
            let d2 = |p: &[f64; 3]| (p[0] - node_x).powi(2) + (p[1] - node_y).powi(2);
            let k = params.neighbours.min(cell.len());
            if k < cell.len() {
                cell.select_nth_unstable_by(k - 1, |a, b| d2(a).total_cmp(&d2(b)));
            }
            let near = &cell[..k];
            let (x_m, y_m) = evaluation_point(near, node_x, node_y);
            let z_m = robust_local_height(near, x_m, y_m);
            Some(GridSample {
                ix,
                iy,
                x_m,
                y_m,
                z_m,
                points: k,
            })
        })
        .collect();
    Ok(Samples { extent, samples })
}

/// Where a node's height is evaluated: the node itself when its neighbours
/// surround it (their centroid lies within half their RMS radius of it), else
/// their centroid, so that the height is not extrapolated off the data.
fn evaluation_point(near: &[[f64; 3]], node_x: f64, node_y: f64) -> (f64, f64) {
    let k = near.len() as f64;
    let cx = near.iter().map(|p| p[0]).sum::<f64>() / k;
    let cy = near.iter().map(|p| p[1]).sum::<f64>() / k;
    let rms_radius = (near
        .iter()
        .map(|p| (p[0] - cx).powi(2) + (p[1] - cy).powi(2))
        .sum::<f64>()
        / k)
        .sqrt();
    if (cx - node_x).hypot(cy - node_y) <= 0.5 * rms_radius {
        (node_x, node_y)
    } else {
        (cx, cy)
    }
}

/// Height of the points at (x0, y0): a local plane `z = a + b·dx + c·dy`
/// (dx = x − x0, dy = y − y0), robustly. Round 0 takes b = c = 0 (a plain
/// median of z), rounds 1 and 2 the least-squares slope of the points kept;
/// each round sets `a = median(z − b·dx − c·dy)` and drops the points further
/// than 3 robust standard deviations (1.4826 · MAD) from it. Exact for points
/// on a plane, unmoved by a minority of outliers in z, and free of the slope
/// bias a plain median of z has when the neighbours do not sit symmetrically
/// about (x0, y0).
fn robust_local_height(near: &[[f64; 3]], x0: f64, y0: f64) -> f64 {
    let mut kept: Vec<[f64; 3]> = near.iter().map(|p| [p[0] - x0, p[1] - y0, p[2]]).collect();
    let mut a = 0.0;
    for round in 0..3 {
        let (b, c) = if round == 0 {
            (0.0, 0.0)
        } else {
            plane_slope(&kept)
        };
        let r: Vec<f64> = kept.iter().map(|p| p[2] - b * p[0] - c * p[1]).collect();
        a = median(&mut r.clone());
        if round == 2 {
            break;
        }
        let mut dev: Vec<f64> = r.iter().map(|v| (v - a).abs()).collect();
        let limit = (3.0 * 1.4826 * median(&mut dev)).max(1e-6 * (1.0 + a.abs()));
        let filtered: Vec<[f64; 3]> = kept
            .iter()
            .zip(&r)
            .filter(|(_, v)| (*v - a).abs() <= limit)
            .map(|(p, _)| *p)
            .collect();
        if filtered.len() >= 3 {
            kept = filtered;
        }
    }
    a
}

/// Least-squares slope (b, c) of `z = a + b·x + c·y`; (0, 0) when the points
/// do not span an area.
fn plane_slope(points: &[[f64; 3]]) -> (f64, f64) {
    let n = points.len() as f64;
    if points.len() < 3 {
        return (0.0, 0.0);
    }
    let mx = points.iter().map(|p| p[0]).sum::<f64>() / n;
    let my = points.iter().map(|p| p[1]).sum::<f64>() / n;
    let mz = points.iter().map(|p| p[2]).sum::<f64>() / n;
    let (mut sxx, mut sxy, mut syy, mut sxz, mut syz) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for p in points {
        let (dx, dy, dz) = (p[0] - mx, p[1] - my, p[2] - mz);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
        sxz += dx * dz;
        syz += dy * dz;
    }
    let det = sxx * syy - sxy * sxy;
    if det.is_nan() || det <= 1e-12 * (sxx * syy).max(f64::MIN_POSITIVE) {
        return (0.0, 0.0);
    }
    ((syy * sxz - sxy * syz) / det, (sxx * syz - sxy * sxz) / det)
}

fn median(v: &mut [f64]) -> f64 {
    let k = v.len();
    v.sort_unstable_by(f64::total_cmp);
    if k % 2 == 1 {
        v[k / 2]
    } else {
        0.5 * (v[k / 2 - 1] + v[k / 2])
    }
}

/// The x and y range of a cloud without the `trim` share of points at each end.
fn trimmed_extent(cloud: &PointCloud, trim: f64) -> Extent {
    let n = cloud.len();
    let lo = ((trim * n as f64).floor() as usize).min(n - 1);
    let hi = (n - 1).saturating_sub(lo).max(lo);
    let range = |k: usize| {
        let mut v: Vec<f32> = cloud.points.iter().map(|p| p[k]).collect();
        if lo == 0 && hi == n - 1 {
            let min = v.iter().copied().fold(f32::INFINITY, f32::min);
            let max = v.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            return (f64::from(min), f64::from(max));
        }
        let min = *v.select_nth_unstable_by(lo, f32::total_cmp).1;
        let max = *v.select_nth_unstable_by(hi, f32::total_cmp).1;
        (f64::from(min), f64::from(max))
    };
    let (x_min_m, x_max_m) = range(0);
    let (y_min_m, y_max_m) = range(1);
    Extent {
        x_min_m,
        x_max_m,
        y_min_m,
        y_max_m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn plane_cloud(n_side: usize) -> PointCloud {
        let mut pts = Vec::new();
        for i in 0..n_side {
            for j in 0..n_side {
                let x = i as f64 / (n_side - 1) as f64 * 16.0;
                let y = j as f64 / (n_side - 1) as f64 * 8.0 - 4.0;
                pts.push([x as f32, y as f32, (0.5 * x - 0.25 * y + 1.0) as f32]);
            }
        }
        PointCloud::new(pts)
    }

    #[test]
    fn full_plane_gives_64_samples_at_the_cell_centres() {
        let s = sample_grid(
            &plane_cloud(161),
            &SampleParams {
                trim_fraction: 0.0,
                ..SampleParams::default()
            },
        )
        .unwrap();
        assert_eq!(s.samples.len(), 64);
        assert_relative_eq!(s.extent.x_max_m, 16.0, epsilon = 1e-5);
        for g in &s.samples {
            // At the node, exactly on the plane.
            assert_relative_eq!(g.x_m, 1.0 + 2.0 * g.ix as f64, epsilon = 1e-9);
            assert_relative_eq!(g.y_m, -3.5 + g.iy as f64, epsilon = 1e-9);
            assert_relative_eq!(g.z_m, 0.5 * g.x_m - 0.25 * g.y_m + 1.0, epsilon = 1e-5);
        }
    }

    #[test]
    fn empty_cells_are_skipped() {
        // An L-shaped cloud: the quarter x > 8, y > 0 is empty.
        let mut c = plane_cloud(161);
        c.points.retain(|p| !(p[0] >= 8.0 && p[1] >= 0.0));
        let params = SampleParams {
            trim_fraction: 0.0,
            ..SampleParams::default()
        };
        let s = sample_grid(&c, &params).unwrap();
        assert_eq!(s.samples.len(), 48);
        assert!(s.samples.iter().all(|g| !(g.ix >= 4 && g.iy >= 4)));
    }

    #[test]
    fn five_spikes_among_25_neighbours_do_not_move_a_sample() {
        let mut c = plane_cloud(161);
        // Raise five of the points nearest to the first node (1.0, −3.5) by up to 100 m.
        let near: Vec<usize> = c
            .points
            .iter()
            .enumerate()
            .filter(|(_, p)| (p[0] - 1.0).abs() < 0.11 && (p[1] + 3.5).abs() < 0.11)
            .map(|(i, _)| i)
            .take(5)
            .collect();
        assert_eq!(near.len(), 5);
        for (k, &i) in near.iter().enumerate() {
            c.points[i][2] += 20.0 * (k + 1) as f32;
        }
        let s = sample_grid(&c, &SampleParams::default()).unwrap();
        let g = s.samples[0];
        assert_relative_eq!(g.z_m, 0.5 * g.x_m - 0.25 * g.y_m + 1.0, epsilon = 1e-5);
    }

    #[test]
    fn a_line_of_points_has_no_area() {
        let c = PointCloud::new((0..10).map(|i| [i as f32, 0.0, 1.0]).collect());
        let err = sample_grid(&c, &SampleParams::default()).unwrap_err();
        assert!(matches!(
            err,
            SurfaceError::BadParameter {
                name: "cloud extent",
                ..
            }
        ));
    }
}
