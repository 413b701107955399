//! The instruction-set layer every vectorised kernel goes through:
//! detection (which paths this machine runs, found once), the choice of
//! one (`AUTOSHOVEL_ISA`), and the proofs that make a kernel's call safe.
//!
//! Why by hand: the kernels (`search::within`, the smoothing weights'
//! exponentials, the voxel grid's keys and tables, the statistical filter's
//! roots, the floor search in `autoshovel-terrain`) are written with
//! `core::arch` intrinsics, each path with its own instructions (a
//! compress, a permutation looked up by a mask) that no portable SIMD
//! crate offers on stable Rust; what they share is this choice.
//!
//! An [`Isa`] is made only here, by detection, so holding one that names
//! AVX2 or AVX-512 proves the machine runs it. A kernel file matches on
//! [`Isa::path`], whose arms carry zero-sized proofs ([`Avx2`],
//! [`Avx512`]) that its `#[target_feature]` functions take as their first
//! argument: an arm cannot call an AVX-512 kernel without the proof, and
//! the proof cannot be had on a machine without AVX-512F. What is left to
//! each call's `SAFETY:` comment is the kernel's own preconditions
//! (lengths, ranges). Every path gives the same bits (each kernel's tests
//! run every path [`Isa::available`] lists).

use std::sync::OnceLock;

/// An instruction set with a path of its own, as detected on this machine:
/// a value names only a path the machine runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Isa(Level);

/// The name of a path (for messages, benchmarks and matching).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// The target's baseline (SSE2 on x86-64).
    Portable,
    /// AVX2 (with POPCNT).
    Avx2,
    /// AVX-512F (with AVX2 and POPCNT).
    Avx512,
}

/// The path a kernel takes, with the proof of its instruction set.
#[derive(Debug, Clone, Copy)]
pub enum Path {
    /// The portable loop.
    Portable,
    /// AVX2 and POPCNT, proven.
    #[cfg(target_arch = "x86_64")]
    Avx2(Avx2),
    /// AVX-512F, AVX2 and POPCNT, proven.
    #[cfg(target_arch = "x86_64")]
    Avx512(Avx512),
}

/// Proof that this machine runs AVX2 and POPCNT (made only by detection).
#[derive(Debug, Clone, Copy)]
pub struct Avx2(());

/// Proof that this machine runs AVX-512F, AVX2 and POPCNT (made only by
/// detection).
#[derive(Debug, Clone, Copy)]
pub struct Avx512(());

impl Avx512 {
    /// Every AVX-512 machine the layer accepts also runs AVX2
    /// ([`Isa::available`] asks for both).
    #[inline]
    pub fn avx2(self) -> Avx2 {
        Avx2(())
    }
}

/// The environment variable that holds a run to a narrower path.
pub const ISA_VARIABLE: &str = "AUTOSHOVEL_ISA";

impl Isa {
    /// The portable path, which every machine runs.
    pub const PORTABLE: Isa = Isa(Level::Portable);

    /// The widest path this machine runs (found once), or a narrower one
    /// named by the environment variable `AUTOSHOVEL_ISA` (`portable`,
    /// `avx2`): to measure the paths side by side, or to rule one out. A
    /// name the machine does not run, or no name, gives the widest.
    pub fn best() -> Self {
        static BEST: OnceLock<Isa> = OnceLock::new();
        *BEST.get_or_init(|| {
            let all = Self::available();
            let widest = *all.last().expect("the portable path");
            let named = match std::env::var(ISA_VARIABLE).as_deref() {
                Ok("portable") => Some(Level::Portable),
                Ok("avx2") => Some(Level::Avx2),
                _ => None,
            };
            named
                .and_then(|level| all.iter().copied().find(|isa| isa.0 == level))
                .unwrap_or(widest)
        })
    }

