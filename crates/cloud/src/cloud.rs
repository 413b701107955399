//! The point cloud type: positions only, in metres.

/// One point [m].
pub type Point = [f32; 3];

/// A cloud of points [m]. Non-finite points never enter one: readers drop
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
/// none), non-finite coordinates passed over; the cloud's parts in
/// parallel (a serial pass was 6 ms of a 1 M-point `perceive`).
pub fn bounds(points: &[Point]) -> Option<(Point, Point)> {
    use rayon::prelude::*;
    if points.is_empty() {
        return None;
    }
    let none = || ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    Some(
        points
            .par_iter()
            .fold(none, |(mut lo, mut hi), p| {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
                (lo, hi)
            })
            .reduce(none, |(l1, h1), (l2, h2)| {
                (
                    std::array::from_fn(|a| l1[a].min(l2[a])),
                    std::array::from_fn(|a| h1[a].max(h2[a])),
                )
            }),
    )
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
        }
    }
}
