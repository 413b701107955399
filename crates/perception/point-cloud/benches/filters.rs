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
//! `FILTER_BENCH_WRITE=DIR cargo bench -p autoshovel-point-cloud --bench filters`
//! does not run criterion: it writes the two clouds as binary PCD
//! (`DIR/pile_100k.pcd`, `DIR/pile_1m.pcd`; `FILTER_BENCH_SIZES=100k,1m,5m,20m`
//! for others, `FILTER_BENCH_INPUT=FILE` for a scan of your own instead,
//! labelled by its file stem), runs each filter once to warm
//! up and then `FILTER_BENCH_RUNS` (default 3) times or for half a second,
//! whichever is longer, prints the median time as
//! `ours NAME SIZE MS ms N points`, and writes each output
//! (`DIR/ours_NAME_SIZE.pcd`), for `peer/bench_peers.py`, which runs PCL and
//! Open3D on the same clouds and compares. `FILTER_BENCH_ONLY=NAME:SIZE`
//! (e.g. `statistical:1m`) runs one filter on one cloud, `clouds` none.
//! `FILTER_BENCH_LEAF=M` sets the voxel grid's leaf (m) (e.g. the
//! `perceive` voxel stage's, two spacings, on that stage's input given as
//! `FILTER_BENCH_INPUT`).

use std::io::Write;

use autoshovel_point_cloud::filter::{
    self, PassThroughParams, RadiusOutlierParams, StatisticalOutlierParams, VoxelGridParams,
};
use autoshovel_point_cloud::{Point, PointCloud};
use criterion::{BenchmarkId, Criterion};

/// The voxel leaf (m): 0.05, or `FILTER_BENCH_LEAF`.
fn voxel_leaf() -> f64 {
    static LEAF: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    *LEAF.get_or_init(|| {
        std::env::var("FILTER_BENCH_LEAF").map_or(0.05, |v| {
            v.parse().expect("FILTER_BENCH_LEAF: a leaf in metres")
        })
    })
}

/// The synthetic pile scan of `n` points.
pub fn pile(n: usize, seed: u64) -> PointCloud {
    let mut s = seed;
    let mut uniform = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
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

/// The filters as benchmarked, by name.
type Run = fn(&PointCloud) -> PointCloud;
const FILTERS: [(&str, Run); 4] = [
    ("pass_through", |c| {
        filter::pass_through(c, &PassThroughParams::ground_removal(0.1)).unwrap()
    }),
    ("voxel_grid", |c| {
        filter::voxel_grid(c, &VoxelGridParams::cube(voxel_leaf())).unwrap()
    }),
    ("radius", |c| {
        filter::radius_outlier_removal(
            c,
            &RadiusOutlierParams {
                radius_m: 0.05,
                min_neighbors: 5,
            },
        )
        .unwrap()
    }),
    ("statistical", |c| {
        filter::statistical_outlier_removal(
            c,
            &StatisticalOutlierParams {
                mean_k: 50,
                std_mul: 1.0,
                ..Default::default()
            },
        )
        .unwrap()
    }),
];

fn benches(c: &mut Criterion) {
    for (n, size) in SIZES {
        let cloud = pile(n, 4);
        let mut group = c.benchmark_group(format!("filters_{size}"));
        group.sample_size(10);
        if n >= 1_000_000 {
            group.measurement_time(std::time::Duration::from_secs(20));
        }
        for (name, run) in FILTERS {
            group.bench_with_input(BenchmarkId::new(name, n), &cloud, |b, cloud| {
                b.iter(|| run(cloud))
            });
        }
        group.finish();
    }
}

/// The clouds of the peer mode: `FILTER_BENCH_INPUT=FILE` (any format
/// `autoshovel_point_cloud::io` reads; labelled by its file stem), or the bench
/// pile at the sizes of `FILTER_BENCH_SIZES` (e.g. `100k,1m,5m,20m`;
/// default `100k,1m`).
fn peer_clouds() -> Vec<(String, PointCloud)> {
    if let Ok(path) = std::env::var("FILTER_BENCH_INPUT") {
        let path = std::path::Path::new(&path);
        let cloud = autoshovel_point_cloud::io::read(path, &mut |_, _| {})
            .expect("read FILTER_BENCH_INPUT")
            .cloud;
        let label = path
            .file_stem()
            .expect("a file name")
            .to_string_lossy()
            .into_owned();
        return vec![(label, cloud)];
    }
    let sizes = std::env::var("FILTER_BENCH_SIZES").unwrap_or_else(|_| "100k,1m".into());
    sizes
        .split(',')
        .map(|label| {
            let label = label.trim().to_ascii_lowercase();
            let (digits, unit) = label.split_at(label.len() - 1);
            let n: usize = match unit {
                "k" => digits.parse::<usize>().expect("a size like 100k") * 1_000,
                "m" => digits.parse::<usize>().expect("a size like 5m") * 1_000_000,
                _ => label.parse().expect("a size like 100k, 5m or 20000"),
            };
            let cloud = pile(n, 4);
            (label, cloud)
        })
        .collect()
}

/// The peer mode: clouds, outputs and median timings for `peer/bench_peers.py`.
fn write_for_peers(dir: &std::path::Path) {
    std::fs::create_dir_all(dir).expect("create FILTER_BENCH_WRITE");
    let runs: usize = std::env::var("FILTER_BENCH_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(3)
        .max(1);
    let only = std::env::var("FILTER_BENCH_ONLY").ok();
    for (size, cloud) in peer_clouds() {
        if only.is_none() || only.as_deref() == Some("clouds") {
            write_binary_pcd(&dir.join(format!("pile_{size}.pcd")), &cloud)
                .expect("write the bench cloud");
        }
        for (name, run) in FILTERS {
            if only
                .as_ref()
                .is_some_and(|o| *o != format!("{name}:{size}"))
            {
                continue;
            }
            let out = run(&cloud);
            // At least `runs` runs and half a second, as criterion warms up.
            let started = std::time::Instant::now();
            let mut ms = Vec::new();
            while ms.len() < runs || started.elapsed().as_secs_f64() < 0.5 {
                let t = std::time::Instant::now();
                criterion::black_box(run(&cloud));
                ms.push(t.elapsed().as_secs_f64() * 1e3);
            }
            ms.sort_by(f64::total_cmp);
            println!(
                "ours {name} {size} {:.3} ms {} points",
                ms[ms.len() / 2],
                out.len()
            );
            write_binary_pcd(&dir.join(format!("ours_{name}_{size}.pcd")), &out)
                .expect("write an output");
        }
    }
}

fn main() {
    if let Ok(dir) = std::env::var("FILTER_BENCH_WRITE") {
        write_for_peers(std::path::Path::new(&dir));
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    benches(&mut c);
    c.final_summary();
}
