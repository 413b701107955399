//! Properties of the paper's §4.3 Table-1 controller built on this crate
//! (Mamdani & Assilian 1975 min / max / centroid): odd symmetry, the
//! origin, what monotonicity holds and what does not, the discretisation
//! error of the default 201 output samples, traces and the control surface.

mod common;

use common::table1::{self, TABLE1, TERMS};
use proptest::prelude::*;

fn u(sys: &autoshovel_fuzzy::MamdaniSystem, e: f64, ec: f64) -> f64 {
    sys.infer(&[e, ec]).unwrap()
}

/// Term peaks of a 7-term partition of [−max, max].
fn peaks(max: f64) -> Vec<f64> {
    (0..7).map(|i| -max + 2.0 * max * i as f64 / 6.0).collect()
}

#[test]
fn table_is_antisymmetric() {
    // The fixture itself: cell (r, c) and cell (6 − r, 6 − c) are opposite.
    let neg = |t: &str| TERMS[6 - TERMS.iter().position(|x| *x == t).unwrap()];
    for r in 0..7 {
        for c in 0..7 {
            assert_eq!(TABLE1[6 - r][6 - c], neg(TABLE1[r][c]), "cell ({r}, {c})");
        }
    }
}

#[test]
fn origin_gives_zero() {
    let sys = table1::system();
    assert!(
        u(&sys, 0.0, 0.0).abs() < 1e-9,
        "u(0,0) = {}",
        u(&sys, 0.0, 0.0)
    );
    let t = sys.infer_traced(&[0.0, 0.0]).unwrap();
    // Only rule (ZE, ZE) → ZE fires, at full strength: r = 3, c = 3.
    assert_eq!(t.fired, vec![(3 * 7 + 3, 1.0)]);
    assert!(!t.fallback);
}

#[test]
fn large_positive_error_commands_positive_speed_difference() {
    // e = 0.3 m is the PM peak and ec = 0 the ZE peak: the single rule
    // (ec ZE, e PM) fires, and Table 1 row ZE, column PM says PS (PM needs
    // e = PB). PS is the triangle 0 … 1800 rpm with its peak at 900, which
    // falls between the samples 891 and 918, hence 900 + 0.09 rpm.
    let sys = table1::system();
    let t = sys.infer_traced(&[0.3, 0.0]).unwrap();
    assert_eq!(t.fired.len(), 1);
    let rule = &sys.rules()[t.fired[0].0];
    assert_eq!((rule.antecedent[0], rule.antecedent[1]), (5, 3));
    assert_eq!(sys.output().terms[rule.consequent].0, "PS");
    assert!((t.output - 900.0).abs() < 0.1, "u = {}", t.output);
    assert!((sys.infer_dense(&[0.3, 0.0], 100_001).unwrap() - 900.0).abs() < 1e-6);
    // e = PB, ec = ZE gives PM.
    assert!((u(&sys, 0.45, 0.0) - 1800.0).abs() < 0.1);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// u(−e, −ec) = −u(e, ec), also beyond the universes (clamping is
    /// symmetric too).
    #[test]
    fn odd_symmetry(e in -0.6f64..0.6, ec in -40.0f64..40.0) {
        let sys = table1::system();
        let a = u(&sys, e, ec);
        let b = u(&sys, -e, -ec);
        prop_assert!((a + b).abs() < 1e-9, "u({e},{ec}) = {a}, u(-e,-ec) = {b}");
    }

    /// Shifting e (or ec) by one term spacing never lowers u: every cell of
    /// Table 1 is ≤ the cell one column right (one row down).
    #[test]
    fn one_term_step_never_lowers_u(e in -0.45f64..0.30, ec in -30.0f64..20.0) {
        let sys = table1::system();
        let base = u(&sys, e, ec);
        prop_assert!(u(&sys, e + 0.15, ec) >= base - 1e-9);
        prop_assert!(u(&sys, e, ec + 10.0) >= base - 1e-9);
    }
}

#[test]
fn monotone_on_the_lattice_of_term_peaks() {
    // At a peak pair exactly one rule fires at strength 1, so u is the
    // centroid of that cell's term; Table 1 is non-decreasing along rows
    // and columns, hence so is u on the 7 × 7 lattice.
    let sys = table1::system();
    let (es, ecs) = (peaks(table1::E_MAX), peaks(table1::EC_MAX));
    for (r, &ec) in ecs.iter().enumerate() {
        for (c, &e) in es.iter().enumerate() {
            let here = u(&sys, e, ec);
            if c + 1 < 7 {
                assert!(u(&sys, es[c + 1], ec) >= here - 1e-9, "e step at ({r},{c})");
            }
            if r + 1 < 7 {
                assert!(
                    u(&sys, e, ecs[r + 1]) >= here - 1e-9,
                    "ec step at ({r},{c})"
                );
            }
        }
    }
}

/// Column index of the cell of e containing `x` (0..6), row of ec likewise.
fn cell(x: f64, max: f64) -> usize {
    (((x + max) / (2.0 * max / 6.0)).floor() as usize).min(5)
}

