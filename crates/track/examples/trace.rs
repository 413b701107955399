use autoshovel_track::scenario::resolve;
use autoshovel_track::*;
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let s = resolve(&a[0], None, 1).unwrap();
    let mut c: Box<dyn Controller> = match a[1].as_str() {
        "pid" => Box::new(Pid::new(PidParams::default())),
        "pp" => Box::new(PurePursuit {
            params: Default::default(),
        }),
        _ => Box::new(FuzzyTracker::new(FuzzyParams::default())),
    };
    let r = simulate(&s.setup, c.as_mut());
    for (i, x) in r.samples.iter().enumerate() {
        if i % 5 == 0 && i < 400 {
            println!("t {:5.1} x {:6.2} y {:6.2} th {:6.1} dev {:7.3} d {:7.3} d0 {:7.3} v {:4.2} steer {:7.0} L {:6.0} R {:6.0}", x.t_s, x.truth.x, x.truth.y, x.truth.theta.to_degrees(), x.centroid_dev_m, x.d_m, x.d0_m, x.speed_ref_mps, x.steer_rpm, x.command.left_rpm, x.command.right_rpm);
        }
    }
    println!("{:?}", r.metrics);
}
