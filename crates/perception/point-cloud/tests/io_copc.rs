//! LAZ files from other writers that the LASzip guard once refused or the
//! `laz` decoder could not read: COPC (LAS 1.4, point formats 6–7, variable-
//! size chunks in a chunk table), and the old point-wise LASzip (compressor
//! 1, no chunks). Each must read to the point count, the first and last
//! points and the coordinate means that laspy 2.7.0 reports (lazrs 0.8.2 for
//! COPC; the LASzip C library 0.3.0 binding for the point-wise file, which
//! lazrs cannot decode). Where the files come from: tests/data/README.md.

use std::path::{Path, PathBuf};

use autoshovel_point_cloud::io::read;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// What laspy reads from a file: version, point count, the sums of x, y, z
/// (f64), the first and the last point.
struct Laspy {
    file: &'static str,
    format: &'static str,
    count: usize,
    sum: [f64; 3],
    first: [f64; 3],
    last: [f64; 3],
}

const FILES: [Laspy; 4] = [
    Laspy {
        file: "lasrs_autzen.copc.laz",
        format: "laz 1.4",
        count: 107,
        sum: [68185611.49, 91074233.89999999, 46012.58],
        first: [638433.0700000001, 849326.8, 425.51],
        last: [636295.27, 853439.75, 495.93],
    },
    Laspy {
        file: "pdal_1.2-with-color.copc.laz",
        format: "laz 1.4",
        count: 1065,
        sum: [678721022.9699999, 906580758.49, 462314.2],
        first: [636145.6, 849170.4700000001, 428.15000000000003],
        last: [638314.34, 852793.54, 419.65000000000003],
    },
    Laspy {
        file: "pdal_lone-star.copc.laz",
        format: "laz 1.4",
        count: 518862,
        sum: [267417386868.5165, 2551953195888.609, 1208260675.9404998],
        first: [515378.7675, 4918365.034750001, 2324.30525],
        last: [515398.052, 4918371.58875, 2325.8309999999997],
    },
    Laspy {
        file: "pdal_simple-laszip-compressor-version-1.2r0.laz",
        format: "laz 1.2",
        count: 1065,
        sum: [678721022.97, 906580758.49, 462314.2],
        first: [637012.24, 849028.31, 431.66],
        last: [637342.85, 853240.3200000001, 423.92],
    },
];

#[test]
fn copc_and_pointwise_laszip_read_as_laspy_reads_them() {
    for f in &FILES {
        let r = read(&data(f.file), &mut |_, _| {}).unwrap_or_else(|e| panic!("{}: {e}", f.file));
        assert_eq!(r.format, f.format, "{}", f.file);
        let p = &r.cloud.points;
        assert_eq!(
            p.len() + r.non_finite_dropped,
            f.count,
            "{}: point count",
            f.file
        );
        assert_eq!(r.non_finite_dropped, 0, "{}", f.file);
        // Coordinates about the cloud's f64 origin: laspy's to within the
        // f32 rounding of the offsets (a fraction of a millimetre), where
        // absolute f32 would step by 0.5 m at a UTM northing.
        let c = &r.cloud;
        let tol = c.precision() + 1e-9;
        assert!(tol < 1e-3, "{}: precision {tol}", f.file);
        for k in 0..3 {
            let (first, last) = (c.world(0)[k], c.world(p.len() - 1)[k]);
            assert!(
                (first - f.first[k]).abs() <= tol && (last - f.last[k]).abs() <= tol,
                "{}: axis {k}: first {first} (laspy {}), last {last} (laspy {})",
                f.file,
                f.first[k],
                f.last[k]
            );
            let ours: f64 = (0..p.len()).map(|i| c.world(i)[k]).sum::<f64>() / p.len() as f64;
            let theirs = f.sum[k] / f.count as f64;
            assert!(
                (ours - theirs).abs() <= tol,
                "{}: mean of axis {k}: ours {ours}, laspy {theirs}, bound {tol}",
                f.file
            );
        }
    }
}

fn le32(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize
}

fn refused(name: &str, bytes: &[u8]) -> String {
    use autoshovel_point_cloud::io::{read_from_bytes, Format};
    match read_from_bytes(Format::Laz, bytes) {
        Err(autoshovel_point_cloud::CloudError::Format { what, .. }) => what,
        Err(e) => panic!("{name}: expected a format error, got {e}"),
        Ok(r) => panic!(
            "{name}: expected a format error, read {} points",
            r.cloud.len()
        ),
    }
}

/// The guard still refuses the hostile cases on a real COPC file: a chunk
/// announcing a 4 GB layer, a chunk table holding fewer points than the
/// header; and a cut file says where it was cut.
#[test]
fn damaged_copc_and_pointwise_files_are_refused_by_name() {
    let copc = std::fs::read(data("pdal_1.2-with-color.copc.laz")).unwrap();
    let start = le32(&copc, 96);
    let table = u64::from_le_bytes(copc[start..start + 8].try_into().unwrap()) as usize;
    // First chunk: table offset (8), raw first point (30 + 6 for RGB), count.
    let mut b = copc.clone();
    b[start + 8 + 36 + 4..start + 8 + 36 + 8].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    let what = refused("huge layer", &b);
    assert!(what.contains("bytes of layers"), "{what}");
    assert!(le32(&copc, table + 4) >= 1, "the table lists its chunks");
    // Raise the header's count (legacy and 64-bit fields) one above what
    // the table's chunks hold.
    let mut b = copc.clone();
    b[107..111].copy_from_slice(&1066u32.to_le_bytes());
    b[247..255].copy_from_slice(&1066u64.to_le_bytes());
    let what = refused("count above the table", &b);
    assert!(what.contains("hold fewer than the header's"), "{what}");
    // Cut in the middle of the points.
    let what = refused("cut copc", &copc[..start + (table - start) / 2]);
    assert!(
        what.contains("past the end") || what.contains("truncated"),
        "{what}"
    );
    let pointwise = std::fs::read(data("pdal_simple-laszip-compressor-version-1.2r0.laz")).unwrap();
    let what = refused("cut point-wise", &pointwise[..pointwise.len() / 2]);
    assert!(
        what.contains("truncated") && what.contains("of the 1065 the header claims"),
        "{what}"
    );
}
