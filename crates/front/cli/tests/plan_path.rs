//! `autoshovel plan-path` on the built-in scenarios: the JSON summary, the
//! `--out` folder, and the classic field's local minimum.

mod common;

use std::process::{Command, Stdio};

use common::*;
use serde_json::Value;

const BUILTINS: [&str; 5] = [
    "straight",
    "straight-reverse",
    "curve",
    "curve-reverse",
    "v-shape",
];

/// Fields every plan-path summary carries (null when planning failed).
const SUMMARY_FIELDS: [&str; 5] = [
    "success",
    "length_m",
    "min_clearance_m",
    "final_heading_error_deg",
    "plan_time_ms",
];

fn plan_json(scenario: &str, planner: &str) -> (Run, Value) {
    let r = run(&[
        "plan-path",
        "--scenario",
        scenario,
        "--planner",
        planner,
        "--json",
    ]);
    let v = r.json();
    (r, v)
}

#[test]
fn improved_apf_plans_every_builtin_scenario() {
    for name in BUILTINS {
        let (r, s) = plan_json(name, "improved-apf");
        let r = r.ok();
        assert!(
            r.stderr.is_empty(),
            "{name}: nothing expected on stderr, got:\n{}",
            r.stderr
        );
        for k in SUMMARY_FIELDS {
            assert!(s.get(k).is_some(), "{name}: summary lacks `{k}`: {s:#}");
        }
        assert_eq!(s["job"], "plan-path", "{name}");
        assert_eq!(s["scenario"], name, "{name}");
        assert_eq!(s["planner"], "improved-apf", "{name}");
        assert_eq!(s["success"], true, "{name}: {s:#}");
        assert_eq!(s["error"], Value::Null, "{name}");
        let heading = f64_field(&s, "final_heading_error_deg");
        assert!(
            (0.0..=2.0).contains(&heading),
            "{name}: final heading error {heading} deg > 2"
        );
        let clearance = f64_field(&s, "min_clearance_m");
        assert!(clearance > 0.0, "{name}: min clearance {clearance} m");
        let length = f64_field(&s, "length_m");
        assert!(length > 0.0, "{name}: length {length} m");
        assert!(f64_field(&s, "plan_time_ms") >= 0.0, "{name}");
        // The path is no shorter than the heading-free grid reference allows
        // (a little slack: the reference is a grid path, not the exact optimum).
        let reference = f64_field(&s["reference"], "length_m");
        assert!(
            length >= 0.95 * reference,
            "{name}: length {length} m vs reference {reference} m"
        );
        let legs = s["legs"]
            .as_array()
            .unwrap_or_else(|| panic!("{name}: legs should be an array: {s:#}"));
        let directions: Vec<&str> = legs
            .iter()
            .map(|l| l["direction"].as_str().unwrap_or("?"))
            .collect();
        let expected: &[&str] = match name {
            "v-shape" => &["reverse", "forward"],
            n if n.ends_with("-reverse") => &["reverse"],
            _ => &["forward"],
        };
        assert_eq!(directions, expected, "{name}: leg directions");
        let leg_sum: f64 = legs.iter().map(|l| f64_field(l, "length_m")).sum();
        assert!(
            (leg_sum - length).abs() < 1e-6,
            "{name}: legs add up to {leg_sum} m, total says {length} m"
        );
    }
}

#[test]
fn json_summary_is_deterministic_apart_from_timing() {
    let (_, a) = plan_json("curve", "improved-apf");
    let (_, b) = plan_json("curve", "improved-apf");
    assert_eq!(without_timing(&a), without_timing(&b));
}

#[test]
fn printed_builtin_scenario_plans_like_the_builtin() {
    let dir = TempDir::new("roundtrip");
    for name in ["curve", "v-shape"] {
        let file = dir.write(&format!("{name}.toml"), builtin_text(name));
        let (r, from_file) = plan_json(file.to_str().expect("utf-8 temp path"), "improved-apf");
        r.ok();
        let (_, builtin) = plan_json(name, "improved-apf");
        assert_eq!(
            without_timing(&from_file),
            without_timing(&builtin),
            "{name}: the printed TOML should plan exactly like the built-in"
        );
    }
}

#[test]
fn human_output_without_json() {
    let r = run(&["plan-path", "--scenario", "straight"]).ok();
    assert!(
        r.stdout.starts_with("improved-apf on straight: success\n"),
        "{}",
        r.stdout
    );
    assert!(
        r.stdout.contains("length            40.000 m"),
        "{}",
        r.stdout
    );
    assert!(
        parse_one_json(&r.stdout).is_err(),
        "human output should not be JSON"
    );
}

