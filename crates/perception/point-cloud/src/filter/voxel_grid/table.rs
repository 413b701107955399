//! The voxel grid's way for dense clouds (tens of points a voxel, as a
//! camera's or a terrestrial scanner's scan at a mine-scale leaf). The key
//! range is cut into one part a thread, each about as much work by the
//! keys' sampled histogram (a point, and more for a visit to another
//! voxel than the last point's); each thread picks out the points of its
//! own keys (a compress instruction on AVX-512) and sums them straight
//! into a hash table of its voxels, whose sums lie in the order the voxels
//! were met; its voxels are then put in key order and the parts joined.
//! The sorting way ([`super::bucketed_centroids`]) writes, gathers and
//! sorts a 16-byte entry a point; with 38 points a voxel (1.2 M points of
//! PCL's RGB-D scans) that was most of its time, where a table of 16 k
//! voxels a thread is little to sort (17–21 → 4.6–4.9 ms there,
//! BENCHMARKS.md).
//!
//! The bits are the sorting way's: a voxel belongs to one thread, which
//! sums its points in f64 in input order.
//!
//! Which way runs: this one, where the keys' sample holds at least
//! [`MIN_POINTS_PER_VISIT`] points a visit to a voxel (a scan's rows),
//! and a thread whose table holds more than one voxel for every
//! [`MIN_POINTS_PER_VOXEL`] points it took stops every thread; or, for a
//! cloud of [`ESTIMATE_FROM`] points or more without such runs (points in
//! random order), where an estimate of its voxels from a sample gives at
//! least [`MIN_POINTS_PER_VOXEL`] points a voxel, a thread stopping every
//! thread when its table holds more than one voxel for every
//! [`MIN_POINTS_PER_VOXEL`] of the points its part is estimated to hold
//! (by the histogram). Where the tables do
//! not run or stop, the sorting way runs (with the same keys). The
//! outputs are the same either way.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::keys::{Keys, HISTOGRAM_BITS};
use super::radix::{radix_sort_voxels, Voxel};
use crate::simd::{Isa, Path};
use crate::Point;

/// Fewest points a voxel a thread's table must hold on average, judged
/// every [`WINDOW`] points it takes, for this path to carry on. Measured
/// with the tables forced (BENCHMARKS.md): PCL's RGB-D scans (38 points a
/// voxel, 6.4 a visit) 4.1× quicker than sorting, the 5 M bench pile (32
/// a voxel, in random order) 1.6× quicker, the 1 M bench pile (9.3)
/// about as quick, a 1 M rosette scan (3.5) 2.2× slower, the 20 M bench
/// pile (65, in random order) 1.7× quicker. A cloud in random order
/// fills its voxels late, so it is not judged as it goes but on an
/// estimate of its voxels first ([`estimated_voxels`]).
const MIN_POINTS_PER_VOXEL: usize = 12;

/// Fewest points a visit to a voxel (a run of points of one voxel in
/// the input) the keys' sample must hold for this way to be tried: a
/// visit costs the tables about eight times a point, and a cloud of
/// short runs (a LiDAR's rosette or scan lines across a pile, points in
/// random order) is sorted more quickly, and is mostly too sparse for the
/// tables besides, which would only find that out after [`WINDOW`]
/// points (100 k-point frames of a rosette scan: the voxel stage 0.87–0.94
/// → 1.0–1.1 ms when they did). PCL's RGB-D scans hold 3.0–6.4.
const MIN_POINTS_PER_VISIT: usize = 2;

/// Points from which a cloud without runs of points a voxel has its
/// voxels estimated ([`estimated_voxels`]) and may take the tables:
/// below, the estimate's sort is a share of the grid's time (a 100
/// k-point frame's voxel stage is under a millisecond).
const ESTIMATE_FROM: usize = 1 << 20;

/// Keys the estimate of the voxels samples.
const ESTIMATE_SAMPLE: usize = 1 << 14;

/// How a thread judges its table as it goes.
#[derive(Debug, Clone, Copy)]
enum Judge {
    /// Too sparse where it holds more than one voxel for every
    /// [`MIN_POINTS_PER_VOXEL`] points taken (points in runs, which fill
    /// their voxels as they come).
    AsItGoes,
    /// Too sparse where it holds more voxels than this: one for every
    /// [`MIN_POINTS_PER_VOXEL`] of the points its part is estimated to
    /// hold (points in no order, whose voxels fill late).
    AtMost(usize),
}

