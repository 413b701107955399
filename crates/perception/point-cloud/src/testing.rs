//! Seeded generators for the tests' clouds (an LCG): the same seed gives
//! the same cloud on every machine, without a dependency.

#![cfg(test)]

/// A seeded uniform generator on [0, 1) (an LCG, 24 bits) for the tests'
/// clouds: the same seed gives the same cloud on every machine.
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// A seeded generator of integers below `m` (the same LCG, its top 31
/// bits) for the tests: the same seed gives the same draws everywhere.
pub(crate) fn below(seed: u64) -> impl FnMut(u64) -> u64 {
    let mut s = seed;
    move |m| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 33) % m
    }
}
