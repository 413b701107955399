//! Bad scenarios and bad arguments: every one is refused with exit 1, an
//! `error:` line on stderr naming the file/line/value at fault, no panic, no
//! hang, and nothing but (at most) the JSON summary on stdout. Ends with a
//! seeded mutation test of scenario files.

mod common;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use common::*;

/// The built-in `straight` scenario (start (4, 0) heading 0, goal (44, 0)
/// heading 0, site [0, 50] x [-8, 8], rock of radius 0.6 at (25, 4.6)) with an edit.
fn straight_with(edit: impl FnOnce(String) -> String) -> String {
    edit(builtin_text("straight"))
}

/// Splits the text at `[goal]` and applies `edit` to the goal table onwards.
fn edit_goal(text: String, edit: impl FnOnce(&str) -> String) -> String {
    let (head, tail) = text.split_once("[goal]").expect("[goal] table");
    format!("{head}[goal]{}", edit(tail))
}

/// Runs `plan-path --scenario FILE` with and without `--json`; both must fail
/// the same way. Returns the error message (without `error: `) of the human run.
#[track_caller]
fn refused(file: &Path) -> String {
    let human = run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        file.as_os_str(),
    ])
    .fails();
    let json = run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        file.as_os_str(),
        "--json".as_ref(),
    ])
    .fails();
    // --json: stdout is empty (refused before planning) or one JSON summary of the failure.
    if !json.stdout.trim().is_empty() {
        let s = json.json();
        assert_eq!(s["success"], false, "{s:#}");
        assert!(s["error"].is_string(), "{s:#}");
    }
    let last = |r: &Run| r.stderr.lines().last().unwrap_or("").to_string();
    assert_eq!(
        last(&human),
        last(&json),
        "the same error with and without --json"
    );
    human.error_message().to_string()
}

fn write(dir: &TempDir, name: &str, text: &str) -> (PathBuf, String) {
    let p = dir.write(name, text);
    let shown = p.display().to_string();
    (p, shown)
}

#[test]
fn start_inside_an_obstacle() {
    let dir = TempDir::new("start-in");
    let text = straight_with(|t| {
        let (head, tail) = t.split_once("[goal]").expect("[goal]");
        let head = replace_once(head, "x_m = 4.0", "x_m = 25.0");
        let head = replace_once(&head, "y_m = 0.0", "y_m = 4.6");
        format!("{head}[goal]{tail}")
    });
    let (file, _) = write(&dir, "start-in.toml", &text);
    let e = refused(&file);
    assert!(e.contains("start (25.000, 4.600)"), "{e}");
    assert!(
        e.contains("'rock'"),
        "the message should name the obstacle: {e}"
    );
    assert!(e.contains("clearance -1.600 m"), "{e}");
}

#[test]
fn goal_outside_the_site() {
    let dir = TempDir::new("goal-out");
    let text = straight_with(|t| edit_goal(t, |g| replace_once(g, "x_m = 44.0", "x_m = 60.0")));
    let (file, _) = write(&dir, "goal-out.toml", &text);
    let e = refused(&file);
    assert!(
        e.contains("goal (60.000, 0.000) is outside the site [0, 50] x [-8, 8]"),
        "{e}"
    );
}

#[test]
fn goal_heading_blocked_behind_the_goal() {
    // A wall 1.9 m behind the goal: the goal itself is clear (footprint 1 m),
    // but the last metre of the approach along heading 0 is not.
    let dir = TempDir::new("goal-blocked");
    let text = straight_with(|t| {
        t + "\n[[polygon]]\nname = \"wall\"\nvertices_m = [[41.5, -1.0], [42.1, -1.0], [42.1, 1.0], [41.5, 1.0]]\n"
    });
    let (file, _) = write(&dir, "goal-blocked.toml", &text);
    let e = refused(&file);
    assert!(e.contains("goal (44.000, 0.000)"), "{e}");
    assert!(e.contains("turning on the spot"), "{e}");
    assert!(e.contains("heading 0.0 deg is blocked by 'wall'"), "{e}");
    assert!(e.contains("behind it"), "{e}");
}

