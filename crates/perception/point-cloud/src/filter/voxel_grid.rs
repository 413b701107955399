//! Voxel-grid down-sampling ([RS eq. 17]–[RS eq. 18]): the bounding box
//! of the cloud (l_x, l_y, l_z = max − min, [RS eq. 17]) is cut into voxels of edge
//! r (D = l / r voxels per axis, [RS eq. 18]), and the points of each occupied
//! voxel are replaced by their centroid.
//!
//! Voxels are PCL 1.13's (`filters/include/pcl/filters/impl/voxel_grid.hpp`):
//! the leaf is stored as f32 and inverted in f32 (`inverse_leaf_size_ =
//! Array4f::Ones () / leaf_size_`), and a point falls in voxel
//! `floor (p * inverse_leaf)` per axis, computed in f32: the grid is anchored
//! at the origin, not at the cloud's minimum, and a point on a voxel face
//! belongs to the voxel above it. Centroids are accumulated in f64 and stored
//! as f32 (PCL accumulates in f32; they agree within 1e-5 m on the tests).
//!
//! The output is ordered as PCL orders it: by voxel, with x varying fastest,
//! then y, then z (PCL's `idx = i·1 + j·D_x + k·D_x·D_y` sort). PCL 1.13
//! refuses a leaf whose linear voxel index would overflow an `int32`
//! ("Leaf size is too small for the input dataset. Integer indices would
//! overflow.") and returns the input unchanged; here voxel coordinates are
//! i64. When the occupied box has fewer than 2³² voxels, every point's
//! linear voxel index is computed once as a 32-bit key (`keys.rs`, 16
//! points a step on AVX-512); then a dense cloud (tens of points a voxel)
//! is summed into one hash table a thread, each thread owning a range of
//! keys (`table.rs`), and any other is bucketed by the keys' top bits in
//! parallel chunks, each bucket sorted stably by the rest
//! (`bucketed_centroids`). Beyond, the points are sorted through (u64
//! linear index, point index) pairs below 2⁶⁴ voxels, and through (z, y,
//! x) i64 triplets beyond that, so any leaf whose products stay finite in
//! f32 works. Every way sums each voxel's points in f64 in input order,
//! so the bits depend neither on the way nor on the number of threads.
//!
//! Open3D's `voxel_down_sample` anchors its grid at `min_bound − leaf/2`
//! and computes in f64, so its voxels differ from PCL's.

use autoshovel_core::config::short;
use rayon::prelude::*;

mod keys;
mod radix;
mod table;

use keys::floor_i64;
pub use keys::VoxelCells;
use radix::{radix_sort_voxels, Voxel};

use super::common::{bad, empty_input, is_finite};
use crate::simd::Isa;
use crate::{Point, PointCloud, Result};
use serde::{Deserialize, Serialize};

const FILTER: &str = "voxel grid";

/// Parameters of [`voxel_grid`] ([RS eq. 17]–[RS eq. 18]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VoxelGridParams {
    /// The voxel edge r along x, y and z (m).
    pub leaf_m: [f64; 3],
}

impl Default for VoxelGridParams {
    /// The paper gives no value: a 5 cm cube (documented choice) for a
    /// full-size pile; the 1:30 scale model of the paper wants a few mm.
    fn default() -> Self {
        Self::cube(0.05)
    }
}

impl VoxelGridParams {
    /// Cubic voxels of edge `leaf_m` (m).
    pub fn cube(leaf_m: f64) -> Self {
        Self {
            leaf_m: [leaf_m; 3],
        }
    }

    /// The inverse leaf per axis, in f32 as PCL computes it.
    fn inverse_leaf(&self) -> Result<[f32; 3]> {
        let mut inv = [0.0_f32; 3];
        for (a, (&leaf, inv)) in self.leaf_m.iter().zip(inv.iter_mut()).enumerate() {
            let leaf32 = leaf as f32;
            *inv = 1.0 / leaf32;
            if !(leaf.is_finite()
                && leaf > 0.0
                && leaf32 > 0.0
                && leaf32.is_finite()
                && inv.is_finite())
            {
                return Err(bad(
                    FILTER,
                    format!(
                        "leaf_m[{a}] must be positive and finite in f32, got {} \
                         (use a voxel edge in metres, e.g. 0.05)",
                        short(leaf)
                    ),
                ));
            }
        }
        Ok(inv)
    }
}

