//! `autoshovel study-paths` (seeded, so repeatable) and `autoshovel demo`.

mod common;

use common::*;
use serde_json::Value;

fn study(seed: &str) -> Value {
    let r = run(&["study-paths", "--maps", "20", "--seed", seed, "--json"]).ok();
    assert!(
        r.stderr.is_empty(),
        "--json: no progress bar or other text on stderr expected:\n{}",
        r.stderr
    );
    r.json()
}

#[test]
fn study_is_repeatable_for_a_seed() {
    let a = study("3");
    let b = study("3");
    assert_eq!(a["job"], "study-paths");
    assert_eq!(a["maps"], 20);
    assert_eq!(a["seed"], 3);
    assert_eq!(a["success"], true);
    let names: Vec<&str> = a["planners"]
        .as_array()
        .expect("planners")
        .iter()
        .map(|p| p["planner"].as_str().expect("planner name"))
        .collect();
    assert_eq!(names, ["apf", "improved-apf"]);
    let solved = a["reference"]["solved"].as_u64().expect("reference.solved");
    assert!(solved <= 20, "{solved}");
    for (pa, pb) in a["planners"]
        .as_array()
        .expect("planners")
        .iter()
        .zip(b["planners"].as_array().expect("planners"))
    {
        let name = &pa["planner"];
        for k in [
            "success_pct",
            "reached_pct",
            "local_minima",
            "maps",
            "mean_length_ratio",
            "max_final_heading_error_deg",
        ] {
            assert_eq!(
                pa[k], pb[k],
                "{name}.{k} differs between two runs with --seed 3"
            );
        }
        let pct = f64_field(pa, "success_pct");
        assert!((0.0..=100.0).contains(&pct), "{name}: success_pct {pct}");
        assert_eq!(
            pa["maps"].as_u64(),
            Some(solved),
            "{name}: judged over the maps the reference solves"
        );
    }
    assert_eq!(a["reference"]["solved"], b["reference"]["solved"]);
    // Everything but the wall-clock timings is identical.
    assert_eq!(without_timing(&a), without_timing(&b));
    // The improved field beats the classic one on these roads (README table).
    let pct = |v: &Value, i: usize| f64_field(&v["planners"][i], "success_pct");
    assert!(
        pct(&a, 1) > pct(&a, 0),
        "improved {} % vs classic {} %",
        pct(&a, 1),
        pct(&a, 0)
    );
}

#[test]
fn study_out_dir_gets_csv_summary_and_plot() {
    let dir = TempDir::new("study-out");
    let r = run(&[
        "study-paths".as_ref(),
        "--maps".as_ref(),
        "5".as_ref(),
        "--seed".as_ref(),
        "7".as_ref(),
        "--json".as_ref(),
        "--out".as_ref(),
        dir.path().as_os_str(),
    ])
    .ok();
    let printed = r.json();
    let csv = std::fs::read_to_string(dir.path().join("maps.csv")).expect("maps.csv");
    let mut lines = csv.lines();
    assert!(lines
        .next()
        .expect("header")
        .starts_with("map,obstacles,reference_length_m,apf_success,"));
    assert_eq!(lines.count(), 5, "one row per map");
    let summary: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("summary.json")).expect("summary.json"),
    )
    .expect("summary JSON");
    assert_eq!(summary, printed, "--json prints what summary.json holds");
    for f in ["success_by_obstacles.svg", "success_by_obstacles.png"] {
        assert!(dir.path().join(f).is_file(), "{f} missing");
    }
}

#[test]
fn study_refuses_zero_maps_and_bad_obstacle_ranges() {
    for json in [false, true] {
        let mut args = vec!["study-paths", "--maps", "0"];
        if json {
            args.push("--json");
        }
        let r = run(&args).fails();
        assert_eq!(r.error_message(), "--maps 0 must be between 1 and 1000000");
        assert!(r.stdout.is_empty(), "{}", r.stdout);
    }
    let r = run(&[
        "study-paths",
        "--maps",
        "3",
        "--min-obstacles",
        "5",
        "--max-obstacles",
        "2",
    ])
    .fails();
    assert!(
        r.error_message()
            .starts_with("--min-obstacles 5 and --max-obstacles 2"),
        "{}",
        r.stderr
    );
    let r = run(&["study-paths", "--maps", "3", "--max-obstacles", "61"]).fails();
    assert!(
        r.error_message().contains("--max-obstacles 61"),
        "{}",
        r.stderr
    );
}