fn files_in(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| {
            e.expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    v.sort();
    v
}

fn read(path: &std::path::Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

#[track_caller]
fn assert_svg(path: &std::path::Path) {
    let text = String::from_utf8(read(path))
        .unwrap_or_else(|e| panic!("{}: not UTF-8: {e}", path.display()));
    assert!(
        text.contains("<svg") && text.trim_end().ends_with("</svg>"),
        "{}: not an SVG document",
        path.display()
    );
}

#[track_caller]
fn assert_png(path: &std::path::Path) {
    let bytes = read(path);
    assert!(
        bytes.len() > 1000,
        "{}: only {} bytes",
        path.display(),
        bytes.len()
    );
    assert_eq!(
        bytes[..8],
        PNG_SIGNATURE,
        "{}: no PNG signature",
        path.display()
    );
}

#[test]
fn out_dir_gets_summary_csv_and_plots_and_keeps_other_files() {
    let dir = TempDir::new("out");
    let unrelated = dir.write("notes.txt", "my notes\n");
    let r = run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        "curve".as_ref(),
        "--out".as_ref(),
        dir.path().as_os_str(),
    ])
    .ok();
    assert!(r.stdout.contains("wrote "), "{}", r.stdout);
    assert_eq!(
        files_in(dir.path()),
        [
            "notes.txt",
            "path.csv",
            "path.png",
            "path.svg",
            "profile.png",
            "profile.svg",
            "raw_path.csv",
            "summary.json"
        ],
        "files in --out"
    );
    assert_eq!(
        read(&unrelated),
        b"my notes\n",
        "an unrelated file in --out must be left untouched"
    );

    // summary.json: the --json summary plus the list of files written.
    let text = String::from_utf8(read(&dir.path().join("summary.json"))).expect("utf-8 summary");
    let summary =
        parse_one_json(&text).unwrap_or_else(|e| panic!("summary.json is not JSON ({e}):\n{text}"));
    let (_, printed) = plan_json("curve", "improved-apf");
    let mut files: Vec<String> = summary["files"]
        .as_array()
        .expect("files array")
        .iter()
        .map(|f| f.as_str().expect("file name").to_string())
        .collect();
    files.sort();
    assert_eq!(
        files,
        [
            "path.csv",
            "path.png",
            "path.svg",
            "profile.png",
            "profile.svg",
            "raw_path.csv",
            "summary.json"
        ]
    );
    let mut without_files = summary.clone();
    without_files
        .as_object_mut()
        .expect("summary object")
        .remove("files");
    assert_eq!(
        without_timing(&without_files),
        without_timing(&printed),
        "summary.json should hold the --json summary"
    );
    assert!(summary["plan_time_ms"].is_number());

    // CSV: headers, first row at the start, last row at the goal (curve: (3, 0.937) -> (47, 0.937)).
    let csv = String::from_utf8(read(&dir.path().join("path.csv"))).expect("utf-8 csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "leg,direction,s_m,x_m,y_m,heading_deg,curvature_per_m"
    );
    assert!(lines.len() > 100, "path.csv has only {} lines", lines.len());
    let row = |l: &str| -> Vec<f64> {
        l.split(',')
            .map(|c| {
                c.parse::<f64>()
                    .unwrap_or_else(|e| panic!("path.csv cell `{c}`: {e}"))
            })
            .collect()
    };
    let first = row(lines[1]);
    let last = row(lines[lines.len() - 1]);
    assert_eq!(first.len(), 7);
    assert!(
        (first[3] - 3.0).abs() < 1e-9 && (first[4] - 0.937).abs() < 1e-9,
        "path.csv starts at {first:?}"
    );
    assert!(
        (first[5] - 17.15).abs() < 0.5,
        "start heading {} deg",
        first[5]
    );
    assert!(
        (last[3] - 47.0).abs() < 1e-6 && (last[4] - 0.937).abs() < 1e-6,
        "path.csv ends at {last:?}"
    );
    assert!(
        (last[2] - f64_field(&summary, "length_m")).abs() < 1e-6,
        "last s_m {} vs length_m",
        last[2]
    );
    let raw = String::from_utf8(read(&dir.path().join("raw_path.csv"))).expect("utf-8 csv");
    assert_eq!(raw.lines().next(), Some("leg,x_m,y_m"));
    assert!(raw.lines().count() > 10);

    for plot in ["path", "profile"] {
        assert_svg(&dir.path().join(format!("{plot}.svg")));
        assert_png(&dir.path().join(format!("{plot}.png")));
    }
}

#[test]
fn out_dir_is_created_when_missing() {
    let parent = TempDir::new("nested");
    let out = parent.path().join("a").join("b");
    run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        "straight".as_ref(),
        "--json".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ])
    .ok()
    .json();
    assert!(out.join("summary.json").is_file());
    assert!(out.join("path.png").is_file());
}

