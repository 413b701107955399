//! Real-time scheduling for a live sensor's frames (`perceive --realtime`).
//!
//! On a machine shared with other work a frame's parallel stages wait
//! whenever another task takes one of the pool's cores: on the 2-core
//! benchmark machine 200 frames had a 99th percentile of 27.1 ms and a
//! largest of 30.8 ms against a median of 18.5, where the same run under
//! `SCHED_FIFO` had 20.9 and 22.1 ms (BENCHMARKS.md). A sensor pipeline
//! on Linux runs so (as `chrt -f`, or ROS 2's real-time executors do):
//! ordinary tasks then wait for it, and the kernel's real-time throttling
//! (`sched_rt_runtime_us`, 95 % by default) still leaves them a share. A
//! process setting, so the binary's, like its heap policy (`heap`).

use anyhow::{bail, Result};

/// The highest `SCHED_FIFO` priority Linux takes.
const MAX_PRIORITY: u8 = 99;

/// Runs this thread and every thread of the pool under `SCHED_FIFO` at
/// `priority` (1–99); the reason the system gave when it refuses (no
/// `CAP_SYS_NICE`, a real-time priority limit of 0), with what to do.
/// Returns the number of threads set.
pub fn realtime(priority: u8) -> Result<usize> {
    if !(1..=MAX_PRIORITY).contains(&priority) {
        bail!("--realtime {priority}: expected a SCHED_FIFO priority from 1 to {MAX_PRIORITY}");
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
        let refused = |e: std::io::Error| {
            anyhow::anyhow!(
                "--realtime {priority}: the system refused real-time scheduling (SCHED_FIFO): {e}; \
                 run as root, give the binary CAP_SYS_NICE (setcap cap_sys_nice+ep), or raise the \
                 real-time priority limit (ulimit -r, /etc/security/limits.conf)"
            )
        };
        set().map_err(refused)?;
        for got in rayon::broadcast(|_| set()) {
            got.map_err(refused)?;
        }
        Ok(1 + rayon::current_num_threads())
    }
    #[cfg(not(target_os = "linux"))]
    bail!("--realtime {priority}: real-time scheduling is set on Linux only")
}