// `demo` plans six scenarios, a 100-map study, five rope-shovel digs,
// three excavator digs and a 45-minute shift: about 4 s in release, roughly 10–15 s in the test
// profile (opt-level 1, dependencies at 2).
#[test]
fn demo_writes_index_and_summary() {
    let dir = TempDir::new("demo");
    let out = dir.path().join("report");
    let r = run_with_timeout(
        &["demo".as_ref(), "--out".as_ref(), out.as_os_str()],
        std::time::Duration::from_secs(120),
    )
    .ok();
    assert!(
        r.stdout
            .contains(&format!("report: {}", out.join("index.html").display())),
        "{}",
        r.stdout
    );
    let index = std::fs::read_to_string(out.join("index.html")).expect("index.html");
    assert!(
        index.contains("plan-path curve improved-apf"),
        "index.html should have the curve section"
    );
    assert!(
        index.contains("study-paths"),
        "index.html should have the study section"
    );
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    assert!(
        text.contains("plan-path curve improved-apf"),
        "summary.json should mention `plan-path curve improved-apf`"
    );
    let s = parse_one_json(&text).expect("summary.json is JSON");
    assert_eq!(s["job"], "demo");
    let jobs = s["jobs"].as_object().expect("jobs object");
    let mut keys: Vec<&str> = jobs.keys().map(|k| k.as_str()).collect();
    keys.sort();
    assert_eq!(
        keys,
        [
            "drive fig9a over OPC UA",
            "perceive convex-concave pile",
            "perceive typical pile",
            "plan-dig --all-surfaces",
            "plan-dig typical",
            "plan-excavate paper-over",
            "plan-excavate paper-under",
            "plan-excavate two-boulders",
            "plan-path curve apf",
            "plan-path curve improved-apf",
            "plan-path curve-reverse improved-apf",
            "plan-path straight improved-apf",
            "plan-path v-shape apf",
            "plan-path v-shape improved-apf",
            "shift",
            "study-paths",
            "track curve --compare",
            "track curve fuzzy",
            "track fig9a fuzzy",
            "track fig9b fuzzy",
            "track straight fuzzy",
            "track v-shape fuzzy"
        ]
    );
    for key in [
        "track fig9a fuzzy",
        "track fig9b fuzzy",
        "track straight fuzzy",
        "track curve fuzzy",
        "track v-shape fuzzy",
    ] {
        assert_eq!(jobs[key]["success"], true, "{key}");
        assert!(
            jobs[key]["max_centroid_dev_m"].as_f64().unwrap() <= 0.10,
            "{key}"
        );
    }
    // The run over the link repeats the in-process run (lockstep).
    let (link, local) = (&jobs["drive fig9a over OPC UA"], &jobs["track fig9a fuzzy"]);
    assert_eq!(link["success"], true);
    assert_eq!(link["link"]["policy"], "basic256-sha256");
    let dev = |v: &serde_json::Value| v["max_centroid_dev_m"].as_f64().unwrap();
    assert!((dev(link) - dev(local)).abs() < 1e-6, "{link} vs {local}");
    assert!(out.join("drive-fig9a").join("drive.mcap").exists());
    assert_eq!(
        jobs["track curve --compare"]["compare"]
            .as_array()
            .map(|a| a.len()),
        Some(4)
    );
    assert_eq!(jobs["plan-path curve improved-apf"]["success"], true);
    assert_eq!(jobs["plan-path curve apf"]["success"], false);
    assert_eq!(jobs["plan-path curve apf"]["local_minimum"], true);
    assert_eq!(jobs["study-paths"]["maps"], 100);
    // The short shift digs from more than one stand, walks, and its mass
    // balance closes.
    let shift = &jobs["shift"];
    assert!(shift["stands"].as_u64().unwrap() >= 2, "{shift}");
    assert!(shift["walks"].as_u64().unwrap() >= 1, "{shift}");
    assert_eq!(shift["mass_balance"]["closes"], true);
    assert!(out.join("shift").join("animation.html").is_file());
    assert_eq!(jobs["plan-dig typical"]["feasible"], true);
    let piles: Vec<&str> = jobs["plan-dig --all-surfaces"]["surfaces"]
        .as_array()
        .expect("surfaces")
        .iter()
        .map(|p| p["surface"].as_str().expect("surface name"))
        .collect();
    assert_eq!(piles, ["typical", "concave", "convex", "convex-concave"]);
    for (name, sides) in [
        ("paper-over", &["over"][..]),
        ("paper-under", &["under"][..]),
        ("two-boulders", &["over", "over"][..]),
    ] {
        let job = &jobs[format!("plan-excavate {name}").as_str()];
        assert_eq!(job["scenario"], name);
        assert_eq!(job["avoid_directions"], serde_json::json!(sides), "{name}");
    }
    // Each job's plots are where the index links them.
    for sub in [
        "plan-path-curve-improved-apf/path.png",
        "plan-path-curve-improved-apf/profile.svg",
        "study-paths/maps.csv",
        "plan-dig-typical/dig_path.svg",
        "plan-dig-all-surfaces/paths.svg",
        "plan-dig-all-surfaces/table.csv",
        "plan-excavate-paper-over/tooth_path.svg",
        "plan-excavate-paper-under/digging_force.png",
        "plan-excavate-two-boulders/contacts.csv",
    ] {
        assert!(out.join(sub).is_file(), "{sub} missing");
        assert!(index.contains(sub), "index.html should link {sub}");
    }
}

