//! Issue 46: real surveys nobody here made, kept whole. PDAL's test
//! surveys (crates/perception/point-cloud/tests/data/README.md) go through
//! `autoshovel filter`, and laspy, an independent LAS implementation, says
//! whether what came out is what went in: every coordinate within half the
//! file's scale, the same CRS, point format, version and attributes (a
//! no-op), or rows of the input whole (removal filters).
//!
//! `.ci/run` installs laspy in a venv and sets `AUTOSHOVEL_PYTHON`; with it
//! set, a missing laspy fails the test. Without it, `python3` is tried and
//! the tests are skipped, saying so, when it has no laspy.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::*;

fn python() -> Option<String> {
    let set = std::env::var("AUTOSHOVEL_PYTHON").ok();
    let py = set.clone().unwrap_or_else(|| "python3".into());
    let ok = Command::new(&py)
        .args(["-c", "import laspy, lazrs, numpy, pyproj"])
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    match (ok, set) {
        (true, _) => Some(py),
        (false, Some(p)) => {
            panic!("AUTOSHOVEL_PYTHON={p} cannot import laspy, lazrs, numpy and pyproj")
        }
        (false, None) => {
            eprintln!("SKIPPED: python3 has no laspy (pip install 'laspy[lazrs]' pyproj, or run .ci/run, which sets AUTOSHOVEL_PYTHON)");
            None
        }
    }
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../perception/point-cloud/tests/data")
        .join(name)
}

