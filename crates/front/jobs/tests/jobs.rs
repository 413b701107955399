//! The job layer against what it promises: a job's `summary.json` is the
//! summary it returns (a round trip through the file), the files it lists
//! are there, nothing is written without an output folder, and its errors
//! name the setting or the step at fault.

use std::path::PathBuf;

use autoshovel_jobs::{out_dir, plan_path, JobError};
use autoshovel_walk_planner::{FieldKind, Scenario, DEFAULT_HEADING_TOLERANCE_DEG};

/// A fresh folder under the system's temporary one, removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("autoshovel-jobs-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn summary_file_is_the_returned_summary_and_lists_what_is_there() {
    let scratch = Scratch::new("round-trip");
    let scenario = Scenario::builtin("straight").expect("built-in");
    let out = out_dir(Some(&scratch.0), &[], false).unwrap();
    let job = plan_path(
        &scenario,
        FieldKind::Improved,
        DEFAULT_HEADING_TOLERANCE_DEG,
        out.as_ref(),
    )
    .unwrap();
    let text = std::fs::read_to_string(scratch.0.join("summary.json")).unwrap();
    let on_disk: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(on_disk, job.json().unwrap());
    let files = on_disk["files"].as_array().expect("files listed");
    assert!(files.len() > 2, "{files:?}");
    for f in files {
        let f = f.as_str().unwrap();
        assert!(scratch.0.join(f).is_file(), "{f} listed but missing");
    }
    // The same job without a folder writes nothing and lists no files.
    let bare = plan_path(
        &scenario,
        FieldKind::Improved,
        DEFAULT_HEADING_TOLERANCE_DEG,
        None,
    )
    .unwrap();
    assert!(bare.out.is_none() && bare.written.all().is_empty());
    assert!(bare.json().unwrap().get("files").is_none());
    assert_eq!(bare.summary.success, job.summary.success);
    assert_eq!(bare.summary.escapes, job.summary.escapes);
}

#[test]
fn errors_name_the_setting_or_the_file() {
    let scenario = Scenario::builtin("straight").expect("built-in");
    let e = plan_path(&scenario, FieldKind::Improved, -1.0, None).unwrap_err();
    assert!(matches!(e, JobError::Setting { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        "--heading-tolerance-deg -1 must be a non-negative number"
    );
    // An --out that is a file is refused before any work.
    let scratch = Scratch::new("out-is-file");
    std::fs::create_dir_all(&scratch.0).unwrap();
    let file = scratch.0.join("a-file");
    std::fs::write(&file, "mine").unwrap();
    let e = out_dir(Some(&file), &[], true).unwrap_err();
    assert!(e.to_string().contains("a-file"), "{e}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");
    // A pipeline error is wrapped with the file it was reading.
    let cloud = scratch.0.join("flat.xyz");
    std::fs::write(&cloud, "0 0 0\n1 0 0\n0 1 0\n").unwrap();
    let e = autoshovel_jobs::perceive(&cloud, &Default::default(), None, false).unwrap_err();
    match &e {
        JobError::During { step, .. } => assert_eq!(step, &cloud.display().to_string()),
        other => panic!("expected the file named as the step, got {other:?}"),
    }
    assert!(std::error::Error::source(&e).is_some());
    assert!(!e.interrupted());
}
