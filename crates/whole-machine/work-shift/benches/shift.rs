//! One loading cycle of the built-in shift (scan, perceive, plan, dig,
//! swing, dump, return): `cargo bench -p autoshovel-work-shift`.

use criterion::{criterion_group, criterion_main, Criterion};

use autoshovel_rope_shovel_dig::MachineProfile;
use autoshovel_work_shift::{run_shift, ShiftOptions, ShiftScenario};

fn cycle(c: &mut Criterion) {
    let scenario = ShiftScenario::bench();
    let profile = MachineProfile::scale_model();
    let options = ShiftOptions {
        cycles: Some(1),
        ..ShiftOptions::default()
    };
    let mut group = c.benchmark_group("shift");
    group.sample_size(20);
    group.bench_function("one cycle (bench)", |b| {
        b.iter(|| run_shift(&scenario, &profile, &options, &mut |_| {}).unwrap())
    });
    group.finish();
}

criterion_group!(benches, cycle);
criterion_main!(benches);
