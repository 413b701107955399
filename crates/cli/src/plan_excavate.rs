//! `autoshovel plan-excavate`: the hydraulic excavator's two-level dig
//! planning (SPEC §5; Shao, Ye & Sun 2016) on a built-in scenario or a TOML
//! file: level 1 plans a quintic dig for the target volume (eqs. 1–2), the
//! soil simulator executes it, and each buried boulder met (eq. 10) is passed
//! over or under by the preimage rule on γ, a forward search and a re-plan of
//! the remaining volume (§2). The planning itself is `autoshovel_excavate`;
//! this module loads the inputs, adds the summary fields SPEC §6 asks for and
//! writes the outputs.
//!
//! `--out DIR` gets `summary.json`, `samples.csv` (every executed sample,
//! every field), `contacts.csv`, `planned_path.csv` (the level-1 plan made
//! before any contact) and the plots of the paper's Figs. 5–6: `tooth_path`
//! (ground, boulder envelopes, contacts with V_c and F_f, the planned and the
//! executed path, the level-1 midpoint and end point), `excavator` (the whole
//! front at the start, the first contact and the end), `digging_force` (|F|
//! against time, contacts marked) and `joints` (θ₁, θ₂, θ₃ and the attitude
//! angle φ in degrees, and the Lagrange joint torques). A plan that fails is
//! an error naming the reason; no summary is written for it.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use autoshovel_excavate::profile::EXCAVATOR_15T_TOML;
use autoshovel_excavate::segment::SegmentKind;
use autoshovel_excavate::TomlFile as _;
use autoshovel_excavate::{
    excavate, Backhoe, ContactReport, Excavation, Joints, MachineProfile, Sample, Scenario,
};
use autoshovel_report::{write_csv, write_csv_cells, write_panels, Figure, Layer, Rgb, Stroke};
use serde_json::{json, Value};

use crate::output::{num, prepare_dir, write_job_summary, Written};

/// Length of the V_c and F_f direction arrows drawn at a contact [m].
const ARROW_M: f64 = 0.3;

/// Arguments of `plan-excavate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// paper-over, paper-under, two-boulders, or a scenario TOML file (`--print-scenario` shows the format).
    #[arg(long, default_value = "paper-over")]
    pub scenario: String,
    /// Machine profile (TOML); default: the 15 t class backhoe (`--print-profile` shows it).
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Print the scenario as TOML and exit (a built-in with its comments, or the checked file).
    #[arg(long, conflicts_with = "print_profile")]
    pub print_scenario: bool,
    /// Print the machine profile as TOML and exit (the built-in one, commented, or the checked --profile).
    #[arg(long)]
    pub print_profile: bool,
    /// Write summary.json, CSV and plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
}

/// The dig and the machine of a run, and where they came from.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The checked scenario.
    pub scenario: Scenario,
    /// "builtin" or the file's path.
    pub scenario_source: String,
    /// The checked machine profile.
    pub profile: MachineProfile,
    /// "builtin excavator-15t" or the file's path.
    pub profile_name: String,
}

impl Setup {
    /// Loads the scenario (a built-in name or a file) and the profile (the
    /// built-in one without a path); the library's errors name file, line and key.
    pub fn load(scenario: &str, profile: Option<&Path>) -> Result<Self> {
        let scenario_source = if Scenario::builtin_toml(scenario).is_some() {
            "builtin".to_string()
        } else {
            scenario.to_string()
        };
        let scenario = Scenario::from_name_or_file(scenario)?;
        let (profile, profile_name) = load_profile(profile)?;
        Ok(Self {
            scenario,
            scenario_source,
            profile,
            profile_name,
        })
    }
}

fn load_profile(path: Option<&Path>) -> Result<(MachineProfile, String)> {
    Ok(match path {
        Some(p) => (MachineProfile::load(p)?, p.display().to_string()),
        None => (
            MachineProfile::excavator_15t(),
            "builtin excavator-15t".to_string(),
        ),
    })
}

/// One plan's result.
#[derive(Debug)]
pub struct Job {
    /// Summary (SPEC §6 `plan-excavate`).
    pub summary: Value,
    /// Files written.
    pub written: Written,
}

