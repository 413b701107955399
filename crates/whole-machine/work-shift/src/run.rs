//! A shift: the loop of scan → perceive → plan dig → dig → swing → dump →
//! return, and the walk to the next stand when no feasible dig remains,
//! with the timeline, the mass balance and the figures of merit.
//!
//! Faults are handled as a machine would: each is a named event of the
//! timeline and leaves the machine in a safe state (at rest, track speeds
//! zero — the tracker's workstation zeroes them itself on any fault):
//!
//! | event | when | recovery |
//! |---|---|---|
//! | `perceive-failed` | the scan has no floor or no face perception accepts | scan again once; a second failure ends the stand |
//! | `no-feasible-dig` | no swing angle gives a plan meeting c1–c18 (each angle's reason kept) | the stand is done: look round, walk on |
//! | `look-round` | before every walk | the upper works swing the LiDAR round once; the ground about the machine enters the walking map |
//! | `stand-unreachable` | the walk planner finds no path to a stand | try the next stand |
//! | `walk-stalled` | the tracker does not bring the machine within 1.5 m of the stand | plan again from where it stopped, once; then the next stand |
//! | `no-stand` | no stand with material within reach remains | end of the shift |
//! | `overfill` | the dipper took more than c2 allows (the pile held more than the scan showed) | none: counted as a safety event |
//! | `over-rating` | the executed dig broke a force or power rating the plan met | none: counted |
//!
//! Times are simulated seconds; perception, planning and simulation wall
//! times are measured beside them.

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::Serialize;

use autoshovel_core::{Pose2, Vec2};
use autoshovel_rope_shovel_dig::{
    plan_dig, DigModel, DigSearch, DigSurface, MachineProfile, Similarity,
};
use autoshovel_terrain::perceive::perceive;
use autoshovel_walk_planner::{plan_path, Direction, FieldKind, PlanOptions, Scenario as Travel};
use autoshovel_walk_tracker::{
    simulate, ControllerKind, ControllerParams, CrawlerParams, RefLeg, RtkParams, Setup, SimParams,
    SlipParams,
};

use crate::cycle::{propel_energy_j, SwingDrive};
use crate::error::{Result, ShiftError};
use crate::grid::Cut;
use crate::machine::{
    dig_options, next_stands, v_midpoint, walking_map, PileModel, FOOTPRINT_MARGIN_M,
};
use crate::record::{
    CycleTimes, EnergyPerTonne, Event, FillStats, Frame, MassBalance, PassRecord, ShiftRun,
    ShiftSummary, StandRecord, WalkRecord,
};
use crate::scenario::ShiftScenario;
use crate::world::{Lidar, World};

/// How a shift is run (the scenario says what is simulated).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShiftOptions {
    /// Simulated hours (default: the scenario's).
    pub hours: Option<f64>,
    /// Stop after this many passes (default: none).
    pub cycles: Option<usize>,
    /// The dig search of every pass (seeded per pass from the scenario's seed).
    pub search: DigSearch,
    /// Most snapshots of the pit kept for the animation.
    pub frames: usize,
    /// Share of each drive rating (c11–c14) the planner keeps in reserve:
    /// a plan sits on its limits, and the true pile differs from the
    /// scanned one.
    pub rating_margin: f64,
}

impl Default for ShiftOptions {
    /// The paper's GWO setting at a third of its evaluations, warm-started
    /// from the last pass, and a CMA-ES polish of 2000: about 0.1 s a plan
    /// on 2 cores.
    fn default() -> Self {
        let mut gwo = autoshovel_rope_shovel_dig::gwo_preset();
        gwo.population = 30;
        gwo.iterations = 50;
        Self {
            hours: None,
            cycles: None,
            search: DigSearch {
                gwo,
                polish_evaluations: 2000,
                polish_step: 0.05,
            },
            frames: 160,
            rating_margin: 0.1,
        }
    }
}

/// Greatest share of a walk's stop error the machine accepts as arrived (m).
const ARRIVED_M: f64 = 1.5;
/// Passes at one stand at most (a guard: the planner ends a stand long before).
const MAX_PASSES_PER_STAND: usize = 200;
/// Stands in a row without a pass after which the shift ends.
const MAX_BARREN_STANDS: usize = 12;
/// Cell of an animation frame (m).
const FRAME_CELL_M: f64 = 1.0;