/// Voxel coordinates are kept below this magnitude, far inside i64.
const MAX_CELL: f32 = 4.0e18;

/// The centroids of the occupied voxels, in PCL's order (x fastest, then y,
/// then z). Non-finite points are skipped.
///
/// ```
/// use autoshovel_point_cloud::{filter, PointCloud};
/// let cloud = PointCloud::new(vec![[0.1, 0.1, 0.1], [0.3, 0.3, 0.3], [1.1, 0.1, 0.1]]);
/// let down = filter::voxel_grid(&cloud, &filter::VoxelGridParams::cube(1.0)).unwrap();
/// assert_eq!(down.len(), 2);
/// assert!((down.points[0][0] - 0.2).abs() < 1e-6 && (down.points[1][0] - 1.1).abs() < 1e-6);
/// ```
pub fn voxel_grid(cloud: &[Point], params: &VoxelGridParams) -> Result<PointCloud> {
    let (centroids, _) = centroids(cloud, params, Isa::best(), true)?;
    Ok(PointCloud::new(centroids))
}

/// [`voxel_grid`], and for each centroid the input point nearest it (the
/// first in input order on a tie): the row whose attributes the new point
/// takes, as PDAL's `filters.voxelcentroidnearestneighbor` does. One value
/// of one real point a voxel keeps a classification, a return number or a
/// GPS time meaningful, where a mean of them would not be.
pub fn voxel_grid_nearest(
    cloud: &[Point],
    params: &VoxelGridParams,
) -> Result<(PointCloud, Vec<usize>)> {
    let centroids = voxel_grid(cloud, params)?.points;
    // The voxels in PCL's order (z slowest, x fastest), as the centroids.
    let keys = sorted_triplets(cloud, &VoxelCells::new(params)?);
    let mut nearest = Vec::with_capacity(centroids.len());
    let d2 = |p: &Point, c: &Point| -> f64 {
        (0..3)
            .map(|a| (f64::from(p[a]) - f64::from(c[a])).powi(2))
            .sum()
    };
    for run in keys.chunk_by(|a, b| a.0 == b.0) {
        let Some(c) = centroids.get(nearest.len()) else {
            break;
        };
        let best = run.iter().map(|&(_, i)| (d2(&cloud[i], c), i)).fold(
            (f64::INFINITY, usize::MAX),
            |b, x| if x.0 < b.0 { x } else { b },
        );
        nearest.push(best.1);
    }
    debug_assert_eq!(nearest.len(), centroids.len(), "one run a voxel");
    Ok((PointCloud::new(centroids), nearest))
}

/// Every finite point's voxel as a (z, y, x) triplet with its index,
/// sorted: PCL's order (z slowest, x fastest), a voxel's points in input
/// order.
fn sorted_triplets(points: &[Point], cells: &VoxelCells) -> Vec<([i64; 3], usize)> {
    let mut keys: Vec<([i64; 3], usize)> = points
        .par_iter()
        .enumerate()
        .filter(|(_, p)| is_finite(p))
        .map(|(i, p)| {
            let c = cells.of(p);
            ([c[2], c[1], c[0]], i)
        })
        .collect();
    keys.par_sort_unstable();
    keys
}

/// Which way [`centroids`] went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Way {
    /// A table a thread (`table.rs`).
    Table,
    /// Keys bucketed and sorted ([`bucketed_centroids`]).
    Buckets,
    /// (u64 index, point) pairs sorted.
    Pairs,
    /// (z, y, x) triplets sorted.
    Triplets,
}