/// Runs `plan-excavate` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    if args.print_scenario {
        let text = match Scenario::builtin_toml(&args.scenario) {
            Some(t) => t.to_string(),
            None => Scenario::from_name_or_file(&args.scenario)?.to_toml(),
        };
        print_raw(&text);
        return Ok(());
    }
    if args.print_profile {
        let text = match &args.profile {
            Some(p) => MachineProfile::load(p)?.to_toml(),
            None => EXCAVATOR_15T_TOML.to_string(),
        };
        print_raw(&text);
        return Ok(());
    }
    let setup = Setup::load(&args.scenario, args.profile.as_deref())?;
    if let Some(dir) = &args.out {
        // Refuse a bad --out before planning, but create it only for a plan.
        if dir.exists() && !dir.is_dir() {
            anyhow::bail!("--out {}: exists and is not a directory", dir.display());
        }
    }
    let ex = plan(&setup)?;
    let out = args.out.as_deref().map(prepare_dir).transpose()?;
    let job = finish(&setup, &ex, out.as_deref())?;
    crate::output::report(&job.summary, args.json, out.as_deref(), print_human)
}

fn print_raw(text: &str) {
    use std::io::Write as _;
    let _ = write!(std::io::stdout().lock(), "{text}");
}

/// Plans and executes the dig; an impossible dig is an error naming the scenario.
pub fn plan(setup: &Setup) -> Result<Excavation> {
    excavate(&setup.scenario, &setup.profile).with_context(|| {
        format!(
            "plan-excavate {} ({})",
            setup.scenario.name, setup.scenario_source
        )
    })
}

/// Plans `setup` and writes into `out` if given.
pub fn job(setup: &Setup, out: Option<&Path>) -> Result<Job> {
    let ex = plan(setup)?;
    finish(setup, &ex, out)
}

fn finish(setup: &Setup, ex: &Excavation, out: Option<&Path>) -> Result<Job> {
    let mut summary = summary_json(setup, ex)?;
    let mut written = Written::default();
    if let Some(dir) = out {
        write_outputs(dir, setup, ex, &mut written)?;
        write_job_summary(dir, &mut summary, &mut written)?;
    }
    Ok(Job { summary, written })
}

/// The library's [`autoshovel_excavate::Summary`] and what SPEC §6 and the
/// report add: sources, every side chosen, the error in %, the whole level-1
/// plan, the boulders, the detours, the segments and the peak digging force
/// with the contacts.
fn summary_json(setup: &Setup, ex: &Excavation) -> Result<Value> {
    let mut s = serde_json::to_value(ex.summary()).context("summary")?;
    let o = s.as_object_mut().expect("the summary is an object");
    let sc = &setup.scenario;
    let l1 = &ex.level1;
    let met: Vec<bool> = (0..ex.obstacles.len())
        .map(|i| ex.contacts.iter().any(|c| c.obstacle == i))
        .collect();
    let peak_force = ex
        .samples
        .iter()
        .map(|s| s.digging_force_magnitude_n)
        .fold(0.0, f64::max);
    let detour_segments = ex.segments.iter().filter(|g| g.kind == SegmentKind::Detour);
    let detours: Vec<Value> = ex
        .detours
        .iter()
        .zip(detour_segments)
        .map(|(d, g)| {
            json!({
                "contact": d.contact,
                "side": d.side,
                "goal_x_m": d.goal_x_m,
                "clearance_m": num(d.clearance_m),
                "t_start_s": g.t_start_s,
                "t_end_s": g.t_end_s,
                "completed": g.completed,
                "waypoints": d.search.waypoints.len(),
                "free_points": d.search.free_points,
                "blocked_points": d.search.blocked_points,
                "expanded": d.search.expanded,
                "volume_before_replan_m3": d.volume_before_replan_m3,
            })
        })
        .collect();
    let extra = json!({
        "job": "plan-excavate",
        "description": sc.description,
        "scenario_source": setup.scenario_source,
        "profile": setup.profile_name,
        "volume_error_pct": num(100.0 * ex.volume_error()),
        "avoid_directions": ex.contacts.iter().map(|c| c.decision).collect::<Vec<_>>(),
        "contact_count": ex.contacts.len(),
        "level1_start_m": l1.start_m,
        "level1": {
            "start_m": l1.start_m,
            "mid_m": l1.mid_m,
            "end_m": l1.end_m,
            "first_half_m3": l1.first_half_m3,
            "second_half_m3": l1.second_half_m3,
            "mid_steps": l1.mid_steps,
            "end_steps": l1.end_steps,
            "durations_s": l1.durations_s,
        },
        "obstacles": ex.obstacles.iter().zip(&met).map(|(e, m)| json!({
            "center_m": e.center_m,
            "radius_m": e.radius_m,
            "volume_m3": e.area_m2() * setup.profile.bucket.width_m,
            "met": m,
        })).collect::<Vec<_>>(),
        "detours": detours,
        "segments": ex.segments.iter().map(|g| json!({
            "kind": g.kind,
            "t_start_s": g.t_start_s,
            "t_end_s": g.t_end_s,
            "from_m": g.from_m,
            "to_m": g.to_m,
            "planned_volume_m3": g.planned_volume_m3,
            "completed": g.completed,
        })).collect::<Vec<_>>(),
        "peak_digging_force_n": peak_force,
        "max_digging_force_n": setup.profile.force.max_digging_force_n,
        "samples": ex.samples.len(),
        "step_m": sc.dig.step_m,
        "depth_m": sc.dig.depth_m,
        "refine_volume": sc.planner.refine_volume,
    });
    for (k, v) in extra.as_object().expect("object") {
        o.insert(k.clone(), v.clone());
    }
    Ok(s)
}