/// The finite points of a cloud and its voxels, estimated from
/// [`ESTIMATE_SAMPLE`] keys evenly spaced through it, by Chao's estimator
/// (the distinct keys seen, and the singletons' count squared over twice
/// the doubletons'); `None` where the sample holds no finite point. It is
/// near for voxels about evenly filled, and a lower bound where they are
/// not: 79 k and 81 k voxels on the 5 M and 20 M bench piles, which have
/// 156 k and 308 k. A cloud it underrates is judged denser than it is;
/// the tables then run where sorting might have been as quick (the 1 M
/// pile, nine points a voxel: about as quick either way), and stop once
/// a thread holds a voxel for every twelve of its part's points
/// ([`Judge::AtMost`]), where sorting takes over.
fn estimated_voxels(keys: &[u32]) -> Option<(f64, f64)> {
    let step = (keys.len() / ESTIMATE_SAMPLE).max(1);
    let mut sample: Vec<u32> = keys
        .iter()
        .step_by(step)
        .copied()
        .filter(|&k| k != super::keys::NOT_FINITE)
        .collect();
    if sample.is_empty() {
        return None;
    }
    let finite = keys.len() as f64 * sample.len() as f64 / keys.len().div_ceil(step) as f64;
    sample.sort_unstable();
    let (mut distinct, mut once, mut twice) = (0.0, 0.0, 0.0);
    for run in sample.chunk_by(|a, b| a == b) {
        distinct += 1.0;
        match run.len() {
            1 => once += 1.0,
            2 => twice += 1.0,
            _ => {}
        }
    }
    let unseen = if twice > 0.0 {
        once * once / (2.0 * twice)
    } else {
        once * (once - 1.0) / 2.0
    };
    Some((finite, distinct + unseen))
}

/// Points a thread takes before the density is first judged.
const WINDOW: usize = 1 << 15;

/// Keys a thread reads at a time (below 2³²).
const BLOCK: usize = 1 << 12;

/// A table slot no voxel holds (no key of a box of fewer than 2³² voxels).
const EMPTY: u32 = u32::MAX;

/// A voxel of a thread's part, summed: its key, and x, y, z and the
/// count (exact in f64 below 2⁵³).
#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    key: u32,
    sum: [f64; 4],
}

impl Voxel for Slot {
    #[inline(always)]
    fn voxel(&self) -> u32 {
        self.key
    }
}

/// An open-addressed table of voxels (linear probing, at most half
/// full), holding for each voxel its place in `sums`, where voxels are
/// in the order they were first met: 32 bytes a voxel, neighbours in the
/// scan mostly neighbours there (a table of the sums themselves, half
/// empty, left the second-level cache at 30 k voxels: 4.2 → … ms for
/// that thread's part of PCL's RGB-D scans). `sums[0]` is no voxel's
/// ([`Table::SPARE`]).
struct Table {
    /// Per slot: a voxel's key and its place in `sums`, or [`EMPTY`].
    slots: Vec<(u32, u32)>,
    /// Per voxel: x, y, z and the count.
    sums: Vec<[f64; 4]>,
    /// Per voxel: its key.
    keys: Vec<u32>,
    bits: u32,
}

impl Table {
    /// The sums' place that no voxel has.
    const SPARE: usize = 0;

    fn new(bits: u32) -> Self {
        let mut sums = Vec::with_capacity(1 << (bits - 1));
        sums.push([0.0; 4]);
        Self {
            slots: vec![(EMPTY, 0); 1 << bits],
            sums,
            keys: vec![EMPTY],
            bits,
        }
    }

    /// The voxels held.
    fn held(&self) -> usize {
        self.keys.len() - 1
    }

    /// Where `key` is, or would be taken.
    #[inline(always)]
    fn probe(&self, key: u32) -> usize {
        let mask = self.slots.len() - 1;
        // Fibonacci hashing: neighbouring voxels land far apart.
        let mut at = (key.wrapping_mul(0x9E37_79B9) >> (32 - self.bits)) as usize;
        loop {
            let held = self.slots[at].0;
            if held == key || held == EMPTY {
                return at;
            }
            at = (at + 1) & mask;
        }
    }

