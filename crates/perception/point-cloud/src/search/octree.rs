//! Exact k nearest distances of every point on an octree, searched a group
//! of neighbouring points at a time: the statistical filter's search
//! ([RS eq. 14]) for scans whose density changes widely from place to place.
//!
//! Why beside the grid of columns (`search::columns`): the grid files every point on
//! columns of one side, sized for the median k-th distance. Where the
//! density changes tenfold across one cloud (PCL's five RGB-D scans side by
//! side, `kinect5`: k-th distances from 4 mm on the close-up scans to 4 cm
//! on the office, a quarter of them below half the median and a quarter
//! above twice it), the dense places read thousands of points a query: a
//! third of `kinect5`'s points read 1 900–3 000 candidates each, against
//! 340 on the bench pile (BENCHMARKS.md, 2026-12-05). An octree's cells
//! shrink where the points crowd, so a leaf holds a few dozen points at any
//! density.
//!
//! The tree: every point's Morton code (up to 21 bits an axis over the
//! cloud's bounding cube, fewer where the points lie far apart:
//! [`Octree::with_finest`]), the points sorted by code (dealt by the top 16
//! bits in parallel, each bucket then sorted by a radix sort), and a binary
//! tree over the sorted codes split at the highest bit in which a node's
//! codes differ, down to leaves of at most [`LEAF`] points (an octree with
//! its levels cut in three; equal codes are cut by count), its top built
//! alone and its subtrees in parallel ([`Builder`]). Each node keeps the
//! bounding box of its points; nodes are stored depth first, each with the
//! index past its subtree, so a search is a loop over an array.
//!
//! The search: the nodes of at most [`GROUP`] points (a few leaves, close
//! in space) are the groups. For a group, the leaves whose boxes meet the
//! group's box widened by a reach R (the largest k-th distance of the
//! group before, times [`REACH`]) are gathered and their points copied
//! into one buffer; every point within R of any point of the group is in
//! it. Each [`PART`] points of the group (a patch next in Morton order)
//! cut that buffer to their own box widened by R (one vector pass,
//! `within::keep_inside`), and each point then takes one vector pass over
//! its part's cut (`search::within`) keeping the distances within r (the k-th
//! distance of the point before, times [`GUESS`], at most R), and when k
//! are within r they hold its k nearest. The k are picked by splitting
//! the distances at a little below the point before's k-th
//! (`within::smallest_near`). A point
//! whose k nearest lie beyond R (the edge of a scan, a stray) waits for the
//! end of its group, and those of a group are answered together on one
//! wider gather; what still lacks k (an outlier far from the rest) is
//! searched alone, its reach grown by the count it found.
//!
//! The gather climbs from the group to the first ancestor whose Morton cell
//! holds the widened box (no point outside that subtree can lie in it) and
//! walks that subtree only. Each of the three (a group, its points left
//! over, a point alone) gathers into a buffer of its own: when a point
//! searched alone wrote over its group's wider gather, the next point
//! left over read the wrong candidates (13 points of `kinect5`, caught by
//! the peer script's comparison with PCL).
//!
//! Measured (BENCHMARKS.md, 2026-12-06): on `kinect5` a group's gather
//! holds about 480 points, a part's cut 270, of which 61 lie within r (on
//! the grid a query reads about 950); the filter takes 0.6–0.7 of the
//! grid's time. Cutting the gather to parts of 16 took the filter from
//! 191–199 to 181–185 ms (parts of 8 or 32, groups of 128 or 256, leaves of
//! 16: slower; per-query tests of 16-point blocks' boxes, 14 % slower).
//! Where a scan is a layer as thick as its k-th distance (the bench pile,
//! the rosette scan), a group's gather reads a box round the group, and
//! the grid is up to twice as fast: `statistical_outlier.rs` chooses.
//!
//! Arithmetic as in `search::columns` and `search::kdtree`: squared distances in f32 in
//! FLANN's order (`search::within`), so the distances are PCL's bit for bit;
//! every box is widened by a relative [`SLACK`], far above the f32 rounding
//! of a squared distance, and rounded outwards to f32, so no point within r
//! is left out of it. The results never depend on the grouping, the reach
//! or the number of threads, only the time does.

use rayon::prelude::*;

use super::bounds::{within_f32, SLACK};
use super::within::{self, Run};
use crate::simd::Isa;
use crate::Point;

/// Most points a leaf holds.
const LEAF: usize = 32;

/// Most points a group (the points searched on one gather) holds.
const GROUP: usize = 64;

/// Points of a group that take their candidates from its gather cut to
/// their own box.
const PART: usize = 16;

/// Most bits of a coordinate in a Morton code.
const BITS: u32 = 21;

/// Fewest bits of a coordinate in a Morton code (three times it at least [`TOP`]).
const FEWEST_BITS: u32 = 6;

/// Bits of a code's first digit, by which [`sort_by_code`] deals the points.
const TOP: u32 = 16;

/// A point's first radius: the k-th distance of the point before, times this.
const GUESS: f64 = 1.1;

/// A group's reach: the largest k-th distance of the group before, times this.
const REACH: f64 = 1.1;

/// The k nearest are split at this times the point before's k-th squared
/// distance (a little below it, so that the few above are sorted).
const PIVOT: f32 = 0.95;

/// Groups a parallel task takes at a time.
const GROUPS_A_TASK: usize = 512;