fn print_human(s: &Value) {
    let g = |k: &str| s[k].as_f64().unwrap_or(f64::NAN);
    let p = |v: &Value| {
        format!(
            "({:.3}, {:.3})",
            // + 0.0 turns −0 into 0.
            v[0].as_f64().unwrap_or(f64::NAN) + 0.0,
            v[1].as_f64().unwrap_or(f64::NAN) + 0.0
        )
    };
    crate::say!(
        "plan-excavate {} ({}), profile {}",
        s["scenario"].as_str().unwrap_or(""),
        s["scenario_source"].as_str().unwrap_or(""),
        s["profile"].as_str().unwrap_or("")
    );
    crate::say!(
        "  volume {:.3} m³ of {:.3} m³ ({:+.2} %): soil {:.3} + boulders {:.3} m³",
        g("achieved_volume_m3"),
        g("target_volume_m3"),
        g("volume_error_pct"),
        g("soil_volume_m3"),
        g("obstacle_volume_m3")
    );
    crate::say!(
        "  level 1: start {}, midpoint {}, end {} m",
        p(&s["level1_start_m"]),
        p(&s["level1_mid_m"]),
        p(&s["level1_end_m"])
    );
    let contacts = s["contacts"].as_array().cloned().unwrap_or_default();
    if contacts.is_empty() {
        crate::say!("  no boulder met");
    }
    for (i, c) in contacts.iter().enumerate() {
        let f = &c["force_n"];
        crate::say!(
            "  contact {} with boulder {} at {:.2} s, {} m: F_f ({:.1}, {:.1}) kN, γ {:.1}° → {}",
            i + 1,
            c["obstacle"],
            c["t_s"].as_f64().unwrap_or(f64::NAN),
            p(&c["point_m"]),
            f[0].as_f64().unwrap_or(f64::NAN) / 1e3,
            f[1].as_f64().unwrap_or(f64::NAN) / 1e3,
            c["gamma_deg"].as_f64().unwrap_or(f64::NAN),
            c["decision"].as_str().unwrap_or("?")
        );
    }
    let torques = &s["peak_torques_nm"];
    let t = |i: usize| torques[i].as_f64().unwrap_or(f64::NAN) / 1e3;
    crate::say!(
        "  dig {:.2} s, ends at {} m; min envelope distance {} m; max joint step {:.2} of the speed limit",
        g("duration_s"),
        p(&s["final_tip_m"]),
        s["min_envelope_distance_m"]
            .as_f64()
            .map_or("-".to_string(), |d| format!("{d:.4}")),
        g("max_joint_step_ratio")
    );
    crate::say!(
        "  peak torques boom {:.0}, stick {:.0}, bucket {:.0} kN·m; peak digging force {:.1} kN (soil alone {:.1} kN); planned in {:.2} ms",
        t(0),
        t(1),
        t(2),
        g("peak_digging_force_n") / 1e3,
        g("peak_soil_force_n") / 1e3,
        g("plan_time_ms")
    );
}

