//! Big-file sanity: 2 M points through each binary format, timed. Ignored
//! by default (a few seconds in release, more in the test profile):
//! `cargo test -p autoshovel-point-cloud --release --test io_big -- --ignored --nocapture`

use std::time::Instant;

use autoshovel_point_cloud::io::{read, write_with, Encoding, LasVersion, WriteOptions};
use autoshovel_point_cloud::PointCloud;

#[test]
#[ignore = "big file: run explicitly, preferably with --release"]
fn two_million_points_in_every_binary_format() {
    let n = 2_000_000;
    let cloud = PointCloud::new(
        (0..n)
            .map(|i| {
                let x = (i % 2000) as f32 * 0.025 - 25.0;
                let y = (i / 2000) as f32 * 0.025;
                [x, y, 4.0 + (0.2 * x).sin() + 0.001 * (i % 97) as f32]
            })
            .collect(),
    );
    let dir = std::env::temp_dir().join(format!("autoshovel-io-big-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: &[(&str, Encoding, LasVersion)] = &[
        ("pcd", Encoding::Binary, LasVersion::V1_2),
        ("pcd", Encoding::BinaryCompressed, LasVersion::V1_2),
        ("ply", Encoding::Binary, LasVersion::V1_2),
        ("ply", Encoding::BinaryBigEndian, LasVersion::V1_2),
        ("las", Encoding::Binary, LasVersion::V1_2),
        ("las", Encoding::Binary, LasVersion::V1_4),
        ("laz", Encoding::Binary, LasVersion::V1_2),
        ("laz", Encoding::Binary, LasVersion::V1_4),
    ];
    println!(
        "{:<46} {:>10} {:>9} {:>9}",
        "format", "MB", "write s", "read s"
    );
    for (ext, enc, ver) in cases {
        let path = dir.join(format!("big.{ext}"));
        let t = Instant::now();
        write_with(
            &path,
            &cloud,
            &WriteOptions {
                encoding: Some(*enc),
                las_version: *ver,
            },
        )
        .unwrap();
        let tw = t.elapsed().as_secs_f64();
        let mb = std::fs::metadata(&path).unwrap().len() as f64 / 1e6;
        let mut calls = 0;
        let t = Instant::now();
        let r = read(&path, &mut |_, _| calls += 1).unwrap();
        let tr = t.elapsed().as_secs_f64();
        assert_eq!(r.cloud.len(), n);
        assert!(calls > 3, "progress reported {calls} times");
        if *ext == "las" || *ext == "laz" {
            for (a, b) in cloud.points.iter().zip(&r.cloud.points).step_by(997) {
                for k in 0..3 {
                    assert!((a[k] - b[k]).abs() <= 6e-4, "{a:?} {b:?}");
                }
            }
        } else {
            assert!(r.cloud.points == cloud.points);
        }
        println!(
            "{:<46} {mb:>10.1} {tw:>9.3} {tr:>9.3}",
            format!("{} ({enc}, {ver:?})", r.format)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn multi_chunk_laz_1_4_passes_the_layer_walk() {
    // 120 001 points: three 50 000-point chunks, the last one partial, so
    // the guard walks several layered chunk headers of a real file.
    let n = 120_001;
    let cloud = PointCloud::new(
        (0..n)
            .map(|i| [i as f32 * 0.01, (i % 13) as f32, (i % 101) as f32 * 0.1])
            .collect(),
    );
    let dir = std::env::temp_dir().join(format!("autoshovel-io-chunks-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("c.laz");
    write_with(
        &path,
        &cloud,
        &WriteOptions {
            encoding: None,
            las_version: LasVersion::V1_4,
        },
    )
    .unwrap();
    let r = read(&path, &mut |_, _| {}).unwrap();
    assert_eq!(r.cloud.len(), n);
    assert_eq!(r.format, "laz 1.4");
    let _ = std::fs::remove_dir_all(&dir);
}
