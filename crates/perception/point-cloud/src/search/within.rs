//! The inner loop of every grid search (`search::columns`): the squared distances
//! from a query to a run of points, and which of them lie within a cap —
//! kept (the distances themselves, or a payload such as the points'
//! indices) or counted.
//!
//! Why written by hand: the loop is most of a search's time, and its two
//! halves pull apart in plain Rust. The distances vectorise, but keeping
//! those within the cap is a loop-carried store (`out[kept] = d; kept +=
//! d ≤ cap`) that the compiler leaves scalar, and fused into one loop the
//! distances stop vectorising too (1.15× slower, measured). A vector
//! "left-pack" does both at once: AVX-512's `vpcompressd` (from a register;
//! its store form is slow on AMD's Zen 4), or on AVX2 a permutation looked
//! up by the comparison's mask. `std::simd` is not stable, and no kept
//! crate offers a compress. The instruction set is found at run time, so
//! one build serves every x86-64 machine, and other targets take the
//! portable loop; `AUTOSHOVEL_ISA=avx2` or `=portable` in the environment
//! holds a run to a narrower path (BENCHMARKS.md compares them).
//!
//! Every path computes `dx·dx + dy·dy + dz·dz` in f32, in that order, with
//! no fused multiply-add (FLANN's arithmetic, as `search::kdtree`), so each
//! gives the same bits as the portable loop; the tests hold them to it.

use crate::simd::{Isa, Path};

/// A run of points by axis (equal lengths).
#[derive(Debug, Clone, Copy)]
pub(super) struct Run<'a> {
    pub x: &'a [f32],
    pub y: &'a [f32],
    pub z: &'a [f32],
}

impl Run<'_> {
    /// The points from position `i` on.
    fn from(self, i: usize) -> Self {
        Run {
            x: &self.x[i..],
            y: &self.y[i..],
            z: &self.z[i..],
        }
    }
}

/// Appends to `out` the squared distances from `q` (as bits) of the run's
/// points within squared distance `cap` (inclusive), in run order.
#[inline]
pub(super) fn keep_distances(isa: Isa, q: [f32; 3], run: Run, cap: f32, out: &mut Vec<u32>) {
    keep::<false>(isa, q, run, &[], cap, out);
}

/// Appends to `out` `payload[i]` for each point `i` of the run within
/// squared distance `cap` of `q` (inclusive), in run order.
#[inline]
pub(super) fn keep_payload(
    isa: Isa,
    q: [f32; 3],
    run: Run,
    payload: &[u32],
    cap: f32,
    out: &mut Vec<u32>,
) {
    assert_eq!(payload.len(), run.x.len(), "a payload a point");
    keep::<true>(isa, q, run, payload, cap, out);
}

/// Appends to `out` (by axis) the points of `run` inside the box `lo..hi`
/// (bounds included), in run order.
///
/// Why: a group's gather holds every point near any of its few dozen
/// points; a quarter of the group, cut to its own box, reads about half
/// as many a query (272 of 478 on `kinect5`). AVX-512 packs the points
/// kept with a compress a vector; the other paths take the portable,
/// branch-free loop.
pub(super) fn keep_inside(isa: Isa, run: Run, lo: [f32; 3], hi: [f32; 3], out: [&mut Vec<f32>; 3]) {
    check(run);
    let [ox, oy, oz] = out;
    assert!(
        ox.len() == oy.len() && ox.len() == oz.len(),
        "the output's axes differ in length"
    );
    match isa.path() {
        // SAFETY: `t` proves AVX-512; `check` made the run's axes equally
        // long, and the output's axes are equally long (asserted above).
        #[cfg(target_arch = "x86_64")]
        Path::Avx512(t) => unsafe { avx512::keep_inside(t, run, lo, hi, [ox, oy, oz]) },
        _ => portable::keep_inside(run, lo, hi, [ox, oy, oz]),
    }
}