fn kind_name(kind: SegmentKind) -> &'static str {
    match kind {
        SegmentKind::Descent => "descent",
        SegmentKind::Rise => "rise",
        SegmentKind::Detour => "detour",
    }
}

/// The columns of `samples.csv`: every field of [`Sample`], vectors split.
const SAMPLE_COLUMNS: [&str; 22] = [
    "t_s",
    "tip_x_m",
    "tip_y_m",
    "theta1_rad",
    "theta2_rad",
    "theta3_rad",
    "theta1_rate_rad_s",
    "theta2_rate_rad_s",
    "theta3_rate_rad_s",
    "attitude_rad",
    "torque1_nm",
    "torque2_nm",
    "torque3_nm",
    "digging_force_x_n",
    "digging_force_y_n",
    "digging_force_magnitude_n",
    "load_kg",
    "swept_volume_m3",
    "segment",
    "kind",
    "contact",
    "attitude_deg",
];

fn sample_row(s: &Sample) -> Vec<String> {
    let mut row: Vec<String> = [
        s.t_s,
        s.tip_m[0],
        s.tip_m[1],
        s.joints_rad[0],
        s.joints_rad[1],
        s.joints_rad[2],
        s.joint_rates_rad_s[0],
        s.joint_rates_rad_s[1],
        s.joint_rates_rad_s[2],
        s.attitude_rad,
        s.torques_nm[0],
        s.torques_nm[1],
        s.torques_nm[2],
        s.digging_force_n[0],
        s.digging_force_n[1],
        s.digging_force_magnitude_n,
        s.load_kg,
        s.swept_volume_m3,
    ]
    .into_iter()
    .map(autoshovel_report::format_f64)
    .collect();
    row.push(s.segment.to_string());
    row.push(kind_name(s.kind).to_string());
    row.push(s.contact.to_string());
    row.push(autoshovel_report::format_f64(s.attitude_rad.to_degrees()));
    row
}

const CONTACT_COLUMNS: [&str; 13] = [
    "contact",
    "obstacle",
    "t_s",
    "point_x_m",
    "point_y_m",
    "velocity_x_m_s",
    "velocity_y_m_s",
    "force_x_n",
    "force_y_n",
    "force_magnitude_n",
    "gamma_deg",
    "decision",
    "attitude_deg",
];

fn contact_row(i: usize, c: &ContactReport, ex: &Excavation) -> Vec<String> {
    let attitude = contact_sample(ex, c).map_or(f64::NAN, |s| s.attitude_rad.to_degrees());
    vec![
        (i + 1).to_string(),
        c.obstacle.to_string(),
        autoshovel_report::format_f64(c.t_s),
        autoshovel_report::format_f64(c.point_m[0]),
        autoshovel_report::format_f64(c.point_m[1]),
        autoshovel_report::format_f64(c.velocity_m_s[0]),
        autoshovel_report::format_f64(c.velocity_m_s[1]),
        autoshovel_report::format_f64(c.force_n[0]),
        autoshovel_report::format_f64(c.force_n[1]),
        autoshovel_report::format_f64(c.force_n[0].hypot(c.force_n[1])),
        autoshovel_report::format_f64(c.gamma_deg),
        c.decision.to_string(),
        autoshovel_report::format_f64(attitude),
    ]
}

/// The executed sample at a contact.
fn contact_sample<'a>(ex: &'a Excavation, c: &ContactReport) -> Option<&'a Sample> {
    ex.samples
        .iter()
        .filter(|s| s.contact)
        .min_by(|a, b| (a.t_s - c.t_s).abs().total_cmp(&(b.t_s - c.t_s).abs()))
}

