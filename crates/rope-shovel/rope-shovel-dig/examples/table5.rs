//! Plan the four piles of the rope-shovel paper's Tables 4–5 (rebuilt from
//! those tables, `paper_pile`) and print our plans beside the paper's; asserts that every plan is feasible, fills the
//! dipper 90–110 % in 9–15 s and digs within 10 % of the paper's mass.
//!
//! `cargo run --release -p autoshovel-rope-shovel-dig --example table5`

use autoshovel_optim::GwoParams;
use autoshovel_rope_shovel_dig::{
    paper_pile, plan_dig, search_preset, DigModel, DigSearch, MachineProfile, PAPER_TABLES_4_5,
};

fn main() {
    let profile = MachineProfile::scale_model();
    println!("| pile | f (paper) | f1 J/kg (paper) | m_dig kg (paper) | fill % (paper) | t_d s |");
    println!("|---|---|---|---|---|---|");
    for row in &PAPER_TABLES_4_5 {
        let (shape, f, f1, m, fill) = (
            row.shape,
            row.f,
            row.f1_j_per_kg,
            row.m_dig_kg,
            row.fill_pct,
        );
        let surface = paper_pile(&profile, shape)
            .expect("Table 4's decision fills the dipper on a pile 2-60 cm high")
            .surface(profile.dipper.width_m);
        let model = DigModel::new(&profile, surface).expect("the scale model reaches the pile");
        let preset = search_preset();
        let gwo = DigSearch {
            gwo: GwoParams {
                seed: 1,
                ..preset.gwo
            },
            ..preset
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