/// [`voxel_grid`]'s centroids on the instruction set `isa`, and the way
/// taken; the tables are tried only where `tables` (the tests compare
/// the ways).
fn centroids(
    cloud: &[Point],
    params: &VoxelGridParams,
    isa: Isa,
    tables: bool,
) -> Result<(Vec<Point>, Way)> {
    let inv = params.inverse_leaf()?;
    if cloud.is_empty() {
        return Err(empty_input(FILTER));
    }
    let points = cloud;
    // A point's coordinates in leaves, and whether a voxel index from them
    // is exact: |floor(v)| < 4e18 exactly when |v| < 4e18 at f32's spacing
    // there (2³⁹).
    let scaled = |p: &Point| [0, 1, 2].map(|a| p[a] * inv[a]);
    let in_range = |v: f32| v.is_finite() && v.abs() < MAX_CELL;
    // The voxel of a finite point ([RS eq. 18] per point), checked.
    let cell = |p: &Point| -> Result<[i64; 3]> {
        let v = scaled(p);
        if let Some(a) = (0..3).find(|&a| !in_range(v[a])) {
            return Err(bad(
                FILTER,
                format!(
                    "leaf_m[{a}] = {} is too small for the coordinate {} (voxel index beyond 4e18)",
                    short(params.leaf_m[a]),
                    p[a]
                ),
            ));
        }
        Ok(v.map(floor_i64))
    };
    // Bounds in voxels ([RS eq. 17]), in one parallel pass (⌊·⌋ is
    // monotonic, so the bounds' voxels are the voxels' bounds; so is
    // rounding v · (1 / leaf), so the bounds of the points scale to those
    // of the scaled points), checked once at the end.
    let (vlo, vhi) = match crate::cloud::lane_bounds(points) {
        (lo, hi, true) => (
            [0, 1, 2].map(|a| lo[a] * inv[a]),
            [0, 1, 2].map(|a| hi[a] * inv[a]),
        ),
        _ => {
            // A coordinate is not finite: its point's others are passed
            // over too.
            let none = || ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            points
                .par_chunks(1 << 14)
                .map(|chunk| {
                    let (mut lo, mut hi) = none();
                    for p in chunk.iter().filter(|p| is_finite(p)) {
                        let v = scaled(p);
                        for a in 0..3 {
                            lo[a] = lo[a].min(v[a]);
                            hi[a] = hi[a].max(v[a]);
                        }
                    }
                    (lo, hi)
                })
                .reduce(none, |(l1, h1), (l2, h2)| {
                    (
                        [0, 1, 2].map(|a| l1[a].min(l2[a])),
                        [0, 1, 2].map(|a| h1[a].max(h2[a])),
                    )
                })
        }
    };
    if vlo[0] > vhi[0] {
        return Err(super::common::emptied(
            FILTER,
            cloud.len(),
            "every point has a non-finite coordinate",
        ));
    }
    if !(0..3).all(|a| in_range(vlo[a]) && in_range(vhi[a])) {
        // Name the first point at fault.
        for p in points.iter().filter(|p| is_finite(p)) {
            cell(p)?;
        }
    }
    let (lo, hi) = (vlo.map(floor_i64), vhi.map(floor_i64));
    let extent = [0, 1, 2].map(|a| (hi[a] - lo[a]) as u128 + 1);
    // Each extent is below 8e18, so the product of all three may pass
    // u128 (fuzzing the settings found it): saturate, which only selects
    // the triplet sort below.
    let voxels = extent[0]
        .saturating_mul(extent[1])
        .saturating_mul(extent[2]);
    // The linear index, PCL's order: x fastest, z slowest (the cell is
    // valid: the bounds pass checked every finite point).
    let cells = VoxelCells::with_inverse(inv);
    let grid = keys::Lattice {
        cells,
        lo,
        ex: extent[0] as u64,
        exy: (extent[0] * extent[1]) as u64,
        bits: bits_of(voxels.min(u128::from(u64::MAX)) as u64),
        cells_fit_i32: (0..3).all(|a| vlo[a] >= -2_147_483_648.0 && vhi[a] < 2_147_483_648.0),
    };
    let centroids = if voxels < 1 << 32 {
        // Usual case: every point's key once; then a dense cloud summed
        // into a table a thread, or else the keys bucketed by their top
        // bits, each bucket sorted by the rest.
        let keys = grid.keys(points, isa);
        match tables
            .then(|| table::centroids(points, &keys, grid.bits, isa))
            .flatten()
        {
            Some(centroids) => (centroids, Way::Table),
            None => (
                bucketed_centroids(points, &keys.keys, grid.bits),
                Way::Buckets,
            ),
        }
    } else if voxels <= u128::from(u64::MAX) {
        let mut keys: Vec<(u64, usize)> = points
            .par_iter()
            .enumerate()
            .filter(|(_, p)| is_finite(p))
            .map(|(i, p)| (grid.linear(p), i))
            .collect();
        keys.par_sort_unstable();
        (
            centroids_of_runs(points, &keys, |k| k.0, |k| k.1),
            Way::Pairs,
        )
    } else {
        // A box of 2⁶⁴ voxels or more: sort (z, y, x) triplets, same order.
        let keys = sorted_triplets(points, &cells);
        (
            centroids_of_runs(points, &keys, |k| k.0, |k| k.1),
            Way::Triplets,
        )
    };
    Ok(centroids)
}

