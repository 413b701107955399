//! The world model of travel planning (SPEC §2): a rectangular site with
//! obstacles (circles and convex polygons: trucks, stockpiles, rocks) and road
//! boundaries (polylines). Every distance is to the element's *nearest point*,
//! never to its centre, so a long stockpile repels from its near edge.
//!
//! The machine is a disc of radius `footprint_radius_m` (at least its
//! half-width); clearance is the distance from that disc to the nearest element.

use autoshovel_core::{perp, segment_nearest, Vec2};

/// The shape of one obstacle.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A disc.
    Circle {
        /// Centre (m).
        center: Vec2,
        /// Radius (m).
        radius: f64,
    },
    /// A convex polygon, vertices counter-clockwise.
    Polygon {
        /// Vertices (m), counter-clockwise, without repeating the first.
        vertices: Vec<Vec2>,
    },
}

/// An obstacle: a named shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle {
    /// Name for messages and plots, e.g. "truck".
    pub name: String,
    /// Its shape.
    pub shape: Shape,
}

/// A road boundary: a polyline the machine must not cross or touch.
#[derive(Debug, Clone, PartialEq)]
pub struct Boundary {
    /// Name for messages and plots.
    pub name: String,
    /// Vertices (m).
    pub points: Vec<Vec2>,
}

/// The nearest point of one map element to a query point.
#[derive(Debug, Clone, Copy)]
pub struct Nearest {
    /// Signed distance from the query point to the element (m), negative inside.
    pub distance: f64,
    /// Unit direction in which the distance grows (away from the element).
    pub normal: Vec2,
    /// Which element: obstacles first, then boundaries, then the site edge.
    pub element: usize,
}

/// Why a polygon was refused.
#[derive(Debug, Clone, PartialEq)]
pub enum PolygonFault {
    /// Fewer than three vertices.
    TooFewVertices(usize),
    /// Two consecutive vertices coincide (index of the first).
    RepeatedVertex(usize),
    /// The turn at this vertex goes the other way: not convex.
    NotConvex(usize),
    /// Zero area (all vertices collinear).
    Degenerate,
}

impl std::fmt::Display for PolygonFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PolygonFault::TooFewVertices(n) => write!(f, "has {n} vertices, needs at least 3"),
            PolygonFault::RepeatedVertex(i) => write!(f, "repeats vertex {i} (0-based)"),
            PolygonFault::NotConvex(i) => write!(
                f,
                "is not convex: it turns the other way at vertex {i} (0-based)"
            ),
            PolygonFault::Degenerate => write!(f, "has zero area"),
        }
    }
}

/// Checks that `vertices` form a convex polygon and returns them
/// counter-clockwise.
pub fn convex_polygon(mut vertices: Vec<Vec2>) -> Result<Vec<Vec2>, PolygonFault> {
    let n = vertices.len();
    if n < 3 {
        return Err(PolygonFault::TooFewVertices(n));
    }
    for i in 0..n {
        if (vertices[(i + 1) % n] - vertices[i]).norm() < 1e-9 {
            return Err(PolygonFault::RepeatedVertex(i));
        }
    }
    let area2: f64 = (0..n)
        .map(|i| {
            let a = vertices[i];
            let b = vertices[(i + 1) % n];
            a.x * b.y - a.y * b.x
        })
        .sum();
    if area2.abs() < 1e-12 {
        return Err(PolygonFault::Degenerate);
    }
    if area2 < 0.0 {
        vertices.reverse();
    }
    for i in 0..n {
        let a = vertices[(i + n - 1) % n];
        let b = vertices[i];
        let c = vertices[(i + 1) % n];
        let cross = (b - a).x * (c - b).y - (b - a).y * (c - b).x;
        if cross < -1e-9 {
            return Err(PolygonFault::NotConvex(i));
        }
    }
    Ok(vertices)
}

impl Shape {
    /// Signed distance and outward direction from `p`.
    pub fn nearest(&self, p: Vec2) -> (f64, Vec2) {
        match self {
            Shape::Circle { center, radius } => {
                let d = p - center;
                let r = d.norm();
                let normal = if r > 1e-12 {
                    d / r
                } else {
                    Vec2::new(1.0, 0.0)
                };
                (r - radius, normal)
            }
            Shape::Polygon { vertices } => {
                // Squared distances in the loop, one square root at the end:
                // this runs for every obstacle at every descent step.
                let n = vertices.len();
                let mut best2 = f64::INFINITY;
                let mut best_q = vertices[0];
                let mut best_edge = 0;
                let mut inside = true;
                for i in 0..n {
                    let a = vertices[i];
                    let b = vertices[(i + 1) % n];
                    let e = b - a;
                    let ap = p - a;
                    if e.x * ap.y - e.y * ap.x < 0.0 {
                        inside = false;
                    }
                    let (q, _) = segment_nearest(p, a, b);
                    let d2 = (p - q).norm_squared();
                    if d2 < best2 {
                        best2 = d2;
                        best_q = q;
                        best_edge = i;
                    }
                }
                let best = best2.sqrt();
                let outward_edge = {
                    let e = vertices[(best_edge + 1) % n] - vertices[best_edge];
                    -perp(e).normalize()
                };
                if inside {
                    (-best, outward_edge)
                } else if best > 1e-12 {
                    (best, (p - best_q) / best)
                } else {
                    (0.0, outward_edge)
                }
            }
        }
    }

    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Vec2, Vec2) {
        match self {
            Shape::Circle { center, radius } => (
                center - Vec2::repeat(*radius),
                center + Vec2::repeat(*radius),
            ),
            Shape::Polygon { vertices } => bounds_of(vertices),
        }
    }
}

