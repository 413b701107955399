//! Exact neighbour searches on a uniform grid of columns, for dense scans:
//! the k nearest distances (statistical removal), a count within a radius
//! (radius removal) and all points within a radius (smoothing).
//!
//! Why beside the k-d tree: on a LiDAR scan the k nearest of a point lie in
//! a ball whose radius changes slowly over the cloud. Points are filed in
//! vertical columns of side `h` (about twice the k-th distance, or the
//! search radius), numbered in 8 × 8 blocks so that neighbouring columns
//! lie close in memory, each column sorted by height and cut in slabs of
//! `h / 2` whose first positions are stored; points are queried in that
//! order. A k-nearest query takes the k-th distance of the point before
//! it, a little more, as a radius r; the columns that meet the box q ± r
//! give the runs of points whose height may be within r (a row of a
//! block's columns, numbered in a run, as one run where their heights lie
//! within the box's, as on a surface; else each column by two look-ups in
//! its slabs), and one vector pass over those contiguous runs
//! (`search::within`) gives their squared distances and keeps those within r.
//! If k of them lie within r, they hold the k nearest (kept by a sorting
//! network, `within::smallest`); otherwise r grows
//! (by the count found, as on a surface) and the query is repeated. The
//! queries are the grid's own points, a column's after one another, so the
//! 3 × 3 columns round a column are described once for its queries and a
//! query whose radius is below a column's side takes its runs from them
//! (`near.rs`); a radius count reads first the points filed round the
//! query's own, which on a dense scan already hold the few it wants. A
//! point far from the rest (an outlier above the scan, whose box would
//! sweep many columns) is answered after the others (`far.rs`): blocks of
//! columns searched nearest box first, and a block's columns nearest
//! first (a k-d tree built for them at 2 M points and more answered them
//! more slowly since, and took 0.8 GB more at 20 M). A grid searched once
//! may be searched again with some points dropped (`ColumnGrid::retain`: the
//! statistical filter on what the radius filter kept, on columns sized for
//! both). In place of the
//! tree's walk with a branch a node, a query costs a few look-ups and
//! some six times k distances:
//! the statistical filter on the 1 M-point bench pile fell from 2.15 s
//! (the tree alone) to 0.64–0.79 s (BENCHMARKS.md, 2026-12-03). A cloud
//! whose grid would need far more columns than points (two scans
//! kilometres apart) is declined and the caller uses the k-d tree; both
//! give the same distances, bit for bit.
//!
//! Arithmetic as in `search::kdtree`: squared distances in f32 in FLANN's order,
//! so that the sums agree with PCL's; the box is the radius widened by a
//! relative 1e-4, far above the f32 rounding of a squared distance, so no
//! point within r is left out of it.

use std::mem::MaybeUninit;

use rayon::prelude::*;

mod far;
mod near;

use super::bounds::{within_f32 as heights_within, SLACK};
use super::within::{self, Run};
use crate::simd::Isa;
use near::Near;

use crate::Point;

/// Columns allowed per point before the grid is declined.
const COLUMNS_PER_POINT: usize = 8;

/// A column's span widened by this share of its side (see `ColumnGrid::off_columns`).
const MARGIN: f64 = 1e-6;

/// The distance from `v` to the span `lo..=hi` (0 within).
#[inline]
fn gap(v: f64, lo: f64, hi: f64) -> f64 {
    larger(larger(lo - v, v - hi), 0.0)
}

/// The larger of two numbers that are not NaN (coordinates, distances):
/// one instruction, where `f64::max` must also order a NaN (three more, in
/// the search's innermost bookkeeping).
#[inline(always)]
fn larger<T: PartialOrd>(a: T, b: T) -> T {
    if a > b {
        a
    } else {
        b
    }
}

/// The smaller of two numbers that are not NaN (see [`larger`]).
#[inline(always)]
fn smaller<T: PartialOrd>(a: T, b: T) -> T {
    if a < b {
        a
    } else {
        b
    }
}

/// Points filed by column (numbered in blocks, see `block_index`), each column by height.
pub(crate) struct ColumnGrid {
    /// Corner of the grid (the cloud's minimum) and cell side.
    origin: [f64; 3],
    h: f64,
    /// Columns along x and y.
    nx: usize,
    ny: usize,
    /// First sorted position of each column (numbered by [`block_index`]),
    /// and one past the last.
    start: Vec<u32>,
    /// Each column's height index.
    slabs: Vec<Slabs>,
    /// The first sorted position of each slab, per column (from
    /// `Slabs::first`), and one past the column's last point.
    slab_start: Vec<u32>,
    /// The lowest and highest height of each block of columns (infinite,
    /// the wrong way round, for an empty one).
    block_heights: Vec<(f32, f32)>,
    /// Coordinates in sorted order.
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    /// Input index of each sorted position.
    ids: Vec<u32>,
    /// Input indices run below this: the points filed, and after
    /// [`ColumnGrid::retain`] those it dropped.
    inputs: usize,
    /// The search loop's instruction set.
    isa: Isa,
}

impl ColumnGrid {
    /// Files `points` (finite, more than `k`) on columns whose side suits
    /// their k-th neighbour distance, or `None` when the cloud is too
    /// sparse for a grid (see the module docs).
    pub(crate) fn for_k_nearest(points: &[Point], k: usize) -> Option<Self> {
        Self::for_k_nearest_at_least(points, k, 0.0)
    }

    /// [`ColumnGrid::for_k_nearest`] with columns at least `min_side` wide (so
    /// that the same grid serves searches within a radius below it), or
    /// `None` also when that is more than [`WIDER`] times the side the k
    /// nearest want.
    pub(crate) fn for_k_nearest_at_least(
        points: &[Point],
        k: usize,
        min_side: f64,
    ) -> Option<Self> {
        let n = points.len();
        if n <= k || u32::try_from(n).is_err() {
            return None;
        }
        let (lo, hi) = bounds(points);
        // A side from the density over the columns the points occupy (a
        // scan is a surface: k points in a disc of radius h), found on a
        // first grid of 16 points a column on the box's floor.
        let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(f64::MIN_POSITIVE);
        let first = (16.0 * area / n as f64).sqrt();
        let side = match Columns::occupied(points, lo, hi, first) {
            Some((h, occupied)) => {
                // (A column with one point is a stray's: an outlier's.)
                let covered = occupied as f64 * h * h;
                (covered * k as f64 / (std::f64::consts::PI * n as f64)).sqrt()
            }
            None => first,
        };
        let first = Self::new(points, lo, hi, (side * SIDE).max(min_side))?;
        // The density over the columns assumes a surface; where the range
        // noise makes the scan a layer of some thickness (dense scans) the
        // k nearest lie much closer. The median k-th distance of evenly
        // spread points tells, and a grid far off it is made again.
        // (Points far from the rest, an outlier above the scan, would
        // sweep many columns for nothing here: they are passed over.)
        let probes = PROBES.min(n);
        let mut scratch = Scratch::default();
        let mut kth: Vec<f64> = (0..probes)
            .filter_map(|i| {
                let kth =
                    first.k_nearest(i * n / probes, first.h / SIDE, k, &mut scratch, false)?;
                Some(f64::from(kth).sqrt())
            })
            .collect();
        if kth.is_empty() {
            return Some(first);
        }
        kth.sort_unstable_by(f64::total_cmp);
        let side = kth[kth.len() / 2] * SIDE;
        if min_side > WIDER * side {
            return None;
        }
        let side = side.max(min_side);
        if side > 0.0 && (side < first.h / 1.5 || side > first.h * 1.5) {
            Self::new(points, lo, hi, side).or(Some(first))
        } else {
            Some(first)
        }
    }

