//! The paper's §3 case, passed over and under (Figs. 5–6), beside the
//! paper's figures; asserts the done criteria: 0.9 m³ within 2 %, the side
//! the preimage rule gives, no sample inside the boulder's envelope, and no
//! joint moving faster than its speed limit between two samples.
//!
//! `cargo run -p autoshovel-excavator-dig --example paper_cases`

use autoshovel_excavator_dig::{excavate, AvoidSide, MachineProfile, Scenario, PAPER_CASES};

fn main() {
    let profile = MachineProfile::default();
    // (scenario, side, the paper's volume (m³), the paper's contact times (s))
    let cases = PAPER_CASES.map(|c| {
        (
            Scenario::builtin(c.scenario).expect("built-in"),
            c.side,
            c.volume_m3,
            c.contacts_text(),
        )
    });
    println!(
        "| case | V [m³] (paper) | contacts [s] (paper) | γ [°] | side | dig [s] | plan [ms] |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (scenario, side, paper_volume, paper_times) in cases {
        let ex = excavate(&scenario, &profile).expect("the paper's case plans");
        let times: Vec<String> = ex
            .contacts
            .iter()
            .map(|c| format!("{:.2}", c.t_s))
            .collect();
        let gammas: Vec<String> = ex
            .contacts
            .iter()
            .map(|c| format!("{:.0}", c.gamma_deg))
            .collect();
        println!(
            "| {} | {:.3} ({paper_volume}) | {} ({paper_times}) | {} | {} | {:.1} | {:.1} |",
            ex.scenario,
            ex.achieved_volume_m3,
            times.join(", "),
            gammas.join(", "),
            side,
            ex.duration_s,
            ex.plan_time_ms
        );
        assert!(
            ex.volume_error().abs() < 0.02,
            "volume {}",
            ex.achieved_volume_m3
        );
        assert_eq!(ex.avoid_direction, Some(side));
        let min = ex.min_envelope_distance_m.expect("one boulder");
        assert!(min >= -1e-9, "entered the envelope by {min} m");
        assert!(
            ex.max_joint_step_ratio <= 1.0,
            "joint jump {}",
            ex.max_joint_step_ratio
        );
        // Passed on that side: where the path crosses the boulder's centre line.
        let o = ex.obstacles[0];
        let c = &ex.contacts[0];
        let y = ex
            .samples
            .windows(2)
            .filter(|w| w[0].t_s > c.t_s)
            .find(|w| (w[0].tip_m[0] - o.center_m[0]) * (w[1].tip_m[0] - o.center_m[0]) <= 0.0)
            .map(|w| w[0].tip_m[1])
            .expect("the path passes the boulder");
        match side {
            AvoidSide::Over => assert!(y > o.center_m[1] + o.radius_m),
            AvoidSide::Under => assert!(y < o.center_m[1] - o.radius_m),
        }
    }
}