/// How much nearer than the footprint a segment's bounding box must come
/// before [`Map::is_clear`] computes the segment's distance (m): far above
/// the rounding of a distance on a site of kilometres, so a skipped segment
/// is one whose computed distance would also have cleared the footprint.
pub const CLEAR_MARGIN_M: f64 = 1e-6;

/// Squared distance from `p` to the bounding box of the segment `a`–`b`:
/// never more than the distance to the segment, and no division.
fn box_distance2(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let dx = (a.x.min(b.x) - p.x).max(p.x - a.x.max(b.x)).max(0.0);
    let dy = (a.y.min(b.y) - p.y).max(p.y - a.y.max(b.y)).max(0.0);
    dx * dx + dy * dy
}

/// Whether `p` is outside a counter-clockwise convex polygon, by the same
/// test as [`Shape::nearest`] (some edge has `p` on its right).
fn outside_convex(vertices: &[Vec2], p: Vec2) -> bool {
    let n = vertices.len();
    (0..n).any(|i| {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        let (e, ap) = (b - a, p - a);
        e.x * ap.y - e.y * ap.x < 0.0
    })
}

fn bounds_of(points: &[Vec2]) -> (Vec2, Vec2) {
    let mut lo = Vec2::repeat(f64::INFINITY);
    let mut hi = Vec2::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

fn polyline_nearest(points: &[Vec2], p: Vec2) -> (f64, Vec2) {
    let mut best2 = f64::INFINITY;
    let mut best_q = p;
    let mut best_seg = 0;
    for (i, w) in points.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        let (q, _) = segment_nearest(p, a, b);
        let d2 = (p - q).norm_squared();
        if d2 < best2 {
            best2 = d2;
            best_q = q;
            best_seg = i;
        }
    }
    let best = best2.sqrt();
    let normal = if best > 1e-12 {
        (p - best_q) / best
    } else if points.len() >= 2 {
        perp(points[best_seg + 1] - points[best_seg]).normalize()
    } else {
        Vec2::new(1.0, 0.0)
    };
    (best, normal)
}

/// A planning site: bounds, obstacles and road boundaries.
#[derive(Debug, Clone, PartialEq)]
pub struct Map {
    /// Lower-left corner of the site (m).
    pub min: Vec2,
    /// Upper-right corner of the site (m).
    pub max: Vec2,
    /// Obstacles.
    pub obstacles: Vec<Obstacle>,
    /// Road boundaries.
    pub boundaries: Vec<Boundary>,
}

impl Map {
    /// An empty site.
    pub fn new(min: Vec2, max: Vec2) -> Self {
        Self {
            min,
            max,
            obstacles: Vec::new(),
            boundaries: Vec::new(),
        }
    }

    /// Number of elements that [`Map::for_each_nearest`] visits (obstacles, boundaries, site edge).
    pub fn element_count(&self) -> usize {
        self.obstacles.len() + self.boundaries.len() + 1
    }

    /// Name of element `i` as numbered by [`Nearest::element`].
    pub fn element_name(&self, i: usize) -> &str {
        let no = self.obstacles.len();
        if i < no {
            &self.obstacles[i].name
        } else if i < no + self.boundaries.len() {
            &self.boundaries[i - no].name
        } else {
            "site edge"
        }
    }