    /// Files `points` (finite) on columns as wide as `radius`, for
    /// searches within it, or `None` when the cloud is too sparse for a grid.
    pub(crate) fn for_radius(points: &[Point], radius: f64) -> Option<Self> {
        if points.is_empty() || u32::try_from(points.len()).is_err() {
            return None;
        }
        let (lo, hi) = bounds(points);
        // A hair wider than the radius, so that a box of the radius
        // (widened by `SLACK`) reaches no further than the columns next
        // to its own (`near.rs`).
        Self::new(points, lo, hi, radius_side(radius))
    }

    /// The grid of the points that `keep` marks by sorted position (as
    /// [`ColumnGrid::map_has_within_in_grid_order`] gives it), which keep their
    /// input indices: the same columns, each still by height, the others
    /// dropped in place, with no sort and no new memory but a copy of the
    /// column starts (a filter's output
    /// searched again: the statistical filter after the radius filter).
    /// Its results in input order hold the dropped points' places too.
    pub(crate) fn retain(self, keep: &[bool]) -> Self {
        let Self {
            origin,
            h,
            nx,
            ny,
            mut start,
            mut x,
            mut y,
            mut z,
            mut ids,
            inputs,
            ..
        } = self;
        // Runs of columns in parallel, each kept point moved down to the
        // next free position of its run (never up, so none is overwritten
        // before it is read); then each run's kept points moved down next
        // to the run before's, one block copy an axis.
        let old = start.clone();
        let columns = old.len() - 1;
        let firsts: Vec<usize> = (0..columns)
            .step_by(RETAIN_COLUMNS)
            .chain(std::iter::once(columns))
            .collect();
        let mut parts = Vec::with_capacity(firsts.len());
        let (mut xs, mut ys, mut zs) = (&mut x[..], &mut y[..], &mut z[..]);
        let (mut is, mut ends) = (&mut ids[..], &mut start[1..]);
        for w in firsts.windows(2) {
            let (c0, c1) = (w[0], w[1]);
            let size = (old[c1] - old[c0]) as usize;
            let (px, rx) = std::mem::take(&mut xs).split_at_mut(size);
            let (py, ry) = std::mem::take(&mut ys).split_at_mut(size);
            let (pz, rz) = std::mem::take(&mut zs).split_at_mut(size);
            let (pi, ri) = std::mem::take(&mut is).split_at_mut(size);
            let (pe, re) = std::mem::take(&mut ends).split_at_mut(c1 - c0);
            parts.push((c0, [px, py, pz], pi, pe));
            (xs, ys, zs, is, ends) = (rx, ry, rz, ri, re);
        }
        let counts: Vec<usize> = parts
            .into_par_iter()
            .map(|(c0, [px, py, pz], pi, pe)| {
                let base = old[c0] as usize;
                let keep = &keep[base..];
                let mut at = 0;
                for (j, end) in pe.iter_mut().enumerate() {
                    let (s, e) = (old[c0 + j] as usize - base, old[c0 + j + 1] as usize - base);
                    for p in s..e {
                        if keep[p] {
                            px[at] = px[p];
                            py[at] = py[p];
                            pz[at] = pz[p];
                            pi[at] = pi[p];
                            at += 1;
                        }
                    }
                    *end = at as u32;
                }
                at
            })
            .collect();
        // (from, count, to) of each run; every array moved on its own, two
        // at a time.
        let mut at = 0;
        let mut moves = Vec::with_capacity(counts.len());
        for (w, &count) in firsts.windows(2).zip(&counts) {
            let (c0, c1) = (w[0], w[1]);
            moves.push((old[c0] as usize, count, at));
            for end in &mut start[c0 + 1..=c1] {
                *end += at as u32;
            }
            at += count;
        }
        rayon::join(
            || {
                close_up(&mut x, &moves);
                close_up(&mut y, &moves);
            },
            || {
                close_up(&mut z, &moves);
                close_up(&mut ids, &moves);
            },
        );
        for v in [&mut x, &mut y, &mut z] {
            v.truncate(at);
        }
        ids.truncate(at);
        Self {
            inputs,
            ..Self::assemble(origin, h, (nx, ny), start, [x, y, z], ids)
        }
    }

