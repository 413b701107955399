//! Room for large outputs, with its pages mapped in one call.
//!
//! A filter's output at millions of points is fresh memory: the allocator
//! maps it anew for each call, and the kernel then takes one page fault for
//! each 4 KiB the filter first writes. On the project's 2-core VMs that is
//! 2.2–2.7 GB/s, whatever the number of threads (the faults share one lock),
//! and it was most of the pass-through filter's time at 5 M points.
//! `madvise(MADV_POPULATE_WRITE)` (Linux 5.14) maps the same pages in one
//! call, without a trap a page: a 60 MB buffer written in 23 ms after
//! faults, 15 ms after populating it in pieces of 384 KiB. Why by hand: no
//! allocator crate offers it; the standard library's `Vec` stays the owner.
//!
//! Not huge pages: with `defrag = madvise` the kernel may compact memory to
//! find them, which made whole runs slower on a loaded machine (BENCHMARKS.md).

use std::mem::MaybeUninit;

/// Bytes from which [`populate`] asks the kernel (16 pages): below it, a
/// system call saves little over the faults.
const FROM_BYTES: usize = 1 << 16;

/// Maps the pages of `room` for writing, in one call, where the kernel
/// offers it (Linux 5.14 and later); elsewhere, or on a refusal, it does
/// nothing and the pages come by faults as usual. Only the whole pages inside
/// `room` are asked for. The contents stay as they were (uninitialised).
pub(crate) fn populate<T>(room: &mut [MaybeUninit<T>]) {
    let bytes = std::mem::size_of_val(room);
    if bytes < FROM_BYTES {
        return;
    }
    #[cfg(target_os = "linux")]
    {
        const PAGE: usize = 4096;
        let start = room.as_mut_ptr() as usize;
        let first = start.next_multiple_of(PAGE);
        let end = (start + bytes) / PAGE * PAGE;
        if end > first {
            // SAFETY: [first, end) lies inside `room`, memory this process
            // owns and may write; MADV_POPULATE_WRITE only maps its pages
            // (as a write would, contents unchanged) and changes no data
            // the program can see. Its result is only a hint's: on an error
            // (EINVAL before Linux 5.14) nothing was changed.
            unsafe {
                libc::madvise(
                    first as *mut libc::c_void,
                    end - first,
                    libc::MADV_POPULATE_WRITE,
                );
            }
        }
    }
}

/// Room for `n` values of `T`, its pages mapped by [`populate`]: the
/// capacity of the vector returned, which is empty.
pub(crate) fn with_room<T>(n: usize) -> Vec<T> {
    let mut v = Vec::with_capacity(n);
    populate(&mut v.spare_capacity_mut()[..n]);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn populated_room_is_ordinary_room() {
        // Large enough to be populated, and misaligned to pages on purpose.
        for n in [0, 10, 300_001, 1 << 20] {
            let mut v: Vec<u32> = with_room(n);
            assert!(v.capacity() >= n && v.is_empty());
            v.extend((0..n as u32).map(|i| i.wrapping_mul(2_654_435_761)));
            assert!(v
                .iter()
                .enumerate()
                .all(|(i, &x)| x == (i as u32).wrapping_mul(2_654_435_761)));
            let mut u: Vec<u8> = Vec::with_capacity(n + 3);
            populate(&mut u.spare_capacity_mut()[1..]);
            u.resize(n, 7);
            assert!(u.iter().all(|&b| b == 7));
        }
    }
}
