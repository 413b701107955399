#[test]
#[ignore]
fn probe() {
    let s = autoshovel_shift::ShiftScenario::bench();
    let p = autoshovel_dig::MachineProfile::scale_model();
    let hours: f64 = std::env::var("HOURS").map(|h| h.parse().unwrap()).unwrap_or(0.5);
    let o = autoshovel_shift::ShiftOptions { hours: Some(hours), ..Default::default() };
    let run = autoshovel_shift::run_shift(&s, &p, &o, &mut |_| {}).unwrap();
    println!("{}", serde_json::to_string_pretty(&run.summary).unwrap());
    for e in run.events.iter().filter(|e| e.kind != "dig").take(40) { println!("{:8.0} {:>18} {} {}", e.t_s, e.kind, e.stand, e.message); }
    for p in run.passes.iter().take(12) { println!("pass {} swing {:+.0} toe {:.2} planned {:.1} exec {:.1} dug {:.1} fill {:.2} td {:.1} plan {:.0} ms perc {:.0} ms wall {:.0}", p.pass, p.swing_deg, p.toe_distance_m, p.planned_m3, p.executed_m3, p.dug_m3, p.fill_factor, p.dig_s, p.plan_ms, p.perceive_ms, p.wall_ms); }
}
