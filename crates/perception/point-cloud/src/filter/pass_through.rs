//! Pass-through filter: keep the points whose coordinate on one axis lies in
//! `[min, max]` (or outside it). The rope-shovel paper (§3.2, first step of
//! the combined filtering process) uses it to strip the ground after the
//! horizontal calibration of [RS eq. 11]–[RS eq. 12]: a point with z below the height
//! threshold is ground and is discarded, one with z at or above it is kept.
//!
//! Semantics of PCL 1.13's `pcl::PassThrough<PointT>::applyFilterIndices`
//! (`filters/include/pcl/filters/impl/passthrough.hpp`):
//! - a point with a non-finite coordinate is always removed;
//! - the limits are stored as f32 (`setFilterLimits (const float&, const float&)`)
//!   and compared with the f32 coordinate;
//! - `keep_inside` (PCL's `!negative_`) keeps `min <= v <= max`: points on a
//!   limit are kept;
//! - `!keep_inside` keeps exactly the complement, `v < min || v > max`.
//!
//! PCL's `PassThrough<PCLPointCloud2>` (used by the `pcl_passthrough_filter`
//! tool) differs in the negative mode only: it removes the open interval
//! `min < v < max`, so it also keeps points lying exactly on a limit. We keep
//! the complement of the positive mode, as `PassThrough<PointT>` does.
//! Open3D has no pass-through; its `crop(AxisAlignedBoundingBox)` keeps the
//! closed box too.

use autoshovel_core::config::short;
use rayon::prelude::*;

use super::common::{bad, emptied, empty_input, is_finite};
use crate::{Point, PointCloud, Result};

const FILTER: &str = "pass-through";

/// A coordinate axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z (up after the calibration of [RS eq. 11]–[RS eq. 12]).
    #[default]
    Z,
}

impl Axis {
    fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

/// Parameters of [`pass_through`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassThroughParams {
    /// The axis filtered on.
    pub axis: Axis,
    /// Lower limit (m), inclusive; may be `-inf`.
    pub min_m: f64,
    /// Upper limit (m), inclusive; may be `+inf`.
    pub max_m: f64,
    /// Keep the points inside `[min_m, max_m]` (true) or outside it (false).
    pub keep_inside: bool,
}

impl Default for PassThroughParams {
    /// The paper's ground removal, keep z ≥ threshold. The paper does not
    /// give the threshold: 0.1 m (documented choice) clears a calibrated
    /// floor with a few centimetres of range noise on a full-size machine.
    fn default() -> Self {
        Self::ground_removal(0.1)
    }
}

impl PassThroughParams {
    /// Ground removal as in the paper: keep `z >= threshold_m`.
    pub fn ground_removal(threshold_m: f64) -> Self {
        Self {
            axis: Axis::Z,
            min_m: threshold_m,
            max_m: f64::INFINITY,
            keep_inside: true,
        }
    }

    /// The limits as PCL stores them (f32), validated.
    fn limits(&self) -> Result<(f32, f32)> {
        if self.min_m.is_nan() || self.max_m.is_nan() {
            return Err(bad(
                FILTER,
                format!(
                    "limits must be numbers, got min_m = {}, max_m = {}",
                    self.min_m, self.max_m
                ),
            ));
        }
        if self.min_m > self.max_m {
            return Err(bad(
                FILTER,
                format!(
                    "min_m = {} is above max_m = {}",
                    short(self.min_m),
                    short(self.max_m)
                ),
            ));
        }
        Ok((self.min_m as f32, self.max_m as f32))
    }
}

/// The test of a point, with the limits already in f32.
#[derive(Debug, Clone, Copy)]
struct Limits {
    axis: usize,
    lo: f32,
    hi: f32,
    keep_inside: bool,
}

impl Limits {
    fn of(params: &PassThroughParams) -> Result<Self> {
        let (lo, hi) = params.limits()?;
        Ok(Self {
            axis: params.axis.index(),
            lo,
            hi,
            keep_inside: params.keep_inside,
        })
    }

    /// Whether `p` passes.
    #[inline]
    fn passes(&self, p: &Point) -> bool {
        if !is_finite(p) {
            return false;
        }
        let v = p[self.axis];
        let inside = v >= self.lo && v <= self.hi;
        inside == self.keep_inside
    }

    /// Whether any of the [`BLOCK`] points of `block` (their coordinates
    /// in a row) may pass: false only when none does. The coordinate on
    /// the axis alone is tested, every lane at once (lanes of the other
    /// axes masked out), so that a run of points that all fail (a scan
    /// cut far from most of it) is passed over at the speed of reading.
    #[inline]
    fn may_pass_any(&self, block: &[f32], on_axis: &[bool; 3 * BLOCK]) -> bool {
        let mut any = false;
        for (&v, &on) in block.iter().zip(on_axis) {
            let inside = (v >= self.lo) & (v <= self.hi);
            any |= on & (inside == self.keep_inside);
        }
        any
    }
}

/// Points a block of [`Limits::may_pass_any`] tests at once.
const BLOCK: usize = 16;

