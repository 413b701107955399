//! Tiles give the whole cloud's result: a survey perceived by tiles much
//! smaller than the pile (so that many points, outliers among them, lie near
//! a tile edge) keeps, stage by stage, the same number of points as the
//! whole-cloud pipeline with the same roll, pitch and floor, and its cleaned
//! cloud is the whole cloud's bit for bit (as a set: tiles hand points on
//! tile by tile). Also: a survey in several files is the concatenation of
//! its files, files that do not share a scale are refused naming the file,
//! a tile over the memory limit is refused naming the tile, and no working
//! file is left behind.

use std::path::{Path, PathBuf};

use autoshovel_point_cloud::io::{read, write, Encoding};
use autoshovel_point_cloud::{Point, PointCloud};
use autoshovel_terrain::perceive::{perceive_after, PerceptionParams, Prior};
use autoshovel_terrain::tiles::{
    perceive_tiled, perceive_tiled_with, run_tile_task, Survey, TileExecutor, TileOptions,
    TileReport, TileTask, TiledPerceived,
};
use autoshovel_terrain::{generate_pile, PileParams, ScanPattern, SurfaceError};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("autoshovel-tiles-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Asserts that the work folder `d` holds the survey file alone (no
/// working file left behind), then removes it.
fn only_the_survey_left(d: &Path) {
    let left: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "{left:?}");
    let _ = std::fs::remove_dir_all(d);
}

fn pile(points: usize, seed: u64, pattern: ScanPattern) -> PointCloud {
    generate_pile(&PileParams {
        points,
        seed,
        pattern,
        ..PileParams::default()
    })
    .expect("pile")
}

fn options(tile_m: f64, work: &Path) -> TileOptions {
    TileOptions {
        tile_m: Some(tile_m),
        sample_points: 50_000,
        work_dir: work.to_path_buf(),
        ..TileOptions::default()
    }
}

/// The survey by tiles, and its cleaned points gathered.
fn tiled(
    files: &[PathBuf],
    params: &PerceptionParams,
    opt: &TileOptions,
) -> (TiledPerceived, Vec<Point>) {
    let survey = Survey::open(files).expect("survey");
    let mut cleaned = Vec::new();
    let got = perceive_tiled(&survey, params, opt, &mut |_, _, _| {}, &mut |tile| {
        cleaned.extend_from_slice(&tile.cloud.points);
        Ok(())
    })
    .expect("tiled");
    (got, cleaned)
}

fn sorted_bits(points: &[Point]) -> Vec<[u32; 3]> {
    let mut v: Vec<[u32; 3]> = points.iter().map(|p| p.map(f32::to_bits)).collect();
    v.sort_unstable();
    v
}

/// The tiled run against the whole cloud with the same roll, pitch, floor,
/// scale and spacing.
fn check_against_whole(
    whole: &PointCloud,
    params: &PerceptionParams,
    got: &TiledPerceived,
    cleaned: &[Point],
) {
    let prior = Prior {
        roll_rad: got.roll_rad,
        pitch_rad: got.pitch_rad,
        floor: got.floor,
        scale: got.scale,
        spacing_m: got.spacing_m,
    };
    let reference = perceive_after(whole, params, Some(&prior), &mut |_| {}).expect("whole");
    assert_eq!(got.input_points, whole.len() as u64);
    let counts =
        |stages: &[autoshovel_terrain::perceive::StageRecord]| -> Vec<(&'static str, usize)> {
            stages
                .iter()
                .filter(|s| !matches!(s.stage, "read" | "level" | "write" | "fit"))
                .map(|s| (s.stage, s.points))
                .collect()
        };
    println!(
        "tiles {:?} of {} m, halo {:.3} m, {} searched again; stages {:?}",
        got.grid,
        got.tile_m,
        got.halo_m,
        got.statistical_researched,
        counts(&got.stages)
    );
    assert_eq!(counts(&got.stages), counts(&reference.stages));
    assert_eq!(cleaned.len() as u64, got.output_points);
    assert!(
        sorted_bits(cleaned) == sorted_bits(&reference.cloud.points),
        "the cleaned points differ from the whole cloud's"
    );
}

