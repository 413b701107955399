use autoshovel_core::{Pose2, Vec2};
use autoshovel_propel::Direction;
use autoshovel_track::*;
fn main() {
    let leg = RefLeg::new(
        Direction::Forward,
        vec![Vec2::new(0.0, 0.0), Vec2::new(30.0, 30.0)],
        None,
    )
    .unwrap();
    for (name, start, v) in [
        (
            "fig9a",
            Pose2::new(2.0, -2.0, std::f64::consts::FRAC_PI_4),
            2.0,
        ),
        (
            "fig9b",
            Pose2::new(0.0, 5.0, std::f64::consts::FRAC_PI_4),
            1.0,
        ),
    ] {
        let setup = Setup {
            legs: vec![leg.clone()],
            start,
            crawler: CrawlerParams::default(),
            slip: SlipParams::none(),
            rtk: RtkParams::ideal(),
            sim: SimParams {
                speed_mps: v,
                ..Default::default()
            },
        };
        let mut ctrls: Vec<Box<dyn Controller>> = vec![
            Box::new(Pid::new(PidParams::default())),
            Box::new(PurePursuit {
                params: PurePursuitParams::default(),
            }),
        ];
        for c in ctrls.iter_mut() {
            let t = std::time::Instant::now();
            let r = simulate(&setup, c.as_mut());
            let m = r.metrics;
            println!("{name} {:12} conv {:.2} m  max {:.4} mean {:.4} overall max {:.3} fpe {:.3} fhe {:.2} done {} t {:.1}s wall {:.2} ms events {}", c.name(), m.convergence_distance_m, m.max_centroid_dev_m, m.mean_centroid_dev_m, m.max_centroid_dev_overall_m, m.final_position_error_m, m.final_heading_error_deg, m.completed, m.duration_s, t.elapsed().as_secs_f64()*1e3, r.events.len());
        }
    }
}
