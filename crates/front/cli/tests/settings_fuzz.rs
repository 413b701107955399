//! Issue 11: property "fuzzers" for every settings file the program reads —
//! plan-path and track scenarios, excavator scenarios and machine profiles,
//! rope-shovel profiles, perception settings, warm-start packs and shift
//! scenarios. Each case
//! starts from a built-in file, puts hostile values in one to three of its
//! settings (zero, negatives, 1e308, NaN, infinities, huge integers, wrong
//! types, extra coordinates), drops lines or cuts the text, then reads it
//! and runs the job on it with the libraries, as the command would.
//!
//! The property: an error, or a result within the stated bounds — never a
//! panic, and never one allocation beyond [`ALLOCATION_BOUND`] (the global
//! allocator below refuses larger ones, which aborts the test binary).
//! `PROPTEST_CASES=N` runs more cases (the record of longer runs is in
//! docs/robustness.md).

use std::alloc::{GlobalAlloc, Layout, System};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use autoshovel_core::config::TomlFile;
use proptest::prelude::*;

/// Largest single allocation a settings file may cause (bytes): above the
/// biggest the stated work ceilings allow (the excavator's 10⁶ simulator
/// samples, about 180 MB in one vector).
const ALLOCATION_BOUND: usize = 512 << 20;

struct Bounded;

