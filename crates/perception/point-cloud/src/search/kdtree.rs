//! A static k-d tree over the points of one cloud, for the neighbourhood
//! filters: k nearest, count within a radius (stopping as soon as enough are
//! found), all within a radius.
//!
//! Why not `kiddo`: on the 1 M-point pile of `benches/filters.rs`, kiddo 5.3's
//! `ImmutableKdTree::nearest_n(51)` for every point took 25 s on this 2-core
//! machine (its mutable `KdTree` too; PCL 1.13 needs 10.7 s for the whole
//! statistical filter). Two likely causes, both fixed here: kiddo prunes with
//! `rd + (new_off − old_off)²`, much weaker than the exact
//! `rd − old_off² + new_off²`, and it cycles the split axis, which on a
//! noisy floor cuts z (the noise) as often as x and y and makes leaves long
//! and flat. This tree splits at the median of the axis of largest variance,
//! stores the points in tree order, each leaf sorted along its own main
//! axis, and the filters query the points in that order, so that
//! consecutive queries are close and touch the same memory.
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

/// How many previous points bound the next k-nearest search.
const HISTORY: usize = 16;

/// The first guess of a k-nearest search: this times the k-th distance of
/// the nearest recent point.
const GUESS: f64 = 1.1;

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

/// A subtree: (node, start, len) in the point array.
type Subtree = (usize, usize, usize);

impl KdTree {
    /// Builds the tree over `points` (finite, at most u32::MAX of them).
    pub(crate) fn new(points: &[Point]) -> Self {
        let n = points.len();
        assert!(
            u32::try_from(n).is_ok(),
            "a k-d tree holds at most 2^32 - 1 points"
        );
        let mut depth = 0u32;
        while (n >> depth) > LEAF {
            depth += 1;
        }
        let inner = (1usize << depth) - 1;
        let mut entries: Vec<(Point, u32)> = points
            .iter()
            .enumerate()
            .map(|(i, p)| (*p, i as u32))
            .collect();
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
        knn.reset(f32::INFINITY);
        let mut off = [0.0f64; 3];
        self.nearest_in(0, 0, self.len(), self.depth, q, &mut off, 0.0, knn);
    }

    /// The split axis of `node`, the query's signed offset from its split
    /// plane, and its (node, start, len) children nearer and farther from `q`.
    #[inline]
    fn children(
        &self,
        node: usize,
        start: usize,
        len: usize,
        q: &[f32; 3],
    ) -> (usize, f64, Subtree, Subtree) {
        let (axis, split) = self.splits[node];
        let half = len / 2;
        let diff = f64::from(q[axis as usize]) - f64::from(split);
        let left = (2 * node + 1, start, half);
        let right = (2 * node + 2, start + half, len - half);
        if diff < 0.0 {
            (axis as usize, diff, left, right)
        } else {
            (axis as usize, diff, right, left)
        }
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
        let (a, diff, near, far) = self.children(node, start, len, q);
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
        self.count_in(
            0,
            0,
            self.len(),
            self.depth,
            q,
            &mut off,
            0.0,
            r2,
            wanted,
            &mut count,
        );
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
        let (a, diff, near, far) = self.children(node, start, len, q);
        self.count_in(
            near.0,
            near.1,
            near.2,
            levels - 1,
            q,
            off,
            rd,
            r2,
            wanted,
            count,
        );
        if *count >= wanted {
            return;
        }
        let old = off[a];
        let far_rd = rd - old * old + diff * diff;
        if far_rd <= f64::from(r2) * SLACK {
            off[a] = diff.abs();
            self.count_in(
                far.0,
                far.1,
                far.2,
                levels - 1,
                q,
                off,
                far_rd,
                r2,
                wanted,
                count,
            );
            off[a] = old;
        }
    }

    /// The tree positions of all points within squared distance `r2` of `q`
    /// (inclusive, `q` itself included), in tree order, into `out`.
    pub(crate) fn within(&self, q: &Point, r2: f32, out: &mut Vec<u32>) {
        out.clear();
        let mut off = [0.0f64; 3];
        self.within_in(
            0,
            0,
            self.len(),
            self.depth,
            q,
            &mut off,
            0.0,
            r2,
            &mut |_, pos| out.push(pos),
        );
    }