/// Runs the laspy peer; its JSON line, or a panic with its reason.
fn peer(py: &str, args: &[&Path], mode: &str) -> serde_json::Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/peers/las_peer.py");
    let out = Command::new(py)
        .arg(script)
        .arg(mode)
        .args(args)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(text.trim()).unwrap_or_else(|_| {
        panic!(
            "laspy peer: {text} {}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    assert!(
        out.status.success() && v["ok"] == true,
        "laspy {mode} {args:?}: {v}"
    );
    v
}

/// `autoshovel perceive --input INPUT [--config CONFIG] --json`, which
/// must succeed: its summary.
fn perceive_json(input: &Path, config: Option<&Path>) -> serde_json::Value {
    let mut a = vec!["perceive".as_ref(), "--input".as_ref(), input.as_os_str()];
    if let Some(c) = config {
        a.extend(["--config".as_ref(), c.as_os_str()]);
    }
    a.push("--json".as_ref());
    run(&a).ok().json()
}

fn filter(input: &Path, output: &Path, stages: &[&str]) {
    let mut a: Vec<String> = vec![
        "filter".into(),
        "--input".into(),
        input.display().to_string(),
        "--output".into(),
        output.display().to_string(),
    ];
    a.extend(stages.iter().map(|s| s.to_string()));
    run(&a).ok();
}

#[test]
fn a_no_op_filter_gives_laspy_every_coordinate_attribute_and_the_crs_back() {
    let Some(py) = python() else { return };
    let tmp = TempDir::new("real-noop");
    for (file, epsg) in [
        ("autzen-utm.las", Some(26910)),
        ("mvk-thin.las", Some(26995)),
        ("extrabytes.las", None),
    ] {
        for ext in ["las", "laz"] {
            let out = tmp.path().join(format!("{file}.{ext}"));
            filter(&data(file), &out, &["--pass", "z:-inf:inf"]);
            let v = peer(&py, &[&data(file), &out], "same");
            assert_eq!(v["epsg"].as_i64(), epsg, "{file}");
            assert_eq!(v["worst_steps"].as_f64(), Some(0.0), "{file}: {v}");
        }
    }
}

#[test]
fn removal_filters_keep_whole_rows_of_a_survey_13_km_across() {
    let Some(py) = python() else { return };
    let tmp = TempDir::new("real-wide");
    // laspy writes it: Autzen in UTM and a copy 12 km east, at 1 mm steps.
    let wide = tmp.path().join("wide.las");
    let v = peer(&py, &[&data("autzen-utm.las"), &wide], "wide");
    assert!(v["span_m"].as_f64().unwrap() > 10_000.0, "{v}");
    let out = tmp.path().join("noop.laz");
    filter(&wide, &out, &["--pass", "x:-inf:inf"]);
    peer(&py, &[&wide, &out], "same");
    for stages in [
        &["--statistical", "8,1"][..],
        &["--radius", "20,3"],
        &["--pass", "z:130:170"],
        &[
            "--pass",
            "x:495000:inf",
            "--statistical",
            "8,1,both",
            "--radius",
            "20,3",
        ],
    ] {
        let out = tmp.path().join("kept.las");
        let _ = std::fs::remove_file(&out);
        filter(&wide, &out, stages);
        let v = peer(&py, &[&wide, &out], "subset");
        let (kept, of) = (v["points"].as_u64().unwrap(), v["of"].as_u64().unwrap());
        assert!(kept > 0 && kept < of, "{stages:?}: {v}");
    }
}

/// The same scan levels the same from every container and in any point
/// order: PDAL's Autzen sample as COPC (in tests/data), and laspy's
/// plain-LAS, point-wise LAZ (lazrs) and shuffled copies of it, each with
/// its CRS (a compound one: metres across, US survey feet up). PDAL's
/// point-wise LASzip copy of the same points is not among them: it states
/// no CRS, so its z stays in feet and the scan is another shape.
/// Before the floor search drew its points by their coordinates, the
/// shuffled copy levelled differently (a floor of 9 points against 15).
#[test]
fn the_same_scan_levels_the_same_from_las_laz_copc_and_shuffled() {
    let Some(py) = python() else { return };
    let tmp = TempDir::new("real-level");
    let copc = data("pdal_1.2-with-color.copc.laz");
    let (plain, laz, shuffled) = (
        tmp.path().join("plain.las"),
        tmp.path().join("pointwise.laz"),
        tmp.path().join("shuffled.las"),
    );
    peer(&py, &[&copc, &plain], "copy");
    peer(&py, &[&copc, &laz], "copy");
    peer(&py, &[&copc, &shuffled], "shuffle");
    // An airborne survey: its ground is a small share of the returns, and
    // the fit's gate is off (this is about the levelling). Estimated, not
    // taken as level: by default a survey in a projected CRS is level.
    let config = tmp.write(
        "level.toml",
        "[level]\nmode = \"estimate\"\nmin_floor_share = 0.005\n[fit]\nr2_threshold = 0\n",
    );
    let mut angles = Vec::new();
    for input in [copc, plain, laz, shuffled] {
        let v = perceive_json(&input, Some(&config));
        angles.push((f64_field(&v, "roll_deg"), f64_field(&v, "pitch_deg")));
    }
    for (i, a) in angles.iter().enumerate() {
        assert!(
            (a.0 - angles[0].0).abs() < 0.01 && (a.1 - angles[0].1).abs() < 0.01,
            "input {i}: roll {} pitch {}, the COPC's {} {}",
            a.0,
            a.1,
            angles[0].0,
            angles[0].1
        );
    }
    assert!(
        angles[0].0.abs() > 0.0,
        "a real estimate, not the default: {angles:?}"
    );
}

/// The height model's volume above a given base against laspy + numpy's
/// own grid of the same definition (mean height a cell of three point
/// spacings, the points at or above the base), in metres by pyproj's unit
/// of the file's CRS: a survey in UTM metres and one in US survey feet
/// (EPSG:2903). Every filter off, so both grid the same points.
#[test]
fn volume_above_a_given_base_agrees_with_laspy_and_numpy_in_metres() {
    let Some(py) = python() else { return };
    let tmp = TempDir::new("real-volume");
    for (file, base_m) in [("autzen-utm.las", 140.0), ("4_6_crop.las", 2160.0)] {
        let config = tmp.write(
            "volume.toml",
            format!(
                "[level]\nmode = \"none\"\n[ground]\nmode = \"height\"\nheight_m = {base_m}\nmargin_m = 0\n\
                 [radius]\nenabled = false\n[statistical]\nenabled = false\n[voxel]\nenabled = false\n\
                 [smooth]\nenabled = false\n[fit]\ncell_spacings = 3\n"
            ),
        );
        let input = data(file);
        let v = perceive_json(&input, Some(&config));
        assert_eq!(v["ground_mode"], "height", "{file}");
        let ours = f64_field(&v, "volume_m3");
        let base = f64_field(&v, "volume_base_m");
        assert!((base - base_m).abs() < 1e-6, "{file}: base {base}");
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/peers/las_peer.py");
        let out = Command::new(&py)
            .arg(script)
            .args(["volume", input.to_str().unwrap(), &base_m.to_string(), "3"])
            .output()
            .unwrap();
        let theirs: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let theirs = theirs["volume_m3"].as_f64().unwrap();
        assert!(theirs > 100.0, "{file}: a real volume, {theirs}");
        assert!(
            (ours - theirs).abs() <= 0.01 * theirs,
            "{file}: ours {ours} m³, laspy + numpy {theirs} m³"
        );
        let model = &v["height_model"];
        assert!(model["rms_residual_m"].as_f64().unwrap() > 0.0, "{model}");
    }
}

/// A classified airborne survey of a slope with trees on it (PDAL's
/// 4_6_crop, US survey feet, class 2 its ground): with no settings the
/// height model's residual is metres, and perceive says so, naming the
/// setting that keeps the file's ground. That setting, taken from the
/// warning as a user would copy it, gives a residual of centimetres; with
/// a base it gives a volume laspy + numpy agree with to 1 %.
#[test]
fn a_classified_slope_says_how_to_keep_its_ground_and_that_advice_works() {
    let Some(py) = python() else { return };
    let tmp = TempDir::new("real-classified");
    let input = data("4_6_crop.las");
    let perceive = |config: Option<&Path>| perceive_json(&input, config);
    let rms = |v: &serde_json::Value| v["height_model"]["rms_residual_m"].as_f64().unwrap();
    let plain = perceive(None);
    assert!(
        rms(&plain) > 1.0,
        "trees over the ground: {}",
        plain["height_model"]
    );
    let warning = plain["warnings"][0]
        .as_str()
        .unwrap_or_default()
        .to_string();
    let setting = warning
        .split_once("[range] limits = ")
        .and_then(|(_, rest)| rest.split_whitespace().next())
        .unwrap_or_else(|| panic!("no [range] advice in the warnings: {}", plain["warnings"]));
    assert_eq!(setting, "\"Classification[2:2]\"");
    let advised = tmp.write("advised.toml", format!("[range]\nlimits = {setting}\n"));
    let ground = perceive(Some(&advised));
    assert!(
        rms(&ground) < 0.05,
        "the ground alone: {}",
        ground["height_model"]
    );
    assert_eq!(ground["warnings"], serde_json::json!([]));
    assert_eq!(
        ground["stage_points"]["range"], 9003,
        "laspy counts 9003 of class 2"
    );
    // The same ranges through `filter`, as PDAL writes them, against numpy's
    // selection of the same rows (z in the file's US survey feet).
    let out = tmp.path().join("ground.las");
    filter(&input, &out, &["--range", "Classification[2:2],z[7085:]"]);
    let v = peer(
        &py,
        &[&input, &out, Path::new("2"), Path::new("7085")],
        "range",
    );
    assert!(v["points"].as_u64().unwrap() > 1000, "{v}");
    // The survey path reads no dimensions: it refuses the range, saying to
    // select first; done so, the selected file perceives by tiles (Autzen,
    // in metres: the survey path does not convert feet).
    let input = data("autzen-utm.las");
    let args = |f: &Path, c: Option<&Path>| {
        let mut a = vec![
            "perceive".into(),
            "--tiles".into(),
            "--input".into(),
            f.display().to_string(),
        ];
        if let Some(c) = c {
            a.extend(["--config".into(), c.display().to_string()]);
        }
        a
    };
    let refused = run(&args(&input, Some(&advised))).fails();
    let m = refused.error_message();
    assert!(
        m.contains("not applied with --tiles") && m.contains("--range"),
        "{m}"
    );
    let ground_only = tmp.path().join("ground-only.las");
    filter(&input, &ground_only, &["--range", "Classification[2:2]"]);
    run(&args(&ground_only, None)).ok();
    let input = data("4_6_crop.las");

    let base_m = 2160.0;
    let with_base = tmp.write(
        "volume.toml",
        format!(
            "[range]\nlimits = {setting}\n[level]\nmode = \"none\"\n\
             [ground]\nmode = \"height\"\nheight_m = {base_m}\nmargin_m = 0\n\
             [radius]\nenabled = false\n[statistical]\nenabled = false\n[voxel]\nenabled = false\n\
             [smooth]\nenabled = false\n[fit]\ncell_spacings = 3\n"
        ),
    );
    let v = perceive(Some(&with_base));
    let ours = f64_field(&v, "volume_m3");
    let base = Path::new(&base_m.to_string()).to_path_buf();
    let theirs = peer(
        &py,
        &[&input, &base, Path::new("3"), Path::new("2")],
        "volume",
    );
    let theirs = theirs["volume_m3"].as_f64().unwrap();
    assert!(theirs > 100.0, "a real volume, {theirs}");
    assert!(
        (ours - theirs).abs() <= 0.01 * theirs,
        "ours {ours} m³, laspy + numpy {theirs} m³"
    );
}

/// Two surveys of the same BMX track, 2010 and 2023 (PDAL's change-detection
/// data; metres across, US survey feet up, in one compound CRS): with the
/// earlier as the base surface, the fill, cut and net volume agree with
/// laspy + numpy's grid of the same definition, each axis in metres by
/// pyproj. Had z stayed in feet, every volume would be 3.28 times too big.
#[test]
fn the_change_between_two_surveys_agrees_with_laspy_and_numpy() {
    let Some(py) = python() else { return };
    let tmp = TempDir::new("real-change");
    let (later, earlier) = (
        data("pdal_autzen-bmx-2023.las"),
        data("pdal_autzen-bmx-2010.las"),
    );
    let config = tmp.write(
        "change.toml",
        format!(
            "[ground]\nmode = \"surface\"\nsurface = {:?}\n\
             [radius]\nenabled = false\n[statistical]\nenabled = false\n[voxel]\nenabled = false\n\
             [smooth]\nenabled = false\n[fit]\ncell_spacings = 3\n",
            earlier.display().to_string()
        ),
    );
    let v = perceive_json(&later, Some(&config));
    assert_eq!(v["ground_mode"], "surface");
    assert_eq!(v["level_mode"], "none", "a survey is level");
    let ours = &v["change"];
    let theirs = peer(&py, &[&later, &earlier, Path::new("3")], "change");
    assert_eq!(
        ours["cells_compared"], theirs["cells_compared"],
        "{ours} {theirs}"
    );
    for key in ["fill_m3", "cut_m3", "net_m3"] {
        let (a, b) = (ours[key].as_f64().unwrap(), theirs[key].as_f64().unwrap());
        assert!(b.abs() > 10.0, "{key}: a real volume, {b}");
        assert!(
            (a - b).abs() <= 0.01 * b.abs(),
            "{key}: ours {a} m³, laspy + numpy {b} m³"
        );
    }
    assert_eq!(v["volume_m3"], ours["fill_m3"]);
    // A base in another CRS is refused, naming both.
    let other = tmp.write(
        "other.toml",
        format!(
            "[ground]\nmode = \"surface\"\nsurface = {:?}\n",
            data("4_6_crop.las").display().to_string()
        ),
    );
    let refused = run(&[
        "perceive".as_ref(),
        "--input".as_ref(),
        later.as_os_str(),
        "--config".as_ref(),
        other.as_os_str(),
    ])
    .fails();
    let m = refused.error_message();
    assert!(
        m.contains("4_6_crop.las") && m.contains("EPSG:2903") && m.contains("same frame"),
        "{m}"
    );
}

/// The survey path's cleaned tiles are in the survey's own coordinates and
/// CRS, with its points' attributes: before, they were written less the
/// survey's kilometre origin and with no CRS (Autzen's eastings of 494 km
/// came out as 428 m), and then with every attribute field zero.
#[test]
fn survey_tiles_keep_the_surveys_coordinates_crs_and_attributes() {
    let Some(py) = python() else { return };
    let tmp = TempDir::new("real-tiles");
    let input = data("autzen-utm.las");
    let out = tmp.path().join("out");
    let survey = |out: &Path, config: Option<&Path>| {
        let mut a = vec![
            "perceive".as_ref(),
            "--tiles".as_ref(),
            "--tile-size".as_ref(),
            "300".as_ref(),
            "--input".as_ref(),
            input.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ];
        if let Some(c) = config {
            a.extend(["--config".as_ref(), c.as_os_str()]);
        }
        let r = run(&a).ok();
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["warnings"], serde_json::json!([]), "{summary}");
        assert!(!r.stderr.contains("warning"), "{}", r.stderr);
        let mut tiles: Vec<PathBuf> = std::fs::read_dir(out.join("tiles"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        tiles.sort();
        assert!(tiles.len() > 1, "{tiles:?}");
        tiles
    };
    // With filters that keep points as they are (the statistical and
    // radius filters), every tile point is a survey point with all its
    // attributes, as laspy reads both.
    let config = tmp.path().join("keep.toml");
    std::fs::write(
        &config,
        "[voxel]\nenabled = false\n[smooth]\nenabled = false\n",
    )
    .unwrap();
    let kept = survey(&tmp.path().join("kept"), Some(&config));
    let mut args: Vec<&Path> = vec![&input];
    args.extend(kept.iter().map(PathBuf::as_path));
    let v = peer(&py, &args, "tile-attributes");
    assert!(v["points"].as_u64().unwrap() > 500, "{v}");
    assert!(v["dimensions"].to_string().contains("gps_time"), "{v}");
    let tiles = survey(&out, None);
    let mut args: Vec<&Path> = vec![&input];
    args.extend(tiles.iter().map(PathBuf::as_path));
    let v = peer(&py, &args, "tiles");
    assert!(v["points"].as_u64().unwrap() > 100, "{v}");
}

/// With no settings at all, a survey perceives, naming what the level and
/// ground stages chose; a longitude–latitude cloud is refused naming its
/// CRS and what to do.
#[test]
fn surveys_perceive_with_no_settings_and_degrees_are_refused() {
    for file in ["autzen-utm.las", "4_6_crop.las", "mvk-thin.las"] {
        let input = data(file);
        let v = perceive_json(&input, None);
        assert_eq!(v["level_mode"], "none", "{file}: a survey is level");
        assert!(
            v["ground_note"].as_str().unwrap_or("").contains("survey"),
            "{file}: {}",
            v["ground_note"]
        );
        assert!(f64_field(&v, "volume_m3") > 0.0);
    }
    let input = data("epsg_4326.las");
    for tiles in [false, true] {
        let mut args = vec!["perceive".as_ref(), "--input".as_ref(), input.as_os_str()];
        if tiles {
            args.push("--tiles".as_ref());
        }
        let r = run(&args).fails();
        let m = r.error_message();
        assert!(
            m.contains("epsg_4326.las")
                && m.contains("EPSG:4326")
                && m.contains("project it first"),
            "tiles {tiles}: {m}"
        );
    }
    // The survey path works in metres and does not convert: a feet survey
    // is refused naming its CRS, and the advice (no --tiles) works above.
    let feet = data("4_6_crop.las");
    let r = run(&[
        "perceive".as_ref(),
        "--tiles".as_ref(),
        "--input".as_ref(),
        feet.as_os_str(),
    ])
    .fails();
    let m = r.error_message();
    assert!(
        m.contains("4_6_crop.las") && m.contains("US survey foot") && m.contains("without --tiles"),
        "{m}"
    );
}

/// PDAL's own PCD of Autzen in UTM (X Y Z as F8 doubles, upper case, and
/// its LAS dimensions as fields) reads with every coordinate and attribute
/// laspy reads from PDAL's LAS of the same points; and a survey written to
/// PCD in each encoding (doubles about no origin, the columns as fields)
/// comes back to LAS with the same coordinates and attributes.
#[test]
fn pdal_pcd_and_pcd_round_trips_keep_coordinates_and_attributes() {
    let Some(py) = python() else { return };
    let tmp = TempDir::new("real-pcd");
    let las = data("autzen-utm.las");
    let from_pcd = tmp.path().join("from-pcd.las");
    filter(
        &data("pdal_autzen-utm.pcd"),
        &from_pcd,
        &["--pass", "z:-inf:inf"],
    );
    peer(&py, &[&las, &from_pcd], "values");
    for encoding in ["binary", "ascii", "binary-compressed"] {
        let pcd = tmp.path().join(format!("{encoding}.pcd"));
        filter(
            &las,
            &pcd,
            &["--pass", "z:-inf:inf", "--encoding", encoding],
        );
        let back = tmp.path().join(format!("{encoding}.las"));
        filter(&pcd, &back, &["--pass", "z:-inf:inf"]);
        peer(&py, &[&las, &back], "values");
    }
}
