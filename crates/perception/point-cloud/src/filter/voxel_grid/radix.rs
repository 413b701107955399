//! The stable radix sort by voxel index shared by the voxel grid's two
//! ways (a sorting way's entries, a table's voxels).

/// What [`radix_sort_voxels`] sorts by: a voxel's linear index.
pub(super) trait Voxel: Copy {
    fn voxel(&self) -> u32;
}

/// Bits of a digit of [`radix_sort_voxels`]: its counts (8 KiB) stay in
/// the first-level cache, and 22 bits take two passes.
const DIGIT_BITS: u32 = 11;

/// Sorts `entries` by the low `bits` bits of their voxel index: a stable
/// least-significant-digit radix sort on digits of [`DIGIT_BITS`], every
/// digit counted in one pass first (a digit all entries share is passed
/// over), so each voxel's points keep their order. `spare` (as long as
/// `entries`) is scratch; returns whichever of the two holds the sorted
/// entries.
#[inline]
pub(super) fn radix_sort_voxels<'a, T: Voxel>(
    mut entries: &'a mut [T],
    mut spare: &'a mut [T],
    bits: u32,
) -> &'a [T] {
    const DIGITS: usize = 1 << DIGIT_BITS;
    const MAX_PASSES: usize = 32_usize.div_ceil(DIGIT_BITS as usize);
    let passes = bits.div_ceil(DIGIT_BITS) as usize;
    let mut count = [[0u32; DIGITS]; MAX_PASSES];
    let digit = |e: &T, pass: usize| {
        ((e.voxel() >> (pass as u32 * DIGIT_BITS)) & (DIGITS as u32 - 1)) as usize
    };
    for e in entries.iter() {
        for (pass, c) in count.iter_mut().enumerate().take(passes) {
            c[digit(e, pass)] += 1;
        }
    }
    for (pass, c) in count.iter_mut().enumerate().take(passes) {
        if c.iter().any(|&k| k as usize == entries.len()) {
            continue;
        }
        // Counts to starts.
        let mut at = 0;
        for k in c.iter_mut() {
            let n = *k;
            *k = at;
            at += n;
        }
        for e in entries.iter() {
            let slot = &mut c[digit(e, pass)];
            spare[*slot as usize] = *e;
            *slot += 1;
        }
        std::mem::swap(&mut entries, &mut spare);
    }
    entries
}

#[cfg(test)]
mod tests {
    use super::{radix_sort_voxels, Voxel};

    /// A voxel index and the entry's place in the input.
    #[derive(Debug, Clone, Copy, Default, PartialEq)]
    struct Marked {
        voxel: u32,
        place: usize,
    }

    impl Voxel for Marked {
        fn voxel(&self) -> u32 {
            self.voxel
        }
    }

    #[test]
    fn radix_sort_orders_voxels_and_keeps_each_voxels_entries_in_order() {
        let mut next = crate::testing::below(9);
        for trial in 0..2_000 {
            let bits = 1 + (trial % 31) as u32;
            let n = next(300) as usize;
            // Voxels at random below 2^bits (from few distinct to all
            // different), each entry marked with its place in the input.
            let spread = 1 + next(1 << bits);
            let mut entries: Vec<Marked> = (0..n)
                .map(|place| Marked {
                    voxel: next(spread) as u32,
                    place,
                })
                .collect();
            let mut want = entries.clone();
            want.sort_by_key(|e| e.voxel);
            let mut spare = vec![Marked::default(); n];
            let sorted = radix_sort_voxels(&mut entries, &mut spare, bits);
            assert!(sorted == want, "bits {bits}, {n} entries");
        }
    }
}
