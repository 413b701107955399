//! Issue 11, the output rule: no job writes onto a file it read, nor onto an
//! existing file autoshovel did not write unless `--force` is given; a job
//! may rerun into its own folder; a refusal leaves every file as it was and
//! no staging folder behind.

mod common;

use std::path::Path;

use common::*;

fn args<'a>(v: &'a [&'a str]) -> Vec<&'a std::ffi::OsStr> {
    v.iter().map(|s| s.as_ref()).collect()
}

fn no_staging_left(dir: &Path) {
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".autoshovel"))
        .collect();
    assert!(
        left.is_empty(),
        "left behind in {}: {left:?}",
        dir.display()
    );
}

/// Every job: a user's `summary.json` in --out is kept (refused, byte for
/// byte), --force replaces it, and a rerun into the job's own folder works.
#[test]
fn every_job_keeps_a_users_file_unless_forced_and_reruns_into_its_own_folder() {
    let tmp = TempDir::new("outputs-jobs");
    let jobs: [&[&str]; 6] = [
        &["plan-path", "--scenario", "straight"],
        &["track", "--scenario", "straight"],
        &["study-paths", "--maps", "4"],
        &["study-boulders", "--cases", "3"],
        &["plan-excavate", "--scenario", "paper-over"],
        &["plan-dig", "--surface", "typical"],
    ];
    for (i, job) in jobs.iter().enumerate() {
        let dir = tmp.path().join(format!("job{i}"));
        std::fs::create_dir_all(&dir).unwrap();
        let mine = tmp.write(&format!("job{i}/summary.json"), "my notes\n");
        let d = dir.to_str().unwrap();
        let mut a = job.to_vec();
        a.extend(["--out", d]);
        let r = run(&args(&a)).fails();
        assert!(
            r.error_message().contains("--force") && r.error_message().contains("summary.json"),
            "{}: {}",
            job[0],
            r.error_message()
        );
        assert_eq!(std::fs::read_to_string(&mine).unwrap(), "my notes\n");
        no_staging_left(&dir);
        a.push("--force");
        run(&args(&a)).ok();
        assert_ne!(std::fs::read_to_string(&mine).unwrap(), "my notes\n");
        a.pop();
        run(&args(&a)).ok(); // its own files now: no --force needed
        no_staging_left(&dir);
    }
}

#[test]
fn no_job_writes_onto_its_input_even_forced() {
    let tmp = TempDir::new("outputs-inputs");
    let d = tmp.path().to_str().unwrap().to_string();
    let scan = tmp.path().join("cleaned.pcd");
    let s = scan.to_str().unwrap();
    run(&args(&["generate-pile", "--points", "30000", "--out", s])).ok();
    let before = std::fs::read(&scan).unwrap();
    for force in [false, true] {
        let mut a = vec!["perceive", "--input", s, "--out", &d];
        if force {
            a.push("--force");
        }
        let r = run(&args(&a)).fails();
        assert!(
            r.error_message().contains("is an input"),
            "{}",
            r.error_message()
        );
        assert_eq!(
            std::fs::read(&scan).unwrap(),
            before,
            "the scan is untouched"
        );
    }
    // Issue 46: links planted in the output folder under every staging
    // name an earlier autoshovel used (`.autoshovel-staging-PID-N`, for the
    // next pids) and pointing at the input's folder steer no write: the
    // staging folder is made new under a random name.
    let atk = tmp.path().join("atk");
    std::fs::create_dir_all(&atk).unwrap();
    let next = std::fs::read_to_string("/proc/sys/kernel/ns_last_pid")
        .ok()
        .and_then(|t| t.trim().parse::<u64>().ok())
        .unwrap_or(1);
    for pid in next..next + 200 {
        for n in 0..2 {
            let link = atk.join(format!(".autoshovel-staging-{pid}-{n}"));
            std::os::unix::fs::symlink(tmp.path(), link).unwrap();
        }
    }
    let a = atk.to_str().unwrap();
    run(&args(&["perceive", "--input", s, "--out", a])).ok();
    assert_eq!(
        std::fs::read(&scan).unwrap(),
        before,
        "the input is byte-identical"
    );
    assert!(atk.join("summary.json").is_file());
    let links = std::fs::read_dir(&atk)
        .unwrap()
        .flatten()
        .filter(|e| e.file_type().unwrap().is_symlink())
        .count();
    assert_eq!(links, 400, "the planted links are left as they were");
    // A warm-start pack read from the folder it would be written to.
    let out = tmp.path().join("dig");
    let o = out.to_str().unwrap();
    run(&args(&["plan-dig", "--surface", "convex", "--out", o])).ok();
    let pack = out.join("pack.csv");
    let p = pack.to_str().unwrap();
    let before = std::fs::read(&pack).unwrap();
    let r = run(&args(&[
        "plan-dig",
        "--warm-start",
        p,
        "--out",
        o,
        "--force",
    ]))
    .fails();
    assert!(
        r.error_message().contains("is an input"),
        "{}",
        r.error_message()
    );
    assert_eq!(std::fs::read(&pack).unwrap(), before);
    no_staging_left(&out);
    // A scenario file in the output folder under an output's name.
    std::fs::create_dir_all(tmp.path().join("road")).unwrap();
    let sc = tmp.write("road/path.csv", builtin_text("straight"));
    let road = tmp.path().join("road");
    let r = run(&args(&[
        "plan-path",
        "--scenario",
        sc.to_str().unwrap(),
        "--out",
        road.to_str().unwrap(),
        "--force",
    ]));
    // plan-path writes path.csv: the scenario of that name is an input.
    let r = r.fails();
    assert!(
        r.error_message().contains("is an input"),
        "{}",
        r.error_message()
    );
    assert_eq!(
        std::fs::read_to_string(&sc).unwrap(),
        builtin_text("straight")
    );
}