    /// Files the points on columns of side about `wanted`.
    fn new(points: &[Point], lo: [f64; 3], hi: [f64; 3], wanted: f64) -> Option<Self> {
        let n = points.len();
        let columns = Columns::new(points, lo, hi, wanted)?;
        let Columns { h, nx, ny, of, .. } = columns;
        let count = block_index(nx - 1, ny - 1, nx) + 1;
        // Counting sort by column, then each column by height, a row of
        // blocks at a time in parallel (their columns are numbered in one
        // run). The points are first dealt to their rows of blocks: chunks
        // of the input count theirs a row, then write them into their own
        // piece of each row's part, all in parallel (a row keeps the input
        // order). Each row then counts its columns and sorts its own part
        // of the output. (A "row" here is one or more rows of blocks, so
        // that there are at most `DEAL_ROWS`.)
        let block_row = nx.div_ceil(BLOCK) * BLOCK * BLOCK;
        let row_len = block_row * count.div_ceil(block_row).div_ceil(DEAL_ROWS);
        let rows = count.div_ceil(row_len);
        let chunk = n.div_ceil(4 * rayon::current_num_threads()).max(1 << 14);
        let tallies: Vec<Vec<usize>> = of
            .par_chunks(chunk)
            .map(|part| {
                let mut tally = vec![0usize; rows];
                for &c in part {
                    tally[c as usize / row_len] += 1;
                }
                tally
            })
            .collect();
        // Each point is dealt with its coordinates and column, so that a
        // row then reads its own points in its own part alone (reading
        // them by index from the cloud and the columns was a read from
        // anywhere in 200 MB a point, most of the filing of a 14 M-point
        // scan).
        let mut dealt: Vec<Dealt> = crate::prefault::with_room(n);
        let mut row_first = Vec::with_capacity(rows + 1);
        let mut pieces: Vec<Vec<&mut [MaybeUninit<Dealt>]>> =
            tallies.iter().map(|_| Vec::new()).collect();
        let (mut rest, mut at) = (&mut dealt.spare_capacity_mut()[..n], 0);
        for r in 0..rows {
            row_first.push(at);
            for (tally, mine) in tallies.iter().zip(pieces.iter_mut()) {
                let (piece, tail) = std::mem::take(&mut rest).split_at_mut(tally[r]);
                mine.push(piece);
                rest = tail;
                at += tally[r];
            }
        }
        row_first.push(at);
        points
            .par_chunks(chunk)
            .zip(of.par_chunks(chunk))
            .zip(pieces.par_iter_mut())
            .enumerate()
            .for_each(|(j, ((part, columns), mine))| {
                let mut fill = vec![0usize; rows];
                for (i, (p, &c)) in part.iter().zip(columns).enumerate() {
                    let r = c as usize / row_len;
                    mine[r][fill[r]].write(Dealt {
                        column: c,
                        index: (j * chunk + i) as u32,
                        point: *p,
                    });
                    fill[r] += 1;
                }
            });
        drop(pieces);
        // SAFETY: every point went to one slot of its row's piece of its
        // chunk, whose length is the chunk's tally of that row: the pieces
        // tile the n slots, and each slot was written once.
        unsafe { dealt.set_len(n) };
        drop(of);
        let mut start = vec![0u32; count + 1];
        start[count] = n as u32;
        // Each row writes its own part of the grid's arrays: the input
        // indices and coordinates in sorted order.
        let (mut ids, mut x, mut y, mut z) =
            (vec![0u32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]);
        let mut parts = Vec::with_capacity(rows);
        let mut rest = (&mut ids[..], &mut x[..], &mut y[..], &mut z[..]);
        let mut left = dealt.as_slice();
        for (r, starts) in start[..count].chunks_mut(row_len).enumerate() {
            let len = row_first[r + 1] - row_first[r];
            let (ids, x, y, z) = std::mem::take(&mut rest);
            let ((pi, ri), (px, rx)) = (ids.split_at_mut(len), x.split_at_mut(len));
            let ((py, ry), (pz, rz)) = (y.split_at_mut(len), z.split_at_mut(len));
            let (mine, others) = left.split_at(len);
            parts.push((r, starts, [px, py, pz], pi, mine));
            (rest, left) = ((ri, rx, ry, rz), others);
        }
        let isa = Isa::best();
        parts
            .into_par_iter()
            .for_each_init(Vec::new, |part, (r, starts, xyz, pi, mine)| {
                let (c0, base) = (r * row_len, row_first[r]);
                // The row's columns' starts (their counts, summed).
                for d in mine {
                    starts[d.column as usize - c0] += 1;
                }
                let mut sum = base as u32;
                for s in starts.iter_mut() {
                    (*s, sum) = (sum, sum + *s);
                }
                // Each point's key (its height above, its place in the
                // row's part below) in its column's slots: eight bytes an
                // entry, so that a row's entries stay in a core's cache
                // on a 20 M-point scan.
                let mut next = starts.to_vec();
                part.clear();
                part.resize(mine.len(), 0u64);
                for (j, d) in mine.iter().enumerate() {
                    let slot = &mut next[d.column as usize - c0];
                    // Heights ordered as integers (finite f32, sign folded).
                    let bits = d.point[2].to_bits();
                    let key = if bits >> 31 == 1 {
                        !bits
                    } else {
                        bits | 1 << 31
                    };
                    part[*slot as usize - base] = u64::from(key) << 32 | j as u64;
                    *slot += 1;
                }
                for (&s, &e) in starts.iter().zip(&next) {
                    sort_column(isa, &mut part[s as usize - base..e as usize - base]);
                }
                // The points in sorted order, from the row's own part,
                // split by axis.
                let [px, py, pz] = xyz;
                for (j, &key) in part.iter().enumerate() {
                    let d = &mine[key as u32 as usize];
                    let p = d.point;
                    (pi[j], px[j], py[j], pz[j]) = (d.index, p[0], p[1], p[2]);
                }
            });
        let xyz = [x, y, z];
        Some(Self::assemble(lo, h, (nx, ny), start, xyz, ids))
    }

    /// The grid of points filed by column (`start`, numbered by
    /// [`block_index`]), each column by height, with their coordinates and
    /// input indices in that order: the columns' height indices added.
    fn assemble(
        origin: [f64; 3],
        h: f64,
        (nx, ny): (usize, usize),
        start: Vec<u32>,
        [x, y, z]: [Vec<f32>; 3],
        ids: Vec<u32>,
    ) -> Self {
        let (slabs, slab_start) = slab_index(&start, &z, h);
        let block_heights = slabs
            .chunks(BLOCK * BLOCK)
            .map(|block| {
                let filled = block.iter().filter(|s| s.count > 0);
                filled.fold((f32::INFINITY, f32::NEG_INFINITY), |(l, t), s| {
                    (l.min(s.base), t.max(s.top))
                })
            })
            .collect();
        Self {
            origin,
            h,
            nx,
            ny,
            start,
            slabs,
            slab_start,
            block_heights,
            x,
            y,
            z,
            inputs: ids.len(),
            ids,
            isa: Isa::best(),
        }
    }

    /// The column holding coordinate `v` along axis `a` (0: x, 1: y),
    /// clamped to the grid.
    fn column_at(&self, v: f64, a: usize) -> usize {
        let last = [self.nx, self.ny][a] - 1;
        // `as` saturates: below the grid (and NaN) is column 0.
        (((v - self.origin[a]) / self.h) as usize).min(last)
    }

    /// Where column `c` begins along axis `a`.
    fn edge(&self, c: usize, a: usize) -> f64 {
        self.origin[a] + c as f64 * self.h
    }

    /// How far `v` lies along axis `a` from columns `from..to`, their span
    /// widened by far more than the rounding of the division that filed
    /// the points (0 within it).
    fn off_columns(&self, v: f64, from: usize, to: usize, a: usize) -> f64 {
        let margin = self.h * MARGIN;
        gap(v, self.edge(from, a) - margin, self.edge(to, a) + margin)
    }

    /// The sorted positions of a column (its `slabs`) in the slabs that
    /// hold heights `lo32..=hi32` (a slab's number grows with height, so
    /// none between is missed).
    fn slab_run(&self, slabs: &Slabs, lo32: f32, hi32: f32) -> (usize, usize) {
        let (a, b) = (slabs.of(lo32), slabs.of(hi32));
        let first = slabs.first as usize;
        (
            self.slab_start[first + a] as usize,
            self.slab_start[first + b + 1] as usize,
        )
    }