fn write_outputs(dir: &Path, setup: &Setup, ex: &Excavation, written: &mut Written) -> Result<()> {
    let samples = dir.join("samples.csv");
    let rows: Vec<Vec<String>> = ex.samples.iter().map(sample_row).collect();
    write_csv_cells(&samples, &SAMPLE_COLUMNS, &rows)?;
    written.file(dir, &samples);
    let contacts = dir.join("contacts.csv");
    let rows: Vec<Vec<String>> = ex
        .contacts
        .iter()
        .enumerate()
        .map(|(i, c)| contact_row(i, c, ex))
        .collect();
    write_csv_cells(&contacts, &CONTACT_COLUMNS, &rows)?;
    written.file(dir, &contacts);
    let planned = dir.join("planned_path.csv");
    write_csv(
        &planned,
        &["x_m", "y_m"],
        ex.planned_path().iter().map(|p| p.to_vec()),
    )?;
    written.file(dir, &planned);
    let name = &ex.scenario;
    written.plot(
        dir,
        write_panels(&[tooth_path_figure(ex)], dir, "tooth_path").context("tooth path plot")?,
    );
    written.plot(
        dir,
        write_panels(&[excavator_figure(setup, ex)], dir, "excavator").context("excavator plot")?,
    );
    written.plot(
        dir,
        write_panels(&[force_figure(setup, ex)], dir, "digging_force")
            .context("digging force plot")?,
    );
    written.plot(
        dir,
        write_panels(&joint_figures(ex, name), dir, "joints").context("joint plot")?,
    );
    Ok(())
}

fn pt(p: [f64; 2]) -> (f64, f64) {
    (p[0], p[1])
}

/// Bounds (x0, x1, y0, y1) of the dig: every path, boulder and the start.
fn dig_bounds(ex: &Excavation) -> (f64, f64, f64, f64) {
    let mut b = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64, 0.0f64);
    let mut take = |x: f64, y: f64| {
        b.0 = b.0.min(x);
        b.1 = b.1.max(x);
        b.2 = b.2.min(y);
        b.3 = b.3.max(y);
    };
    for p in ex
        .planned_path()
        .iter()
        .chain(ex.samples.iter().map(|s| &s.tip_m))
    {
        take(p[0], p[1]);
    }
    for e in &ex.obstacles {
        let [x, y] = e.center_m;
        take(x - e.radius_m, y - e.radius_m);
        take(x + e.radius_m, y + e.radius_m);
    }
    b
}

/// The ground line from `x0` to `x1`, with its vertices in between.
fn ground_line(ex: &Excavation, x0: f64, x1: f64) -> Layer {
    let mut pts = vec![(x0, ex.ground.height(x0))];
    pts.extend(
        ex.ground
            .points
            .iter()
            .filter(|p| p[0] > x0 && p[0] < x1)
            .map(|p| (p[0], p[1])),
    );
    pts.push((x1, ex.ground.height(x1)));
    Layer::line(pts, Stroke::solid(Rgb::BLACK, 2)).with_label("ground")
}

