//! Runs the random haul-road study on a few maps and prints the aggregates (tuning aid).
use autoshovel_propel::study::{aggregate, run_map, StudyParams};
fn main() {
    let n: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(100);
    let p = StudyParams { maps: n, ..Default::default() };
    let rows: Vec<_> = (0..n).map(|i| run_map(&p, i)).collect();
    let a = aggregate(&rows, "improved-apf", |r| &r.improved);
    println!("success {:.1}% minima {} ratio {:.3} max {:.3} clr mean {:.3} min {:.3} head mean {:.3} max {:.3} esc {} t {:.2}", a.success_pct, a.local_minima, a.mean_length_ratio, a.max_length_ratio, a.mean_min_clearance_m, a.min_min_clearance_m, a.mean_final_heading_error_deg, a.max_final_heading_error_deg, a.maps_with_escapes, a.mean_plan_time_ms);
}