/// Runs a shift of `scenario` with the dig planner's `model_profile` (the
/// 1:30 model, scaled by the scenario's λ).
pub fn run_shift(
    scenario: &ShiftScenario,
    model_profile: &MachineProfile,
    options: &ShiftOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<ShiftRun> {
    let wall = Instant::now();
    let m = &scenario.machine;
    let similarity = Similarity { lambda: m.lambda };
    let profile = similarity.machine(model_profile);
    let hours = options.hours.unwrap_or(scenario.shift.hours);
    if !(hours.is_finite() && hours > 0.0) {
        return Err(ShiftError::BadSetting {
            name: "hours",
            value: hours.to_string(),
            expected: "a finite number of hours > 0",
        });
    }
    let t_end = hours * 3600.0;
    let mut world = World::new(scenario);
    let before = world.clone();
    let mut pose = Pose2::new(m.start_m[0], m.start_m[1], m.heading_deg.to_radians());
    if !world.is_clear(
        pose.x,
        pose.y,
        m.footprint_radius_m,
        crate::machine::OBSTACLE_HEIGHT_M,
    ) {
        return Err(ShiftError::BadStart {
            x_m: pose.x,
            y_m: pose.y,
            why: format!(
                "its footprint ({:.1} m radius) is not on bare floor inside the world",
                m.footprint_radius_m
            ),
        });
    }
    let seed = scenario.shift.seed;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let rtk_noise = Normal::new(0.0, 0.01).expect("σ > 0");
    let measured = |truth: Pose2, rng: &mut ChaCha8Rng| {
        Pose2::new(
            truth.x + rtk_noise.sample(rng),
            truth.y + rtk_noise.sample(rng),
            truth.theta + 0.001 * rtk_noise.sample(rng) * 100.0,
        )
    };
    let mut pose_seen = measured(pose, &mut rng);
    let lidar = Lidar::on_machine(m.sensor_height_m, scenario.shift.scan_points);
    let perception = crate::machine::perception();
    let mut model = PileModel::new(
        scenario.world.min_m,
        scenario.world.max_m,
        scenario.world.cell_m,
    );
    let swing = SwingDrive {
        speed_rad_s: m.swing_speed_deg_s.to_radians(),
        accel_rad_s2: m.swing_accel_deg_s2.to_radians(),
        inertia_kg_m2: m.upper_inertia_kg_m2,
        radius_m: m.dipper_radius_m,
    };
    let angles: Vec<f64> = scenario
        .shift
        .dig_angles_deg
        .iter()
        .map(|a| a.to_radians())
        .collect();
    let width = profile.dipper.width_m;
    let reach = profile.search.gx_m[1];
    let deepest = similarity.length(autoshovel_rope_shovel_dig::dig_surface::DEEPEST_CUT_M);
    let density_t = profile.material.density_kg_m3 / 1000.0;
    let capacity = profile.dipper.capacity_m3;
    let nominal_toe = profile
        .geometry
        .toe_distance_m
        .unwrap_or(similarity.length(0.0875));
    let stand_off = m.saddle_ahead_m + nominal_toe;
    let truck_swing = scenario.truck.swing_deg.to_radians();

    let frame_size = [0, 1].map(|a| {
        ((scenario.world.max_m[a] - scenario.world.min_m[a]) / FRAME_CELL_M).ceil() as usize
    });
    let snapshot = |world: &World, t: f64, pose: Pose2| Frame {
        t_s: t,
        pose,
        z: (0..frame_size[0] * frame_size[1])
            .map(|k| {
                let (i, j) = (k % frame_size[0], k / frame_size[0]);
                world.height(
                    scenario.world.min_m[0] + (i as f64 + 0.5) * FRAME_CELL_M,
                    scenario.world.min_m[1] + (j as f64 + 0.5) * FRAME_CELL_M,
                ) as f32
            })
            .collect(),
    };
    let mut frames = vec![snapshot(&world, 0.0, pose)];

    let mut t = 0.0;
    let mut events: Vec<Event> = Vec::new();
    let mut passes: Vec<PassRecord> = Vec::new();
    let mut walks: Vec<WalkRecord> = Vec::new();
    let mut stands = vec![StandRecord {
        stand: 1,
        x_m: pose.x,
        y_m: pose.y,
        heading_deg: pose.theta.to_degrees(),
        t_arrive_s: 0.0,
        passes: 0,
        dug_t: 0.0,
        left_because: String::new(),
        before: world.z.clone(),
        after: Vec::new(),
    }];
    let mut warm: Vec<Vec<f64>> = Vec::new();
    let (mut truck, mut truck_load_t, mut trucks_t) = (1usize, 0.0f64, 0.0f64);
    let mut failed_scans = 0;
    let mut exhausted: Vec<(f64, String)> = Vec::new();
    // The LiDAR's mounting tilt and the floor's height as perception last
    // found them on the face.
    let mut mounting: Option<(f64, f64, f64)> = None;
    let mut completed = false;
    let mut scans = 0u64;
    let mut propel_j = 0.0;
    let note =
        |events: &mut Vec<Event>, t: f64, kind: &'static str, stand: usize, message: String| {
            events.push(Event {
                t_s: t,
                kind,
                stand,
                message,
            })
        };

    'shift: loop {
        let stand_no = stands.len();
        if t >= t_end || options.cycles.is_some_and(|c| passes.len() >= c) {
            completed = true;
            note(&mut events, t, "end", stand_no, "end of the shift".into());
            break;
        }
        progress((t / t_end).min(1.0));
        // Scan and perceive.
        let pass_wall = Instant::now();
        scans += 1;
        let scan = world.scan(
            pose,
            &lidar,
            seed.wrapping_mul(1_000_003).wrapping_add(scans),
        );
        let t_perceive = Instant::now();
        let perceived = perceive(&scan, &perception);
        let perceive_ms = t_perceive.elapsed().as_secs_f64() * 1e3;
        let mut leave_because = None;
        match perceived {
            Ok(got) => {
                failed_scans = 0;
                let seen = autoshovel_terrain::level(&scan, got.roll_rad, got.pitch_rad);
                model.update(&seen, &got.cloud, got.floor_height_m, pose_seen);
                mounting = Some((got.roll_rad, got.pitch_rad, got.floor_height_m));
            }
            Err(e) => {
                failed_scans += 1;
                note(&mut events, t, "perceive-failed", stand_no, e.to_string());
                if failed_scans < 2 {
                    t += 2.0;
                    continue;
                }
                leave_because = Some(format!("two scans without a face ({e})"));
            }
        }
        // Plan the dig: the swing angles with most material first.
        let t_plan = Instant::now();
        let mut chosen = None;
        let mut reasons: Vec<String> = Vec::new();
        if leave_because.is_none() {
            let (options_here, refused) =
                dig_options(&model, pose_seen, &angles, width, reach, deepest);
            for (a, why) in refused {
                reasons.push(format!("{:+.0}°: {why}", a.to_degrees()));
            }
            for option in options_here {
                let label = format!("{:+.0}°", option.swing.to_degrees());
                // An angle the planner could not dig at this stand stays
                // undiggable while the machine stands here (nothing but
                // the dipper changes the pile, and it only takes away).
                if let Some(why) = exhausted
                    .iter()
                    .find(|(a, _)| *a == option.swing)
                    .map(|(_, w)| w)
                {
                    reasons.push(format!("{label}: {why}"));
                    continue;
                }
                if option.material_m3 < profile.limits.fill_min * capacity {
                    reasons.push(format!(
                        "{label}: {:.1} m³ within reach",
                        option.material_m3
                    ));
                    continue;
                }
                let mut p = profile.clone();
                let keep = 1.0 - options.rating_margin;
                p.limits.hoist_force_max_n *= keep;
                p.limits.crowd_force_max_n *= keep;
                p.limits.hoist_power_max_w *= keep;
                p.limits.crowd_power_max_w *= keep;
                let toe_distance = option.toe_s_m - m.saddle_ahead_m;
                p.geometry.toe_distance_m = Some(toe_distance);
                let dig = match DigModel::new(&p, option.surface.clone()) {
                    Ok(dig) => dig,
                    Err(e) => {
                        reasons.push(format!("{label}: {e}"));
                        continue;
                    }
                };
                let mut search = options.search;
                search.gwo.seed = seed.wrapping_add(passes.len() as u64);
                match plan_dig(&dig, &search, &warm) {
                    Ok(plan) => {
                        chosen = Some((option, p, dig, plan, toe_distance));
                        break;
                    }
                    Err(e) => {
                        reasons.push(format!("{label}: {e}"));
                        exhausted.push((option.swing, e.to_string()));
                    }
                }
            }
            if chosen.is_none() || stands[stand_no - 1].passes >= MAX_PASSES_PER_STAND {
                leave_because = Some(format!("no feasible dig: {}", reasons.join("; ")));
            }
        }
        let plan_ms = t_plan.elapsed().as_secs_f64() * 1e3;
        if let (None, Some((option, p, dig, plan, toe_distance))) = (&leave_because, chosen) {
            // Dig: the planned path, along the line the machine swung to
            // (its swing angle on its true heading, from its true axis).
            let d = plan.outcome.decision;
            let path: Vec<[f64; 2]> = plan.samples.iter().map(|s| s.tip_m).collect();
            let cut = Cut {
                origin: [pose.x, pose.y],
                heading: pose.theta + option.swing,
                toe_s_m: option.toe_s_m,
                half_width_m: 0.5 * width,
                path,
            };
            // The same path on the true pile ([RS eq. 28]), for the balance
            // and the drives' energy as executed.
            let (x0, x1) = option.surface.x_range();
            let truth = DigSurface::from_fn(
                |x, w| {
                    let [wx, wy] = cut.world(x, w);
                    world.height(wx, wy)
                },
                width,
                x0,
                x1,
                "the pit along the dig line",
            )
            .with_deepest_cut(deepest);
            let mut rated = p.clone();
            rated.limits = profile.limits.clone();
            let executed = DigModel::new(&rated, truth)
                .ok()
                .map(|true_dig| true_dig.evaluate(&d));
            let dug_m3 = world.cut(&cut);
            // The machine's own account of the same dig, where it believes
            // it stands.
            model.dug(&Cut {
                origin: [pose_seen.x, pose_seen.y],
                heading: pose_seen.theta + option.swing,
                ..cut.clone()
            });
            let dug_t = dug_m3 * density_t;
            let path_world: Vec<[f64; 3]> = cut
                .path
                .iter()
                .map(|&[x, y]| {
                    let [wx, wy] = cut.world(x, 0.0);
                    [wx, wy, y]
                })
                .collect();
            let fill = dug_m3 / capacity;
            if fill > profile.limits.fill_max {
                note(
                    &mut events,
                    t + d.td_s,
                    "overfill",
                    stand_no,
                    format!(
                        "pass {}: the dipper took {:.1} m³ ({:.0} % of its capacity; c2 allows {:.0} %): the pile held more than the scan showed",
                        passes.len() + 1,
                        dug_m3,
                        100.0 * fill,
                        100.0 * profile.limits.fill_max
                    ),
                );
            }
            let (hoist_j, crowd_j, executed_m3) = match &executed {
                Some(e) => {
                    let broken: Vec<String> = e
                        .violated()
                        .into_iter()
                        .filter(|v| {
                            ["c11", "c12", "c13", "c14"]
                                .iter()
                                .any(|c| v.starts_with(c))
                        })
                        .collect();
                    if !broken.is_empty() {
                        note(
                            &mut events,
                            t + d.td_s,
                            "over-rating",
                            stand_no,
                            format!(
                                "pass {}: on the true pile {}",
                                passes.len() + 1,
                                broken.join(", ")
                            ),
                        );
                    }
                    (e.hoist_energy_j, e.crowd_energy_j, e.volume_m3)
                }
                None => (
                    plan.outcome.hoist_energy_j,
                    plan.outcome.crowd_energy_j,
                    f64::NAN,
                ),
            };
            // Swing to the truck, dump, return to the face.
            let to_truck = (truck_swing - option.swing).abs();
            let swing_s = swing.time_s(to_truck);
            let return_s = swing.time_s(to_truck);
            let swing_j = swing.energy_j(to_truck, dug_t * 1000.0) + swing.energy_j(to_truck, 0.0);
            truck_load_t += dug_t;
            trucks_t += dug_t;
            let mut wait_s = 0.0;
            let this_truck = truck;
            if truck_load_t >= scenario.truck.capacity_t {
                // The next truck is spotted while the dipper returns and digs.
                wait_s = (scenario.truck.exchange_s - return_s - d.td_s).max(0.0);
                note(
                    &mut events,
                    t + d.td_s + swing_s + m.dump_s,
                    "truck-exchange",
                    stand_no,
                    format!("truck {truck} leaves with {truck_load_t:.1} t"),
                );
                truck += 1;
                truck_load_t = 0.0;
            }
            let record = PassRecord {
                pass: passes.len() + 1,
                stand: stand_no,
                t_start_s: t,
                swing_deg: option.swing.to_degrees(),
                toe_distance_m: toe_distance,
                dig_s: d.td_s,
                swing_s,
                dump_s: m.dump_s,
                return_s,
                wait_s,
                planned_m3: plan.outcome.volume_m3,
                executed_m3,
                dug_m3,
                dug_t,
                fill_factor: fill,
                hoist_j,
                crowd_j,
                swing_j,
                perceive_ms,
                plan_ms,
                wall_ms: pass_wall.elapsed().as_secs_f64() * 1e3,
                path: path_world,
                truck: this_truck,
            };
            note(
                &mut events,
                t,
                "dig",
                stand_no,
                format!(
                    "pass {}: {:+.0}°, {:.1} m³ ({:.0} % fill) in {:.1} s",
                    record.pass,
                    record.swing_deg,
                    dug_m3,
                    100.0 * fill,
                    d.td_s
                ),
            );
            t += d.td_s + swing_s + m.dump_s + return_s + wait_s;
            warm = vec![dig.vector(&d)];
            let stand = &mut stands[stand_no - 1];
            stand.passes += 1;
            stand.dug_t += dug_t;
            passes.push(record);
            pose_seen = measured(pose, &mut rng);
            let every = (t_end / 60.0 / options.frames.max(1) as f64).max(1.0);
            if frames.last().is_none_or(|f| t - f.t_s >= every * 60.0) {
                frames.push(snapshot(&world, t, pose));
            }
            continue;
        }
        // The stand is done: walk to the next.
        let why = leave_because.unwrap_or_default();
        note(&mut events, t, "no-feasible-dig", stand_no, why.clone());
        {
            let stand = &mut stands[stand_no - 1];
            stand.left_because = why;
            stand.after = world.z.clone();
        }
        // Before it walks the machine looks round: the upper works swing
        // the LiDAR to each side and behind (the ground there was never in
        // view while it dug), so the walking map holds what it could hit.
        if let Some((roll, pitch, floor_z)) = mounting {
            for quarter in 1..4 {
                let turn = f64::from(quarter) * std::f64::consts::FRAC_PI_2;
                scans += 1;
                let look = Pose2::new(pose.x, pose.y, pose.theta + turn);
                let scan = world.scan(
                    look,
                    &lidar,
                    seed.wrapping_mul(1_000_003).wrapping_add(scans),
                );
                let seen = autoshovel_terrain::level(&scan, roll, pitch);
                let believed = Pose2::new(pose_seen.x, pose_seen.y, pose_seen.theta + turn);
                model.update_raw(&seen, floor_z, believed, m.footprint_radius_m);
            }
            let turn = 2.0 * swing.time_s(std::f64::consts::PI);
            t += turn;
            note(
                &mut events,
                t,
                "look-round",
                stand_no,
                format!("the upper works swung round once to scan the ground about the machine ({turn:.0} s)"),
            );
        }
        let map = walking_map(&model);
        let (candidates, refused) = next_stands(
            &model,
            &map,
            pose_seen,
            m.heading_deg.to_radians(),
            &angles,
            width,
            reach,
            stand_off,
            scenario.shift.lateral_step_m,
            m.footprint_radius_m,
            3.0 * capacity,
        );
        // A stand already stood on is no new stand.
        let candidates: Vec<_> = candidates
            .into_iter()
            .filter(|c| {
                stands
                    .iter()
                    .all(|s| (s.x_m - c.pose.x).hypot(s.y_m - c.pose.y) > 0.75)
            })
            .collect();
        if candidates.is_empty() {
            note(
                &mut events,
                t,
                "no-stand",
                stand_no,
                format!(
                    "no stand with material within reach remains in the perceived pit ({})",
                    refused.join("; ")
                ),
            );
            break 'shift;
        }
        let barren = stands.iter().rev().take_while(|s| s.passes == 0).count();
        if barren >= MAX_BARREN_STANDS {
            note(
                &mut events,
                t,
                "no-stand",
                stand_no,
                format!("{barren} stands in a row without a feasible dig: the pile as scanned cannot be dug by this machine"),
            );
            break 'shift;
        }
        note(
            &mut events,
            t,
            "next-stand",
            stand_no,
            candidates
                .iter()
                .take(3)
                .map(|c| {
                    format!(
                        "({:.1}, {:.1}) {:+.0} m aside, {:.0} m³ within reach",
                        c.pose.x, c.pose.y, c.lateral_m, c.material_m3
                    )
                })
                .collect::<Vec<_>>()
                .join("; "),
        );
        // Standing closer to the face than a walk may start from (the new
        // scan showed it nearer than the last): back straight out first,
        // over ground the machine has just stood or walked on.
        let here = map.clearance(pose_seen.position(), m.footprint_radius_m);
        if here < FOOTPRINT_MARGIN_M {
            let back = FOOTPRINT_MARGIN_M + 1.0 - here;
            let (c, sn) = (pose_seen.theta.cos(), pose_seen.theta.sin());
            let to = Vec2::new(pose_seen.x - back * c, pose_seen.y - back * sn);
            if let Ok(leg) = RefLeg::new(
                Direction::Reverse,
                vec![pose_seen.position(), to],
                Some(pose_seen.theta),
            ) {
                let d = drive(
                    vec![leg],
                    pose,
                    m.walk_speed_mps,
                    seed.wrapping_add(7919 + walks.len() as u64),
                );
                let energy =
                    propel_energy_j(m.mass_t * 1000.0, m.rolling_resistance, d.travelled_m);
                propel_j += energy;
                t += d.time_s;
                note(
                    &mut events,
                    t,
                    "back-off",
                    stand_no,
                    format!(
                        "{:.1} m straight back from the face ({:.2} m clearance on the new scan)",
                        d.travelled_m, here
                    ),
                );
                walks.push(WalkRecord {
                    from_stand: stand_no,
                    to_stand: stand_no,
                    v_move: false,
                    planned_m: back,
                    travelled_m: d.travelled_m,
                    time_s: d.time_s,
                    energy_j: energy,
                    final_error_m: (d.end.position() - to).norm(),
                    max_deviation_m: d.run.metrics.max_centroid_dev_overall_m,
                    planned: vec![[pose_seen.x, pose_seen.y], [to.x, to.y]],
                    driven: d
                        .run
                        .samples
                        .iter()
                        .step_by(10)
                        .map(|s| [s.truth.x, s.truth.y])
                        .collect(),
                    driven_at: d
                        .run
                        .samples
                        .iter()
                        .step_by(10)
                        .map(|s| [t - d.time_s + s.t_s, s.truth.theta])
                        .collect(),
                });
                pose = d.end;
                pose_seen = d.run.samples.last().map_or(pose, |s| s.measured);
            }
        }
        let mut arrived = false;
        for candidate in candidates.iter().take(3) {
            let goal = candidate.pose;
            // Sideways: a V-shaped move; ahead or behind: straight.
            let v_move = candidate.lateral_m.abs() > 1.0;
            let ahead = (goal.x - pose_seen.x) * pose_seen.theta.cos()
                + (goal.y - pose_seen.y) * pose_seen.theta.sin();
            let mut attempt = 0;
            let mut start = pose_seen;
            while attempt < 2 {
                attempt += 1;
                // A V-move backs out 10-15 m (more for a longer move
                // sideways); where that midpoint is blocked, less.
                let full = (0.7 * candidate.lateral_m.abs()).clamp(10.0, 15.0);
                let backs: &[f64] = if v_move { &[1.0, 0.6, 0.35] } else { &[0.0] };
                let mut tried = Vec::new();
                let mut found = None;
                for &share in backs {
                    let travel = Travel {
                        name: format!("stand {} to {}", stand_no, stand_no + 1),
                        map: map.clone(),
                        footprint_radius_m: m.footprint_radius_m,
                        start,
                        midpoint: v_move.then(|| v_midpoint(start, goal, share * full)),
                        goal,
                        direction: if ahead >= 0.0 || v_move {
                            Direction::Forward
                        } else {
                            Direction::Reverse
                        },
                    };
                    match plan_path(&travel, &PlanOptions::new(FieldKind::Improved)) {
                        Ok(p) => {
                            found = Some((travel, p));
                            break;
                        }
                        Err(e) => tried.push(e.to_string()),
                    }
                }
                let Some((travel, planned)) = found else {
                    note(
                        &mut events,
                        t,
                        "stand-unreachable",
                        stand_no,
                        format!("({:.1}, {:.1}): {}", goal.x, goal.y, tried.join("; ")),
                    );
                    break;
                };
                let legs_spec = travel.legs();
                let mut legs = Vec::new();
                for (leg, (_, to, _)) in planned.path.legs.iter().zip(&legs_spec) {
                    let pts = leg.points.iter().map(|p| p.pose.position()).collect();
                    if let Ok(l) = RefLeg::new(leg.direction, pts, Some(to.theta)) {
                        legs.push(l);
                    }
                }
                if legs.len() != legs_spec.len() {
                    note(
                        &mut events,
                        t,
                        "stand-unreachable",
                        stand_no,
                        "a planned leg the tracker cannot follow".into(),
                    );
                    break;
                }
                let drive = drive(
                    legs,
                    pose,
                    m.walk_speed_mps,
                    seed.wrapping_add(walks.len() as u64),
                );
                let (run, end, time_s, travelled) =
                    (&drive.run, drive.end, drive.time_s, drive.travelled_m);
                let last = run.samples.last();
                let energy = propel_energy_j(m.mass_t * 1000.0, m.rolling_resistance, travelled);
                propel_j += energy;
                let error = (end.position() - goal.position()).norm();
                walks.push(WalkRecord {
                    from_stand: stand_no,
                    to_stand: stand_no + 1,
                    v_move,
                    planned_m: planned.metrics.length_m,
                    travelled_m: travelled,
                    time_s,
                    energy_j: energy,
                    final_error_m: error,
                    max_deviation_m: run.metrics.max_centroid_dev_overall_m,
                    planned: planned
                        .path
                        .legs
                        .iter()
                        .flat_map(|l| l.points.iter().map(|p| [p.pose.x, p.pose.y]))
                        .collect(),
                    driven: run
                        .samples
                        .iter()
                        .step_by(10)
                        .map(|s| [s.truth.x, s.truth.y])
                        .collect(),
                    driven_at: run
                        .samples
                        .iter()
                        .step_by(10)
                        .map(|s| [t + s.t_s, s.truth.theta])
                        .collect(),
                });
                t += time_s;
                pose = end;
                pose_seen = last.map_or(pose, |s| s.measured);
                if run.metrics.completed && error <= ARRIVED_M {
                    note(
                        &mut events,
                        t,
                        "walk",
                        stand_no,
                        format!(
                            "{} {:.1} m to stand {} in {:.0} s ({:.2} m off the stand)",
                            if v_move { "V-move" } else { "walk" },
                            travelled,
                            stand_no + 1,
                            time_s,
                            error
                        ),
                    );
                    arrived = true;
                    break;
                }
                note(
                    &mut events,
                    t,
                    "walk-stalled",
                    stand_no,
                    format!(
                        "stopped {error:.2} m from ({:.1}, {:.1}); track speeds zero; {}",
                        goal.x,
                        goal.y,
                        if attempt < 2 {
                            "planning again from here"
                        } else {
                            "giving up this stand"
                        }
                    ),
                );
                start = pose_seen;
            }
            if arrived {
                break;
            }
        }
        if !arrived {
            note(
                &mut events,
                t,
                "no-stand",
                stand_no,
                "no stand could be reached".into(),
            );
            break 'shift;
        }
        stands.push(StandRecord {
            stand: stand_no + 1,
            x_m: pose.x,
            y_m: pose.y,
            heading_deg: pose.theta.to_degrees(),
            t_arrive_s: t,
            passes: 0,
            dug_t: 0.0,
            left_because: String::new(),
            before: world.z.clone(),
            after: Vec::new(),
        });
        frames.push(snapshot(&world, t, pose));
        failed_scans = 0;
        exhausted.clear();
    }
    if let Some(last) = stands.last_mut() {
        if last.after.is_empty() {
            last.after = world.z.clone();
            if last.left_because.is_empty() {
                last.left_because = "end of the shift".into();
            }
        }
    }
    frames.push(snapshot(&world, t, pose));
    progress(1.0);

    // The figures of merit.
    let n = passes.len().max(1) as f64;
    let mean = |f: fn(&PassRecord) -> f64| passes.iter().map(f).sum::<f64>() / n;
    let cycle = CycleTimes {
        dig_s: mean(|p| p.dig_s),
        swing_s: mean(|p| p.swing_s),
        dump_s: mean(|p| p.dump_s),
        return_s: mean(|p| p.return_s),
        wait_s: mean(|p| p.wait_s),
        total_s: mean(|p| p.dig_s + p.swing_s + p.dump_s + p.return_s + p.wait_s),
    };
    let tonnes: f64 = passes.iter().map(|p| p.dug_t).sum();
    let kwh = |j: f64| j / 3.6e6 / tonnes.max(f64::MIN_POSITIVE);
    let (hoist, crowd, swing_e) = (
        passes.iter().map(|p| p.hoist_j).sum::<f64>(),
        passes.iter().map(|p| p.crowd_j).sum::<f64>(),
        passes.iter().map(|p| p.swing_j).sum::<f64>(),
    );
    let energy = EnergyPerTonne {
        hoist: kwh(hoist),
        crowd: kwh(crowd),
        swing: kwh(swing_e),
        propel: kwh(propel_j),
        total: kwh(hoist + crowd + swing_e + propel_j),
    };
    let fills: Vec<f64> = passes.iter().map(|p| p.fill_factor).collect();
    let fill_factor = FillStats {
        mean: fills.iter().sum::<f64>() / n,
        min: fills.iter().cloned().fold(f64::INFINITY, f64::min),
        max: fills.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
    };
    let pit_lost_t = (before.volume_m3() - world.volume_m3()) * density_t;
    let tolerance_t = 1e-9 * before.volume_m3() * density_t;
    let balance = MassBalance {
        pit_lost_t,
        dug_t: tonnes,
        dumped_t: trucks_t,
        planned_t: passes.iter().map(|p| p.planned_m3).sum::<f64>() * density_t,
        executed_t: passes
            .iter()
            .filter(|p| p.executed_m3.is_finite())
            .map(|p| p.executed_m3)
            .sum::<f64>()
            * density_t,
        error_t: (pit_lost_t - trucks_t).abs(),
        tolerance_t,
        closes: (pit_lost_t - trucks_t).abs() <= tolerance_t
            && (tonnes - trucks_t).abs() <= tolerance_t,
    };
    let mut by_kind = std::collections::BTreeMap::new();
    for e in &events {
        *by_kind.entry(e.kind).or_insert(0) += 1;
    }
    let safety_events = events
        .iter()
        .filter(|e| matches!(e.kind, "overfill" | "over-rating" | "walk-stalled"))
        .count();
    let quarter = (passes.len() / 4).max(1);
    let wall_mean =
        |ps: &[PassRecord]| ps.iter().map(|p| p.wall_ms).sum::<f64>() / ps.len().max(1) as f64;
    let hours_run = t / 3600.0;
    let summary = ShiftSummary {
        job: "shift",
        scenario: scenario.name.clone(),
        completed,
        hours: hours_run,
        passes: passes.len(),
        stands: stands.len(),
        walks: walks.len(),
        tonnes,
        tonnes_per_hour: if hours_run > 0.0 {
            tonnes / hours_run
        } else {
            0.0
        },
        cycle_time_s: cycle,
        walk_time_s: walks.iter().fold(0.0, |a, w| a + w.time_s),
        walked_m: walks.iter().fold(0.0, |a, w| a + w.travelled_m),
        energy_kwh_per_t: energy,
        fill_factor,
        volume_left_m3: world.volume_m3(),
        mass_balance: balance,
        safety_events,
        events: by_kind,
        lambda: m.lambda,
        dipper_m3: capacity,
        dig_time_range_s: [profile.limits.time_min_s, profile.limits.time_max_s],
        wall_ms: wall.elapsed().as_secs_f64() * 1e3,
        ms_per_pass: wall_mean(&passes),
        ms_per_pass_first_quarter: wall_mean(&passes[..quarter.min(passes.len())]),
        ms_per_pass_last_quarter: wall_mean(&passes[passes.len().saturating_sub(quarter)..]),
        assumptions: assumptions(scenario, &profile, &swing),
    };
    Ok(ShiftRun {
        summary,
        passes,
        stands,
        walks,
        events,
        before,
        after: world,
        frames,
        frame_size,
        frame_cell_m: FRAME_CELL_M,
    })
}