impl VoxelCells {
    /// The cells of `params`' leaf (an error for a leaf [`voxel_grid`] refuses).
    pub fn new(params: &VoxelGridParams) -> Result<Self> {
        Ok(Self::with_inverse(params.inverse_leaf()?))
    }
}

/// Fewest points a task of [`bucketed_centroids`] gathers (neighbouring
/// super-buckets taken together): a task's super-buckets are gathered and
/// sorted one after another in one buffer, which with a second of its size
/// stays in the second-level cache.
const SUPER: usize = 1 << 14;

/// Points a super-bucket of [`bucketed_centroids`] holds on average: a
/// sixteenth of a task, so that a slab of the box where most points lie (a
/// scan's floor, a camera's wall at one depth) is cut into many
/// super-buckets, which tasks share out, where super-buckets of a task's
/// size left one task with a sixth of the points (1.2 M points of PCL's
/// RGB-D scans: 19–20 → 16–17 ms; the raw 1 M scan at 5 cm, floor and
/// all: 16–17 → 11–12 ms, and `perceive`'s voxel stage on it 15.3 → 13.2
/// ms; the bench pile of `benches/filters.rs`, whose points are spread
/// more evenly, 13.3–13.5 → 14.2–14.6 ms, BENCHMARKS.md).
const BUCKET_POINTS: usize = 1 << 10;

/// Most super-buckets of [`bucketed_centroids`] (2¹²): each chunk keeps a
/// start a super-bucket.
const MAX_SUPER_BITS: u32 = 12;

/// Most points of a chunk of [`bucketed_centroids`]: a chunk's entries
/// stay within the caches' reach and the allocator's reuse, where an
/// eighth of a large cloud is fresh memory (the 20 M bench pile, entries of
/// 24 bytes then: 0.82 s with chunks of 2.5 M points, 0.41–0.45 s with 2¹⁷).
const MAX_CHUNK: usize = 1 << 17;

/// A point filed by [`bucketed_centroids`]: its voxel's linear index less
/// the super-bucket's bits, and the point itself (16 bytes). The point's
/// index is not kept: every step keeps a voxel's points in input order
/// (chunks in order, each counting-sorted stably, each super-bucket sorted
/// stably), and the entries are most of the memory the grid writes at 20 M
/// points.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Entry {
    voxel: u32,
    point: Point,
}

impl Voxel for Entry {
    #[inline(always)]
    fn voxel(&self) -> u32 {
        self.voxel
    }
}

