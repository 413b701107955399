//! The process's heap policy: memory a stage frees is kept for the next
//! stage, or the next frame, rather than handed back to the system.
//!
//! Each stage of `perceive` allocates its outputs afresh (a few MB a
//! 100 k-point frame, tens of MB a 1 M-point scan), and glibc's malloc
//! returns large blocks to the system when they are freed (`mmap`ed
//! blocks above a threshold that starts at 128 KiB, and a heap top above
//! twice that), so the next stage takes fresh pages, and a fresh page
//! costs a fault and a zeroing: on the benchmark machine 2.2 GB/s, some
//! 2 ms of a 30 ms frame (BENCHMARKS.md). Raising both thresholds keeps
//! that memory in the process for the next frame, as a live sensor's
//! pipeline keeps its buffers, without threading scratch buffers through
//! every library call. A process setting, so the binary's and not the
//! libraries' (a Python program sets its own; `GLIBC_TUNABLES` does the
//! same from outside); one the user has set with `GLIBC_TUNABLES` is left
//! as it is. Other platforms' allocators keep their own policies.

/// Blocks from this size on still come from `mmap` (and go back when
/// freed): the largest threshold glibc takes on 64-bit targets.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MMAP_FROM: i32 = 32 << 20;

/// Free memory at the heap's top beyond this goes back to the system.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const TRIM_ABOVE: i32 = 256 << 20;

/// Sets the policy (see the module docs); does nothing elsewhere than on
/// glibc, or where the user has set malloc tunables.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        let user_set = std::env::var("GLIBC_TUNABLES").is_ok_and(|t| t.contains("malloc."));
        if !user_set {
            // SAFETY: mallopt only changes the allocator's thresholds; it is
            // called before any thread of ours starts.
            unsafe {
                libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_FROM);
                libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_ABOVE);
            }
        }
    }
}
