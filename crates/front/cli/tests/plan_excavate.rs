//! `autoshovel plan-excavate`: the SPEC §6 summary of the paper's two cases
//! checked against the scenario and profile texts the program prints (not
//! against numbers copied from a run), the files of `--out` against the
//! summary, the round trips of `--print-scenario` and `--print-profile`, the
//! two-boulder example file, and broken or impossible scenarios.
//!
//! A plan takes about a millisecond; every test runs the program a few times.

mod common;

use std::path::{Path, PathBuf};

use common::*;
use serde_json::Value;

/// `plan-excavate` with `args`.
fn cmd<'a>(args: &[&'a std::ffi::OsStr]) -> Vec<&'a std::ffi::OsStr> {
    let mut v = vec!["plan-excavate".as_ref()];
    v.extend_from_slice(args);
    v
}

/// The scenario text as `--print-scenario` prints it.
fn scenario_text(name: &str) -> String {
    let r = run(&["plan-excavate", "--print-scenario", "--scenario", name]).ok();
    assert!(r.stdout.contains("[dig]"), "{}", r.stdout);
    r.stdout
}

/// The built-in machine profile as `--print-profile` prints it.
fn profile_text() -> String {
    let r = run(&["plan-excavate", "--print-profile"]).ok();
    assert!(r.stdout.contains("[geometry]"), "{}", r.stdout);
    r.stdout
}

/// The text of the value of every `key = value` line of a TOML text, in order.
fn values<'t>(text: &'t str, key: &str) -> Vec<&'t str> {
    text.lines()
        .filter_map(|l| {
            let (k, v) = l.split_once('=')?;
            (k.trim() == key).then(|| v.split('#').next().unwrap_or("").trim())
        })
        .collect()
}

/// The number of the first `key = value` line.
#[track_caller]
fn number(text: &str, key: &str) -> f64 {
    let v = values(text, key);
    let first = v
        .first()
        .unwrap_or_else(|| panic!("no `{key} =` in:\n{text}"));
    first
        .parse()
        .unwrap_or_else(|e| panic!("`{key} = {first}`: {e}"))
}

/// The boulders of a scenario text: (centre, radius) per `[[obstacle]]`.
fn boulders(text: &str) -> Vec<([f64; 2], f64)> {
    let centres = values(text, "center_m");
    let radii = values(text, "radius_m");
    assert_eq!(centres.len(), radii.len(), "{text}");
    centres
        .iter()
        .zip(radii)
        .map(|(c, r)| {
            let xy: Vec<f64> = c
                .trim_matches(['[', ']'])
                .split(',')
                .map(|v| v.trim().parse().expect("a number"))
                .collect();
            ([xy[0], xy[1]], r.parse().expect("a radius"))
        })
        .collect()
}

fn pair(v: &Value) -> [f64; 2] {
    [
        v[0].as_f64().expect("x number"),
        v[1].as_f64().expect("y number"),
    ]
}

/// γ as the paper defines it in our mirrored frame (docs/excavator-dig.md):
/// clockwise from V_c to F_f, atan2(−(V × F), V·F) mod 360° (deg).
fn gamma_deg(v: [f64; 2], f: [f64; 2]) -> f64 {
    let cross = v[0] * f[1] - v[1] * f[0];
    let dot = v[0] * f[0] + v[1] * f[1];
    (-cross).atan2(dot).to_degrees().rem_euclid(360.0)
}

/// The preimage rule: γ in (0°, 180°) → over, (180°, 360°) → under.
fn side_of(gamma: f64) -> &'static str {
    if gamma > 0.0 && gamma < 180.0 {
        "over"
    } else if gamma > 180.0 && gamma < 360.0 {
        "under"
    } else {
        "a tie"
    }
}

