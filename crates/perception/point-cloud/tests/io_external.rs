//! Files written by other programs (PCL 1.13, VTK through PCL, Python's
//! struct module, laspy/lazrs) read to the points they hold. How each file
//! was made is in tests/data/README.md.

use std::path::{Path, PathBuf};

use autoshovel_point_cloud::io::{read, ReadReport};
use autoshovel_point_cloud::Point;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn load(name: &str) -> ReadReport {
    let mut calls = 0;
    let r = read(&data(name), &mut |done, total| {
        assert!(done <= total);
        calls += 1;
    })
    .unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(calls >= 2, "{name}: progress called {calls} times");
    r
}

fn bits(points: &[Point]) -> Vec<[u32; 3]> {
    points.iter().map(|p| p.map(f32::to_bits)).collect()
}

/// The finite points of tests/data/pcl_source.pcd, as f32 (Rust's parse is
/// correctly rounded, as is PCL's). The literals are the file's text, more
/// digits than an f32 holds on purpose.
#[allow(clippy::excessive_precision)]
fn source_points() -> Vec<Point> {
    vec![
        [0.0, 0.0, 0.0],
        [1.5, -2.25, 3.125],
        [-1000.5, 2000.25, -0.001],
        [123456.789, -0.000123, 42.0],
        [3.4028235e38, -1.1754944e-38, 1e-7],
        [0.1, 0.2, 0.3],
    ]
}

#[test]
fn pcl_binary_and_binary_compressed_hold_the_source_points() {
    let src = load("pcl_source.pcd");
    assert_eq!(src.format, "pcd ascii");
    assert_eq!(bits(&src.cloud.points), bits(&source_points()));
    for (file, format) in [
        ("pcl_binary.pcd", "pcd binary"),
        ("pcl_binary_compressed.pcd", "pcd binary_compressed"),
    ] {
        let r = load(file);
        assert_eq!(r.format, format);
        assert_eq!(r.non_finite_dropped, 1, "{file}");
        assert_eq!(bits(&r.cloud.points), bits(&source_points()), "{file}");
    }
}

#[test]
fn pcl_ascii_pcd_holds_what_pcl_printed() {
    // PCL prints 7 significant digits by default.
    let r = load("pcl_ascii.pcd");
    assert_eq!(r.non_finite_dropped, 1);
    let expect: Vec<Point> = vec![
        [0.0, 0.0, 0.0],
        [1.5, -2.25, 3.125],
        [-1000.5, 2000.25, -0.001],
        [123456.8, -0.000123, 42.0],
        [3.402823e38, -1.175494e-38, 1e-7],
        [0.1, 0.2, 0.3],
    ];
    assert_eq!(bits(&r.cloud.points), bits(&expect));
}

#[test]
fn pcl_and_vtk_ply_files() {
    let exact = bits(&source_points());
    // PCL's own PLY writer: a camera element after the vertices, an empty
    // face element.
    let b = load("pcl_binary.ply");
    assert_eq!(b.format, "ply binary_little_endian");
    assert_eq!(
        (bits(&b.cloud.points), b.non_finite_dropped),
        (exact.clone(), 1)
    );
    let a = load("pcl_ascii.ply");
    assert_eq!(a.format, "ply ascii");
    assert_eq!(a.non_finite_dropped, 1);
    for (p, q) in a.cloud.points.iter().zip(source_points()) {
        for k in 0..3 {
            // PCL prints 8 significant digits.
            approx::assert_relative_eq!(p[k], q[k], max_relative = 1e-7);
        }
    }
    // VTK's writer (pcl_converter): obj_info, a face element with lists;
    // ASCII doubles with 17 digits read back exactly.
    for file in ["vtk_ascii.ply", "vtk_binary.ply"] {
        let r = load(file);
        assert_eq!(
            (bits(&r.cloud.points), r.non_finite_dropped),
            (exact.clone(), 1),
            "{file}"
        );
    }
}

#[test]
fn ply_of_every_scalar_type_with_lists_in_three_encodings() {
    let expect: Vec<Point> = vec![
        [1.5, -2.0, 100000.0],
        [-0.001, 32767.0, -7.0],
        [123456.789f64 as f32, -32768.0, 0.0],
    ];
    for (file, format) in [
        ("python_mixed_ascii.ply", "ply ascii"),
        ("python_mixed_le.ply", "ply binary_little_endian"),
        ("python_mixed_be.ply", "ply binary_big_endian"),
    ] {
        let r = load(file);
        assert_eq!(r.format, format);
        assert_eq!(r.non_finite_dropped, 1, "{file}");
        // int32 z (100000, −300000) is held in f64 about an origin; in
        // the file's frame every coordinate is the f32 expected.
        let world: Vec<Point> = (0..r.cloud.len())
            .map(|i| r.cloud.world(i).map(|v| v as f32))
            .collect();
        assert_eq!(bits(&world), bits(&expect), "{file}");
    }
}