/// A node of the tree: the bounding box of its points, their sorted
/// positions, and where its subtree ends.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Node {
    lo: [f32; 3],
    hi: [f32; 3],
    start: u32,
    end: u32,
    /// The node after this one's subtree (nodes are stored depth first).
    skip: u32,
    parent: u32,
    /// The codes of every point in the cloud that share this node's code
    /// bits above this one are in its subtree (below −1: a node cut from
    /// equal codes by count, which has no cell of its own).
    level: i8,
    leaf: bool,
}

/// Points in Morton order with a binary tree over them (see the module docs).
pub(crate) struct Octree {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    /// Input index of each sorted position.
    ids: Vec<u32>,
    /// Morton code of each sorted position.
    codes: Vec<u64>,
    nodes: Vec<Node>,
    /// The groups' nodes, in order.
    groups: Vec<u32>,
    /// The cube of the codes: its corner, codes per metre, and bits a coordinate.
    corner: [f64; 3],
    scale: f64,
    bits: u32,
    /// A millionth of the cloud's size: the least reach searched.
    hair: f64,
    /// The diagonal of the cloud's box: past twice it, every point is within.
    diagonal: f64,
    isa: Isa,
}

impl Octree {
    /// The tree of `points` (finite), or `None` for an empty cloud or one
    /// of 2³² points or more: codes of [`BITS`] bits a coordinate.
    pub(crate) fn new(points: &[Point]) -> Option<Self> {
        Self::with_finest(points, 0.0)
    }

