//! Plan the four piles of the rope-shovel paper's Tables 4–5 and print our
//! plans beside the paper's; asserts that every plan is feasible, fills the
//! dipper 90–110 % in 9–15 s and digs within 10 % of the paper's mass.
//!
//! `cargo run --release -p autoshovel-dig --example table5`

use autoshovel_dig::{plan_dig, DigModel, DigSurface, MachineProfile};
use autoshovel_optim::GwoParams;
use autoshovel_surface::PileShape;

fn main() {
    // Table 5: f, f1 [J/kg], f2 [s/kg], m_dig [kg], fill [%].
    let paper = [
        (13.76, 17.19, 5.771, 2.053, 99.72),
        (13.83, 17.22, 5.925, 1.991, 96.71),
        (13.87, 17.51, 5.367, 2.156, 104.7),
        (12.57, 15.55, 5.625, 2.045, 99.29),
    ];
    let profile = MachineProfile::scale_model();
    println!("| pile | f (paper) | f1 J/kg (paper) | m_dig kg (paper) | fill % (paper) | t_d s |");
    println!("|---|---|---|---|---|---|");
    for (shape, (f, f1, _f2, m, fill)) in PileShape::ALL.into_iter().zip(paper) {
        let surface = DigSurface::from_shape(shape, profile.dipper.width_m);
        let model = DigModel::new(&profile, surface).expect("the scale model reaches the pile");
        let gwo = GwoParams {
            seed: 1,
            ..GwoParams::default()
        };
        let plan = plan_dig(&model, &gwo, &[]).expect("a feasible plan");
        let o = &plan.outcome;
        println!(
            "| {} | {:.2} ({f}) | {:.2} ({f1}) | {:.3} ({m}) | {:.1} ({fill}) | {:.2} |",
            shape.name(),
            o.f,
            o.f1_j_per_kg,
            o.m_dig_kg,
            100.0 * o.fill_factor,
            o.decision.td_s
        );
        assert!(o.feasible());
        assert!((0.9..=1.1).contains(&o.fill_factor));
        assert!((9.0..=15.0).contains(&o.decision.td_s));
        assert!((o.m_dig_kg / m - 1.0).abs() <= 0.10);
    }
}
