use autoshovel_track::scenario::resolve;
use autoshovel_track::*;
use rand::{Rng, SeedableRng};
fn main() {
    let base: Vec<_> = ["fig9a", "fig9b", "straight", "curve", "v-shape"]
        .iter()
        .map(|n| resolve(n, None, 1).unwrap())
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut best = Vec::new();
    for it in 0..400 {
        let j =
            |x: f64, r: f64, rng: &mut rand_chacha::ChaCha8Rng| x * (1.0 + rng.gen_range(-r..r));
        let p = FuzzyParams {
            alpha: j(0.53, 0.4, &mut rng),
            k1: j(3.84, 0.4, &mut rng),
            k2: j(18.7, 0.5, &mut rng),
            k3: j(0.95, 0.4, &mut rng),
        };
        let pm = j(0.26, 0.5, &mut rng);
        let pg = j(0.75, 0.5, &mut rng);
        let mut cost = 0.0;
        let mut line = format!(
            "{it} a {:.2} k1 {:.2} k2 {:.2} k3 {:.2} L {:.2} g {:.2} |",
            p.alpha, p.k1, p.k2, p.k3, pm, pg
        );
        for s in &base {
            let mut setup = s.setup.clone();
            setup.sim.preview_m = pm;
            setup.sim.preview_gain_s = pg;
            let m = simulate(&setup, &mut FuzzyTracker::new(p)).metrics;
            if s.name.starts_with("fig9") {
                cost += (m.reached_distance_m - 5.0).max(0.0)
                    + 20.0 * m.max_centroid_dev_m
                    + 0.2 * m.settled_1cm_distance_m.min(50.0);
                if !m.reached_distance_m.is_finite() || !m.settled_1cm_distance_m.is_finite() {
                    cost += 100.0;
                }
            } else {
                cost += 30.0 * (m.max_centroid_dev_m - 0.04).max(0.0)
                    + 30.0 * m.mean_centroid_dev_m
                    + 5.0 * (m.final_heading_error_deg.abs() - 1.0).max(0.0);
                if !m.max_centroid_dev_m.is_finite() {
                    cost += 100.0;
                }
            }
            if !m.completed {
                cost += 100.0;
            }
            line += &format!(
                " re {:.2} s {:.2} max {:.3} mean {:.3} h {:.2} |",
                m.reached_distance_m,
                m.settled_1cm_distance_m,
                m.max_centroid_dev_m,
                m.mean_centroid_dev_m,
                m.final_heading_error_deg
            );
        }
        best.push((cost, line));
    }
    best.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (c, l) in best.iter().take(8) {
        println!("{c:.2} {l}");
    }
}