/// The time-limit helper itself: a run that outlives its limit is killed and
/// fails the test (so a hang in any other test cannot go unnoticed).
#[test]
#[should_panic(expected = "did not finish within")]
fn timeout_helper_kills_a_slow_run() {
    run_with_timeout(
        &["study-paths", "--maps", "100000", "--json"],
        std::time::Duration::from_millis(200),
    );
}

#[test]
fn the_boulder_study_is_repeatable_and_writes_its_cases() {
    let dir = TempDir::new("boulders-out");
    let go = |out: Option<&std::path::Path>| {
        let mut a: Vec<&std::ffi::OsStr> =
            ["study-boulders", "--cases", "8", "--seed", "5", "--json"]
                .iter()
                .map(|s| s.as_ref())
                .collect();
        if let Some(d) = out {
            a.extend(["--out".as_ref(), d.as_os_str()]);
        }
        run(&a).ok().json()
    };
    let printed = go(Some(dir.path()));
    let mut without_files = printed.clone();
    without_files.as_object_mut().unwrap().remove("files");
    assert_eq!(without_files, go(None), "same seed, same study");
    assert_eq!(printed["job"], "study-boulders");
    let planners: Vec<&str> = printed["planners"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["planner"].as_str().unwrap())
        .collect();
    assert_eq!(planners, ["class prior", "true size"]);
    let csv = std::fs::read_to_string(dir.path().join("cases.csv")).expect("cases.csv");
    assert!(csv.starts_with("case,center_x_m,center_y_m,radius_m,class_prior_completed,"));
    assert_eq!(csv.lines().count(), 9, "a header and one row per boulder");
    for f in [
        "volume_error_by_radius.svg",
        "volume_error_by_radius.png",
        "summary.json",
    ] {
        assert!(dir.path().join(f).is_file(), "{f} missing");
    }
    let r = run(&["study-boulders", "--cases", "0"]).fails();
    assert!(
        r.error_message().contains("--cases 0"),
        "{}",
        r.error_message()
    );
    let r = run(&[
        "study-boulders",
        "--min-radius",
        "0.6",
        "--max-radius",
        "0.5",
    ])
    .fails();
    assert!(
        r.error_message().contains("--min-radius 0.6"),
        "{}",
        r.error_message()
    );
}
