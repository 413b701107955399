//! A static k-d tree over the points of one cloud, for the neighbourhood
//! filters: k nearest, count within a radius (stopping as soon as enough are
//! found), all within a radius.
//!
//! Why not `kiddo`: on the 1 M-point pile of `benches/filters.rs`, kiddo 5.3's
//! `ImmutableKdTree::nearest_n(51)` for every point took 25 s on this 2-core
//! machine (PCL 1.13 needs 10.7 s for the whole statistical filter), mostly
//! because its pruning bound `rd + (new_off − old_off)²` is much weaker than
//! the exact `rd − old_off² + new_off²`. This tree uses the exact bound, splits
//! at the median of the widest axis, stores the points in tree order, and
//! the filters query the points in that order, so that consecutive queries
//! touch the same memory.
//!
//! Arithmetic, so that results agree with PCL bit for bit: a squared
//! distance is computed in f32 as `(dx·dx + dy·dy) + dz·dz` (which equals
//! FLANN's `L2_Simple<float>`, `((0 + dx²) + dy²) + dz²`); the pruning bound
//! is computed in f64 from exact f32 differences and a cell is skipped only
//! when the bound exceeds the current limit by a relative 1e-6, far more than
//! the f32 rounding of a distance (< 4e-7), so no point that can be within
//! the limit in f32 is ever skipped. Ties between equal distances never
//! matter to the filters: they use the k-th distance value, a count, or the
//! whole set within a radius.

use rayon::prelude::*;

use crate::Point;

/// Target number of points in a leaf; leaves hold between half and all of it.
const LEAF: usize = 16;

/// Above this many points a subtree is built in parallel.
const PARALLEL_BUILD: usize = 32 * 1024;

/// Relative slack of the pruning test (see the module docs).
const SLACK: f64 = 1.0 + 1e-6;

/// The f32 squared distance, in FLANN's order.
#[inline(always)]
pub(crate) fn squared_distance(a: &Point, b: &Point) -> f32 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    dx * dx + dy * dy + dz * dz
}

/// A balanced k-d tree in implicit (heap) layout: inner node `i` has
/// children `2i + 1` and `2i + 2`; a node of `m` points sends `m / 2` to the
/// left; after `depth` levels every node is a leaf.
pub(crate) struct KdTree {
    /// Split axis and value of each inner node.
    splits: Vec<(u8, f32)>,
    /// Number of inner levels.
    depth: u32,
    /// The points in tree order.
    points: Vec<Point>,
    /// For each point in tree order, its index in the input.
    ids: Vec<u32>,
}

impl KdTree {
    /// Builds the tree over `points` (finite, at most u32::MAX of them).
    pub(crate) fn new(points: &[Point]) -> Self {
        let n = points.len();
        assert!(u32::try_from(n).is_ok(), "a k-d tree holds at most 2^32 - 1 points");
        let mut depth = 0u32;
        while (n >> depth) > LEAF {
            depth += 1;
        }
        let inner = (1usize << depth) - 1;
        let mut entries: Vec<(Point, u32)> = points.iter().enumerate().map(|(i, p)| (*p, i as u32)).collect();
        let mut splits = vec![(0u8, 0.0f32); inner];
        let mut found = Vec::with_capacity(inner);
        build(&mut entries, 0, depth, &mut found);
        for (node, split) in found {
            splits[node] = split;
        }
        let (points, ids) = entries.into_iter().unzip();
        Self {
            splits,
            depth,
            points,
            ids,
        }
    }

    /// Number of points.
    pub(crate) fn len(&self) -> usize {
        self.points.len()
    }

    /// The points in tree order.
    pub(crate) fn points(&self) -> &[Point] {
        &self.points
    }

    /// The input index of the point at tree position `pos`.
    #[inline]
    pub(crate) fn id(&self, pos: usize) -> usize {
        self.ids[pos] as usize
    }

    /// Computes `f` for every point, visiting them in tree order in
    /// parallel (`init` makes one scratch value per task), and returns the
    /// results in input order.
    pub(crate) fn map_points<T, S, I, F>(&self, init: I, f: F) -> Vec<T>
    where
        T: Send + Clone + Default,
        I: Fn() -> S + Sync + Send,
        F: Fn(&mut S, usize, &Point) -> T + Sync + Send,
    {
        let in_tree_order: Vec<T> = (0..self.len())
            .into_par_iter()
            .map_init(init, |scratch, pos| f(scratch, pos, &self.points[pos]))
            .collect();
        let mut out = vec![T::default(); self.len()];
        for (pos, value) in in_tree_order.into_iter().enumerate() {
            out[self.ids[pos] as usize] = value;
        }
        out
    }

    /// The k nearest points to `q` (as tree positions with their squared
    /// distances), nearest first, into `knn`.
    pub(crate) fn nearest(&self, q: &Point, knn: &mut Nearest) {
        knn.clear();
        let mut off = [0.0f64; 3];
        self.nearest_in(0, 0, self.len(), self.depth, q, &mut off, 0.0, knn);
    }