/// A drive along planned legs in the crawler simulator: loose-bench
/// slip, Table 2-like RTK, the fuzzy tracker.
struct Drive {
    run: autoshovel_walk_tracker::Run,
    end: Pose2,
    time_s: f64,
    travelled_m: f64,
}

fn drive(legs: Vec<RefLeg>, start: Pose2, speed_mps: f64, seed: u64) -> Drive {
    let setup = Setup {
        legs,
        start,
        crawler: CrawlerParams::default(),
        slip: SlipParams::loose_bench(),
        rtk: RtkParams::rtk(seed),
        sim: SimParams {
            speed_mps,
            ..SimParams::default()
        },
    };
    let mut controller = ControllerKind::Fuzzy.build(&ControllerParams::default());
    let run = simulate(&setup, controller.as_mut());
    let last = run.samples.last();
    Drive {
        end: last.map_or(start, |s| s.truth),
        time_s: last.map_or(0.0, |s| s.t_s),
        travelled_m: run.metrics.travelled_m,
        run,
    }
}

/// The models behind the figures of merit, in words.
fn assumptions(s: &ShiftScenario, profile: &MachineProfile, swing: &SwingDrive) -> Vec<String> {
    let m = &s.machine;
    vec![
        format!(
            "machine: the rope-shovel paper's 1:30 model scaled by Froude similarity, λ = {} (lengths λ, masses and forces λ³, times λ^½, powers λ^3.5): dipper {:.1} m³, dig {:.0}-{:.0} s, hoist rating {:.2} MW",
            m.lambda,
            profile.dipper.capacity_m3,
            profile.limits.time_min_s,
            profile.limits.time_max_s,
            profile.limits.hoist_power_max_w / 1e6
        ),
        format!(
            "material: bank density {:.0} kg/m³; tonnes are bank mass of what the dipper's path swept out of the pit",
            profile.material.density_kg_m3
        ),
        "hoist and crowd energy: ∫ v·F dt of the planned path on the true pile ([RS eq. 25]), motoring only".into(),
        format!(
            "swing: rest to rest at {:.0}°/s and {:.0}°/s²; energy ½·J·ω² to accelerate (J = {:.1e} kg·m² + load at {:.0} m), braking not recovered, bearing friction left out",
            m.swing_speed_deg_s, m.swing_accel_deg_s2, swing.inertia_kg_m2, swing.radius_m
        ),
        format!(
            "dump {:.0} s; a truck of {:.0} t exchanged in {:.0} s while the dipper returns and digs (the shovel waits only for the rest)",
            m.dump_s, s.truck.capacity_t, s.truck.exchange_s
        ),
        format!(
            "propel: rolling resistance {:.2} × {:.0} t × g over the distance driven, turning losses left out",
            m.rolling_resistance, m.mass_t
        ),
        "scans: an 80-line LiDAR on the swing axis, mounted off level (perception estimates the tilt), 2 cm range noise, 0.3 % dust; the face is scanned during the return swing at no cost of time; before each walk the upper works swing round once (half a turn and back) to scan the ground about the machine".into(),
        "trucks are not in the pit's height grid: they are not scanned and do not block walks (they leave before the machine walks)".into(),
    ]
}
