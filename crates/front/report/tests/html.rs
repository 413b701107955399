//! The HTML report page.

mod common;

use autoshovel_report::*;
use common::Scratch;
use serde_json::json;

fn section() -> Section {
    Section {
        title: "Path following".into(),
        description: "Follows a <b>planned</b> path.\n\nSecond paragraph & more.".into(),
        summary: json!({
            "a": {"b": 42},
            "rms_m": 0.123456789,
            "passed": true,
            "samples": (0..50).collect::<Vec<i32>>(),
            "label": "<img src=x onerror=alert(1)>"
        }),
        plots: vec!["follow/map.svg".into(), "follow/dev heading.svg".into()],
        files: vec!["follow/trace.csv".into(), "follow/summary.json".into()],
    }
}

#[test]
fn index_is_self_contained_and_escaped() {
    let dir = Scratch::new("html_index");
    let path =
        write_index_html(dir.path(), "<script>alert('x')</script> demo", &[section()]).unwrap();
    assert_eq!(path, dir.path().join("index.html"));
    let page = std::fs::read_to_string(&path).unwrap();

    assert!(page.starts_with("<!DOCTYPE html>"));
    assert!(!page.contains("<script"), "title must be escaped");
    assert!(page.contains("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; demo"));
    assert!(!page.contains("<img src=x"), "summary strings escaped");
    assert!(
        page.contains("&lt;b&gt;planned&lt;/b&gt;"),
        "description escaped"
    );
    assert!(page.contains("Second paragraph &amp; more."));

    // No external resources: only relative links to the job's files.
    assert!(!page.contains("http://") && !page.contains("https://"));
    assert!(page.contains("<style>"));

    // Flattened summary table.
    assert!(page.contains("<td class=\"key\">a.b</td><td class=\"value\">42</td>"));
    assert!(page.contains(">0.123457</td>"), "floats shortened");
    assert!(
        page.contains("title=\"0.123456789\""),
        "full value kept as tooltip"
    );
    assert!(page.contains("(50 items)"), "long arrays abbreviated");
    assert!(page.contains(">true</td>"));

    // Plots as images linking to themselves, files as links.
    assert!(page.contains("<a href=\"follow/map.svg\"><img src=\"follow/map.svg\""));
    assert!(page.contains("src=\"follow/dev%20heading.svg\""));
    assert!(page.contains("<a href=\"follow/trace.csv\">follow/trace.csv</a>"));
    assert!(page.contains("<a href=\"#job-1\">Path following</a>"));
}

#[test]
fn index_with_no_sections_and_odd_summaries() {
    let dir = Scratch::new("html_odd");
    let path = write_index_html(dir.path(), "Empty demo", &[]).unwrap();
    let page = std::fs::read_to_string(path).unwrap();
    assert!(page.contains("<h1>Empty demo</h1>") && page.ends_with("</html>\n"));

    let odd = [
        Section {
            title: "null summary".into(),
            ..Section::default()
        },
        Section {
            title: "scalar".into(),
            summary: json!(3.5),
            ..Section::default()
        },
    ];
    let page = std::fs::read_to_string(write_index_html(dir.path(), "t", &odd).unwrap()).unwrap();
    assert!(page.contains("No summary values."));
    assert!(page.contains("<td class=\"key\">(value)</td><td class=\"value\">3.5</td>"));

    assert!(matches!(
        write_index_html(&dir.path().join("missing"), "t", &odd),
        Err(ReportError::Io { .. })
    ));
}