#[test]
fn pcd_with_integer_coordinates_padding_and_rgb() {
    let r = load("python_int_fields.pcd");
    let expect: Vec<Point> = vec![
        [-5.0, 7.0, -300000.0],
        [0.0, 65535.0, 12.0],
        [127.0, 1.0, -1.0],
        [-128.0, 0.0, 2147483647.0],
    ];
    // Read about an origin (z is far from zero): the file's integers exactly.
    let world: Vec<[f64; 3]> = (0..r.cloud.len()).map(|i| r.cloud.world(i)).collect();
    let want: Vec<[f64; 3]> = expect.iter().map(|p| p.map(f64::from)).collect();
    assert_eq!(world[..3], want[..3]);
    // 2147483647 is no f32; about the origin it is within f32's step there.
    assert!(
        (world[3][2] - 2147483647.0).abs() <= 256.0,
        "{:?}",
        world[3]
    );
    // The rgb field and the padding: rgb a column, "_" not.
    assert!(r.cloud.attributes.get("rgb").is_some());
    assert!(r.cloud.attributes.get("_").is_none());
}

#[test]
fn las_and_laz_from_laspy() {
    let x = [0, 100, -250, 123456, 5, -99999];
    let y = [7, -7, 70000, 0, 1, 2];
    let z = [-1, 0, 1, 2, 3000, -3000];
    let expect: Vec<Point> = (0..6)
        .map(|i| {
            [
                (f64::from(x[i]) * 0.01 + 1000.0) as f32,
                (f64::from(y[i]) * 0.01 + 2000.0) as f32,
                (f64::from(z[i]) * 0.001 + 10.0) as f32,
            ]
        })
        .collect();
    for (file, format) in [
        ("laspy_1_2_format1.las", "las 1.2"),
        ("laspy_1_4_format6.las", "las 1.4"),
        ("laspy_1_2_format3.laz", "laz 1.2"),
        ("laspy_1_4_format7.laz", "laz 1.4"),
    ] {
        let r = load(file);
        assert_eq!(r.format, format, "{file}");
        assert_eq!(bits(&r.cloud.points), bits(&expect), "{file}");
    }
}

#[test]
fn old_pcd_headers_and_crlf_ply_headers() {
    use autoshovel_point_cloud::io::{read_from_bytes, Format};
    // PCD .5 style: COLUMNS, no SIZE/TYPE/COUNT (4-byte floats, as PCL
    // assumes), no POINTS (WIDTH × HEIGHT), no VIEWPOINT.
    let old = b"# .PCD v.5 - Point Cloud Data file format\nVERSION .5\nCOLUMNS x y z\nWIDTH 2\nHEIGHT 1\nDATA ascii\n1 2 3\n4 5 6\n";
    let r = read_from_bytes(Format::Pcd, old).unwrap();
    assert_eq!(r.cloud.points, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    let v6 = b"VERSION .6\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA binary\n\0\0\x80\x3f\0\0\0\x40\0\0\x40\x40";
    let r = read_from_bytes(Format::Pcd, v6).unwrap();
    assert_eq!(r.cloud.points, vec![[1.0, 2.0, 3.0]]);
    // A PLY header with Windows line ends, binary data right after it.
    let mut ply = b"ply\r\nformat binary_big_endian 1.0\r\nelement vertex 1\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nend_header\r\n".to_vec();
    for v in [1.0f32, 2.0, 3.0] {
        ply.extend_from_slice(&v.to_be_bytes());
    }
    let r = read_from_bytes(Format::Ply, &ply).unwrap();
    assert_eq!(r.cloud.points, vec![[1.0, 2.0, 3.0]]);
}

/// A stream's LAS rows decode to the attributes a whole read gives, row for
/// row, in every point format here (1 and 3 from PDAL and laspy, 6 and 7
/// with GPS time and colour, extra bytes, LAZ and COPC): the survey path
/// carries a tile's attributes this way.
#[test]
fn streamed_las_rows_are_the_attributes_of_a_whole_read() {
    use autoshovel_point_cloud::io::read_chunks_with;
    for name in [
        "autzen-utm.las",
        "extrabytes.las",
        "laspy_1_2_format1.las",
        "laspy_1_2_format3.laz",
        "laspy_1_4_format6.las",
        "laspy_1_4_format7.laz",
        "pdal_1.2-with-color.copc.laz",
    ] {
        let whole = load(name);
        let layout = whole.cloud.georef.las.clone().expect("a LAS layout");
        let (mut points, mut rows, mut calls) = (Vec::new(), Vec::new(), 0);
        read_chunks_with(
            &data(name),
            whole.cloud.origin,
            3,
            true,
            &mut |_, _| {},
            &mut |p, r| {
                assert_eq!(r.len(), p.len() * layout.record_len(), "{name}");
                points.extend_from_slice(p);
                rows.extend_from_slice(r);
                calls += 1;
                Ok(())
            },
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(calls, points.len().div_ceil(3), "{name}: in chunks of 3");
        assert_eq!(bits(&points), bits(&whole.cloud.points), "{name}");
        let got = layout.attributes_of_rows(&rows).unwrap();
        assert!(!got.is_empty(), "{name}");
        assert_eq!(got, whole.cloud.attributes, "{name}");
        // Without rows, none.
        read_chunks_with(
            &data(name),
            whole.cloud.origin,
            1 << 20,
            false,
            &mut |_, _| {},
            &mut |_, r| {
                assert!(r.is_empty());
                Ok(())
            },
        )
        .unwrap();
    }
}