/// How many of the run's points lie within squared distance `cap` of `q`
/// (inclusive).
#[inline]
pub(super) fn count(isa: Isa, q: [f32; 3], run: Run, cap: f32) -> usize {
    check(run);
    match isa.path() {
        Path::Portable => portable::count(q, run, cap),
        // SAFETY: `t` proves the instruction set; `check` made the lengths equal.
        #[cfg(target_arch = "x86_64")]
        Path::Avx2(t) => unsafe { avx2::count(t, q, run, cap) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Path::Avx512(t) => unsafe { avx512::count(t, q, run, cap) },
    }
}

/// Leaves the `k` smallest of `bits` in `bits[..k]`, the largest of them
/// (the k-th) last and the others in any order (what lies past k is
/// left in no order, and not always a permutation); `bits` are squared
/// distances as bits (≥ +0, so below 2³¹, and ordered as the numbers)
/// and `1 ≤ k ≤ bits.len()`.
///
/// A k-nearest query finds a few more than k (a few dozen) and keeps the
/// k: a comparison sort or a quickselect of a few dozen branches on every
/// comparison, which mispredicts on distances in no order (about 300 and
/// 190 ns for 21 of 21–32 on the Xeon VM; 560 and 240 for 51 of 51–64).
/// Up to 128 of them (64 on AVX2) are sorted by a network instead,
/// branch-free (`avx512::sort`, `avx2::sort`): on AVX-512 and AVX2 24 and
/// 49 ns for 21 of 21–32, 41 and 74 for 51 of 51–64, 95 ns for 51 of 60–80
/// on AVX-512 (ranking them, each value's rank the count of values below
/// it by a vector compare and add a value, took 80 and 112, 160 and 188,
/// and 250; measured on the model-167 VM, 2026-12-05). Past those counts,
/// and on the portable path, a quickselect (`select_nth_unstable`) does it.
pub(super) fn smallest(isa: Isa, bits: &mut [u32], k: usize) {
    assert!(
        (1..=bits.len()).contains(&k),
        "k = {k} of {} distances",
        bits.len()
    );
    // (the portable path asks no network: no call on its queries)
    #[cfg(target_arch = "x86_64")]
    let sorted = isa.avx2().is_some() && sort_by_network(isa, bits);
    #[cfg(not(target_arch = "x86_64"))]
    let sorted = false;
    if !sorted {
        bits.select_nth_unstable(k - 1);
    }
}

/// As [`smallest`], told a value `pivot` near the k-th (a little below a
/// neighbour's k-th): the values are split at it (`avx512::split`, two
/// compresses a vector), and only the side holding the k-th is sorted: the
/// few above the pivot where it lies a little below the k-th (a network
/// of 16 or 32 lanes, where [`smallest`] sorts all 60–80 in one of 64 or
/// 128). Any pivot gives the same k (the tests try pivots below, at and
/// above the k-th, and 0); a far one only costs time. AVX-512 only: a
/// scalar split (two cursors, branch-free) took 17 % of the statistical
/// filter's time on `kinect5`, the vector split 4 % (perf, 2026-12-06), so
/// the other paths, and lists of at most 16 or more than 128, go to
/// [`smallest`].
pub(super) fn smallest_near(isa: Isa, bits: &mut [u32], k: usize, pivot: u32) {
    let n = bits.len();
    if n > 128 || n <= 16 {
        return smallest(isa, bits, k);
    }
    assert!((1..=n).contains(&k), "k = {k} of {n} distances");
    let a = match isa.path() {
        // SAFETY: `t` proves AVX-512F; n ≤ 128 (above).
        #[cfg(target_arch = "x86_64")]
        Path::Avx512(t) => unsafe { avx512::split(t, bits, pivot) },
        _ => return smallest(isa, bits, k),
    };
    if a > k {
        smallest(isa, &mut bits[..a], k);
    } else if a == k {
        let (mut at, mut most) = (0, 0);
        for (i, &v) in bits[..k].iter().enumerate() {
            if v >= most {
                (at, most) = (i, v);
            }
        }
        bits.swap(at, k - 1);
    } else {
        smallest(isa, &mut bits[a..], k - a);
    }
}

/// Sorts `values` ascending by the network of `avx512::sort` (at most
/// 128 of them) or `avx2::sort` (at most 64); `false`, with them
/// untouched, for more, or on the portable path.
#[cfg(target_arch = "x86_64")]
fn sort_by_network(isa: Isa, values: &mut [u32]) -> bool {
    let n = values.len();
    // SAFETY: `t` proves the instruction set; the lengths as `sort` requires.
    unsafe {
        match (isa.path(), n) {
            (Path::Avx512(t), 0..=16) => avx512::sort::<1>(t, values),
            (Path::Avx512(t), 17..=32) => avx512::sort::<2>(t, values),
            (Path::Avx512(t), 33..=64) => avx512::sort::<4>(t, values),
            (Path::Avx512(t), 65..=128) => avx512::sort::<8>(t, values),
            (Path::Avx2(t), 0..=8) => avx2::sort::<1>(t, values),
            (Path::Avx2(t), 9..=16) => avx2::sort::<2>(t, values),
            (Path::Avx2(t), 17..=32) => avx2::sort::<4>(t, values),
            (Path::Avx2(t), 33..=64) => avx2::sort::<8>(t, values),
            _ => return false,
        }
    }
    true
}

/// Sorts `values` ascending by the network of `avx512::sort_wide` (at most
/// 128 of them, on AVX-512); `false`, with them untouched, elsewhere.
pub(super) fn sort_wide(isa: Isa, values: &mut [u64]) -> bool {
    #[cfg(target_arch = "x86_64")]
    if let Some(t) = isa.avx512() {
        // SAFETY: `t` proves AVX-512F; the lengths as `sort_wide` requires.
        unsafe {
            match values.len() {
                0..=8 => avx512::sort_wide::<1>(t, values),
                9..=16 => avx512::sort_wide::<2>(t, values),
                17..=32 => avx512::sort_wide::<4>(t, values),
                33..=64 => avx512::sort_wide::<8>(t, values),
                65..=128 => avx512::sort_wide::<16>(t, values),
                _ => return false,
            }
        }
        return true;
    }
    let _ = (isa, values);
    false
}

/// Most values [`ranks`] ranks.
pub(super) const MOST_RANKED: usize = 64;

/// Each of `values`' rank (the count of values below it, as unsigned
/// integers) in `ranks[..n]`, by vector compares (AVX2's, on AVX-512
/// machines too, which sort by their network where this would serve);
/// `false` where two are equal (no rank is then unique), for more than
/// [`MOST_RANKED`] values, and on the portable path.
pub(super) fn ranks(isa: Isa, values: &[u32], ranks: &mut [u32; MOST_RANKED]) -> bool {
    let n = values.len();
    let ranked = match isa.avx2() {
        None => false,
        Some(_) if n < 2 => {
            ranks[..n].fill(0);
            true
        }
        // SAFETY: `t` proves AVX2 (AVX-512 machines have it too); the
        // lengths as `ranks` requires.
        #[cfg(target_arch = "x86_64")]
        Some(t) if n <= 32 => unsafe { avx2::ranks::<4>(t, values, ranks) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Some(t) if n <= 64 => unsafe { avx2::ranks::<8>(t, values, ranks) },
        Some(_) => false,
    };
    // Distinct values have ranks 0..n, whose sum is n(n − 1)/2; with ties
    // every rank is at most the distinct case's and some below it.
    ranked && ranks[..n].iter().map(|&r| r as usize).sum::<usize>() == n * n.saturating_sub(1) / 2
}

/// Sorts `ids` ascending: a search's neighbours into input order (a few
/// dozen, gathered column by column). By the network of [`smallest`]: 42
/// and 71 ns for 30–60 values on AVX-512 and AVX2, against 266 for
/// `sort_unstable`, which was a tenth of the smoothing stage's time.
/// Longer lists (more than 128, or 64 on AVX2) and the portable path take
/// `sort_unstable`.
pub(super) fn sort_ids(isa: Isa, ids: &mut [u32]) {
    #[cfg(target_arch = "x86_64")]
    if sort_by_network(isa, ids) {
        return;
    }
    let _ = isa;
    ids.sort_unstable();
}

/// Puts `items` in the order of their `keys` (one an item) where [`ranks`]
/// ranks the keys; `false`, with `items` untouched, where it does not
/// (ties, too many, the portable path).
pub(super) fn order_by_rank<T: Copy + Default>(isa: Isa, keys: &[u32], items: &mut [T]) -> bool {
    assert_eq!(keys.len(), items.len(), "a key an item");
    let mut rank = [0u32; MOST_RANKED];
    if !ranks(isa, keys, &mut rank) {
        return false;
    }
    let mut sorted = [T::default(); MOST_RANKED];
    for (&item, &r) in items.iter().zip(&rank) {
        sorted[r as usize] = item;
    }
    items.copy_from_slice(&sorted[..items.len()]);
    true
}

fn keep<const PAYLOAD: bool>(
    isa: Isa,
    q: [f32; 3],
    run: Run,
    payload: &[u32],
    cap: f32,
    out: &mut Vec<u32>,
) {
    check(run);
    match isa.path() {
        Path::Portable => portable::keep::<PAYLOAD>(q, run, payload, cap, out),
        // SAFETY: as in `count`; `payload` is as long as the run when
        // `PAYLOAD` (asserted by `keep_payload`).
        #[cfg(target_arch = "x86_64")]
        Path::Avx2(t) => unsafe { avx2::keep::<PAYLOAD>(t, q, run, payload, cap, out) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Path::Avx512(t) => unsafe { avx512::keep::<PAYLOAD>(t, q, run, payload, cap, out) },
    }
}

fn check(run: Run) {
    assert!(
        run.x.len() == run.y.len() && run.x.len() == run.z.len(),
        "a run's axes differ in length"
    );
}

/// The squared distance in FLANN's order.
#[inline(always)]
fn squared(q: [f32; 3], x: f32, y: f32, z: f32) -> f32 {
    let (dx, dy, dz) = (q[0] - x, q[1] - y, q[2] - z);
    dx * dx + dy * dy + dz * dz
}

/// A vector register of unsigned lanes that [`network`] sorts.
#[cfg(target_arch = "x86_64")]
trait Network: Copy {
    /// Lanes a register.
    const LANES: usize;
    /// The lane-wise smaller and larger of `a` and `b`.
    ///
    /// # Safety
    /// The register's instruction set.
    unsafe fn min_max(a: Self, b: Self) -> (Self, Self);
    /// Lane i holding lane i ^ j (`j` below `LANES`).
    ///
    /// # Safety
    /// The register's instruction set.
    unsafe fn partner(self, j: usize) -> Self;
    /// `hi`'s lanes where `mask` has their bit, `lo`'s elsewhere.
    ///
    /// # Safety
    /// The register's instruction set.
    unsafe fn pick(lo: Self, hi: Self, mask: u32) -> Self;
}

/// Sorts the lanes of `r` ascending, register after register: a bitonic
/// network, each stage comparing every lane with the lane `j` away (a
/// permutation of the register, or the register `j / LANES` away) and
/// keeping the smaller or the larger by a mask. No branch depends on the
/// values, where a comparison sort mispredicts on distances in no order;
/// 32 lanes of u32 sort in some 120 instructions, where ranking them took a
/// compare and an add a value and a register. The stages are written out
/// (`stages!`), with constant masks and permutations, so that the
/// registers stay registers.
///
/// # Safety
/// The register's instruction set; `V` a power of two, `LANES · V ≤ 128`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn network<R: Network, const V: usize>(r: &mut [R; V]) {
    macro_rules! stages {
        ($(($size:literal; $($j:literal)*))*) => {
            $(if $size <= R::LANES * V {
                // SAFETY: as this function's.
                $(unsafe { stage::<R, V, $size, $j>(r) };)*
            })*
        };
    }
    stages! {
        (2; 1) (4; 2 1) (8; 4 2 1) (16; 8 4 2 1) (32; 16 8 4 2 1)
        (64; 32 16 8 4 2 1) (128; 64 32 16 8 4 2 1)
    }
}

/// One stage of [`network`]: runs of `SIZE` lanes sorted up where
/// (lane & SIZE) = 0 and down elsewhere (all up in the last round), each
/// lane against the lane `J` away.
///
/// # Safety
/// As [`network`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn stage<R: Network, const V: usize, const SIZE: usize, const J: usize>(r: &mut [R; V]) {
    let all = (1u32 << R::LANES) - 1;
    // A register's lanes i with i & j ≠ 0: the upper of each pair.
    let upper = |j: usize| -> u32 {
        all & match j {
            1 => 0xAAAA,
            2 => 0xCCCC,
            4 => 0xF0F0,
            _ => 0xFF00,
        }
    };
    if J >= R::LANES {
        let d = J / R::LANES;
        for c in (0..V).filter(|c| c & d == 0 && (c | d) < V) {
            // SAFETY: as this function's.
            let (lo, hi) = unsafe { R::min_max(r[c], r[c | d]) };
            (r[c], r[c | d]) = if (R::LANES * c) & SIZE == 0 {
                (lo, hi)
            } else {
                (hi, lo)
            };
        }
        return;
    }
    for (c, lane) in r.iter_mut().enumerate() {
        let down = if SIZE < R::LANES {
            upper(SIZE)
        } else if (R::LANES * c) & SIZE != 0 {
            all
        } else {
            0
        };
        // SAFETY: as this function's.
        unsafe {
            let (lo, hi) = R::min_max(*lane, lane.partner(J));
            // The larger where a lane is its pair's upper in a run sorted
            // up, or its lower in one sorted down.
            *lane = R::pick(lo, hi, upper(J) ^ down);
        }
    }
}

mod portable {
    use super::{squared, Run};

    pub(super) fn keep<const PAYLOAD: bool>(
        q: [f32; 3],
        run: Run,
        payload: &[u32],
        cap: f32,
        out: &mut Vec<u32>,
    ) {
        // In chunks: the distances in a loop of arithmetic alone (which
        // the compiler vectorises for the target), then a branch-free keep
        // (a branch a point mispredicts at every other point: 2× slower).
        const CHUNK: usize = 64;
        let mut d = [0f32; CHUNK];
        for s in (0..run.x.len()).step_by(CHUNK) {
            let chunk = run.from(s);
            let m = chunk.x.len().min(CHUNK);
            let points = chunk.x[..m].iter().zip(&chunk.y[..m]).zip(&chunk.z[..m]);
            for (d, ((&x, &y), &z)) in d.iter_mut().zip(points) {
                *d = squared(q, x, y, z);
            }
            let base = out.len();
            out.resize(base + m, 0);
            let mut kept = 0;
            for (i, &d) in d[..m].iter().enumerate() {
                out[base + kept] = if PAYLOAD { payload[s + i] } else { d.to_bits() };
                kept += usize::from(d <= cap);
            }
            out.truncate(base + kept);
        }
    }

    pub(super) fn keep_inside(run: Run, lo: [f32; 3], hi: [f32; 3], out: [&mut Vec<f32>; 3]) {
        // Branch-free, as `keep`: a point in, a point out, in no pattern.
        let base = out[0].len();
        let n = run.x.len();
        let [ox, oy, oz] = out;
        for o in [&mut *ox, &mut *oy, &mut *oz] {
            o.resize(base + n, 0.0);
        }
        let mut kept = base;
        for i in 0..n {
            let (x, y, z) = (run.x[i], run.y[i], run.z[i]);
            (ox[kept], oy[kept], oz[kept]) = (x, y, z);
            let inside = (x >= lo[0])
                & (x <= hi[0])
                & (y >= lo[1])
                & (y <= hi[1])
                & (z >= lo[2])
                & (z <= hi[2]);
            kept += usize::from(inside);
        }
        for o in [ox, oy, oz] {
            o.truncate(kept);
        }
    }

    pub(super) fn count(q: [f32; 3], run: Run, cap: f32) -> usize {
        let points = run.x.iter().zip(run.y).zip(run.z);
        points
            .filter(|&((&x, &y), &z)| squared(q, x, y, z) <= cap)
            .count()
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::{portable, Run};
    use crate::simd::Avx2;

    /// For each 8-bit mask, the lanes it selects, first to last, then
    /// zeros: the permutation that packs the selected lanes to the front.
    static PACK: [[u32; 8]; 256] = {
        let mut table = [[0u32; 8]; 256];
        let mut mask = 0;
        while mask < 256 {
            let (mut lane, mut next) = (0, 0);
            while lane < 8 {
                if mask >> lane & 1 == 1 {
                    table[mask][next] = lane as u32;
                    next += 1;
                }
                lane += 1;
            }
            mask += 1;
        }
        table
    };

    /// Squared distances of the 8 points from position `i`.
    ///
    /// # Safety
    /// AVX2; `i + 8 <= run.x.len()` and the axes equally long.
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn eight(q: [__m256; 3], run: Run, i: usize) -> __m256 {
        // SAFETY: the caller's bounds.
        let (x, y, z) = unsafe {
            (
                _mm256_loadu_ps(run.x.as_ptr().add(i)),
                _mm256_loadu_ps(run.y.as_ptr().add(i)),
                _mm256_loadu_ps(run.z.as_ptr().add(i)),
            )
        };
        let (dx, dy, dz) = (
            _mm256_sub_ps(q[0], x),
            _mm256_sub_ps(q[1], y),
            _mm256_sub_ps(q[2], z),
        );
        _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
            _mm256_mul_ps(dz, dz),
        )
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    fn splat(q: [f32; 3]) -> [__m256; 3] {
        [
            _mm256_set1_ps(q[0]),
            _mm256_set1_ps(q[1]),
            _mm256_set1_ps(q[2]),
        ]
    }

    /// # Safety
    /// AVX2; equal axes; `payload` as long as the run when `PAYLOAD`.
    #[target_feature(enable = "avx2,popcnt")]
    pub(super) unsafe fn keep<const PAYLOAD: bool>(
        _: Avx2,
        q: [f32; 3],
        run: Run,
        payload: &[u32],
        cap: f32,
        out: &mut Vec<u32>,
    ) {
        let n = run.x.len();
        let (qv, capv) = (splat(q), _mm256_set1_ps(cap));
        // Each step stores 8 lanes at the end and keeps some of them.
        out.reserve(n + 8);
        let base = out.len();
        let dst = out.as_mut_ptr();
        let (mut kept, mut i) = (0, 0);
        while i + 8 <= n {
            // SAFETY: i + 8 <= n; the store lies within the reserve (kept ≤ i).
            unsafe {
                let d = eight(qv, run, i);
                let mask = _mm256_movemask_ps(_mm256_cmp_ps(d, capv, _CMP_LE_OQ)) as usize;
                let lanes = if PAYLOAD {
                    _mm256_loadu_si256(payload.as_ptr().add(i).cast())
                } else {
                    _mm256_castps_si256(d)
                };
                let order = _mm256_loadu_si256(PACK[mask].as_ptr().cast());
                let packed = _mm256_permutevar8x32_epi32(lanes, order);
                _mm256_storeu_si256(dst.add(base + kept).cast(), packed);
                kept += mask.count_ones() as usize;
            }
            i += 8;
        }
        // SAFETY: the first `base + kept` are written.
        unsafe { out.set_len(base + kept) };
        let rest = if PAYLOAD { &payload[i..] } else { payload };
        portable::keep::<PAYLOAD>(q, run.from(i), rest, cap, out);
    }

    /// # Safety
    /// AVX2; equal axes.
    #[target_feature(enable = "avx2,popcnt")]
    pub(super) unsafe fn count(_: Avx2, q: [f32; 3], run: Run, cap: f32) -> usize {
        let n = run.x.len();
        let (qv, capv) = (splat(q), _mm256_set1_ps(cap));
        let (mut found, mut i) = (0, 0);
        while i + 8 <= n {
            // SAFETY: i + 8 <= n.
            let d = unsafe { eight(qv, run, i) };
            found += _mm256_movemask_ps(_mm256_cmp_ps(d, capv, _CMP_LE_OQ)).count_ones() as usize;
            i += 8;
        }
        found + portable::count(q, run.from(i), cap)
    }

    /// A register of 8 lanes of u32 for [`super::network`] (lanes picked
    /// by a vector mask, AVX2 having no mask registers).
    #[derive(Clone, Copy)]
    pub(super) struct Lanes(__m256i);

    impl super::Network for Lanes {
        const LANES: usize = 8;
        #[inline(always)]
        unsafe fn min_max(a: Self, b: Self) -> (Self, Self) {
            // SAFETY: the caller has AVX2.
            unsafe {
                (
                    Self(_mm256_min_epu32(a.0, b.0)),
                    Self(_mm256_max_epu32(a.0, b.0)),
                )
            }
        }
        #[inline(always)]
        unsafe fn partner(self, j: usize) -> Self {
            let j = j as i32;
            // SAFETY: the caller has AVX2.
            unsafe {
                let across = _mm256_setr_epi32(j, 1 ^ j, 2 ^ j, 3 ^ j, 4 ^ j, 5 ^ j, 6 ^ j, 7 ^ j);
                Self(_mm256_permutevar8x32_epi32(self.0, across))
            }
        }
        #[inline(always)]
        unsafe fn pick(lo: Self, hi: Self, mask: u32) -> Self {
            let bit = |i: u32| -((mask >> i & 1) as i32);
            // SAFETY: the caller has AVX2.
            unsafe {
                let pick = _mm256_setr_epi32(
                    bit(0),
                    bit(1),
                    bit(2),
                    bit(3),
                    bit(4),
                    bit(5),
                    bit(6),
                    bit(7),
                );
                Self(_mm256_blendv_epi8(lo.0, hi.0, pick))
            }
        }
    }

    /// Sorts `values` (at most `8 · V`) ascending as unsigned integers by
    /// [`super::network`].
    ///
    /// # Safety
    /// AVX2; `values.len() ≤ 8 · V`, `V` one of 1, 2, 4, 8.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn sort<const V: usize>(_: Avx2, values: &mut [u32]) {
        let n = values.len();
        debug_assert!(n <= 8 * V && V.is_power_of_two() && V <= 8);
        let mut filled = [u32::MAX; 64];
        filled[..n].copy_from_slice(values);
        // SAFETY: 8 · V ≤ 64 lanes of `filled`.
        let mut r: [Lanes; V] = std::array::from_fn(|c| unsafe {
            Lanes(_mm256_loadu_si256(filled.as_ptr().add(8 * c).cast()))
        });
        // SAFETY: AVX2, as the network's registers need.
        unsafe { super::network(&mut r) };
        for (c, lane) in r.iter().enumerate() {
            // SAFETY: 8 · V ≤ 64 lanes of `filled`.
            unsafe { _mm256_storeu_si256(filled.as_mut_ptr().add(8 * c).cast(), lane.0) };
        }
        values.copy_from_slice(&filled[..n]);
    }

    /// [`super::ranks`] of at most `8 · V` values (ties not checked).
    ///
    /// # Safety
    /// AVX2; `values.len() ≤ 8 · V ≤ 64`.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn ranks<const V: usize>(
        _: Avx2,
        values: &[u32],
        ranks: &mut [u32; 64],
    ) -> bool {
        let n = values.len();
        debug_assert!(n <= 8 * V && 8 * V <= 64);
        // AVX2 compares signed integers only: the sign bit flipped, they
        // order as the unsigned values do. Lanes past n are never read.
        let mut flipped = [0i32; 64];
        for (v, &b) in flipped.iter_mut().zip(values) {
            *v = (b ^ 1 << 31) as i32;
        }
        // SAFETY: 8 · V ≤ 64 lanes of `flipped`.
        let lanes: [__m256i; V] = std::array::from_fn(|c| unsafe {
            _mm256_loadu_si256(flipped.as_ptr().add(8 * c).cast())
        });
        let mut rank = [_mm256_setzero_si256(); V];
        for &v in &flipped[..n] {
            let v = _mm256_set1_epi32(v);
            for (rank, &lane) in rank.iter_mut().zip(&lanes) {
                // −1 where the lane's value is above v
                *rank = _mm256_sub_epi32(*rank, _mm256_cmpgt_epi32(lane, v));
            }
        }
        for (c, rank) in rank.iter().enumerate() {
            // SAFETY: 8 · V ≤ 64 lanes of `ranks`.
            unsafe { _mm256_storeu_si256(ranks.as_mut_ptr().add(8 * c).cast(), *rank) };
        }
        true
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::Run;
    use crate::simd::Avx512;

    /// Squared distances of the points from position `i` that `lanes`
    /// selects (the others read as zero).
    ///
    /// # Safety
    /// AVX-512F; the selected lanes lie within the run, whose axes are equally long.
    #[inline]
    #[target_feature(enable = "avx512f")]
    unsafe fn sixteen(q: [__m512; 3], run: Run, i: usize, lanes: __mmask16) -> __m512 {
        // SAFETY: masked loads touch only the selected lanes.
        let (x, y, z) = unsafe {
            (
                _mm512_maskz_loadu_ps(lanes, run.x.as_ptr().add(i)),
                _mm512_maskz_loadu_ps(lanes, run.y.as_ptr().add(i)),
                _mm512_maskz_loadu_ps(lanes, run.z.as_ptr().add(i)),
            )
        };
        let (dx, dy, dz) = (
            _mm512_sub_ps(q[0], x),
            _mm512_sub_ps(q[1], y),
            _mm512_sub_ps(q[2], z),
        );
        _mm512_add_ps(
            _mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)),
            _mm512_mul_ps(dz, dz),
        )
    }

    /// The lanes of a step from `i` that lie within `n`.
    fn lanes(i: usize, n: usize) -> __mmask16 {
        if n - i >= 16 {
            u16::MAX
        } else {
            (1u16 << (n - i)) - 1
        }
    }

    #[inline]
    #[target_feature(enable = "avx512f")]
    fn splat(q: [f32; 3]) -> [__m512; 3] {
        [
            _mm512_set1_ps(q[0]),
            _mm512_set1_ps(q[1]),
            _mm512_set1_ps(q[2]),
        ]
    }

    /// # Safety
    /// AVX-512F; equal axes; `payload` as long as the run when `PAYLOAD`.
    #[target_feature(enable = "avx512f,popcnt")]
    pub(super) unsafe fn keep<const PAYLOAD: bool>(
        _: Avx512,
        q: [f32; 3],
        run: Run,
        payload: &[u32],
        cap: f32,
        out: &mut Vec<u32>,
    ) {
        let n = run.x.len();
        let (qv, capv) = (splat(q), _mm512_set1_ps(cap));
        // Each step stores 16 lanes at the end and keeps some of them.
        out.reserve(n + 16);
        let base = out.len();
        let dst = out.as_mut_ptr();
        let (mut kept, mut i) = (0, 0);
        while i < n {
            let step = lanes(i, n);
            // SAFETY: loads masked to the run; the store lies within the
            // reserve (kept ≤ i < n).
            unsafe {
                let d = sixteen(qv, run, i, step);
                let within = _mm512_mask_cmp_ps_mask(step, d, capv, _CMP_LE_OQ);
                let lanes = if PAYLOAD {
                    _mm512_maskz_loadu_epi32(step, payload.as_ptr().add(i).cast())
                } else {
                    _mm512_castps_si512(d)
                };
                let packed = _mm512_maskz_compress_epi32(within, lanes);
                _mm512_storeu_si512(dst.add(base + kept).cast(), packed);
                kept += within.count_ones() as usize;
            }
            i += 16;
        }
        // SAFETY: the first `base + kept` are written.
        unsafe { out.set_len(base + kept) };
    }

    /// # Safety
    /// AVX-512F; equal axes, in the run and in the output.
    #[target_feature(enable = "avx512f,popcnt")]
    pub(super) unsafe fn keep_inside(
        _: Avx512,
        run: Run,
        lo: [f32; 3],
        hi: [f32; 3],
        out: [&mut Vec<f32>; 3],
    ) {
        let n = run.x.len();
        let (lov, hiv) = (splat(lo), splat(hi));
        let base = out[0].len();
        // Each step stores 16 lanes at the end of each axis and keeps some.
        let dst = out.map(|o| {
            o.reserve(n + 16);
            o
        });
        let (mut kept, mut i) = (0, 0);
        while i < n {
            let step = lanes(i, n);
            // SAFETY: loads masked to the run; the stores lie within the
            // reserve (kept ≤ i < n).
            unsafe {
                let v = [
                    _mm512_maskz_loadu_ps(step, run.x.as_ptr().add(i)),
                    _mm512_maskz_loadu_ps(step, run.y.as_ptr().add(i)),
                    _mm512_maskz_loadu_ps(step, run.z.as_ptr().add(i)),
                ];
                let mut inside = step;
                for a in 0..3 {
                    inside = _mm512_mask_cmp_ps_mask(inside, v[a], lov[a], _CMP_GE_OQ);
                    inside = _mm512_mask_cmp_ps_mask(inside, v[a], hiv[a], _CMP_LE_OQ);
                }
                for a in 0..3 {
                    let packed = _mm512_maskz_compress_ps(inside, v[a]);
                    _mm512_storeu_ps(dst[a].as_mut_ptr().add(base + kept), packed);
                }
                kept += inside.count_ones() as usize;
            }
            i += 16;
        }
        for o in dst {
            // SAFETY: the first `base + kept` are written.
            unsafe { o.set_len(base + kept) };
        }
    }

    /// # Safety
    /// AVX-512F; equal axes.
    #[target_feature(enable = "avx512f,popcnt")]
    pub(super) unsafe fn count(_: Avx512, q: [f32; 3], run: Run, cap: f32) -> usize {
        let n = run.x.len();
        let (qv, capv) = (splat(q), _mm512_set1_ps(cap));
        let (mut found, mut i) = (0, 0);
        while i < n {
            let step = lanes(i, n);
            // SAFETY: loads masked to the run.
            let d = unsafe { sixteen(qv, run, i, step) };
            found += _mm512_mask_cmp_ps_mask(step, d, capv, _CMP_LE_OQ).count_ones() as usize;
            i += 16;
        }
        found
    }
    /// A register type of AVX-512 for [`super::network`]: `$lanes` lanes
    /// of `$index` (the permutation's lane type), compared, permuted and
    /// picked by the instructions named.
    macro_rules! network_register {
        ($(#[$doc:meta])* $name:ident, $lanes:literal, $index:ty, $mask:ty,
         $min:ident, $max:ident, $permute:ident, $mov:ident) => {
            $(#[$doc])*
            #[derive(Clone, Copy)]
            pub(super) struct $name(__m512i);

            impl super::Network for $name {
                const LANES: usize = $lanes;
                #[inline(always)]
                unsafe fn min_max(a: Self, b: Self) -> (Self, Self) {
                    // SAFETY: the caller has AVX-512F.
                    unsafe { (Self($min(a.0, b.0)), Self($max(a.0, b.0))) }
                }
                #[inline(always)]
                unsafe fn partner(self, j: usize) -> Self {
                    let across: [$index; $lanes] = std::array::from_fn(|i| (i ^ j) as $index);
                    // SAFETY: the caller has AVX-512F; one register's bytes read.
                    unsafe {
                        let across = _mm512_loadu_si512(across.as_ptr().cast());
                        Self($permute(across, self.0))
                    }
                }
                #[inline(always)]
                unsafe fn pick(lo: Self, hi: Self, mask: u32) -> Self {
                    // SAFETY: the caller has AVX-512F.
                    unsafe { Self($mov(lo.0, mask as $mask, hi.0)) }
                }
            }
        };
    }

    network_register!(
        /// A register of 16 lanes of u32 for [`super::network`].
        Lanes, 16, i32, __mmask16,
        _mm512_min_epu32, _mm512_max_epu32, _mm512_permutexvar_epi32, _mm512_mask_mov_epi32
    );
    network_register!(
        /// A register of 8 lanes of u64 for [`super::network`].
        Wide, 8, i64, __mmask8,
        _mm512_min_epu64, _mm512_max_epu64, _mm512_permutexvar_epi64, _mm512_mask_mov_epi64
    );

    /// Puts the values at or below `pivot` first (in order), the rest
    /// after; returns how many are at or below.
    ///
    /// # Safety
    /// AVX-512F; `values.len() ≤ 128`.
    #[target_feature(enable = "avx512f,popcnt")]
    pub(super) unsafe fn split(_: Avx512, values: &mut [u32], pivot: u32) -> usize {
        let n = values.len();
        debug_assert!(n <= 128);
        let mut low = [std::mem::MaybeUninit::<u32>::uninit(); 144];
        let mut high = [std::mem::MaybeUninit::<u32>::uninit(); 144];
        let p = _mm512_set1_epi32(pivot as i32);
        let (mut a, mut b, mut i) = (0, 0, 0);
        while i < n {
            let present = lanes(i, n);
            // SAFETY: masked load within `values`; stores within the 144
            // (a, b ≤ i < 128).
            unsafe {
                let v = _mm512_maskz_loadu_epi32(present, values.as_ptr().add(i).cast());
                let below = _mm512_mask_cmple_epu32_mask(present, v, p);
                let above = present & !below;
                _mm512_storeu_si512(
                    low.as_mut_ptr().add(a).cast(),
                    _mm512_maskz_compress_epi32(below, v),
                );
                _mm512_storeu_si512(
                    high.as_mut_ptr().add(b).cast(),
                    _mm512_maskz_compress_epi32(above, v),
                );
                a += below.count_ones() as usize;
                b += above.count_ones() as usize;
            }
            i += 16;
        }
        // SAFETY: the first a of `low` and b of `high` are written.
        unsafe {
            std::ptr::copy_nonoverlapping(low.as_ptr().cast::<u32>(), values.as_mut_ptr(), a);
            std::ptr::copy_nonoverlapping(
                high.as_ptr().cast::<u32>(),
                values.as_mut_ptr().add(a),
                b,
            );
        }
        a
    }

    /// Sorts `values` (at most `16 · V`) ascending as unsigned integers by
    /// [`super::network`].
    ///
    /// # Safety
    /// AVX-512F; `values.len() ≤ 16 · V`, `V` one of 1, 2, 4, 8.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn sort<const V: usize>(_: Avx512, values: &mut [u32]) {
        let n = values.len();
        debug_assert!(n <= 16 * V && V.is_power_of_two() && V <= 8);
        let present: [__mmask16; V] = std::array::from_fn(|c| lanes((16 * c).min(n), n));
        let fill = _mm512_set1_epi32(-1);
        // SAFETY: masked loads touch only the lanes within `values`.
        let mut r: [Lanes; V] = std::array::from_fn(|c| unsafe {
            let at = values.as_ptr().add((16 * c).min(n));
            Lanes(_mm512_mask_loadu_epi32(fill, present[c], at.cast()))
        });
        // SAFETY: AVX-512F, as the network's registers need.
        unsafe { super::network(&mut r) };
        for (c, lane) in r.iter().enumerate() {
            // SAFETY: masked stores touch only the lanes within `values`.
            unsafe {
                let at = values.as_mut_ptr().add((16 * c).min(n));
                _mm512_mask_storeu_epi32(at.cast(), present[c], lane.0)
            };
        }
    }

    /// Sorts `values` (at most `8 · V`) ascending by [`super::network`].
    ///
    /// # Safety
    /// AVX-512F; `values.len() ≤ 8 · V`, `V` one of 1, 2, 4, 8, 16.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn sort_wide<const V: usize>(_: Avx512, values: &mut [u64]) {
        let n = values.len();
        debug_assert!(n <= 8 * V && V.is_power_of_two() && V <= 16);
        let present: [__mmask8; V] = std::array::from_fn(|c| {
            let left = n - (8 * c).min(n);
            if left >= 8 {
                u8::MAX
            } else {
                (1u8 << left) - 1
            }
        });
        let fill = _mm512_set1_epi64(-1);
        // SAFETY: masked loads touch only the lanes within `values`.
        let mut r: [Wide; V] = std::array::from_fn(|c| unsafe {
            let at = values.as_ptr().add((8 * c).min(n));
            Wide(_mm512_mask_loadu_epi64(fill, present[c], at.cast()))
        });
        // SAFETY: AVX-512F, as the network's registers need.
        unsafe { super::network(&mut r) };
        for (c, lane) in r.iter().enumerate() {
            // SAFETY: masked stores touch only the lanes within `values`.
            unsafe {
                let at = values.as_mut_ptr().add((8 * c).min(n));
                _mm512_mask_storeu_epi64(at.cast(), present[c], lane.0)
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (the crate's tests avoid a rand dependency here).
    fn runs(seed: u64) -> impl Iterator<Item = (Vec<f32>, Vec<f32>, Vec<f32>, [f32; 3], f32)> {
        let mut s = seed;
        let mut next = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        (0..400).map(move |t| {
            let n = t % 70;
            let scale = [1e-3f32, 1.0, 1e3, 1e30][t % 4];
            let mut axis = || (0..n).map(|_| next() * scale).collect::<Vec<f32>>();
            let (x, y, z) = (axis(), axis(), axis());
            let q = [next() * scale, next() * scale, next() * scale];
            // Caps from none kept to all, and exactly a point's distance.
            let cap = match t % 5 {
                0 => 0.0,
                1 => f32::INFINITY,
                2 if n > 0 => squared(q, x[0], y[0], z[0]),
                _ => (next().abs() * scale).powi(2),
            };
            (x, y, z, q, cap)
        })
    }

    #[test]
    fn every_path_keeps_and_counts_what_the_definition_does() {
        for isa in Isa::available() {
            for (x, y, z, q, cap) in runs(7) {
                let run = Run {
                    x: &x,
                    y: &y,
                    z: &z,
                };
                let payload: Vec<u32> = (0..x.len() as u32).map(|i| i * 3 + 1).collect();
                // The definition, independent of every path.
                let within: Vec<usize> = (0..x.len())
                    .filter(|&i| {
                        let (dx, dy, dz) = (q[0] - x[i], q[1] - y[i], q[2] - z[i]);
                        dx * dx + dy * dy + dz * dz <= cap
                    })
                    .collect();
                let bits: Vec<u32> = within
                    .iter()
                    .map(|&i| squared(q, x[i], y[i], z[i]).to_bits())
                    .collect();
                let ids: Vec<u32> = within.iter().map(|&i| payload[i]).collect();
                // Appended after what the buffer holds.
                let mut out = vec![99];
                keep_distances(isa, q, run, cap, &mut out);
                assert_eq!(out[0], 99, "{isa:?}");
                assert_eq!(out[1..], bits[..], "{isa:?} distances, {} points", x.len());
                let mut out = Vec::new();
                keep_payload(isa, q, run, &payload, cap, &mut out);
                assert_eq!(out, ids, "{isa:?} payload");
                assert_eq!(count(isa, q, run, cap), within.len(), "{isa:?} count");
            }
        }
    }

    #[test]
    fn every_path_keeps_the_points_inside_a_box_in_order() {
        for isa in Isa::available() {
            for (x, y, z, q, cap) in runs(11) {
                let run = Run {
                    x: &x,
                    y: &y,
                    z: &z,
                };
                // A box round q, and now and then one that is a point or empty.
                let w = cap.min(f32::MAX).sqrt();
                let (lo, hi) = match x.len() % 3 {
                    0 => (q.map(|v| v - w), q.map(|v| v + w)),
                    1 if !x.is_empty() => ([x[0], y[0], z[0]], [x[0], y[0], z[0]]),
                    _ => (q.map(|v| v + w), q.map(|v| v - w)),
                };
                let inside = |i: usize| {
                    [x[i], y[i], z[i]]
                        .iter()
                        .enumerate()
                        .all(|(a, &v)| lo[a] <= v && v <= hi[a])
                };
                let want: Vec<[f32; 3]> = (0..x.len())
                    .filter(|&i| inside(i))
                    .map(|i| [x[i], y[i], z[i]])
                    .collect();
                // Appended after what the buffers hold.
                let (mut ox, mut oy, mut oz) = (vec![7.0], vec![8.0], vec![9.0]);
                keep_inside(isa, run, lo, hi, [&mut ox, &mut oy, &mut oz]);
                let got: Vec<[f32; 3]> = (1..ox.len()).map(|i| [ox[i], oy[i], oz[i]]).collect();
                assert_eq!([ox[0], oy[0], oz[0]], [7.0, 8.0, 9.0], "{isa:?}");
                assert_eq!((ox.len(), oy.len()), (oz.len(), oz.len()), "{isa:?}");
                assert_eq!(got, want, "{isa:?}, {} points", x.len());
            }
        }
    }

    #[test]
    fn every_path_leaves_the_k_smallest_with_the_kth_last() {
        let mut next = crate::testing::below(3);
        for trial in 0..20_000 {
            let n = 1 + trial % 140;
            // Distances of every spread, ties (duplicates, zeros) among them
            // now and then, up to +∞.
            let spread = [3, 50, 1 << 20, 1 << 31][trial % 4];
            let bits: Vec<u32> = (0..n)
                .map(|_| match next(40) {
                    0 => 0,
                    1 => f32::INFINITY.to_bits(),
                    _ => (next(spread) as u32).min(f32::INFINITY.to_bits()),
                })
                .collect();
            let k = 1 + next(n as u64) as usize;
            let mut sorted = bits.clone();
            sorted.sort_unstable();
            // A pivot below, at or above the k-th, one of the values or not,
            // or none (0).
            let pivot = match trial % 5 {
                0 => 0,
                1 => sorted[k - 1],
                2 => sorted[(k + next(3) as usize).min(n - 1)],
                3 => sorted[k.saturating_sub(1 + next(4) as usize)].saturating_add(1),
                _ => next(spread) as u32,
            };
            for isa in Isa::available() {
                for near in [false, true] {
                    let mut got = bits.clone();
                    if near {
                        smallest_near(isa, &mut got, k, pivot);
                    } else {
                        smallest(isa, &mut got, k);
                    }
                    let how = if near { "smallest_near" } else { "smallest" };
                    assert_eq!(
                        got[k - 1],
                        sorted[k - 1],
                        "{isa:?} {how} the k-th last, {bits:?} k {k} pivot {pivot}"
                    );
                    let mut kept = got[..k].to_vec();
                    kept.sort_unstable();
                    assert_eq!(
                        kept,
                        sorted[..k],
                        "{isa:?} {how} the k smallest, {bits:?} k {k}"
                    );
                }
            }
        }
    }

    #[test]
    fn every_path_sorts_ids() {
        let mut next = crate::testing::below(5);
        for trial in 0..20_000 {
            let n = trial % 140;
            // Distinct mostly, ties now and then, values up to u32::MAX
            // (above 2³¹ the signed compares would misorder them).
            let spread = [5, 1000, 1 << 31, 1 << 32][trial % 4];
            let mut ids: Vec<u32> = (0..n).map(|_| next(spread) as u32).collect();
            if trial % 3 != 0 {
                ids.sort_unstable();
                ids.dedup();
                // a fixed shuffle
                for i in (1..ids.len()).rev() {
                    ids.swap(i, next(i as u64 + 1) as usize);
                }
            }
            let mut want = ids.clone();
            want.sort_unstable();
            for isa in Isa::available() {
                let mut got = ids.clone();
                sort_ids(isa, &mut got);
                assert_eq!(got, want, "{isa:?} {ids:?}");
            }
        }
    }

    #[test]
    fn every_path_sorts_wide_keys_or_declines() {
        let mut next = crate::testing::below(11);
        for trial in 0..20_000 {
            let n = trial % 140;
            // Keys of every spread up to u64::MAX, ties now and then.
            let spread = [5, 1 << 20, 1 << 40, u64::MAX][trial % 4];
            let keys: Vec<u64> = (0..n)
                .map(|_| match next(30) {
                    0 => u64::MAX,
                    _ => next(spread),
                })
                .collect();
            let mut want = keys.clone();
            want.sort_unstable();
            for isa in Isa::available() {
                let mut got = keys.clone();
                if sort_wide(isa, &mut got) {
                    assert_eq!(got, want, "{isa:?} {keys:?}");
                } else {
                    assert_eq!(got, keys, "{isa:?} declined, untouched");
                }
            }
        }
    }

    #[test]
    fn the_best_path_is_one_this_machine_runs() {
        assert!(Isa::available().contains(&Isa::best()));
    }
}