/// The centroids of the occupied voxels in linear-index order, from each
/// point's key (`keys.rs`: its voxel's index, below 2^`voxel_bits` ≤ 2³²,
/// or `NOT_FINITE`). Why not one sort of all keys: the cloud is cut into chunks (a few a
/// thread, at most [`MAX_CHUNK`] points), and each chunk is counting-sorted
/// on its own (in cache, in parallel) into super-buckets by the voxel
/// index's top bits (about [`BUCKET_POINTS`] points each, over all
/// chunks); then neighbouring super-buckets are taken together into tasks
/// of at least [`SUPER`] points, and each super-bucket's parts (in chunk
/// order, whole runs of entries) are gathered into a buffer in the
/// second-level cache, where [`sort_and_sum`] sorts and sums them, tasks
/// in parallel. No pass
/// over the whole cloud is serial, the gathering reads long runs (with
/// one level of a few points a bucket, it read one or two entries from
/// each chunk in turn, which on the 20 M pipeline's voxel stage was half
/// its time), and the centroids read the points from the gathered parts,
/// not at random from the cloud.
fn bucketed_centroids(points: &[Point], keys: &[u32], voxel_bits: u32) -> Vec<Point> {
    use keys::NOT_FINITE;
    let n = points.len();
    let super_bits = (usize::BITS - (n / BUCKET_POINTS).max(1).leading_zeros())
        .min(voxel_bits)
        .min(MAX_SUPER_BITS);
    // At most 31: `voxel_bits` ≤ 32 and at least one super-bucket bit.
    let shift = voxel_bits - super_bits;
    let low = (1u32 << shift) - 1;
    let supers = 1usize << super_bits;
    let super_of = |key: u32| (key >> shift) as usize;
    let chunk = n
        .div_ceil(rayon::current_num_threads() * 4)
        .clamp(1 << 12, MAX_CHUNK);
    // Per chunk: its entries by super-bucket, and `start`, where
    // super-bucket b's entries are `start[b]..start[b + 1]`.
    type Part = (Vec<Entry>, Vec<u32>);
    let parts: Vec<Part> = points
        .par_chunks(chunk)
        .zip(keys.par_chunks(chunk))
        .map(|(ps, keys)| {
            let mut start = vec![0u32; supers + 2];
            for &k in keys.iter().filter(|&&k| k != NOT_FINITE) {
                start[super_of(k) + 2] += 1;
            }
            let total = counts_to_starts(&mut start);
            let mut sorted: Vec<Entry> = crate::prefault::with_room(total);
            let room = &mut sorted.spare_capacity_mut()[..total];
            for (&k, p) in keys.iter().zip(ps).filter(|(&k, _)| k != NOT_FINITE) {
                let slot = &mut start[super_of(k) + 1];
                room[*slot as usize].write(Entry {
                    voxel: k & low,
                    point: *p,
                });
                *slot += 1;
            }
            // SAFETY: a counting sort: bucket b's count of entries went to
            // its own slots start(b)..start(b + 1), so each of the `total`
            // slots was written exactly once. Not zeroed first: that was a
            // pass over fresh memory.
            unsafe { sorted.set_len(total) };
            (sorted, start)
        })
        .collect();
    // Tasks: runs of neighbouring super-buckets of at least SUPER points.
    let mut total = vec![0usize; supers];
    for (_, start) in &parts {
        for (b, t) in total.iter_mut().enumerate() {
            *t += (start[b + 1] - start[b]) as usize;
        }
    }
    let mut tasks: Vec<(usize, usize)> = Vec::new();
    let (mut from, mut held) = (0, 0);
    for (b, &t) in total.iter().enumerate() {
        held += t;
        if held >= SUPER {
            tasks.push((from, b + 1));
            (from, held) = (b + 1, 0);
        }
    }
    if from < supers {
        tasks.push((from, supers));
    }
    let out: Vec<Vec<Point>> = tasks
        .into_par_iter()
        .map_init(Buffers::default, |buf, (first, end)| {
            let mut out = Vec::new();
            for b in first..end {
                buf.gathered.clear();
                for (sorted, start) in &parts {
                    buf.gathered
                        .extend_from_slice(&sorted[start[b] as usize..start[b + 1] as usize]);
                }
                if !buf.gathered.is_empty() {
                    sort_and_sum(buf, shift, &mut out);
                }
            }
            out
        })
        .collect();
    out.concat()
}

/// Bits of the linear index of a box of `voxels` (at least 1).
fn bits_of(voxels: u64) -> u32 {
    64 - (voxels.max(2) - 1).leading_zeros()
}