    /// Calls `visit` with each run of sorted positions that may hold points
    /// within `r` of `q` (all such points are in some run), until it
    /// returns `false`.
    fn runs(&self, q: [f32; 3], r: f64, mut visit: impl FnMut(usize, usize) -> bool) {
        let wide = r * (1.0 + SLACK);
        let (qx, qy) = (f64::from(q[0]), f64::from(q[1]));
        let (x0, x1) = (self.column_at(qx - wide, 0), self.column_at(qx + wide, 0));
        let (y0, y1) = (self.column_at(qy - wide, 1), self.column_at(qy + wide, 1));
        let (lo32, hi32) = heights_within(q[2], wide);
        // Row by row, the query's own row first (a count may stop there).
        // The columns of a row within one block are numbered in a run, so
        // their points lie in one run of positions: where each of them
        // lies within the box's heights (widened by r: a surface, not a
        // wall) they are taken as one run, else column by column, each by
        // its slabs. A run or column whose box (its span of x and y, its
        // points' heights) lies farther than r from q is passed over: the
        // corners of a near query's box, and most of a far query's.
        let (pad_lo, pad_hi) = (lo32 - wide as f32, hi32 + wide as f32);
        let wide2 = wide * wide;
        let qz = f64::from(q[2]);
        let own_y = self.column_at(qy, 1);
        let rows = std::iter::once(own_y).chain((y0..=y1).filter(|&cy| cy != own_y));
        for cy in rows {
            let dy2 = self.off_columns(qy, cy, cy + 1, 1).powi(2);
            let mut cx = x0;
            while cx <= x1 {
                let (first_x, last) = (cx, ((cx / BLOCK + 1) * BLOCK - 1).min(x1));
                let c0 = block_index(cx, cy, self.nx);
                let c1 = c0 + (last - cx);
                cx = last + 1;
                let columns = &self.slabs[c0..=c1];
                let (mut low, mut top) = (f32::INFINITY, f32::NEG_INFINITY);
                for s in columns.iter().filter(|s| s.count > 0) {
                    low = smaller(s.base, low);
                    top = larger(s.top, top);
                }
                if low > top {
                    continue;
                }
                let dx = self.off_columns(qx, first_x, last + 1, 0);
                let dz = gap(qz, f64::from(low), f64::from(top));
                if dx * dx + dy2 + dz * dz > wide2 {
                    continue;
                }
                if low >= pad_lo && top <= pad_hi {
                    let (s, e) = (self.start[c0] as usize, self.start[c1 + 1] as usize);
                    if s < e && !visit(s, e) {
                        return;
                    }
                    continue;
                }
                for (i, slabs) in columns.iter().enumerate() {
                    if slabs.count == 0 {
                        continue;
                    }
                    let dx = self.off_columns(qx, first_x + i, first_x + i + 1, 0);
                    let dz = gap(qz, f64::from(slabs.base), f64::from(slabs.top));
                    if dx * dx + dy2 + dz * dz > wide2 {
                        continue;
                    }
                    let (s, e) = self.slab_run(slabs, lo32, hi32);
                    if s < e && !visit(s, e) {
                        return;
                    }
                }
            }
        }
    }

    /// The run of sorted positions `s..e`.
    fn run(&self, s: usize, e: usize) -> Run<'_> {
        Run {
            x: &self.x[s..e],
            y: &self.y[s..e],
            z: &self.z[s..e],
        }
    }

    /// The squared distances (as ordered bits: squared distances are
    /// ≥ +0, whose bits order as the numbers) from the point at sorted
    /// position `p` to every point within `r` of it, into `bits`; `near`
    /// the columns round the last query's (`near.rs`).
    fn within(&self, p: usize, near: &mut Near, r: f64, bits: &mut Vec<u32>) {
        bits.clear();
        let q = [self.x[p], self.y[p], self.z[p]];
        let cap = (r * r) as f32;
        self.runs_near(near, p, q, r, |s, e| {
            within::keep_distances(self.isa, q, self.run(s, e), cap, bits);
            true
        });
    }

    /// Whether at least `wanted` points (itself counted) lie within
    /// squared distance `r2` of the point at sorted position `p`,
    /// inclusive; stops at a run that brings the count there.
    ///
    /// The points filed next to it come first (its column's nearest in
    /// height, mostly): on a dense scan they hold the few wanted, and the
    /// columns round it are not read. The runs after leave them out.
    fn has_within(&self, p: usize, near: &mut Near, r2: f32, wanted: usize) -> bool {
        let q = [self.x[p], self.y[p], self.z[p]];
        let (first, last) = (
            p.saturating_sub(FIRST / 2),
            (p + FIRST / 2).min(self.ids.len()),
        );
        let mut count = within::count(self.isa, q, self.run(first, last), r2);
        if count >= wanted {
            return true;
        }
        self.runs_near(near, p, q, f64::from(r2).sqrt(), |s, e| {
            for (a, b) in [(s, e.min(first)), (s.max(last), e)] {
                if a < b {
                    count += within::count(self.isa, q, self.run(a, b), r2);
                }
            }
            count < wanted
        });
        count >= wanted
    }

    /// Whether each point has at least `wanted` points (itself counted)
    /// within squared distance `r2`, by sorted position (radius outlier
    /// removal, [RS eq. 13]; [`ColumnGrid::kept_inputs`] gives the survivors'
    /// input indices).
    pub(crate) fn map_has_within_in_grid_order(&self, r2: f32, wanted: usize) -> Vec<bool> {
        self.map_runs(Near::default, |near, p| {
            self.has_within(p, near, r2, wanted)
        })
        .concat()
    }

    /// `f(scratch, i, found)` for every point `i` of the input, `found` the
    /// input indices of the points within squared distance `r2` of it
    /// (inclusive, itself counted), ascending; in input order.
    pub(crate) fn map_within<T, S, I, F>(&self, r2: f32, init: I, f: F) -> Vec<T>
    where
        T: Send + Sync + Clone + Default,
        I: Fn() -> S + Sync + Send,
        F: Fn(&mut S, usize, &[u32]) -> T + Sync + Send,
    {
        let r = f64::from(r2).sqrt();
        self.map_sorted(
            || (init(), Vec::new(), Near::default()),
            |(scratch, found, near), p| {
                let q = [self.x[p], self.y[p], self.z[p]];
                found.clear();
                self.runs_near(near, p, q, r, |s, e| {
                    let (run, ids) = (self.run(s, e), &self.ids[s..e]);
                    within::keep_payload(self.isa, q, run, ids, r2, found);
                    true
                });
                within::sort_ids(self.isa, found);
                f(scratch, self.ids[p] as usize, found)
            },
        )
    }

    /// `f(scratch, sorted position)` for every point, runs of positions in
    /// parallel (`init` makes each task's scratch), in input order (the
    /// places of inputs not filed left at the default).
    fn map_sorted<T, S, I, F>(&self, init: I, f: F) -> Vec<T>
    where
        T: Send + Sync + Clone + Default,
        I: Fn() -> S + Sync + Send,
        F: Fn(&mut S, usize) -> T + Sync + Send,
    {
        self.runs_in_input_order(self.map_runs(init, f), |v| v)
    }

    /// The values of [`ColumnGrid::map_runs`]' runs put in input order through
    /// `value` (the places of inputs not filed left at the default).
    fn runs_in_input_order<V, T, G>(&self, runs: Vec<Vec<V>>, value: G) -> Vec<T>
    where
        T: Clone + Default,
        G: Fn(V) -> T,
    {
        let mut result = vec![T::default(); self.inputs];
        for (values, ids) in runs.into_iter().zip(self.ids.chunks(RUN)) {
            for (v, &i) in values.into_iter().zip(ids) {
                result[i as usize] = value(v);
            }
        }
        result
    }

    /// `f(scratch, sorted position)` for every point, in sorted order, in
    /// runs of `RUN` positions computed in parallel (`init` makes each
    /// task's scratch).
    fn map_runs<T, S, I, F>(&self, init: I, f: F) -> Vec<Vec<T>>
    where
        T: Send,
        I: Fn() -> S + Sync + Send,
        F: Fn(&mut S, usize) -> T + Sync + Send,
    {
        let n = self.ids.len();
        (0..n.div_ceil(RUN))
            .into_par_iter()
            .map_init(init, |scratch, i| {
                (i * RUN..((i + 1) * RUN).min(n))
                    .map(|p| f(scratch, p))
                    .collect()
            })
            .collect()
    }

    /// The input indices, ascending, of the points `keep` marks by sorted
    /// position, through a bitmap of the inputs: a bit a point, which stays
    /// in cache where a byte a point in input order was written at random
    /// across 14 MB (at 14 M points; with the indices' collection, a
    /// seventh of the radius filter there).
    pub(crate) fn kept_inputs(&self, keep: &[bool]) -> Vec<usize> {
        let words = self.inputs.div_ceil(64);
        let part = part_a_thread(keep.len());
        let bits = keep
            .par_chunks(part)
            .zip(self.ids.par_chunks(part))
            .map(|(keep, ids)| {
                let mut bits = vec![0u64; words];
                for (&k, &i) in keep.iter().zip(ids) {
                    bits[i as usize / 64] |= u64::from(k) << (i % 64);
                }
                bits
            })
            .reduce_with(|mut a, b| {
                a.iter_mut().zip(&b).for_each(|(a, b)| *a |= b);
                a
            })
            .unwrap_or_default();
        set_bits(&bits)
    }

    /// The k nearest squared distances of the point at sorted position
    /// `p`, in any order but the k-th last, left in `bits[..k]`, starting
    /// from the radius `guess` (which may be too small or too large);
    /// returns the k-th, or `None` for a point far from the rest (its
    /// radius grew past `FAR` columns) unless `unbounded`.
    fn k_nearest(
        &self,
        p: usize,
        guess: f64,
        k: usize,
        scratch: &mut Scratch,
        unbounded: bool,
    ) -> Option<f32> {
        let mut r = guess;
        loop {
            self.within(p, &mut scratch.near, r, &mut scratch.bits);
            let found = scratch.bits.len();
            if found >= k {
                let bits = &mut scratch.bits;
                within::smallest(self.isa, bits, k);
                return Some(f32::from_bits(bits[k - 1]));
            }
            // Too few within r: on a surface the count grows as r², so
            // grow r by the shortfall (at least ×1.25, at most ×4) ...
            let grow = (k as f64 / found.max(1) as f64).sqrt() * 1.1;
            r *= grow.clamp(1.25, 4.0);
            if r > FAR * self.h && !unbounded {
                // ... but a point far from the rest (an outlier above the
                // scan) sweeps a wide box: such points are left for later.
                return None;
            }
        }
    }

    /// `f` of the k nearest squared distances (the point itself counted;
    /// in any order, the k-th last) of every point, in input order; runs of
    /// sorted positions in parallel. Points far from the rest (outliers of
    /// a noisy scan) are answered after the others, by `far_k_nearest`.
    pub(crate) fn map_k_nearest_distances<T, F>(&self, k: usize, f: F) -> Vec<T>
    where
        T: Send + Sync + Clone + Default,
        F: Fn(&[f32]) -> T + Sync + Send,
    {
        let answer = |scratch: &mut Scratch| {
            let dist = &mut scratch.nearest;
            dist.clear();
            dist.extend(scratch.bits[..k].iter().map(|&b| f32::from_bits(b)));
            f(dist)
        };
        // In sorted order (runs of RUN positions), `None` for a far point;
        // put in input order once, at the end. (Through an input-ordered
        // vector of options, the far points were found by a serial pass of
        // random reads, a tenth of a second at 20 M points.)
        let mut runs: Vec<Vec<Option<T>>> = self.map_runs(
            || (Scratch::default(), self.h),
            |(scratch, guess), p| {
                let kth = self.k_nearest(p, *guess, k, scratch, false)?;
                // The next point is near (same column, a little higher,
                // mostly): its k-th distance is likely within a little
                // more. Not past the columns round its own, though: a
                // point off a thick layer (its k-th far) is followed by
                // one in it, which a radius past a column's side would
                // send through `ColumnGrid::runs` (at 20 M points on the bench
                // pile, 11 % of the searches; 6 % so).
                *guess = (f64::from(kth).sqrt() * GUESS)
                    .min(GUESS_REACH * self.near_width())
                    .max(self.h * 1e-3);
                Some(answer(scratch))
            },
        );
        let far: Vec<usize> = runs
            .par_iter()
            .enumerate()
            .flat_map_iter(|(r, run)| {
                let far = run.iter().enumerate().filter(|(_, v)| v.is_none());
                far.map(move |(j, _)| r * RUN + j)
            })
            .collect();
        // (A k-d tree built for them on large clouds answered them more
        // slowly than `far_k_nearest` once a block's columns were ordered
        // on their own: the statistical filter on the bench pile at 5 M
        // 2.44–2.48 s with it against 2.14–2.32 without, at 20 M 11.5
        // against 11.3 s and 2.0 against 1.2 GB of memory.)
        let late: Vec<T> = far
            .par_iter()
            .map_init(Scratch::default, |scratch, &p| {
                let q = [self.x[p], self.y[p], self.z[p]];
                self.far_k_nearest(q, k, scratch);
                answer(scratch)
            })
            .collect();
        for (&p, value) in far.iter().zip(late) {
            runs[p / RUN][p % RUN] = Some(value);
        }
        self.runs_in_input_order(runs, Option::unwrap_or_default)
    }
}

