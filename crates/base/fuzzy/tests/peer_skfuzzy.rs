//! Peer check: our Table-1 controller (paper §4.3) against scikit-fuzzy
//! 0.5's ControlSystemSimulation, whose output `peer/skfuzzy_table1.py`
//! stored in tests/data/skfuzzy_table1_surface.csv (21 × 21 grid, e, ec, u).
//!
//! Both use the same 201 output samples, the same breakpoints, Mamdani
//! min / min / max and the same discretised centroid (the aggregated set at
//! the samples plus the clipping corners, piecewise-linear centroid — see
//! the `mamdani` module docs), and skfuzzy's interpolated fuzzification is
//! exact because every input breakpoint is one of its universe samples. So
//! the only differences are rounding: the test bounds them at 1e-9 rpm (measured: ≈ 4e-12).

mod common;

use common::table1;

const CSV: &str = include_str!("data/skfuzzy_table1_surface.csv");

fn peer_rows() -> Vec<[f64; 3]> {
    CSV.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .skip(1) // header e,ec,u
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|f| f.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn header_is_e_ec_u() {
    let header = CSV.lines().find(|l| !l.starts_with('#')).unwrap();
    assert_eq!(header.trim(), "e,ec,u");
}

#[test]
fn matches_skfuzzy_on_the_21x21_grid() {
    let sys = table1::system();
    let rows = peer_rows();
    assert_eq!(rows.len(), 21 * 21);
    let mut worst = (0.0f64, [0.0; 3], 0.0);
    for row @ [e, ec, u_peer] in rows {
        assert!(e.abs() <= table1::E_MAX && ec.abs() <= table1::EC_MAX);
        let u = sys.infer(&[e, ec]).unwrap();
        let d = (u - u_peer).abs();
        if d > worst.0 {
            worst = (d, row, u);
        }
    }
    println!(
        "max |ours − skfuzzy| = {:.3e} rpm at {:?} (ours {})",
        worst.0, worst.1, worst.2
    );
    assert!(worst.0 < 1e-9, "max difference {worst:?}");
}

#[test]
fn plain_sampling_would_not_match() {
    // Guard that the comparison has teeth: without the clipping corners
    // (the aggregated set only at the 201 samples) the centroid moves by a
    // good fraction of an rpm somewhere on the grid, far above the 1e-6
    // tolerance used above. infer_dense with 201 samples is exactly that.
    let sys = table1::system();
    let worst = peer_rows()
        .into_iter()
        .map(|[e, ec, u]| (sys.infer_dense(&[e, ec], 201).unwrap() - u).abs())
        .fold(0.0f64, f64::max);
    assert!(worst > 0.05, "plain sampling differs by only {worst}");
}