    /// As [`Octree::new`], with codes no finer than needed for cells of
    /// edge `finest` (at most [`BITS`] bits a coordinate, at least
    /// [`FEWEST_BITS`]); 0 for the finest.
    ///
    /// Why: the codes are radix-sorted on every bit that varies, and bits
    /// far below the spacing of the points only cost time (on `kinect5`,
    /// 43 m wide, 21 bits cut cells of 21 µm for points 3 mm apart and
    /// more; 16 bits took the filter from 167 to 162 ms, median of eight
    /// alternated rounds). The results never depend on it: where more
    /// than a leaf's points share a code they are cut by count, as equal
    /// points are.
    pub(crate) fn with_finest(points: &[Point], finest: f64) -> Option<Self> {
        let n = points.len();
        if n == 0 || u32::try_from(n).is_err() {
            return None;
        }
        let (lo, hi) = crate::cloud::bounds(points)?;
        let extent = (0..3)
            .map(|a| f64::from(hi[a]) - f64::from(lo[a]))
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE);
        let bits = if finest > 0.0 {
            ((extent / finest).log2().ceil() as u32).clamp(FEWEST_BITS, BITS)
        } else {
            BITS
        };
        let scale = f64::from((1u32 << bits) - 1) / extent;
        let corner = lo.map(f64::from);
        let code = |p: &Point| {
            let c = |a: usize| ((f64::from(p[a]) - corner[a]) * scale) as u64;
            spread(c(0)) | (spread(c(1)) << 1) | (spread(c(2)) << 2)
        };
        let keyed = sort_by_code(points, 3 * bits - TOP, code);
        let (codes, ids): (Vec<u64>, Vec<u32>) = keyed.into_par_iter().unzip();
        let axis =
            |a: usize| -> Vec<f32> { ids.par_iter().map(|&i| points[i as usize][a]).collect() };
        let mut tree = Self {
            x: axis(0),
            y: axis(1),
            z: axis(2),
            ids,
            codes: Vec::new(),
            nodes: Vec::new(),
            groups: Vec::new(),
            corner,
            scale,
            bits,
            hair: (extent * 1e-6).max(f64::MIN_POSITIVE),
            diagonal: (0..3)
                .map(|a| (f64::from(hi[a]) - f64::from(lo[a])).powi(2))
                .sum::<f64>()
                .sqrt(),
            isa: Isa::best(),
        };
        let (nodes, groups) = Builder::tree(&tree.x, &tree.y, &tree.z, &codes, 3 * bits as i32 - 1);
        (tree.nodes, tree.groups, tree.codes) = (nodes, groups, codes);
        Some(tree)
    }

    /// Whether every point within the box `lo..hi` is in node `i`'s
    /// subtree: the box lies inside the node's Morton cell (shrunk by a
    /// hair for the rounding of the codes).
    fn cell_holds(&self, i: usize, lo: [f32; 3], hi: [f32; 3]) -> bool {
        let node = &self.nodes[i];
        let level = i32::from(node.level);
        if level < -1 {
            return false;
        }
        let code = self.codes[node.start as usize];
        let extent = f64::from(1u32 << self.bits) / self.scale;
        (0..3).all(|a| {
            // Far above the f64 rounding of a code's arithmetic.
            let hair = 1e-9 * extent + 1e-12 * self.corner[a].abs();
            // Bits of this axis at or below `level` are free in the cell.
            let free = if level >= a as i32 {
                (level - a as i32) as u32 / 3 + 1
            } else {
                0
            };
            let base = (compact(code >> a) >> free) << free;
            let cell_lo = self.corner[a] + base as f64 / self.scale + hair;
            let cell_hi = self.corner[a] + (base + (1u64 << free)) as f64 / self.scale - hair;
            f64::from(lo[a]) >= cell_lo && f64::from(hi[a]) < cell_hi
        })
    }

    /// Puts in `cand` the leaves whose boxes meet the box `lo..hi` widened
    /// by `reach` (a superset of those holding a point within `reach` of
    /// the box), walking the subtree of the first ancestor of node `from`
    /// whose cell holds the widened box.
    fn gather(&self, from: usize, lo: [f32; 3], hi: [f32; 3], reach: f64, cand: &mut Cand) {
        cand.clear();
        let (qlo, qhi) = widened(lo, hi, reach);
        let mut top = from;
        while top != 0 && !self.cell_holds(top, qlo, qhi) {
            top = self.nodes[top].parent as usize;
        }
        let end = self.nodes[top].skip as usize;
        let mut i = top;
        while i < end {
            let node = &self.nodes[i];
            let miss = (node.lo[0] > qhi[0])
                | (node.hi[0] < qlo[0])
                | (node.lo[1] > qhi[1])
                | (node.hi[1] < qlo[1])
                | (node.lo[2] > qhi[2])
                | (node.hi[2] < qlo[2]);
            if miss {
                i = node.skip as usize;
                continue;
            }
            if node.leaf {
                cand.leaf(node);
            }
            i += 1;
        }
        cand.fill(self);
    }

    /// `f` of the k nearest squared distances (the point itself counted;
    /// in any order, the k-th last) of every point, in input order; groups
    /// in parallel. `k` at most the number of points.
    pub(crate) fn map_k_nearest_distances<T, F>(&self, k: usize, f: F) -> Vec<T>
    where
        T: Send + Sync + Clone + Default,
        F: Fn(&[f32]) -> T + Sync + Send,
    {
        assert!(k >= 1 && k <= self.x.len(), "1 <= k <= number of points");
        let tasks: Vec<Vec<(u32, T)>> = self
            .groups
            .par_chunks(GROUPS_A_TASK)
            .map_init(Scratch::default, |scratch, groups| {
                let mut out = Vec::with_capacity(groups.len() * GROUP / 2);
                for &group in groups {
                    self.group_k_nearest(group as usize, k, scratch, &f, &mut out);
                }
                out
            })
            .collect();
        let mut result = vec![T::default(); self.x.len()];
        for task in tasks {
            for (i, v) in task {
                result[i as usize] = v;
            }
        }
        result
    }

    /// The k nearest of every point of group `group`, into `out` with their input indices.
    fn group_k_nearest<T, F>(
        &self,
        group: usize,
        k: usize,
        scratch: &mut Scratch,
        f: &F,
        out: &mut Vec<(u32, T)>,
    ) where
        F: Fn(&[f32]) -> T,
    {
        let node = self.nodes[group];
        // At least half the group's size (a task's first group has no
        // reach yet, and one after a group of equal points a reach of 0).
        let side = (0..3)
            .map(|a| f64::from(node.hi[a]) - f64::from(node.lo[a]))
            .fold(0.0, f64::max);
        let reach = scratch.reach.max(side / 2.0).max(self.hair);
        if scratch.guess <= 0.0 {
            scratch.guess = reach;
        }
        self.gather(group, node.lo, node.hi, reach, &mut scratch.cand);
        let mut widest: f64 = 0.0;
        let mut answer = |scratch: &mut Scratch, p: usize, widest: &mut f64| {
            let kth = f32::from_bits(scratch.bits[k - 1]);
            *widest = widest.max(f64::from(kth).sqrt());
            scratch.nearest.clear();
            scratch
                .nearest
                .extend(scratch.bits[..k].iter().map(|&b| f32::from_bits(b)));
            out.push((self.ids[p], f(&scratch.nearest)));
            kth
        };
        for p in node.start as usize..node.end as usize {
            if (p - node.start as usize).is_multiple_of(PART) {
                // The gather cut to the box of this part of the group.
                let part = p..(p + PART).min(node.end as usize);
                let (lo, hi) = self.bounds(part);
                let (lo, hi) = widened(lo, hi, reach);
                scratch.part.clear();
                scratch.part.inside(self.isa, &scratch.cand, lo, hi);
            }
            let q = [self.x[p], self.y[p], self.z[p]];
            let mut r = scratch.guess.min(reach);
            loop {
                scratch.bits.clear();
                let cap = (r * r) as f32;
                within::keep_distances(self.isa, q, scratch.part.run(), cap, &mut scratch.bits);
                let found = scratch.bits.len();
                if found >= k {
                    within::smallest_near(self.isa, &mut scratch.bits, k, scratch.pivot);
                    let kth = answer(scratch, p, &mut widest);
                    scratch.guess = (f64::from(kth).sqrt() * GUESS).max(reach / 64.0);
                    scratch.pivot = (kth * PIVOT).to_bits();
                    break;
                }
                if r >= reach {
                    scratch.failed.push((p, found));
                    break;
                }
                r = (r * grow(k, found)).max(reach / 64.0).min(reach);
            }
        }
        if !scratch.failed.is_empty() {
            // Those whose k nearest reach past the group's: together, on
            // one gather wide enough for the fewest found.
            let failed = std::mem::take(&mut scratch.failed);
            let (lo, hi) = self.bounds(failed.iter().map(|&(p, _)| p));
            let fewest = failed.iter().map(|&(_, found)| found).min().unwrap_or(0);
            let wider = reach * grow(k, fewest);
            self.gather(group, lo, hi, wider, &mut scratch.wider);
            for &(p, found) in &failed {
                let q = [self.x[p], self.y[p], self.z[p]];
                let mut r = (reach * grow(k, found)).min(wider);
                loop {
                    scratch.bits.clear();
                    let cap = (r * r) as f32;
                    within::keep_distances(
                        self.isa,
                        q,
                        scratch.wider.run(),
                        cap,
                        &mut scratch.bits,
                    );
                    if scratch.bits.len() >= k {
                        within::smallest(self.isa, &mut scratch.bits, k);
                        break;
                    }
                    if r >= wider {
                        self.lone_k_nearest(q, k, wider, scratch);
                        break;
                    }
                    r = wider;
                }
                answer(scratch, p, &mut widest);
            }
            scratch.failed = failed;
            scratch.failed.clear();
        }
        scratch.reach = widest * REACH;
    }

    /// The bounding box of the points at sorted positions `at`.
    fn bounds(&self, at: impl Iterator<Item = usize>) -> ([f32; 3], [f32; 3]) {
        bounds_of([&self.x, &self.y, &self.z], at)
    }

    /// The k nearest squared distances of `q` (any point, in any order but
    /// the k-th last) into `scratch.bits`, searching alone from a reach
    /// `from` within which `scratch.bits` holds fewer than k (or from a
    /// hair of the cloud's size when `from` is 0).
    fn lone_k_nearest(&self, q: [f32; 3], k: usize, from: f64, scratch: &mut Scratch) {
        let diagonal = self.diagonal;
        let mut reach = (from * grow(k, scratch.bits.len()))
            .max(diagonal * 1e-4)
            .max(self.hair);
        loop {
            // Past twice the cloud's diagonal every point is within.
            let all = reach > 2.0 * diagonal;
            let r = if all {
                f64::from(f32::MAX).sqrt()
            } else {
                reach
            };
            self.gather(0, q, q, r, &mut scratch.lone);
            scratch.bits.clear();
            within::keep_distances(
                self.isa,
                q,
                scratch.lone.run(),
                (r * r) as f32,
                &mut scratch.bits,
            );
            if scratch.bits.len() >= k {
                within::smallest(self.isa, &mut scratch.bits, k);
                return;
            }
            assert!(!all, "k at most the number of points");
            reach *= grow(k, scratch.bits.len());
        }
    }

    /// The k-th distances (not squared) of `probes` points spread evenly
    /// over the Morton order (so over the points, wherever they crowd),
    /// ascending: how the density varies.
    pub(crate) fn probe_k_nearest(&self, k: usize, probes: usize) -> Vec<f64> {
        let n = self.x.len();
        if k == 0 || k > n {
            return Vec::new();
        }
        let mut scratch = Scratch::default();
        let probes = probes.min(n);
        let mut kth: Vec<f64> = (0..probes)
            .map(|j| {
                let p = j * n / probes;
                self.lone_k_nearest([self.x[p], self.y[p], self.z[p]], k, 0.0, &mut scratch);
                f64::from(f32::from_bits(scratch.bits[k - 1])).sqrt()
            })
            .collect();
        kth.sort_unstable_by(f64::total_cmp);
        kth
    }
}