/// Moves each run `(from, count, to)` of `v` down to `to`, in order (no
/// run's place is written before it is read: `to ≤ from`, and earlier
/// runs end below later runs' places).
fn close_up<T: Copy>(v: &mut [T], moves: &[(usize, usize, usize)]) {
    for &(from, count, to) in moves {
        v.copy_within(from..from + count, to);
    }
}

/// Items of a part when `len` are cut into one part a thread (at least
/// 2¹⁶), each part counted into an array of its own, then merged.
fn part_a_thread(len: usize) -> usize {
    len.div_ceil(rayon::current_num_threads()).max(1 << 16)
}

/// The positions of the set bits of `bits` (bit j of word w: 64 w + j),
/// ascending: counted by parts, then each part written into its own
/// range, in parallel.
fn set_bits(bits: &[u64]) -> Vec<usize> {
    let words = bits
        .len()
        .div_ceil(4 * rayon::current_num_threads())
        .max(1 << 10);
    let counts: Vec<usize> = bits
        .par_chunks(words)
        .map(|part| part.iter().map(|w| w.count_ones() as usize).sum())
        .collect();
    let total = counts.iter().sum();
    let mut out: Vec<usize> = crate::prefault::with_room(total);
    let mut pieces = Vec::with_capacity(counts.len());
    let mut rest = &mut out.spare_capacity_mut()[..total];
    for &count in &counts {
        let (piece, tail) = std::mem::take(&mut rest).split_at_mut(count);
        pieces.push(piece);
        rest = tail;
    }
    bits.par_chunks(words)
        .zip(pieces)
        .enumerate()
        .for_each(|(k, (part, piece))| {
            let mut n = 0;
            for (j, &word) in part.iter().enumerate() {
                let (base, mut w) = ((k * words + j) * 64, word);
                while w != 0 {
                    piece[n].write(base + w.trailing_zeros() as usize);
                    n += 1;
                    w &= w - 1;
                }
            }
        });
    // SAFETY: each part wrote its count of set bits, one a slot, into its
    // own piece of that length, and the pieces tile `..total`.
    unsafe { out.set_len(total) };
    out
}

