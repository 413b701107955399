//! Clipping of data-space geometry to the visible axis rectangle, so that
//! nothing is drawn outside the axes and no far-away coordinate reaches the
//! rasteriser. Non-finite points are dropped here.

/// A point in data coordinates.
pub(crate) type Pt = (f64, f64);

/// The visible data rectangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rect {
    pub x0: f64,
    pub x1: f64,
    pub y0: f64,
    pub y1: f64,
}

impl Rect {
    pub(crate) fn new((x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> Self {
        Self { x0, x1, y0, y1 }
    }

    /// Whether `p` is finite and inside (borders included).
    pub(crate) fn contains(&self, p: Pt) -> bool {
        p.0 >= self.x0 && p.0 <= self.x1 && p.1 >= self.y0 && p.1 <= self.y1
    }
}

fn finite(p: Pt) -> bool {
    p.0.is_finite() && p.1.is_finite()
}

/// Liang–Barsky: the part of segment `a`-`b` inside `r`, if any.
pub(crate) fn clip_segment(a: Pt, b: Pt, r: &Rect) -> Option<(Pt, Pt)> {
    if !(finite(a) && finite(b)) {
        return None;
    }
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    if !(dx.is_finite() && dy.is_finite()) {
        return None;
    }
    let mut t0 = 0.0_f64;
    let mut t1 = 1.0_f64;
    let edges = [
        (-dx, a.0 - r.x0),
        (dx, r.x1 - a.0),
        (-dy, a.1 - r.y0),
        (dy, r.y1 - a.1),
    ];
    for (p, q) in edges {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
            if t0 > t1 {
                return None;
            }
        }
    }
    let at = |t: f64| {
        if t == 0.0 {
            a
        } else if t == 1.0 {
            b
        } else {
            (a.0 + t * dx, a.1 + t * dy)
        }
    };
    Some((at(t0), at(t1)))
}

/// The visible runs of the polyline through `points`; a non-finite point
/// breaks the line.
pub(crate) fn clip_polyline(points: &[Pt], r: &Rect) -> Vec<Vec<Pt>> {
    let mut runs: Vec<Vec<Pt>> = Vec::new();
    let mut current: Vec<Pt> = Vec::new();
    for pair in points.windows(2) {
        match clip_segment(pair[0], pair[1], r) {
            Some((p, q)) => {
                if current.last() != Some(&p) {
                    if current.len() > 1 {
                        runs.push(std::mem::take(&mut current));
                    }
                    current.clear();
                    current.push(p);
                }
                current.push(q);
            }
            None => {
                if current.len() > 1 {
                    runs.push(std::mem::take(&mut current));
                }
                current.clear();
            }
        }
    }
    if current.len() > 1 {
        runs.push(current);
    }
    runs
}

/// The visible runs of the closed outline through `points` (non-finite
/// vertices are dropped first).
pub(crate) fn clip_ring(points: &[Pt], r: &Rect) -> Vec<Vec<Pt>> {
    let mut ring: Vec<Pt> = points.iter().copied().filter(|p| finite(*p)).collect();
    if ring.len() < 2 {
        return Vec::new();
    }
    ring.push(ring[0]);
    clip_polyline(&ring, r)
}

/// Sutherland–Hodgman: the part of the polygon through `points` (closed,
/// non-finite vertices dropped) inside `r`; empty if nothing is visible.
pub(crate) fn clip_polygon(points: &[Pt], r: &Rect) -> Vec<Pt> {
    let mut poly: Vec<Pt> = points.iter().copied().filter(|p| finite(*p)).collect();
    if poly.len() < 3 {
        return Vec::new();
    }
    // Each edge: inside test and the intersection of a segment with the edge line.
    type Inside = fn(&Rect, Pt) -> bool;
    type Cut = fn(&Rect, Pt, Pt) -> Pt;
    let edges: [(Inside, Cut); 4] = [
        (|r, p| p.0 >= r.x0, |r, a, b| at_x(a, b, r.x0)),
        (|r, p| p.0 <= r.x1, |r, a, b| at_x(a, b, r.x1)),
        (|r, p| p.1 >= r.y0, |r, a, b| at_y(a, b, r.y0)),
        (|r, p| p.1 <= r.y1, |r, a, b| at_y(a, b, r.y1)),
    ];
    for (inside, cut) in edges {
        let input = std::mem::take(&mut poly);
        let Some(&last) = input.last() else {
            break;
        };
        let mut prev = last;
        for &cur in &input {
            match (inside(r, prev), inside(r, cur)) {
                (true, true) => poly.push(cur),
                (true, false) => poly.push(cut(r, prev, cur)),
                (false, true) => {
                    poly.push(cut(r, prev, cur));
                    poly.push(cur);
                }
                (false, false) => {}
            }
            prev = cur;
        }
    }
    if poly.len() < 3 || poly.iter().any(|p| !finite(*p)) {
        Vec::new()
    } else {
        poly
    }
}

fn at_x(a: Pt, b: Pt, x: f64) -> Pt {
    let t = (x - a.0) / (b.0 - a.0);
    (x, a.1 + t * (b.1 - a.1))
}

fn at_y(a: Pt, b: Pt, y: f64) -> Pt {
    let t = (y - a.1) / (b.1 - a.1);
    (a.0 + t * (b.0 - a.0), y)
}

/// `n` vertices of the circle of `radius` about `c`, in data units.
pub(crate) fn circle_polygon(c: Pt, radius: f64, n: usize) -> Vec<Pt> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            (c.0 + radius * a.cos(), c.1 + radius * a.sin())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: Rect = Rect {
        x0: 0.0,
        x1: 10.0,
        y0: 0.0,
        y1: 10.0,
    };

    #[test]
    fn segment_inside_outside_crossing() {
        assert_eq!(
            clip_segment((1.0, 1.0), (2.0, 2.0), &R),
            Some(((1.0, 1.0), (2.0, 2.0)))
        );
        assert_eq!(clip_segment((-5.0, -5.0), (-1.0, 20.0), &R), None);
        let (p, q) = clip_segment((-10.0, 5.0), (20.0, 5.0), &R).unwrap();
        assert_eq!((p, q), ((0.0, 5.0), (10.0, 5.0)));
        assert_eq!(clip_segment((f64::NAN, 5.0), (2.0, 5.0), &R), None);
        assert_eq!(clip_segment((-1e308, 5.0), (1e308, 5.0), &R), None);
    }

    #[test]
    fn polyline_gaps_at_nan_and_outside() {
        let pts = [
            (1.0, 1.0),
            (2.0, 2.0),
            (f64::NAN, 3.0),
            (3.0, 3.0),
            (4.0, 4.0),
            (20.0, 4.0),
            (30.0, 4.0),
            (5.0, 5.0),
        ];
        let runs = clip_polyline(&pts, &R);
        assert_eq!(runs.len(), 3);
        assert_eq!(runs[0], vec![(1.0, 1.0), (2.0, 2.0)]);
        assert_eq!(runs[1], vec![(3.0, 3.0), (4.0, 4.0), (10.0, 4.0)]);
        assert_eq!(runs[2].last(), Some(&(5.0, 5.0)));
    }

    #[test]
    fn polygon_clipped_to_rect() {
        let big = [(-5.0, -5.0), (15.0, -5.0), (15.0, 15.0), (-5.0, 15.0)];
        let c = clip_polygon(&big, &R);
        assert_eq!(c.len(), 4);
        assert!(c.iter().all(|p| R.contains(*p)));
        let outside = [(20.0, 20.0), (30.0, 20.0), (30.0, 30.0)];
        assert!(clip_polygon(&outside, &R).is_empty());
    }
}