#[test]
fn not_monotone_but_only_on_plateaus() {
    // u is NOT monotone in e (or ec) everywhere. Where two neighbouring
    // cells of a fired row share a consequent (e.g. row ec = NB: e = NB and
    // NM both give NB), that term's clipping level is max(μ_NB(e), μ_NM(e)),
    // which dips to ½ between the peaks; the clipped NB shoulder's centroid
    // then moves toward ZE and back, so u rises and falls again. This is the
    // max–min + centroid inference itself (infer_dense shows the same), not
    // discretisation. Check: (1) such decreases exist; (2) every decrease on
    // a fine grid lies in a cell where a fired row (column) has two equal
    // neighbouring consequents.
    let sys = table1::system();
    assert!(u(&sys, -0.375, -30.0) > u(&sys, -0.30, -30.0) + 1.0);
    assert!(
        sys.infer_dense(&[-0.375, -30.0], 100_001).unwrap()
            > sys.infer_dense(&[-0.30, -30.0], 100_001).unwrap() + 1.0
    );

    let (n, m) = (181, 121);
    let xs: Vec<f64> = (0..n)
        .map(|i| -0.45 + 0.9 * i as f64 / (n - 1) as f64)
        .collect();
    let ys: Vec<f64> = (0..m)
        .map(|j| -30.0 + 60.0 * j as f64 / (m - 1) as f64)
        .collect();
    let z: Vec<Vec<f64>> = ys
        .iter()
        .map(|&y| xs.iter().map(|&x| u(&sys, x, y)).collect())
        .collect();
    let (mut along_e, mut along_ec) = (0, 0);
    for (j, &y) in ys.iter().enumerate() {
        for i in 1..n {
            if z[j][i - 1] > z[j][i] + 1e-9 {
                along_e += 1;
                let c = cell(0.5 * (xs[i - 1] + xs[i]), table1::E_MAX);
                let r0 = cell(y, table1::EC_MAX);
                let shared = [r0, r0 + 1]
                    .iter()
                    .any(|&r| TABLE1[r][c] == TABLE1[r][c + 1]);
                assert!(shared, "decrease along e at e = {}, ec = {y}", xs[i]);
            }
        }
    }
    for (i, &x) in xs.iter().enumerate() {
        for j in 1..m {
            if z[j - 1][i] > z[j][i] + 1e-9 {
                along_ec += 1;
                let r = cell(0.5 * (ys[j - 1] + ys[j]), table1::EC_MAX);
                let c0 = cell(x, table1::E_MAX);
                let shared = [c0, c0 + 1]
                    .iter()
                    .any(|&c| TABLE1[r][c] == TABLE1[r + 1][c]);
                assert!(shared, "decrease along ec at e = {x}, ec = {}", ys[j]);
            }
        }
    }
    assert!(along_e > 0 && along_ec > 0);
}

#[test]
fn discretisation_error_of_201_samples_is_below_half_an_rpm() {
    // Against the 100 001-sample reference (itself within ~1e-6 rpm of the
    // continuous centroid). Measured max ≈ 0.34 rpm; the chord-cut peaks at
    // ±900 / ±1800 rpm (between samples 27 rpm apart) and the uninserted
    // crossings of two clipped terms are what remains. 41 × 41 grid plus
    // pseudo-random points.
    let sys = table1::system();
    let mut points: Vec<(f64, f64)> = Vec::new();
    for i in 0..41 {
        for j in 0..41 {
            points.push((
                -0.45 + 0.9 * i as f64 / 40.0,
                -30.0 + 60.0 * j as f64 / 40.0,
            ));
        }
    }
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..300 {
        points.push((-0.45 + 0.9 * uniform(), -30.0 + 60.0 * uniform()));
    }
    let mut worst = 0.0f64;
    for (e, ec) in points {
        let reference = sys.infer_dense(&[e, ec], 100_001).unwrap();
        worst = worst.max((u(&sys, e, ec) - reference).abs());
    }
    println!("max |infer − reference| = {worst:.4} rpm");
    assert!(worst < 0.5, "discretisation error {worst} rpm");
    // The reference converged: 4× the samples moves it by far less.
    let a = sys.infer_dense(&[0.1, 3.0], 100_001).unwrap();
    let b = sys.infer_dense(&[0.1, 3.0], 400_001).unwrap();
    assert!((a - b).abs() < 1e-4);
}

#[test]
fn trace_is_consistent_with_infer() {
    let sys = table1::system();
    for &(e, ec) in &[(0.1, -7.0), (-0.44, 29.0), (0.9, -100.0), (0.0, 12.5)] {
        let t = sys.infer_traced(&[e, ec]).unwrap();
        assert_eq!(t.output, u(&sys, e, ec));
        assert_eq!(t.inputs, vec![e.clamp(-0.45, 0.45), ec.clamp(-30.0, 30.0)]);
        for d in &t.degrees {
            assert_eq!(d.len(), 7);
            assert!((d.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
        // Each fired strength is min of its two antecedent degrees, and the
        // term levels are the max over the fired rules.
        let mut levels = [0.0f64; 7];
        for &(r, s) in &t.fired {
            let rule = &sys.rules()[r];
            let want = t.degrees[0][rule.antecedent[0]].min(t.degrees[1][rule.antecedent[1]]);
            assert_eq!(s, want);
            assert!(s > 0.0);
            levels[rule.consequent] = levels[rule.consequent].max(s);
        }
        assert_eq!(t.term_strengths, levels.to_vec());
        // Two memberships per input at most are non-zero → at most 4 rules.
        assert!(!t.fired.is_empty() && t.fired.len() <= 4);
    }
}

#[test]
fn surface_matches_pointwise_inference() {
    let sys = table1::system();
    let s = sys.surface(11, 7).unwrap();
    assert_eq!((s.xs.len(), s.ys.len(), s.z.len()), (11, 7, 7));
    assert_eq!((s.xs[0], s.xs[10]), (-0.45, 0.45));
    assert_eq!((s.ys[0], s.ys[6]), (-30.0, 30.0));
    for (iy, row) in s.z.iter().enumerate() {
        assert_eq!(row.len(), 11);
        for (ix, &z) in row.iter().enumerate() {
            assert_eq!(z, u(&sys, s.xs[ix], s.ys[iy]));
        }
    }
    let csv = s.to_csv();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("e,ec,u"));
    assert_eq!(lines.count(), 77);
}