/// A column's keys (height key above, point index below) in order, so
/// by height, ties by index: on AVX-512 by a sorting network
/// ([`within::sort_wide`]) where a column holds at most 128; else by rank
/// ([`within::ranks`]) where the heights are distinct and a few dozen (a
/// comparison sort of a column was half of filing a scan), else by a
/// comparison sort.
fn sort_column(isa: Isa, column: &mut [u64]) {
    let n = column.len();
    if n < 2 || within::sort_wide(isa, column) {
        return;
    }
    let mut heights = [0u32; within::MOST_RANKED];
    let ranked = n <= within::MOST_RANKED && {
        for (h, &key) in heights.iter_mut().zip(column.iter()) {
            *h = (key >> 32) as u32;
        }
        within::order_by_rank(isa, &heights[..n], column)
    };
    if !ranked {
        column.sort_unstable();
    }
}

/// Columns a side of a block (see [`block_index`]).
const BLOCK: usize = 8;

/// The index of column (cx, cy) when the columns are numbered in blocks of
/// 8 × 8, blocks in rows: the columns around a query then lie close
/// together in memory (in plain rows the row above is a whole row of points
/// away, which outgrows the caches on a 20 M-point scan).
#[inline]
fn block_index(cx: usize, cy: usize, nx: usize) -> usize {
    let blocks_x = nx.div_ceil(BLOCK);
    ((cy / BLOCK) * blocks_x + cx / BLOCK) * BLOCK * BLOCK + (cy % BLOCK) * BLOCK + cx % BLOCK
}

/// Columns a parallel task of `ColumnGrid::retain` compacts.
const RETAIN_COLUMNS: usize = 256;

/// Points whose k-th distance checks a grid's side.
const PROBES: usize = 256;

/// Points filed round a radius query's own that it counts first.
const FIRST: usize = 16;

/// Parts the points are dealt to at most, by `ColumnGrid::new` (rows of blocks
/// next to each other taken together past it): a chunk of the input
/// writes to each part in turn, and past a hundred or so places written
/// at once the writes slow down (at 20 M points, 129 rows: dealing 12.1–13.1
/// ns a point, 8.3–8.4 in 65 parts of two rows, whose sorting then took
/// 1.4 ns a point more; 43 parts of three: 8.3–9.0 and 2.1 more).
const DEAL_ROWS: usize = 96;

/// Points per parallel task.
const RUN: usize = 4096;

/// The next query's radius: this times the k-th distance of the last ...
const GUESS: f64 = 1.1;

/// ... at most this share of [`ColumnGrid::near_width`]: within the reach of the
/// columns round a query's own (`near.rs`).
const GUESS_REACH: f64 = 0.99;

/// The side of columns for searches within `radius`: a hair wider, so
/// that a box of the radius (widened by `SLACK`) reaches no further than
/// the columns next to its own (`near.rs`).
pub(crate) fn radius_side(radius: f64) -> f64 {
    radius * (1.0 + 2.0 * SLACK)
}

/// A k-nearest grid is not made this many times wider than the k nearest
/// want for a radius search to share it (`ColumnGrid::for_k_nearest_at_least`).
const WIDER: f64 = 2.0;

/// Columns this many times as wide as the typical k-th distance: runs
/// long enough to vectorise, few columns a query (1.3–1.5× faster than
/// columns as wide as the distance on the bench piles).
const SIDE: f64 = 2.0;

/// A query whose radius grows past this many columns goes to the tree.
const FAR: f64 = 3.0;

/// Slabs per column at most, a point.
const SLABS_PER_POINT: usize = 4;

/// The height index of one column: its points fall in slabs of equal
/// height from its lowest point, slab `s` holding the sorted positions
/// `slab_start[first + s] .. slab_start[first + s + 1]`.
#[derive(Debug, Clone, Copy, Default)]
struct Slabs {
    /// The lowest and highest heights, and the slabs a unit of height.
    base: f32,
    top: f32,
    per_unit: f32,
    /// Index of the column's first entry in `slab_start`.
    first: u32,
    /// Number of slabs (0 for an empty column).
    count: u32,
}

impl Slabs {
    /// The slab of height `z` (clamped to the column's): f32 operations
    /// rounded to nearest are monotonic, so a higher point never falls in
    /// a lower slab.
    #[inline]
    fn of(&self, z: f32) -> usize {
        // `as` saturates: below the base is slab 0.
        (((z - self.base) * self.per_unit) as usize).min(self.count as usize - 1)
    }
}

/// The slab index of every column: slabs of about `h / 2` (fewer in a
/// column spanning a great height with few points).
fn slab_index(start: &[u32], z: &[f32], h: f64) -> (Vec<Slabs>, Vec<u32>) {
    // Runs of columns in parallel, each indexed on its own (its `first`s
    // counted from its own start), then put end to end.
    let columns = start.len() - 1;
    let parts: Vec<(Vec<Slabs>, Vec<u32>)> = (0..columns.div_ceil(SLAB_COLUMNS))
        .into_par_iter()
        .map(|part| {
            let (c0, c1) = (
                part * SLAB_COLUMNS,
                ((part + 1) * SLAB_COLUMNS).min(columns),
            );
            slab_index_of(&start[c0..=c1], z, h)
        })
        .collect();
    let mut slabs = Vec::with_capacity(columns);
    let mut slab_start = Vec::with_capacity(parts.iter().map(|p| p.1.len()).sum());
    for (part_slabs, part_starts) in parts {
        let offset = slab_start.len() as u32;
        slabs.extend(part_slabs.into_iter().map(|mut column| {
            if column.count > 0 {
                column.first += offset;
            }
            column
        }));
        slab_start.extend_from_slice(&part_starts);
    }
    (slabs, slab_start)
}

/// Columns a parallel task of [`slab_index`] indexes.
const SLAB_COLUMNS: usize = 1024;

/// [`slab_index`] of the columns starting at `start` (the last entry one
/// past the last column's points), their `first`s from 0.
fn slab_index_of(start: &[u32], z: &[f32], h: f64) -> (Vec<Slabs>, Vec<u32>) {
    let columns = start.len() - 1;
    let points = (start[columns] - start[0]) as usize;
    let mut slabs = vec![Slabs::default(); columns];
    let mut slab_start = Vec::with_capacity(2 * columns + points / 4);
    for c in 0..columns {
        let (s, e) = (start[c] as usize, start[c + 1] as usize);
        if s == e {
            continue;
        }
        let (low, high) = (z[s], z[e - 1]);
        let wanted = (f64::from(high - low) / (h / 2.0)).floor() as usize + 1;
        let count = wanted.min(SLABS_PER_POINT * (e - s)).max(1);
        let per_unit = if high > low {
            (count as f64 / f64::from(high - low) * (1.0 - 1e-6)) as f32
        } else {
            0.0
        };
        let column = Slabs {
            base: low,
            top: high,
            per_unit,
            first: slab_start.len() as u32,
            count: count as u32,
        };
        // slab_start[first + t] = first position whose slab is ≥ t.
        let mut pos = s;
        for t in 0..count {
            while pos < e && column.of(z[pos]) < t {
                pos += 1;
            }
            slab_start.push(pos as u32);
        }
        slab_start.push(e as u32);
        slabs[c] = column;
    }
    (slabs, slab_start)
}

