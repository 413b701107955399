//! The process's settings a front end chooses for its jobs: its heap
//! policy and, for a live sensor's frames, its scheduling.
//!
//! **Heap.** Memory a stage frees is kept for the next stage, or the next
//! frame, rather than handed back to the system.
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
//! every library call. A process setting, so the front end's to call, once,
//! first thing (the binary does; a Python program sets its own, and
//! `GLIBC_TUNABLES` does the same from outside); one the user has set with
//! `GLIBC_TUNABLES` is left as it is. Other platforms' allocators keep
//! their own policies.
//!
//! The first frame still took fresh pages: 3.0–8.2 ms more than the same
//! 100 k-point frame perceived again (medians of eight or ten runs,
//! BENCHMARKS.md), most of it on the thread pool's threads, each of which
//! glibc gives an arena of its own. [`warm`] maps that memory before the
//! first frame (`perceive_frames` calls it), as a real-time program's
//! start-up touches its heap before the work begins.
//!
//! **Scheduling** for a live sensor's frames ([`realtime`], `perceive
//! --realtime`). On a machine shared with other work a frame's parallel stages wait
//! whenever another task takes one of the pool's cores: on the 2-core
//! benchmark machine 200 frames had a 99th percentile of 27.1 ms and a
//! largest of 30.8 ms against a median of 18.5, where the same run under
//! `SCHED_FIFO` had 20.9 and 22.1 ms (BENCHMARKS.md). A sensor pipeline
//! on Linux runs so (as `chrt -f`, or ROS 2's real-time executors do):
//! ordinary tasks then wait for it, and the kernel's real-time throttling
//! (`sched_rt_runtime_us`, 95 % by default) still leaves them a share.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::{JobError, Result};

/// Blocks from this size on still come from `mmap` (and go back when
/// freed): the largest threshold glibc takes on 64-bit targets.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MMAP_FROM: i32 = 32 << 20;

/// Free memory at the heap's top beyond this goes back to the system.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const TRIM_ABOVE: i32 = 256 << 20;

/// Whether [`keep_freed_memory`] set the policy.
static KEPT: AtomicBool = AtomicBool::new(false);

/// Sets the heap policy (see the module docs), to be called before any
/// thread starts; does nothing elsewhere than on glibc, or where the user
/// has set malloc tunables.
pub fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        let user_set = std::env::var("GLIBC_TUNABLES").is_ok_and(|t| t.contains("malloc."));
        if !user_set {
            // SAFETY: mallopt only changes the allocator's thresholds; the
            // caller calls it before any thread of its starts.
            unsafe {
                libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_FROM);
                libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_ABOVE);
            }
            KEPT.store(true, Ordering::Relaxed);
        }
    }
}

/// Per thread, bytes [`warm`] maps for each byte of a frame's file.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const WARM_PER_BYTE: usize = 12;

/// Per thread, the least and most [`warm`] maps.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const WARM_BYTES: (usize, usize) = (32 << 20, 512 << 20);

/// Before a sequence of frames whose files are about `frame_bytes` each:
/// maps heap on this thread and on each of the thread pool's (12 bytes for
/// each byte of a frame, 32–512 MiB a thread), in pieces of 1 MiB, then
/// frees it. With the policy of [`keep_freed_memory`] it stays in each
/// thread's arena, so the first frame finds its pages mapped as the frames
/// after it do (a 100 k-point frame: 3.0–8.2 → 0.2–0.4 ms more than the
/// same frame again). Does nothing unless [`keep_freed_memory`] set the
/// policy: the memory would go straight back.
pub fn warm(frame_bytes: u64) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        if !KEPT.load(Ordering::Relaxed) {
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

/// The highest `SCHED_FIFO` priority Linux takes.
const MAX_PRIORITY: u8 = 99;

/// Runs this thread and every thread of the pool under `SCHED_FIFO` at
/// `priority` (1–99); the reason the system gave when it refuses (no
/// `CAP_SYS_NICE`, a real-time priority limit of 0), with what to do.
/// Returns the number of threads set.
pub fn realtime(priority: u8) -> Result<usize> {
    let refused = |problem: String| JobError::Realtime { priority, problem };
    if !(1..=MAX_PRIORITY).contains(&priority) {
        return Err(refused(format!(
            "expected a SCHED_FIFO priority from 1 to {MAX_PRIORITY}"
        )));
    }
    #[cfg(target_os = "linux")]
    {
        let set = || -> std::io::Result<()> {
            // SAFETY: a zeroed sched_param is valid (its other fields, on
            // the C libraries that have them, unused by SCHED_FIFO).
            let mut param: libc::sched_param = unsafe { std::mem::zeroed() };
            param.sched_priority = i32::from(priority);
            // SAFETY: pid 0 names the calling thread; `param` lives across
            // the call, which only reads it.
            match unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) } {
                0 => Ok(()),
                _ => Err(std::io::Error::last_os_error()),
            }
        };
        let system = |e: std::io::Error| {
            refused(format!(
                "the system refused real-time scheduling (SCHED_FIFO): {e}; run as root, give the \
                 binary CAP_SYS_NICE (setcap cap_sys_nice+ep), or raise the real-time priority \
                 limit (ulimit -r, /etc/security/limits.conf)"
            ))
        };
        set().map_err(system)?;
        for got in rayon::broadcast(|_| set()) {
            got.map_err(system)?;
        }
        Ok(1 + rayon::current_num_threads())
    }
    #[cfg(not(target_os = "linux"))]
    Err(refused("real-time scheduling is set on Linux only".into()))
}
