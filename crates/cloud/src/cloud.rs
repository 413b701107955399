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
        let first = *self.points.first()?;
        let mut lo = first;
        let mut hi = first;
        for p in &self.points {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        Some((lo, hi))
    }
}
