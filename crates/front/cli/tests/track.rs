//! `autoshovel track`: the paper's cases, the comparison, the outputs and bad input.

mod common;

use common::*;

fn track_file(body: &str) -> (TempDir, std::path::PathBuf) {
    let dir = TempDir::new("track");
    let path = dir.write("run.toml", body);
    (dir, path)
}

const GOOD: &str = "name = \"mine\"\nspeed_mps = 0.5\nnoise = \"rtk\"\n[start]\nx_m = 0.0\ny_m = 0.3\nheading_deg = 0.0\n[[leg]]\ndirection = \"forward\"\npoints_m = [[0.0, 0.0], [10.0, 0.0], [20.0, 3.0]]\n";

#[test]
fn fig9_cases_meet_the_paper() {
    for name in ["fig9a", "fig9b"] {
        let s = run(&["track", "--scenario", name, "--json"]).ok().json();
        for key in [
            "max_centroid_dev_m",
            "mean_centroid_dev_m",
            "convergence_distance_m",
            "final_heading_error_deg",
            "final_position_error_m",
        ] {
            assert!(s[key].is_number(), "{name}: {key} missing: {s:#}");
        }
        assert!(f64_field(&s, "reached_distance_m") <= 5.0, "{name}: {s:#}");
        assert_eq!(s["noise"], "off");
        // Speed is measured by the criterion benches, not asserted here: the
        // factor only has to be reported.
        assert!(f64_field(&s, "realtime_factor") > 0.0, "{name}: {s:#}");
    }
}