/// Builds the tree's nodes (depth first) and groups over points sorted by
/// code: the top of the tree alone, its subtrees of at most a task's
/// points in parallel, each into nodes of its own, then put in place.
/// (Built alone, the tree took 6–7 ms of `kinect5`'s 160–200.)
struct Builder<'a> {
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
    codes: &'a [u64],
    nodes: Vec<Node>,
    groups: Vec<u32>,
}

/// A subtree built by a task of its own: its sorted positions and the bit
/// its codes share those above. (It lies within no group: the nodes above
/// it hold more points than a task, and a task more than a group.)
type Task = (usize, usize, i32);

impl<'a> Builder<'a> {
    fn new(x: &'a [f32], y: &'a [f32], z: &'a [f32], codes: &'a [u64]) -> Self {
        Self {
            x,
            y,
            z,
            codes,
            nodes: Vec::new(),
            groups: Vec::new(),
        }
    }

    /// The nodes and groups of the tree over all of `codes` (sorted),
    /// whose bits above `bit` are free.
    fn tree(x: &[f32], y: &[f32], z: &[f32], codes: &[u64], bit: i32) -> (Vec<Node>, Vec<u32>) {
        let n = codes.len();
        let most = n.div_ceil(rayon::current_num_threads() * 8).max(4096);
        let mut tasks = Vec::new();
        top_tasks(codes, 0, n, bit, most, &mut tasks);
        let built: Vec<Builder> = tasks
            .par_iter()
            .map(|&(s, e, bit)| {
                let mut b = Builder::new(x, y, z, codes);
                b.build(s, e, bit, false);
                b
            })
            .collect();
        let mut top = Builder::new(x, y, z, codes);
        top.nodes
            .reserve(built.iter().map(|b| b.nodes.len()).sum::<usize>() + 2 * tasks.len());
        let mut built = built.into_iter();
        top.build_top(0, n, bit, most, &mut built);
        (top.nodes, top.groups)
    }

    /// As [`Builder::build`], but a subtree of at most `most` points is
    /// the next of `built` (built from [`top_tasks`]' list, in the same
    /// order), put in place.
    fn build_top(
        &mut self,
        s: usize,
        e: usize,
        bit: i32,
        most: usize,
        built: &mut impl Iterator<Item = Builder<'a>>,
    ) -> usize {
        if e - s <= most {
            let task = built.next().expect("a built subtree for each task");
            let at = self.nodes.len() as u32;
            self.nodes.extend(task.nodes.into_iter().map(|mut node| {
                node.skip += at;
                node.parent += at;
                node
            }));
            self.groups.extend(task.groups.into_iter().map(|g| g + at));
            return at as usize;
        }
        let me = self.nodes.len();
        self.nodes.push(Node::default());
        let (split, b) = split_at(self.codes, s, e, bit);
        let left = self.build_top(s, split, b - 1, most, built);
        let right = self.build_top(split, e, b - 1, most, built);
        self.join(me, left, right, s, e, bit);
        me
    }