/// A point dealt to its row of blocks by `ColumnGrid::new`: its column, input
/// index and coordinates (20 bytes).
#[derive(Clone, Copy)]
struct Dealt {
    column: u32,
    index: u32,
    point: Point,
}

/// The column of every point on a grid of side `h` over the box.
struct Columns {
    h: f64,
    nx: usize,
    ny: usize,
    of: Vec<u32>,
}

impl Columns {
    /// Columns of side `wanted` (grown until they number at most
    /// `COLUMNS_PER_POINT` a point; `None` past 4× `wanted`).
    fn new(points: &[Point], lo: [f64; 3], hi: [f64; 3], wanted: f64) -> Option<Self> {
        let (h, nx, ny) = Self::sized(points.len(), lo, hi, wanted)?;
        let of = points
            .par_iter()
            .map(|p| column_of(p, lo, h, (nx, ny)) as u32)
            .collect();
        Some(Self { h, nx, ny, of })
    }

    /// The side and counts along x and y of [`Columns::new`]'s columns.
    fn sized(n: usize, lo: [f64; 3], hi: [f64; 3], wanted: f64) -> Option<(f64, usize, usize)> {
        let extent = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let largest = extent.iter().cloned().fold(0.0, f64::max);
        if largest <= 0.0 || !wanted.is_finite() {
            return None;
        }
        // No side below the cloud's extent over 2^20 (duplicates give a
        // k-th distance of zero).
        let wanted = wanted.max(largest / f64::from(1u32 << 20));
        let cells = |h: f64, e: f64| (e / h).floor() as usize + 1;
        let limit = COLUMNS_PER_POINT * n + 1024;
        let count = |h: f64| cells(h, extent[0]).saturating_mul(cells(h, extent[1]));
        let mut h = wanted;
        while count(h) > limit {
            h *= 1.25;
            if h > 4.0 * wanted {
                return None;
            }
        }
        Some((h, cells(h, extent[0]), cells(h, extent[1])))
    }

    /// The side of [`Columns::new`]'s columns and how many of them hold
    /// more than one point, counted by parts in parallel (no column kept
    /// for each point).
    fn occupied(points: &[Point], lo: [f64; 3], hi: [f64; 3], wanted: f64) -> Option<(f64, usize)> {
        let (h, nx, ny) = Self::sized(points.len(), lo, hi, wanted)?;
        let columns = block_index(nx - 1, ny - 1, nx) + 1;
        let part = part_a_thread(points.len());
        let counts = points
            .par_chunks(part)
            .map(|part| {
                let mut counts = vec![0u32; columns];
                for p in part {
                    counts[column_of(p, lo, h, (nx, ny))] += 1;
                }
                counts
            })
            .reduce_with(|mut a, b| {
                a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
                a
            })
            .unwrap_or_default();
        Some((h, counts.iter().filter(|&&c| c > 1).count()))
    }
}

/// The column (numbered by [`block_index`]) of point `p` on columns of
/// side `h` from `lo`, `nx` × `ny` of them.
#[inline]
fn column_of(p: &Point, lo: [f64; 3], h: f64, (nx, ny): (usize, usize)) -> usize {
    let cx = (((f64::from(p[0]) - lo[0]) / h) as usize).min(nx - 1);
    let cy = (((f64::from(p[1]) - lo[1]) / h) as usize).min(ny - 1);
    block_index(cx, cy, nx)
}

/// Buffers of one task.
#[derive(Default)]
struct Scratch {
    bits: Vec<u32>,
    /// The columns round the last query's.
    near: Near,
    nearest: Vec<f32>,
    /// The nearest so far of `far_k_nearest` (the k nearest, the k-th
    /// last, after each pick).
    best: Vec<u32>,
    /// The blocks `far_k_nearest` has still to open, nearest first.
    waiting: std::collections::BinaryHeap<std::cmp::Reverse<(u64, usize)>>,
    /// The columns of the block `far_k_nearest` is opening.
    columns: Vec<(u64, usize)>,
}

/// The cloud's bounding box, in f64.
fn bounds(points: &[Point]) -> ([f64; 3], [f64; 3]) {
    let (lo, hi) =
        crate::cloud::bounds(points).unwrap_or(([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]));
    (lo.map(f64::from), hi.map(f64::from))
}

#[cfg(test)]
mod tests {
    use super::super::kdtree::KdTree;
    use super::*;

    #[test]
    fn the_slab_index_by_runs_of_columns_is_the_index_in_one_run() {
        // 5000 columns (five runs), some empty, some tall, heights sorted
        // within each.
        let mut u = crate::testing::uniform(3);
        let (mut start, mut z) = (vec![0u32], Vec::new());
        for c in 0..5000 {
            let n = match c % 7 {
                0 => 0,
                1 => 60,
                _ => (u() * 12.0) as usize,
            };
            let mut column: Vec<f32> = (0..n)
                .map(|_| u() * if c % 5 == 0 { 9.0 } else { 0.3 })
                .collect();
            column.sort_by(f32::total_cmp);
            z.extend(column);
            start.push(z.len() as u32);
        }
        let (slabs, slab_start) = slab_index(&start, &z, 0.25);
        let (one_slabs, one_start) = slab_index_of(&start, &z, 0.25);
        assert_eq!(slab_start, one_start);
        assert_eq!(format!("{slabs:?}"), format!("{one_slabs:?}"));
    }

    #[test]
    fn a_column_sorts_by_height_then_index_on_every_path() {
        let mut u = crate::testing::uniform(5);
        for trial in 0..3_000 {
            let n = trial % 140;
            // Distinct heights mostly, ties (a few values) now and then.
            let spread = if trial % 3 == 0 { 4.0 } else { 4e9 };
            let entries: Vec<u64> = (0..n)
                .map(|i| ((f64::from(u()) * spread) as u64) << 32 | (n - i) as u64)
                .collect();
            let mut want = entries.clone();
            want.sort_unstable();
            for isa in Isa::available() {
                let mut got = entries.clone();
                sort_column(isa, &mut got);
                assert_eq!(got, want, "{isa:?}, {n} entries");
            }
        }
    }

    fn cloud(n: usize, seed: u64) -> Vec<Point> {
        let mut u = crate::testing::uniform(seed);
        // A rough surface with noise, a few outliers high above it and
        // duplicated points.
        let mut points: Vec<Point> = (0..n)
            .map(|_| {
                let (x, y) = (u() * 20.0, u() * 10.0);
                [x, y, (x * 0.3).sin() + 0.01 * u()]
            })
            .collect();
        for i in 0..n / 100 {
            points[i * 97 % n][2] += 3.0 + u() * 5.0;
        }
        for i in 0..n / 200 {
            points[i * 31 % n] = points[i * 37 % n];
        }
        points
    }

    /// The distances as sorted bits, after checking that the k-th is last.
    fn bits(d: &[f32]) -> Vec<u32> {
        let mut b: Vec<u32> = d.iter().map(|x| x.to_bits()).collect();
        assert_eq!(b.iter().max(), b.last(), "the k-th is last");
        b.sort_unstable();
        b
    }

