//! Bad input ends in a clear, structured error — never in a path through a boulder.

use autoshovel_excavator_dig::obstacle::Envelope;
use autoshovel_excavator_dig::TomlFile as _;
use autoshovel_excavator_dig::{
    excavate, AvoidSide, ExcavateError, IkError, Joint, MachineProfile, Scenario,
};

fn plan(s: &Scenario) -> ExcavateError {
    excavate(s, &MachineProfile::default()).expect_err("this scenario must fail")
}

#[test]
fn a_start_out_of_reach_names_the_reach() {
    let mut s = Scenario::paper_over();
    s.dig.start_x_m = 9.5;
    let e = plan(&s);
    assert!(
        matches!(
            e,
            ExcavateError::StartOutOfReach {
                cause: IkError::OutOfReach { .. },
                ..
            }
        ),
        "{e:?}"
    );
    let msg = e.to_string();
    assert!(
        msg.contains("(9.500, 0.000)") && msg.contains("out of reach"),
        "{msg}"
    );
}

#[test]
fn a_start_beyond_a_joint_limit_names_the_joint() {
    let mut s = Scenario::paper_over();
    s.dig.start_x_m = 7.4;
    let e = plan(&s);
    assert!(
        matches!(
            e,
            ExcavateError::StartOutOfReach {
                cause: IkError::JointOutOfLimit {
                    joint: Joint::Stick,
                    ..
                },
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("stick (θ2)"), "{e}");
}

#[test]
fn a_target_the_reachable_ground_cannot_hold_is_refused() {
    let mut s = Scenario::paper_over();
    s.dig.target_volume_m3 = 12.0;
    let e = plan(&s);
    match &e {
        ExcavateError::TargetVolumeTooLarge {
            needed_m3,
            reachable_m3,
            ..
        } => {
            assert_eq!(*needed_m3, 6.0);
            assert!(*reachable_m3 > 0.5 && *reachable_m3 < 3.0, "{reachable_m3}");
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().contains("the first half"), "{e}");
}

#[test]
fn an_obstacle_enclosing_the_start_is_refused() {
    let mut s = Scenario::paper_over();
    s.obstacles.push(Envelope {
        center_m: [7.1, -0.1],
        radius_m: 0.3,
    });
    let e = plan(&s);
    assert!(
        matches!(e, ExcavateError::ObstacleEnclosesStart { index: 1, .. }),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .contains("encloses the dig start (7.000, 0.000)"),
        "{e}"
    );
}

#[test]
fn a_boulder_the_joint_limits_do_not_let_the_bucket_pass_is_named() {
    // Met while descending on its lower part, near the far end of the reach,
    // by a planner that assumes boulders of 0.45 m radius: passing under the
    // envelope it assumes needs the stick straighter than its limit.
    let mut s = Scenario::paper_under();
    s.obstacles[0].center_m = [6.6, -0.50];
    s.planner.boulder_radius_m = Some(0.45);
    let e = plan(&s);
    match &e {
        ExcavateError::ObstacleImpassable {
            index, side, why, ..
        } => {
            assert_eq!((*index, *side), (0, AvoidSide::Under));
            assert!(why.contains("stick (θ2)"), "{why}");
        }
        other => panic!("{other:?}"),
    }
    assert!(
        e.to_string().starts_with("cannot pass obstacle 0 under"),
        "{e}"
    );
}

#[test]
fn soil_beyond_the_machines_force_is_refused() {
    let mut s = Scenario::paper_over();
    s.obstacles.clear();
    s.soil.cutting_resistance_pa = 400_000.0;
    let e = plan(&s);
    match &e {
        ExcavateError::SoilTooHard { force_n, max_n, .. } => assert!(force_n > max_n),
        other => panic!("{other:?}"),
    }
    assert!(
        e.to_string()
            .contains("more than the machine's digging force 100000 N"),
        "{e}"
    );
}

#[test]
fn unknown_names_missing_files_and_bad_files_are_named() {
    let e = Scenario::from_name_or_file("paper-sideways").unwrap_err();
    assert!(matches!(e, ExcavateError::UnknownScenario { .. }));
    assert!(e.to_string().contains("paper-over, paper-under"), "{e}");
    let e = Scenario::from_name_or_file("/nonexistent/dig.toml").unwrap_err();
    assert!(
        matches!(
            e,
            ExcavateError::Config(autoshovel_core::config::ConfigError::Io { .. })
        ),
        "{e:?}"
    );
    let text =
        Scenario::builtin_toml("paper-over")
            .unwrap()
            .replacen("step_m = 0.05", "step_m = 0.0", 1);
    let e = Scenario::from_toml(&text, "dig.toml")
        .unwrap_err()
        .to_string();
    let line = text.lines().position(|l| l.starts_with("step_m")).unwrap() + 1;
    assert!(
        e.starts_with(&format!("dig.toml:{line}: [dig] step_m = 0")),
        "{e}"
    );
}

/// The built-in paper-over scenario with `key = value` set in its TOML.
fn edited(key: &str, value: &str) -> Result<Scenario, ExcavateError> {
    let text = Scenario::builtin_toml("paper-over").unwrap();
    let mut found = false;
    let edited: String = text
        .lines()
        .map(|l| {
            if l.starts_with(&format!("{key} =")) {
                found = true;
                format!("{key} = {value}\n")
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    assert!(found, "{key} is in the built-in");
    Scenario::from_toml(&edited, "edited.toml")
}

/// Settings that size work beyond the ceilings are refused before the
/// work, at the line of the setting at fault, with the estimate; the
/// estimates are the closed forms of the grid and the step search.
#[test]
fn settings_that_size_too_much_work_are_refused_with_the_estimate() {
    use autoshovel_excavator_dig::scenario::{MAX_GRID_POINTS, MAX_STEP_SEARCH_STRIPS};
    let line = |key: &str| {
        let text = Scenario::builtin_toml("paper-over").unwrap();
        1 + text
            .lines()
            .position(|l| l.starts_with(&format!("{key} =")))
            .unwrap()
    };
    // Grid round the 0.25 m boulder with 0.1 m clearance: side
    // 2·(0.35 + window)/step + 5 points.
    for (key, value, side) in [
        ("search_window_m", "1e6", 2.0 * (0.35 + 1e6) / 0.05 + 5.0),
        ("step_m", "1e-4", 2.0 * (0.35 + 1.0) / 1e-4 + 5.0),
    ] {
        let msg = edited(key, value).unwrap_err().to_string();
        assert!(side * side > MAX_GRID_POINTS);
        let expect = autoshovel_core::config::approx(side * side);
        assert!(
            msg.starts_with(&format!("edited.toml:{}:", line(key)))
                && msg.contains(key)
                && msg.contains("grid points")
                && msg.contains(&expect),
            "{msg} (expected about {expect})"
        );
    }
    // The step search: 7 m / step × trapezoids strips; without boulders
    // the grid does not apply and the step search is what breaks.
    let mut s = Scenario::paper_over();
    s.obstacles.clear();
    let text = toml::to_string(&s)
        .unwrap()
        .replace("step_m = 0.05", "step_m = 1e-6");
    let msg = Scenario::from_toml(&text, "s.toml")
        .unwrap_err()
        .to_string();
    const { assert!(7e6 * 100.0 > MAX_STEP_SEARCH_STRIPS) };
    assert!(
        msg.contains("[dig] step_m") && msg.contains("7.00e8") && msg.contains("volume strips"),
        "{msg}"
    );
    // Simulator steps: refused once the level-1 plan's duration is known,
    // before any step is taken.
    let s = edited("dt_s", "1e-9").unwrap();
    let e = plan(&s);
    assert!(
        matches!(
            e,
            ExcavateError::TooMuchWork {
                key: "[planner] dt_s",
                ..
            }
        ),
        "{e:?}"
    );
    let msg = e.to_string();
    assert!(
        msg.contains("the level-1 plan takes")
            && msg.contains("simulator steps")
            && msg.contains("TB"),
        "{msg}"
    );
}
