//! Plans every built-in scenario with the classic and the improved field and
//! prints the measures; asserts what the issue asks of the improved field:
//! success, final heading error ≤ 2° and positive footprint clearance.

use autoshovel_walk_planner::{plan_path, scenario::BUILTINS, FieldKind, PlanOptions, Scenario};

fn main() {
    for (name, _) in BUILTINS {
        let scenario = Scenario::builtin(name).expect("built-in");
        for field in [FieldKind::Classic, FieldKind::Improved] {
            match plan_path(&scenario, &PlanOptions::new(field)) {
                Ok(plan) => {
                    let m = &plan.metrics;
                    println!(
                        "{name:18} {:13} ok   length {:6.2} m  clearance {:5.2} m  heading error {:6.2} deg  start {:5.2} deg  cusp {:5.2}  max curvature {:5.3} 1/m  escapes {}  {:6.3} ms",
                        field.name(),
                        m.length_m,
                        m.min_clearance_m,
                        m.final_heading_error_deg,
                        m.start_heading_error_deg,
                        m.cusp_heading_error_deg,
                        m.max_curvature_per_m,
                        m.escapes,
                        m.plan_time_ms
                    );
                    if field == FieldKind::Improved {
                        assert!(
                            m.final_heading_error_deg <= 2.0,
                            "{name}: heading error {}",
                            m.final_heading_error_deg
                        );
                        assert!(
                            m.min_clearance_m > 0.0,
                            "{name}: clearance {}",
                            m.min_clearance_m
                        );
                    }
                }
                Err(e) => {
                    println!("{name:18} {:13} FAIL {e}", field.name());
                    assert!(
                        field == FieldKind::Classic,
                        "the improved planner failed on {name}: {e}"
                    );
                }
            }
        }
    }
}