    /// The place in `sums` of `key`'s voxel, taken for it if it has none.
    #[inline(always)]
    fn slot(&mut self, key: u32) -> usize {
        let at = self.probe(key);
        let (held, place) = self.slots[at];
        if held == key {
            place as usize
        } else {
            self.take(at, key)
        }
    }

    #[cold]
    #[inline(never)]
    fn take(&mut self, at: usize, key: u32) -> usize {
        let place = self.sums.len();
        self.slots[at] = (key, place as u32);
        self.sums.push([0.0; 4]);
        self.keys.push(key);
        if 2 * self.held() > self.slots.len() {
            self.bits += 1;
            self.slots = vec![(EMPTY, 0); 1 << self.bits];
            for (place, &key) in self.keys.iter().enumerate().skip(1) {
                let at = self.probe(key);
                self.slots[at] = (key, place as u32);
            }
        }
        place
    }

    /// Adds the points `ps[i]` at the positions `own` (ascending) to
    /// their voxels (keys `block[i]`), each voxel's in input order.
    fn add(&mut self, isa: Isa, block: &[u32], ps: &[Point], own: &[u32]) {
        match isa.avx2() {
            // SAFETY: `t` proves AVX2; `own` indexes `block` and `ps` (the
            // caller's positions of its own keys).
            #[cfg(target_arch = "x86_64")]
            Some(t) => unsafe { avx2::add(t, self, block, ps, own) },
            _ => self.add_portable(block, ps, own),
        }
    }

    /// [`Table::add`]: neighbouring points mostly share a voxel, so a run
    /// of them is summed in registers, in input order, then stored.
    fn add_portable(&mut self, block: &[u32], ps: &[Point], own: &[u32]) {
        let mut j = 0;
        while j < own.len() {
            let key = block[own[j] as usize];
            let at = self.slot(key);
            let mut sum = self.sums[at];
            while j < own.len() && block[own[j] as usize] == key {
                let p = ps[own[j] as usize];
                for a in 0..3 {
                    sum[a] += f64::from(p[a]);
                }
                sum[3] += 1.0;
                j += 1;
            }
            self.sums[at] = sum;
        }
    }
}

/// The centroids of the voxels with keys in `from..to`, in key order, or
/// `None` where they are too sparse or too many (or another thread found
/// its own so): then `stop` is set.
fn own_part(
    points: &[Point],
    keys: &[u32],
    (from, to): (u64, u64),
    bits: u32,
    isa: Isa,
    judge: Judge,
    stop: &AtomicBool,
) -> Option<Vec<Point>> {
    let mut table = Table::new(14);
    let span = to - from;
    let mut taken = 0;
    let mut judged = WINDOW;
    let mut own = [0u32; BLOCK];
    for (block, ps) in keys.chunks(BLOCK).zip(points.chunks(BLOCK)) {
        if stop.load(Ordering::Relaxed) {
            return None;
        }
        // This thread's points of the block, without a branch (which
        // mispredicted where the threads' voxels interleave).
        let held = owned(isa, block, (from as u32, span as u32), &mut own);
        table.add(isa, block, ps, &own[..held]);
        taken += held;
        if taken >= judged {
            judged = taken + WINDOW;
            let sparse = match judge {
                Judge::AsItGoes => table.held() * MIN_POINTS_PER_VOXEL > taken,
                Judge::AtMost(voxels) => table.held() > voxels,
            };
            if sparse {
                stop.store(true, Ordering::Relaxed);
                return None;
            }
        }
    }
    let mut slots: Vec<Slot> = (table.keys.iter().zip(&table.sums))
        .skip(1)
        .map(|(&key, &sum)| Slot { key, sum })
        .collect();
    let mut spare = vec![Slot::default(); slots.len()];
    let sorted = radix_sort_voxels(&mut slots, &mut spare, bits);
    Some(
        sorted
            .iter()
            .map(|s| [0, 1, 2].map(|a| (s.sum[a] / s.sum[3]) as f32))
            .collect(),
    )
}