/// The boulders, the planned and executed paths and the contacts, shared by
/// both dig-plane figures; `detail` adds the legend entries, the search
/// waypoints, the V_c/F_f arrows and the level-1 points' coordinates.
fn dig_layers(ex: &Excavation, x0: f64, x1: f64, detail: bool) -> Vec<Layer> {
    let label = |l: Layer, text: &str| if detail { l.with_label(text) } else { l };
    let mut layers = vec![label(ground_line(ex, x0, x1), "ground")];
    for (i, e) in ex.obstacles.iter().enumerate() {
        let l = Layer::circle(
            pt(e.center_m),
            e.radius_m,
            Some(Rgb::BROWN),
            Stroke::solid(Rgb::BROWN, 1),
        );
        layers.push(if i == 0 {
            label(l, "boulder envelope (unknown to the planner until met)")
        } else {
            l
        });
        if detail {
            layers.push(Layer::text(
                (e.center_m[0] - 0.35 * e.radius_m, e.center_m[1]),
                format!("boulder {i}"),
                Rgb::BLACK,
            ));
        }
    }
    layers.push(label(
        Layer::line(
            ex.planned_path().iter().map(|p| pt(*p)),
            Stroke::dashed(Rgb::GREY, 2),
        ),
        "level-1 plan before any contact",
    ));
    layers.push(label(
        Layer::line(
            ex.samples.iter().map(|s| pt(s.tip_m)),
            Stroke::solid(Rgb::BLUE, 3),
        ),
        "executed tooth path (with re-plans)",
    ));
    // The detours over the executed path, each a run of detour samples.
    let mut first = true;
    let mut run: Vec<(f64, f64)> = Vec::new();
    let mut flush = |run: &mut Vec<(f64, f64)>, layers: &mut Vec<Layer>| {
        if run.len() > 1 {
            let l = Layer::line(run.drain(..), Stroke::solid(Rgb::ORANGE, 4));
            layers.push(if first {
                first = false;
                label(l, "detour (forward search, B-spline smoothed)")
            } else {
                l
            });
        }
        run.clear();
    };
    for s in &ex.samples {
        if s.kind == SegmentKind::Detour {
            run.push(pt(s.tip_m));
        } else {
            flush(&mut run, &mut layers);
        }
    }
    flush(&mut run, &mut layers);
    if detail {
        let waypoints: Vec<(f64, f64)> = ex
            .detours
            .iter()
            .flat_map(|d| d.search.waypoints.iter().map(|p| pt(*p)))
            .collect();
        if !waypoints.is_empty() {
            layers.push(
                Layer::points(waypoints, Rgb::PURPLE, 2).with_label("forward-search grid path"),
            );
        }
    }
    let l1 = &ex.level1;
    layers.push(label(
        Layer::points([pt(l1.start_m), pt(l1.mid_m), pt(l1.end_m)], Rgb::GREEN, 5),
        "level-1 start, midpoint, end point",
    ));
    if detail {
        // The midpoint's label below it, clear of the paths that meet there.
        for (name, p, dy) in [
            ("start", l1.start_m, 0.06),
            ("mid", l1.mid_m, -0.07),
            ("end", l1.end_m, 0.06),
        ] {
            layers.push(Layer::text(
                (p[0] + 0.03, p[1] + dy),
                format!("{name} ({:.2}, {:.2})", p[0], p[1]),
                Rgb::GREEN,
            ));
        }
    }
    for (i, c) in ex.contacts.iter().enumerate() {
        let at = pt(c.point_m);
        layers.push(label(
            Layer::points([at], Rgb::RED, 6),
            &format!(
                "contact {}: t = {:.2} s, γ = {:.1}° → {}",
                i + 1,
                c.t_s,
                c.gamma_deg,
                c.decision
            ),
        ));
        if detail {
            for (v, color, what) in [
                (c.velocity_m_s, Rgb::BLACK, "tip velocity V_c"),
                (c.force_n, Rgb::RED, "contact force F_f"),
            ] {
                let n = v[0].hypot(v[1]);
                if n > 0.0 {
                    let to = (at.0 + ARROW_M * v[0] / n, at.1 + ARROW_M * v[1] / n);
                    let l = Layer::arrow(at, to, Stroke::solid(color, 2));
                    layers.push(if i == 0 {
                        l.with_label(format!("{what} (direction)"))
                    } else {
                        l
                    });
                }
            }
        }
    }
    layers
}

/// Figs. 5a/6a: the tooth path round the boulders in the dig plane.
fn tooth_path_figure(ex: &Excavation) -> Figure {
    let (bx0, bx1, by0, by1) = dig_bounds(ex);
    let (x0, x1) = (bx0 - 0.3, bx1 + 0.3);
    // Room above the ground for the legend.
    let (y0, y1) = (by0 - 0.15, by1.max(ex.ground.height(bx1)) + 0.7);
    let height = ((1200.0 * (y1 - y0) / (x1 - x0)) as u32 + 120).clamp(420, 900);
    let mut fig = Figure::new(
        format!(
            "Tooth path round the buried boulders ({}): {:.3} m³ of {:.3} m³",
            ex.scenario, ex.achieved_volume_m3, ex.target_volume_m3
        ),
        "x from the slew axis [m]",
        "y above the ground [m]",
    )
    .equal_aspect()
    .x_range(x0, x1)
    .y_range(y0, y1)
    .size(1200, height);
    for l in dig_layers(ex, x0, x1, true) {
        fig.push(l);
    }
    fig
}