/// Checks a summary against its scenario and the built-in profile: every
/// SPEC field, the volume identities, the contacts on the boulders' rims
/// with the machine's full force and a side that agrees with γ.
#[track_caller]
fn check_summary(s: &Value, scenario: &str, profile: &str) {
    for key in [
        "target_volume_m3",
        "achieved_volume_m3",
        "plan_time_ms",
        "volume_error_pct",
        "soil_volume_m3",
        "obstacle_volume_m3",
        "max_joint_step_ratio",
        "peak_digging_force_n",
        "peak_soil_force_n",
        "duration_s",
    ] {
        f64_field(s, key);
    }
    assert_eq!(s["job"], "plan-excavate");
    assert!(s["scenario"].is_string(), "{s:#}");
    assert!(
        s.get("avoid_direction").is_some(),
        "avoid_direction missing"
    );
    let target = number(scenario, "target_volume_m3");
    assert_eq!(f64_field(s, "target_volume_m3"), target);
    let (achieved, soil, rock) = (
        f64_field(s, "achieved_volume_m3"),
        f64_field(s, "soil_volume_m3"),
        f64_field(s, "obstacle_volume_m3"),
    );
    assert!(
        (achieved - target).abs() <= 0.02 * target,
        "{achieved} m³ is not within 2 % of {target} m³"
    );
    assert!((achieved - soil - rock).abs() < 1e-9, "soil + rock");
    let pct = f64_field(s, "volume_error_pct");
    assert!((pct - 100.0 * (achieved - target) / target).abs() < 1e-9);
    // Level 1: from the start on the ground down to the dig depth and back up.
    let depth = number(scenario, "depth_m");
    let mid = pair(&s["level1_mid_m"]);
    let end = pair(&s["level1_end_m"]);
    let start = number(scenario, "start_x_m");
    assert!((mid[1] + depth).abs() < 1e-9, "midpoint {mid:?}");
    assert!(end[1].abs() < 1e-9 && end[0] < mid[0] && mid[0] < start);
    assert!(f64_field(s, "max_joint_step_ratio") <= 1.0 + 1e-9);
    let peaks = s["peak_torques_nm"].as_array().expect("peak torques");
    assert_eq!(peaks.len(), 3);
    assert!(peaks.iter().all(|t| t.as_f64().unwrap() > 0.0), "{peaks:?}");
    // The contacts: on a boulder's rim, pushed back with the rated force,
    // the side the preimage rule gives for the γ of V_c and F_f.
    let rated = number(profile, "max_digging_force_n");
    let width = number(profile, "width_m");
    let rocks = boulders(scenario);
    let contacts = s["contacts"].as_array().expect("contacts array");
    assert_eq!(f64_field(s, "contact_count") as usize, contacts.len());
    let mut last_t = 0.0;
    for c in contacts {
        let t = f64_field(c, "t_s");
        assert!(t > last_t && t < f64_field(s, "duration_s"), "{c}");
        last_t = t;
        let (centre, r) = rocks[c["obstacle"].as_u64().expect("obstacle index") as usize];
        let p = pair(&c["point_m"]);
        let d = (p[0] - centre[0]).hypot(p[1] - centre[1]);
        assert!(
            (d - r).abs() < 1e-6,
            "contact {p:?} is {d} m from the centre, r = {r}"
        );
        let (v, f) = (pair(&c["velocity_m_s"]), pair(&c["force_n"]));
        assert!((f[0].hypot(f[1]) - rated).abs() < 1e-6 * rated, "{c}");
        // The planner reads γ from the force it measured, not the simulator's.
        let f = pair(&c["measured_force_n"]);
        let g = f64_field(c, "gamma_deg");
        assert!(
            (g - gamma_deg(v, f)).abs() < 1e-9,
            "γ {g} vs {}",
            gamma_deg(v, f)
        );
        assert_eq!(c["decision"], side_of(g), "decision against γ = {g}");
    }
    // The side: the first contact's, and every contact's in order.
    let sides: Vec<&Value> = contacts.iter().map(|c| &c["decision"]).collect();
    assert_eq!(
        s["avoid_directions"]
            .as_array()
            .unwrap()
            .iter()
            .collect::<Vec<_>>(),
        sides
    );
    match contacts.first() {
        Some(c) => assert_eq!(s["avoid_direction"], c["decision"]),
        None => assert!(s["avoid_direction"].is_null()),
    }
    // Every boulder met counts π r² h_b as dug.
    let met: f64 = rocks
        .iter()
        .enumerate()
        .filter(|(i, _)| contacts.iter().any(|c| c["obstacle"] == *i))
        .map(|(_, (_, r))| std::f64::consts::PI * r * r * width)
        .sum();
    assert!((rock - met).abs() < 1e-9, "boulders {rock} vs {met}");
}