#[test]
fn start_heading_blocked_ahead_of_the_start() {
    let dir = TempDir::new("start-blocked");
    let text = straight_with(|t| {
        t + "\n[[polygon]]\nname = \"wall\"\nvertices_m = [[5.9, -1.0], [6.5, -1.0], [6.5, 1.0], [5.9, 1.0]]\n"
    });
    let (file, _) = write(&dir, "start-blocked.toml", &text);
    let e = refused(&file);
    assert!(
        e.contains("start (4.000, 0.000) is reachable only by turning on the spot"),
        "{e}"
    );
    assert!(e.contains("'wall'") && e.contains("ahead of it"), "{e}");
}

/// The value errors name the file, the line of the value's key and the value.
#[test]
fn nan_and_inf_are_refused_with_file_and_line() {
    let dir = TempDir::new("nonfinite");
    for (bad, shown) in [("nan", "NaN"), ("inf", "inf"), ("-inf", "-inf")] {
        let text =
            straight_with(|t| replace_once(&t, "radius_m = 0.6", &format!("radius_m = {bad}")));
        let line = line_of(&text, &format!("radius_m = {bad}"));
        let (file, path) = write(&dir, &format!("circle-{bad}.toml"), &text);
        let e = refused(&file);
        assert!(
            e.starts_with(&format!("{path}:{line}: ")),
            "`{bad}`: should start with `{path}:{line}: `: {e}"
        );
        assert!(
            e.contains("circle #1 'rock': radius_m")
                && e.contains(&format!("non-finite number ({shown})")),
            "{e}"
        );

        let text = straight_with(|t| {
            let (head, tail) = t.split_once("[goal]").expect("[goal]");
            format!(
                "{}[goal]{tail}",
                replace_once(head, "x_m = 4.0", &format!("x_m = {bad}"))
            )
        });
        let line = line_of(&text, &format!("x_m = {bad}"));
        let (file, path) = write(&dir, &format!("start-{bad}.toml"), &text);
        let e = refused(&file);
        assert!(
            e.starts_with(&format!(
                "{path}:{line}: [start]: x_m has a non-finite number ({shown})"
            )),
            "{e}"
        );
    }
    let text =
        straight_with(|t| replace_once(&t, "footprint_radius_m = 1.0", "footprint_radius_m = nan"));
    let (file, path) = write(&dir, "footprint-nan.toml", &text);
    let e = refused(&file);
    assert!(
        e.starts_with(&format!(
            "{path}:{}: footprint_radius_m = NaN",
            line_of(&text, "footprint_radius_m = nan")
        )),
        "{e}"
    );
}

#[test]
fn malformed_toml_names_file_line_and_column() {
    let dir = TempDir::new("malformed");
    // A table header without its closing bracket: the error is on that line.
    let text = straight_with(|t| replace_once(&t, "[site]", "[site"));
    let line = line_of(&text, "[site");
    let (file, path) = write(&dir, "header.toml", &text);
    let e = refused(&file);
    assert!(
        e.starts_with(&format!("{path}:{line}:")),
        "should start with `{path}:{line}:`: {e}"
    );
    assert!(e.contains("invalid table header"), "{e}");

    // An array without its closing bracket: the parser notices on that line
    // or at the start of the next one.
    let text =
        straight_with(|t| replace_once(&t, "center_m = [25.0, 4.6]", "center_m = [25.0, 4.6"));
    let line = line_of(&text, "center_m = [25.0, 4.6");
    let (file, path) = write(&dir, "array.toml", &text);
    let e = refused(&file);
    assert!(
        e.starts_with(&format!("{path}:{line}:"))
            || e.starts_with(&format!("{path}:{}:", line + 1)),
        "should start with `{path}:{line}:` (or the next line): {e}"
    );
    assert!(e.contains("expected `]`"), "{e}");
}