    /// Appends the subtree of sorted positions `s..e`, whose codes share
    /// their bits above `bit`; returns its node.
    fn build(&mut self, s: usize, e: usize, bit: i32, grouped: bool) -> usize {
        let me = self.nodes.len();
        self.nodes.push(Node::default());
        let grouped = grouped || {
            if e - s <= GROUP {
                self.groups.push(me as u32);
            }
            e - s <= GROUP
        };
        if e - s <= LEAF {
            let (lo, hi) = bounds_of([self.x, self.y, self.z], s..e);
            self.nodes[me] = Node {
                lo,
                hi,
                start: s as u32,
                end: e as u32,
                skip: me as u32 + 1,
                parent: 0,
                level: level(bit),
                leaf: true,
            };
            return me;
        }
        let (split, b) = split_at(self.codes, s, e, bit);
        let left = self.build(s, split, b - 1, grouped);
        let right = self.build(split, e, b - 1, grouped);
        self.join(me, left, right, s, e, bit);
        me
    }

    /// Makes node `me` the parent of `left` and `right` (the last nodes).
    fn join(&mut self, me: usize, left: usize, right: usize, s: usize, e: usize, bit: i32) {
        self.nodes[left].parent = me as u32;
        self.nodes[right].parent = me as u32;
        let (l, r) = (self.nodes[left], self.nodes[right]);
        self.nodes[me] = Node {
            lo: std::array::from_fn(|a| l.lo[a].min(r.lo[a])),
            hi: std::array::from_fn(|a| l.hi[a].max(r.hi[a])),
            start: s as u32,
            end: e as u32,
            skip: self.nodes.len() as u32,
            parent: 0,
            level: level(bit),
            leaf: false,
        };
    }
}

/// Lists, in depth-first order, the subtrees of at most `most` points that
/// [`Builder::build_top`] meets below the node of `s..e`.
fn top_tasks(codes: &[u64], s: usize, e: usize, bit: i32, most: usize, out: &mut Vec<Task>) {
    if e - s <= most {
        out.push((s, e, bit));
        return;
    }
    let (split, b) = split_at(codes, s, e, bit);
    top_tasks(codes, s, split, b - 1, most, out);
    top_tasks(codes, split, e, b - 1, most, out);
}

/// Where the sorted codes `s..e` (sharing their bits above `bit`, more
/// than a leaf's) split: at the highest bit in which they differ (those
/// with it clear come first), or, all equal, in half by count; and that bit.
fn split_at(codes: &[u64], s: usize, e: usize, bit: i32) -> (usize, i32) {
    let mut b = bit;
    loop {
        if b < 0 {
            return ((s + e) / 2, b);
        }
        let m = s + codes[s..e].partition_point(|c| (c >> b) & 1 == 0);
        if m > s && m < e {
            return (m, b);
        }
        b -= 1;
    }
}

/// The bounding box of the points at positions `at` of the axes `xyz`.
fn bounds_of(xyz: [&[f32]; 3], at: impl Iterator<Item = usize>) -> ([f32; 3], [f32; 3]) {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in at {
        for a in 0..3 {
            lo[a] = lo[a].min(xyz[a][p]);
            hi[a] = hi[a].max(xyz[a][p]);
        }
    }
    (lo, hi)
}

/// A node's level from the bit its codes share those above.
fn level(bit: i32) -> i8 {
    bit.max(-100) as i8
}

/// The leaves of a gather, and their points copied into one run.
#[derive(Default)]
struct Cand {
    /// Each leaf's sorted positions.
    spans: Vec<(u32, u32)>,
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl Cand {
    fn clear(&mut self) {
        self.spans.clear();
        self.x.clear();
        self.y.clear();
        self.z.clear();
    }

    fn leaf(&mut self, node: &Node) {
        self.spans.push((node.start, node.end));
    }

    /// Copies the leaves' points, leaves next to each other in one copy.
    fn fill(&mut self, tree: &Octree) {
        let (mut s, mut e) = (0usize, 0usize);
        let mut copy = |s: usize, e: usize| {
            self.x.extend_from_slice(&tree.x[s..e]);
            self.y.extend_from_slice(&tree.y[s..e]);
            self.z.extend_from_slice(&tree.z[s..e]);
        };
        for &(ls, le) in &self.spans {
            let (ls, le) = (ls as usize, le as usize);
            if ls != e {
                copy(s, e);
                s = ls;
            }
            e = le;
        }
        copy(s, e);
    }

    /// Copies the points of `from` inside the box `lo..hi`.
    fn inside(&mut self, isa: Isa, from: &Cand, lo: [f32; 3], hi: [f32; 3]) {
        within::keep_inside(
            isa,
            from.run(),
            lo,
            hi,
            [&mut self.x, &mut self.y, &mut self.z],
        );
    }

    fn run(&self) -> Run<'_> {
        Run {
            x: &self.x,
            y: &self.y,
            z: &self.z,
        }
    }
}

/// Buffers and the running guesses of one task.
#[derive(Default)]
struct Scratch {
    /// The gathers of a group, of its points left for after it, and of a
    /// point searched alone.
    cand: Cand,
    /// The group's gather cut to the box of a part of it.
    part: Cand,
    wider: Cand,
    lone: Cand,
    bits: Vec<u32>,
    nearest: Vec<f32>,
    /// The next group's reach and the next point's radius.
    reach: f64,
    guess: f64,
    /// The split of the next point's distances (as bits; 0 before any).
    pivot: u32,
    /// The group's points left for after it, with the count each found.
    failed: Vec<(usize, usize)>,
}

