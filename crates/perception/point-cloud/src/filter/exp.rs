//! e^x for many x at once: the weights of bilateral smoothing ([RS eq.
//! 19]), a few dozen exponentials a point.
//!
//! Why written by hand: libm's `exp` is a call a value (about 5 ns here,
//! a sixth of the smoothing stage), `std::simd` is not stable, and the
//! vector `exp` of the `wide` crate follows the build's target features,
//! which for a binary that runs on every x86-64 are SSE2's: slower than
//! libm (6.5 against 5 ns, measured). Here the same steps run on four
//! (AVX2) or eight (AVX-512) values an instruction, chosen at run time as
//! in `search::within`, or one at a time elsewhere: Cody and Waite's reduction
//! x = k·ln 2 + r (ln 2 in two parts, fdlibm's), e^r by its Taylor series to
//! r¹³ (|r| ≤ ln 2 / 2: the terms left out are below 10⁻¹⁷), and 2^k as
//! two powers of two built from their exponent bits (so that e^x below
//! 2⁻¹⁰²² rounds once, to a subnormal or zero). Every step is one IEEE 754
//! addition or multiplication, no fused multiply-add, in the same order on
//! every path: the same bits everywhere (the tests hold each path to the
//! scalar one, and all to libm within 2⁻⁵¹ relative).

use crate::simd::{Isa, Path};

/// Rounds to an integer by adding and taking away 1.5 · 2⁵².
const ROUND: f64 = 6_755_399_441_055_744.0;
/// 2⁵² + 1023: added to an integer m, the low bits of the sum are m + 1023,
/// the exponent field of 2^m once shifted up by 52 bits.
const POW2: f64 = 4_503_599_627_371_519.0;
const LOG2_E: f64 = std::f64::consts::LOG2_E;
/// ln 2 = LN2_HI + LN2_LO, LN2_HI with its low 32 bits zero (fdlibm's
/// `ln2HI` and `ln2LO`, 6.93147180369123816490e-01 and
/// 1.90821492927058770002e-10, by their bits).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// Below e^LOW every result is zero, above e^HIGH infinite: x is clamped
/// into [LOW, HIGH] first.
const LOW: f64 = -746.0;
const HIGH: f64 = 710.0;
/// 1/n! for n = 13 down to 2.
const TAYLOR: [f64; 12] = [
    1.0 / 6_227_020_800.0,
    1.0 / 479_001_600.0,
    1.0 / 39_916_800.0,
    1.0 / 3_628_800.0,
    1.0 / 362_880.0,
    1.0 / 40_320.0,
    1.0 / 5_040.0,
    1.0 / 720.0,
    1.0 / 120.0,
    1.0 / 24.0,
    1.0 / 6.0,
    1.0 / 2.0,
];

/// Replaces each of `x` (finite or infinite, not NaN) by e^x.
pub(super) fn exp_in_place(isa: Isa, x: &mut [f64]) {
    let mut chunks = x.chunks_exact_mut(8);
    match isa.path() {
        #[cfg(target_arch = "x86_64")]
        Path::Avx512(t) => {
            for c in &mut chunks {
                // SAFETY: `t` proves AVX-512F, the kernel's one requirement.
                unsafe { avx512::exp8(t, c.try_into().expect("8 values")) };
            }
        }
        #[cfg(target_arch = "x86_64")]
        Path::Avx2(t) => {
            for c in &mut chunks {
                for half in c.chunks_exact_mut(4) {
                    // SAFETY: `t` proves AVX2, the kernel's one requirement.
                    unsafe { avx2::exp4(t, half.try_into().expect("4 values")) };
                }
            }
        }
        Path::Portable => {
            for v in chunks.by_ref().flatten() {
                *v = exp(*v);
            }
        }
    }
    for v in chunks.into_remainder() {
        *v = exp(*v);
    }
}