/// The front (boom, stick, bucket link) at joint values `q`.
fn front_layers(machine: &Backhoe, q: [f64; 3], color: Rgb, label: String) -> Vec<Layer> {
    let [stick_pin, bucket_pin, tip] = machine.joint_points(&Joints::new(q[0], q[1], q[2]));
    let foot = machine.foot();
    let xy = |v: autoshovel_core::Vec2| (v.x, v.y);
    vec![
        Layer::line([xy(foot), xy(stick_pin)], Stroke::solid(color, 7)).with_label(label),
        Layer::line([xy(stick_pin), xy(bucket_pin)], Stroke::solid(color, 5)),
        Layer::line([xy(bucket_pin), xy(tip)], Stroke::solid(color, 3)),
        Layer::points([xy(foot), xy(stick_pin), xy(bucket_pin)], color, 4),
    ]
}

/// The whole machine in the dig plane: a schematic body at the slew axis,
/// the front at the start, the first contact and the end, and the dig.
fn excavator_figure(setup: &Setup, ex: &Excavation) -> Figure {
    let machine = Backhoe::new(&setup.profile);
    let g = &setup.profile.geometry;
    let (_, bx1, by0, _) = dig_bounds(ex);
    let reach = g.boom_length_m + g.stick_length_m + g.bucket_tip_radius_m;
    let x0 = (-2.2f64).min(g.boom_foot_x_m - 1.0);
    let x1 = bx1.max(g.boom_foot_x_m + 0.6 * reach) + 0.4;
    let mut fig = Figure::new(
        format!(
            "The excavator at the start, the first contact and the end ({})",
            ex.scenario
        ),
        "x from the slew axis [m]",
        "y above the ground [m]",
    )
    .equal_aspect()
    .size(1200, 640);
    // Schematic body (not to scale): crawler and upper structure round the slew axis.
    let hb = g.boom_foot_height_m;
    fig.push(
        Layer::polygon(
            [(-1.8, 0.0), (1.8, 0.0), (1.8, 0.8), (-1.8, 0.8)],
            Some(Rgb::GREY),
            Stroke::solid(Rgb::GREY, 1),
        )
        .with_label("crawler and upper structure (schematic)"),
    );
    fig.push(Layer::polygon(
        [
            (-1.6, 0.85),
            (g.boom_foot_x_m + 0.5, 0.85),
            (g.boom_foot_x_m + 0.5, hb + 0.7),
            (-1.6, hb + 0.7),
        ],
        Some(Rgb::GREY),
        Stroke::solid(Rgb::GREY, 1),
    ));
    for l in dig_layers(ex, x0, x1, false) {
        fig.push(l);
    }
    let mut poses: Vec<(&Sample, Rgb, String)> = Vec::new();
    if let Some(s) = ex.samples.first() {
        poses.push((
            s,
            Rgb::BLUE,
            format!("front at the start, t = {:.2} s", s.t_s),
        ));
    }
    if let Some(s) = ex.contacts.first().and_then(|c| contact_sample(ex, c)) {
        poses.push((
            s,
            Rgb::RED,
            format!("at the first contact, t = {:.2} s", s.t_s),
        ));
    }
    if let Some(s) = ex.samples.last() {
        poses.push((s, Rgb::GREEN, format!("at the end, t = {:.2} s", s.t_s)));
    }
    for (s, color, label) in poses {
        for l in front_layers(&machine, s.joints_rad, color, label) {
            fig.push(l);
        }
    }
    fig.x_range = Some((x0, x1));
    fig.y_range = Some((by0 - 0.3, hb + 0.45 * reach));
    fig
}

/// A vertical dashed line at each contact from `lo` to `hi`.
fn contact_marks(ex: &Excavation, lo: f64, hi: f64) -> Vec<Layer> {
    ex.contacts
        .iter()
        .enumerate()
        .map(|(i, c)| {
            Layer::line([(c.t_s, lo), (c.t_s, hi)], Stroke::dashed(Rgb::RED, 2)).with_label(
                format!(
                    "contact {} at {:.2} s (γ {:.1}°, {})",
                    i + 1,
                    c.t_s,
                    c.gamma_deg,
                    c.decision
                ),
            )
        })
        .collect()
}