/// Counts at `b + 2` (bucket b's count) into starts in place: after it,
/// `start[b + 1]` is bucket b's start, which a counting sort's filing moves
/// on to its end (the next bucket's start), leaving `start[b]` as bucket
/// b's start. Returns the total.
fn counts_to_starts(start: &mut [u32]) -> usize {
    for b in 1..start.len() {
        start[b] += start[b - 1];
    }
    start.last().map_or(0, |&t| t as usize)
}

/// The working buffers of one thread of [`bucketed_centroids`].
#[derive(Default)]
struct Buffers {
    gathered: Vec<Entry>,
    spare: Vec<Entry>,
}

/// Pushes the centroids of the entries in `buf.gathered` (voxel indices
/// below 2^`bits`, each voxel's points in input order) onto `out`, in
/// voxel order: sorted stably by voxel (a radix sort, or a comparison
/// sort for a few entries unless they are in order) and summed.
fn sort_and_sum(buf: &mut Buffers, bits: u32, out: &mut Vec<Point>) {
    let len = buf.gathered.len();
    let sorted: &[Entry] = if len >= RADIX_FROM {
        if buf.spare.len() < len {
            buf.spare.resize(len, Entry::default());
        }
        radix_sort_voxels(&mut buf.gathered, &mut buf.spare[..len], bits)
    } else {
        if !buf.gathered.is_sorted_by_key(|e| e.voxel) {
            // Stable: a voxel's points stay in input order.
            buf.gathered.sort_by_key(|e| e.voxel);
        }
        &buf.gathered
    };
    push_centroids(sorted, |e| e.voxel, |e| e.point, out);
}

/// Entries from which [`radix_sort_voxels`] sorts them (below, a
/// comparison sort is quicker).
const RADIX_FROM: usize = 32;

/// The centroid of each run of equal voxel keys in the sorted `keys`, in
/// key order. Within a voxel, points are summed in ascending index, so the
/// result depends neither on the sort nor on the number of threads.
fn centroids_of_runs<T, K, V, I>(points: &[Point], keys: &[T], voxel: V, index: I) -> Vec<Point>
where
    T: Sync,
    V: Fn(&T) -> K + Sync,
    I: Fn(&T) -> usize + Sync,
    K: PartialEq,
{
    // Cut the sorted keys into chunks at run starts, one chunk per task.
    let n = keys.len();
    let tasks = (rayon::current_num_threads() * 4).max(1);
    let mut cuts = vec![0];
    for t in 1..tasks {
        let mut c = (n * t / tasks).max(*cuts.last().expect("not empty"));
        while c > 0 && c < n && voxel(&keys[c]) == voxel(&keys[c - 1]) {
            c += 1;
        }
        if c < n && c > *cuts.last().expect("not empty") {
            cuts.push(c);
        }
    }
    cuts.push(n);
    let chunks: Vec<Vec<Point>> = cuts
        .par_windows(2)
        .map(|w| {
            let mut out = Vec::new();
            push_centroids(&keys[w[0]..w[1]], &voxel, |k| points[index(k)], &mut out);
            out
        })
        .collect();
    chunks.concat()
}

/// Pushes the centroid of each run of entries with equal `voxel` in
/// `sorted`, in order, onto `out`; a voxel's points (`point`) are summed in
/// f64 in the order given, so the result depends neither on the sort nor
/// on the number of threads when that order is the input order.
fn push_centroids<T, K, V, P>(sorted: &[T], voxel: V, point: P, out: &mut Vec<Point>)
where
    V: Fn(&T) -> K,
    P: Fn(&T) -> Point,
    K: PartialEq,
{
    let mut start = 0;
    while start < sorted.len() {
        let key = voxel(&sorted[start]);
        let mut sum = [0.0_f64; 3];
        let mut end = start;
        while end < sorted.len() && voxel(&sorted[end]) == key {
            let p = point(&sorted[end]);
            for a in 0..3 {
                sum[a] += f64::from(p[a]);
            }
            end += 1;
        }
        let count = (end - start) as f64;
        out.push([0, 1, 2].map(|a| (sum[a] / count) as f32));
        start = end;
    }
}

