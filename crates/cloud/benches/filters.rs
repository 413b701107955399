//! Criterion benches of the filters on a synthetic pile scan at 100 k and
//! 1 M points, with the parameters of the speed aims (SPEC §4.1; issue 4):
//! radius removal r = 0.05 m with 5 neighbours, statistical removal k = 50,
//! α = 1.0, voxel grid leaf 0.05 m, pass-through z ≥ 0.1 m.
//!
//! The cloud: a 40° face 10 m wide rising 6.4 m from a 2 m floor strip to a
//! flat crest (≈ 150 m² in all), points placed uniformly at random (1.2 cm
//! mean spacing at 1 M points, 3.9 cm at 100 k), 1 cm Gaussian-like range
//! noise, 1 % outliers in the box grown by 1 m; a seeded LCG, so every run
//! and every peer sees the same cloud.
//!
//! `FILTER_BENCH_WRITE=DIR cargo bench -p autoshovel-cloud --bench filters`
//! writes the two clouds as binary PCD (`DIR/pile_100k.pcd`,
//! `DIR/pile_1m.pcd`) and exits, for `peer/bench_peers.py`, which runs PCL and
//! Open3D on them.

use std::io::Write;

use autoshovel_cloud::filter::{self, PassThroughParams, RadiusOutlierParams, StatisticalOutlierParams, VoxelGridParams};
use autoshovel_cloud::{Point, PointCloud};
use criterion::{BenchmarkId, Criterion};

/// The synthetic pile scan of `n` points.
pub fn pile(n: usize, seed: u64) -> PointCloud {
    let mut s = seed;
    let mut uniform = move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let tan40 = 40f64.to_radians().tan();
    let (width_m, floor_m, height_m, top_m) = (10.0, 2.0, 6.4, 2.0);
    let depth_m = floor_m + height_m / tan40 + top_m;
    let outliers = n / 100;
    let mut points: Vec<Point> = Vec::with_capacity(n);
    for _ in 0..n - outliers {
        let x = uniform() * width_m;
        let y = uniform() * depth_m;
        let surface = ((y - floor_m) * tan40).clamp(0.0, height_m);
        // Sum of three uniforms: near-Gaussian, σ = 1 cm.
        let noise = (uniform() + uniform() + uniform() - 1.5) * 0.02;
        points.push([x as f32, y as f32, (surface + noise) as f32]);
    }
    for _ in 0..outliers {
        let p = [
            uniform() * (width_m + 2.0) - 1.0,
            uniform() * (depth_m + 2.0) - 1.0,
            uniform() * (height_m + 2.0) - 1.0,
        ];
        points.push(p.map(|c| c as f32));
    }
    // Outliers spread through the file, as a scanner would give them.
    for i in (1..points.len()).rev() {
        let j = (uniform() * (i + 1) as f64) as usize;
        points.swap(i, j.min(i));
    }
    PointCloud::new(points)
}

fn write_binary_pcd(path: &std::path::Path, cloud: &PointCloud) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    let n = cloud.len();
    write!(
        f,
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n\
         WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n"
    )?;
    for p in &cloud.points {
        for c in p {
            f.write_all(&c.to_le_bytes())?;
        }
    }
    f.flush()
}

const SIZES: [(usize, &str); 2] = [(100_000, "100k"), (1_000_000, "1m")];

fn benches(c: &mut Criterion) {
    for (n, name) in SIZES {
        let cloud = pile(n, 4);
        let mut group = c.benchmark_group(format!("filters_{name}"));
        group.sample_size(10);
        if n >= 1_000_000 {
            group.measurement_time(std::time::Duration::from_secs(20));
        }
        group.bench_with_input(BenchmarkId::new("pass_through_z0.1", n), &cloud, |b, cloud| {
            b.iter(|| filter::pass_through(cloud, &PassThroughParams::ground_removal(0.1)).unwrap())
        });
        group.bench_with_input(BenchmarkId::new("voxel_grid_0.05", n), &cloud, |b, cloud| {
            b.iter(|| filter::voxel_grid(cloud, &VoxelGridParams::cube(0.05)).unwrap())
        });
        group.bench_with_input(BenchmarkId::new("radius_r0.05_min5", n), &cloud, |b, cloud| {
            let params = RadiusOutlierParams { radius_m: 0.05, min_neighbors: 5 };
            b.iter(|| filter::radius_outlier_removal(cloud, &params).unwrap())
        });
        group.bench_with_input(BenchmarkId::new("statistical_k50_s1", n), &cloud, |b, cloud| {
            let params = StatisticalOutlierParams { mean_k: 50, std_mul: 1.0 };
            b.iter(|| filter::statistical_outlier_removal(cloud, &params).unwrap())
        });
        group.finish();
    }
}

fn main() {
    if let Ok(dir) = std::env::var("FILTER_BENCH_WRITE") {
        let dir = std::path::PathBuf::from(dir);
        std::fs::create_dir_all(&dir).expect("create FILTER_BENCH_WRITE");
        for (n, name) in SIZES {
            let path = dir.join(format!("pile_{name}.pcd"));
            write_binary_pcd(&path, &pile(n, 4)).expect("write the bench cloud");
            println!("wrote {}", path.display());
        }
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    benches(&mut c);
    c.final_summary();
}
