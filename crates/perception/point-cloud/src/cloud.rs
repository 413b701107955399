//! The point cloud type: positions as f32 offsets from an f64 origin, the
//! attributes as columns, and what the file said of its coordinates.

use crate::attributes::Attributes;
use crate::georef::Georef;

/// One point, relative to its cloud's origin (m, or the CRS's unit).
pub type Point = [f32; 3];

/// A cloud of points. A point's coordinates in the file's frame are
/// `origin + point`, summed in f64: the origin (a whole number near the
/// middle of the data, chosen by the reader) keeps a survey's UTM
/// coordinates, whose northings in f32 would step by 0.5 m, to a small
/// fraction of a millimetre (f32 resolves 0.49 mm at 8 km from the origin;
/// [`PointCloud::precision`]). The filters work on `points` alone; the
/// origin, the attributes' rows and the georeference travel with them.
/// Non-finite points never enter a cloud: readers drop and count them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    /// The points, relative to `origin`.
    pub points: Vec<Point>,
    /// Added to every point in f64 to give the file's coordinates.
    pub origin: [f64; 3],
    /// Per-point attributes, each column as long as `points`.
    pub attributes: Attributes,
    /// The coordinate system and the file layout read, written back.
    pub georef: Georef,
}

/// A cloud reads as its slice of points: the filters take `&[Point]`, so a
/// cloud, a `Vec` or a borrowed buffer (a numpy array from Python) all go in
/// without a copy.
impl std::ops::Deref for PointCloud {
    type Target = [Point];

    fn deref(&self) -> &[Point] {
        &self.points
    }
}

impl PointCloud {
    /// A cloud of these points, at origin zero, with no attributes.
    pub fn new(points: Vec<Point>) -> Self {
        Self {
            points,
            ..Self::default()
        }
    }

    /// The rows `rows` of this cloud, in that order: the points and every
    /// attribute column, with the same origin and georeference (what a
    /// filter that drops points returns).
    pub fn select(&self, rows: &[usize]) -> PointCloud {
        use rayon::prelude::*;
        PointCloud {
            // In parallel: a stage of `perceive` keeps most of a 1 M-point
            // scan, and a serial copy of it was 3 ms of the ground stage.
            points: rows.par_iter().map(|&i| self.points[i]).collect(),
            origin: self.origin,
            attributes: self.attributes.select(rows),
            georef: self.georef.clone(),
        }
    }

    /// New points in this cloud's frame (same origin and georeference),
    /// each taking the attributes of the row `rows[i]` (a voxel's nearest
    /// point), or none when `rows` is `None`.
    pub fn derived(&self, points: Vec<Point>, rows: Option<&[usize]>) -> PointCloud {
        PointCloud {
            points,
            origin: self.origin,
            attributes: rows.map_or_else(Attributes::new, |r| self.attributes.select(r)),
            georef: self.georef.clone(),
        }
    }

    /// Point `i` in the file's frame (f64); about a zero origin the point
    /// itself (a −0 stays −0).
    pub fn world(&self, i: usize) -> [f64; 3] {
        let p = self.points[i];
        [0, 1, 2].map(|a| match self.origin[a] {
            0.0 => f64::from(p[a]),
            o => o + f64::from(p[a]),
        })
    }

    /// The largest rounding error of a coordinate held as f32 about the
    /// origin: half the f32 spacing at the largest offset (0 when empty).
    pub fn precision(&self) -> f64 {
        self.precision_axes().into_iter().fold(0.0, f64::max)
    }

    /// [`PointCloud::precision`] an axis at a time.
    pub fn precision_axes(&self) -> [f64; 3] {
        let Some((lo, hi)) = self.bounds() else {
            return [0.0; 3];
        };
        [0, 1, 2].map(|a| f64::from(half_ulp(lo[a].abs().max(hi[a].abs()))))
    }