#[test]
fn tiles_keep_what_the_whole_cloud_keeps_bit_for_bit() {
    let d = dir("whole");
    let file = d.join("pile.laz");
    write(
        &file,
        &pile(120_000, 7, ScanPattern::Rosette),
        Encoding::Binary,
    )
    .expect("write");
    // The whole cloud as the survey reader sees it (LAZ stores millimetres).
    let whole = read(&file, &mut |_, _| {}).expect("read").cloud;
    let params = PerceptionParams::default();
    // Tiles of 3 m over a ~30 m pile: about a hundred, most points within a
    // few halos of an edge.
    let (got, cleaned) = tiled(&[file], &params, &options(3.0, &d));
    assert!(got.tiles_used >= 30, "{} tiles used", got.tiles_used);
    assert!(
        got.statistical_researched > 0,
        "no outlier needed a wider search"
    );
    check_against_whole(&whole, &params, &got, &cleaned);
    // Nothing left in the work folder but the survey itself.
    only_the_survey_left(&d);
}

#[test]
fn a_survey_in_several_files_is_their_concatenation() {
    let d = dir("files");
    let scan = pile(80_000, 11, ScanPattern::Area);
    // Three files of unequal parts, as a survey's flight lines might be.
    let cuts = [0, 17_000, 55_000, scan.len()];
    let mut files = Vec::new();
    for (i, w) in cuts.windows(2).enumerate() {
        let f = d.join(format!("part-{i}.laz"));
        write(
            &f,
            &PointCloud::new(scan.points[w[0]..w[1]].to_vec()),
            Encoding::Binary,
        )
        .unwrap();
        files.push(f);
    }
    let mut whole = Vec::new();
    for f in &files {
        whole.extend(read(f, &mut |_, _| {}).unwrap().cloud.points);
    }
    let params = PerceptionParams::default();
    // The folder, read in natural order, is the same survey.
    let (got, cleaned) = tiled(std::slice::from_ref(&d), &params, &options(4.0, &d));
    check_against_whole(&PointCloud::new(whole), &params, &got, &cleaned);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn files_of_another_scale_are_refused_naming_the_file() {
    let d = dir("scale");
    let scan = pile(20_000, 3, ScanPattern::Area);
    let a = d.join("a.las");
    write(&a, &scan, Encoding::Binary).unwrap();
    // The same points at a 1 cm scale: written by hand with `las`.
    let b = d.join("b.las");
    let mut builder = las::Builder::from((1, 2));
    builder.transforms = las::Vector {
        x: las::Transform {
            scale: 0.01,
            offset: 0.0,
        },
        y: las::Transform {
            scale: 0.01,
            offset: 0.0,
        },
        z: las::Transform {
            scale: 0.01,
            offset: 0.0,
        },
    };
    let mut w = las::Writer::from_path(&b, builder.into_header().unwrap()).unwrap();
    for p in &scan.points {
        w.write_point(las::Point {
            x: f64::from(p[0]),
            y: f64::from(p[1]),
            z: f64::from(p[2]),
            ..Default::default()
        })
        .unwrap();
    }
    w.close().unwrap();
    drop(w);
    let err = Survey::open(&[a, b.clone()]).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SurfaceError::Survey { .. }), "{msg}");
    assert!(
        msg.starts_with(&b.display().to_string()) && msg.contains("scale"),
        "{msg}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A LAS file of `points` with a WKT coordinate system record.
fn las_with_wkt(path: &Path, points: &[Point], wkt: &str) {
    let mut builder = las::Builder::from((1, 4));
    builder.vlrs.push(las::Vlr {
        user_id: "LASF_Projection".into(),
        record_id: 2112,
        description: "OGC WKT".into(),
        data: wkt.as_bytes().to_vec(),
    });
    let mut w = las::Writer::from_path(path, builder.into_header().unwrap()).unwrap();
    for p in points {
        w.write_point(las::Point {
            x: f64::from(p[0]),
            y: f64::from(p[1]),
            z: f64::from(p[2]),
            ..Default::default()
        })
        .unwrap();
    }
    w.close().unwrap();
}

#[test]
fn files_of_another_coordinate_system_are_refused_naming_the_file() {
    let d = dir("crs");
    let scan = pile(10_000, 3, ScanPattern::Area);
    let (a, b, c) = (d.join("a.las"), d.join("b.las"), d.join("c.las"));
    las_with_wkt(&a, &scan.points, "PROJCS[\"WGS 84 / UTM zone 33N\"]");
    las_with_wkt(&b, &scan.points, "PROJCS[\"WGS 84 / UTM zone 33N\"]");
    las_with_wkt(&c, &scan.points, "PROJCS[\"WGS 84 / UTM zone 34N\"]");
    // The same system twice is one survey.
    assert_eq!(Survey::open(&[a.clone(), b]).unwrap().files.len(), 2);
    let err = Survey::open(&[a, c.clone()]).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.starts_with(&c.display().to_string())
            && msg.contains("zone 34N")
            && msg.contains("zone 33N"),
        "{msg}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_tile_over_the_memory_limit_is_refused_naming_it_and_leaves_nothing() {
    let d = dir("limit");
    let file = d.join("pile.laz");
    write(&file, &pile(40_000, 5, ScanPattern::Area), Encoding::Binary).unwrap();
    let survey = Survey::open(&[file]).unwrap();
    let opt = TileOptions {
        memory_limit: 1 << 20,
        ..options(100.0, &d)
    };
    let err = perceive_tiled(
        &survey,
        &PerceptionParams::default(),
        &opt,
        &mut |_, _, _| {},
        &mut |_| Ok(()),
    )
    .unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SurfaceError::TileTooLarge { .. }), "{msg}");
    assert!(
        msg.contains("tile (0, 0)") && msg.contains("--tile-size"),
        "{msg}"
    );
    only_the_survey_left(&d);
}

