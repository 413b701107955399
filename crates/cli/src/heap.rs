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
//!
//! The first frame still took fresh pages: 3.0–8.2 ms more than the same
//! 100 k-point frame perceived again (medians of eight or ten runs,
//! BENCHMARKS.md), most of it on the thread pool's threads, each of which
//! glibc gives an arena of its own. [`warm`] maps that memory before the first frame, as a real-time
//! program's start-up touches its heap before the work begins.

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
        if policy_set() {
            // SAFETY: mallopt only changes the allocator's thresholds; it is
            // called before any thread of ours starts.
            unsafe {
                libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_FROM);
                libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_ABOVE);
            }
        }
    }
}

/// Per thread, bytes [`warm`] maps for each byte of a frame's file.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const WARM_PER_BYTE: usize = 12;

/// Per thread, the least and most [`warm`] maps.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const WARM_BYTES: (usize, usize) = (32 << 20, 512 << 20);

/// Whether [`keep_freed_memory`] set the policy (glibc, and no malloc
/// tunables of the user's).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn policy_set() -> bool {
    !std::env::var("GLIBC_TUNABLES").is_ok_and(|t| t.contains("malloc."))
}

/// Before a sequence of frames whose files are about `frame_bytes` each:
/// maps heap on this thread and on each of the thread pool's (12 bytes for
/// each byte of a frame, 32–512 MiB a thread), in pieces of 1 MiB, then
/// frees it. With the policy of [`keep_freed_memory`] it stays in each
/// thread's arena, so the first frame finds its pages mapped as the frames
/// after it do (a 100 k-point frame: 3.0–8.2 → 0.2–0.4 ms more than the
/// same frame again). Does nothing where the policy is not set.
pub fn warm(frame_bytes: u64) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        if !policy_set() {
            return;
        }
        const PIECE: usize = 1 << 20;
        let bytes = usize::try_from(frame_bytes)
            .unwrap_or(usize::MAX)
            .saturating_mul(WARM_PER_BYTE)
            .clamp(WARM_BYTES.0, WARM_BYTES.1);
        // Written, not zeroed: a zeroed block of fresh memory is not
        // touched (the allocator knows it is zero already).
        let touch = || {
            let pieces: Vec<Vec<u8>> = (0..bytes / PIECE).map(|_| vec![1u8; PIECE]).collect();
            std::hint::black_box(&pieces);
        };
        touch();
        rayon::broadcast(|_| touch());
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = frame_bytes;
}