    /// Where holding the points as f32 about the origin is coarser than
    /// half the step of the LAS file they came from, (axis, precision,
    /// step): what writing them back cannot keep to the file's own step.
    /// Empty for a cloud from any other format, and for every real survey
    /// in UTM at 1 mm steps up to 32 km across.
    pub fn coarser_than_file(&self) -> Vec<(char, f64, f64)> {
        let Some(las) = &self.georef.las else {
            return Vec::new();
        };
        let (p, s) = (self.precision_axes(), las.scale());
        (0..3)
            .filter(|&a| p[a] > s[a] / 2.0)
            .map(|a| (['x', 'y', 'z'][a], p[a], s[a]))
            .collect()
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Axis-aligned bounds (min, max), `None` when empty.
    pub fn bounds(&self) -> Option<(Point, Point)> {
        bounds(&self.points)
    }
}

/// Half the distance from `v` to the next f32 away from zero.
fn half_ulp(v: f32) -> f32 {
    let v = v.abs();
    if !v.is_finite() {
        return f32::INFINITY;
    }
    (f32::from_bits(v.to_bits() + 1) - v) / 2.0
}

/// The least and greatest coordinate on each axis of `points` (`None` for
/// none), NaN coordinates passed over (an infinite one is a bound); the
/// cloud's parts in parallel (a serial pass was 6 ms of a 1 M-point
/// `perceive`).
pub fn bounds(points: &[Point]) -> Option<(Point, Point)> {
    (!points.is_empty()).then(|| {
        let (lo, hi, _) = lane_bounds(points);
        (lo, hi)
    })
}

/// [`bounds`] of a non-empty cloud, and whether every coordinate is
/// finite. One pass over the coordinates as a flat array, 16 points a step
/// in lanes that vectorise (a point at a time did not: 3.5 ns a point, 45
/// ms of the 20 M pipeline's voxel stage and as much of its radius stage).
pub(crate) fn lane_bounds(points: &[Point]) -> (Point, Point, bool) {
    use rayon::prelude::*;
    const W: usize = 48; // 16 points; lane j holds axis j % 3
    let none = || ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], true);
    points
        .par_chunks(1 << 14)
        .map(|chunk| {
            let flat = chunk.as_flattened();
            let mut lo = [f32::INFINITY; W];
            let mut hi = [f32::NEG_INFINITY; W];
            let mut poison = [0.0_f32; W];
            let mut blocks = flat.chunks_exact(W);
            for b in &mut blocks {
                for j in 0..W {
                    lo[j] = lo[j].min(b[j]);
                    hi[j] = hi[j].max(b[j]);
                    // 0 · v is NaN for an infinite or NaN v, and stays so.
                    poison[j] += b[j] * 0.0;
                }
            }
            for (j, &v) in blocks.remainder().iter().enumerate() {
                lo[j] = lo[j].min(v);
                hi[j] = hi[j].max(v);
                poison[j] += v * 0.0;
            }
            let (mut l, mut h, _) = none();
            for j in 0..W {
                l[j % 3] = l[j % 3].min(lo[j]);
                h[j % 3] = h[j % 3].max(hi[j]);
            }
            (l, h, !poison.iter().any(|v| v.is_nan()))
        })
        .reduce(none, |(l1, h1, f1), (l2, h2, f2)| {
            (
                std::array::from_fn(|a| l1[a].min(l2[a])),
                std::array::from_fn(|a| h1[a].max(h2[a])),
                f1 && f2,
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_the_least_and_greatest_coordinates() {
        assert_eq!(PointCloud::default().bounds(), None);
        // Against a serial pass, on clouds of many sizes (the parallel
        // parts split differently), with the extremes anywhere.
        let mut state = 7_u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 200.0
        };
        for n in [1, 2, 3, 1000, 70_000, 300_001] {
            let cloud = PointCloud::new((0..n).map(|_| [next(), next(), next()]).collect());
            let mut lo = cloud.points[0];
            let mut hi = lo;
            for p in &cloud.points {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
            assert_eq!(cloud.bounds(), Some((lo, hi)), "{n} points");
            assert!(lane_bounds(&cloud.points).2);
        }
        // NaN is passed over, an infinity is a bound; neither is finite.
        for (at, bad) in [(0, f32::NAN), (1, f32::INFINITY), (2, f32::NEG_INFINITY)] {
            let mut points = vec![[1.0, 2.0, 3.0]; 100];
            points[37][at] = bad;
            let (lo, hi, finite) = lane_bounds(&points);
            assert!(!finite);
            let want = if bad.is_nan() { 1.0 + at as f32 } else { bad };
            assert_eq!(
                if bad > 0.0 { hi[at] } else { lo[at] },
                want,
                "{bad} at axis {at}"
            );
        }
    }
}
