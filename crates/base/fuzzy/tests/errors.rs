//! Every definition or call error surfaces as the right `FuzzyError`
//! variant naming the value at fault, and inference never panics nor leaves
//! the output universe (proptest over the paper's §4.3 Table-1 controller
//! and over random generic systems; Mamdani & Assilian 1975 inference).

mod common;

use autoshovel_fuzzy::{FuzzyError, MamdaniSystem, Membership, Rule, RuleBase, Variable};
use common::table1::{self, TABLE1, TERMS};
use proptest::prelude::*;

fn vars() -> (Variable, Variable, Variable) {
    (
        Variable::evenly_spaced_triangles("e", -0.45, 0.45, &TERMS).unwrap(),
        Variable::evenly_spaced_triangles("ec", -30.0, 30.0, &TERMS).unwrap(),
        Variable::evenly_spaced_triangles("u", -2700.0, 2700.0, &TERMS).unwrap(),
    )
}

fn rows(table: &[[&'static str; 7]]) -> Vec<&'static [&'static str]> {
    table
        .iter()
        .map(|r| -> &'static [&'static str] { Box::leak(Box::new(*r)) })
        .collect()
}

#[test]
fn unknown_term_in_table() {
    let (e, ec, u) = vars();
    let mut table = TABLE1;
    table[2][4] = "PX";
    let err = RuleBase::from_table(&e, &ec, &u, &rows(&table)).unwrap_err();
    assert_eq!(
        err,
        FuzzyError::UnknownTerm {
            variable: "u".into(),
            term: "PX".into()
        }
    );
    assert_eq!(err.to_string(), "variable `u` has no term `PX`");
}

#[test]
fn table_shape_errors() {
    let (e, ec, u) = vars();
    let short = rows(&TABLE1[..6]);
    assert_eq!(
        RuleBase::from_table(&e, &ec, &u, &short).unwrap_err(),
        FuzzyError::TableRows {
            variable: "ec".into(),
            expected: 7,
            got: 6
        }
    );
    let mut ragged = rows(&TABLE1);
    ragged[3] = &["NB", "NB"];
    assert_eq!(
        RuleBase::from_table(&e, &ec, &u, &ragged).unwrap_err(),
        FuzzyError::TableColumns {
            row: 3,
            variable: "e".into(),
            expected: 7,
            got: 2
        }
    );
}

#[test]
fn name_based_rule_errors() {
    let (e, ec, u) = vars();
    let inputs = [e, ec];
    let mut rb = RuleBase::new();
    assert_eq!(
        rb.add(&inputs, &u, &["NB"], "ZE", 1.0).unwrap_err(),
        FuzzyError::RuleArity {
            rule: 0,
            expected: 2,
            got: 1
        }
    );
    assert_eq!(
        rb.add(&inputs, &u, &["NB", "QQ"], "ZE", 1.0).unwrap_err(),
        FuzzyError::UnknownTerm {
            variable: "ec".into(),
            term: "QQ".into()
        }
    );
    assert!(matches!(
        rb.add(&inputs, &u, &["NB", "NB"], "ZE", f64::NAN)
            .unwrap_err(),
        FuzzyError::BadWeight { rule: 0, .. }
    ));
    assert!(rb.is_empty());
}

#[test]
fn wrong_input_count_and_non_finite_inputs() {
    let sys = table1::system();
    assert_eq!(
        sys.infer(&[0.1]).unwrap_err(),
        FuzzyError::InputCount {
            expected: 2,
            got: 1
        }
    );
    assert_eq!(
        sys.infer(&[0.1, 0.2, 0.3]).unwrap_err(),
        FuzzyError::InputCount {
            expected: 2,
            got: 3
        }
    );
    match sys.infer(&[0.1, f64::NAN]).unwrap_err() {
        FuzzyError::NotFinite { input, value } => {
            assert_eq!(input, "ec");
            assert!(value.is_nan());
        }
        other => panic!("wrong error {other:?}"),
    }
    assert_eq!(
        sys.infer(&[f64::NEG_INFINITY, 0.0]).unwrap_err(),
        FuzzyError::NotFinite {
            input: "e".into(),
            value: f64::NEG_INFINITY
        }
    );
    let mut scratch = sys.scratch();
    assert!(sys.infer_with(&[f64::NAN, 0.0], &mut scratch).is_err());
    assert!(sys.infer_traced(&[]).is_err());
    assert!(sys.infer_dense(&[0.0, 0.0], 1).is_err());
}

#[test]
fn system_construction_errors() {
    let (e, ec, u) = vars();
    let ok_rules = || vec![Rule::new(vec![0, 0], 0)];
    let build = |inputs: Vec<Variable>, out: Variable, rules: Vec<Rule>| {
        MamdaniSystem::new(inputs, out, rules).unwrap_err()
    };
    assert_eq!(build(vec![], u.clone(), ok_rules()), FuzzyError::NoInputs);
    assert_eq!(
        build(vec![e.clone(), ec.clone()], u.clone(), vec![]),
        FuzzyError::NoRules
    );
    assert_eq!(
        build(
            vec![e.clone(), ec.clone()],
            u.clone(),
            vec![Rule::new(vec![0], 0)]
        ),
        FuzzyError::RuleArity {
            rule: 0,
            expected: 2,
            got: 1
        }
    );
    assert_eq!(
        build(
            vec![e.clone(), ec.clone()],
            u.clone(),
            vec![Rule::new(vec![0, 7], 0)]
        ),
        FuzzyError::TermIndex {
            rule: 0,
            variable: "ec".into(),
            index: 7,
            count: 7
        }
    );
    assert_eq!(
        build(
            vec![e.clone(), ec.clone()],
            u.clone(),
            vec![Rule::new(vec![0, 0], 9)]
        ),
        FuzzyError::TermIndex {
            rule: 0,
            variable: "u".into(),
            index: 9,
            count: 7
        }
    );
    let heavy = Rule {
        weight: 1.5,
        ..Rule::new(vec![0, 0], 0)
    };
    assert_eq!(
        build(vec![e.clone(), ec.clone()], u.clone(), vec![heavy]),
        FuzzyError::BadWeight {
            rule: 0,
            weight: 1.5
        }
    );
    assert_eq!(
        MamdaniSystem::with_resolution(vec![e.clone(), ec.clone()], u.clone(), ok_rules(), 1)
            .unwrap_err(),
        FuzzyError::BadResolution { resolution: 1 }
    );
    let mut bad_mf = e.clone();
    bad_mf.terms[2].1 = Membership::Triangle {
        a: 0.1,
        b: 0.0,
        c: 0.2,
    };
    assert_eq!(
        build(vec![bad_mf, ec.clone()], u.clone(), ok_rules()),
        FuzzyError::BadMembership {
            variable: "e".into(),
            term: "NS".into(),
            why: "triangle needs a <= b <= c"
        }
    );
    let mut empty = ec.clone();
    empty.max = empty.min;
    assert!(matches!(
        build(vec![e.clone(), empty], u.clone(), ok_rules()),
        FuzzyError::EmptyUniverse { ref variable, .. } if variable == "ec"
    ));
    // An output term narrower than the sampling step is invisible.
    let thin = Variable::new("y", 0.0, 1.0)
        .with_term(
            "wide",
            Membership::Triangle {
                a: 0.0,
                b: 0.5,
                c: 1.0,
            },
        )
        .with_term(
            "thin",
            Membership::Triangle {
                a: 0.301,
                b: 0.302,
                c: 0.303,
            },
        );
    assert!(matches!(
        MamdaniSystem::with_resolution(vec![e.clone()], thin, vec![Rule::new(vec![0], 0)], 11)
            .unwrap_err(),
        FuzzyError::BadMembership { ref term, .. } if term == "thin"
    ));
}

#[test]
fn surface_errors() {
    let (e, _, u) = vars();
    let one = MamdaniSystem::new(vec![e], u, vec![Rule::new(vec![3], 3)]).unwrap();
    assert_eq!(
        one.surface(5, 5).unwrap_err(),
        FuzzyError::NotTwoInputs { inputs: 1 }
    );
    assert_eq!(
        table1::system().surface(1, 5).unwrap_err(),
        FuzzyError::BadGrid { nx: 1, ny: 5 }
    );
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1.0f64..1.0,
        -100.0f64..100.0,
        prop::num::f64::NORMAL | prop::num::f64::SUBNORMAL | prop::num::f64::ZERO,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    /// Any finite input, however far outside the universes: a value inside
    /// [−2700, 2700] rpm, equal on every inference path.
    #[test]
    fn table1_never_panics_and_stays_in_universe(e in finite(), ec in finite()) {
        let sys = table1::system();
        let u = sys.infer(&[e, ec]).unwrap();
        prop_assert!((-2700.0..=2700.0).contains(&u), "u = {u}");
        let mut scratch = sys.scratch();
        prop_assert_eq!(sys.infer_with(&[e, ec], &mut scratch).unwrap(), u);
        prop_assert_eq!(sys.infer_traced(&[e, ec]).unwrap().output, u);
    }
}

/// A random generic system: 1–3 inputs, 1–5 terms each of any kind, random
/// rules and weights, a random output resolution.
fn random_system() -> impl Strategy<Value = (MamdaniSystem, Vec<f64>)> {
    let mf = (0u8..3, -1.0f64..1.0, 0.01f64..1.0, 0.0f64..1.0, 0.0f64..1.0).prop_map(
        |(kind, centre, width, l, r)| match kind {
            0 => Membership::Triangle {
                a: centre - width * l,
                b: centre,
                c: centre + width * r.max(0.01),
            },
            1 => Membership::Trapezoid {
                a: centre - width,
                b: centre - width * l,
                c: centre + width * r,
                d: centre + width,
            },
            _ => Membership::Gaussian {
                mean: centre,
                sigma: width,
            },
        },
    );
    let variable = |name: &'static str| {
        prop::collection::vec(mf.clone(), 1..=5).prop_map(move |mfs| {
            let mut v = Variable::new(name, -1.0, 1.0);
            for (i, m) in mfs.into_iter().enumerate() {
                v.terms.push((format!("t{i}"), m));
            }
            v
        })
    };
    (
        prop::collection::vec(variable("in"), 1..=3),
        variable("out"),
        prop::collection::vec(
            (prop::collection::vec(0usize..5, 3), 0usize..5, 0.0f64..=1.0),
            1..20,
        ),
        2usize..300,
        prop::collection::vec(-3.0f64..3.0, 3),
    )
        .prop_filter_map("valid system", |(inputs, out, raw, res, x)| {
            let n = inputs.len();
            let rules: Vec<Rule> = raw
                .into_iter()
                .map(|(ante, cons, weight)| Rule {
                    antecedent: ante
                        .iter()
                        .zip(&inputs)
                        .map(|(&t, v)| t % v.terms.len())
                        .collect(),
                    consequent: cons % out.terms.len(),
                    weight,
                })
                .collect();
            let sys = MamdaniSystem::with_resolution(inputs, out, rules, res).ok()?;
            Some((sys, x[..n].to_vec()))
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_systems_never_panic_and_stay_in_universe((sys, x) in random_system()) {
        let u = sys.infer(&x).unwrap();
        prop_assert!((-1.0..=1.0).contains(&u), "u = {u}");
        let t = sys.infer_traced(&x).unwrap();
        prop_assert_eq!(t.output, u);
        prop_assert_eq!(t.fallback, t.fired.is_empty());
        let d = sys.infer_dense(&x, 2001).unwrap();
        prop_assert!((-1.0..=1.0).contains(&d));
    }
}
