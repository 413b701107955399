//! The voxel of every point as one 32-bit key (its linear index in the
//! occupied box, x fastest), computed once for both of the voxel grid's
//! ways, 16 points a step on AVX-512. Why a pass of its own: computed
//! point by point inside the sorting way's filing, the index (PCL's f32
//! product, a floor and three i64 conversions, each checked) was a sixth
//! of the grid's time, and the tables' owners read it once each.

use std::mem::MaybeUninit;

use rayon::prelude::*;

use crate::filter::common::is_finite;
use crate::simd::{Isa, Path};
use crate::Point;

/// ⌊v⌋ of a finite `v` with |v| < 4e18, as `v.floor() as i64` gives it.
/// Why by hand: without SSE4.1 (the x86-64 baseline) `f32::floor` is a
/// call into libm, a tenth of the voxel grid's time; truncation and one
/// comparison are exact for every f32 in range.
#[inline(always)]
pub(super) fn floor_i64(v: f32) -> i64 {
    let t = v as i64;
    t - i64::from((t as f32) > v)
}

/// The voxel of a point as [`voxel_grid`](crate::filter::voxel_grid)
/// computes it (PCL's `floor(p · (1 / leaf))` in f32), for a caller that
/// must know which points share a voxel before calling it (a tile deciding
/// which voxels are its own); the voxel grid's keys are made from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VoxelCells {
    inv: [f32; 3],
}

impl VoxelCells {
    /// The cells of an inverse leaf, PCL's f32 (checked by the caller).
    pub(super) fn with_inverse(inv: [f32; 3]) -> Self {
        Self { inv }
    }

    /// The voxel (x, y, z indices) of the finite point `p`.
    #[inline]
    pub fn of(&self, p: &Point) -> [i64; 3] {
        [0, 1, 2].map(|a| floor_i64(p[a] * self.inv[a]))
    }
}

/// The key of a point with a non-finite coordinate (no voxel's: a box of
/// fewer than 2³² voxels).
pub(super) const NOT_FINITE: u32 = u32::MAX;

/// Bits of the key a [`Keys`] histogram counts by.
pub(super) const HISTOGRAM_BITS: u32 = 10;

/// Keys a run of the histogram's sample holds.
const SAMPLE: usize = 256;

/// One run of [`SAMPLE`] keys in this many is counted in the histogram
/// (a count a key was a tenth of the grid's time on a camera's scan).
const SAMPLE_EVERY: usize = 4;

/// What a visit to a voxel (a point of another voxel than the last
/// point's) costs the tables, in points: a new voxel's sums are
/// fetched (most of the cost in a part of many small voxels; measured on
/// PCL's RGB-D scans, 14.5 ns a visit against 1.9 ns a point).
const VISIT: usize = 8;

/// The lattice of voxels of one call of [`super::voxel_grid`].
#[derive(Debug, Clone, Copy)]
pub(super) struct Lattice {
    /// A point's cell (PCL's f32 product with the inverse leaf, floored).
    pub cells: VoxelCells,
    /// The least occupied cell per axis.
    pub lo: [i64; 3],
    /// Cells along x, and in an xy layer.
    pub ex: u64,
    pub exy: u64,
    /// Bits of the largest key (the keys are 32 bits for a box of fewer
    /// than 2³² voxels, which [`Lattice::keys`] is for).
    pub bits: u32,
    /// Every finite point's cells lie within i32 (−2³¹ ≤ ⌊v⌋ < 2³¹), so
    /// the vector path may compute them in 32 bits.
    pub cells_fit_i32: bool,
}

/// Every point's key, and what the tables decide by.
pub(super) struct Keys {
    /// A key a point, in input order ([`NOT_FINITE`] for a point with a
    /// non-finite coordinate).
    pub keys: Vec<u32>,
    /// The tables' cost by the key's top [`HISTOGRAM_BITS`] bits,
    /// from a sample of the keys: a point, and [`VISIT`] more where its
    /// voxel is not the last point's.
    pub histogram: Vec<usize>,
    /// Finite points in the histogram's sample, and how many of them
    /// visit another voxel than the point before.
    pub sampled: usize,
    pub visits: usize,
}