    /// Every path this machine runs, the portable one first.
    pub fn available() -> Vec<Self> {
        static ALL: OnceLock<Vec<Isa>> = OnceLock::new();
        ALL.get_or_init(|| {
            let mut all = vec![Isa::PORTABLE];
            #[cfg(target_arch = "x86_64")]
            {
                // (every machine with AVX2 has POPCNT, which counts the
                // kept lanes: without it a count is a dozen dependent
                // instructions on the search loop's critical path; checked
                // all the same)
                let avx2 = std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("popcnt");
                if avx2 {
                    all.push(Isa(Level::Avx2));
                }
                // (every AVX-512 machine has AVX2; the other paths rely on it)
                if std::arch::is_x86_feature_detected!("avx512f") && avx2 {
                    all.push(Isa(Level::Avx512));
                }
            }
            all
        })
        .clone()
    }

    /// The path's name.
    pub fn level(self) -> Level {
        self.0
    }

    /// The path with its proof, for a kernel's dispatch.
    #[inline]
    pub fn path(self) -> Path {
        match self.0 {
            Level::Portable => Path::Portable,
            #[cfg(target_arch = "x86_64")]
            Level::Avx2 => Path::Avx2(Avx2(())),
            #[cfg(target_arch = "x86_64")]
            Level::Avx512 => Path::Avx512(Avx512(())),
            // An `Isa` names only what `available` found, and off x86-64
            // that is the portable path alone.
            #[cfg(not(target_arch = "x86_64"))]
            _ => Path::Portable,
        }
    }

    /// The proof of AVX2 where this path has it (AVX2 and AVX-512).
    #[inline]
    pub fn avx2(self) -> Option<Avx2> {
        match self.path() {
            #[cfg(target_arch = "x86_64")]
            Path::Avx2(t) => Some(t),
            #[cfg(target_arch = "x86_64")]
            Path::Avx512(t) => Some(t.avx2()),
            Path::Portable => None,
        }
    }

    /// The proof of AVX-512 where this path is AVX-512.
    #[inline]
    pub fn avx512(self) -> Option<Avx512> {
        match self.path() {
            #[cfg(target_arch = "x86_64")]
            Path::Avx512(t) => Some(t),
            _ => None,
        }
    }

    /// The path's name as `AUTOSHOVEL_ISA` spells it (`avx512` is never
    /// chosen by the variable: it is the default where the machine has it).
    pub fn name(self) -> &'static str {
        match self.0 {
            Level::Portable => "portable",
            Level::Avx2 => "avx2",
            Level::Avx512 => "avx512",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paths_are_the_detected_ones_widest_last() {
        let all = Isa::available();
        assert_eq!(all[0], Isa::PORTABLE);
        assert!(all.windows(2).all(|w| w[0].level() < w[1].level()));
        #[cfg(target_arch = "x86_64")]
        for isa in &all {
            match isa.level() {
                Level::Portable => assert!(isa.avx2().is_none()),
                Level::Avx2 => {
                    assert!(std::arch::is_x86_feature_detected!("avx2"));
                    assert!(isa.avx512().is_none());
                }
                Level::Avx512 => {
                    assert!(std::arch::is_x86_feature_detected!("avx512f"));
                    assert!(isa.avx2().is_some());
                }
            }
        }
        assert!(all.contains(&Isa::best()));
    }

    /// Prints the path `Isa::best` chose in this process (run alone by
    /// the test below, with `AUTOSHOVEL_ISA` set).
    #[test]
    fn report_the_chosen_path() {
        println!("chosen path: {}", Isa::best().name());
    }

    #[test]
    fn the_variable_holds_a_run_to_a_narrower_path() {
        let chosen = |value: &str| {
            let out = std::process::Command::new(std::env::current_exe().unwrap())
                .args([
                    "--exact",
                    "simd::tests::report_the_chosen_path",
                    "--nocapture",
                ])
                .env(ISA_VARIABLE, value)
                .output()
                .unwrap();
            let text = String::from_utf8_lossy(&out.stdout).into_owned();
            let at = text.find("chosen path: ").expect("the child's report") + 13;
            text[at..].split_whitespace().next().unwrap().to_string()
        };
        let all = Isa::available();
        let widest = all.last().unwrap().name();
        assert_eq!(chosen("portable"), "portable");
        let avx2 = if all.iter().any(|i| i.level() == Level::Avx2) {
            "avx2"
        } else {
            widest
        };
        assert_eq!(chosen("avx2"), avx2);
        assert_eq!(chosen("no-such-path"), widest);
        assert_eq!(chosen(""), widest);
    }
}