/// The centroids of the occupied voxels in key order (those of
/// [`super::bucketed_centroids`], to the bit), or `None` where the cloud
/// is too sparse for this path. Keys are below 2^`bits` < 2³².
pub(super) fn centroids(points: &[Point], keys: &Keys, bits: u32, isa: Isa) -> Option<Vec<Point>> {
    // `Some(finite points)` where they are judged against the whole
    // count, `None` as they come.
    let finite = if keys.visits * MIN_POINTS_PER_VISIT <= keys.sampled {
        None
    } else if keys.keys.len() >= ESTIMATE_FROM {
        // Points in no order (a cloud shuffled, merged or gridded): their
        // voxels fill late, so the density is estimated first.
        let (finite, voxels) = estimated_voxels(&keys.keys)?;
        if finite < MIN_POINTS_PER_VOXEL as f64 * voxels {
            return None;
        }
        Some(finite)
    } else {
        return None;
    };
    let parts = rayon::current_num_threads();
    // Cut the key range where the histogram's running count passes each
    // part's share.
    let shift = bits.saturating_sub(HISTOGRAM_BITS);
    let total: usize = keys.histogram.iter().sum();
    // Every finite point's key is below 2^bits and below NOT_FINITE.
    let end = (1u64 << bits).min(u64::from(super::keys::NOT_FINITE));
    let mut cuts = vec![0u64];
    let mut running = 0;
    for (bin, &count) in keys.histogram.iter().enumerate() {
        running += count;
        let part = cuts.len();
        if part < parts && running * parts >= total * part {
            cuts.push(((bin as u64 + 1) << shift).min(end));
        }
    }
    cuts.push(end);
    cuts.dedup();
    let judge = |from: u64, to: u64| match finite {
        None => Judge::AsItGoes,
        Some(finite) => {
            // The part's share of the points, by the histogram's (a cloud
            // in no order visits a voxel at about every point, so its
            // bins weigh points alike).
            let bins = (from >> shift) as usize..((to + (1 << shift) - 1) >> shift) as usize;
            let share = keys.histogram[bins].iter().sum::<usize>() as f64 / total.max(1) as f64;
            Judge::AtMost((finite * share) as usize / MIN_POINTS_PER_VOXEL + WINDOW)
        }
    };
    let stop = AtomicBool::new(false);
    let out: Option<Vec<Vec<Point>>> = cuts
        .par_windows(2)
        .map(|w| {
            let judge = judge(w[0], w[1]);
            own_part(points, &keys.keys, (w[0], w[1]), bits, isa, judge, &stop)
        })
        .collect();
    Some(out?.concat())
}

/// The positions in `block` of the keys in `from..from + span` (wrapping
/// u32 arithmetic: `from + span` ≤ 2³² − 1, so [`NOT_FINITE`] is never
/// one), written to the front of `own`; returns how many.
fn owned(isa: Isa, block: &[u32], (from, span): (u32, u32), own: &mut [u32; BLOCK]) -> usize {
    match isa.path() {
        // SAFETY: `t` proves AVX-512F; `block` holds at most `BLOCK` keys
        // (asserted in the kernel).
        #[cfg(target_arch = "x86_64")]
        Path::Avx512(t) => unsafe { avx512::owned(t, block, from, span, own) },
        _ => {
            // Without a branch, which mispredicted where the threads'
            // voxels interleave.
            let mut held = 0;
            for (i, &key) in block.iter().enumerate() {
                own[held] = i as u32;
                held += usize::from(key.wrapping_sub(from) < span);
            }
            held
        }
    }
}

#[cfg(test)]
mod tests {
    use super::estimated_voxels;
    use crate::filter::voxel_grid::keys::NOT_FINITE;