/// How much to widen a search that found `found` of the `k` it wants: on
/// a surface the count grows as the radius squared, so by the shortfall's
/// root, a little more (at least ×1.25, at most ×4).
fn grow(k: usize, found: usize) -> f64 {
    ((k as f64 / found.max(1) as f64).sqrt() * 1.2).clamp(1.25, 4.0)
}

/// The box `lo..hi` widened by `reach` (and [`SLACK`]), rounded outwards to f32.
fn widened(lo: [f32; 3], hi: [f32; 3], reach: f64) -> ([f32; 3], [f32; 3]) {
    let wide = reach * (1.0 + SLACK);
    (
        lo.map(|v| within_f32(v, wide).0),
        hi.map(|v| within_f32(v, wide).1),
    )
}

/// `(code, index)` of every point, sorted: dealt by the code's top [`TOP`]
/// bits (those from `shift` up) in parallel (each part counts its own,
/// then writes its own places), then each bucket sorted, in parallel.
fn sort_by_code(points: &[Point], shift: u32, code: impl Fn(&Point) -> u64 + Sync) -> Vec<Keyed> {
    let n = points.len();
    let buckets = 1usize << TOP;
    let part = n.div_ceil(rayon::current_num_threads() * 4).max(4096);
    let codes: Vec<u64> = points.par_iter().map(&code).collect();
    let counts: Vec<Vec<u32>> = codes
        .par_chunks(part)
        .map(|c| {
            let mut count = vec![0u32; buckets];
            for &x in c {
                count[(x >> shift) as usize] += 1;
            }
            count
        })
        .collect();
    // Each part's first place in each bucket, and each bucket's start.
    let mut starts = vec![0usize; buckets + 1];
    let mut firsts = vec![vec![0u32; buckets]; counts.len()];
    let mut at = 0u32;
    for b in 0..buckets {
        starts[b] = at as usize;
        for (first, count) in firsts.iter_mut().zip(&counts) {
            first[b] = at;
            at += count[b];
        }
    }
    starts[buckets] = n;
    let mut keyed = vec![(0u64, 0u32); n];
    {
        /// Where the parts write: each its own places, by the counts.
        struct Places(*mut Keyed);
        // SAFETY: the parts write disjoint places (below).
        unsafe impl Sync for Places {}
        let places = Places(keyed.as_mut_ptr());
        codes
            .par_chunks(part)
            .zip(firsts)
            .enumerate()
            .for_each(|(j, (c, mut first))| {
                let places = &places;
                for (i, &x) in c.iter().enumerate() {
                    let slot = &mut first[(x >> shift) as usize];
                    // SAFETY: part j's places in bucket b are
                    // firsts[j][b]..firsts[j][b] + counts[j][b], disjoint
                    // from every other part's and bucket's and below n.
                    unsafe {
                        places
                            .0
                            .add(*slot as usize)
                            .write((x, (j * part + i) as u32))
                    };
                    *slot += 1;
                }
            });
    }
    let mut buckets_of: Vec<&mut [Keyed]> = Vec::new();
    let mut rest = &mut keyed[..];
    for w in starts.windows(2) {
        let (bucket, after) = std::mem::take(&mut rest).split_at_mut(w[1] - w[0]);
        if bucket.len() > 1 {
            buckets_of.push(bucket);
        }
        rest = after;
    }
    buckets_of
        .into_par_iter()
        .for_each_init(Vec::new, |spare, bucket| sort_bucket(bucket, shift, spare));
    keyed
}

/// A point's Morton code and input index.
type Keyed = (u64, u32);

/// Sorts a bucket of `(code, index)` (indices ascending, codes sharing
/// their bits from `shift` up) by code, then index: by comparison when
/// short, else by a least-significant-digit radix sort (stable, so equal
/// codes keep their indices ascending) on the digits below `shift` that
/// vary. (On `kinect5`, whose top 16 bits leave cells about a metre
/// wide, sorting the buckets by comparison took 6 % of the filter.)
fn sort_bucket(bucket: &mut [Keyed], shift: u32, spare: &mut Vec<Keyed>) {
    const DIGIT: u32 = 11;
    const MASK: u64 = (1 << DIGIT) - 1;
    if bucket.len() <= 256 {
        bucket.sort_unstable();
        return;
    }
    let varying = bucket.iter().fold(0u64, |m, e| m | (e.0 ^ bucket[0].0));
    spare.clear();
    spare.resize(bucket.len(), (0, 0));
    let mut in_spare = false;
    for at in (0..shift).step_by(DIGIT as usize) {
        if (varying >> at) & MASK == 0 {
            continue;
        }
        let (from, to): (&[Keyed], &mut [Keyed]) = if in_spare {
            (spare, bucket)
        } else {
            (bucket, spare)
        };
        let mut count = [0u32; 1 << DIGIT];
        for e in from {
            count[((e.0 >> at) & MASK) as usize] += 1;
        }
        let mut sum = 0;
        for c in count.iter_mut() {
            (*c, sum) = (sum, sum + *c);
        }
        for e in from {
            let slot = &mut count[((e.0 >> at) & MASK) as usize];
            to[*slot as usize] = *e;
            *slot += 1;
        }
        in_spare = !in_spare;
    }
    if in_spare {
        bucket.copy_from_slice(spare);
    }
}