#[test]
fn a_survey_in_utm_metres_keeps_its_millimetres() {
    let d = dir("utm");
    let scan = pile(60_000, 9, ScanPattern::Area);
    // The same scan at UTM coordinates (E 500 km, N 5 000 km, where f32
    // steps by half a metre) and 1 km from the origin, both stored in mm.
    let write_at = |path: &Path, shift: [f64; 2]| {
        let mut builder = las::Builder::from((1, 2));
        let t = |offset| las::Transform {
            scale: 0.001,
            offset,
        };
        builder.transforms = las::Vector {
            x: t(shift[0]),
            y: t(shift[1]),
            z: t(0.0),
        };
        let mut w = las::Writer::from_path(path, builder.into_header().unwrap()).unwrap();
        for p in &scan.points {
            w.write_point(las::Point {
                x: f64::from(p[0]) + shift[0],
                y: f64::from(p[1]) + shift[1],
                z: f64::from(p[2]),
                ..Default::default()
            })
            .unwrap();
        }
        w.close().unwrap();
    };
    let (near, utm) = (d.join("near.las"), d.join("utm.las"));
    // 1 km from the origin: the frame the UTM survey is read in.
    write_at(&near, [1_000.0, 1_000.0]);
    write_at(&utm, [500_000.0, 5_000_000.0]);
    let params = PerceptionParams::default();
    let (a, ca) = tiled(&[near], &params, &options(6.0, &d));
    let survey = Survey::open(std::slice::from_ref(&utm)).unwrap();
    let origin = survey.origin();
    assert_eq!(origin, [499_000.0, 4_999_000.0, 0.0]);
    let (b, cb) = tiled(&[utm], &params, &options(6.0, &d));
    assert_eq!(b.origin_m, origin);
    // The same survey, read 1 km from the origin either way: the same
    // points kept, each within a tenth of a millimetre.
    assert_eq!(a.output_points, b.output_points);
    let (mut ca, mut cb) = (ca, cb);
    let key = |p: &Point| (p[0] + 1000.0 * p[1]) as i64;
    ca.sort_by_key(key);
    cb.sort_by_key(key);
    let worst = ca
        .iter()
        .zip(&cb)
        .map(|(p, q)| (0..3).map(|k| (q[k] - p[k]).abs()).fold(0.0f32, f32::max))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-4, "worst {worst} m");
    let _ = std::fs::remove_dir_all(&d);
}

/// An executor as a cluster would be: every task sent as JSON and read
/// back, the stage's tasks run last to first on two threads at once.
struct Elsewhere {
    /// Rewrites each task's JSON on its way (a worker's view of it).
    route: fn(String) -> String,
    /// Reports dropped from each stage's answer (a lost task).
    drop_reports: usize,
    stages: Vec<(String, usize)>,
}

impl Elsewhere {
    fn new() -> Self {
        Self {
            route: |s| s,
            drop_reports: 0,
            stages: Vec::new(),
        }
    }
}

impl TileExecutor for Elsewhere {
    fn run(
        &mut self,
        stage: &str,
        tasks: Vec<TileTask>,
        _progress: &mut dyn FnMut(&str, u64, u64),
    ) -> Result<Vec<TileReport>, SurfaceError> {
        self.stages.push((stage.to_string(), tasks.len()));
        let sent: Vec<String> = tasks
            .iter()
            .rev()
            .map(|t| (self.route)(serde_json::to_string(t).unwrap()))
            .collect();
        let half = sent.len().div_ceil(2);
        let (a, b) = sent.split_at(half);
        let work = |part: &[String]| -> Result<Vec<String>, SurfaceError> {
            part.iter()
                .map(|json| {
                    let task: TileTask = serde_json::from_str(json).unwrap();
                    let report = run_tile_task(&task)?;
                    Ok(serde_json::to_string(&report).unwrap())
                })
                .collect()
        };
        let (ra, rb) = std::thread::scope(|s| {
            let ha = s.spawn(|| work(a));
            let hb = s.spawn(|| work(b));
            (ha.join().unwrap(), hb.join().unwrap())
        });
        let mut reports: Vec<TileReport> = ra?
            .into_iter()
            .chain(rb?)
            .map(|j| serde_json::from_str(&j).unwrap())
            .collect();
        reports.truncate(reports.len().saturating_sub(self.drop_reports));
        Ok(reports)
    }
}