#[test]
fn compare_runs_every_controller_on_the_same_seed_and_writes_the_table() {
    let dir = TempDir::new("compare");
    let out = dir.path().join("out");
    let s = run(&[
        "track".as_ref(),
        "--scenario".as_ref(),
        "straight".as_ref(),
        "--compare".as_ref(),
        "--json".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ])
    .ok()
    .json();
    let rows = s["compare"].as_array().expect("compare rows");
    let names: Vec<&str> = rows
        .iter()
        .map(|r| r["controller"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["fuzzy", "pid", "pure-pursuit", "stanley"]);
    for f in [
        "summary.json",
        "compare.csv",
        "track_fuzzy.csv",
        "track_pid.csv",
        "track_pure-pursuit.csv",
        "track_stanley.csv",
        "track_path.svg",
        "track_path.png",
        "track_deviation_heading.svg",
        "fuzzy_surface.csv",
        "fuzzy_surface.svg",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let csv = std::fs::read_to_string(out.join("compare.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "{csv}");
    // Same seed, same fuzzy numbers as a run on its own.
    let alone = run(&["track", "--scenario", "straight", "--json"])
        .ok()
        .json();
    assert_eq!(alone["max_centroid_dev_m"], rows[0]["max_centroid_dev_m"]);
}

#[test]
fn a_users_tracking_file_and_a_plan_path_file_both_run() {
    let (_d, p) = track_file(GOOD);
    let s = run(&[
        "track".as_ref(),
        "--scenario".as_ref(),
        p.as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    assert_eq!(s["scenario"], "mine");
    assert_eq!(s["noise"], "rtk");
    assert!(f64_field(&s, "max_centroid_dev_m") < 0.3);
    let dir = TempDir::new("travel");
    let travel = dir.write("road.toml", builtin_text("curve"));
    let s = run(&[
        "track".as_ref(),
        "--scenario".as_ref(),
        travel.as_os_str(),
        "--controller".as_ref(),
        "pid".as_ref(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    assert_eq!(s["controller"], "pid");
}

#[test]
fn bad_tracking_input_is_refused_clearly() {
    let cases: [(&str, String, &str); 7] = [
        (
            "one point",
            GOOD.replace("[[0.0, 0.0], [10.0, 0.0], [20.0, 3.0]]", "[[0.0, 0.0]]"),
            "needs at least 2",
        ),
        (
            "repeated",
            GOOD.replace(
                "[[0.0, 0.0], [10.0, 0.0], [20.0, 3.0]]",
                "[[0.0, 0.0], [10.0, 0.0], [10.0, 0.0]]",
            ),
            "repeats point",
        ),
        (
            "far start",
            GOOD.replace("y_m = 0.3", "y_m = 300.0"),
            "from the first leg",
        ),
        (
            "nan",
            GOOD.replace("y_m = 0.3", "y_m = nan"),
            "not a finite number",
        ),
        (
            "zero gauge",
            format!("{GOOD}[crawler]\ngauge_m = 0.0\n"),
            "gauge_m = 0",
        ),
        (
            "negative limit",
            format!("{GOOD}[crawler]\nmotor_max_rpm = -5.0\n"),
            "motor_max_rpm = -5",
        ),
        (
            "too fast",
            GOOD.replace("speed_mps = 0.5", "speed_mps = 9.0"),
            "speed limit",
        ),
    ];
    for (what, text, expect) in cases {
        let (_d, p) = track_file(&text);
        let r = run(&["track".as_ref(), "--scenario".as_ref(), p.as_os_str()]).fails();
        assert!(
            r.error_message().contains(expect),
            "{what}: {}",
            r.error_message()
        );
        assert!(
            r.error_message().contains("run.toml"),
            "{what}: the file is not named: {}",
            r.error_message()
        );
    }
    let r = run(&["track", "--scenario", "nosuch"]).fails();
    assert!(r.error_message().contains("fig9a"), "{}", r.error_message());
}

#[test]
fn scenario_gains_change_the_run_and_the_summary_reports_them() {
    let (_d, plain) = track_file(GOOD);
    let args = |p: &std::path::Path| -> Vec<std::ffi::OsString> {
        ["track", "--scenario"]
            .iter()
            .map(Into::into)
            .chain([
                p.as_os_str().to_owned(),
                "--compare".into(),
                "--json".into(),
            ])
            .collect()
    };
    let base = run(&args(&plain)).ok().json();
    assert_eq!(base["gains"]["k1"], 2.42, "{base:#}");
    assert_eq!(base["params"]["pid"]["kp"], 800.0);
    let tuned = format!(
        "{GOOD}[controller.fuzzy]\nk1 = 1.2\n[controller.pid]\nkp = 400.0\n\
         [controller.pure_pursuit]\nlookahead_m = 3.0\n[controller.stanley]\nk_per_s = 2.5\n"
    );
    let (_d2, p) = track_file(&tuned);
    let s = run(&args(&p)).ok().json();
    // The summary reports the gains each controller ran with, the others at
    // their defaults.
    assert_eq!(s["gains"]["k1"], 1.2, "{s:#}");
    assert_eq!(s["gains"]["k2"], 32.1);
    assert_eq!(s["params"]["fuzzy"]["k1"], 1.2);
    assert_eq!(s["params"]["pid"]["kp"], 400.0);
    assert_eq!(s["params"]["pure_pursuit"]["lookahead_m"], 3.0);
    let rows = s["compare"].as_array().expect("compare rows");
    assert_eq!(rows[0]["gains"]["k1"], 1.2);
    assert_eq!(rows[1]["gains"]["kp"], 400.0);
    assert_eq!(rows[1]["gains"]["ki"], 100.0);
    assert_eq!(rows[2]["gains"]["lookahead_m"], 3.0);
    assert_eq!(rows[3]["gains"]["k_per_s"], 2.5);
    // ... and every controller's run changes with its gains.
    let before = base["compare"].as_array().expect("compare rows");
    for (i, (a, b)) in before.iter().zip(rows).enumerate() {
        assert_ne!(
            a["mean_centroid_dev_overall_m"], b["mean_centroid_dev_overall_m"],
            "row {i}: {a:#} vs {b:#}"
        );
    }
}

#[test]
fn a_bad_gain_is_refused_naming_its_key_and_line() {
    for (table, key, value, line) in [
        ("fuzzy", "k2", "-1.0", 12),
        ("pid", "kd", "nan", 12),
        ("pure_pursuit", "max_steer_rpm", "0.0", 12),
    ] {
        let text = format!("{GOOD}[controller.{table}]\nalpha_or_other = 1\n");
        // An unknown key is refused with its line too.
        let (_d, p) = track_file(&text);
        let r = run(&["track".as_ref(), "--scenario".as_ref(), p.as_os_str()]).fails();
        assert!(
            r.error_message().contains("run.toml:12")
                && r.error_message().contains("alpha_or_other"),
            "{}",
            r.error_message()
        );
        let text = format!("{GOOD}[controller.{table}]\n{key} = {value}\n");
        let (_d, p) = track_file(&text);
        let r = run(&["track".as_ref(), "--scenario".as_ref(), p.as_os_str()]).fails();
        let msg = r.error_message();
        assert!(
            msg.contains(&format!("run.toml:{line}"))
                && msg.contains(&format!("[controller.{table}] {key}")),
            "{table} {key}: {msg}"
        );
    }
}
