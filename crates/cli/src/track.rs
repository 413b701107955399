//! `autoshovel track`: closed-loop tracking of a path by the crawler with the
//! fuzzy tracker, PID or pure pursuit (SPEC §3, §6), and `--compare` to run
//! every controller on the same scenario and seed.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use autoshovel_report::{
    write_csv, write_csv_cells, write_figure, write_heatmap, write_panels, Figure, Heatmap, Layer,
    Rgb, Stroke,
};
use autoshovel_track::scenario::{resolve, validate, Noise, TrackScenario};
use autoshovel_track::{
    simulate, Controller, FuzzyParams, FuzzyTracker, Pid, PidParams, PurePursuit,
    PurePursuitParams, Run,
};
use serde_json::{json, Value};

use crate::output::{num, prepare_dir, Written};

/// Controller choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ControllerArg {
    /// Fuzzy tracker on preview and centroid deviation (§4.3, Table 1).
    Fuzzy,
    /// PID on the lateral error (kp 800, ki 100, kd 300, §5.4).
    Pid,
    /// Pure pursuit (geometric), forward and reverse.
    PurePursuit,
}

impl ControllerArg {
    /// Every controller, in report order.
    pub const ALL: [ControllerArg; 3] = [
        ControllerArg::Fuzzy,
        ControllerArg::Pid,
        ControllerArg::PurePursuit,
    ];

    /// A fresh controller.
    pub fn build(self) -> Box<dyn Controller> {
        match self {
            ControllerArg::Fuzzy => Box::new(FuzzyTracker::new(FuzzyParams::default())),
            ControllerArg::Pid => Box::new(Pid::new(PidParams::default())),
            ControllerArg::PurePursuit => Box::new(PurePursuit {
                params: PurePursuitParams::default(),
            }),
        }
    }

    fn color(self) -> Rgb {
        match self {
            ControllerArg::Fuzzy => Rgb::RED,
            ControllerArg::Pid => Rgb::BLUE,
            ControllerArg::PurePursuit => Rgb::GREEN,
        }
    }
}

/// Noise choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum NoiseArg {
    /// Exact fixes, ideal tracks.
    Off,
    /// RTK noise (1 cm, ≤ 0.2°, 0.3° mounting offset) and loose-bench slip.
    Rtk,
}

/// Arguments of `track`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// fig9a, fig9b, straight, curve, v-shape, or a TOML file (tracking scenario, or a plan-path scenario to plan first).
    #[arg(long, default_value = "fig9a")]
    pub scenario: String,
    /// Tracker.
    #[arg(long, value_enum, default_value = "fuzzy")]
    pub controller: ControllerArg,
    /// Sensor noise and slip (default: off for fig9a/b, rtk for the others).
    #[arg(long, value_enum)]
    pub noise: Option<NoiseArg>,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Run every controller on the same scenario and seed; one table, one overlay plot.
    #[arg(long)]
    pub compare: bool,
    /// Write summary.json, CSV and plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Result of a track job.
pub struct Job {
    /// Summary.
    pub summary: Value,
    /// Files written.
    pub written: Written,
    /// Why it failed, if it did.
    pub error: Option<String>,
}

/// Runs `track` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let noise = args.noise.map(|n| match n {
        NoiseArg::Off => Noise::Off,
        NoiseArg::Rtk => Noise::Rtk,
    });
    let scenario = resolve(&args.scenario, noise, args.seed)?;
    validate(&scenario.setup).map_err(|e| anyhow::anyhow!("{}: {e}", args.scenario))?;
    let out = args.out.as_deref().map(prepare_dir).transpose()?;
    let job = job(&scenario, args.controller, args.compare, out.as_deref())?;
    // The safety log: on stderr, so stdout stays the summary alone with --json.
    if let Some(events) = job.summary["events"].as_array() {
        for e in events.iter().filter(|e| e["kind"] != "leg-end") {
            eprintln!(
                "safety: t = {:.2} s: {} ({})",
                e["t_s"].as_f64().unwrap_or(f64::NAN),
                e["message"].as_str().unwrap_or(""),
                e["kind"].as_str().unwrap_or("")
            );
        }
    }
    crate::output::report(&job.summary, args.json, out.as_deref(), print_human)?;
    match job.error {
        Some(e) => bail!("{e}"),
        None => Ok(()),
    }
}