/// Indices of the points that pass, in input order.
pub fn pass_through_indices(cloud: &[Point], params: &PassThroughParams) -> Result<Vec<usize>> {
    let limits = Limits::of(params)?;
    if cloud.is_empty() {
        return Err(empty_input(FILTER));
    }
    let kept = compact(cloud, &limits, |i, _| i);
    if kept.is_empty() {
        return Err(emptied(FILTER, cloud.len(), HINT));
    }
    Ok(kept)
}

const HINT: &str = "widen [min_m, max_m], check the axis, or flip keep_inside";

/// The points that pass, in input order.
///
/// ```
/// use autoshovel_point_cloud::{filter, PointCloud};
/// let cloud = PointCloud::new(vec![[0.0, 0.0, 0.05], [0.0, 0.0, 0.1], [0.0, 0.0, 2.0]]);
/// let kept = filter::pass_through(&cloud, &filter::PassThroughParams::ground_removal(0.1)).unwrap();
/// assert_eq!(kept.points, vec![[0.0, 0.0, 0.1], [0.0, 0.0, 2.0]]);
/// ```
pub fn pass_through(cloud: &[Point], params: &PassThroughParams) -> Result<PointCloud> {
    let limits = Limits::of(params)?;
    if cloud.is_empty() {
        return Err(empty_input(FILTER));
    }
    let points = compact(cloud, &limits, |_, p| *p);
    if points.is_empty() {
        return Err(emptied(FILTER, cloud.len(), HINT));
    }
    Ok(PointCloud::new(points))
}

/// Points per task of [`compact`].
const CHUNK: usize = 1 << 15;

/// `out(i, p)` for the points `p` (at index `i`) that pass `limits`, in
/// input order. Each task writes its chunk's survivors, branch-free, to
/// the start of the chunk's own range of the output; the ranges are then
/// closed up in order. The output is never zeroed first (that was a serial
/// pass over all of it, a fifth of the filter's time at 1 M). A block of
/// points none of which can pass is passed over.
fn compact<T, O>(points: &[Point], limits: &Limits, out: O) -> Vec<T>
where
    T: Copy + Send + Sync,
    O: Fn(usize, &Point) -> T + Sync,
{
    let on_axis: [bool; 3 * BLOCK] = std::array::from_fn(|k| k % 3 == limits.axis);
    let mut result: Vec<T> = Vec::with_capacity(points.len());
    let counts: Vec<usize> = result.spare_capacity_mut()[..points.len()]
        .par_chunks_mut(CHUNK)
        .zip(points.par_chunks(CHUNK))
        .enumerate()
        .map(|(chunk, (dst, src))| {
            crate::prefault::populate(dst);
            let mut n = 0;
            for (b, block) in src.chunks(BLOCK).enumerate() {
                if block.len() == BLOCK && !limits.may_pass_any(block.as_flattened(), &on_axis) {
                    continue;
                }
                let first = chunk * CHUNK + b * BLOCK;
                for (j, p) in block.iter().enumerate() {
                    dst[n].write(out(first + j, p));
                    n += usize::from(limits.passes(p));
                }
            }
            n
        })
        .collect();
    let spare = result.spare_capacity_mut();
    let mut kept = 0;
    for (chunk, &count) in counts.iter().enumerate() {
        spare.copy_within(chunk * CHUNK..chunk * CHUNK + count, kept);
        kept += count;
    }
    // SAFETY: each chunk wrote its `count` survivors at the start of its
    // range, and those were copied, in order, to `..kept`.
    unsafe { result.set_len(kept) };
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter against a point-by-point pass, on clouds with runs of
    /// points that all fail (whole blocks passed over), runs that all
    /// pass, lone survivors, and non-finite coordinates on and off the
    /// axis, every axis, both modes, limits open and closed.
    #[test]
    fn blocks_passed_over_lose_no_point() {
        let mut state = 5u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut points: Vec<Point> = Vec::new();
        for run in 0..400 {
            let len = 1 + (next() * 40.0) as usize;
            for _ in 0..len {
                let v = match run % 4 {
                    0 => -1.0 - next(), // fails
                    1 => next(),        // passes
                    2 if next() < 0.05 => next(),
                    _ => -1.0 - next(),
                };
                let mut p = [next(), next(), next()];
                p[run % 3] = v;
                if next() < 0.01 {
                    p[(run / 3) % 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY][run % 3];
                }
                points.push(p);
            }
        }
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            for keep_inside in [true, false] {
                for (min_m, max_m) in [(0.0, 1.0), (0.0, f64::INFINITY), (-0.5, 0.5)] {
                    let params = PassThroughParams {
                        axis,
                        min_m,
                        max_m,
                        keep_inside,
                    };
                    let limits = Limits::of(&params).unwrap();
                    let want: Vec<usize> = (0..points.len())
                        .filter(|&i| limits.passes(&points[i]))
                        .collect();
                    let got = pass_through_indices(&points, &params).unwrap();
                    assert_eq!(got, want, "{params:?}");
                }
            }
        }
    }
}