#[test]
fn the_paper_cases_pass_over_and_under_within_two_percent() {
    let profile = profile_text();
    for (name, side) in [("paper-over", "over"), ("paper-under", "under")] {
        let scenario = scenario_text(name);
        let s = run(&["plan-excavate", "--scenario", name, "--json"])
            .ok()
            .json();
        check_summary(&s, &scenario, &profile);
        assert_eq!(s["scenario"], name);
        assert_eq!(s["avoid_direction"], side, "{name}");
        assert!(!s["contacts"].as_array().unwrap().is_empty(), "{name}");
        assert!(s.get("files").is_none(), "no --out, no files: {s:#}");
    }
    // paper-over is the default; the paper met its boulder at about 1.6 s.
    let s = run(&["plan-excavate", "--json"]).ok().json();
    assert_eq!(s["scenario"], "paper-over");
    let t = f64_field(&s["contacts"][0], "t_s");
    assert!(
        (t - 1.6).abs() < 0.25,
        "contact at {t} s, the paper's at 1.6 s"
    );
    // Human output without --json.
    let r = run(&["plan-excavate", "--scenario", "paper-under"]).ok();
    assert!(r.stdout.contains("→ under"), "{}", r.stdout);
}

/// samples.csv as (header, rows of cells).
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("a header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

#[test]
fn out_writes_the_data_and_plots_that_agree_with_the_summary() {
    let dir = TempDir::new("plan-excavate-out");
    let out = dir.path().join("under");
    let r = run(&cmd(&[
        "--scenario".as_ref(),
        "paper-under".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
        "--json".as_ref(),
    ]))
    .ok();
    let s = r.json();
    let scenario = scenario_text("paper-under");
    let profile = profile_text();
    check_summary(&s, &scenario, &profile);
    assert_written(
        &out,
        &s,
        &[
            "summary.json",
            "samples.csv",
            "contacts.csv",
            "planned_path.csv",
            "tooth_path.svg",
            "tooth_path.png",
            "excavator.svg",
            "excavator.png",
            "digging_force.svg",
            "digging_force.png",
            "joints.svg",
            "joints.png",
        ],
    );
    // samples.csv: every sample field, from the start at rest to the end.
    let (header, rows) = read_csv(&out.join("samples.csv"));
    for c in [
        "t_s",
        "tip_x_m",
        "tip_y_m",
        "theta1_rad",
        "theta2_rad",
        "theta3_rad",
        "theta1_rate_rad_s",
        "attitude_rad",
        "torque1_nm",
        "digging_force_x_n",
        "digging_force_y_n",
        "digging_force_magnitude_n",
        "load_kg",
        "swept_volume_m3",
        "segment",
        "kind",
        "contact",
    ] {
        assert!(
            header.iter().any(|h| h == c),
            "samples.csv lacks {c}: {header:?}"
        );
    }
    assert_eq!(rows.len() as u64, s["samples"].as_u64().unwrap());
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let f = |row: &Vec<String>, name: &str| -> f64 { row[col(name)].parse().unwrap() };
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    assert_eq!(f(first, "t_s"), 0.0);
    assert!((f(first, "tip_x_m") - number(&scenario, "start_x_m")).abs() < 1e-9);
    assert!(f(first, "tip_y_m").abs() < 1e-9);
    assert!((f(last, "t_s") - f64_field(&s, "duration_s")).abs() < 1e-9);
    let end = pair(&s["final_tip_m"]);
    assert!((f(last, "tip_x_m") - end[0]).abs() < 1e-9);
    assert!(
        f(last, "tip_y_m").abs() < 1e-6,
        "the dig ends on the ground"
    );
    // φ = θ1 + θ2 + θ3 on every sample; no sample inside the boulder; no
    // joint faster than its speed limit between two samples; the largest
    // force is the summary's peak.
    let limits =
        ["boom_deg_s", "stick_deg_s", "bucket_deg_s"].map(|k| number(&profile, k).to_radians());
    let (centre, r) = boulders(&scenario)[0];
    let mut peak: f64 = 0.0;
    for (i, row) in rows.iter().enumerate() {
        let q = ["theta1_rad", "theta2_rad", "theta3_rad"].map(|c| f(row, c));
        assert!((q.iter().sum::<f64>() - f(row, "attitude_rad")).abs() < 1e-9);
        let d = (f(row, "tip_x_m") - centre[0]).hypot(f(row, "tip_y_m") - centre[1]);
        assert!(d >= r - 1e-9, "sample {i} is inside the boulder: {d} < {r}");
        peak = peak.max(f(row, "digging_force_magnitude_n"));
        if i > 0 {
            let prev = &rows[i - 1];
            let dt = f(row, "t_s") - f(prev, "t_s");
            for (j, c) in ["theta1_rad", "theta2_rad", "theta3_rad"]
                .iter()
                .enumerate()
            {
                let step = (f(row, c) - f(prev, c)).abs();
                assert!(
                    step <= limits[j] * dt + 1e-9,
                    "sample {i}: {c} steps {step} in {dt} s"
                );
            }
        }
    }
    assert!((peak - f64_field(&s, "peak_digging_force_n")).abs() < 1e-6);
    // The contact sample is at the contact point, and the force jumps there.
    let contact = &s["contacts"][0];
    let hit: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| r[col("contact")] == "true")
        .collect();
    assert_eq!(hit.len(), 1);
    let p = pair(&contact["point_m"]);
    assert!((f(hit[0], "tip_x_m") - p[0]).abs() < 1e-9);
    assert!((f(hit[0], "tip_y_m") - p[1]).abs() < 1e-9);
    assert!(f(hit[0], "digging_force_magnitude_n") >= number(&profile, "max_digging_force_n"));
    // Passed under: where the path after the contact crosses the boulder's
    // vertical centre line, it is below the boulder.
    let t_c = f64_field(contact, "t_s");
    let crossing = rows
        .windows(2)
        .filter(|w| f(&w[0], "t_s") >= t_c)
        .find(|w| (f(&w[0], "tip_x_m") - centre[0]) * (f(&w[1], "tip_x_m") - centre[0]) <= 0.0)
        .expect("the path passes the boulder");
    assert!(
        f(&crossing[0], "tip_y_m") < centre[1] - r,
        "not under the boulder"
    );
    // contacts.csv: the summary's contacts.
    let (header, rows) = read_csv(&out.join("contacts.csv"));
    assert_eq!(rows.len(), 1);
    let c = |name: &str| &rows[0][header.iter().position(|h| h == name).unwrap()];
    assert_eq!(c("decision"), "under");
    assert_eq!(c("t_s").parse::<f64>().unwrap(), t_c);
    assert_eq!(
        c("gamma_deg").parse::<f64>().unwrap(),
        f64_field(contact, "gamma_deg")
    );
    // planned_path.csv: the level-1 plan from the start to its end point.
    let (_, plan) = read_csv(&out.join("planned_path.csv"));
    let xy = |r: &Vec<String>| [r[0].parse::<f64>().unwrap(), r[1].parse::<f64>().unwrap()];
    let level1_end = pair(&s["level1_end_m"]);
    assert!((xy(&plan[0])[0] - number(&scenario, "start_x_m")).abs() < 1e-9);
    let e = xy(&plan[plan.len() - 1]);
    assert!((e[0] - level1_end[0]).abs() < 1e-9 && (e[1] - level1_end[1]).abs() < 1e-9);
}

