//! The trackers' laws against their closed forms: the path's curvature, the
//! curvature-dependent α of [W eq. 23], the variable universe of [W eq. 24]
//! and Stanley's law.

use autoshovel_core::{Pose2, Vec2};
use autoshovel_walk_planner::Direction;
use autoshovel_walk_tracker::*;
use std::f64::consts::PI;

/// A left-turning arc of radius `r` from (r, 0), sampled every 5 cm.
fn arc(r: f64) -> RefLeg {
    let n = (r * PI / 0.05) as usize;
    let pts = (0..=n)
        .map(|i| {
            let a = PI * i as f64 / n as f64;
            Vec2::new(r * a.cos(), r * a.sin())
        })
        .collect();
    RefLeg::new(Direction::Forward, pts, None).unwrap()
}

fn straight() -> RefLeg {
    RefLeg::new(
        Direction::Forward,
        vec![Vec2::new(0.0, 0.0), Vec2::new(50.0, 0.0)],
        None,
    )
    .unwrap()
}

fn input<'a>(
    leg: &'a RefLeg,
    dev: &'a Deviations,
    crawler: &'a CrawlerParams,
    speed: f64,
) -> ControlInput<'a> {
    ControlInput {
        leg,
        pose: Pose2::new(0.0, 0.0, 0.0),
        dev,
        speed_mps: speed,
        dt_s: 0.1,
        crawler,
    }
}

fn dev(d: f64, d0: f64, s: f64, heading_error: f64) -> Deviations {
    Deviations {
        d_m: d,
        d0_m: d0,
        s_a_m: s,
        heading_error_rad: heading_error,
        c: Vec2::zeros(),
        a: Vec2::zeros(),
        b: Vec2::zeros(),
    }
}

#[test]
fn the_curvature_of_an_arc_is_one_over_its_radius() {
    for r in [4.0, 8.0, 20.0] {
        let leg = arc(r);
        let k = leg.curvature_at(0.5 * leg.length_m(), 0.5);
        // A polyline of 5 cm chords: within half a per cent of 1/R.
        assert!((k * r - 1.0).abs() < 5e-3, "r {r}: κ {k}");
    }
    assert_eq!(straight().curvature_at(10.0, 0.5), 0.0);
}

#[test]
fn alpha_grows_with_curvature_as_set() {
    // With ec = 0 at the first tick, the output depends on e alone: the same
    // u as a constant-α tracker whose α is α0 + c·|κ|.
    let crawler = CrawlerParams::default();
    let leg = arc(5.0);
    let dv = dev(0.02, 0.05, 0.5 * leg.length_m(), 0.0);
    let kappa = leg.curvature_at(dv.s_a_m, 0.5);
    let curved = FuzzyParams {
        alpha: 0.3,
        alpha_curvature_m: 2.0,
        ..FuzzyParams::default()
    };
    let constant = FuzzyParams {
        alpha: 0.3 + 2.0 * kappa.abs(),
        ..FuzzyParams::default()
    };
    let a = FuzzyTracker::new(curved).step(&input(&leg, &dv, &crawler, 1.0));
    let b = FuzzyTracker::new(constant).step(&input(&leg, &dv, &crawler, 1.0));
    assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    // On a straight the curvature term is idle.
    let s = straight();
    let a = FuzzyTracker::new(curved).step(&input(&s, &dv, &crawler, 1.0));
    let b = FuzzyTracker::new(FuzzyParams {
        alpha: 0.3,
        ..FuzzyParams::default()
    })
    .step(&input(&s, &dv, &crawler, 1.0));
    assert_eq!(a, b);
}

#[test]
fn the_variable_universe_is_li_s_law() {
    let crawler = CrawlerParams::default();
    let leg = straight();
    let fixed = FuzzyParams {
        alpha: 0.0,
        ..FuzzyParams::default()
    };
    let variable = FuzzyParams {
        universe: Universe::Variable,
        ..fixed
    };
    let system = autoshovel_walk_tracker::fuzzy_tracker::table1_system().unwrap();
    for e in [0.005, 0.02, 0.08, 0.186] {
        let dv = dev(e, 0.0, 1.0, 0.0);
        let got = FuzzyTracker::new(variable).step(&input(&leg, &dv, &crawler, 1.0));
        // α(x) = (|x|/E)^τ + ε on x = k1·e against E = 0.45; the rule base
        // sees k1·e/α and the output is scaled by β = α.
        let x = fixed.k1 * e;
        let a = ((x / 0.45).powf(variable.vu_tau) + variable.vu_epsilon).min(1.0);
        let want = -(a * fixed.k3 * system.infer(&[x / a, 0.0]).unwrap());
        assert!((got - want).abs() < 1e-9, "e {e}: {got} vs {want}");
        // At the universe's edge the factor is 1: the fixed law.
        if a == 1.0 {
            let f = FuzzyTracker::new(fixed).step(&input(&leg, &dv, &crawler, 1.0));
            assert!((got - f).abs() < 1e-9);
        }
    }
}

#[test]
fn stanley_is_its_closed_form() {
    let crawler = CrawlerParams::default();
    let p = StanleyParams::default();
    let per_rad_s = crawler.gauge_m / crawler.mps_per_rpm();
    // On the path, aligned, on a straight: nothing to do.
    let leg = straight();
    let mut st = Stanley { params: p };
    assert_eq!(
        st.step(&input(&leg, &dev(0.0, 0.0, 5.0, 0.0), &crawler, 1.5)),
        0.0
    );
    // 0.2 m left of the path, heading 3° left of it, at 1.5 m/s.
    let (d0, he, v) = (0.2, 3f64.to_radians(), 1.5);
    let delta = -he + (-p.k_per_s * d0).atan2(p.softening_mps + v);
    let want = delta / p.heading_time_s * per_rad_s;
    let got = st.step(&input(&leg, &dev(0.0, d0, 5.0, he), &crawler, v));
    assert!((got - want).abs() < 1e-9, "{got} vs {want}");
    assert!(got < 0.0, "turns right, back to the path");
    // On an arc, on the path: the curvature's yaw rate v/R alone.
    let leg = arc(6.0);
    let got = st.step(&input(&leg, &dev(0.0, 0.0, 5.0, 0.0), &crawler, v));
    let want = v / 6.0 * per_rad_s;
    assert!((got - want).abs() < 5e-3 * want, "{got} vs {want}");
}
