//! A short shift on the built-in bench: the mass balance closes (the pit's
//! own sum against the passes' and the trucks'), the machine digs more than
//! one stand and walks between them, the plans' volumes stay near what the
//! dipper took, the run is the same for the same seed, and faults end in
//! events or named errors, never a panic.

use autoshovel_rope_shovel_dig::MachineProfile;
use autoshovel_work_shift::{run_shift, ShiftError, ShiftOptions, ShiftRun, ShiftScenario};

fn shift(scenario: &ShiftScenario, cycles: usize) -> ShiftRun {
    let options = ShiftOptions {
        cycles: Some(cycles),
        ..ShiftOptions::default()
    };
    run_shift(
        scenario,
        &MachineProfile::scale_model(),
        &options,
        &mut |_| {},
    )
    .unwrap()
}

#[test]
fn a_short_shift_digs_two_stands_walks_and_balances_its_mass() {
    let scenario = ShiftScenario::bench();
    let run = shift(&scenario, 16);
    let s = &run.summary;
    assert_eq!(s.passes, 16);
    assert!(s.stands >= 2, "{} stands", s.stands);
    assert!(run.events.iter().any(|e| e.kind == "walk"), "no walk");
    // The pit's loss (its grid summed before and after) is what the trucks got.
    let density_t = 2.54;
    let lost = (run.before.volume_m3() - run.after.volume_m3()) * density_t;
    let dumped: f64 = run.passes.iter().map(|p| p.dug_t).sum();
    assert!(
        (lost - dumped).abs() <= 1e-9 * run.before.volume_m3() * density_t,
        "{lost} vs {dumped}"
    );
    assert!(s.mass_balance.closes);
    // Each pass took about a dipper-full, and about what its plan expected
    // on the scanned pile (perception is not exact: within a quarter).
    for p in &run.passes {
        assert!(
            (0.4..2.0).contains(&p.fill_factor),
            "pass {}: fill {}",
            p.pass,
            p.fill_factor
        );
    }
    let planned: f64 = run.passes.iter().map(|p| p.planned_m3).sum();
    let dug: f64 = run.passes.iter().map(|p| p.dug_m3).sum();
    assert!(
        (dug / planned - 1.0).abs() < 0.25,
        "dug {dug} against planned {planned}"
    );
    // Every stage of every cycle took time; the shift's clock adds them up
    // with the walks.
    let cycles: f64 = run
        .passes
        .iter()
        .map(|p| p.dig_s + p.swing_s + p.dump_s + p.return_s + p.wait_s)
        .sum();
    let walking: f64 = run.walks.iter().map(|w| w.time_s).sum();
    let rescans = 2.0
        * run
            .events
            .iter()
            .filter(|e| e.kind == "perceive-failed")
            .count() as f64;
    // Looking round before a walk: the upper works swing half round and back.
    let m = &scenario.machine;
    let drive = autoshovel_work_shift::cycle::SwingDrive {
        speed_rad_s: m.swing_speed_deg_s.to_radians(),
        accel_rad_s2: m.swing_accel_deg_s2.to_radians(),
        inertia_kg_m2: m.upper_inertia_kg_m2,
        radius_m: m.dipper_radius_m,
    };
    let looks = run.events.iter().filter(|e| e.kind == "look-round").count();
    assert!(looks >= 1);
    let looking = looks as f64 * 2.0 * drive.time_s(std::f64::consts::PI);
    assert!((s.hours * 3600.0 - cycles - walking - rescans - looking).abs() < 1e-6);
    assert!(s.tonnes_per_hour > 0.0 && s.energy_kwh_per_t.total > 0.0);
}

#[test]
fn the_same_seed_gives_the_same_shift() {
    let scenario = ShiftScenario::bench();
    let (a, b) = (shift(&scenario, 3), shift(&scenario, 3));
    assert_eq!(a.passes.len(), 3);
    for (p, q) in a.passes.iter().zip(&b.passes) {
        assert_eq!(p.dug_m3.to_bits(), q.dug_m3.to_bits());
        assert_eq!(p.path, q.path);
    }
    assert_eq!(a.after, b.after);
}

#[test]
fn a_pile_out_of_reach_ends_the_shift_with_a_named_event() {
    // Move the pile 40 m further east: the machine sees a face far away,
    // can dig nothing from where it stands, walks to it and digs.
    let mut scenario = ShiftScenario::bench();
    scenario.pile.toe_x_m = 60.0;
    let run = shift(&scenario, 2);
    assert!(run.events.iter().any(|e| e.kind == "no-feasible-dig"));
    assert!(run.events.iter().any(|e| e.kind == "walk"));
    // No pile at all: the scan has no face; the shift ends, saying why.
    let mut bare = ShiftScenario::bench();
    bare.pile.face_height_m = 0.1;
    bare.boulder.clear();
    bare.parked.clear();
    bare.stockpile.clear();
    let run = shift(&bare, 2);
    assert_eq!(run.summary.passes, 0);
    assert!(!run.summary.completed);
    let last = run.events.last().unwrap();
    assert_eq!(last.kind, "no-stand", "{:?}", run.events);
}

#[test]
fn a_machine_standing_in_the_pile_is_refused() {
    let mut scenario = ShiftScenario::bench();
    scenario.machine.start_m = [33.0, 60.0];
    let e = run_shift(
        &scenario,
        &MachineProfile::scale_model(),
        &ShiftOptions::default(),
        &mut |_| {},
    )
    .unwrap_err();
    assert!(matches!(e, ShiftError::BadStart { .. }), "{e}");
    assert!(e.to_string().contains("(33.0, 60.0)"), "{e}");
}