    #[test]
    fn the_voxels_are_estimated_within_a_fifth() {
        // 2 M keys drawn at random from v voxels (a tenth of them not
        // finite): where the tables could pay (v up to a twelfth of the
        // points and beyond), the estimate is near v, and the finite
        // points near their count.
        let mut next = crate::testing::below(8);
        for v in [1_000u64, 20_000, 150_000, 500_000] {
            let keys: Vec<u32> = (0..2_000_000)
                .map(|_| {
                    if next(10) == 0 {
                        NOT_FINITE
                    } else {
                        (next(v) * 7) as u32
                    }
                })
                .collect();
            let finite = keys.iter().filter(|&&k| k != NOT_FINITE).count() as f64;
            let (f, got) = estimated_voxels(&keys).unwrap();
            assert!((got / v as f64 - 1.0).abs() < 0.2, "{v} voxels, {got}");
            assert!((f / finite - 1.0).abs() < 0.02, "{f} finite of {finite}");
        }
        assert_eq!(estimated_voxels(&[NOT_FINITE; 100]), None);
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::BLOCK;

    /// [`super::owned`], 16 keys a step, the positions packed by a
    /// compress instruction.
    ///
    /// # Safety
    /// AVX-512F; `block` at most [`BLOCK`] keys.
    #[target_feature(enable = "avx512f,popcnt")]
    pub(super) unsafe fn owned(
        _: crate::simd::Avx512,
        block: &[u32],
        from: u32,
        span: u32,
        own: &mut [u32; BLOCK],
    ) -> usize {
        assert!(block.len() <= BLOCK);
        let (from, span) = (
            _mm512_set1_epi32(from as i32),
            _mm512_set1_epi32(span as i32),
        );
        let step = _mm512_set1_epi32(16);
        let mut at = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
        let mut held = 0;
        for chunk in block.chunks(16) {
            let lanes: __mmask16 = if chunk.len() == 16 {
                u16::MAX
            } else {
                (1 << chunk.len()) - 1
            };
            // SAFETY: the masked lanes lie in `chunk`; `own` has room for
            // every key of the block.
            unsafe {
                let key = _mm512_maskz_loadu_epi32(lanes, chunk.as_ptr().cast());
                let mine = lanes & _mm512_cmplt_epu32_mask(_mm512_sub_epi32(key, from), span);
                _mm512_mask_compressstoreu_epi32(own.as_mut_ptr().add(held).cast(), mine, at);
                held += mine.count_ones() as usize;
            }
            at = _mm512_add_epi32(at, step);
        }
        held
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::Table;
    use crate::Point;

    /// [`Table::add`] without a branch on where a run of points of one
    /// voxel ends (a misprediction at the end of every run was most of the
    /// time on a camera's scan, 3.8 points a run): a point's slot is
    /// found, the running sum (x, y, z, count in one register) is taken
    /// from that slot unless it is the last point's, the point is added,
    /// and the sum is stored back to its slot, every point. Where the slot
    /// is the last point's, the load reads the spare slot instead, so the
    /// sum's chain of additions never waits on its own store.
    ///
    /// # Safety
    /// AVX2; `own` indexes `block` and `ps`.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn add(
        _: crate::simd::Avx2,
        table: &mut Table,
        block: &[u32],
        ps: &[Point],
        own: &[u32],
    ) {
        // `Table::slot`'s probe, with the table's fields in registers (the
        // stores below could alias them), read again after a voxel is
        // taken: calling `Table::slot` here was 6–16 % slower (`kinect5`
        // 4.9–5.0 → 5.3–5.5 ms, the 5 M pile 50–51 → 55–59 ms).
        let mut slots = table.slots.as_ptr();
        let mut mask = table.slots.len() - 1;
        let mut shift = 32 - table.bits;
        let mut sums = table.sums.as_mut_ptr();
        let count = _mm256_setr_pd(0.0, 0.0, 0.0, 1.0);
        let mut last = Table::SPARE;
        let mut sum = _mm256_setzero_pd();
        for &i in own {
            // SAFETY: `own` indexes `block` and `ps`; slots are read
            // within the table (masked), sums at places it gave.
            unsafe {
                let key = *block.get_unchecked(i as usize);
                let p = ps.get_unchecked(i as usize).as_ptr();
                let mut at = (key.wrapping_mul(0x9E37_79B9) >> shift) as usize;
                let place = loop {
                    let (held, place) = *slots.add(at);
                    if held == key {
                        break place as usize;
                    }
                    if held == super::EMPTY {
                        let place = table.take(at, key);
                        slots = table.slots.as_ptr();
                        mask = table.slots.len() - 1;
                        shift = 32 - table.bits;
                        sums = table.sums.as_mut_ptr();
                        break place;
                    }
                    at = (at + 1) & mask;
                };
                let same = place == last;
                let from = if same { Table::SPARE } else { place };
                let stored = _mm256_loadu_pd(sums.add(from).cast());
                let keep = _mm256_castsi256_pd(_mm256_set1_epi64x(-(same as i64)));
                sum = _mm256_blendv_pd(stored, sum, keep);
                // x, y, z (the fourth lane masked off: the last point may
                // end the cloud), and 1 for the count.
                let xyz = _mm_maskload_ps(p, _mm_setr_epi32(-1, -1, -1, 0));
                let point = _mm256_blend_pd::<0b1000>(_mm256_cvtps_pd(xyz), count);
                sum = _mm256_add_pd(sum, point);
                _mm256_storeu_pd(sums.add(place).cast(), sum);
                last = place;
            }
        }
    }
}
