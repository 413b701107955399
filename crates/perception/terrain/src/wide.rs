//! The floor search's passes over the points, eight a step on AVX-512
//! (`autoshovel_point_cloud::simd`): the distance of each point from a
//! plane, and the points kept by it packed by a compress instruction where
//! the portable loop stores every index and moves a count on by the test.
//! On a 100 k-point frame those stores were two fifths of the floor
//! search, the first frame's largest stage. Why by hand: the compiler
//! vectorises the distances but not the packing. Every distance is
//! computed as the portable path's `Plane::signed_distance` computes it
//! (the same products and sums in the same order, no fused multiply-add),
//! and the tests are the same comparisons, so both paths keep the same
//! points; the tests below compare them.

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512 {
    use std::arch::x86_64::*;

    use autoshovel_point_cloud::simd::Avx512;

    /// A plane n · p = d as (n, d), n of unit length (`ransac::Plane`'s
    /// normal and offset).
    pub(crate) type Coefficients = ([f64; 3], f64);

    /// The plane's coefficients, each in every lane.
    struct Lanes {
        n: [__m512d; 3],
        offset: __m512d,
    }

    impl Lanes {
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn of((normal, offset): Coefficients) -> Self {
            Self {
                n: normal.map(|v| _mm512_set1_pd(v)),
                offset: _mm512_set1_pd(offset),
            }
        }

        /// `Plane::signed_distance` of the eight points `xyz`, lane by lane.
        #[inline]
        #[target_feature(enable = "avx512f")]
        fn distance(&self, [x, y, z]: [__m512d; 3]) -> __m512d {
            let xy = _mm512_add_pd(_mm512_mul_pd(self.n[0], x), _mm512_mul_pd(self.n[1], y));
            _mm512_sub_pd(_mm512_add_pd(xy, _mm512_mul_pd(self.n[2], z)), self.offset)
        }
    }

    /// The x, y and z of eight points stored x, y, z one after another in
    /// `a`, `b`, `c` (24 values).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn columns(a: __m512d, b: __m512d, c: __m512d) -> [__m512d; 3] {
        // a = x0 y0 z0 x1 y1 z1 x2 y2, b = z2 x3 y3 z3 x4 y4 z4 x5,
        // c = y5 z5 x6 y6 z6 x7 y7 z7: each axis's lanes from a and b,
        // then the rest from c.
        [
            pick(
                [a, b, c],
                [0, 3, 6, 9, 12, 15, 0, 0],
                [0, 1, 2, 3, 4, 5, 10, 13],
            ),
            pick(
                [a, b, c],
                [1, 4, 7, 10, 13, 0, 0, 0],
                [0, 1, 2, 3, 4, 8, 11, 14],
            ),
            pick(
                [a, b, c],
                [2, 5, 8, 11, 14, 0, 0, 0],
                [0, 1, 2, 3, 4, 9, 12, 15],
            ),
        ]
    }

    /// The lanes `ab` of `a` and `b` (8 and on: `b`'s), then those lanes
    /// or, from 8 on, `c`'s, by `abc`.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn pick([a, b, c]: [__m512d; 3], ab: [i64; 8], abc: [i64; 8]) -> __m512d {
        let index = |l: [i64; 8]| _mm512_setr_epi64(l[0], l[1], l[2], l[3], l[4], l[5], l[6], l[7]);
        _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, index(ab), b), index(abc), c)
    }

    /// The indices `first`, `first + 1`, … `first + 7`.
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn indices(first: usize) -> __m512i {
        _mm512_add_epi64(
            _mm512_set1_epi64(first as i64),
            _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7),
        )
    }

    /// The lowest `n` bits (n ≤ 8).
    #[inline]
    fn low(n: usize) -> __mmask8 {
        ((1u16 << n) - 1) as __mmask8
    }

    /// The masks of a step of eight points from `i` of `n`: the points,
    /// and the three loads of their 24 coordinates.
    #[inline]
    fn step(i: usize, n: usize) -> (__mmask8, [__mmask8; 3]) {
        if n - i >= 8 {
            return (0xff, [0xff; 3]);
        }
        let values = 3 * (n - i);
        (
            low(n - i),
            [
                low(values.min(8)),
                low(values.saturating_sub(8).min(8)),
                low(values.saturating_sub(16)),
            ],
        )
    }

    /// `first + i` for each point `i` of `points` within `threshold` of
    /// `plane`, ascending (`ransac::inliers_from`'s portable loop).
    ///
    /// # Safety
    /// The machine has AVX-512F and POPCNT (the proof).
    #[target_feature(enable = "avx512f,popcnt")]
    pub(crate) unsafe fn inliers(
        _: Avx512,
        points: &[[f64; 3]],
        first: usize,
        plane: Coefficients,
        threshold: f64,
    ) -> Vec<usize> {
        let n = points.len();
        let lanes = Lanes::of(plane);
        let limit = _mm512_set1_pd(threshold);
        // Each step stores eight lanes at the end and keeps some of them.
        let mut out: Vec<usize> = Vec::with_capacity(n + 8);
        let dst = out.as_mut_ptr();
        let flat = points.as_ptr().cast::<f64>();
        let mut index = indices(first);
        let (mut kept, mut i) = (0, 0);
        while i < n {
            let (points, loads) = step(i, n);
            let p = flat.wrapping_add(3 * i);
            // SAFETY: the loads are masked to the points' values (a masked
            // lane is not read); the store lies within the capacity
            // (kept ≤ i < n, eight lanes).
            unsafe {
                let xyz = columns(
                    _mm512_maskz_loadu_pd(loads[0], p),
                    _mm512_maskz_loadu_pd(loads[1], p.wrapping_add(8)),
                    _mm512_maskz_loadu_pd(loads[2], p.wrapping_add(16)),
                );
                let d = _mm512_abs_pd(lanes.distance(xyz));
                let within = _mm512_mask_cmp_pd_mask::<_CMP_LE_OQ>(points, d, limit);
                let packed = _mm512_maskz_compress_epi64(within, index);
                _mm512_storeu_si512(dst.add(kept).cast(), packed);
                kept += within.count_ones() as usize;
            }
            index = _mm512_add_epi64(index, _mm512_set1_epi64(8));
            i += 8;
        }
        // SAFETY: the first `kept` are written.
        unsafe { out.set_len(kept) };
        out
    }

    /// What `floor::Split::of` makes of a part of the cloud (its points
    /// `points`, their cells `cells`, the first at index `first`): the
    /// points within `threshold` of `plane` (ascending), the cells of those
    /// above it by more than `threshold` and at most `rise`, and the count
    /// of those more than `below` under it.
    ///
    /// # Safety
    /// The machine has AVX-512F and POPCNT (the proof); `cells` is as long
    /// as `points`.
    #[target_feature(enable = "avx512f,popcnt")]
    pub(crate) unsafe fn split(
        _: Avx512,
        points: &[[f32; 3]],
        cells: &[u32],
        first: usize,
        plane: Coefficients,
        [threshold, rise, below]: [f64; 3],
    ) -> (Vec<usize>, Vec<u32>, usize) {
        let n = points.len();
        let lanes = Lanes::of(plane);
        let (limit, top, under) = (
            _mm512_set1_pd(threshold),
            _mm512_set1_pd(rise),
            _mm512_set1_pd(-below),
        );
        let mut inliers: Vec<usize> = Vec::with_capacity(n + 8);
        let dst = inliers.as_mut_ptr();
        let flat = points.as_ptr().cast::<f32>();
        let mut index = indices(first);
        let (mut kept, mut rising, mut count_below, mut i) = (0, Vec::new(), 0, 0);
        while i < n {
            let (points, loads) = step(i, n);
            let p = flat.wrapping_add(3 * i);
            // SAFETY: as in `inliers`; the 24 values are read as 16 and 8.
            unsafe {
                let front =
                    _mm512_maskz_loadu_ps(u16::from(loads[0]) | (u16::from(loads[1]) << 8), p);
                let back = _mm512_maskz_loadu_ps(u16::from(loads[2]), p.wrapping_add(16));
                let xyz = columns(
                    _mm512_cvtps_pd(_mm512_castps512_ps256(front)),
                    _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd::<1>(
                        _mm512_castps_pd(front),
                    ))),
                    _mm512_cvtps_pd(_mm512_castps512_ps256(back)),
                );
                let d = lanes.distance(xyz);
                let within = _mm512_mask_cmp_pd_mask::<_CMP_LE_OQ>(points, _mm512_abs_pd(d), limit);
                let packed = _mm512_maskz_compress_epi64(within, index);
                _mm512_storeu_si512(dst.add(kept).cast(), packed);
                kept += within.count_ones() as usize;
                let mut up = _mm512_mask_cmp_pd_mask::<_CMP_LE_OQ>(
                    _mm512_mask_cmp_pd_mask::<_CMP_GT_OQ>(points, d, limit),
                    d,
                    top,
                );
                while up != 0 {
                    rising.push(cells[i + up.trailing_zeros() as usize]);
                    up &= up - 1;
                }
                count_below +=
                    _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(points, d, under).count_ones() as usize;
            }
            index = _mm512_add_epi64(index, _mm512_set1_epi64(8));
            i += 8;
        }
        // SAFETY: the first `kept` are written.
        unsafe { inliers.set_len(kept) };
        (inliers, rising, count_below)
    }
}