/// e^x, one value, by the steps of the vector paths.
fn exp(x: f64) -> f64 {
    // As MAXPD and MINPD: the second operand unless the first is beyond it.
    let x = if x > LOW { x } else { LOW };
    let x = if x < HIGH { x } else { HIGH };
    let k = (x * LOG2_E + ROUND) - ROUND;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let mut p = TAYLOR[0];
    for c in &TAYLOR[1..] {
        p = p * r + c;
    }
    let p = (p * r + 1.0) * r + 1.0;
    // 2^k as 2^k1 · 2^k2, k1 = ⌊k / 2⌋ (rounded to nearest from k/2 − 1/4).
    let k1 = ((k * 0.5 - 0.25) + ROUND) - ROUND;
    let k2 = k - k1;
    let pow2 = |m: f64| f64::from_bits((m + POW2).to_bits() << 52);
    p * pow2(k1) * pow2(k2)
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use std::arch::x86_64::*;

    use super::*;

    /// # Safety
    /// AVX2.
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn exp4(_: crate::simd::Avx2, x: &mut [f64; 4]) {
        let s = _mm256_set1_pd;
        // SAFETY: four values.
        let v = unsafe { _mm256_loadu_pd(x.as_ptr()) };
        let v = _mm256_max_pd(v, s(LOW));
        let v = _mm256_min_pd(v, s(HIGH));
        let k = _mm256_sub_pd(
            _mm256_add_pd(_mm256_mul_pd(v, s(LOG2_E)), s(ROUND)),
            s(ROUND),
        );
        let r = _mm256_sub_pd(
            _mm256_sub_pd(v, _mm256_mul_pd(k, s(LN2_HI))),
            _mm256_mul_pd(k, s(LN2_LO)),
        );
        let mut p = s(TAYLOR[0]);
        for &c in &TAYLOR[1..] {
            p = _mm256_add_pd(_mm256_mul_pd(p, r), s(c));
        }
        let p = _mm256_add_pd(_mm256_mul_pd(p, r), s(1.0));
        let p = _mm256_add_pd(_mm256_mul_pd(p, r), s(1.0));
        let half = _mm256_sub_pd(_mm256_mul_pd(k, s(0.5)), s(0.25));
        let k1 = _mm256_sub_pd(_mm256_add_pd(half, s(ROUND)), s(ROUND));
        let k2 = _mm256_sub_pd(k, k1);
        let pow2 = |m: __m256d| {
            _mm256_castsi256_pd(_mm256_slli_epi64::<52>(_mm256_castpd_si256(_mm256_add_pd(
                m,
                s(POW2),
            ))))
        };
        let e = _mm256_mul_pd(_mm256_mul_pd(p, pow2(k1)), pow2(k2));
        // SAFETY: four values.
        unsafe { _mm256_storeu_pd(x.as_mut_ptr(), e) };
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    use super::*;

    /// # Safety
    /// AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn exp8(_: crate::simd::Avx512, x: &mut [f64; 8]) {
        let s = _mm512_set1_pd;
        // SAFETY: eight values.
        let v = unsafe { _mm512_loadu_pd(x.as_ptr()) };
        let v = _mm512_max_pd(v, s(LOW));
        let v = _mm512_min_pd(v, s(HIGH));
        let k = _mm512_sub_pd(
            _mm512_add_pd(_mm512_mul_pd(v, s(LOG2_E)), s(ROUND)),
            s(ROUND),
        );
        let r = _mm512_sub_pd(
            _mm512_sub_pd(v, _mm512_mul_pd(k, s(LN2_HI))),
            _mm512_mul_pd(k, s(LN2_LO)),
        );
        let mut p = s(TAYLOR[0]);
        for &c in &TAYLOR[1..] {
            p = _mm512_add_pd(_mm512_mul_pd(p, r), s(c));
        }
        let p = _mm512_add_pd(_mm512_mul_pd(p, r), s(1.0));
        let p = _mm512_add_pd(_mm512_mul_pd(p, r), s(1.0));
        let half = _mm512_sub_pd(_mm512_mul_pd(k, s(0.5)), s(0.25));
        let k1 = _mm512_sub_pd(_mm512_add_pd(half, s(ROUND)), s(ROUND));
        let k2 = _mm512_sub_pd(k, k1);
        let pow2 = |m: __m512d| {
            _mm512_castsi512_pd(_mm512_slli_epi64::<52>(_mm512_castpd_si512(_mm512_add_pd(
                m,
                s(POW2),
            ))))
        };
        let e = _mm512_mul_pd(_mm512_mul_pd(p, pow2(k1)), pow2(k2));
        // SAFETY: eight values.
        unsafe { _mm512_storeu_pd(x.as_mut_ptr(), e) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values() -> Vec<f64> {
        let mut s = 17u64;
        let mut v: Vec<f64> = (0..100_000)
            .map(|i| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (s >> 11) as f64 / (1u64 << 53) as f64;
                match i % 4 {
                    0 => -60.0 * u,
                    1 => -750.0 * u,
                    2 => 1420.0 * u - 710.0,
                    _ => 2.0 * u - 1.0,
                }
            })
            .collect();
        v.extend([
            0.0,
            -0.0,
            1.0,
            -1.0,
            709.7,
            709.79,
            710.0,
            1e6,
            -708.3,
            -708.5,
            -744.0,
            -745.2,
            -746.0,
            -1e6,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e-300,
            -1e-17,
        ]);
        v
    }

    #[test]
    fn every_path_gives_the_scalar_bits_and_libm_within_two_ulps() {
        let x = values();
        let scalar: Vec<f64> = x.iter().map(|&v| exp(v)).collect();
        for (&v, &e) in x.iter().zip(&scalar) {
            let want = v.exp();
            if want == 0.0 || want.is_infinite() {
                assert_eq!(e, want, "e^{v}");
            } else if want < f64::MIN_POSITIVE {
                // Subnormal: within one unit of the last place there.
                assert!(
                    (e - want).abs() <= 4.9e-324 * 1.0001,
                    "e^{v}: {e} against {want}"
                );
            } else {
                assert!(
                    ((e - want) / want).abs() <= 2.0 * f64::EPSILON,
                    "e^{v}: {e} against {want}"
                );
            }
        }
        for isa in Isa::available() {
            let mut got = x.clone();
            exp_in_place(isa, &mut got);
            for ((g, s), v) in got.iter().zip(&scalar).zip(&x) {
                assert_eq!(g.to_bits(), s.to_bits(), "{isa:?} e^{v}");
            }
        }
    }
}
