//! The Lagrange torques along a planned dig segment, against the soil's
//! resistance: the motors' work ∫ τ·q̇ dt equals the change of kinetic plus
//! potential energy plus the work done against the resistance ∫ −F·v dt
//! (a conservation law the torques must obey however M, C and G were built).

use approx::assert_relative_eq;
use autoshovel_excavator_dig::dynamics::Dynamics;
use autoshovel_excavator_dig::level1::plan_level1;
use autoshovel_excavator_dig::soil::Soil;
use autoshovel_excavator_dig::{MachineProfile, Scenario};

#[test]
fn motor_work_is_energy_change_plus_work_against_the_soil() {
    let profile = MachineProfile::default();
    let d = Dynamics::new(&profile);
    let paper = Scenario::paper_over();
    let plan = plan_level1(
        &paper.step_search(&d.machine, profile.bucket.width_m, &[]),
        &paper.level1_request(),
    )
    .unwrap();
    let soil = Soil {
        cutting_resistance_pa: 60_000.0,
        normal_ratio: 0.3,
        density_kg_m3: 1800.0,
        rock_friction: 0.0,
    };
    let load = 800.0; // kg, held constant so that the mechanical energy is defined
    for seg in plan.segments() {
        let total = seg.duration_s();
        let n = 4000;
        let h = total / n as f64;
        let power = |t: f64| {
            let s = seg.state(&d.machine, t);
            let f = soil.resistance(&paper.ground, s.tip, s.direction, 1.0);
            let tau = d.inverse_dynamics(&s.q, &s.qd, &s.qdd, load, f);
            (tau.dot(&s.qd), -f.dot(&s.tip_velocity))
        };
        let (mut motor, mut resist) = (0.0, 0.0);
        for k in 0..n {
            let t = k as f64 * h;
            let (a, b, c) = (power(t), power(t + 0.5 * h), power(t + h));
            motor += h / 6.0 * (a.0 + 4.0 * b.0 + c.0);
            resist += h / 6.0 * (a.1 + 4.0 * b.1 + c.1);
        }
        let (s0, s1) = (seg.state(&d.machine, 0.0), seg.state(&d.machine, total));
        let e0 = d.energy(&s0.q, &s0.qd, load);
        let e1 = d.energy(&s1.q, &s1.qd, load);
        let delta = e1.kinetic_j + e1.potential_j - e0.kinetic_j - e0.potential_j;
        assert!(resist > 5_000.0, "the soil resists: {resist} J");
        assert_relative_eq!(motor, delta + resist, max_relative = 1e-6);
    }
}
