#[test]
#[ignore]
fn probe() {
    let s = autoshovel_shift::ShiftScenario::bench();
    let p = autoshovel_dig::MachineProfile::scale_model();
    let hours: f64 = std::env::var("HOURS").map(|h| h.parse().unwrap()).unwrap_or(0.5);
    let o = autoshovel_shift::ShiftOptions { hours: Some(hours), ..Default::default() };
    let run = autoshovel_shift::run_shift(&s, &p, &o, &mut |_| {}).unwrap();
    println!("{}", serde_json::to_string_pretty(&run.summary).unwrap());
    let ev: Vec<_> = run.events.iter().filter(|e| !matches!(e.kind, "dig" | "truck-exchange")).collect(); for e in ev.iter().rev().take(25).rev() { println!("{:8.0} {:>18} {} {}", e.t_s, e.kind, e.stand, e.message); }
    for st in &run.stands { println!("stand {} ({:.1},{:.1}) t {:.0} passes {} dug {:.0} t: {}", st.stand, st.x_m, st.y_m, st.t_arrive_s, st.passes, st.dug_t, &st.left_because[..st.left_because.len().min(120)]); }
    for y in [24.0, 52.0] { let row: Vec<String> = (0..30).map(|i| format!("{:.1}", run.after.height(26.0 + i as f64 * 0.5, y))).collect(); println!("after y={y}: {}", row.join(" ")); }
    for p in run.passes.iter().take(6) { println!("pass {} path {:?}", p.pass, p.path.iter().step_by(20).map(|q| [(q[0]*10.0).round()/10.0, (q[1]*10.0).round()/10.0, (q[2]*10.0).round()/10.0]).collect::<Vec<_>>()); }
    for p in run.passes.iter().take(0) { println!("pass {} swing {:+.0} toe {:.2} planned {:.1} exec {:.1} dug {:.1} fill {:.2} td {:.1} plan {:.0} ms perc {:.0} ms wall {:.0}", p.pass, p.swing_deg, p.toe_distance_m, p.planned_m3, p.executed_m3, p.dug_m3, p.fill_factor, p.dig_s, p.plan_ms, p.perceive_ms, p.wall_ms); }
}

#[test]
#[ignore]
fn profile_bias() {
    use autoshovel_shift::machine::*;
    use autoshovel_shift::*;
    use autoshovel_surface::perceive::{perceive, PerceptionParams};
    let s = ShiftScenario::bench();
    let world = World::new(&s);
    let pose = autoshovel_core::Pose2::new(24.0, 24.0, 0.0);
    let lidar = Lidar::on_machine(12.0, 30_000);
    let scan = world.scan(pose, &lidar, 5);
    let got = perceive(&scan, &PerceptionParams::default()).unwrap();
    let seen = autoshovel_surface::level(&scan, got.roll_rad, got.pitch_rad);
    let mut model = PileModel::new(s.world.min_m, s.world.max_m, 0.5);
    model.update(&seen, &got.cloud, got.floor_height_m, pose);
    println!("roll {} pitch {} floor {}", got.roll_rad.to_degrees(), got.pitch_rad.to_degrees(), got.floor_height_m);
    for a in [0.0f64, 20.0] {
        let (o, _) = dig_options(&model, pose, &[a.to_radians()], 3.6, 15.0, 120.0);
        let o = &o[0];
        println!("angle {a} toe_s {:.2}", o.toe_s_m);
        for k in 0..16 {
            let x = k as f64 * 0.5 - 1.0;
            let along = o.toe_s_m + x;
            let (c, sn) = (o.heading.cos(), o.heading.sin());
            let t = world.height(24.0 + along * c, 24.0 + along * sn);
            println!("  x {x:5.1} model {:.3} true {:.3}", o.surface.height(x), t);
        }
    }
}
