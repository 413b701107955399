//! Mamdani centroids with closed forms (Mamdani & Assilian 1975
//! min / max / centroid): a single unclipped symmetric triangle, a clipped
//! symmetric trapezoid, two clipped triangles side by side (worked by hand
//! below), rule weights, and the no-rule-fires fallback.

use approx::assert_abs_diff_eq;
use autoshovel_fuzzy::{MamdaniSystem, Membership, Rule, RuleBase, Variable};

/// One input x ∈ [0, 1] with a left shoulder "lo" (1 at 0 → 0 at 1) and a
/// right shoulder "hi" (0 at 0 → 1 at 1), plus "all" = 1 everywhere.
fn input() -> Variable {
    Variable::new("x", 0.0, 1.0)
        .with_term(
            "lo",
            Membership::Triangle {
                a: 0.0,
                b: 0.0,
                c: 1.0,
            },
        )
        .with_term(
            "hi",
            Membership::Triangle {
                a: 0.0,
                b: 1.0,
                c: 1.0,
            },
        )
        .with_term(
            "all",
            Membership::Trapezoid {
                a: 0.0,
                b: 0.0,
                c: 1.0,
                d: 1.0,
            },
        )
}

#[test]
fn single_full_rule_gives_the_triangle_peak() {
    // Output y ∈ [−10, 10], 201 samples 0.1 apart; symmetric triangle
    // (−2, 1, 4) at strength 1 → centroid = peak = 1.
    let y = Variable::new("y", -10.0, 10.0).with_term(
        "T",
        Membership::Triangle {
            a: -2.0,
            b: 1.0,
            c: 4.0,
        },
    );
    let x = input();
    let rules = vec![Rule::new(vec![x.require_term("all").unwrap()], 0)];
    let sys = MamdaniSystem::new(vec![x], y, rules).unwrap();
    for xv in [0.0, 0.3, 1.0, -5.0, 5.0] {
        assert_abs_diff_eq!(sys.infer(&[xv]).unwrap(), 1.0, epsilon = 1e-12);
    }
}

#[test]
fn clipped_symmetric_trapezoid_gives_its_centre() {
    // Trapezoid (−3, −1, 3, 5), centre 1, clipped at μ_lo(0.6) = 0.4: the
    // clipped shape (−3, −2.2, 4.2, 5) at height 0.4 is still symmetric
    // about 1. Coarse (21 samples, 1 apart: the clip corners −2.2 and 4.2
    // fall between samples and must be inserted) and default resolution.
    for resolution in [21, 201] {
        let y = Variable::new("y", -10.0, 10.0).with_term(
            "T",
            Membership::Trapezoid {
                a: -3.0,
                b: -1.0,
                c: 3.0,
                d: 5.0,
            },
        );
        let x = input();
        let rules = vec![Rule::new(vec![0], 0)];
        let sys = MamdaniSystem::with_resolution(vec![x], y, rules, resolution).unwrap();
        let t = sys.infer_traced(&[0.6]).unwrap();
        assert_abs_diff_eq!(t.term_strengths[0], 0.4, epsilon = 1e-15);
        assert_abs_diff_eq!(t.output, 1.0, epsilon = 1e-12);
    }
}

/// Output z ∈ [0, 20] with L = (2, 4, 6) and R = (10, 14, 18).
fn two_triangles() -> Variable {
    Variable::new("z", 0.0, 20.0)
        .with_term(
            "L",
            Membership::Triangle {
                a: 2.0,
                b: 4.0,
                c: 6.0,
            },
        )
        .with_term(
            "R",
            Membership::Triangle {
                a: 10.0,
                b: 14.0,
                c: 18.0,
            },
        )
}

#[test]
fn two_clipped_triangles_give_the_area_weighted_centroid() {
    // x = 1/3: μ_lo = 2/3 fires "lo → L", μ_hi = 1/3 fires "hi → R".
    //
    // L clipped at 2/3: base 2…6 (4 wide), μ_L = (z − 2)/2 reaches 2/3 at
    //   z = 10/3 and leaves it at 14/3, top 4/3 wide;
    //   area = ½ (4 + 4/3) · 2/3 = 16/9, centroid 4 (symmetric).
    // R clipped at 1/3: base 10…18 (8 wide), μ_R = (z − 10)/4 reaches 1/3
    //   at 34/3 and leaves it at 50/3, top 16/3 wide;
    //   area = ½ (8 + 16/3) · 1/3 = 20/9, centroid 14.
    // Disjoint supports, so the centroid is the area-weighted mean:
    //   (16/9 · 4 + 20/9 · 14) / (36/9) = (64 + 280) / 36 = 86/9 ≈ 9.5556.
    //
    // All clip corners (10/3, 14/3, 34/3, 50/3) fall between the samples
    // 0.1 apart; the triangles' own breakpoints are samples, so with the
    // corners inserted the piecewise-linear aggregate is exact.
    let x = input();
    let z = two_triangles();
    let mut rules = RuleBase::new();
    rules
        .add(std::slice::from_ref(&x), &z, &["lo"], "L", 1.0)
        .unwrap();
    rules
        .add(std::slice::from_ref(&x), &z, &["hi"], "R", 1.0)
        .unwrap();
    let sys = MamdaniSystem::new(vec![x], z, rules).unwrap();
    let got = sys.infer(&[1.0 / 3.0]).unwrap();
    assert_abs_diff_eq!(got, 86.0 / 9.0, epsilon = 1e-12);
    // The dense exact-membership reference agrees; plain sampling (the
    // reference at the same 201 points, no corners) is visibly worse.
    let dense = sys.infer_dense(&[1.0 / 3.0], 100_001).unwrap();
    assert_abs_diff_eq!(dense, 86.0 / 9.0, epsilon = 1e-6);
    let plain = sys.infer_dense(&[1.0 / 3.0], 201).unwrap();
    assert!((plain - 86.0 / 9.0).abs() > 1e-5, "plain {plain}");
}