#[test]
fn out_pointing_at_a_regular_file_is_refused_and_the_file_kept() {
    let dir = TempDir::new("outfile");
    let file = dir.write("not-a-dir", "precious\n");
    for json in [false, true] {
        let mut args = vec![
            "plan-path".as_ref(),
            "--scenario".as_ref(),
            "straight".as_ref(),
            "--out".as_ref(),
            file.as_os_str(),
        ];
        if json {
            args.push("--json".as_ref());
        }
        let r = run(&args).fails();
        assert!(
            r.stderr.contains(&file.display().to_string()),
            "the message should name {}:\n{}",
            file.display(),
            r.stderr
        );
        assert!(r.stderr.contains("not a directory"), "{}", r.stderr);
        assert!(
            r.stdout.is_empty(),
            "nothing on stdout expected, got:\n{}",
            r.stdout
        );
        assert_eq!(
            read(&file),
            b"precious\n",
            "the file must be left as it was"
        );
    }
}

/// "local minimum at (13.856, -0.170) after ..." -> (13.856, -0.170)
fn local_minimum_position(text: &str) -> (f64, f64) {
    let rest = text
        .split("local minimum at (")
        .nth(1)
        .unwrap_or_else(|| panic!("no `local minimum at (` in:\n{text}"));
    let inner = rest.split(')').next().expect("closing parenthesis");
    let (x, y) = inner
        .split_once(", ")
        .unwrap_or_else(|| panic!("position `({inner})` is not `(x, y)`"));
    (
        x.parse().unwrap_or_else(|e| panic!("x `{x}`: {e}")),
        y.parse().unwrap_or_else(|e| panic!("y `{y}`: {e}")),
    )
}

#[test]
fn classic_apf_stalls_on_curve_in_a_local_minimum() {
    let r = run(&["plan-path", "--scenario", "curve", "--planner", "apf"]).fails();
    assert!(
        r.stderr.contains("apf could not plan scenario 'curve'"),
        "{}",
        r.stderr
    );
    let (x, y) = local_minimum_position(&r.stderr);
    // Inside the site [0, 50] x [-8, 14], short of the truck at x = 14.7..22.1.
    assert!(
        (0.0..=50.0).contains(&x) && (-8.0..=14.0).contains(&y),
        "({x}, {y}) outside the site"
    );
    assert!(
        x < 22.0,
        "the classic field should stall before passing the truck, stalled at ({x}, {y})"
    );
    // The human summary is still printed.
    assert!(
        r.stdout.starts_with("apf on curve: FAILED\n"),
        "{}",
        r.stdout
    );

    let r = run(&[
        "plan-path",
        "--scenario",
        "curve",
        "--planner",
        "apf",
        "--json",
    ])
    .fails();
    let s = r.json();
    assert_eq!(s["success"], false);
    assert_eq!(s["local_minimum"], true);
    assert_eq!(s["planner"], "apf");
    for k in SUMMARY_FIELDS {
        assert!(s.get(k).is_some(), "summary lacks `{k}`: {s:#}");
    }
    assert_eq!(s["length_m"], Value::Null);
    let at = s["error_at_m"]
        .as_array()
        .unwrap_or_else(|| panic!("error_at_m should be [x, y]: {s:#}"));
    assert_eq!(at.len(), 2);
    let (jx, jy) = (at[0].as_f64().expect("x"), at[1].as_f64().expect("y"));
    let (ex, ey) = local_minimum_position(&r.stderr);
    assert!(
        (jx - ex).abs() < 5e-4 && (jy - ey).abs() < 5e-4,
        "JSON error_at_m ({jx}, {jy}) vs stderr ({ex}, {ey})"
    );
    let err = s["error"].as_str().expect("error string");
    assert!(err.starts_with("local minimum at ("), "{err}");
    assert_eq!(local_minimum_position(err), (ex, ey));
}

#[test]
fn failed_plan_with_out_still_writes_summary_and_map() {
    let dir = TempDir::new("failout");
    let r = run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        "curve".as_ref(),
        "--planner".as_ref(),
        "apf".as_ref(),
        "--out".as_ref(),
        dir.path().as_os_str(),
    ])
    .fails();
    assert!(r.stderr.contains("local minimum"), "{}", r.stderr);
    assert_eq!(
        files_in(dir.path()),
        ["path.png", "path.svg", "summary.json"]
    );
    let s =
        parse_one_json(&String::from_utf8(read(&dir.path().join("summary.json"))).expect("utf-8"))
            .expect("summary.json is JSON");
    assert_eq!(s["success"], false);
    assert_eq!(s["local_minimum"], true);
}

