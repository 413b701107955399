//! Tuning on equal terms: every tracker gets the same budget on the same
//! runs, the search is seeded, and the runs it is scored on are not the ones
//! it was tuned on.

use autoshovel_walk_tracker::tune::{evaluate, tune, CaseSets, Tunable};

#[test]
fn every_tracker_gets_the_same_budget_and_the_sets_are_disjoint() {
    let sets = CaseSets::standard().unwrap();
    let names = |c: &[autoshovel_walk_tracker::tune::Case]| {
        c.iter().map(|c| c.name.clone()).collect::<Vec<_>>()
    };
    let (train, held, unseen) = (
        names(&sets.training),
        names(&sets.held_out),
        names(&sets.unseen),
    );
    for n in held.iter().chain(&unseen) {
        assert!(!train.contains(n), "{n} is tuned on and scored on");
    }
    assert!(unseen
        .iter()
        .all(|n| n.starts_with("tight-curve@") || n.starts_with("long-v-slip@")));
    // A small training set keeps the test quick; the budget is what matters.
    let training = &sets.training[..3];
    for t in Tunable::ALL {
        let a = tune(t, training, 5, 9);
        assert_eq!(a.evaluations, 5, "{}", a.name);
        assert_eq!(a.progress.len(), 5);
        // The best never gets worse, starts at the defaults and is what its gains give.
        assert!(a.progress.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(a.progress[0], a.default_cost);
        let (again, _) = evaluate(t.kind(), &a.params, training);
        assert!(
            (again - a.training_cost).abs() < 1e-12,
            "{}: {again} vs {} {:?}",
            a.name,
            a.training_cost,
            a.progress
        );
        // Seeded: the same search again gives the same gains.
        let b = tune(t, training, 5, 9);
        assert_eq!(format!("{:?}", a.params), format!("{:?}", b.params));
    }
}
