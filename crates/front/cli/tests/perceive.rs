//! `autoshovel generate-pile` and `autoshovel perceive`: every shape and
//! format round trip through the pipeline, and bad input.

mod common;

use common::*;

#[test]
fn every_shape_and_format_recovers_the_tilt_and_fits() {
    let dir = TempDir::new("piles");
    let shapes = ["typical", "convex", "concave", "convex-concave"];
    let formats = ["pcd", "ply", "las", "laz", "xyz"];
    for (i, shape) in shapes.iter().enumerate() {
        // Each shape once per format would be 20 runs: rotate the formats over the shapes
        // and give the first shape every format.
        let fmts: Vec<&str> = if i == 0 {
            formats.to_vec()
        } else {
            vec![formats[i % formats.len()]]
        };
        for ext in fmts {
            let file = dir.path().join(format!("{shape}.{ext}"));
            let g = run(&[
                "generate-pile".as_ref(),
                "--shape".as_ref(),
                shape.as_ref(),
                "--points".as_ref(),
                "60000".as_ref(),
                "--seed".as_ref(),
                "3".as_ref(),
                "--roll".as_ref(),
                "2.5".as_ref(),
                "--pitch".as_ref(),
                "-1.5".as_ref(),
                "--out".as_ref(),
                file.as_os_str(),
                "--json".as_ref(),
            ])
            .ok()
            .json();
            assert_eq!(g["points"], 60000);
            let s = run(&[
                "perceive".as_ref(),
                "--input".as_ref(),
                file.as_os_str(),
                "--json".as_ref(),
            ])
            .ok()
            .json();
            for key in [
                "input_points",
                "output_points",
                "stage_points",
                "roll_deg",
                "pitch_deg",
                "r2",
                "timings_ms",
            ] {
                assert!(!s[key].is_null(), "{shape}.{ext}: {key} missing");
            }
            assert_eq!(s["input_points"], 60000, "{shape}.{ext}");
            let roll = f64_field(&s, "roll_deg");
            let pitch = f64_field(&s, "pitch_deg");
            assert!(
                (roll - 2.5).abs() < 0.2 && (pitch + 1.5).abs() < 0.2,
                "{shape}.{ext}: roll {roll}, pitch {pitch}"
            );
            assert!(f64_field(&s, "r2") > 0.95, "{shape}.{ext}: {s:#}");
        }
    }
}

