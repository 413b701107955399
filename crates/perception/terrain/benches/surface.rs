//! Floor estimate, surface fit and scan generation at 100 k and 1 M points.

use autoshovel_point_cloud::PointCloud;
use autoshovel_terrain::{
    estimate_tilt, fit_surface, generate_pile, level, FitParams, PileParams, PileShape, TiltParams,
};
use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn scan(points: usize) -> PileParams {
    PileParams {
        shape: PileShape::Typical,
        points,
        ..PileParams::default()
    }
}

/// The levelled pile with the floor cut away, as `fit_surface` sees it.
fn pile_only(raw: &PointCloud) -> PointCloud {
    let t = estimate_tilt(raw, &TiltParams::default()).expect("floor");
    let flat = level(raw, t.roll_rad, t.pitch_rad);
    PointCloud::new(
        flat.points
            .into_iter()
            .filter(|q| f64::from(q[2]) > t.floor_height_m + 0.2)
            .collect(),
    )
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("surface");
    g.sample_size(10);
    for (label, n) in [("100k", 100_000), ("1M", 1_000_000)] {
        let raw = generate_pile(&scan(n)).expect("scan");
        let pile = pile_only(&raw);
        let tp = TiltParams::default();
        g.bench_function(format!("estimate_tilt/{label}"), |b| {
            b.iter(|| estimate_tilt(black_box(&raw), &tp).expect("floor"))
        });
        let fp = FitParams::default();
        g.bench_function(format!("fit_surface/{label}"), |b| {
            b.iter(|| fit_surface(black_box(&pile), &fp).expect("fit"))
        });
    }
    let p = scan(1_000_000);
    g.bench_function("generate_pile/1M", |b| {
        b.iter(|| generate_pile(black_box(&p)).expect("scan"))
    });
    g.finish();
}

criterion_group!(surface, benches);
criterion_main!(surface);
