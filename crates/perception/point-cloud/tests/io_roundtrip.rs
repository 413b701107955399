//! Round trips: random clouds, f32 extremes included, through every format
//! and encoding come back bit for bit (PCD, PLY, text) or within the LAS
//! scale (LAS, LAZ).

use std::path::PathBuf;

use autoshovel_point_cloud::io::{
    read, read_from_bytes, write, write_with, Encoding, Format, LasVersion, WriteOptions,
};
use autoshovel_point_cloud::{Point, PointCloud};
use proptest::prelude::*;

/// A fresh directory under the system temp dir, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> Self {
        use std::sync::atomic::{AtomicU64, Ordering};
        static N: AtomicU64 = AtomicU64::new(0);
        let p = std::env::temp_dir().join(format!(
            "autoshovel-io-{tag}-{}-{}",
            std::process::id(),
            N.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&p).unwrap();
        TempDir(p)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn bits(points: &[Point]) -> Vec<[u32; 3]> {
    points.iter().map(|p| p.map(f32::to_bits)).collect()
}

/// Every exact (format, encoding) pair.
const EXACT: &[(&str, Encoding)] = &[
    ("pcd", Encoding::Ascii),
    ("pcd", Encoding::Binary),
    ("pcd", Encoding::BinaryCompressed),
    ("ply", Encoding::Ascii),
    ("ply", Encoding::Binary),
    ("ply", Encoding::BinaryBigEndian),
    ("xyz", Encoding::Ascii),
    ("csv", Encoding::Ascii),
    ("TXT", Encoding::Ascii),
];

fn finite_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -1.0e4f32..1.0e4,
        2 => proptest::num::f32::NORMAL | proptest::num::f32::SUBNORMAL | proptest::num::f32::ZERO,
        1 => prop::sample::select(vec![
            f32::MAX, f32::MIN, f32::MIN_POSITIVE, -f32::MIN_POSITIVE, 1e-45, -1e-45, 0.0, -0.0,
            16_777_217.0, 0.1, 1e16, 9.999_999e15, 1e-5, 9.999_999e-6,
        ]),
    ]
}

/// The cloud's points in the file's frame, as f32.
fn world(c: &PointCloud) -> Vec<Point> {
    (0..c.len()).map(|i| c.world(i).map(|v| v as f32)).collect()
}

fn cloud(max: usize) -> impl Strategy<Value = Vec<Point>> {
    prop::collection::vec([finite_f32(), finite_f32(), finite_f32()], 0..max)
}

fn near_las(a: f32, b: f64, precision: f64) -> bool {
    // Half a millimetre of quantisation, plus the f32 rounding about the origin.
    (f64::from(a) - b).abs() <= 5e-4 + precision
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn every_exact_format_and_encoding_round_trips(points in cloud(120)) {
        let dir = TempDir::new("rt");
        let cloud = PointCloud::new(points);
        for (ext, enc) in EXACT {
            let path = dir.0.join(format!("c-{enc}.{ext}"));
            write(&path, &cloud, *enc).unwrap();
            let r = read(&path, &mut |_, _| {}).unwrap();
            prop_assert_eq!(r.non_finite_dropped, 0);
            // Text is read about an origin of its first point: the file's
            // coordinates, origin added back, are the f32 values written.
            prop_assert_eq!(bits(&world(&r.cloud)), bits(&cloud.points), "{} {}", ext, enc);
            // The in-memory entry point reads the same bytes the same way.
            let bytes = std::fs::read(&path).unwrap();
            let f = Format::from_path(&path).unwrap();
            let m = read_from_bytes(f, &bytes).unwrap();
            prop_assert_eq!(bits(&world(&m.cloud)), bits(&cloud.points));
            prop_assert_eq!(m.format, r.format);
        }
    }

    #[test]
    fn las_and_laz_round_trip_within_a_millimetre(
        points in prop::collection::vec([-1.0e5f32..1.0e5, -1.0e5f32..1.0e5, -500.0f32..3000.0], 0..200),
    ) {
        let dir = TempDir::new("las");
        let cloud = PointCloud::new(points);
        for ext in ["las", "laz"] {
            for version in [LasVersion::V1_2, LasVersion::V1_4] {
                let path = dir.0.join(format!("c.{ext}"));
                write_with(&path, &cloud, &WriteOptions { las_version: version, ..Default::default() }).unwrap();
                let r = read(&path, &mut |_, _| {}).unwrap();
                prop_assert!(r.format.starts_with(ext));
                prop_assert_eq!(r.cloud.len(), cloud.len());
                // Read back about an f64 origin: the file's coordinates to
                // the f32 rounding of the offsets from it.
                let tol = r.cloud.precision();
                for (i, a) in cloud.points.iter().enumerate() {
                    let b = r.cloud.world(i);
                    for k in 0..3 {
                        prop_assert!(near_las(a[k], b[k], tol), "{} {:?}: {} -> {}", ext, version, a[k], b[k]);
                    }
                }
            }
        }
    }
}