#[test]
fn weights_scale_the_firing_strength() {
    // Both rules on "all" (strength 1), weights 1 (L) and 0.5 (R): L whole,
    // area ½ · 4 · 1 = 2, centroid 4; R clipped at ½: top 12…16, area
    // ½ (8 + 4) · ½ = 3, centroid 14. Result (2 · 4 + 3 · 14) / 5 = 10.
    let x = input();
    let z = two_triangles();
    let mut rules = RuleBase::new();
    rules
        .add(std::slice::from_ref(&x), &z, &["all"], "L", 1.0)
        .unwrap();
    rules
        .add(std::slice::from_ref(&x), &z, &["all"], "R", 0.5)
        .unwrap();
    let sys = MamdaniSystem::new(vec![x], z, rules).unwrap();
    let t = sys.infer_traced(&[0.5]).unwrap();
    assert_eq!(t.fired, vec![(0, 1.0), (1, 0.5)]);
    assert_abs_diff_eq!(t.output, 10.0, epsilon = 1e-12);
}

#[test]
fn three_inputs_and_gaussians_work() {
    // Genericity: three inputs, Gaussian output terms. Symmetric setup →
    // symmetric result.
    let names = ["N", "Z", "P"];
    let a = Variable::evenly_spaced_triangles("a", -1.0, 1.0, &names).unwrap();
    let b = Variable::evenly_spaced_triangles("b", -2.0, 2.0, &names).unwrap();
    let c = Variable::evenly_spaced_triangles("c", -3.0, 3.0, &names).unwrap();
    let out = Variable::new("o", -5.0, 5.0)
        .with_term(
            "N",
            Membership::Gaussian {
                mean: -3.0,
                sigma: 1.0,
            },
        )
        .with_term(
            "Z",
            Membership::Gaussian {
                mean: 0.0,
                sigma: 1.0,
            },
        )
        .with_term(
            "P",
            Membership::Gaussian {
                mean: 3.0,
                sigma: 1.0,
            },
        );
    let mut rules = RuleBase::new();
    let inputs = vec![a, b, c];
    for (i, t) in names.iter().enumerate() {
        rules.add(&inputs, &out, &[t, t, t], t, 1.0).unwrap();
        let other = names[2 - i];
        rules
            .add(&inputs, &out, &[t, "Z", other], "Z", 0.5)
            .unwrap();
    }
    let sys = MamdaniSystem::new(inputs, out, rules).unwrap();
    let p = sys.infer(&[0.4, 0.9, 1.1]).unwrap();
    let n = sys.infer(&[-0.4, -0.9, -1.1]).unwrap();
    assert!(p > 0.0);
    assert_abs_diff_eq!(p, -n, epsilon = 1e-9);
    assert_abs_diff_eq!(sys.infer(&[0.0, 0.0, 0.0]).unwrap(), 0.0, epsilon = 1e-9);
    let mut scratch = sys.scratch();
    assert_eq!(sys.infer_with(&[0.4, 0.9, 1.1], &mut scratch).unwrap(), p);
}

#[test]
fn no_rule_fired_returns_the_universe_centre_and_says_so() {
    // Only "lo" has a rule; at x = 1 its degree is 0.
    let x = input();
    let z = two_triangles();
    let mut rules = RuleBase::new();
    rules
        .add(std::slice::from_ref(&x), &z, &["lo"], "R", 1.0)
        .unwrap();
    let sys = MamdaniSystem::new(vec![x], z, rules).unwrap();
    assert_eq!(sys.infer(&[1.0]).unwrap(), 10.0);
    let t = sys.infer_traced(&[1.0]).unwrap();
    assert!(t.fallback);
    assert!(t.fired.is_empty());
    assert_eq!(t.output, 10.0);
    assert!(!sys.infer_traced(&[0.5]).unwrap().fallback);
}

#[test]
fn scratch_of_any_size_is_fitted() {
    let x = input();
    let z = two_triangles();
    let rules = vec![Rule::new(vec![0], 0), Rule::new(vec![1], 1)];
    let sys = MamdaniSystem::new(vec![x], z, rules).unwrap();
    let mut scratch = autoshovel_fuzzy::Scratch::default();
    for v in [0.0, 0.25, 1.0 / 3.0, 0.9] {
        assert_eq!(
            sys.infer_with(&[v], &mut scratch).unwrap(),
            sys.infer(&[v]).unwrap()
        );
    }
}
