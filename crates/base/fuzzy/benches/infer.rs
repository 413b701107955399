//! Criterion benchmarks of Mamdani inference (Mamdani & Assilian 1975) on
//! the paper's §4.3 Table-1 controller (2 inputs × 7 terms, 49 rules, 201
//! output samples): one inference at a few operating points, through each
//! entry point, and whole control surfaces.
//!
//! Run: `cargo bench -p autoshovel-fuzzy --bench infer`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};

#[path = "../tests/common/table1.rs"]
mod table1;

fn bench_infer(c: &mut Criterion) {
    let sys = table1::system();
    let mut group = c.benchmark_group("infer");
    // Origin (1 rule fires), inside a cell (4 rules), a saturated corner,
    // and a point where the clipped shapes have many corners.
    for (label, x) in [
        ("origin", [0.0, 0.0]),
        ("cell", [0.1, -7.0]),
        ("saturated", [0.6, 45.0]),
        ("mixed", [-0.2925, 12.3]),
    ] {
        group.bench_function(label, |b| b.iter(|| sys.infer(black_box(&x)).unwrap()));
    }
    let mut scratch = sys.scratch();
    group.bench_function("cell_with_scratch", |b| {
        b.iter(|| {
            sys.infer_with(black_box(&[0.1, -7.0]), &mut scratch)
                .unwrap()
        })
    });
    group.bench_function("cell_traced", |b| {
        b.iter(|| sys.infer_traced(black_box(&[0.1, -7.0])).unwrap())
    });
    group.finish();

    let mut group = c.benchmark_group("surface");
    group.sample_size(20);
    group.bench_function("21x21", |b| {
        b.iter(|| sys.surface(black_box(21), 21).unwrap())
    });
    group.bench_function("101x101", |b| {
        b.iter(|| sys.surface(black_box(101), 101).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench_infer);
criterion_main!(benches);
