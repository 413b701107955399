//! `autoshovel validate-dig`: a plan from `plan-dig`, a measurement simulated
//! from it with known errors (`--simulate`), and the report giving those
//! errors back ([RS §5], [RS Table 6], [RS Fig. 20]); the same report from
//! the written file (`--measured`); and the refusals of broken records.

mod common;

use std::path::Path;

use common::*;
use serde_json::Value;

/// A number at a JSON pointer of `v`.
#[track_caller]
fn num(v: &Value, pointer: &str) -> f64 {
    v.pointer(pointer)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("no number at {pointer} in {v:#}"))
}

#[track_caller]
fn near(v: &Value, pointer: &str, want: f64, tol: f64) {
    let got = num(v, pointer);
    assert!(
        (got - want).abs() <= tol,
        "{pointer} = {got}, expected {want} ± {tol}"
    );
}

/// Plans the typical pile into `dir/plan`.
fn plan(dir: &TempDir) -> std::path::PathBuf {
    let plan = dir.path().join("plan");
    run(&[
        "plan-dig",
        "--surface",
        "typical",
        "--out",
        plan.to_str().unwrap(),
    ])
    .ok();
    plan
}

#[test]
fn a_simulated_measurement_gives_its_errors_back_from_the_file_too() {
    let dir = TempDir::new("validate-dig");
    let plan = plan(&dir);
    let m = dir.path().join("m.csv");
    let check = dir.path().join("check");
    let r = run(&[
        "validate-dig",
        "--plan",
        plan.to_str().unwrap(),
        "--simulate",
        m.to_str().unwrap(),
        "--out",
        check.to_str().unwrap(),
        "--json",
    ])
    .ok();
    let s = r.json();
    assert_eq!(s["job"], "validate-dig");
    assert_eq!(s["surface"], "typical");
    // The defaults of --sim-*: 0.37 s delay, gains 1.06 and 0.95, 33 g, pace 0.997.
    near(&s, "/alignment/delay_s", 0.37, 0.005);
    near(&s, "/alignment/time_scale", 0.997, 1e-3);
    near(&s, "/hoist_force/gain", 1.06, 0.0106);
    near(&s, "/crowd_force/gain", 0.95, 0.0095);
    near(&s, "/mass_kg/difference", 0.033, 1e-12);
    let planned: Value =
        serde_json::from_str(&std::fs::read_to_string(plan.join("summary.json")).unwrap()).unwrap();
    near(&s, "/mass_kg/planned", num(&planned, "/m_dig_kg"), 0.0);
    near(&s, "/dig_time_s/planned", num(&planned, "/td_s"), 0.0);
    near(
        &s,
        "/dig_time_s/measured",
        0.997 * num(&planned, "/td_s"),
        0.01,
    );
    for f in ["hoist_force", "crowd_force"] {
        let r2 = num(&s, &format!("/{f}/r_squared"));
        let rp = num(&s, &format!("/{f}/r2_pearson"));
        assert!(r2 > 0.9 && r2 < rp && rp > 0.99, "{f}: R² {r2}, r² {rp}");
    }
    assert!(
        s["rope_length"].is_object() && s["handle_extension"].is_object(),
        "{s:#}"
    );
    // The files, and summary.json saying the same.
    let files: Vec<&str> = s["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(Value::as_str)
        .collect();
    for f in [
        "aligned.csv",
        "forces.svg",
        "forces.png",
        "travel.svg",
        "summary.json",
    ] {
        assert!(files.contains(&f), "{f} not in {files:?}");
        assert!(check.join(f).is_file(), "{f} not written");
    }
    let on_disk: Value =
        serde_json::from_str(&std::fs::read_to_string(check.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(on_disk["alignment"], s["alignment"]);
    // The written file gives the same comparison.
    let again = run(&[
        "validate-dig",
        "--plan",
        plan.to_str().unwrap(),
        "--measured",
        m.to_str().unwrap(),
        "--json",
    ])
    .ok()
    .json();
    for key in [
        "alignment",
        "hoist_force",
        "crowd_force",
        "mass_kg",
        "dig_time_s",
    ] {
        assert_eq!(again[key], s[key], "{key}");
    }
    // --simulate never writes over a file that is there.
    let e = run(&[
        "validate-dig",
        "--plan",
        plan.to_str().unwrap(),
        "--simulate",
        m.to_str().unwrap(),
    ])
    .fails();
    assert!(
        e.error_message().contains("the file exists"),
        "{}",
        e.stderr
    );
    // The human lines: Table 6's row.
    let h = run(&[
        "validate-dig",
        "--plan",
        plan.to_str().unwrap(),
        "--measured",
        m.to_str().unwrap(),
    ])
    .ok();
    assert!(h.stdout.contains("| typical |"), "{}", h.stdout);
    assert!(
        h.stdout.contains("0.370 s into the record") || h.stdout.contains("0.36"),
        "{}",
        h.stdout
    );

    broken_records_are_refused_by_file_line_and_column(&dir, &plan, &m);
}

/// Runs validate-dig on `text` written to `name`; returns the error message.
#[track_caller]
fn refused(dir: &TempDir, plan: &Path, name: &str, text: &str) -> String {
    let p = dir.write(name, text);
    let r = run(&[
        "validate-dig",
        "--plan",
        plan.to_str().unwrap(),
        "--measured",
        p.to_str().unwrap(),
    ])
    .fails();
    r.error_message().to_string()
}

fn broken_records_are_refused_by_file_line_and_column(dir: &TempDir, plan: &Path, m: &Path) {
    let good = std::fs::read_to_string(m).unwrap();
    let mut lines: Vec<String> = good.lines().map(String::from).collect();
    assert!(
        lines[0].starts_with("t_s,hoist_force_n,crowd_force_n"),
        "{}",
        lines[0]
    );
    // No crowd force column.
    let e = refused(
        dir,
        plan,
        "nocrowd.csv",
        &good.replacen("crowd_force_n", "crowd_n", 1),
    );
    assert!(
        e.contains("nocrowd.csv:1: no column 'crowd_force_n'"),
        "{e}"
    );
    // A bad number on line 5.
    let mut cells: Vec<String> = lines[4].split(',').map(String::from).collect();
    cells[1] = "12,5".replace(',', ";");
    lines[4] = cells.join(",");
    let e = refused(dir, plan, "bad.csv", &(lines.join("\n") + "\n"));
    assert!(
        e.contains("bad.csv:5: column hoist_force_n: '12;5' is not a finite number"),
        "{e}"
    );
    // Time going back on line 8.
    let mut lines: Vec<String> = good.lines().map(String::from).collect();
    let t6 = lines[5].split(',').next().unwrap().to_string();
    let rest: Vec<&str> = lines[7].splitn(2, ',').collect();
    lines[7] = format!("{t6},{}", rest[1]);
    let e = refused(dir, plan, "back.csv", &(lines.join("\n") + "\n"));
    assert!(e.contains("back.csv:8: t_s = "), "{e}");
    assert!(e.contains("does not increase"), "{e}");
    // Too short.
    let short: String = good.lines().take(4).map(|l| format!("{l}\n")).collect();
    let e = refused(dir, plan, "short.csv", &short);
    assert!(
        e.contains("short.csv: 3 samples; at least 10 are needed"),
        "{e}"
    );
    // A folder that is not a plan.
    let r = run(&[
        "validate-dig",
        "--plan",
        dir.path().to_str().unwrap(),
        "--measured",
        m.to_str().unwrap(),
    ])
    .fails();
    assert!(r.error_message().contains("summary.json"), "{}", r.stderr);
}