impl Lattice {
    /// The key of each point of `ps` written into `out` (as long), which
    /// it returns initialised.
    fn keys_into<'o>(&self, isa: Isa, ps: &[Point], out: &'o mut [MaybeUninit<u32>]) -> &'o [u32] {
        assert_eq!(ps.len(), out.len(), "a key a point");
        match isa.path() {
            // SAFETY: `t` proves AVX-512F; the cells of every finite point
            // fit i32; `out` is as long as `ps`.
            #[cfg(target_arch = "x86_64")]
            Path::Avx512(t) if self.cells_fit_i32 => unsafe { avx512::keys(t, self, ps, out) },
            _ => self.keys_portable(ps, out),
        }
        // SAFETY: both paths write every element of `out` (the vector
        // loop the whole steps of 16, `keys_portable` the rest), and
        // `MaybeUninit<u32>` has `u32`'s layout (the standard library's
        // `assume_init_ref` on slices, stable only from Rust 1.93).
        unsafe { &*(out as *const [MaybeUninit<u32>] as *const [u32]) }
    }

    /// The linear index of the voxel of a finite point of the box (x
    /// fastest, z slowest), for a box of at most 2⁶⁴ voxels.
    #[inline]
    pub(super) fn linear(&self, p: &Point) -> u64 {
        let cell = self.cells.of(p);
        let c: [u64; 3] = std::array::from_fn(|a| (cell[a] - self.lo[a]) as u64);
        c[0] + c[1] * self.ex + c[2] * self.exy
    }

    fn keys_portable(&self, ps: &[Point], out: &mut [MaybeUninit<u32>]) {
        for (p, key) in ps.iter().zip(out) {
            key.write(if is_finite(p) {
                self.linear(p) as u32
            } else {
                NOT_FINITE
            });
        }
    }

    /// The keys of `points` (every finite one in the box), in parallel.
    pub(super) fn keys(&self, points: &[Point], isa: Isa) -> Keys {
        const CHUNK: usize = 1 << 14;
        let shift = self.bits.saturating_sub(HISTOGRAM_BITS);
        let mut keys: Vec<u32> = crate::prefault::with_room(points.len());
        let room = &mut keys.spare_capacity_mut()[..points.len()];
        let bins = 1 << HISTOGRAM_BITS;
        let none = || (vec![0usize; bins], 0, 0);
        let (histogram, sampled, visits) = room
            .par_chunks_mut(CHUNK)
            .zip(points.par_chunks(CHUNK))
            .map(|(room, ps)| {
                let out = self.keys_into(isa, ps, room);
                let (mut histogram, mut sampled, mut visits) = none();
                for run in out.chunks(SAMPLE).step_by(SAMPLE_EVERY) {
                    let mut last = NOT_FINITE;
                    for &k in run.iter().filter(|&&k| k != NOT_FINITE) {
                        let visit = usize::from(k != last);
                        histogram[(k >> shift) as usize] += 1 + VISIT * visit;
                        sampled += 1;
                        visits += visit;
                        last = k;
                    }
                }
                (histogram, sampled, visits)
            })
            .reduce(none, |(mut a, sa, va), (b, sb, vb)| {
                a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
                (a, sa + sb, va + vb)
            });
        // SAFETY: every key was written above.
        unsafe { keys.set_len(points.len()) };
        Keys {
            keys,
            histogram,
            sampled,
            visits,
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::{Lattice, NOT_FINITE};
    use crate::Point;

    /// Lane l of axis a of 16 points (48 interleaved floats in three
    /// registers) is float 3l + a: from the first two registers where that
    /// is below 32 (these indices), else from the third ([`third`]).
    const fn first_two(a: usize) -> [i32; 16] {
        let mut idx = [0; 16];
        let mut l = 0;
        while l < 16 {
            let f = 3 * l + a;
            idx[l] = if f < 32 { f as i32 } else { 0 };
            l += 1;
        }
        idx
    }

    /// The indices into the third register, and the lanes that take them.
    const fn third(a: usize) -> ([i32; 16], u16) {
        let mut idx = [0; 16];
        let mut lanes = 0u16;
        let mut l = 0;
        while l < 16 {
            let f = 3 * l + a;
            if f >= 32 {
                idx[l] = (f - 32) as i32;
                lanes |= 1 << l;
            }
            l += 1;
        }
        (idx, lanes)
    }

    const FIRST_TWO: [[i32; 16]; 3] = [first_two(0), first_two(1), first_two(2)];
    const THIRD: [([i32; 16], u16); 3] = [third(0), third(1), third(2)];

    /// [`Lattice::keys_portable`], 16 points a step.
    ///
    /// # Safety
    /// AVX-512F (the proof); every finite point's cells fit i32.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn keys(
        _: crate::simd::Avx512,
        grid: &Lattice,
        ps: &[Point],
        out: &mut [std::mem::MaybeUninit<u32>],
    ) {
        assert_eq!(ps.len(), out.len());
        let whole = ps.len() / 16 * 16;
        let flat = ps.as_flattened();
        let inv = [
            _mm512_set1_ps(grid.cells.inv[0]),
            _mm512_set1_ps(grid.cells.inv[1]),
            _mm512_set1_ps(grid.cells.inv[2]),
        ];
        let lo = [
            _mm512_set1_epi32(grid.lo[0] as i32),
            _mm512_set1_epi32(grid.lo[1] as i32),
            _mm512_set1_epi32(grid.lo[2] as i32),
        ];
        let (ex, exy) = (
            _mm512_set1_epi32(grid.ex as u32 as i32),
            _mm512_set1_epi32(grid.exy as u32 as i32),
        );
        let infinity = _mm512_set1_ps(f32::INFINITY);
        // SAFETY: constant tables of 16 i32.
        let load = |i: &[i32; 16]| unsafe { _mm512_loadu_si512(i.as_ptr().cast()) };
        let first_two = [
            load(&FIRST_TWO[0]),
            load(&FIRST_TWO[1]),
            load(&FIRST_TWO[2]),
        ];
        let third = [
            (load(&THIRD[0].0), THIRD[0].1),
            (load(&THIRD[1].0), THIRD[1].1),
            (load(&THIRD[2].0), THIRD[2].1),
        ];
        for i in (0..whole).step_by(16) {
            // SAFETY: points i..i + 16 are in `ps`: 48 floats from 3i.
            let (r0, r1, r2) = unsafe {
                let at = flat.as_ptr().add(3 * i);
                (
                    _mm512_loadu_ps(at),
                    _mm512_loadu_ps(at.add(16)),
                    _mm512_loadu_ps(at.add(32)),
                )
            };
            let mut finite: __mmask16 = u16::MAX;
            let mut cell = [_mm512_setzero_si512(); 3];
            for a in 0..3 {
                let v = _mm512_castsi512_ps(_mm512_mask_permutexvar_epi32(
                    _mm512_castps_si512(_mm512_permutex2var_ps(r0, first_two[a], r1)),
                    third[a].1,
                    third[a].0,
                    _mm512_castps_si512(r2),
                ));
                finite &= _mm512_cmp_ps_mask::<_CMP_LT_OQ>(_mm512_abs_ps(v), infinity);
                // ⌊v · inv⌋: the scalar path's f32 product, floored exactly.
                let floor = _mm512_roundscale_ps::<{ _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC }>(
                    _mm512_mul_ps(v, inv[a]),
                );
                cell[a] = _mm512_sub_epi32(_mm512_cvttps_epi32(floor), lo[a]);
            }
            // The key is below 2³², so wrapping 32-bit arithmetic is exact.
            let key = _mm512_add_epi32(
                _mm512_add_epi32(cell[0], _mm512_mullo_epi32(cell[1], ex)),
                _mm512_mullo_epi32(cell[2], exy),
            );
            let key = _mm512_mask_mov_epi32(key, !finite, _mm512_set1_epi32(NOT_FINITE as i32));
            // SAFETY: `out` holds i..i + 16.
            unsafe { _mm512_storeu_si512(out.as_mut_ptr().add(i).cast(), key) };
        }
        grid.keys_portable(&ps[whole..], &mut out[whole..]);
    }
}

#[cfg(test)]
mod tests {
    use super::floor_i64;

    #[test]
    fn floor_by_hand_is_floor() {
        let mut v = vec![
            0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 2.5, -2.5, 1e-30, -1e-30, 3.9e18, -3.9e18,
        ];
        v.extend([
            8388607.5f32,
            -8388607.5,
            16777217.0,
            -16777217.0,
            0.99999994,
            -0.99999994,
        ]);
        let mut s = 1u64;
        for _ in 0..100_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = f32::from_bits((s >> 32) as u32);
            if x.is_finite() && x.abs() < 4.0e18 {
                v.push(x);
            }
        }
        for x in v {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x}");
        }
    }
}