/// The summary without what names where the inputs came from or the wall time.
fn comparable(s: &Value) -> Value {
    let mut v = without_timing(s);
    let o = v.as_object_mut().unwrap();
    o.remove("scenario_source");
    o.remove("profile");
    v
}

#[test]
fn printed_scenario_and_profile_round_trip_to_the_same_plan() {
    let dir = TempDir::new("plan-excavate-round-trip");
    let builtin = run(&["plan-excavate", "--scenario", "paper-under", "--json"])
        .ok()
        .json();
    // The commented built-in, loaded from a file.
    let file = dir.write("under.toml", scenario_text("paper-under"));
    let from_file = run(&cmd(&[
        "--scenario".as_ref(),
        file.as_os_str(),
        "--json".as_ref(),
    ]))
    .ok()
    .json();
    assert_eq!(comparable(&from_file), comparable(&builtin));
    assert_eq!(from_file["scenario_source"], file.display().to_string());
    assert_eq!(builtin["scenario_source"], "builtin");
    // A loaded file printed back (`to_toml`, no comments) plans the same.
    let printed = run(&cmd(&[
        "--print-scenario".as_ref(),
        "--scenario".as_ref(),
        file.as_os_str(),
    ]))
    .ok()
    .stdout;
    assert!(
        !printed.contains('#'),
        "to_toml has no comments:\n{printed}"
    );
    let again = dir.write("again.toml", &printed);
    let from_again = run(&cmd(&[
        "--scenario".as_ref(),
        again.as_os_str(),
        "--json".as_ref(),
    ]))
    .ok()
    .json();
    assert_eq!(comparable(&from_again), comparable(&builtin));
    // The profile likewise.
    let profile = dir.write("machine.toml", profile_text());
    let with_profile = run(&cmd(&[
        "--scenario".as_ref(),
        "paper-under".as_ref(),
        "--profile".as_ref(),
        profile.as_os_str(),
        "--json".as_ref(),
    ]))
    .ok()
    .json();
    assert_eq!(comparable(&with_profile), comparable(&builtin));
    assert_eq!(with_profile["profile"], profile.display().to_string());
    let printed = run(&cmd(&[
        "--print-profile".as_ref(),
        "--profile".as_ref(),
        profile.as_os_str(),
    ]))
    .ok()
    .stdout;
    assert_eq!(
        number(&printed, "boom_length_m"),
        number(&profile_text(), "boom_length_m")
    );
}