#[test]
fn perceive_writes_the_cleaned_cloud_surface_and_plots() {
    let dir = TempDir::new("perceive-out");
    let file = dir.path().join("scan.ply");
    run(&[
        "generate-pile".as_ref(),
        "--points".as_ref(),
        "40000".as_ref(),
        "--out".as_ref(),
        file.as_os_str(),
    ])
    .ok();
    let out = dir.path().join("out");
    let s = run(&[
        "perceive".as_ref(),
        "--input".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    for f in [
        "summary.json",
        "cleaned.pcd",
        "surface_grid.csv",
        "fit_samples.csv",
        "height_map.svg",
        "height_map.png",
        "residuals.svg",
        "profile.svg",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    // The cleaned cloud holds the count the summary gives (its PCD header says so).
    let bytes = std::fs::read(out.join("cleaned.pcd")).unwrap();
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(400)]).to_string();
    let points: usize = head
        .lines()
        .find_map(|l| l.strip_prefix("POINTS "))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert_eq!(serde_json::json!(points), s["output_points"]);
}

#[test]
fn bad_scans_and_settings_are_refused_clearly() {
    let dir = TempDir::new("perceive-bad");
    let missing = dir.path().join("nope.pcd");
    let r = run(&["perceive".as_ref(), "--input".as_ref(), missing.as_os_str()]).fails();
    assert!(
        r.error_message().contains("nope.pcd"),
        "{}",
        r.error_message()
    );
    let unknown = dir.write("scan.e57", "whatever");
    let r = run(&["perceive".as_ref(), "--input".as_ref(), unknown.as_os_str()]).fails();
    assert!(r.error_message().contains("e57"), "{}", r.error_message());
    let empty = dir.write("empty.xyz", "");
    let r = run(&["perceive".as_ref(), "--input".as_ref(), empty.as_os_str()]).fails();
    assert!(
        r.error_message().contains("empty.xyz"),
        "{}",
        r.error_message()
    );
    let lies = dir.write("lies.pcd", "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 4000000000\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4000000000\nDATA binary\n\u{0}\u{0}\u{0}\u{0}");
    let r = run(&["perceive".as_ref(), "--input".as_ref(), lies.as_os_str()]).fails();
    assert!(
        r.error_message().contains("lies.pcd"),
        "{}",
        r.error_message()
    );
    // Settings: a leaf of zero, an unknown key.
    let scan = dir.path().join("scan.pcd");
    run(&[
        "generate-pile".as_ref(),
        "--points".as_ref(),
        "20000".as_ref(),
        "--out".as_ref(),
        scan.as_os_str(),
    ])
    .ok();
    let cfg = dir.write("zero.toml", "[voxel]\nleaf_spacings = 0.0\n");
    let r = run(&[
        "perceive".as_ref(),
        "--input".as_ref(),
        scan.as_os_str(),
        "--config".as_ref(),
        cfg.as_os_str(),
    ])
    .fails();
    assert!(
        r.error_message().to_lowercase().contains("leaf"),
        "{}",
        r.error_message()
    );
    let cfg = dir.write("typo.toml", "[voxel]\nleaf = 0.1\n");
    let r = run(&[
        "perceive".as_ref(),
        "--input".as_ref(),
        scan.as_os_str(),
        "--config".as_ref(),
        cfg.as_os_str(),
    ])
    .fails();
    assert!(
        r.error_message().contains("typo.toml:2") && r.error_message().contains("leaf"),
        "{}",
        r.error_message()
    );
    let r = run(&["generate-pile", "--shape", "pyramid", "--out", "x.pcd"]);
    assert_ne!(r.code(), Some(0));
    r.no_panic();
}

/// Issue 11: scales whose coordinates overflow (all inf) or the sampler's
/// range (a panic, exit 101) are refused, naming the setting, and no file
/// is written.
#[test]
fn generate_pile_refuses_scales_that_overflow() {
    let dir = TempDir::new("pile-scale");
    for scale in ["1e39", "1e307", "1e-9"] {
        let file = dir.path().join(format!("p{scale}.pcd"));
        let r = run(&[
            "generate-pile".as_ref(),
            "--scale".as_ref(),
            scale.as_ref(),
            "--points".as_ref(),
            "1000".as_ref(),
            "--out".as_ref(),
            file.as_os_str(),
        ])
        .fails();
        assert!(
            r.error_message().contains(&format!("--scale {scale}")),
            "{}",
            r.error_message()
        );
        assert!(!file.exists(), "{scale}: nothing written");
    }
}

/// Frame mode: `generate-pile --frames` writes a sequence, `perceive` on
/// the folder levels once, keeps going past a broken frame (counted, named)
/// and writes its files; each frame's cleaned cloud is what the library
/// gives for it with the first frame's levelling.
#[test]
fn a_folder_of_frames_is_perceived_frame_by_frame_past_a_broken_one() {
    use autoshovel_terrain::frames::FrameOptions;
    use autoshovel_terrain::perceive::PerceptionParams;
    let dir = TempDir::new("frames");
    let seq = dir.path().join("seq");
    let g = run(&[
        "generate-pile".as_ref(),
        "--points".as_ref(),
        "20000".as_ref(),
        "--frames".as_ref(),
        "4".as_ref(),
        "--seed".as_ref(),
        "7".as_ref(),
        "--out".as_ref(),
        seq.join("frame.pcd").as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    assert_eq!(g["frames"], 4);
    assert!(g["last_file"].as_str().unwrap().ends_with("frame-0003.pcd"));
    // A broken frame between the second and third (by name order).
    let broken = seq.join("frame-0001b.pcd");
    std::fs::write(
        &broken,
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let s = run(&[
        "perceive".as_ref(),
        "--input".as_ref(),
        seq.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--json".as_ref(),
    ])
    .ok()
    .json();
    assert_eq!(
        (s["frames"].as_u64(), s["frames_ok"].as_u64()),
        (Some(5), Some(4))
    );
    assert_eq!(s["frames_skipped"], 1);
    assert_eq!(s["skipped"][0]["index"], 2);
    let reason = s["skipped"][0]["reason"].as_str().unwrap();
    assert!(
        reason.contains("frame-0001b.pcd") && reason.contains("line 4"),
        "{reason}"
    );
    assert_eq!(s["relevelled_frames"], 1);
    assert!(s["realtime_priority"].is_null(), "ordinary scheduling");
    for key in [
        "roll_deg",
        "pitch_deg",
        "r2",
        "input_points",
        "output_points",
    ] {
        assert!(s[key].is_number(), "{key}");
    }
    assert_written(
        &out,
        &s,
        &[
            "frames.csv",
            "model.csv",
            "cleaned.pcd",
            "latency.svg",
            "latency.png",
            "model.svg",
            "model.png",
        ],
    );
    // The library on the same files gives the same last cloud.
    let done = autoshovel_terrain::frames::perceive_folder(
        &seq,
        &PerceptionParams::default(),
        FrameOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    let cleaned = autoshovel_point_cloud::io::read(&out.join("cleaned.pcd"), &mut |_, _| {})
        .unwrap()
        .cloud;
    assert_eq!(cleaned, done.last.cloud);
    assert_eq!(
        s["output_points"].as_u64(),
        Some(done.last.cloud.len() as u64)
    );
    // Frame-mode flags on a single file are refused.
    let e = run(&[
        "perceive".as_ref(),
        "--input".as_ref(),
        seq.join("frame-0000.pcd").as_os_str(),
        "--relevel-every".as_ref(),
        "5".as_ref(),
    ])
    .fails();
    assert!(e.error_message().contains("--relevel-every"));
    // An empty folder is refused by name.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let e = run(&["perceive".as_ref(), "--input".as_ref(), empty.as_os_str()]).fails();
    assert!(
        e.error_message().contains("no frame"),
        "{}",
        e.error_message()
    );
}

/// `--realtime`: a priority outside 1–99, or a single file, is refused by
/// name; on a folder the frames run under SCHED_FIFO and the summary says
/// so or, where the system refuses it (not root, no CAP_SYS_NICE), the
/// error says what to do and nothing is written.
#[test]
fn frames_run_under_real_time_scheduling_or_say_why_not() {
    let dir = TempDir::new("realtime");
    let seq = dir.path().join("seq");
    run(&[
        "generate-pile".as_ref(),
        "--points".as_ref(),
        "20000".as_ref(),
        "--frames".as_ref(),
        "2".as_ref(),
        "--out".as_ref(),
        seq.join("frame.pcd").as_os_str(),
    ])
    .ok();
    let perceive = |input: &std::path::Path, more: &[&str]| {
        let mut args: Vec<&std::ffi::OsStr> =
            vec!["perceive".as_ref(), "--input".as_ref(), input.as_os_str()];
        args.extend(more.iter().map(std::ffi::OsStr::new));
        run(&args)
    };
    for bad in ["0", "100"] {
        let e = perceive(&seq, &["--realtime", bad]).fails();
        assert!(
            e.error_message().contains(&format!("--realtime {bad}"))
                && e.error_message().contains("from 1 to 99"),
            "{}",
            e.error_message()
        );
    }
    let e = perceive(&seq.join("frame-0000.pcd"), &["--realtime"]).fails();
    assert!(
        e.error_message().contains("--realtime"),
        "{}",
        e.error_message()
    );
    let out = dir.path().join("out");
    let got = perceive(
        &seq,
        &["--realtime", "20", "--out", out.to_str().unwrap(), "--json"],
    );
    if got.code() == Some(0) {
        let s = got.json();
        assert_eq!(s["realtime_priority"], 20);
        assert_eq!(s["frames_ok"], 2);
        assert!(out.join("frames.csv").exists());
    } else {
        let e = got.fails();
        assert!(
            e.error_message().contains("--realtime 20")
                && e.error_message().contains("CAP_SYS_NICE"),
            "{}",
            e.error_message()
        );
        assert!(!out.exists(), "nothing written");
    }
}

#[test]
fn a_survey_by_tiles_writes_its_tiles_and_refuses_a_tile_over_the_limit() {
    let dir = TempDir::new("survey");
    let scan = dir.path().join("survey.laz");
    run(&[
        "generate-pile",
        "--points",
        "60000",
        "--seed",
        "4",
        "--out",
        scan.to_str().unwrap(),
        "--json",
    ])
    .ok();
    let out = dir.path().join("out");
    let s = run(&[
        "perceive",
        "--input",
        scan.to_str().unwrap(),
        "--tile-size",
        "8",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ])
    .ok()
    .json();
    assert_eq!(s["mode"], "tiles");
    assert_eq!(s["input_points"], 60000);
    for key in [
        "roll_deg",
        "pitch_deg",
        "r2",
        "output_points",
        "peak_memory_bytes",
        "halo_m",
    ] {
        assert!(s[key].is_number(), "{key}: {}", s[key]);
    }
    // Every cleaned point is in exactly one tile file.
    let files: Vec<String> = s["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap().to_string())
        .collect();
    let tiles: Vec<&String> = files.iter().filter(|f| f.starts_with("tiles/")).collect();
    assert_eq!(tiles.len() as u64, s["tiles_used"].as_u64().unwrap());
    let mut points = 0;
    for t in &tiles {
        points += autoshovel_point_cloud::io::read(&out.join(t), &mut |_, _| {})
            .unwrap()
            .cloud
            .len();
    }
    assert_eq!(points as u64, s["output_points"].as_u64().unwrap());
    assert_written(
        &out,
        &s,
        &[
            "model.csv",
            "stages.csv",
            "model.svg",
            "model.png",
            "stages.svg",
        ],
    );
    // No working file is left in the output.
    let hidden: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
    // A tile over the memory limit: a clear error, nothing written.
    let out2 = dir.path().join("out2");
    let e = run(&[
        "perceive",
        "--input",
        scan.to_str().unwrap(),
        "--tile-size",
        "100",
        "--memory-limit",
        "0.001",
        "--out",
        out2.to_str().unwrap(),
    ])
    .fails();
    assert!(
        e.error_message().contains("tile (0, 0)"),
        "{}",
        e.error_message()
    );
    let left: Vec<_> = std::fs::read_dir(&out2)
        .map(|d| d.filter_map(|e| e.ok()).collect())
        .unwrap_or_default();
    assert!(left.is_empty(), "{left:?}");
    // A survey file that is not LAS/LAZ is refused by name.
    let pcd = dir.path().join("scan.pcd");
    run(&[
        "generate-pile",
        "--points",
        "5000",
        "--out",
        pcd.to_str().unwrap(),
        "--json",
    ])
    .ok();
    let e = run(&["perceive", "--input", pcd.to_str().unwrap(), "--tiles"]).fails();
    assert!(
        e.error_message().contains("scan.pcd") && e.error_message().contains("LAS"),
        "{}",
        e.error_message()
    );
}