fn metrics_json(run: &Run) -> Value {
    let m = &run.metrics;
    json!({
        "max_centroid_dev_m": num(m.max_centroid_dev_m),
        "mean_centroid_dev_m": num(m.mean_centroid_dev_m),
        "rms_centroid_dev_m": num(m.rms_centroid_dev_m),
        "max_centroid_dev_overall_m": num(m.max_centroid_dev_overall_m),
        "mean_centroid_dev_overall_m": num(m.mean_centroid_dev_overall_m),
        "reached_distance_m": num(m.reached_distance_m),
        "convergence_distance_m": num(m.convergence_distance_m),
        "settled_1cm_distance_m": num(m.settled_1cm_distance_m),
        "converged_below_m": m.converged_below_m,
        "final_heading_error_deg": num(m.final_heading_error_deg),
        "final_position_error_m": num(m.final_position_error_m),
        "travelled_m": num(m.travelled_m),
        "duration_s": num(m.duration_s),
        "completed": m.completed,
        "safety_events": run.events.iter().filter(|e| e.kind != "leg-end").count(),
    })
}

fn print_human(s: &Value) {
    let f = |v: &Value, d: usize| {
        v.as_f64()
            .map(|x| format!("{x:.d$}"))
            .unwrap_or_else(|| "-".into())
    };
    crate::say!(
        "track {} (noise {}, seed {})",
        s["scenario"].as_str().unwrap_or(""),
        s["noise"].as_str().unwrap_or(""),
        s["seed"]
    );
    crate::say!("| controller | reached [m] | converged [m] | max dev [m] | mean dev [m] | final heading err [deg] | final pos err [m] | completed |");
    crate::say!("|---|---|---|---|---|---|---|---|");
    let rows: Vec<&Value> = match s["compare"].as_array() {
        Some(a) => a.iter().collect(),
        None => vec![s],
    };
    for r in rows {
        crate::say!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            r["controller"].as_str().unwrap_or(""),
            f(&r["reached_distance_m"], 2),
            f(&r["convergence_distance_m"], 2),
            f(&r["max_centroid_dev_m"], 3),
            f(&r["mean_centroid_dev_m"], 3),
            f(&r["final_heading_error_deg"], 2),
            f(&r["final_position_error_m"], 3),
            r["completed"]
        );
    }
}