    fn both(points: &[Point], k: usize) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
        let grid = ColumnGrid::for_k_nearest(points, k).expect("a grid");
        let tree = KdTree::new(points);
        (
            grid.map_k_nearest_distances(k, bits),
            tree.map_k_nearest_distances(k, bits),
        )
    }

    #[test]
    fn the_k_nearest_are_the_trees_bit_for_bit() {
        // (with outliers: some queries answered by `far_k_nearest`)
        for (n, k, seed) in [(20_000, 21, 1), (5_000, 51, 2), (300, 8, 3), (60, 59, 4)] {
            let points = cloud(n, seed);
            let (grid, tree) = both(&points, k);
            assert_eq!(grid, tree, "n {n}, k {k}");
        }
    }

    #[test]
    fn points_far_from_a_sloped_scan_on_every_side_agree_too() {
        // A scan on a 35° slope with 3 % of its points moved far off it
        // (above, below, beside it, past its end, into an empty corner of
        // the box): answered nearest box first, as `far_k_nearest`.
        let mut u = crate::testing::uniform(11);
        let mut points: Vec<Point> = (0..30_000)
            .map(|_| {
                let (x, y) = (u() * 30.0, u() * 12.0);
                [x, y, 0.7 * x + 0.02 * u()]
            })
            .collect();
        for i in 0..900 {
            let p = &mut points[i * 31 + 7];
            let far = 0.5 + 6.0 * u();
            match i % 5 {
                0 => p[2] += far,
                1 => p[2] -= far,
                2 => p[1] = -far,
                3 => p[0] = 30.0 + far,
                _ => *p = [u() * 3.0, 12.0 - u(), 20.0 + u() * 3.0],
            }
        }
        for k in [6, 21, 51] {
            let (grid, tree) = both(&points, k);
            assert_eq!(grid, tree, "k {k}");
        }
    }

    #[test]
    fn a_flat_or_vertical_cloud_and_far_clusters_agree_too() {
        // All in one plane (one slab), all in one column, and two
        // clusters far apart (the grid grows its cells or is declined).
        let flat: Vec<Point> = cloud(4_000, 5).iter().map(|p| [p[0], p[1], 2.0]).collect();
        let line: Vec<Point> = cloud(4_000, 6).iter().map(|p| [1.0, 1.0, p[0]]).collect();
        let mut far = cloud(4_000, 7);
        for p in far.iter_mut().skip(2_000) {
            p[0] += 5_000.0;
        }
        for points in [flat, line, far] {
            let tree = KdTree::new(&points).map_k_nearest_distances(11, bits);
            if let Some(grid) = ColumnGrid::for_k_nearest(&points, 11) {
                assert_eq!(grid.map_k_nearest_distances(11, bits), tree);
            }
        }
    }

    #[test]
    fn a_layer_thicker_than_a_column_is_wide_agrees_too() {
        // A scan whose noise is several columns thick (`near.rs` reads a
        // tall column whole when it holds few points, else cuts it by its
        // slabs), dense on one side and sparse on the other, so that the
        // tall columns come in both kinds.
        let mut u = crate::testing::uniform(12);
        let points: Vec<Point> = (0..24_000)
            .map(|i| {
                let x = if i < 20_000 {
                    u() * 10.0
                } else {
                    10.0 + u() * 10.0
                };
                [x, u() * 5.0, 2.0 * u()]
            })
            .collect();
        let grid = ColumnGrid::for_k_nearest(&points, 21).expect("a grid");
        let tall: Vec<u32> = (0..grid.slabs.len())
            .filter(|&c| f64::from(grid.slabs[c].top - grid.slabs[c].base) > near::WHOLE * grid.h)
            .map(|c| grid.start[c + 1] - grid.start[c])
            .collect();
        let few = |&n: &u32| n <= near::WHOLE_POINTS;
        assert!(tall.iter().any(few) && !tall.iter().all(few));
        let tree = KdTree::new(&points).map_k_nearest_distances(21, bits);
        assert_eq!(grid.map_k_nearest_distances(21, bits), tree);
    }

    #[test]
    fn a_long_cloud_dealt_in_parts_of_several_rows_agrees_too() {
        // A strip of scan 2 km long: more rows of blocks than `DEAL_ROWS`,
        // so that `ColumnGrid::new` deals them to parts of several rows.
        let mut u = crate::testing::uniform(13);
        let points: Vec<Point> = (0..20_000)
            .map(|_| [u() * 0.5, u() * 2_000.0, 0.05 * u()])
            .collect();
        let grid = ColumnGrid::for_k_nearest(&points, 11).expect("a grid");
        assert!(grid.ny.div_ceil(BLOCK) > DEAL_ROWS, "{} rows", grid.ny);
        let tree = KdTree::new(&points).map_k_nearest_distances(11, bits);
        assert_eq!(grid.map_k_nearest_distances(11, bits), tree);
    }

    #[test]
    fn set_bits_are_found_in_order_in_any_parts() {
        let mut state = 3u64;
        let bits: Vec<u64> = (0..20_000)
            .map(|w| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                // Empty, full and random words.
                match w % 7 {
                    0 => 0,
                    1 => u64::MAX,
                    _ => state & (state >> 17),
                }
            })
            .collect();
        let want: Vec<usize> = (0..bits.len() * 64)
            .filter(|&i| bits[i / 64] >> (i % 64) & 1 == 1)
            .collect();
        for threads in [1, 2, 5] {
            let got = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| set_bits(&bits));
            assert!(got == want, "{threads} threads");
        }
    }

    #[test]
    fn radius_counts_are_the_trees() {
        for (n, r, wanted, seed) in [
            (20_000, 0.05f32, 6, 8),
            (3_000, 0.3, 12, 9),
            (500, 2.0, 40, 10),
        ] {
            let points = cloud(n, seed);
            let r2 = r * r;
            let tree = KdTree::new(&points);
            let by_tree = tree.map_points(|| (), |_, _, p| tree.has_within(p, r2, wanted));
            let grid = ColumnGrid::for_radius(&points, f64::from(r)).expect("a grid");
            let by_tree: Vec<usize> = (0..n).filter(|&i| by_tree[i]).collect();
            let by_grid = grid.kept_inputs(&grid.map_has_within_in_grid_order(r2, wanted));
            assert_eq!(by_grid, by_tree, "n {n}, r {r}");
            assert!(!by_grid.is_empty() && by_grid.len() < n);
        }
    }

    #[test]
    fn neighbours_within_a_radius_are_the_trees() {
        let points = cloud(8_000, 11);
        let r2 = 0.25f32 * 0.25;
        let tree = KdTree::new(&points);
        let by_tree: Vec<Vec<u32>> = tree.map_points(Vec::new, |found, _, p| {
            tree.within(p, r2, found);
            let mut ids: Vec<u32> = found.iter().map(|&q| tree.id(q as usize) as u32).collect();
            ids.sort_unstable();
            ids
        });
        let grid = ColumnGrid::for_radius(&points, 0.25).expect("a grid");
        let by_grid = grid.map_within(
            r2,
            || (),
            |_, i, found| {
                assert!(found.contains(&(i as u32)));
                found.to_vec()
            },
        );
        assert_eq!(by_grid, by_tree);
        assert!(by_grid.iter().map(Vec::len).max() > Some(5));
    }
}