    /// Whether `p` lies within the site rectangle.
    pub fn contains(&self, p: Vec2) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    /// Calls `f` with the nearest point of every element to `p`: each
    /// obstacle, each boundary, and the site edge (as a wall, distance
    /// negative outside the site).
    pub fn for_each_nearest(&self, p: Vec2, mut f: impl FnMut(Nearest)) {
        for (i, o) in self.obstacles.iter().enumerate() {
            let (distance, normal) = o.shape.nearest(p);
            f(Nearest {
                distance,
                normal,
                element: i,
            });
        }
        let no = self.obstacles.len();
        for (i, b) in self.boundaries.iter().enumerate() {
            let (distance, normal) = polyline_nearest(&b.points, p);
            f(Nearest {
                distance,
                normal,
                element: no + i,
            });
        }
        // Site edge: distance to the nearest side, positive inside.
        let sides = [
            (p.x - self.min.x, Vec2::new(1.0, 0.0)),
            (self.max.x - p.x, Vec2::new(-1.0, 0.0)),
            (p.y - self.min.y, Vec2::new(0.0, 1.0)),
            (self.max.y - p.y, Vec2::new(0.0, -1.0)),
        ];
        let (distance, normal) =
            sides
                .into_iter()
                .fold((f64::INFINITY, Vec2::zeros()), |acc, s| {
                    if s.0 < acc.0 {
                        s
                    } else {
                        acc
                    }
                });
        f(Nearest {
            distance,
            normal,
            element: no + self.boundaries.len(),
        });
    }

    /// The nearest element to `p` (smallest signed distance).
    pub fn nearest(&self, p: Vec2) -> Nearest {
        let mut best = Nearest {
            distance: f64::INFINITY,
            normal: Vec2::zeros(),
            element: 0,
        };
        self.for_each_nearest(p, |n| {
            if n.distance < best.distance {
                best = n;
            }
        });
        best
    }

    /// Whether a disc footprint of radius `footprint_radius_m` centred at `p`
    /// is clear of every element: exactly `self.clearance(p, r) > 0.0`, with
    /// the same arithmetic for every distance it computes, but it stops at
    /// the first element in reach and skips the segments whose bounding box
    /// lies farther than the footprint (plus [`CLEAR_MARGIN_M`]). The
    /// reference planner asks this of every cell of its grid, where the
    /// distance to every road boundary's segment was most of a study's time.
    pub fn is_clear(&self, p: Vec2, footprint_radius_m: f64) -> bool {
        let r = footprint_radius_m;
        if r.is_nan() {
            return false;
        }
        // `min(d) - r > 0` holds exactly when no `d - r <= 0` (subtraction
        // is monotonic; a NaN distance is never the nearest).
        let reaches = |d: f64| d - r <= 0.0;
        let reach = r + CLEAR_MARGIN_M;
        let far = |a: Vec2, b: Vec2| reach > 0.0 && box_distance2(p, a, b) > reach * reach;
        for o in &self.obstacles {
            let d = match &o.shape {
                Shape::Polygon { vertices } if outside_convex(vertices, p) => {
                    let n = vertices.len();
                    let best2 = (0..n)
                        .map(|i| (vertices[i], vertices[(i + 1) % n]))
                        .filter(|(a, b)| !far(*a, *b))
                        .map(|(a, b)| (p - segment_nearest(p, a, b).0).norm_squared())
                        .fold(f64::INFINITY, f64::min);
                    let best = best2.sqrt();
                    if best > 1e-12 {
                        best
                    } else {
                        0.0
                    }
                }
                shape => shape.nearest(p).0,
            };
            if reaches(d) {
                return false;
            }
        }
        for b in &self.boundaries {
            let best2 = b
                .points
                .windows(2)
                .filter(|w| !far(w[0], w[1]))
                .map(|w| (p - segment_nearest(p, w[0], w[1]).0).norm_squared())
                .fold(f64::INFINITY, f64::min);
            if reaches(best2.sqrt()) {
                return false;
            }
        }
        let sides = [
            p.x - self.min.x,
            self.max.x - p.x,
            p.y - self.min.y,
            self.max.y - p.y,
        ];
        !sides.into_iter().any(reaches)
    }

