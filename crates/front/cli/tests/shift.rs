//! `autoshovel shift`: a short shift written to a folder (the summary
//! against the tables it wrote, not against numbers copied from a run),
//! the scenario's print-and-load round trip, and broken scenarios refused
//! with the file, line and key, nothing written.

mod common;

use common::*;

#[test]
fn a_short_shift_writes_its_tables_maps_and_animation_and_balances() {
    let dir = TempDir::new("shift-out");
    let out = dir.path().join("out");
    let r = run(&[
        "shift",
        "--cycles",
        "4",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ])
    .ok();
    let s = r.json();
    assert_eq!(s["job"], "shift");
    assert_eq!(s["passes"], 4);
    assert_eq!(s["mass_balance"]["closes"], true);
    // The tonnes are the passes' dug mass, row by row.
    let passes = std::fs::read_to_string(out.join("passes.csv")).unwrap();
    let header: Vec<&str> = passes.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "dug_t").unwrap();
    let rows: Vec<f64> = passes
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    assert_eq!(rows.len(), 4);
    let tonnes = s["tonnes"].as_f64().unwrap();
    assert!(
        (rows.iter().sum::<f64>() - tonnes).abs() < 1e-6 * tonnes,
        "{rows:?} vs {tonnes}"
    );
    for file in [
        "summary.json",
        "events.csv",
        "stands.csv",
        "walks.csv",
        "pit_before.svg",
        "pit_after.png",
        "stand_01_before.svg",
        "stand_01_after.png",
        "timeline.svg",
        "animation.html",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    let page = std::fs::read_to_string(out.join("animation.html")).unwrap();
    assert!(page.contains("<canvas") && page.contains("type=\"range\""));
    // The MCAP log reads back: a message per pass and per event, in time
    // order, the summary last.
    let bytes = std::fs::read(out.join("shift.mcap")).unwrap();
    let mut topics = std::collections::BTreeMap::<String, usize>::new();
    let mut last = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        assert!(m.log_time >= last, "out of order");
        last = m.log_time;
        *topics.entry(m.channel.topic.clone()).or_default() += 1;
    }
    let events = std::fs::read_to_string(out.join("events.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    assert_eq!(topics["/shift/pass"], 4, "{topics:?}");
    assert_eq!(topics["/autoshovel/event"], events, "{topics:?}");
    assert_eq!(topics["/autoshovel/summary"], 1);
    assert!(topics["/sim/truth"] >= 4);
}

#[test]
fn the_printed_scenario_loads_back_and_runs() {
    let text = run(&["shift", "--print-scenario"]).ok().stdout;
    assert!(
        text.contains("[pile]") && text.contains("[machine]"),
        "{text}"
    );
    let dir = TempDir::new("shift-scenario");
    let file = dir.write(
        "mine.toml",
        text.replace("name = \"bench\"", "name = \"mine\""),
    );
    let s = run(&[
        "shift",
        "--scenario",
        file.to_str().unwrap(),
        "--cycles",
        "1",
        "--json",
    ])
    .ok()
    .json();
    assert_eq!(s["scenario"], "mine");
    assert_eq!(s["passes"], 1);
}

#[test]
fn a_broken_scenario_names_its_line_and_writes_nothing() {
    let text = run(&["shift", "--print-scenario"]).ok().stdout;
    let dir = TempDir::new("shift-bad");
    let good = text
        .lines()
        .find(|l| l.starts_with("face_height_m"))
        .unwrap()
        .to_string();
    let bad = replace_once(&text, &good, "face_height_m = -4.5");
    let file = dir.write("bad.toml", &bad);
    let out = dir.path().join("out");
    let r = run(&[
        "shift",
        "--scenario",
        file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
    .fails();
    let line = line_of(&bad, "face_height_m = -4.5");
    assert!(
        r.error_message().contains(&format!("bad.toml:{line}")),
        "{}",
        r.stderr
    );
    assert!(r.error_message().contains("face_height_m"), "{}", r.stderr);
    assert!(!out.exists());
    let r = run(&["shift", "--scenario", "no-such-pit"]).fails();
    assert!(r.error_message().contains("bench"), "{}", r.stderr);
}