#[test]
fn wrong_types_and_missing_fields_name_the_line() {
    let dir = TempDir::new("types");
    // (name, text replaced, replacement, what the message says); the error is on the replacement's line.
    let cases = [
        (
            "string",
            "x_m = 4.0",
            "x_m = \"four\"",
            "invalid type: string \"four\", expected f64",
        ),
        (
            "short-array",
            "min_m = [0.0, -8.0]",
            "min_m = [0.0]",
            "[0.0] has 1 coordinate(s); expected 2 (x, y)",
        ),
        (
            "direction",
            "direction = \"forward\"",
            "direction = \"sideways\"",
            "unknown variant `sideways`",
        ),
        ("huge", "x_m = 4.0", "x_m = 1e999", "invalid"),
    ];
    for (name, from, to, what) in cases {
        let text = straight_with(|t| replace_once(&t, from, to));
        let line = line_of(&text, to);
        let (file, path) = write(&dir, &format!("{name}.toml"), &text);
        let e = refused(&file);
        assert!(
            e.starts_with(&format!("{path}:{line}:")),
            "{name}: should start with `{path}:{line}:`: {e}"
        );
        assert!(e.contains(what), "{name}: {e}");
    }
    let (file, path) = write(&dir, "empty.toml", "");
    let e = refused(&file);
    assert!(
        e.starts_with(&format!("{path}:1:1: missing field `site`")),
        "{e}"
    );
}

#[test]
fn non_convex_polygon_names_line_and_says_not_convex() {
    let dir = TempDir::new("dart");
    let text = straight_with(|t| {
        t + "\n[[polygon]]\nname = \"dart\"\nvertices_m = [[20.0, -4.0], [22.0, -3.0], [24.0, -4.0], [22.0, -1.0]]\n"
    });
    let line = line_of(&text, "[[polygon]]");
    let (file, path) = write(&dir, "dart.toml", &text);
    let e = refused(&file);
    assert!(
        e.starts_with(&format!("{path}:{line}: polygon #1 'dart' is not convex")),
        "{e}"
    );
}

#[test]
fn unknown_field_is_named() {
    let dir = TempDir::new("unknown");
    let text = straight_with(|t| {
        replace_once(
            &t,
            "footprint_radius_m = 1.0\n",
            "footprint_radius_m = 1.0\nspeed_m_s = 3.0\n",
        )
    });
    let line = line_of(&text, "speed_m_s = 3.0");
    let (file, path) = write(&dir, "unknown.toml", &text);
    let e = refused(&file);
    assert!(e.starts_with(&format!("{path}:{line}:")), "{e}");
    assert!(e.contains("unknown field `speed_m_s`"), "{e}");

    // In a nested table too.
    let text =
        straight_with(|t| replace_once(&t, "radius_m = 0.6", "radius_m = 0.6\ncolour = \"grey\""));
    let (file, path) = write(&dir, "unknown-nested.toml", &text);
    let e = refused(&file);
    assert!(
        e.starts_with(&format!("{path}:")) && e.contains("unknown field `colour`"),
        "{e}"
    );
}

#[test]
fn negative_and_zero_radii_are_refused() {
    let dir = TempDir::new("radius");
    for r in ["-0.6", "0.0"] {
        let text =
            straight_with(|t| replace_once(&t, "radius_m = 0.6", &format!("radius_m = {r}")));
        let (file, path) = write(&dir, &format!("circle{r}.toml"), &text);
        let e = refused(&file);
        let line = line_of(&text, &format!("radius_m = {r}"));
        assert!(
            e.starts_with(&format!(
                "{path}:{line}: circle #1 'rock': radius_m = {} must be positive",
                r.trim_end_matches(".0")
            )),
            "{e}"
        );
    }
    let text = straight_with(|t| {
        replace_once(&t, "footprint_radius_m = 1.0", "footprint_radius_m = -1.0")
    });
    let (file, path) = write(&dir, "footprint.toml", &text);
    let e = refused(&file);
    let line = line_of(&text, "footprint_radius_m = -1.0");
    assert!(
        e.starts_with(&format!(
            "{path}:{line}: footprint_radius_m = -1 must be a positive number"
        )),
        "{e}"
    );
}