#[test]
fn empty_clouds_are_valid_everywhere() {
    let dir = TempDir::new("empty");
    let empty = PointCloud::default();
    for (ext, enc) in EXACT
        .iter()
        .chain(&[("las", Encoding::Binary), ("laz", Encoding::Binary)])
    {
        let path = dir.0.join(format!("e-{enc}.{ext}"));
        write(&path, &empty, *enc).unwrap();
        let r = read(&path, &mut |_, _| {}).unwrap();
        assert!(r.is_empty(), "{ext} {enc}");
        assert!(r.to_string().starts_with("empty cloud"), "{r}");
    }
}

#[test]
fn las_with_extreme_extent_coarsens_its_scale_instead_of_failing() {
    let dir = TempDir::new("lasx");
    let cloud = PointCloud::new(vec![
        [f32::MAX, -f32::MAX, 0.0],
        [f32::MIN_POSITIVE, 1.0, -1e30],
    ]);
    let path = dir.0.join("x.las");
    write(&path, &cloud, Encoding::Binary).unwrap();
    let r = read(&path, &mut |_, _| {}).unwrap();
    assert_eq!(r.cloud.len(), 2);
    // The x extent is 3.4e38: one step is about 1e29 m there.
    approx::assert_relative_eq!(
        r.cloud.world(0)[0],
        f64::from(f32::MAX),
        max_relative = 1e-6
    );
}

#[test]
fn writing_is_atomic_and_refuses_impossible_encodings() {
    let dir = TempDir::new("atomic");
    let path = dir.0.join("a.pcd");
    let cloud = PointCloud::new(vec![[1.0, 2.0, 3.0]]);
    write(&path, &cloud, Encoding::Binary).unwrap();
    let before = std::fs::read(&path).unwrap();
    // PCD has no big-endian encoding: an error, and the old file untouched.
    assert!(write(&path, &cloud, Encoding::BinaryBigEndian).is_err());
    assert!(write(&dir.0.join("a.ply"), &cloud, Encoding::BinaryCompressed).is_err());
    // LAS cannot hold a NaN: the writer fails half-way, and neither the
    // target nor a temporary file is left behind.
    let bad = PointCloud::new(vec![[1.0, 2.0, 3.0], [f32::NAN, 0.0, 0.0]]);
    assert!(write(&dir.0.join("b.las"), &bad, Encoding::Binary).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), before);
    let names: Vec<String> = std::fs::read_dir(&dir.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, vec!["a.pcd".to_string()]);
    // Unknown extensions are refused before anything is created.
    assert!(matches!(
        write(&dir.0.join("c.obj"), &cloud, Encoding::Binary),
        Err(autoshovel_point_cloud::CloudError::UnknownFormat { .. })
    ));
}