    #[allow(clippy::too_many_arguments)]
    fn nearest_in(
        &self,
        node: usize,
        start: usize,
        len: usize,
        levels: u32,
        q: &Point,
        off: &mut [f64; 3],
        rd: f64,
        knn: &mut Nearest,
    ) {
        if levels == 0 {
            for (i, p) in self.points[start..start + len].iter().enumerate() {
                knn.offer(squared_distance(q, p), (start + i) as u32);
            }
            return;
        }
        let (axis, split) = self.splits[node];
        let a = axis as usize;
        let half = len / 2;
        let diff = f64::from(q[a]) - f64::from(split);
        let (near, far) = if diff < 0.0 {
            ((2 * node + 1, start, half), (2 * node + 2, start + half, len - half))
        } else {
            ((2 * node + 2, start + half, len - half), (2 * node + 1, start, half))
        };
        self.nearest_in(near.0, near.1, near.2, levels - 1, q, off, rd, knn);
        let old = off[a];
        let far_rd = rd - old * old + diff * diff;
        if far_rd <= f64::from(knn.worst()) * SLACK {
            off[a] = diff.abs();
            self.nearest_in(far.0, far.1, far.2, levels - 1, q, off, far_rd, knn);
            off[a] = old;
        }
    }

    /// Whether at least `wanted` points lie within squared distance `r2` of
    /// `q` (inclusive, `q` itself included); stops as soon as they are found.
    pub(crate) fn has_within(&self, q: &Point, r2: f32, wanted: usize) -> bool {
        let mut count = 0;
        let mut off = [0.0f64; 3];
        self.count_in(0, 0, self.len(), self.depth, q, &mut off, 0.0, r2, wanted, &mut count);
        count >= wanted
    }

    #[allow(clippy::too_many_arguments)]
    fn count_in(
        &self,
        node: usize,
        start: usize,
        len: usize,
        levels: u32,
        q: &Point,
        off: &mut [f64; 3],
        rd: f64,
        r2: f32,
        wanted: usize,
        count: &mut usize,
    ) {
        if levels == 0 {
            for p in &self.points[start..start + len] {
                if squared_distance(q, p) <= r2 {
                    *count += 1;
                    if *count >= wanted {
                        return;
                    }
                }
            }
            return;
        }
        let (axis, split) = self.splits[node];
        let a = axis as usize;
        let half = len / 2;
        let diff = f64::from(q[a]) - f64::from(split);
        let (near, far) = if diff < 0.0 {
            ((2 * node + 1, start, half), (2 * node + 2, start + half, len - half))
        } else {
            ((2 * node + 2, start + half, len - half), (2 * node + 1, start, half))
        };
        self.count_in(near.0, near.1, near.2, levels - 1, q, off, rd, r2, wanted, count);
        if *count >= wanted {
            return;
        }
        let old = off[a];
        let far_rd = rd - old * old + diff * diff;
        if far_rd <= f64::from(r2) * SLACK {
            off[a] = diff.abs();
            self.count_in(far.0, far.1, far.2, levels - 1, q, off, far_rd, r2, wanted, count);
            off[a] = old;
        }
    }

    /// The tree positions of all points within squared distance `r2` of `q`
    /// (inclusive, `q` itself included), in tree order, into `out`.
    pub(crate) fn within(&self, q: &Point, r2: f32, out: &mut Vec<u32>) {
        out.clear();
        let mut off = [0.0f64; 3];
        self.within_in(0, 0, self.len(), self.depth, q, &mut off, 0.0, r2, out);
    }

    #[allow(clippy::too_many_arguments)]
    fn within_in(
        &self,
        node: usize,
        start: usize,
        len: usize,
        levels: u32,
        q: &Point,
        off: &mut [f64; 3],
        rd: f64,
        r2: f32,
        out: &mut Vec<u32>,
    ) {
        if levels == 0 {
            for (i, p) in self.points[start..start + len].iter().enumerate() {
                if squared_distance(q, p) <= r2 {
                    out.push((start + i) as u32);
                }
            }
            return;
        }
        let (axis, split) = self.splits[node];
        let a = axis as usize;
        let half = len / 2;
        let diff = f64::from(q[a]) - f64::from(split);
        let old = off[a];
        let far_rd = rd - old * old + diff * diff;
        let visit_far = far_rd <= f64::from(r2) * SLACK;
        // Left before right, so that the output is in tree order.
        let left = (2 * node + 1, start, half, diff < 0.0 || visit_far);
        let right = (2 * node + 2, start + half, len - half, diff >= 0.0 || visit_far);
        for (child, s, l, visit) in [left, right] {
            if !visit {
                continue;
            }
            let is_far = (child == 2 * node + 1) != (diff < 0.0);
            if is_far {
                off[a] = diff.abs();
                self.within_in(child, s, l, levels - 1, q, off, far_rd, r2, out);
                off[a] = old;
            } else {
                self.within_in(child, s, l, levels - 1, q, off, rd, r2, out);
            }
        }
    }
}