/// With the required goal heading opposite to the only way in (a straight road,
/// goal 40 m ahead but to be reached facing back towards the start), the
/// planner cannot meet the heading without turning round. It must not report
/// success: either a path that arrives within 2° (README: success = within 2°
/// of the required heading) or a failure with a non-zero exit.
#[test]

fn reversed_goal_heading_is_not_reported_as_success() {
    let dir = TempDir::new("uturn");
    let text = builtin_text("straight");
    let goal = text
        .split("[goal]")
        .nth(1)
        .expect("[goal] table")
        .to_string();
    let edited = text.replace(
        &goal,
        &replace_once(&goal, "heading_deg = 0.0", "heading_deg = 180.0"),
    );
    let file = dir.write("uturn.toml", edited);
    let r = run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        file.as_os_str(),
        "--json".as_ref(),
    ]);
    r.no_panic();
    let s = r.json();
    if r.code() == Some(0) {
        assert_eq!(s["success"], true);
        let h = f64_field(&s, "final_heading_error_deg");
        assert!(
            h <= 2.0,
            "exit 0 and success: true, but the path arrives {h} deg off the required heading"
        );
    } else {
        assert_eq!(r.code(), Some(1));
        assert_eq!(s["success"], false);
        assert!(
            s["error"].as_str().unwrap_or("").contains("heading"),
            "the error should say the heading cannot be met: {s:#}"
        );
    }
}

/// A goal on the start pose: a zero-length plan. The summary should still
/// give the clearance (3 m on the straight road) and the heading error (0°),
/// not null.
#[test]

fn goal_on_start_reports_its_clearance_and_heading() {
    let dir = TempDir::new("same");
    let text = builtin_text("straight");
    let goal = text
        .split("[goal]")
        .nth(1)
        .expect("[goal] table")
        .to_string();
    let edited = text.replace(&goal, &replace_once(&goal, "x_m = 44.0", "x_m = 4.0"));
    let file = dir.write("same.toml", edited);
    let r = run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        file.as_os_str(),
        "--json".as_ref(),
    ])
    .ok();
    let s = r.json();
    assert_eq!(s["success"], true);
    assert_eq!(f64_field(&s, "length_m"), 0.0);
    assert!(
        (f64_field(&s, "min_clearance_m") - 3.0).abs() < 1e-9,
        "{s:#}"
    );
    assert_eq!(f64_field(&s, "final_heading_error_deg"), 0.0);
}

/// `autoshovel plan-path ... | head -c 1`: the reader goes away. The program
/// should stop quietly (like any Unix filter), not panic with
/// "failed printing to stdout: Broken pipe" and exit 101.
#[test]

fn closed_stdout_does_not_panic() {
    for json in [true, false] {
        let mut args = vec!["plan-path", "--scenario", "straight"];
        if json {
            args.push("--json");
        }
        let cmd = format!("{} {}", bin(), args.join(" "));
        let mut child = Command::new(bin())
            .args(&args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn");
        // Close the read end before the program has planned and printed anything.
        drop(child.stdout.take());
        let mut err = child.stderr.take().expect("stderr");
        let reader = std::thread::spawn(move || {
            let mut s = String::new();
            let _ = std::io::Read::read_to_string(&mut err, &mut s);
            s
        });
        let status = wait_or_kill(&mut child, TIMEOUT, &cmd);
        let stderr = reader.join().expect("stderr reader");
        assert!(
            !stderr.contains("panicked"),
            "`{cmd}` with stdout closed panicked:\n{stderr}"
        );
        assert_ne!(
            status.code(),
            Some(101),
            "`{cmd}`: exit 101 is Rust's panic exit"
        );
    }
}

/// Issue 11: a vertex with a third coordinate is refused at its line, not
/// read as (x, y) with the rest dropped.
#[test]
fn a_three_coordinate_vertex_is_refused_at_its_line() {
    let dir = TempDir::new("xyz-vertex");
    let text = builtin_text("curve");
    let line = text
        .lines()
        .find(|l| l.starts_with("vertices_m"))
        .expect("a polygon")
        .to_string();
    let bad_line = line.replacen("]", ", 7.0]", 1);
    let bad = replace_once(&text, &line, &bad_line);
    let file = dir.write("road.toml", &bad);
    let r = run(&[
        "plan-path".as_ref(),
        "--scenario".as_ref(),
        file.as_os_str(),
    ])
    .fails();
    let msg = r.error_message();
    let at = format!("road.toml:{}:", line_of(&bad, &bad_line));
    assert!(msg.contains(&at) && msg.contains("3 coordinate"), "{msg}");
}