fn run_elsewhere(
    file: &Path,
    opt: &TileOptions,
    exec: &mut Elsewhere,
) -> Result<(TiledPerceived, Vec<Point>), SurfaceError> {
    let survey = Survey::open(&[file.to_path_buf()]).expect("survey");
    let mut cleaned = Vec::new();
    let got = perceive_tiled_with(
        &survey,
        &PerceptionParams::default(),
        opt,
        exec,
        &mut |_, _, _| {},
        &mut |tile| {
            cleaned.extend_from_slice(&tile.cloud.points);
            Ok(())
        },
    )?;
    Ok((got, cleaned))
}

#[test]
fn tasks_sent_elsewhere_in_any_order_give_the_same_survey_bit_for_bit() {
    let d = dir("elsewhere");
    let file = d.join("pile.laz");
    write(
        &file,
        &pile(60_000, 13, ScanPattern::Rosette),
        Encoding::Binary,
    )
    .unwrap();
    let opt = options(3.0, &d);
    let params = PerceptionParams::default();
    let (here, cleaned_here) = tiled(std::slice::from_ref(&file), &params, &opt);
    let mut exec = Elsewhere::new();
    let (there, cleaned_there) = run_elsewhere(&file, &opt, &mut exec).expect("elsewhere");
    // Tiles come back in the same order, so the cleaned survey is the same
    // sequence, not only the same set.
    assert!(
        cleaned_here
            .iter()
            .map(|p| p.map(f32::to_bits))
            .eq(cleaned_there.iter().map(|p| p.map(f32::to_bits))),
        "the cleaned survey differs"
    );
    let no_times = |g: &TiledPerceived| {
        let mut g = g.clone();
        g.stages.iter_mut().for_each(|s| s.ms = 0.0);
        g.peak_memory = None;
        g
    };
    // Compared as printed: the height model's empty cells are NaN, which
    // no float equals, and each value prints as the shortest text that
    // reads back to it.
    assert!(
        format!("{:?}", no_times(&here)) == format!("{:?}", no_times(&there)),
        "the runs' results differ"
    );
    // Radius, the statistical filter's two rounds, voxel, smoothing.
    let names: Vec<&str> = exec.stages.iter().map(|s| s.0.as_str()).collect();
    assert_eq!(
        names,
        ["radius", "statistical", "statistical", "voxel", "smooth"]
    );
    assert!(exec.stages.iter().all(|s| s.1 >= 20), "{:?}", exec.stages);
    only_the_survey_left(&d);
}

#[test]
fn a_lost_task_or_a_worker_that_cannot_see_the_folder_stops_the_run_saying_so() {
    let d = dir("lost");
    let file = d.join("pile.laz");
    write(
        &file,
        &pile(20_000, 17, ScanPattern::Area),
        Encoding::Binary,
    )
    .unwrap();
    let opt = options(4.0, &d);
    // One report missing from a stage's answer.
    let mut lost = Elsewhere {
        drop_reports: 1,
        ..Elsewhere::new()
    };
    let err = run_elsewhere(&file, &opt, &mut lost).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SurfaceError::TileExecutor { .. }), "{msg}");
    assert!(
        msg.starts_with("the radius stage's tiles:") && msg.contains("1 tile(s) unanswered"),
        "{msg}"
    );
    // Workers whose view of the working folder is elsewhere (an empty
    // folder): the first file they read is named, not taken as empty.
    let mut blind = Elsewhere {
        route: |json| json.replace(".autoshovel-tiles-", "not-shared/.autoshovel-tiles-"),
        ..Elsewhere::new()
    };
    let err = run_elsewhere(&file, &opt, &mut blind).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, SurfaceError::TileFile { .. }), "{msg}");
    assert!(
        msg.contains("not-shared")
            && msg.contains("does every worker see the run's working folder"),
        "{msg}"
    );
    // Nothing left behind by either (the blind workers' own writes fail:
    // their folder does not exist).
    only_the_survey_left(&d);
}