/// Spreads the low 21 bits of `v` to every third bit (a Morton code's axis).
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// The inverse of [`spread`]: every third bit of `x` from bit 0, packed.
fn compact(x: u64) -> u64 {
    let mut x = x & 0x1249_2492_4924_9249;
    x = (x | (x >> 2)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x >> 4)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x >> 8)) & 0x001f_0000_ff00_00ff;
    x = (x | (x >> 16)) & 0x001f_0000_0000_ffff;
    x = (x | (x >> 32)) & 0x1f_ffff;
    x
}

#[cfg(test)]
mod tests {
    use super::super::kdtree::KdTree;
    use super::*;

    /// The distances as sorted bits, after checking that the k-th is last.
    fn bits(d: &[f32]) -> Vec<u32> {
        let mut b: Vec<u32> = d.iter().map(|x| x.to_bits()).collect();
        assert_eq!(b.iter().max(), b.last(), "the k-th is last");
        b.sort_unstable();
        b
    }

    fn agree(points: &[Point], k: usize) {
        let want = KdTree::new(points).map_k_nearest_distances(k, bits);
        let got = Octree::new(points)
            .expect("an octree")
            .map_k_nearest_distances(k, bits);
        let wrong = (0..points.len()).filter(|&i| want[i] != got[i]).count();
        assert_eq!(
            wrong,
            0,
            "{wrong} of {} points differ (k = {k})",
            points.len()
        );
    }

    /// Two camera-like scans of very different density side by side, with
    /// strays above them and duplicated points.
    fn uneven(n: usize, seed: u64) -> Vec<Point> {
        let mut u = crate::testing::uniform(seed);
        let mut points: Vec<Point> = (0..n)
            .map(|i| {
                let (scale, at) = if i % 3 == 0 { (0.2, 0.0) } else { (4.0, 10.0) };
                let (x, y) = (u() * scale, u() * scale);
                [
                    at + x,
                    y,
                    (x * 3.0 / scale).sin() * scale * 0.1 + 0.002 * u(),
                ]
            })
            .collect();
        for i in 0..n / 100 {
            points[i * 97 % n][2] += 1.0 + u() * 5.0;
        }
        for i in 0..n / 200 {
            points[i * 31 % n] = points[i * 37 % n];
        }
        points
    }

    #[test]
    fn the_k_nearest_are_the_trees_bit_for_bit() {
        for (n, seed) in [(40_000, 1), (9_000, 2)] {
            let points = uneven(n, seed);
            for k in [1, 2, 21, 51] {
                agree(&points, k);
            }
        }
    }

    #[test]
    fn the_tree_built_in_parts_is_the_tree_built_whole() {
        // Enough points for a dozen tasks, with runs of equal points.
        let mut points = uneven(60_000, 4);
        points.extend(std::iter::repeat_n([0.5, 0.5, 0.0], 5_000));
        let tree = Octree::new(&points).unwrap();
        let codes = &tree.codes;
        let mut whole = Builder::new(&tree.x, &tree.y, &tree.z, codes);
        whole.build(0, codes.len(), 3 * BITS as i32 - 1, false);
        assert!(whole.nodes == tree.nodes, "the nodes differ");
        assert_eq!(whole.groups, tree.groups);
        let mut tasks = Vec::new();
        top_tasks(codes, 0, codes.len(), 3 * BITS as i32 - 1, 4096, &mut tasks);
        assert!(tasks.len() >= 12, "{} tasks", tasks.len());
    }