static LARGEST: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards every call unchanged to the system allocator, or
// refuses one past the bound with a null pointer, as `GlobalAlloc` allows.
unsafe impl GlobalAlloc for Bounded {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        note(l.size());
        if l.size() > 2 * ALLOCATION_BOUND {
            return std::ptr::null_mut();
        }
        // SAFETY: same contract as our caller's.
        unsafe { System.alloc(l) }
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        note(l.size());
        if l.size() > 2 * ALLOCATION_BOUND {
            return std::ptr::null_mut();
        }
        // SAFETY: same contract as our caller's.
        unsafe { System.alloc_zeroed(l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        note(new);
        if new > 2 * ALLOCATION_BOUND {
            return std::ptr::null_mut();
        }
        // SAFETY: same contract as our caller's.
        unsafe { System.realloc(p, l, new) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: same contract as our caller's.
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static ALLOC: Bounded = Bounded;

fn note(n: usize) {
    LARGEST.fetch_max(n, Ordering::Relaxed);
}

/// One case at a time: the largest-allocation record is process-wide.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Runs `job` on one mutated file: no panic, no allocation past the bound.
fn holds(what: &str, text: &str, job: impl FnOnce() -> Result<(), String>) {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    LARGEST.store(0, Ordering::Relaxed);
    let outcome = catch_unwind(AssertUnwindSafe(job));
    let largest = LARGEST.load(Ordering::Relaxed);
    assert!(outcome.is_ok(), "{what}: panicked on\n{text}");
    assert!(
        largest <= ALLOCATION_BOUND,
        "{what}: allocated {largest} bytes at once on\n{text}"
    );
}

/// Values a hostile user puts in a setting.
const HOSTILE: &[&str] = &[
    "0",
    "-1",
    "-0.0",
    "1e-300",
    "1e-9",
    "1e-3",
    "0.5",
    "2",
    "1e3",
    "1e9",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "4294967296",
    "9223372036854775807",
    "\"x\"",
    "\"\"",
    "true",
    "[]",
    "[1.0, 2.0, 3.0]",
    "[[0.0, 0.0, 0.0]]",
    "{ a = 1 }",
];

/// How one file is damaged.
#[derive(Debug, Clone)]
enum Edit {
    /// Set the value of the `i`-th `key = value` line (mod their number).
    Value(usize, &'static str),
    /// Drop the `i`-th line (mod the number of lines).
    Drop(usize),
}

fn edits() -> impl Strategy<Value = (Vec<Edit>, Option<usize>)> {
    let edit = prop_oneof![
        6 => (any::<usize>(), prop::sample::select(HOSTILE)).prop_map(|(i, v)| Edit::Value(i, v)),
        1 => any::<usize>().prop_map(Edit::Drop),
    ];
    (
        prop::collection::vec(edit, 1..4),
        prop::option::weighted(0.1, any::<usize>()),
    )
}

/// `text` with `edits` applied and, when `cut` is set, cut at that byte
/// (mod its length, on a character boundary).
fn damage(text: &str, (edits, cut): &(Vec<Edit>, Option<usize>)) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for e in edits {
        match *e {
            Edit::Value(i, v) => {
                let keyed: Vec<usize> = (0..lines.len())
                    .filter(|&k| {
                        let l = lines[k].trim_start();
                        !l.starts_with('#') && !l.starts_with('[') && l.contains('=')
                    })
                    .collect();
                if keyed.is_empty() {
                    continue;
                }
                let k = keyed[i % keyed.len()];
                let key = lines[k].split('=').next().unwrap_or("").to_string();
                lines[k] = format!("{key}= {v}");
            }
            Edit::Drop(i) => {
                if !lines.is_empty() {
                    let k = i % lines.len();
                    lines.remove(k);
                }
            }
        }
    }
    let mut out = lines.join("\n");
    out.push('\n');
    if let Some(c) = cut {
        let mut at = c % out.len().max(1);
        while !out.is_char_boundary(at) {
            at -= 1;
        }
        out.truncate(at);
    }
    out
}

/// A cheap optimiser budget: the property is about the settings, not the
/// search.
fn small_dig_setup(
    profile: autoshovel_rope_shovel_dig::MachineProfile,
) -> autoshovel_rope_shovel_dig::DigSetup {
    let mut s = autoshovel_rope_shovel_dig::DigSetup::new(profile, "fuzzed", 1);
    s.gwo.population = 6;
    s.gwo.iterations = 3;
    s.gwo.parallel = false;
    s
}

fn small_pile() -> autoshovel_point_cloud::PointCloud {
    use autoshovel_terrain::{generate_pile, PileParams};
    generate_pile(&PileParams {
        points: 3_000,
        ..PileParams::default()
    })
    .expect("the built-in pile")
}

/// Cases per file kind: `PROPTEST_CASES`, 48 by default (CI).
fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(48)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn plan_path_scenarios(which in 0usize..5, e in edits()) {
        use autoshovel_walk_planner::{FieldKind, PlanOutcome, Scenario};
        let names = autoshovel_walk_planner::scenario::builtin_names();
        let base = autoshovel_walk_planner::scenario::builtin_text(names[which % names.len()]).unwrap();
        let text = damage(base, &e);
        holds("plan-path scenario", &text, || {
            let s = Scenario::from_toml(&text, "fuzz.toml").map_err(|e| e.to_string())?;
            let _ = PlanOutcome::plan(&s, FieldKind::Improved);
            Ok(())
        });
    }

    #[test]
    fn track_scenarios(which in 0usize..2, e in edits()) {
        use autoshovel_walk_tracker::scenario::{builtin_text, from_toml};
        use autoshovel_walk_tracker::ControllerKind;
        let base = builtin_text(["fig9a", "fig9b"][which]).unwrap();
        // The controller tables are optional: give them so they are damaged too.
        let base = format!("{base}\n[controller.fuzzy]\nalpha = 0.3\nk1 = 2.42\n[controller.pid]\nkp = 800.0\n[sim]\nplant_dt_s = 0.001\ncontrol_rate_hz = 10.0\n");
        let text = damage(&base, &e);
        holds("track scenario", &text, || {
            let s = from_toml(&text, "fuzz.toml", None, 1).map_err(|e| e.to_string())?;
            let _ = autoshovel_walk_tracker::job::track(&s, ControllerKind::Fuzzy, false);
            Ok(())
        });
    }

    #[test]
    fn excavator_scenarios_and_profiles(which in 0usize..3, on_profile in any::<bool>(), e in edits()) {
        use autoshovel_excavator_dig::{excavate, MachineProfile, Scenario};
        let names = Scenario::builtin_names();
        let scenario = Scenario::builtin_toml(names[which]).unwrap();
        let profile = autoshovel_excavator_dig::profile::EXCAVATOR_15T_TOML;
        let (s_text, p_text) = if on_profile {
            (scenario.to_string(), damage(profile, &e))
        } else {
            (damage(scenario, &e), profile.to_string())
        };
        holds("excavator scenario/profile", &format!("{s_text}\n---\n{p_text}"), || {
            let s = Scenario::from_toml(&s_text, "s.toml").map_err(|e| e.to_string())?;
            let p = MachineProfile::from_toml(&p_text, "p.toml").map_err(|e| e.to_string())?;
            if let Ok(ex) = excavate(&s, &p) {
                // The simulator's stated ceiling holds.
                assert!(ex.samples.len() as f64 <= autoshovel_excavator_dig::scenario::MAX_SIM_STEPS + 1.0);
            }
            Ok(())
        });
    }

    #[test]
    fn shift_scenarios(e in edits()) {
        use autoshovel_work_shift::{run_shift, ShiftOptions, ShiftScenario};
        let text = damage(autoshovel_work_shift::scenario::BENCH_TOML, &e);
        holds("shift scenario", &text, || {
            let s = ShiftScenario::from_toml(&text, "s.toml").map_err(|e| e.to_string())?;
            let options = ShiftOptions { cycles: Some(1), ..ShiftOptions::default() };
            if let Ok(run) = run_shift(&s, &autoshovel_rope_shovel_dig::MachineProfile::scale_model(), &options, &mut |_| {}) {
                // One pass at most, and the pit's loss is what the trucks got.
                assert!(run.summary.passes <= 1);
                assert!(run.summary.mass_balance.closes, "{:?}", run.summary.mass_balance);
            }
            Ok(())
        });
    }

    #[test]
    fn rope_shovel_profiles(e in edits()) {
        use autoshovel_rope_shovel_dig::{plan_pile, MachineProfile, Pile};
        use autoshovel_terrain::PileShape;
        let text = damage(autoshovel_rope_shovel_dig::profile::SCALE_MODEL_TOML, &e);
        holds("rope-shovel profile", &text, || {
            let p = MachineProfile::from_toml(&text, "p.toml").map_err(|e| e.to_string())?;
            let pile = Pile::shape(PileShape::Typical, &p).map_err(|e| e.to_string())?;
            let _ = plan_pile(&pile, &small_dig_setup(p));
            Ok(())
        });
    }

    #[test]
    fn perception_settings(e in edits()) {
        use autoshovel_terrain::perceive::{perceive, PerceptionParams};
        let base = toml::to_string(&PerceptionParams::default()).unwrap();
        let text = damage(&base, &e);
        let cloud = small_pile();
        holds("perception settings", &text, || {
            let p = PerceptionParams::from_toml(&text, "p.toml").map_err(|e| e.to_string())?;
            let _ = perceive(&cloud, &p);
            Ok(())
        });
    }

    #[test]
    fn warm_start_packs(cells in prop::collection::vec((any::<usize>(), prop::sample::select(HOSTILE)), 1..4), cut in prop::option::weighted(0.1, any::<usize>())) {
        use autoshovel_rope_shovel_dig::{plan_pile, read_pack, write_pack, DigModel, DigSurface, MachineProfile, Pile, WarmStart};
        use autoshovel_optim::Evaluation;
        use autoshovel_terrain::PileShape;
        let p = MachineProfile::scale_model();
        let model = DigModel::new(&p, DigSurface::from_shape(PileShape::Typical, p.dipper.width_m)).unwrap();
        let pack: Vec<(Vec<f64>, Evaluation)> = (0..5)
            .map(|i| (vec![0.01 * i as f64, -0.02, 9.0 + 0.3 * i as f64, 0.3, 0.3], Evaluation::new(13.0 + i as f64, 0.0)))
            .collect();
        let dir = std::env::temp_dir().join(format!("settings-fuzz-pack-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("pack.csv");
        write_pack(&path, &model, &pack).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        // Damage cells of the CSV (a hostile value in place of a number).
        let mut rows: Vec<Vec<String>> = text.lines().map(|l| l.split(',').map(str::to_string).collect()).collect();
        for (i, v) in &cells {
            let r = 1 + i % (rows.len() - 1);
            let c = (i / rows.len()) % rows[r].len();
            rows[r][c] = v.to_string();
        }
        let mut text: String = rows.iter().map(|r| r.join(",") + "\n").collect();
        if let Some(c) = cut {
            text.truncate(c % text.len());
        }
        std::fs::write(&path, &text).unwrap();
        holds("warm-start pack", &text, || {
            let wolves = read_pack(&path).map_err(|e| e.to_string())?;
            let mut setup = small_dig_setup(MachineProfile::scale_model());
            setup.warm_start = Some(WarmStart { file: path.clone(), wolves });
            let pile = Pile::shape(PileShape::Typical, &setup.profile).map_err(|e| e.to_string())?;
            let _ = plan_pile(&pile, &setup);
            Ok(())
        });
    }
}
