//! The warm-start pack file: what `write_pack` writes, `read_pack` reads
//! back bit for bit; a damaged file is refused with its line.

use autoshovel_optim::Evaluation;
use autoshovel_rope_shovel_dig::{
    read_pack, write_pack, DigError, DigModel, DigSurface, MachineProfile, PackProblem,
};
use autoshovel_terrain::PileShape;

#[test]
fn write_then_read_round_trips_every_wolf() {
    let p = MachineProfile::scale_model();
    let m = DigModel::new(
        &p,
        DigSurface::from_shape(PileShape::Typical, p.dipper.width_m),
    )
    .unwrap();
    let pack: Vec<(Vec<f64>, Evaluation)> = (0..7)
        .map(|i| {
            let x = vec![
                0.01 * i as f64,
                -0.02,
                9.0 + 0.37 * i as f64,
                0.3,
                0.3 - 1e-7 * i as f64,
            ];
            (x, Evaluation::new(13.0 + i as f64 / 3.0, 0.1 * i as f64))
        })
        .collect();
    let dir = std::env::temp_dir().join(format!("dig-pack-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("pack.csv");
    write_pack(&path, &m, &pack).unwrap();
    let back = read_pack(&path).unwrap();
    assert_eq!(back.len(), pack.len());
    for ((x, _), d) in pack.iter().zip(&back) {
        let want = m.decision(x);
        for (a, b) in want.to_vec().iter().zip(d.to_vec()) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }
    // A damaged row is refused by file and line.
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replacen('\n', "\n1,2,-3,4,5,6,7\n", 1)).unwrap();
    match read_pack(&path) {
        Err(
            e @ DigError::Pack {
                line: Some(2),
                problem: PackProblem::DurationNotPositive { .. },
                ..
            },
        ) => assert!(e.to_string().contains("pack.csv:2: td_s = -3")),
        other => panic!("expected a refusal of line 2, got {other:?}"),
    }
    std::fs::remove_dir_all(&dir).ok();
}