    #[test]
    fn coarse_codes_agree_too() {
        // Cells from far finer than the points' spacing to 1/64 of the
        // cloud (6 bits, thousands of points a code, cut by count).
        let points = uneven(20_000, 3);
        let want = KdTree::new(&points).map_k_nearest_distances(51, bits);
        let (lo, hi) = crate::cloud::bounds(&points).unwrap();
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f32::max) as f64;
        for (finest, expect_bits) in [
            (1e-9, BITS),
            (extent / 65_536.0, 16),
            (extent / 1000.0, 10),
            (extent, FEWEST_BITS),
        ] {
            let tree = Octree::with_finest(&points, finest).expect("an octree");
            assert_eq!(tree.bits, expect_bits, "finest {finest}");
            let got = tree.map_k_nearest_distances(51, bits);
            let wrong = (0..points.len()).filter(|&i| want[i] != got[i]).count();
            assert_eq!(wrong, 0, "{wrong} points differ at {expect_bits} bits");
        }
    }

    #[test]
    fn a_thick_layer_a_line_and_far_clusters_agree_too() {
        let mut u = crate::testing::uniform(7);
        // A block of noise, as thick as it is wide.
        let block: Vec<Point> = (0..20_000).map(|_| [u(), u(), u()]).collect();
        agree(&block, 51);
        // A line (every code differs in one axis only).
        let line: Vec<Point> = (0..5_000).map(|i| [i as f32 * 1e-3, 0.0, 0.0]).collect();
        agree(&line, 21);
        // Clusters kilometres apart: most cells empty.
        let far: Vec<Point> = (0..12_000)
            .map(|i| {
                let c = (i % 3) as f32 * 2_000.0;
                [c + u(), c * 0.5 + u(), u() * 0.1]
            })
            .collect();
        agree(&far, 51);
    }

    /// Clusters of every size (many with fewer points than k) and spread,
    /// in a box of 20 m: many groups with points whose k nearest lie past
    /// the group's reach, some searched alone.
    fn clusters(seed: u64) -> Vec<Point> {
        let mut u = crate::testing::uniform(seed);
        let mut points = Vec::new();
        for _ in 0..60 {
            let centre = [u() * 20.0, u() * 20.0, u() * 2.0];
            let n = 5 + (u() * u() * 3000.0) as usize;
            let spread = 0.01 + u() * u();
            points.extend((0..n).map(|_| {
                std::array::from_fn(|a| {
                    centre[a] + (u() - 0.5) * spread * if a == 2 { 0.3 } else { 1.0 }
                })
            }));
        }
        points
    }

    /// A plane in tiles of 1 m alternately dense (1 cm) and sparse (6 cm),
    /// jittered: groups at the tiles' edges hold points of both.
    fn checkerboard(seed: u64) -> Vec<Point> {
        let mut u = crate::testing::uniform(seed);
        let mut points = Vec::new();
        for tx in 0..6 {
            for ty in 0..6 {
                let step = if (tx + ty) % 2 == 0 { 0.01 } else { 0.06 };
                let n = (1.0 / step) as usize;
                for i in 0..n {
                    for j in 0..n {
                        points.push([
                            tx as f32 + (i as f32 + u()) * step,
                            ty as f32 + (j as f32 + u()) * step,
                            0.002 * u(),
                        ]);
                    }
                }
            }
        }
        points
    }

    #[test]
    fn clusters_of_every_size_and_tiles_of_two_densities_agree_too() {
        for seed in 1..=6 {
            let points = clusters(seed);
            agree(&points, 51);
            agree(&points, 8);
        }
        for seed in 1..=2 {
            agree(&checkerboard(seed), 51);
        }
    }

    #[test]
    fn a_group_searched_from_any_reach_agrees() {
        // Every seventh group of the tiles, each from reaches far too
        // small to far too large: its points found at once, on the wider
        // gather of those left, or alone, one after another.
        let mut points = checkerboard(3);
        points.extend(clusters(4).iter().map(|p| [p[0] - 25.0, p[1], p[2]]));
        let tree = Octree::new(&points).unwrap();
        let k = 51;
        let want = KdTree::new(&points).map_k_nearest_distances(k, bits);
        let (mut wrong, mut checked) = (0, 0);
        for &group in tree.groups.iter().step_by(7) {
            for reach in [0.002, 0.008, 0.02, 0.05, 0.2, 0.6] {
                let mut scratch = Scratch {
                    reach,
                    ..Default::default()
                };
                let mut out = Vec::new();
                tree.group_k_nearest(group as usize, k, &mut scratch, &bits, &mut out);
                for (i, got) in out {
                    checked += 1;
                    wrong += usize::from(got != want[i as usize]);
                }
            }
        }
        assert!(checked > 10_000);
        assert_eq!(wrong, 0, "{wrong} of {checked} differ");
    }

    #[test]
    fn a_few_strays_far_above_a_scan_agree_too() {
        // Fewer strays than k, spread over a few metres far above a scan:
        // a group of them finds its k nearest on no gather of its own, and
        // they are searched one after another, each alone.
        let mut u = crate::testing::uniform(11);
        let mut points: Vec<Point> = (0..20_000)
            .map(|_| [u() * 20.0, u() * 20.0, 0.01 * u()])
            .collect();
        points.extend((0..40).map(|_| [8.0 + u() * 4.0, 8.0 + u() * 4.0, 60.0 + u() * 3.0]));
        agree(&points, 51);
        agree(&points, 21);
    }

    #[test]
    fn many_equal_points_are_cut_by_count_and_agree() {
        // Far more equal points than a leaf holds (cut from equal codes by
        // count, cells of no use), beside a few others.
        let mut points = vec![[1.0f32, 2.0, 3.0]; 3_000];
        points.extend((0..500).map(|i| [1.0 + i as f32 * 1e-3, 2.0, 3.0]));
        agree(&points, 51);
        // All of them equal, and the fewest points k allows.
        agree(&vec![[0.5f32, 0.5, 0.5]; 200], 51);
        agree(&uneven(52, 3), 51);
    }

    #[test]
    fn codes_sort_as_numbers_and_cells_hold_their_points() {
        let points = uneven(30_000, 5);
        let tree = Octree::new(&points).unwrap();
        assert!(tree.codes.windows(2).all(|w| w[0] <= w[1]));
        let mut ids = tree.ids.clone();
        ids.sort_unstable();
        assert!(ids.iter().enumerate().all(|(i, &id)| id as usize == i));
        // Every node's cell (where it has one) holds its own points' box.
        for (i, node) in tree.nodes.iter().enumerate() {
            if node.level >= -1 && node.lo[0] <= node.hi[0] {
                assert!(
                    tree.cell_holds(i, node.lo, node.hi) || {
                        // (a box touching the cell's edge within the hair)
                        let (lo, hi) = widened(node.lo, node.hi, -1e-6);
                        tree.cell_holds(i, lo, hi)
                    },
                    "node {i}"
                );
            }
        }
        for v in [0u64, 1, 0x1f_ffff, 0x15_5555, 123_456] {
            assert_eq!(compact(spread(v)), v);
        }
    }

    #[test]
    fn probes_are_the_trees_k_th_distances() {
        let points = uneven(20_000, 9);
        let tree = Octree::new(&points).unwrap();
        let kth = tree.probe_k_nearest(51, 64);
        let mut want: Vec<f64> = (0..64)
            .map(|j| {
                let i = tree.ids[j * points.len() / 64] as usize;
                let mut d: Vec<f32> = points
                    .iter()
                    .map(|p| super::super::kdtree::squared_distance(&points[i], p))
                    .collect();
                d.sort_by(f32::total_cmp);
                f64::from(d[50]).sqrt()
            })
            .collect();
        want.sort_unstable_by(f64::total_cmp);
        assert_eq!(kth, want);
    }
}