/// Runs one scenario with one controller (or all with `compare`), writing into `out`.
pub fn job(
    scenario: &TrackScenario,
    controller: ControllerArg,
    compare: bool,
    out: Option<&Path>,
) -> Result<Job> {
    let which: Vec<ControllerArg> = if compare {
        ControllerArg::ALL.to_vec()
    } else {
        vec![controller]
    };
    let mut runs = Vec::new();
    for c in &which {
        let mut ctl = c.build();
        let t0 = std::time::Instant::now();
        let run = simulate(&scenario.setup, ctl.as_mut());
        runs.push((*c, ctl.name(), run, t0.elapsed().as_secs_f64() * 1e3));
    }
    let main = runs.iter().find(|r| r.0 == controller).unwrap_or(&runs[0]);
    let mut summary = metrics_json(&main.2);
    let o = summary.as_object_mut().expect("object");
    o.insert("job".into(), json!("track"));
    o.insert("scenario".into(), json!(scenario.name));
    o.insert("controller".into(), json!(main.1));
    o.insert(
        "noise".into(),
        json!(match scenario.noise {
            Noise::Off => "off",
            Noise::Rtk => "rtk",
        }),
    );
    o.insert("seed".into(), json!(scenario.setup.rtk.seed));
    o.insert("sim_time_ms".into(), json!(main.3));
    o.insert(
        "realtime_factor".into(),
        num(main.2.metrics.duration_s * 1e3 / main.3.max(1e-9)),
    );
    o.insert("events".into(), json!(main.2.events));
    o.insert("success".into(), json!(main.2.metrics.completed));
    o.insert(
        "params".into(),
        json!({
            "crawler": scenario.setup.crawler, "slip": scenario.setup.slip, "rtk": scenario.setup.rtk, "sim": scenario.setup.sim,
            "fuzzy": FuzzyParams::default(), "pid": PidParams::default(), "pure_pursuit": PurePursuitParams::default(),
        }),
    );
    if compare {
        let rows: Vec<Value> = runs
            .iter()
            .map(|(_, name, run, ms)| {
                let mut m = metrics_json(run);
                m["controller"] = json!(name);
                m["sim_time_ms"] = json!(ms);
                m
            })
            .collect();
        o.insert("compare".into(), json!(rows));
    }
    let mut written = Written::default();
    if let Some(dir) = out {
        write_outputs(dir, scenario, &runs, compare, &mut written)?;
        crate::output::write_job_summary(dir, &mut summary, &mut written)?;
    }
    let error = if main.2.metrics.completed {
        None
    } else {
        let why = main
            .2
            .events
            .iter()
            .rev()
            .find(|e| e.kind != "leg-end")
            .map(|e| e.message.clone())
            .unwrap_or_else(|| "did not finish".into());
        Some(format!(
            "{} did not complete scenario '{}': {why}",
            main.1, scenario.name
        ))
    };
    if compare {
        // A comparison reports every controller honestly; it fails only if the chosen one failed.
        summary["success"] = json!(error.is_none());
    }
    Ok(Job {
        summary,
        written,
        error,
    })
}

type RunRow<'a> = (ControllerArg, &'static str, Run, f64);