    /// Clearance of a disc footprint of radius `footprint_radius_m` centred at
    /// `p`: distance from the disc to the nearest element (m), negative on
    /// contact or overlap.
    pub fn clearance(&self, p: Vec2, footprint_radius_m: f64) -> f64 {
        self.nearest(p).distance - footprint_radius_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn square() -> Vec<Vec2> {
        vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, 2.0),
            Vec2::new(0.0, 2.0),
        ]
    }

    #[test]
    fn polygon_validation() {
        assert!(convex_polygon(square()).is_ok());
        let mut cw = square();
        cw.reverse();
        assert_eq!(
            convex_polygon(cw).unwrap(),
            square()
                .into_iter()
                .rev()
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect::<Vec<_>>()
        );
        let dart = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 1.0),
            Vec2::new(4.0, 0.0),
            Vec2::new(2.0, 3.0),
        ];
        assert!(matches!(
            convex_polygon(dart),
            Err(PolygonFault::NotConvex(_))
        ));
        assert!(matches!(
            convex_polygon(vec![Vec2::zeros(), Vec2::new(1.0, 0.0)]),
            Err(PolygonFault::TooFewVertices(2))
        ));
        assert!(matches!(
            convex_polygon(vec![
                Vec2::zeros(),
                Vec2::new(1.0, 0.0),
                Vec2::new(2.0, 0.0)
            ]),
            Err(PolygonFault::Degenerate) | Err(PolygonFault::NotConvex(_))
        ));
    }

    #[test]
    fn polygon_distance_is_to_the_nearest_edge_or_vertex() {
        let s = Shape::Polygon { vertices: square() };
        let (d, n) = s.nearest(Vec2::new(3.0, 1.0));
        assert_relative_eq!(d, 1.0);
        assert_relative_eq!(n, Vec2::new(1.0, 0.0));
        let (d, _) = s.nearest(Vec2::new(5.0, 6.0));
        assert_relative_eq!(d, 5.0); // to the corner (2, 2)
        let (d, n) = s.nearest(Vec2::new(1.0, 0.4));
        assert_relative_eq!(d, -0.4);
        assert_relative_eq!(n, Vec2::new(0.0, -1.0), epsilon = 1e-12);
    }

    #[test]
    fn circle_distance_is_to_the_rim() {
        let c = Shape::Circle {
            center: Vec2::new(1.0, 1.0),
            radius: 0.5,
        };
        let (d, n) = c.nearest(Vec2::new(1.0, 3.0));
        assert_relative_eq!(d, 1.5);
        assert_relative_eq!(n, Vec2::new(0.0, 1.0));
    }

    proptest! {
        /// `is_clear` skips work, never changes the answer: it is
        /// `clearance > 0` for circles, polygons (from inside and out),
        /// road boundaries, the site edge, and footprints down to zero.
        #[test]
        fn is_clear_is_clearance_above_zero(
            cx in 1.0..19.0f64, cy in 1.0..19.0f64, cr in 0.1..3.0f64,
            sx in 2.0..18.0f64, sy in 2.0..18.0f64, half in 0.2..2.0f64,
            road in proptest::collection::vec((0.0..20.0f64, 0.0..20.0f64), 1..12),
            px in -1.0..21.0f64, py in -1.0..21.0f64, r in 0.0..4.0f64,
        ) {
            let mut m = Map::new(Vec2::new(0.0, 0.0), Vec2::new(20.0, 20.0));
            m.obstacles.push(Obstacle {
                name: "disc".into(),
                shape: Shape::Circle { center: Vec2::new(cx, cy), radius: cr },
            });
            let square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(dx, dy)| Vec2::new(sx + dx * half, sy + dy * half * 0.7));
            m.obstacles.push(Obstacle {
                name: "block".into(),
                shape: Shape::Polygon { vertices: square.to_vec() },
            });
            m.boundaries.push(Boundary {
                name: "road".into(),
                points: road.into_iter().map(|(x, y)| Vec2::new(x, y)).collect(),
            });
            let p = Vec2::new(px, py);
            prop_assert_eq!(m.is_clear(p, r), m.clearance(p, r) > 0.0);
            // On an element's edge: the footprint's own radius decides.
            let q = Vec2::new(cx + cr + r, cy);
            prop_assert_eq!(m.is_clear(q, r), m.clearance(q, r) > 0.0);
        }
    }

    #[test]
    fn clearance_subtracts_the_footprint_and_sees_the_site_edge() {
        let mut m = Map::new(Vec2::new(0.0, 0.0), Vec2::new(10.0, 10.0));
        m.boundaries.push(Boundary {
            name: "edge".into(),
            points: vec![Vec2::new(0.0, 8.0), Vec2::new(10.0, 8.0)],
        });
        assert_relative_eq!(m.clearance(Vec2::new(5.0, 5.0), 1.0), 2.0);
        assert_eq!(
            m.element_name(m.nearest(Vec2::new(5.0, 7.0)).element),
            "edge"
        );
        assert_relative_eq!(m.clearance(Vec2::new(0.5, 5.0), 1.0), -0.5);
        assert_eq!(
            m.element_name(m.nearest(Vec2::new(0.5, 5.0)).element),
            "site edge"
        );
    }

    proptest! {
        // The distance gradient: moving a little along `normal` grows the
        // distance by that much (1-Lipschitz, exact away from the medial axis).
        #[test]
        fn normal_is_the_distance_gradient(x in -5.0f64..7.0, y in -5.0f64..7.0) {
            let s = Shape::Polygon { vertices: square() };
            let p = Vec2::new(x, y);
            let (d, n) = s.nearest(p);
            let h = 1e-4;
            let (d2, _) = s.nearest(p + n * h);
            // Inside, the nearest edge can switch exactly on a diagonal: allow it.
            prop_assert!((d2 - d - h).abs() < 1e-7 || d < 0.0 && (d2 - d).abs() <= h + 1e-9);
        }
    }
}
