//! `remove_unfinished` (what the CLI's Ctrl-C handler calls) takes this
//! process's uncommitted staging folders and nothing else. Alone in its
//! own test binary: the call is process-wide.

use autoshovel_report::{remove_unfinished, OutDir, Written, SUMMARY_FILE};

#[test]
fn remove_unfinished_takes_staging_folders_and_nothing_else() {
    let d = std::env::temp_dir().join(format!("as-unfinished-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("mine.txt"), "keep").unwrap();
    let out = OutDir::new(&d);
    // A job interrupted while writing.
    let s = out.stage().unwrap();
    std::fs::write(s.path().join("half.csv"), "1,2").unwrap();
    let staged = s.path().to_path_buf();
    remove_unfinished();
    assert!(!staged.exists());
    assert_eq!(std::fs::read_to_string(d.join("mine.txt")).unwrap(), "keep");
    drop(s);
    // A committed job is no longer unfinished: its files stay.
    let s = out.stage().unwrap();
    std::fs::write(s.path().join("done.txt"), "whole").unwrap();
    std::fs::write(
        s.path().join(SUMMARY_FILE),
        "{\"files\": [\"done.txt\", \"summary.json\"]}",
    )
    .unwrap();
    let mut w = Written::default();
    w.file(s.path(), &s.path().join("done.txt"));
    w.file(s.path(), &s.path().join(SUMMARY_FILE));
    s.commit(&w).unwrap();
    remove_unfinished();
    assert_eq!(
        std::fs::read_to_string(d.join("done.txt")).unwrap(),
        "whole"
    );
    let left: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with(".autoshovel"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    let _ = std::fs::remove_dir_all(&d);
}
