//! The point cloud type: positions only, in metres.

/// One point (m).
pub type Point = [f32; 3];

/// A cloud of points (m). Non-finite points never enter one: readers drop
/// and count them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    /// The points.
    pub points: Vec<Point>,
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
    /// A cloud of these points.
    pub fn new(points: Vec<Point>) -> Self {
        Self { points }
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
