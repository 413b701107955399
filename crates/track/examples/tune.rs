use autoshovel_track::scenario::{resolve, Noise};
use autoshovel_track::*;
fn main() {
    let scen: Vec<_> = ["fig9a", "fig9b", "straight", "curve", "v-shape"]
        .iter()
        .map(|n| resolve(n, None, 1).unwrap())
        .collect();
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let grid: Vec<FuzzyParams> = if args.len() == 4 {
        vec![FuzzyParams {
            alpha: args[0],
            k1: args[1],
            k2: args[2],
            k3: args[3],
        }]
    } else {
        let mut g = vec![];
        for alpha in [0.5, 1.0] {
            for k1 in [0.5, 1.0, 2.0] {
                for k2 in [1.0, 3.0, 10.0] {
                    for k3 in [0.25, 0.5, 1.0] {
                        g.push(FuzzyParams { alpha, k1, k2, k3 });
                    }
                }
            }
        }
        g
    };
    for p in grid {
        let mut line = format!(
            "a {:.1} k1 {:.1} k2 {:>5.0} k3 {:.1} |",
            p.alpha, p.k1, p.k2, p.k3
        );
        for s in &scen {
            let mut c = FuzzyTracker::new(p);
            let r = simulate(&s.setup, &mut c);
            let m = r.metrics;
            let _ = Noise::Off;
            line += &format!(
                " {} re {:5.2} c {:5.2} s {:5.2} max {:.3} mean {:.3} h {:5.2} {}|",
                &s.name[..4.min(s.name.len())],
                m.reached_distance_m,
                m.convergence_distance_m,
                m.settled_1cm_distance_m,
                m.max_centroid_dev_m,
                m.mean_centroid_dev_m,
                m.final_heading_error_deg,
                if m.completed { "" } else { "X" }
            );
        }
        println!("{line}");
    }
}