/// The example file of the library.
fn two_boulders_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../hydraulic-excavator/excavator-dig/scenarios/two-boulders.toml")
}

#[test]
fn the_two_boulder_file_meets_both() {
    let file = two_boulders_file();
    let text = std::fs::read_to_string(&file).expect("the example file");
    let s = run(&cmd(&[
        "--scenario".as_ref(),
        file.as_os_str(),
        "--json".as_ref(),
    ]))
    .ok()
    .json();
    check_summary(&s, &text, &profile_text());
    let contacts = s["contacts"].as_array().unwrap();
    assert_eq!(contacts.len(), 2, "{s:#}");
    let met: Vec<u64> = contacts
        .iter()
        .map(|c| c["obstacle"].as_u64().unwrap())
        .collect();
    assert_eq!(met, [0, 1], "each boulder met once, the nearer first");
    assert_eq!(s["avoid_directions"].as_array().unwrap().len(), 2);
    assert_eq!(s["detours"].as_array().unwrap().len(), 2);
}

#[test]
fn broken_or_impossible_scenarios_are_refused_by_name() {
    let dir = TempDir::new("plan-excavate-bad");
    let over = scenario_text("paper-over");
    let under = scenario_text("paper-under");
    let out = dir.path().join("never");
    // (file, text, what the message must hold; the line of the key if named)
    let cases: [(&str, String, &[&str], Option<&str>); 7] = [
        (
            "negative.toml",
            replace_once(&over, "radius_m = 0.25", "radius_m = -0.25"),
            &["radius_m", "-0.25", "[[obstacle]] #1"],
            Some("radius_m = -0.25"),
        ),
        (
            "missing.toml",
            {
                let line = over.lines().find(|l| l.starts_with("depth_m")).unwrap();
                replace_once(&over, &format!("{line}\n"), "")
            },
            &["missing.toml", "depth_m"],
            None,
        ),
        (
            "enclosing.toml",
            replace_once(&over, "center_m = [6.64, -0.60]", "center_m = [7.0, -0.1]").replacen(
                "radius_m = 0.25",
                "radius_m = 0.3",
                1,
            ),
            &["encloses the dig start", "obstacle 0"],
            None,
        ),
        (
            "far.toml",
            replace_once(&over, "start_x_m = 7.0", "start_x_m = 9.5"),
            &["out of reach", "(9.500, 0.000)"],
            None,
        ),
        (
            "big.toml",
            replace_once(&over, "target_volume_m3 = 0.9", "target_volume_m3 = 12.0"),
            &["target volume cannot be dug"],
            None,
        ),
        (
            "impassable.toml",
            // A planner that assumes 0.45 m boulders cannot pass under one
            // met low near the far end of the reach.
            replace_once(
                &replace_once(
                    &under,
                    "center_m = [6.10, -0.45]",
                    "center_m = [6.6, -0.50]",
                ),
                "max_overdig_m = 0.15",
                "boulder_radius_m = 0.45\nmax_overdig_m = 0.15",
            ),
            &["cannot pass obstacle 0 under", "stick"],
            None,
        ),
        (
            "zero-step.toml",
            replace_once(&over, "step_m = 0.05", "step_m = 0.0"),
            &["[dig] step_m = 0", "(0, 0.5]"],
            Some("step_m = 0.0"),
        ),
    ];
    for (name, text, needles, key_line) in cases {
        let file = dir.write(name, &text);
        let r = run(&cmd(&[
            "--scenario".as_ref(),
            file.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--json".as_ref(),
        ]))
        .fails();
        let msg = r.error_message();
        for n in needles {
            assert!(msg.contains(n), "{name}: `{n}` not in: {msg}");
        }
        if let Some(key) = key_line {
            let line = text
                .lines()
                .position(|l| l.trim_start().starts_with(key))
                .unwrap()
                + 1;
            assert!(
                msg.contains(&format!("{}:{line}:", file.display())),
                "{name}: the file and line {line} not in: {msg}"
            );
        }
        assert!(
            r.stdout.is_empty(),
            "{name}: no summary on failure: {}",
            r.stdout
        );
        assert!(
            !out.exists(),
            "{name}: --out is not created for a failed plan"
        );
    }
    // Unknown names and missing files.
    let r = run(&["plan-excavate", "--scenario", "paper-sideways"]).fails();
    assert!(
        r.error_message().contains("paper-over"),
        "{}",
        r.error_message()
    );
    let r = run(&["plan-excavate", "--scenario", "/nonexistent/dig.toml"]).fails();
    assert!(
        r.error_message().contains("/nonexistent/dig.toml"),
        "{}",
        r.error_message()
    );
    // A broken profile: the file, the line and the key.
    let profile = profile_text();
    let line = profile
        .lines()
        .find(|l| l.starts_with("boom_length_m"))
        .unwrap();
    let bad = replace_once(&profile, line, "boom_length_m = -4.6");
    let file = dir.write("machine.toml", &bad);
    let at = bad
        .lines()
        .position(|l| l.starts_with("boom_length_m"))
        .unwrap()
        + 1;
    for print in [false, true] {
        let mut args = cmd(&["--profile".as_ref(), file.as_os_str()]);
        if print {
            args.push("--print-profile".as_ref());
        }
        let r = run(&args).fails();
        let msg = r.error_message();
        assert!(
            msg.contains(&format!("{}:{at}:", file.display())) && msg.contains("boom_length_m"),
            "{msg}"
        );
        assert!(r.stdout.is_empty());
    }
}