    #[allow(clippy::too_many_arguments)]
    fn within_in<F: FnMut(f32, u32)>(
        &self,
        node: usize,
        start: usize,
        len: usize,
        levels: u32,
        q: &Point,
        off: &mut [f64; 3],
        rd: f64,
        r2: f32,
        sink: &mut F,
    ) {
        if levels == 0 {
            for (i, p) in self.points[start..start + len].iter().enumerate() {
                let d = squared_distance(q, p);
                if d <= r2 {
                    sink(d, (start + i) as u32);
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
        if diff < 0.0 {
            self.within_in(2 * node + 1, start, half, levels - 1, q, off, rd, r2, sink);
            if visit_far {
                off[a] = -diff;
                self.within_in(
                    2 * node + 2,
                    start + half,
                    len - half,
                    levels - 1,
                    q,
                    off,
                    far_rd,
                    r2,
                    sink,
                );
                off[a] = old;
            }
        } else {
            if visit_far {
                off[a] = diff;
                self.within_in(
                    2 * node + 1,
                    start,
                    half,
                    levels - 1,
                    q,
                    off,
                    far_rd,
                    r2,
                    sink,
                );
                off[a] = old;
            }
            self.within_in(
                2 * node + 2,
                start + half,
                len - half,
                levels - 1,
                q,
                off,
                rd,
                r2,
                sink,
            );
        }
    }

    /// For every point of the tree, `f` of the squared distances to its k
    /// nearest points (itself included), nearest first; results in input
    /// order. Exactly the distances [`KdTree::nearest`] finds, faster. The
    /// points are visited in tree order, and each of the last 16 points q'
    /// of the same task, whose k-th nearest lies at r', bounds the k nearest
    /// of the next point q within r' + ‖q − q'‖ (triangle inequality). A
    /// first search collects the points within 1.1 r' of the nearest q'
    /// (a guess); if there are k of them, they hold q's k nearest, whatever
    /// the guess was. Otherwise a second search collects those within the
    /// smallest bound, which holds k points for sure. Every cap is widened
    /// by a relative 1e-5 for the f32 rounding. Collecting within a fixed
    /// cap needs no pruning bound to update; the k smallest are then
    /// selected and sorted.
    pub(crate) fn map_k_nearest_distances<T, F>(&self, k: usize, f: F) -> Vec<T>
    where
        T: Send + Clone + Default,
        F: Fn(&[f32]) -> T + Sync + Send,
    {
        assert!(k >= 1 && k <= self.len(), "1 <= k <= number of points");
        let in_tree_order: Vec<T> = (0..self.len())
            .into_par_iter()
            .map_init(
                || {
                    (
                        Nearest::new(k),
                        Vec::<f32>::new(),
                        Vec::<u32>::new(),
                        Vec::<(Point, f64)>::with_capacity(HISTORY),
                    )
                },
                |(knn, dist, bits, history), pos| {
                    // `history` is a ring of the last HISTORY points and r'.
                    let q = &self.points[pos];
                    // The tightest bound among the last few points of the
                    // task, and the k-th distance of the nearest of them.
                    let (mut reach, mut guess, mut nearest_gap) =
                        (f64::INFINITY, f64::INFINITY, f64::INFINITY);
                    for (p, r) in history.iter() {
                        let gap = (0..3)
                            .map(|a| (f64::from(q[a]) - f64::from(p[a])).powi(2))
                            .sum::<f64>()
                            .sqrt();
                        reach = reach.min(r + gap);
                        if gap < nearest_gap {
                            nearest_gap = gap;
                            guess = *r;
                        }
                    }
                    // Squared distances are ≥ +0, whose f32 bit patterns sort
                    // as the numbers do: select and sort them as integers.
                    bits.clear();
                    if reach < f64::INFINITY {
                        // First a guess: the k-th distance of a close point,
                        // a little more. If k points lie within it, they
                        // include q's k nearest; otherwise use the bound.
                        let guess = (guess * GUESS).min(reach);
                        let mut off = [0.0f64; 3];
                        self.within_in(
                            0,
                            0,
                            self.len(),
                            self.depth,
                            q,
                            &mut off,
                            0.0,
                            widen(guess),
                            &mut |d, _| bits.push(d.to_bits()),
                        );
                        if bits.len() < k && guess < reach {
                            bits.clear();
                            let mut off = [0.0f64; 3];
                            self.within_in(
                                0,
                                0,
                                self.len(),
                                self.depth,
                                q,
                                &mut off,
                                0.0,
                                widen(reach),
                                &mut |d, _| bits.push(d.to_bits()),
                            );
                        }
                    }
                    if bits.len() >= k {
                        let (smaller, _, _) = bits.select_nth_unstable(k - 1);
                        smaller.sort_unstable();
                        dist.clear();
                        dist.extend(bits[..k].iter().map(|&b| f32::from_bits(b)));
                    } else {
                        // First point of the task (a cap too small cannot happen).
                        self.nearest(q, knn);
                        dist.clear();
                        dist.extend_from_slice(knn.distances());
                    }
                    let latest = (*q, f64::from(dist[k - 1]).sqrt());
                    if history.len() < HISTORY {
                        history.push(latest);
                    } else {
                        history[pos % HISTORY] = latest;
                    }
                    f(&dist[..k])
                },
            )
            .collect();
        let mut out = vec![T::default(); self.len()];
        for (pos, value) in in_tree_order.into_iter().enumerate() {
            out[self.ids[pos] as usize] = value;
        }
        out
    }
}

/// The squared distance `r²` widened by a relative 1e-5 (far above the f32
/// rounding of a squared distance), as f32: a cap that surely holds every
/// point whose true distance is at most `r`.
fn widen(r: f64) -> f32 {
    (r * r * (1.0 + 1e-5)) as f32
}

/// Builds the subtree of `node` over `entries`, pushing (node, split) pairs.
fn build(
    entries: &mut [(Point, u32)],
    node: usize,
    levels: u32,
    found: &mut Vec<(usize, (u8, f32))>,
) {
    let axis = axis_of_largest_variance(entries);
    if levels == 0 {
        // A leaf is sorted along its own longest direction, so that
        // consecutive points (consecutive queries) are close.
        entries.sort_unstable_by(|x, y| x.0[axis].total_cmp(&y.0[axis]).then(x.1.cmp(&y.1)));
        return;
    }
    // Split at the median.
    let half = entries.len() / 2;
    // Ties broken by input index, so the tree does not depend on the
    // selection algorithm's choices.
    entries.select_nth_unstable_by(half, |x, y| {
        x.0[axis].total_cmp(&y.0[axis]).then(x.1.cmp(&y.1))
    });
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

/// The axis along which `entries` vary most. (Not the widest extent: on a
/// scanned floor, range noise makes z the widest axis of a small cell, and
/// cutting it yields flat leaves metres wide.)
fn axis_of_largest_variance(entries: &[(Point, u32)]) -> usize {
    let count = entries.len().max(1) as f64;
    let mut mean = [0.0f64; 3];
    for (p, _) in entries {
        for a in 0..3 {
            mean[a] += f64::from(p[a]);
        }
    }
    let mean = mean.map(|m| m / count);
    let mut var = [0.0f64; 3];
    for (p, _) in entries {
        for a in 0..3 {
            let d = f64::from(p[a]) - mean[a];
            var[a] += d * d;
        }
    }
    (0..3)
        .max_by(|&a, &b| var[a].total_cmp(&var[b]).then(b.cmp(&a)))
        .expect("three axes")
}

/// A bounded list of the k nearest found so far, nearest first.
pub(crate) struct Nearest {
    k: usize,
    len: usize,
    cap: f32,
    dist: Vec<f32>,
    pos: Vec<u32>,
}

impl Nearest {
    /// An empty list for `k ≥ 1` neighbours.
    pub(crate) fn new(k: usize) -> Self {
        Self {
            k,
            len: 0,
            cap: f32::INFINITY,
            dist: vec![0.0; k],
            pos: vec![0; k],
        }
    }

    /// Empties the list; until it is full, only points with squared
    /// distance `<= cap` enter.
    fn reset(&mut self, cap: f32) {
        self.len = 0;
        self.cap = cap;
    }

    /// The squared distance a point must not exceed to enter.
    #[inline]
    fn worst(&self) -> f32 {
        if self.len == self.k {
            self.dist[self.k - 1]
        } else {
            self.cap
        }
    }

    #[inline]
    fn offer(&mut self, d: f32, pos: u32) {
        let mut i = if self.len == self.k {
            // Full: only a strictly nearer point enters (as in FLANN).
            if d >= self.dist[self.k - 1] {
                return;
            }
            self.k - 1
        } else {
            if d > self.cap {
                return;
            }
            self.len += 1;
            self.len - 1
        };
        // Insertion keeps equal distances in arrival order.
        while i > 0 && self.dist[i - 1] > d {
            self.dist[i] = self.dist[i - 1];
            self.pos[i] = self.pos[i - 1];
            i -= 1;
        }
        self.dist[i] = d;
        self.pos[i] = pos;
    }

    /// Squared distances, nearest first.
    pub(crate) fn distances(&self) -> &[f32] {
        &self.dist[..self.len]
    }

    /// Tree positions, nearest first.
    pub(crate) fn positions(&self) -> &[u32] {
        &self.pos[..self.len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(n: usize, seed: u64) -> Vec<Point> {
        let mut u = crate::testing::uniform(seed);
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
            // All k nearest at once, leaf by leaf: the same distances.
            let k = 7.min(n);
            let batched = tree.map_k_nearest_distances(k, |d| d.to_vec());
            for (i, q) in pts.iter().enumerate() {
                let mut all: Vec<f32> = pts.iter().map(|p| squared_distance(q, p)).collect();
                all.sort_by(f32::total_cmp);
                assert_eq!(batched[i], &all[..k], "point {i}");
            }
            for q in pts.iter().step_by(3).chain([[0.5, 0.5, 0.5]].iter()) {
                let mut all: Vec<f32> = pts.iter().map(|p| squared_distance(q, p)).collect();
                all.sort_by(f32::total_cmp);
                tree.nearest(q, &mut knn);
                assert_eq!(knn.distances(), &all[..7.min(n)]);
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