#[test]
fn inverted_site_is_refused() {
    let dir = TempDir::new("site");
    let text = straight_with(|t| replace_once(&t, "max_m = [50.0, 8.0]", "max_m = [-50.0, 8.0]"));
    let (file, path) = write(&dir, "site.toml", &text);
    let e = refused(&file);
    assert!(
        e.starts_with(&format!(
            "{path}:{}: [site] max_m",
            line_of(&text, "[site]")
        )),
        "{e}"
    );
}

#[test]
fn unknown_scenario_name_lists_the_builtins() {
    let r = run(&["plan-path", "--scenario", "nosuch"]).fails();
    let e = r.error_message();
    assert!(e.contains("'nosuch'"), "{e}");
    assert!(
        e.contains("(straight, straight-reverse, curve, curve-reverse, v-shape)"),
        "{e}"
    );
    let r = run(&["plan-path", "--scenario", "nosuch", "--json"]).fails();
    assert!(r.stdout.is_empty(), "{}", r.stdout);

    let r = run(&["scenario", "nosuch"]).fails();
    assert!(
        r.error_message().contains("'nosuch'")
            && r.error_message()
                .contains("straight, straight-reverse, curve, curve-reverse, v-shape")
            && r.error_message().contains("fig9a, fig9b")
            && r.error_message().contains("paper-over"),
        "{}",
        r.stderr
    );
}

/// `autoshovel scenario NAME` prints every job's built-ins, and what it
/// prints runs as the built-in does (the same summary).
#[test]
fn every_built_in_scenario_prints_and_runs_as_itself() {
    let dir = TempDir::new("scenario-print");
    for (job, name) in [
        ("track", "fig9a"),
        ("track", "fig9b"),
        ("track", "straight-reverse"),
        ("plan-path", "curve"),
        ("plan-excavate", "two-boulders"),
    ] {
        let text = run(&["scenario", name]).ok().stdout;
        let file = dir.write(&format!("{name}.toml"), &text);
        let file = file.to_str().unwrap();
        let mut built_in = run(&[job, "--scenario", name, "--json"]).ok().json();
        let mut printed = run(&[job, "--scenario", file, "--json"]).ok().json();
        // Only where the scenario came from and the timings may differ.
        fn strip(v: &mut serde_json::Value) {
            match v {
                serde_json::Value::Object(m) => {
                    m.retain(|k, _| {
                        !(k.ends_with("_ms") || k == "realtime_factor" || k.starts_with("scenario"))
                    });
                    m.values_mut().for_each(strip);
                }
                serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
                _ => {}
            }
        }
        strip(&mut built_in);
        strip(&mut printed);
        assert_eq!(built_in, printed, "{job} {name}");
    }
}

#[test]
fn unreadable_scenario_path_is_named() {
    let dir = TempDir::new("dir-as-file");
    let r = run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        dir.path().as_os_str(),
    ])
    .fails();
    assert!(
        r.error_message().starts_with(&format!(
            "cannot read scenario file {}",
            dir.path().display()
        )),
        "{}",
        r.stderr
    );
}

#[test]
fn bad_command_line_is_a_usage_error() {
    let r = run(&["plan-path", "--planner", "dijkstra"]);
    r.no_panic();
    assert_eq!(r.code(), Some(2), "clap usage errors exit 2: {}", r.stderr);
    assert!(
        r.stderr.contains("dijkstra") && r.stderr.contains("improved-apf"),
        "{}",
        r.stderr
    );
    assert!(r.stdout.is_empty());
}