#[test]
fn non_finite_points_are_dropped_and_counted() {
    let dir = TempDir::new("nan");
    let cloud = PointCloud::new(vec![
        [1.0, 2.0, 3.0],
        [f32::NAN, 0.0, 0.0],
        [0.0, f32::INFINITY, 0.0],
        [4.0, 5.0, 6.0],
    ]);
    for (ext, enc) in EXACT {
        let path = dir.0.join(format!("n-{enc}.{ext}"));
        write(&path, &cloud, *enc).unwrap();
        let r = read(&path, &mut |_, _| {}).unwrap();
        assert_eq!(r.non_finite_dropped, 2, "{ext} {enc}");
        assert_eq!(r.cloud.points, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert!(r.to_string().contains("2 non-finite dropped"), "{r}");
    }
}

#[test]
fn non_finite_points_are_dropped_across_the_readers_chunks() {
    // 200 k points (the binary PCD reader takes 1 MiB, 87 381 points, at a
    // time), a non-finite one every 997th: the finite ones in order.
    let dir = TempDir::new("nan-chunks");
    let points: Vec<[f32; 3]> = (0..200_000)
        .map(|i| {
            let v = i as f32 * 0.001;
            match i % 997 {
                0 => [f32::NAN, v, v],
                500 => [v, v, f32::NEG_INFINITY],
                _ => [v, -v, 0.5 * v],
            }
        })
        .collect();
    let finite: Vec<[f32; 3]> = points
        .iter()
        .copied()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .collect();
    let path = dir.0.join("chunks.pcd");
    write(&path, &PointCloud::new(points.clone()), Encoding::Binary).unwrap();
    let r = read(&path, &mut |_, _| {}).unwrap();
    assert_eq!(r.format, "pcd binary");
    assert_eq!(r.non_finite_dropped, points.len() - finite.len());
    assert_eq!(r.cloud.points, finite);
}

#[test]
fn encodings_parse_and_default_by_extension() {
    use std::path::Path;
    assert_eq!(
        "binary_little_endian".parse::<Encoding>().unwrap(),
        Encoding::Binary
    );
    assert_eq!(
        "Binary-Compressed".parse::<Encoding>().unwrap(),
        Encoding::BinaryCompressed
    );
    assert!("zip".parse::<Encoding>().is_err());
    assert_eq!(Encoding::default_for(Path::new("a.PCD")), Encoding::Binary);
    assert_eq!(Encoding::default_for(Path::new("a.ply")), Encoding::Binary);
    assert_eq!(Encoding::default_for(Path::new("a.csv")), Encoding::Ascii);
    assert_eq!(Format::from_path(Path::new("x.LaZ")).unwrap(), Format::Laz);
}

/// A survey in UTM (PDAL's Autzen, northings near 4.88 M m, 1 cm steps)
/// written as PLY (every encoding) and text, and read back, keeps every
/// attribute (PLY in its own type, text as numbers) and every
/// coordinate of the file's frame to within a tenth of the file's 1 cm
/// step (f32 about the first point's whole metres, 0.07 mm 700 m away):
/// the writers add the origin back (PLY as doubles, text to the file's 2
/// decimals) and the readers hold wide values about an origin again. Before, both wrote the
/// coordinates less the origin (494 428.61 became −65.67) and the readers
/// rounded a northing to f32's half metre.
#[test]
fn a_survey_written_as_ply_or_text_keeps_its_coordinates() {
    let dir = TempDir::new("survey");
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/autzen-utm.las");
    let las = read(&src, &mut |_, _| {}).unwrap().cloud;
    assert!(las.origin[1] > 4.8e6, "{:?}", las.origin);
    for (ext, enc) in [
        ("ply", Encoding::Ascii),
        ("ply", Encoding::Binary),
        ("ply", Encoding::BinaryBigEndian),
        ("xyz", Encoding::Ascii),
        ("csv", Encoding::Ascii),
    ] {
        let path = dir.0.join(format!("s-{enc}.{ext}"));
        write(&path, &las, enc).unwrap();
        let back = read(&path, &mut |_, _| {}).unwrap().cloud;
        assert_eq!(back.len(), las.len(), "{ext} {enc}");
        let worst = (0..las.len())
            .flat_map(|i| {
                let (a, b) = (las.world(i), back.world(i));
                (0..3).map(move |k| (a[k] - b[k]).abs())
            })
            .fold(0.0, f64::max);
        assert!(worst < 1e-3, "{ext} {enc}: a coordinate moved by {worst} m");
        if ext == "ply" {
            // Every attribute, row for row, in its own type and name.
            assert_eq!(back.attributes, las.attributes, "{ext} {enc}");
        } else {
            // Text: every attribute by name, its values as numbers.
            for c in las.attributes.columns() {
                let got = back
                    .attributes
                    .get(&c.name)
                    .unwrap_or_else(|| panic!("{ext}: no {}", c.name));
                for i in 0..las.len() {
                    assert_eq!(
                        got.f64_at(i),
                        c.values.f64_at(i),
                        "{ext} {} row {i}",
                        c.name
                    );
                }
            }
        }
    }
    let text = std::fs::read_to_string(dir.0.join("s-ascii.xyz")).unwrap();
    let first = text.lines().nth(1).unwrap_or_default();
    assert!(text.starts_with("x y z Intensity "), "{}", &text[..60]);
    assert!(
        first.starts_with("494428.61 4877455.58 131.57 143 "),
        "{first}"
    );
}
