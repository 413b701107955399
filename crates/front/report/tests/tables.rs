//! CSV and summary.json output.

mod common;

use autoshovel_report::*;
use common::Scratch;
use serde_json::json;

/// Splits one CSV record (RFC 4180 quoting) into cells.
fn parse_record(line: &str) -> Vec<String> {
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            (true, '"') => quoted = false,
            (false, '"') => quoted = true,
            (false, ',') => cells.push(std::mem::take(&mut cell)),
            (_, c) => cell.push(c),
        }
    }
    cells.push(cell);
    cells
}

#[test]
fn csv_numbers_round_trip_exactly() {
    let dir = Scratch::new("csv_round_trip");
    let path = dir.path().join("data.csv");
    let rows: Vec<Vec<f64>> = vec![
        vec![0.0, -0.0, 1.0],
        vec![0.1, 1.0 / 3.0, -2.5e-300],
        vec![1e300, f64::MIN_POSITIVE, f64::MAX],
        vec![123456.789, -7e-7, 1e16],
        vec![f64::INFINITY, f64::NEG_INFINITY, f64::NAN],
        vec![std::f64::consts::PI, 1e-5, 9_007_199_254_740_993.0],
    ];
    write_csv(&path, &["t", "x", "y"], rows.clone()).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,x,y"));
    assert!(text.ends_with('\n'));
    let back: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|c| c.parse::<f64>().unwrap()).collect())
        .collect();
    assert_eq!(back.len(), rows.len());
    for (a, b) in rows.iter().flatten().zip(back.iter().flatten()) {
        if a.is_nan() {
            assert!(b.is_nan());
        } else {
            assert_eq!(a.to_bits(), b.to_bits(), "{a} came back as {b}");
        }
    }
    assert!(
        text.lines().all(|l| l.len() < 80),
        "no huge expansions:\n{text}"
    );
}

#[test]
fn csv_accepts_any_iterator_and_checks_row_length() {
    let dir = Scratch::new("csv_rows");
    let path = dir.path().join("gen.csv");
    write_csv(
        &path,
        &["i", "sq"],
        (0..5).map(|i| vec![f64::from(i), f64::from(i * i)]),
    )
    .unwrap();
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        "i,sq\n0,0\n1,1\n2,4\n3,9\n4,16\n"
    );
    let err = write_csv(&path, &["a", "b"], vec![vec![1.0, 2.0], vec![1.0]]).unwrap_err();
    assert!(matches!(err, ReportError::Invalid { .. }));
    assert!(err.to_string().contains("gen.csv"), "{err}");
}

#[test]
fn csv_cells_are_quoted_and_round_trip() {
    let dir = Scratch::new("csv_cells");
    let path = dir.path().join("cells.csv");
    let rows = vec![
        vec!["plain".to_string(), "1.5".to_string()],
        vec!["with, comma".to_string(), "say \"hi\"".to_string()],
        vec![String::new(), "ünïcode ✓".to_string()],
    ];
    write_csv_cells(&path, &["name", "note, quoted"], &rows).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        parse_record(lines.next().unwrap()),
        vec!["name", "note, quoted"]
    );
    for row in &rows {
        assert_eq!(&parse_record(lines.next().unwrap()), row);
    }
    assert!(lines.next().is_none());
    let ragged = vec![vec!["only one".to_string()]];
    assert!(matches!(
        write_csv_cells(&path, &["a", "b"], &ragged),
        Err(ReportError::Invalid { .. })
    ));
}

#[test]
fn csv_in_missing_directory_is_an_io_error_naming_the_file() {
    let dir = Scratch::new("csv_missing");
    let path = dir.path().join("nope").join("x.csv");
    match write_csv(&path, &["a"], vec![vec![1.0]]) {
        Err(ReportError::Io { path: p, .. }) => assert_eq!(p, path),
        other => panic!("expected Io error, got {other:?}"),
    }
    assert!(matches!(
        write_csv_cells(&path, &["a"], &[]),
        Err(ReportError::Io { .. })
    ));
}

#[test]
fn summary_is_pretty_json_with_trailing_newline() {
    let dir = Scratch::new("summary");
    let summary = json!({"job": "follow", "rms": 0.125, "nested": {"a": [1, 2]}});
    let path = write_summary(dir.path(), &summary).unwrap();
    assert_eq!(path, dir.path().join("summary.json"));
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.ends_with("}\n") && text.contains("\n  \"job\": \"follow\""));
    let back: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(back, summary);
    assert!(matches!(
        write_summary(&dir.path().join("missing"), &summary),
        Err(ReportError::Io { .. })
    ));
}
