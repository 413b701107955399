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
/// Returns whether the kernel mapped them (false below [`FROM_BYTES`], off
/// Linux, or on a kernel without the call).
pub(crate) fn populate<T>(room: &mut [MaybeUninit<T>]) -> bool {
    let bytes = std::mem::size_of_val(room);
    if bytes < FROM_BYTES {
        return false;
    }
    #[cfg(target_os = "linux")]
    {
        let (first, end) = whole_pages(room.as_mut_ptr() as usize, bytes);
        if end > first {
            // SAFETY: [first, end) lies inside `room`, memory this process
            // owns and may write; MADV_POPULATE_WRITE only maps its pages
            // (as a write would, contents unchanged) and changes no data
            // the program can see. On an error (EINVAL before Linux 5.14)
            // nothing was changed, and the pages come by faults.
            let done = unsafe {
                libc::madvise(
                    first as *mut libc::c_void,
                    end - first,
                    libc::MADV_POPULATE_WRITE,
                )
            };
            return done == 0;
        }
    }
    false
}

/// Bytes in a page, the unit `madvise` works in.
#[cfg(target_os = "linux")]
const PAGE: usize = 4096;

/// The first and end addresses of the whole pages within `bytes` from
/// `start`.
#[cfg(target_os = "linux")]
fn whole_pages(start: usize, bytes: usize) -> (usize, usize) {
    (start.next_multiple_of(PAGE), (start + bytes) / PAGE * PAGE)
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

    #[cfg(target_os = "linux")]
    #[test]
    fn populated_pages_are_resident() {
        // 8 MB just mapped (beyond the allocator's reuse): none of it is
        // resident until written or populated.
        let n = 1 << 21;
        let mut v: Vec<u32> = Vec::with_capacity(n);
        let room = &mut v.spare_capacity_mut()[..n];
        let (first, end) = whole_pages(room.as_mut_ptr() as usize, n * 4);
        let resident = |first: usize, end: usize| {
            let mut flags = vec![0u8; (end - first) / PAGE];
            // SAFETY: [first, end) is page-aligned memory of this process
            // (inside `v`'s allocation) and `flags` has a byte a page.
            let r = unsafe {
                libc::mincore(first as *mut libc::c_void, end - first, flags.as_mut_ptr())
            };
            assert_eq!(r, 0);
            flags.iter().filter(|&&f| f & 1 == 1).count()
        };
        if populate(room) {
            assert_eq!(resident(first, end), (end - first) / PAGE);
        } else {
            eprintln!("this kernel has no MADV_POPULATE_WRITE: nothing to check");
        }
    }
}