#[cfg(test)]
mod tests {
    use super::{centroids, VoxelGridParams, Way};
    use crate::simd::Isa;
    use crate::Point;

    /// A camera-like scan: rows of points 2 mm apart over a gentle
    /// surface (with a step), so tens of points share a 2 cm voxel and
    /// neighbours in the input are neighbours in space; points on voxel
    /// faces, non-finite points, and a far corner that widens the box.
    fn scan(rows: usize, columns: usize, seed: u64) -> Vec<Point> {
        let mut next = crate::testing::below(seed);
        let mut points = Vec::with_capacity(rows * columns + 8);
        for r in 0..rows {
            for c in 0..columns {
                let (x, y) = (c as f32 * 0.002 - 1.0, r as f32 * 0.002 - 0.7);
                let step = if x > 0.3 { 0.25 } else { 0.0 };
                let noise = next(1000) as f32 * 2e-6;
                points.push([x, y, 0.1 * x + 0.05 * y + step + noise - 0.5]);
            }
        }
        for i in 0..8 {
            let at = next(points.len() as u64) as usize;
            points[at] = match i % 4 {
                0 => [f32::NAN, 0.0, 0.0],
                1 => [0.0, f32::INFINITY, 0.0],
                // On voxel faces (a multiple of the 2 cm leaf).
                2 => [0.2, -0.4, 0.06],
                _ => [0.02, 0.04, -0.08],
            };
        }
        points.push([3.0, 2.0, 1.5]);
        points
    }

    /// The centroids each voxel's points give when summed in f64 in
    /// input order (PCL's voxels, (z, y, x) order): the rule both ways
    /// keep, computed independently.
    fn map_of_voxels(points: &[Point], leaf: f64) -> Vec<Point> {
        let inv = 1.0 / leaf as f32;
        let mut voxels = std::collections::BTreeMap::<[i64; 3], ([f64; 3], f64)>::new();
        for p in points.iter().filter(|p| p.iter().all(|v| v.is_finite())) {
            let e = voxels
                .entry([2, 1, 0].map(|a| (p[a] * inv).floor() as i64))
                .or_insert(([0.0; 3], 0.0));
            for (sum, &v) in e.0.iter_mut().zip(p) {
                *sum += f64::from(v);
            }
            e.1 += 1.0;
        }
        voxels
            .values()
            .map(|(s, n)| [0, 1, 2].map(|a| (s[a] / n) as f32))
            .collect()
    }

    fn bits(points: &[Point]) -> Vec<[u32; 3]> {
        points.iter().map(|p| p.map(f32::to_bits)).collect()
    }

    #[test]
    fn the_tables_give_the_sorting_bits_on_every_path_and_thread_count() {
        let leaf = 0.02;
        let params = VoxelGridParams::cube(leaf);
        // 640 k points, 12 k voxels: more than a table first holds, with
        // one thread or several; and the same points shuffled in blocks of
        // 15 rows, which cut the 10 rows of a voxel's points apart.
        let dense = scan(800, 800, 3);
        let mut blocks: Vec<&[Point]> = dense.chunks(12_000).collect();
        let mut next = crate::testing::below(4);
        for i in (1..blocks.len()).rev() {
            blocks.swap(i, next(i as u64 + 1) as usize);
        }
        let shuffled: Vec<Point> = blocks.concat();
        for cloud in [&dense, &shuffled] {
            let expected = bits(&map_of_voxels(cloud, leaf));
            for isa in Isa::available() {
                for threads in [1, 2, 3] {
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .unwrap();
                    let (tabled, way) = pool
                        .install(|| centroids(cloud, &params, isa, true))
                        .unwrap();
                    assert_eq!(way, Way::Table, "{isa:?}, {threads} threads");
                    assert!(bits(&tabled) == expected, "{isa:?}, {threads} threads");
                    let (sorted, way) = pool
                        .install(|| centroids(cloud, &params, isa, false))
                        .unwrap();
                    assert_eq!(way, Way::Buckets);
                    assert!(bits(&sorted) == expected, "{isa:?}, {threads} threads");
                }
            }
        }
    }