/// Figs. 5b/6b: the digging force against time, its jump at each contact.
fn force_figure(setup: &Setup, ex: &Excavation) -> Figure {
    let rating_kn = setup.profile.force.max_digging_force_n / 1e3;
    let peak_kn = ex
        .samples
        .iter()
        .map(|s| s.digging_force_magnitude_n / 1e3)
        .fold(rating_kn, f64::max);
    let t_end = ex.duration_s;
    let mut fig = Figure::new(
        format!("Digging force on the tooth ({})", ex.scenario),
        "time [s]",
        "|F| [kN]",
    )
    .size(1000, 520)
    .y_range(0.0, 1.1 * peak_kn);
    fig.push(
        Layer::line(
            [(0.0, rating_kn), (t_end, rating_kn)],
            Stroke::dashed(Rgb::GREY, 1),
        )
        .with_label("machine's digging force rating"),
    );
    for l in contact_marks(ex, 0.0, 1.1 * peak_kn) {
        fig.push(l);
    }
    fig.push(
        Layer::line(
            ex.samples
                .iter()
                .map(|s| (s.t_s, s.digging_force_magnitude_n / 1e3)),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("digging resistance |F| (soil; boulder at a contact)"),
    );
    let jumps: Vec<(f64, f64)> = ex
        .samples
        .iter()
        .filter(|s| s.contact)
        .map(|s| (s.t_s, s.digging_force_magnitude_n / 1e3))
        .collect();
    if !jumps.is_empty() {
        fig.push(Layer::points(jumps, Rgb::RED, 5));
    }
    fig
}

/// Figs. 5c/6c: joint angles and the attitude angle [deg], and the joint torques.
fn joint_figures(ex: &Excavation, name: &str) -> Vec<Figure> {
    let series = |f: &dyn Fn(&Sample) -> f64| -> Vec<(f64, f64)> {
        ex.samples.iter().map(|s| (s.t_s, f(s))).collect()
    };
    let deg = |i: usize| move |s: &Sample| s.joints_rad[i].to_degrees();
    let angles = [
        (series(&deg(0)), Rgb::BLUE, "boom θ₁"),
        (series(&deg(1)), Rgb::ORANGE, "stick θ₂"),
        (series(&deg(2)), Rgb::GREEN, "bucket θ₃"),
        (
            series(&|s: &Sample| s.attitude_rad.to_degrees()),
            Rgb::PURPLE,
            "attitude φ = θ₁ + θ₂ + θ₃",
        ),
    ];
    let a = time_panel(
        ex,
        format!("Joint angles and attitude angle ({name})"),
        "angle [deg]",
        (560, 0.45),
        angles,
    );
    let knm = |i: usize| move |s: &Sample| s.torques_nm[i] / 1e3;
    let torques = [
        (series(&knm(0)), Rgb::BLUE, "boom τ₁"),
        (series(&knm(1)), Rgb::ORANGE, "stick τ₂"),
        (series(&knm(2)), Rgb::GREEN, "bucket τ₃"),
    ];
    let t = time_panel(
        ex,
        format!("Joint torques, Lagrange dynamics ({name})"),
        "torque [kN·m]",
        (460, 0.35),
        torques,
    );
    vec![a, t]
}

/// One labelled line of a [`time_panel`]: (t, value) points, colour, label.
type Line<'a> = (Vec<(f64, f64)>, Rgb, &'a str);

/// A figure of lines against time with the contact instants marked, its
/// height `size.0` px and `size.1` of the data's span left free above for
/// the legend.
fn time_panel<const N: usize>(
    ex: &Excavation,
    title: String,
    y_label: &str,
    size: (u32, f64),
    lines: [Line<'_>; N],
) -> Figure {
    let (lo, hi) = range(lines.iter().flat_map(|(v, ..)| v.iter().map(|p| p.1)));
    let (pad, room) = (0.05 * (hi - lo).max(1.0), size.1 * (hi - lo).max(1.0));
    let mut f = Figure::new(title, "time [s]", y_label)
        .size(1000, size.0)
        .y_range(lo - pad, hi + room);
    for l in contact_marks(ex, lo - pad, hi + room) {
        f.push(l);
    }
    for (v, color, label) in lines {
        f.push(Layer::line(v, Stroke::solid(color, 2)).with_label(label));
    }
    f
}

/// (min, max) of finite values; (0, 1) when there are none.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo <= hi {
        (lo, hi)
    } else {
        (0.0, 1.0)
    }
}
