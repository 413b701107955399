//! Reading and writing 1 M points in the main binary formats and in text.
//! Files are generated into a temporary directory at setup.

use std::path::PathBuf;

use autoshovel_point_cloud::io::{read, write, Encoding};
use autoshovel_point_cloud::PointCloud;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};

const N: usize = 1_000_000;

/// A scan-like cloud: a 1000 × 1000 grid over a wavy pile, in metres.
fn cloud() -> PointCloud {
    PointCloud::new(
        (0..N)
            .map(|i| {
                let x = (i % 1000) as f32 * 0.05;
                let y = (i / 1000) as f32 * 0.05;
                [x, y, 3.0 + (x * 0.3).sin() * (y * 0.2).cos()]
            })
            .collect(),
    )
}

fn bench(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("autoshovel-io-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cloud = cloud();
    let cases: &[(&str, &str, Encoding)] = &[
        ("pcd_binary", "pcd", Encoding::Binary),
        ("pcd_binary_compressed", "pcd", Encoding::BinaryCompressed),
        ("ply_binary_le", "ply", Encoding::Binary),
        ("las", "las", Encoding::Binary),
        ("xyz_ascii", "xyz", Encoding::Ascii),
    ];
    let mut g = c.benchmark_group("io_1M_points");
    g.sample_size(10);
    g.throughput(Throughput::Elements(N as u64));
    for (name, ext, enc) in cases {
        let path: PathBuf = dir.join(format!("bench.{ext}"));
        g.bench_function(format!("write_{name}"), |b| {
            b.iter(|| write(&path, &cloud, *enc).unwrap())
        });
        write(&path, &cloud, *enc).unwrap();
        g.bench_function(format!("read_{name}"), |b| {
            b.iter(|| {
                let r = read(&path, &mut |_, _| {}).unwrap();
                assert_eq!(r.cloud.len(), N);
                r
            })
        });
    }
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