    #[test]
    fn the_tables_are_taken_for_dense_voxels_only() {
        // 100 k points at random in a cube: few points a voxel at 2 cm,
        // ten thousand at 50 cm, but hardly two in a row in one voxel
        // (the keys' sample says so) and too few points to estimate its
        // voxels: sorted; a scan in rows, with runs
        // of three points a voxel and nine points a voxel at 6 mm (tried,
        // then given up) and fifty at 2 cm (tabled).
        let mut next = crate::testing::below(5);
        let random: Vec<Point> = (0..100_000)
            .map(|_| [0, 1, 2].map(|_| next(1 << 20) as f32 / (1 << 20) as f32 * 2.0 - 1.0))
            .collect();
        let rows = scan(400, 400, 6);
        // 1.1 M points at random: estimated first (2 cm: sorted, 50 cm:
        // tabled, one voxel for seventeen thousand points).
        let many: Vec<Point> = (0..1_100_000)
            .map(|_| [0, 1, 2].map(|_| next(1 << 20) as f32 / (1 << 20) as f32 * 2.0 - 1.0))
            .collect();
        for (cloud, leaf, want) in [
            (&random, 0.02, Way::Buckets),
            (&random, 0.5, Way::Buckets),
            (&rows, 0.006, Way::Buckets),
            (&rows, 0.02, Way::Table),
            (&many, 0.02, Way::Buckets),
            (&many, 0.5, Way::Table),
        ] {
            let (got, way) =
                centroids(cloud, &VoxelGridParams::cube(leaf), Isa::best(), true).unwrap();
            assert_eq!(way, want, "leaf {leaf}");
            assert!(
                bits(&got) == bits(&map_of_voxels(cloud, leaf)),
                "leaf {leaf}"
            );
        }
    }

    #[test]
    fn the_tables_cut_a_box_of_nearly_2_32_voxels_among_threads() {
        // A box of 65 535 × 256 × 256 voxels (2³² less 2¹⁶: 32-bit keys)
        // between two dense runs of points at its corners, a third of
        // them at the near one: the far one's keys all fall in the
        // histogram's last bin, where every thread's range must still end
        // within the keys.
        let mut points: Vec<Point> = Vec::new();
        for i in 0..10_000 {
            let x = 0.5 + i as f32 * 0.0267;
            points.extend(std::iter::repeat_n([x, 0.5, 0.5], 3));
        }
        for i in 0..20_000 {
            let x = 65_000.0 + i as f32 * 0.0267;
            points.extend(std::iter::repeat_n([x, 255.5, 255.5], 3));
        }
        let leaf = 1.0;
        let expected = bits(&map_of_voxels(&points, leaf));
        for threads in [1, 2, 3, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let (got, way) = pool
                .install(|| centroids(&points, &VoxelGridParams::cube(leaf), Isa::best(), true))
                .unwrap();
            assert_eq!(way, Way::Table, "{threads} threads");
            assert!(bits(&got) == expected, "{threads} threads");
        }
    }

    #[test]
    fn the_tables_take_cells_beyond_32_bits_on_every_path() {
        // A line 3 km from the origin at a 1 µm leaf: cells near 3e9,
        // past i32 (the vector keys give way to the portable ones), in a
        // box of 5 M voxels; each point repeated 20 times in a row, so
        // the tables take it.
        let points: Vec<Point> = (0..20_000)
            .flat_map(|i| {
                let x = 3000.0 + i as f32 * 2.5e-4;
                std::iter::repeat_n([x, 0.5, -0.25], 20)
            })
            .collect();
        let leaf = 1e-6;
        let expected = bits(&map_of_voxels(&points, leaf));
        for isa in Isa::available() {
            let (got, way) = centroids(&points, &VoxelGridParams::cube(leaf), isa, true).unwrap();
            assert_eq!(way, Way::Table, "{isa:?}");
            assert!(bits(&got) == expected, "{isa:?}");
        }
    }
}
