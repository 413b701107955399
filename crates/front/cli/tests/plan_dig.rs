//! `autoshovel plan-dig`: the summary's fields and their identities, the
//! seed, the files of `--out`, the machine profile's round trip and its
//! errors, `--all-surfaces` against the paper's tables, and `--cloud` on a
//! scan from `generate-pile`.
//!
//! Every plan runs the optimiser in full (50 wolves, 100 iterations); the
//! tests share as few plans as they can.

mod common;

use std::path::Path;

use common::*;
use serde_json::Value;

/// The constraint names of the planner, c1–c18.
const CONSTRAINTS: [&str; 18] = autoshovel_rope_shovel_dig::CONSTRAINT_NAMES;

/// The built-in profile as `--print-profile` prints it.
fn builtin_profile() -> String {
    let r = run(&["plan-dig", "--print-profile"]).ok();
    assert!(r.stdout.contains("[limits]"), "{}", r.stdout);
    r.stdout
}

/// The value of `key = value` in a profile text (first occurrence).
#[track_caller]
fn profile_value(text: &str, key: &str) -> f64 {
    text.lines()
        .find_map(|l| {
            let (k, v) = l.split_once('=')?;
            (k.trim() == key).then(|| v.split('#').next().unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| panic!("no `{key} =` in the profile"))
        .parse()
        .unwrap_or_else(|e| panic!("`{key}` is not a number: {e}"))
}

/// The profile with the line of `key` replaced by `key = value`.
#[track_caller]
fn with_value(text: &str, key: &str, value: &str) -> String {
    let line = text
        .lines()
        .find(|l| l.split_once('=').map(|(k, _)| k.trim()) == Some(key))
        .unwrap_or_else(|| panic!("no `{key} =` in the profile"));
    replace_once(text, line, &format!("{key} = {value}"))
}

/// The profile without the line of `key`.
#[track_caller]
fn without_key(text: &str, key: &str) -> String {
    let line = text
        .lines()
        .find(|l| l.split_once('=').map(|(k, _)| k.trim()) == Some(key))
        .unwrap_or_else(|| panic!("no `{key} =` in the profile"));
    replace_once(text, &format!("{line}\n"), "")
}

/// Checks a feasible plan's summary: every SPEC field, the constraints, and
/// the identities between the fields (eqs. 25–29).
#[track_caller]
fn check_plan(s: &Value, profile: &str) {
    for key in [
        "ax6",
        "ay6",
        "td_s",
        "gx_m",
        "gy_m",
        "f",
        "f1_j_per_kg",
        "f2_s_per_kg",
        "m_dig_kg",
        "fill_factor",
        "plan_time_ms",
        "volume_m3",
        "hoist_energy_j",
        "crowd_energy_j",
        "k_f_pa",
        "epsilon",
    ] {
        f64_field(s, key);
    }
    assert_eq!(s["job"], "plan-dig");
    assert_eq!(s["feasible"], true, "{s:#}");
    assert_eq!(s["success"], true, "{s:#}");
    assert!(
        s["surface"].is_string() && s["profile"].is_string(),
        "{s:#}"
    );
    assert!(s["seed"].is_u64() && s["search_space"].is_string(), "{s:#}");
    assert_eq!(
        s["evaluations"],
        50 * 101 + 20_000,
        "50 wolves, 100 iterations + the first pack, then a CMA-ES polish of 20 000"
    );
    let fill = f64_field(s, "fill_factor");
    let td = f64_field(s, "td_s");
    assert!((0.9..=1.1).contains(&fill), "fill {fill}");
    assert!((9.0..=15.0).contains(&td), "t_d {td}");
    // The identities of [RS eq. 25]–[RS eq. 29] on the numbers the summary reports.
    let (m, v) = (f64_field(s, "m_dig_kg"), f64_field(s, "volume_m3"));
    let close = |a: f64, b: f64, what: &str| {
        assert!(
            (a - b).abs() <= 1e-9 * b.abs().max(1.0),
            "{what}: {a} vs {b}"
        )
    };
    close(m, profile_value(profile, "density_kg_m3") * v, "m_dig = ρV");
    close(
        fill,
        v / profile_value(profile, "capacity_m3"),
        "fill = V/V_cd",
    );
    close(f64_field(s, "f2_s_per_kg"), td / m, "f2 = t_d/m_dig");
    let energy = f64_field(s, "hoist_energy_j") + f64_field(s, "crowd_energy_j");
    close(f64_field(s, "f1_j_per_kg"), energy / m, "f1 = E/m_dig");
    let (k1, k2) = (profile_value(profile, "k1"), profile_value(profile, "k2"));
    close(
        f64_field(s, "f"),
        k1 * f64_field(s, "f1_j_per_kg") + k2 * f64_field(s, "f2_s_per_kg"),
        "f = k1 f1 + k2 f2",
    );
    assert_eq!(
        f64_field(s, "k_f_pa"),
        profile_value(profile, "cutting_resistance_pa")
    );
    assert_eq!(
        f64_field(s, "epsilon"),
        profile_value(profile, "fill_resistance_ratio")
    );
    // Every constraint met, with its measured quantity on the right side of its limit.
    let cs = s["constraints"].as_object().expect("constraints object");
    assert_eq!(cs.len(), 18, "{cs:?}");
    for name in CONSTRAINTS {
        let c = &cs[name];
        assert!(f64_field(c, "value") <= 0.0, "{name}: {c}");
        assert_eq!(c["met"], true, "{name}: {c}");
        let (measured, limit) = (f64_field(c, "measured"), f64_field(c, "limit"));
        match c["bound"].as_str() {
            Some("min") => assert!(measured >= limit - 1e-12, "{name}: {c}"),
            Some("max") => assert!(measured <= limit + 1e-12, "{name}: {c}"),
            other => panic!("{name}: bound {other:?}"),
        }
    }
    let measured = |name: &str| f64_field(&cs[name], "measured");
    let limit = |name: &str| f64_field(&cs[name], "limit");
    close(measured("c1_fill_min"), fill, "c1 measures the fill");
    close(measured("c4_time_max"), td, "c4 measures t_d");
    close(
        measured("c16_hopper_clearance"),
        f64_field(s, "gy_m"),
        "c16 measures g_y",
    );
    close(
        limit("c1_fill_min"),
        profile_value(profile, "fill_min"),
        "c1 limit",
    );
    close(
        limit("c2_fill_max"),
        profile_value(profile, "fill_max"),
        "c2 limit",
    );
    close(
        limit("c11_hoist_force_max"),
        profile_value(profile, "hoist_force_max_n"),
        "c11 limit",
    );
    close(
        limit("c16_hopper_clearance"),
        profile_value(profile, "hopper_height_m") + profile_value(profile, "height_m"),
        "c16 limit = H_kk + H_cd",
    );
}

#[test]
fn json_summary_has_the_spec_fields_and_a_feasible_plan() {
    let profile = builtin_profile();
    let r = run(&["plan-dig", "--json"]).ok();
    let s = r.json();
    check_plan(&s, &profile);
    assert_eq!(s["surface"], "typical", "typical is the default");
    assert_eq!(s["seed"], 1);
    assert_eq!(s["search_space"], "bends");
    assert_eq!(s["init"], "good-point-set");
    assert_eq!(s["profile"], "builtin scale-model");
    assert!(s.get("files").is_none(), "no --out, no files: {s:#}");
}

#[test]
fn the_same_seed_gives_the_same_plan() {
    let plan = || {
        run(&[
            "plan-dig",
            "--surface",
            "convex",
            "--seed",
            "7",
            "--init",
            "random",
            "--json",
        ])
        .ok()
        .json()
    };
    let (a, b) = (plan(), plan());
    assert_eq!(a["surface"], "convex");
    assert_eq!(a["seed"], 7);
    assert_eq!(a["init"], "random");
    assert_eq!(a["feasible"], true, "{a:#}");
    // Everything but the wall-clock time is identical, to the last bit.
    assert_eq!(without_timing(&a), without_timing(&b));
    assert!(a.as_object().unwrap().contains_key("plan_time_ms"));
}

#[test]
fn printed_profile_round_trips_and_out_writes_every_file() {
    let dir = TempDir::new("plan-dig-out");
    let text = builtin_profile();
    let file = dir.write("profile.toml", &text);
    // The printed profile, checked and printed back, is the same profile.
    let back = run(&[
        "plan-dig".as_ref(),
        "--print-profile".as_ref(),
        "--profile".as_ref(),
        file.as_os_str(),
    ])
    .ok();
    for key in [
        "k1",
        "capacity_m3",
        "hoist_force_max_n",
        "fill_min",
        "samples",
    ] {
        assert_eq!(
            profile_value(&back.stdout, key),
            profile_value(&text, key),
            "{key}"
        );
    }
    let out = dir.path().join("out");
    let r = run(&[
        "plan-dig".as_ref(),
        "--profile".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--json".as_ref(),
    ])
    .ok();
    let s = r.json();
    check_plan(&s, &text);
    assert_eq!(s["profile"], file.display().to_string());
    // The same plan as with the built-in profile.
    let builtin = run(&["plan-dig", "--json"]).ok().json();
    for key in [
        "ax6",
        "ay6",
        "td_s",
        "gx_m",
        "gy_m",
        "f",
        "m_dig_kg",
        "constraints",
    ] {
        assert_eq!(s[key], builtin[key], "{key}");
    }
    // Files: the summary printed is the one written, and lists them all.
    assert_written(
        &out,
        &s,
        &[
            "summary.json",
            "samples.csv",
            "convergence.csv",
            "polish.csv",
            "surface.csv",
            "dig_path.svg",
            "dig_path.png",
            "speeds.svg",
            "speeds.png",
            "forces.svg",
            "forces.png",
            "convergence.svg",
            "convergence.png",
        ],
    );
    // samples.csv: every sample, from the toe (0, 0) at rest to (g_x, g_y) at t_d.
    let csv = std::fs::read_to_string(out.join("samples.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for col in [
        "t_s",
        "tip_x_m",
        "tip_y_m",
        "theta1_rad",
        "d2_m",
        "hoist_force_n",
        "crowd_force_n",
        "hoist_speed_m_s",
        "crowd_speed_m_s",
        "rope_handle_angle_rad",
        "resistance_tangential_n",
        "resistance_normal_n",
        "cut_thickness_m",
        "load_kg",
        "back_angle_rad",
    ] {
        assert!(header.contains(&col), "samples.csv lacks {col}: {header:?}");
    }
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len() as u64, s["samples"].as_u64().unwrap());
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    assert!(first[col("t_s")].abs() < 1e-12);
    assert!(first[col("tip_x_m")].abs() < 1e-9 && first[col("tip_y_m")].abs() < 1e-9);
    assert!((last[col("t_s")] - f64_field(&s, "td_s")).abs() < 1e-9);
    assert!((last[col("tip_x_m")] - f64_field(&s, "gx_m")).abs() < 1e-9);
    assert!((last[col("tip_y_m")] - f64_field(&s, "gy_m")).abs() < 1e-9);
    // The load at the end is what was dug.
    assert!((last[col("load_kg")] - f64_field(&s, "m_dig_kg")).abs() < 1e-9);
    // The largest hoist force is what c11 measured.
    let fh = rows
        .iter()
        .map(|r| r[col("hoist_force_n")])
        .fold(f64::NEG_INFINITY, f64::max);
    let c11 = f64_field(&s["constraints"]["c11_hoist_force_max"], "measured");
    assert!((fh - c11).abs() < 1e-9 * c11.abs(), "{fh} vs {c11}");
    // convergence.csv: the first pack and one row per iteration, best never worse.
    let read_rows = |name: &str| -> Vec<Vec<f64>> {
        std::fs::read_to_string(out.join(name))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    let best: Vec<(f64, f64)> = read_rows("convergence.csv")
        .iter()
        .map(|v| (v[1], v[2]))
        .collect();
    assert_eq!(best.len(), 101);
    let (f_gwo, viol_end) = best[best.len() - 1];
    assert_eq!(viol_end, 0.0);
    for w in best.windows(2).filter(|w| w[0].1 == 0.0) {
        assert!(w[1].1 == 0.0 && w[1].0 <= w[0].0, "{w:?}");
    }
    // polish.csv: the CMA-ES polish after GWO's 5050 evaluations, ending on
    // the plan's f, never worse than GWO's.
    let polish = read_rows("polish.csv");
    let last = polish.last().unwrap();
    assert!(polish[0][0] > 5050.0 && last[0] <= 25_050.0, "{last:?}");
    assert_eq!(last[3], 0.0);
    assert!((last[2] - f64_field(&s, "f")).abs() < 1e-9, "{last:?}");
    assert!(last[2] <= f_gwo);
}

#[test]
fn broken_profiles_and_missing_scans_are_refused_by_name() {
    let dir = TempDir::new("plan-dig-bad");
    let text = builtin_profile();
    // A contradictory limit: the file, the line and both keys are named.
    let bad = with_value(&text, "fill_min", "1.2");
    let file = dir.write("contradiction.toml", &bad);
    for json in [false, true] {
        let mut args = vec!["plan-dig".as_ref(), "--profile".as_ref(), file.as_os_str()];
        if json {
            args.push("--json".as_ref());
        }
        let r = run(&args).fails();
        let line = bad.lines().position(|l| l.starts_with("fill_min")).unwrap() + 1;
        let msg = r.error_message();
        assert!(
            msg.contains(&format!("contradiction.toml:{line}:")),
            "{msg}"
        );
        assert!(
            msg.contains("fill_min") && msg.contains("fill_max"),
            "{msg}"
        );
        assert!(r.stdout.is_empty(), "refused before planning: {}", r.stdout);
    }
    // A deleted limit is an error, never a silent default.
    let file = dir.write("missing.toml", without_key(&text, "hoist_force_max_n"));
    let r = run(&["plan-dig".as_ref(), "--profile".as_ref(), file.as_os_str()]).fails();
    assert!(
        r.error_message().contains("missing.toml")
            && r.error_message().contains("hoist_force_max_n"),
        "{}",
        r.error_message()
    );
    // --print-profile checks a given profile too.
    let r = run(&[
        "plan-dig".as_ref(),
        "--print-profile".as_ref(),
        "--profile".as_ref(),
        file.as_os_str(),
    ])
    .fails();
    assert!(
        r.error_message().contains("hoist_force_max_n"),
        "{}",
        r.stderr
    );
    // Files that are not there.
    let r = run(&["plan-dig", "--profile", "no-such-profile.toml"]).fails();
    assert!(
        r.error_message().contains("no-such-profile.toml"),
        "{}",
        r.stderr
    );
    let r = run(&["plan-dig", "--cloud", "no-such-scan.pcd"]).fails();
    assert!(
        r.error_message().contains("no-such-scan.pcd"),
        "{}",
        r.stderr
    );
    // Bad arguments.
    let r = run(&["plan-dig", "--surface", "pyramid"]);
    assert_eq!(r.code(), Some(2), "{}", r.stderr);
    r.no_panic();
    let r = run(&["plan-dig", "--surface", "convex", "--cloud", "x.pcd"]);
    assert_eq!(r.code(), Some(2), "{}", r.stderr);
}

#[test]
fn an_infeasible_machine_fails_with_the_binding_constraints() {
    // A hoist rated at 1 N cannot lift the empty dipper: valid, but no plan meets c11.
    let dir = TempDir::new("plan-dig-infeasible");
    let text = with_value(&builtin_profile(), "hoist_force_max_n", "1.0");
    let file = dir.write("weak.toml", &text);
    let out = dir.path().join("out");
    let r = run(&[
        "plan-dig".as_ref(),
        "--profile".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--json".as_ref(),
    ])
    .fails();
    assert!(
        r.error_message().contains("no feasible dig plan")
            && r.error_message().contains("c11_hoist_force_max"),
        "{}",
        r.stderr
    );
    // The summary says so; it never claims a plan.
    let s = r.json();
    assert_eq!(s["success"], false, "{s:#}");
    assert_eq!(s["feasible"], false, "{s:#}");
    assert!(s["error"].as_str().unwrap().contains("c11_hoist_force_max"));
    assert!(
        s.get("ax6").is_none() && s.get("m_dig_kg").is_none(),
        "{s:#}"
    );
    let written: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(written["success"], false);
    assert!(!out.join("samples.csv").exists());
}

fn csv_rows(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

// Four plans: about 1–3 s in the test profile.
#[test]
fn all_surfaces_tabulates_the_four_piles_beside_the_paper() {
    let dir = TempDir::new("plan-dig-all");
    let profile = builtin_profile();
    let r = run_with_timeout(
        &[
            "plan-dig".as_ref(),
            "--all-surfaces".as_ref(),
            "--out".as_ref(),
            dir.path().as_os_str(),
        ],
        std::time::Duration::from_secs(60),
    )
    .ok();
    let order = ["typical", "concave", "convex", "convex-concave"];
    for name in order {
        assert!(
            r.stdout.contains(&format!("| {name} | ours |")),
            "{}",
            r.stdout
        );
    }
    let s: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(s["success"], true, "{s:#}");
    let surfaces = s["surfaces"].as_array().expect("surfaces");
    let names: Vec<&str> = surfaces
        .iter()
        .map(|p| p["surface"].as_str().unwrap())
        .collect();
    assert_eq!(names, order, "Table 5's order");
    for p in surfaces {
        check_plan(p, &profile);
        let name = p["surface"].as_str().unwrap();
        // Each pile's own folder holds its summary and plots.
        let own: Value = serde_json::from_str(
            &std::fs::read_to_string(dir.path().join(name).join("summary.json")).unwrap(),
        )
        .unwrap();
        for key in ["ax6", "td_s", "f", "m_dig_kg", "constraints"] {
            assert_eq!(own[key], p[key], "{name}: {key}");
        }
        assert!(dir.path().join(name).join("dig_path.svg").is_file());
        let rel = |ours: &str, paper: &str| {
            let (o, q) = (f64_field(p, ours), f64_field(&p["paper"], paper));
            (o - q) / q
        };
        assert!((f64_field(p, "m_dig_rel_diff") - rel("m_dig_kg", "m_dig_kg")).abs() < 1e-12);
        assert!((f64_field(p, "f_rel_diff") - rel("f", "f")).abs() < 1e-12);
    }
    // table.csv: one row per pile, ours beside the paper's, the differences consistent.
    let (header, rows) = csv_rows(&dir.path().join("table.csv"));
    assert_eq!(rows.len(), 4);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("table.csv lacks {name}: {header:?}"))
    };
    for (row, p) in rows.iter().zip(surfaces) {
        assert_eq!(row[col("surface")], p["surface"].as_str().unwrap());
        let num = |name: &str| row[col(name)].parse::<f64>().unwrap();
        assert_eq!(num("m_dig_kg"), f64_field(p, "m_dig_kg"));
        assert_eq!(num("f_paper"), f64_field(&p["paper"], "f"));
        assert!((num("fill_pct") - 100.0 * f64_field(p, "fill_factor")).abs() < 1e-9);
        let rel = (num("m_dig_kg") - num("m_dig_kg_paper")) / num("m_dig_kg_paper");
        assert!((num("m_dig_rel_diff") - rel).abs() < 1e-12);
        for pair in [
            "ax6_1e7",
            "ay6_1e7",
            "gx_m",
            "gy_m",
            "td_s",
            "f1_j_per_kg",
            "f2_s_per_kg",
            "fill_pct",
        ] {
            num(pair);
            num(&format!("{pair}_paper"));
        }
        assert_eq!(row[col("feasible")], "true");
    }
    for f in ["paths.svg", "paths.png"] {
        assert!(dir.path().join(f).is_file(), "{f} missing");
    }
}

#[test]
fn cloud_plans_on_a_generated_scale_model_scan_and_explains_a_full_size_one() {
    let dir = TempDir::new("plan-dig-cloud");
    let profile = builtin_profile();
    let scan = dir.path().join("pile.pcd");
    run(&[
        "generate-pile".as_ref(),
        "--scale".as_ref(),
        "0.0333333".as_ref(),
        "--points".as_ref(),
        "40000".as_ref(),
        "--out".as_ref(),
        scan.as_os_str(),
    ])
    .ok();
    let s = run(&[
        "plan-dig".as_ref(),
        "--cloud".as_ref(),
        scan.as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    check_plan(&s, &profile);
    assert_eq!(s["surface"], "cloud");
    assert_eq!(s["cloud"], scan.display().to_string());
    let p = &s["perception"];
    assert!(f64_field(p, "r2") > 0.95, "{p:#}");
    // The generator's 1:30 pile: a 10 m face at scale 1/30 rises 0.333 m.
    let face = f64_field(p, "face_height_m");
    assert!((face - 10.0 / 30.0).abs() < 0.03, "face {face}");
    // A convex pile rises at 53° from its toe, so perception leaves no floor
    // in the fitted extent: the toe is extrapolated down the face.
    let convex = dir.path().join("convex.pcd");
    run(&[
        "generate-pile".as_ref(),
        "--shape".as_ref(),
        "convex".as_ref(),
        "--scale".as_ref(),
        "0.0333333".as_ref(),
        "--points".as_ref(),
        "40000".as_ref(),
        "--out".as_ref(),
        convex.as_os_str(),
    ])
    .ok();
    let s = run(&[
        "plan-dig".as_ref(),
        "--cloud".as_ref(),
        convex.as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    check_plan(&s, &profile);
    // A full-size scan is far beyond the scale model: refused, with the way out.
    let big = dir.path().join("big.pcd");
    run(&[
        "generate-pile".as_ref(),
        "--points".as_ref(),
        "40000".as_ref(),
        "--out".as_ref(),
        big.as_os_str(),
    ])
    .ok();
    let r = run(&["plan-dig".as_ref(), "--cloud".as_ref(), big.as_os_str()]).fails();
    assert!(
        r.error_message().contains("--scale") && r.error_message().contains("big.pcd"),
        "{}",
        r.stderr
    );
}

#[test]
fn warm_start_from_the_last_plans_pack_never_plans_worse() {
    let dir = TempDir::new("plan-dig-warm");
    let first = dir.path().join("first");
    let a = run(&[
        "plan-dig".as_ref(),
        "--surface".as_ref(),
        "convex".as_ref(),
        "--out".as_ref(),
        first.as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    let pack = first.join("pack.csv");
    let text = std::fs::read_to_string(&pack).unwrap();
    // One row per wolf, the best first and equal to the plan.
    assert_eq!(text.lines().count(), 1 + 50);
    let best: Vec<f64> = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(|c| c.parse().unwrap())
        .collect();
    assert!((best[5] - f64_field(&a, "f")).abs() < 1e-9);
    // Next cycle, another seed, from that pack: the old best is in the pack,
    // and the optimiser never loses its best, so f cannot get worse (beyond
    // the rounding of the decision's round trip through the CSV).
    let b = run(&[
        "plan-dig".as_ref(),
        "--surface".as_ref(),
        "convex".as_ref(),
        "--seed".as_ref(),
        "9".as_ref(),
        "--warm-start".as_ref(),
        pack.as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    assert!(f64_field(&b, "f") <= f64_field(&a, "f") + 1e-9);
    assert_eq!(b["warm_start"]["wolves"], 50);
    // A damaged pack is refused with its line.
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, text.replacen("\n", "\nnot,a,number,at,all,0,0\n", 1)).unwrap();
    let r = run(&[
        "plan-dig".as_ref(),
        "--warm-start".as_ref(),
        bad.as_os_str(),
    ])
    .fails();
    assert!(r.error_message().contains("bad.csv:2:"), "{}", r.stderr);
}