/// Builds the subtree of `node` over `entries`, pushing (node, split) pairs.
fn build(entries: &mut [(Point, u32)], node: usize, levels: u32, found: &mut Vec<(usize, (u8, f32))>) {
    if levels == 0 {
        return;
    }
    // Split the widest axis of the points' bounding box at the median.
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (p, _) in entries.iter() {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])).then(b.cmp(&a)))
        .expect("three axes");
    let half = entries.len() / 2;
    // Ties broken by input index, so the tree does not depend on the
    // selection algorithm's choices.
    entries.select_nth_unstable_by(half, |x, y| x.0[axis].total_cmp(&y.0[axis]).then(x.1.cmp(&y.1)));
    found.push((node, (axis as u8, entries[half].0[axis])));
    let (left, right) = entries.split_at_mut(half);
    if left.len() + right.len() > PARALLEL_BUILD {
        let mut right_found = Vec::new();
        rayon::join(
            || build(left, 2 * node + 1, levels - 1, found),
            || build(right, 2 * node + 2, levels - 1, &mut right_found),
        );
        found.extend(right_found);
    } else {
        build(left, 2 * node + 1, levels - 1, found);
        build(right, 2 * node + 2, levels - 1, found);
    }
}

/// A bounded list of the k nearest found so far, nearest first.
pub(crate) struct Nearest {
    k: usize,
    dist: Vec<f32>,
    pos: Vec<u32>,
}

impl Nearest {
    /// An empty list for `k ≥ 1` neighbours.
    pub(crate) fn new(k: usize) -> Self {
        Self {
            k,
            dist: Vec::with_capacity(k + 1),
            pos: Vec::with_capacity(k + 1),
        }
    }

    fn clear(&mut self) {
        self.dist.clear();
        self.pos.clear();
    }

    /// The squared distance a point must beat (or tie) to enter.
    #[inline]
    fn worst(&self) -> f32 {
        if self.dist.len() < self.k {
            f32::INFINITY
        } else {
            self.dist[self.k - 1]
        }
    }

    #[inline]
    fn offer(&mut self, d: f32, pos: u32) {
        let full = self.dist.len() == self.k;
        if full && d >= self.dist[self.k - 1] {
            return;
        }
        // Insertion keeps equal distances in arrival order.
        let mut i = self.dist.len();
        while i > 0 && self.dist[i - 1] > d {
            i -= 1;
        }
        self.dist.insert(i, d);
        self.pos.insert(i, pos);
        if full {
            self.dist.pop();
            self.pos.pop();
        }
    }

    /// Squared distances, nearest first.
    pub(crate) fn distances(&self) -> &[f32] {
        &self.dist
    }

    /// Tree positions, nearest first.
    pub(crate) fn positions(&self) -> &[u32] {
        &self.pos
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(n: usize, seed: u64) -> Vec<Point> {
        let mut s = seed;
        let mut u = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        // A thin slab with duplicates, to stress ties and flat cells.
        let mut pts: Vec<Point> = (0..n).map(|_| [u(), u() * 2.0, u() * 0.01]).collect();
        for i in 0..n / 10 {
            pts[i * 7 % n] = pts[i];
        }
        pts
    }

    #[test]
    fn queries_equal_brute_force() {
        for (n, seed) in [(1, 1), (5, 2), (17, 3), (100, 4), (2000, 5)] {
            let pts = cloud(n, seed);
            let tree = KdTree::new(&pts);
            let mut knn = Nearest::new(7.min(n));
            let mut out = Vec::new();
            for q in pts.iter().step_by(3).chain([[0.5, 0.5, 0.5]].iter()) {
                let mut all: Vec<f32> = pts.iter().map(|p| squared_distance(q, p)).collect();
                all.sort_by(f32::total_cmp);
                tree.nearest(q, &mut knn);
                assert_eq!(knn.distances(), &all[..7.min(n)]);
                for (d, &pos) in knn.distances().iter().zip(knn.positions()) {
                    assert_eq!(*d, squared_distance(q, &tree.points()[pos as usize]));
                }
                let r2 = all[(n / 3).min(n - 1)];
                let inside = all.iter().filter(|&&d| d <= r2).count();
                tree.within(q, r2, &mut out);
                assert_eq!(out.len(), inside);
                assert!(out.windows(2).all(|w| w[0] < w[1]));
                assert!(tree.has_within(q, r2, inside));
                assert!(!tree.has_within(q, r2, inside + 1));
            }
            // Ids map tree order back to the input.
            let mut seen: Vec<usize> = (0..n).map(|p| tree.id(p)).collect();
            for (pos, &id) in seen.iter().enumerate() {
                assert_eq!(tree.points()[pos], pts[id]);
            }
            seen.sort_unstable();
            assert_eq!(seen, (0..n).collect::<Vec<_>>());
        }
    }
}