/// A small seeded LCG (Knuth's MMIX constants), so the test needs no crate.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Number of mutated scenarios (each one run of the program, about 5–50 ms).
const MUTATIONS: usize = 200;

#[test]
fn mutated_scenarios_never_panic_or_hang() {
    let dir = TempDir::new("mutations");
    let seeds: Vec<Vec<u8>> = ["straight", "curve", "v-shape", "curve-reverse"]
        .iter()
        .map(|n| builtin_text(n).into_bytes())
        .collect();
    let mut rng = Lcg(0x5eed_0003);
    let t0 = Instant::now();
    let (mut ok, mut refused, mut slowest) = (0, 0, Duration::ZERO);
    for i in 0..MUTATIONS {
        let mut text = seeds[rng.below(seeds.len())].clone();
        let edits = 1 + rng.below(3);
        let mut what = Vec::new();
        for _ in 0..edits {
            if rng.below(5) == 0 {
                let at = rng.below(text.len() + 1);
                text.truncate(at);
                what.push(format!("truncate at {at}"));
            } else if !text.is_empty() {
                let at = rng.below(text.len());
                let c = b' ' + rng.below(95) as u8;
                text[at] = c;
                what.push(format!("byte {at} = {:?}", c as char));
            }
        }
        let file = dir.write(&format!("m{i}.toml"), &text);
        let r = run(&[
            "plan-path".as_ref(),
            "--scenario".as_ref(),
            file.as_os_str(),
            "--json".as_ref(),
        ]);
        let context = || {
            format!(
                "mutation {i} ({}), kept at {}",
                what.join(", "),
                file.display()
            )
        };
        assert!(
            !r.stderr.contains("panicked"),
            "{}: panicked:\n{}",
            context(),
            r.stderr
        );
        match r.code() {
            Some(0) => {
                let s = r.json();
                assert_eq!(s["success"], true, "{}", context());
                ok += 1;
            }
            Some(1) => {
                assert!(
                    r.stderr.starts_with("error: "),
                    "{}: {}",
                    context(),
                    r.stderr
                );
                if !r.stdout.trim().is_empty() {
                    assert_eq!(r.json()["success"], false, "{}", context());
                }
                refused += 1;
            }
            other => panic!("{}: exit {other:?}\n{}", context(), r.stderr),
        }
        slowest = slowest.max(r.elapsed);
        let _ = std::fs::remove_file(&file);
    }
    // Both outcomes occur, so the mutations are neither all harmless nor all fatal.
    assert!(ok > 0 && refused > 0, "{ok} planned, {refused} refused");
    eprintln!(
        "{MUTATIONS} mutations: {ok} planned, {refused} refused, slowest {slowest:?}, total {:?}",
        t0.elapsed()
    );
}

/// OS errors are printed once, after the file they concern (never the
/// temporary file autoshovel writes through).
#[test]
fn os_errors_are_printed_once_naming_the_users_path() {
    let dir = TempDir::new("os-errors");
    let missing = dir.path().join("missing.pcd");
    let m = missing.to_str().unwrap();
    let cases: [Vec<&str>; 3] = [
        vec!["perceive", "--input", m],
        vec!["plan-dig", "--cloud", m],
        vec!["generate-pile", "--out", "PLACEHOLDER"],
    ];
    let nested = dir.path().join("no-such-folder").join("pile.pcd");
    for mut a in cases {
        if a[2] == "PLACEHOLDER" {
            a[2] = nested.to_str().unwrap();
        }
        let r = run(&a).fails();
        let e = r.error_message();
        assert_eq!(e.matches("os error").count(), 1, "{e}");
        assert_eq!(e.matches(a[2]).count(), 1, "{e}");
        assert!(!e.contains(".autoshovel"), "{e}");
    }
}