#[test]
fn generate_pile_and_demo_keep_a_users_file() {
    let tmp = TempDir::new("outputs-files");
    let f = tmp.write("pile.pcd", "not mine to lose");
    let r = run(&args(&[
        "generate-pile",
        "--points",
        "1000",
        "--out",
        f.to_str().unwrap(),
    ]))
    .fails();
    assert!(
        r.error_message().contains("--force"),
        "{}",
        r.error_message()
    );
    assert_eq!(std::fs::read_to_string(&f).unwrap(), "not mine to lose");
    run(&args(&[
        "generate-pile",
        "--points",
        "1000",
        "--out",
        f.to_str().unwrap(),
        "--force",
    ]))
    .ok();
    assert_ne!(
        std::fs::read_to_string(&f).unwrap_or_default(),
        "not mine to lose"
    );
    let entries = std::fs::read_dir(tmp.path()).unwrap().count();
    assert_eq!(entries, 1, "no temporary file left beside the pile");
    std::fs::remove_file(&f).unwrap();
    // The demo refuses a user's index.html before doing any work.
    std::fs::create_dir_all(tmp.path().join("report")).unwrap();
    let index = tmp.write("report/index.html", "<p>mine</p>");
    let r = run(&args(&[
        "demo",
        "--out",
        tmp.path().join("report").to_str().unwrap(),
    ]))
    .fails();
    assert!(
        r.error_message().contains("index.html"),
        "{}",
        r.error_message()
    );
    assert_eq!(std::fs::read_to_string(&index).unwrap(), "<p>mine</p>");
    assert_eq!(
        std::fs::read_dir(tmp.path().join("report"))
            .unwrap()
            .count(),
        1
    );
}

/// Ctrl-C stops a job with exit code 130 and leaves no staging folder or
/// temporary file in the output folder (the demo runs many jobs; the
/// interrupt lands in one of them).
#[test]
fn an_interrupted_job_leaves_nothing_half_written() {
    let tmp = TempDir::new("outputs-interrupt");
    let out = tmp.path().join("demo");
    let mut child = std::process::Command::new(bin())
        .args(["demo", "--out"])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let killed = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = wait_or_kill(&mut child, std::time::Duration::from_secs(60), "demo");
    assert_eq!(status.code(), Some(130), "{status:?}");
    let mut err = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
    assert!(err.contains("interrupted"), "{err}");
    if out.exists() {
        no_staging_left(&out);
        for e in std::fs::read_dir(&out).unwrap().flatten() {
            if e.path().is_dir() {
                no_staging_left(&e.path());
            }
        }
    }
}
