//! Large buffers on huge pages.
//!
//! A cloud of millions of points fills its buffers at random (a grid's
//! columns, a voxel's cells) or writes them fresh (a filter's output). On
//! 4 KiB pages the first costs a TLB miss almost every access once the
//! buffer is past the TLB's reach (about 12 MiB on a Zen 4 core), and the
//! second a page fault every 4 KiB. Linux backs an anonymous mapping with
//! 2 MiB pages when asked by `madvise(MADV_HUGEPAGE)` (transparent huge
//! pages in their default `madvise` mode), 512 times fewer of each; Rust's
//! standard library has no call for it, hence `libc`. Elsewhere, or where
//! the kernel declines, the buffer is an ordinary one: only the speed
//! differs, never a result.

/// Below this many bytes a buffer is left on ordinary pages: a 2 MiB page
/// must be zeroed whole, and the TLB holds a small buffer anyway.
pub const HUGE_FROM_BYTES: usize = 8 << 20;

/// An empty `Vec` with room for `capacity` elements, on huge pages where
/// the system gives them (see the module docs). Its memory is untouched:
/// write it before reading, as with [`Vec::with_capacity`].
pub fn vec_with_capacity<T>(capacity: usize) -> Vec<T> {
    let mut v = Vec::with_capacity(capacity);
    advise(&mut v);
    v
}

/// A `Vec` of `len` copies of `value` on huge pages where the system gives
/// them ([`vec_with_capacity`], then filled in parallel).
pub fn vec_filled<T: Copy + Send + Sync>(len: usize, value: T) -> Vec<T> {
    use rayon::prelude::*;
    let mut v = vec_with_capacity(len);
    v.spare_capacity_mut()
        .par_chunks_mut(1 << 16)
        .for_each(|c| c.iter_mut().for_each(|x| {
            x.write(value);
        }));
    // SAFETY: every element of the spare capacity, `len` of them, was
    // written just above.
    unsafe { v.set_len(len) };
    v
}

/// Asks the kernel to back the whole 2 MiB pages inside `v`'s allocation
/// with huge pages, when the allocation is at least [`HUGE_FROM_BYTES`].
#[cfg(target_os = "linux")]
fn advise<T>(v: &mut Vec<T>) {
    const HUGE: usize = 2 << 20;
    let bytes = v.capacity() * std::mem::size_of::<T>();
    if bytes < HUGE_FROM_BYTES {
        return;
    }
    let start = v.as_mut_ptr() as usize;
    let first = start.next_multiple_of(HUGE);
    let end = (start + bytes) / HUGE * HUGE;
    if end > first {
        // SAFETY: [first, end) lies inside the allocation `v` owns; the
        // advice changes how the kernel backs those pages, never their
        // contents, and a refusal (an error return) is harmless.
        unsafe {
            libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise<T>(_: &mut Vec<T>) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buffers_hold_what_is_written_at_every_size() {
        for len in [0usize, 1, 1000, (HUGE_FROM_BYTES / 4) + 12345] {
            let v = vec_filled(len, 7u32);
            assert_eq!(v.len(), len);
            assert!(v.iter().all(|&x| x == 7));
            let mut w: Vec<u64> = vec_with_capacity(len);
            assert!(w.capacity() >= len);
            w.extend((0..len as u64).map(|i| i * 3));
            assert!(w.iter().enumerate().all(|(i, &x)| x == i as u64 * 3));
        }
    }
}