fn write_outputs(
    dir: &Path,
    scenario: &TrackScenario,
    runs: &[RunRow],
    compare: bool,
    written: &mut Written,
) -> Result<()> {
    let setup = &scenario.setup;
    // Path overlay.
    let mut fig = Figure::new(
        format!("{}: reference and actual path", scenario.name),
        "east x [m]",
        "north y [m]",
    )
    .equal_aspect();
    if let Some(map) = &scenario.map {
        for l in autoshovel_figures::map::map_layers(map) {
            fig.push(l);
        }
    }
    for (i, leg) in setup.legs.iter().enumerate() {
        let l = Layer::line(
            leg.points.iter().map(|p| (p.x, p.y)),
            Stroke::dashed(Rgb::BLACK, 2),
        );
        fig.push(if i == 0 {
            l.with_label("reference path")
        } else {
            l
        });
    }
    for (c, name, run, _) in runs {
        fig.push(
            Layer::line(
                run.samples.iter().map(|s| (s.truth.x, s.truth.y)),
                Stroke::solid(c.color(), 2),
            )
            .with_label(format!("actual ({name})")),
        );
    }
    let h = autoshovel_core::heading_vec(setup.start.theta) * 1.5;
    fig.push(
        Layer::arrow(
            (setup.start.x, setup.start.y),
            (setup.start.x + h.x, setup.start.y + h.y),
            Stroke::solid(Rgb::GREEN, 3),
        )
        .with_label("start heading"),
    );
    written.plot(
        dir,
        write_figure(&fig, dir, "track_path").context("path plot")?,
    );
    // Deviation and heading against time.
    let mut dev = Figure::new(
        "Centroid deviation (true, signed, left positive)",
        "time [s]",
        "deviation [m]",
    );
    let mut head = Figure::new(
        "Heading of motion minus path tangent",
        "time [s]",
        "heading error [deg]",
    );
    for (c, name, run, _) in runs {
        dev.push(
            Layer::line(
                run.samples.iter().map(|s| (s.t_s, s.centroid_dev_m)),
                Stroke::solid(c.color(), 2),
            )
            .with_label(*name),
        );
        head.push(
            Layer::line(
                run.samples
                    .iter()
                    .map(|s| (s.t_s, s.heading_error_rad.to_degrees())),
                Stroke::solid(c.color(), 2),
            )
            .with_label(*name),
        );
    }
    written.plot(
        dir,
        write_panels(&[dev, head], dir, "track_deviation_heading").context("deviation plot")?,
    );
    // Samples of each run.
    for (_, name, run, _) in runs {
        let path = dir.join(if compare {
            format!("track_{name}.csv")
        } else {
            "track.csv".to_string()
        });
        write_csv(
            &path,
            &[
                "t_s",
                "leg",
                "x_m",
                "y_m",
                "heading_deg",
                "x_meas_m",
                "y_meas_m",
                "heading_meas_deg",
                "centroid_dev_m",
                "heading_error_deg",
                "d_m",
                "d0_m",
                "speed_ref_mps",
                "steer_rpm",
                "left_rpm_cmd",
                "right_rpm_cmd",
                "travelled_m",
            ],
            run.samples.iter().map(|s| {
                vec![
                    s.t_s,
                    s.leg as f64,
                    s.truth.x,
                    s.truth.y,
                    s.truth.theta.to_degrees(),
                    s.measured.x,
                    s.measured.y,
                    s.measured.theta.to_degrees(),
                    s.centroid_dev_m,
                    s.heading_error_rad.to_degrees(),
                    s.d_m,
                    s.d0_m,
                    s.speed_ref_mps,
                    s.steer_rpm,
                    s.command.left_rpm,
                    s.command.right_rpm,
                    s.travelled_m,
                ]
            }),
        )?;
        written.file(dir, &path);
    }
    if compare {
        let path = dir.join("compare.csv");
        let cells: Vec<Vec<String>> = runs
            .iter()
            .map(|(_, name, run, _)| {
                let m = run.metrics;
                vec![
                    name.to_string(),
                    format!("{}", m.reached_distance_m),
                    format!("{}", m.convergence_distance_m),
                    format!("{}", m.max_centroid_dev_m),
                    format!("{}", m.mean_centroid_dev_m),
                    format!("{}", m.rms_centroid_dev_m),
                    format!("{}", m.final_heading_error_deg),
                    format!("{}", m.final_position_error_m),
                    m.completed.to_string(),
                ]
            })
            .collect();
        write_csv_cells(
            &path,
            &[
                "controller",
                "reached_distance_m",
                "convergence_distance_m",
                "max_centroid_dev_m",
                "mean_centroid_dev_m",
                "rms_centroid_dev_m",
                "final_heading_error_deg",
                "final_position_error_m",
                "completed",
            ],
            &cells,
        )?;
        written.file(dir, &path);
    }
    // The fuzzy control surface, when the fuzzy tracker ran.
    if runs.iter().any(|r| r.0 == ControllerArg::Fuzzy) {
        let sys = autoshovel_track::fuzzy_tracker::table1_system()?;
        let surf = sys.surface(61, 61)?;
        let path = dir.join("fuzzy_surface.csv");
        std::fs::write(&path, surf.to_csv())
            .with_context(|| format!("writing {}", path.display()))?;
        written.file(dir, &path);
        let map = Heatmap::new(
            "Fuzzy control surface u(e, ec) of Table 1",
            "e (fuzzy universe)",
            "ec (fuzzy universe)",
            surf.xs.clone(),
            surf.ys.clone(),
            surf.z.clone(),
        )
        .z_label("u [rpm]");
        written.plot(dir, write_heatmap(&map, dir, "fuzzy_surface")?);
    }
    Ok(())
}
