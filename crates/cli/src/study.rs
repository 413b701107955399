//! `autoshovel study-paths`: the seeded random haul-road study comparing the
//! classic field, the improved field and the Theta* reference.

use std::path::PathBuf;

use anyhow::{bail, Result};
use autoshovel_propel::study::{aggregate, run_map, Aggregate, MapRow, StudyParams};
use autoshovel_report::{write_csv_cells, write_figure, Figure, Layer, Rgb, Stroke};
use indicatif::{ParallelProgressIterator, ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde_json::{json, Value};

use crate::output::{num, prepare_dir, print_json, Written};

/// Arguments of `study-paths`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Number of random maps.
    #[arg(long, default_value_t = 500)]
    pub maps: usize,
    /// Seed of the map generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Fewest obstacles per map.
    #[arg(long, default_value_t = 3)]
    pub min_obstacles: usize,
    /// Most obstacles per map.
    #[arg(long, default_value_t = 12)]
    pub max_obstacles: usize,
    /// Write summary.json, maps.csv and plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs the study as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let params = StudyParams {
        maps: args.maps,
        seed: args.seed,
        min_obstacles: args.min_obstacles,
        max_obstacles: args.max_obstacles,
        ..Default::default()
    };
    let out = args.out.as_deref().map(prepare_dir).transpose()?;
    let (summary, _) = study(&params, out.as_deref(), !args.json)?;
    if args.json {
        print_json(&summary)?;
    } else {
        crate::say!("{}", markdown_table(&summary));
        if let Some(dir) = &out {
            crate::say!("wrote {}", dir.display());
        }
    }
    Ok(())
}

/// Runs the study; writes outputs into `out` if given.
pub fn study(
    params: &StudyParams,
    out: Option<&std::path::Path>,
    progress: bool,
) -> Result<(Value, Written)> {
    if params.maps == 0 || params.maps > 100_000 {
        bail!("--maps {} must be between 1 and 100000", params.maps);
    }
    if params.min_obstacles > params.max_obstacles || params.max_obstacles > 60 {
        bail!(
            "--min-obstacles {} and --max-obstacles {} must satisfy min <= max <= 60",
            params.min_obstacles,
            params.max_obstacles
        );
    }
    let bar = if progress {
        ProgressBar::new(params.maps as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} maps, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message("planning");
    let rows: Vec<MapRow> = (0..params.maps)
        .into_par_iter()
        .progress_with(bar.clone())
        .map(|i| run_map(params, i))
        .collect();
    bar.finish_and_clear();
    let solved = rows
        .iter()
        .filter(|r| r.reference_length_m.is_some())
        .count();
    let classic = aggregate(&rows, "apf", |r| &r.classic);
    let improved = aggregate(&rows, "improved-apf", |r| &r.improved);
    let agg = |a: &Aggregate| {
        json!({
            "planner": a.planner, "maps": a.maps, "reached_pct": num(a.reached_pct), "success_pct": num(a.success_pct),
            "local_minima": a.local_minima, "other_failures": a.other_failures,
            "mean_length_ratio": num(a.mean_length_ratio), "max_length_ratio": num(a.max_length_ratio),
            "mean_min_clearance_m": num(a.mean_min_clearance_m), "min_min_clearance_m": num(a.min_min_clearance_m),
            "mean_final_heading_error_deg": num(a.mean_final_heading_error_deg), "max_final_heading_error_deg": num(a.max_final_heading_error_deg),
            "maps_with_escapes": a.maps_with_escapes, "mean_plan_time_ms": num(a.mean_plan_time_ms),
        })
    };
    let mut summary = json!({
        "job": "study-paths",
        "command": format!("autoshovel study-paths --maps {} --seed {} --min-obstacles {} --max-obstacles {}", params.maps, params.seed, params.min_obstacles, params.max_obstacles),
        "maps": params.maps,
        "seed": params.seed,
        "heading_tolerance_deg": params.heading_tolerance_deg,
        "reference": { "planner": "theta-star", "solved": solved, "solved_pct": num(100.0 * solved as f64 / params.maps as f64) },
        "planners": [agg(&classic), agg(&improved)],
        "success": true,
    });
    let mut written = Written::default();
    if let Some(dir) = out {
        let csv = dir.join("maps.csv");
        let cell = |v: f64| {
            if v.is_finite() {
                format!("{v}")
            } else {
                String::new()
            }
        };
        let cells: Vec<Vec<String>> = rows
            .iter()
            .map(|r| {
                let mut v = vec![
                    r.index.to_string(),
                    r.obstacles.to_string(),
                    r.reference_length_m.map(cell).unwrap_or_default(),
                ];
                for o in [&r.classic, &r.improved] {
                    v.extend([
                        o.success.to_string(),
                        o.local_minimum.to_string(),
                        cell(o.length_m),
                        cell(o.min_clearance_m),
                        cell(o.final_heading_error_deg),
                        o.escapes.to_string(),
                        o.error.clone().unwrap_or_default(),
                    ]);
                }
                v
            })
            .collect();
        let mut header = vec!["map", "obstacles", "reference_length_m"];
        for p in ["apf", "improved_apf"] {
            for f in [
                "success",
                "local_minimum",
                "length_m",
                "min_clearance_m",
                "final_heading_error_deg",
                "escapes",
                "error",
            ] {
                header.push(Box::leak(format!("{p}_{f}").into_boxed_str()));
            }
        }
        write_csv_cells(&csv, &header, &cells)?;
        written.file(dir, &csv);
        // Success rate by obstacle count.
        let mut fig = Figure::new(
            "Success rate by obstacle count (maps the reference solves)",
            "obstacles on the map",
            "success within heading tolerance [%]",
        )
        .y_range(0.0, 100.0);
        for (name, color, pick) in [("apf", Rgb::BLUE, 0usize), ("improved-apf", Rgb::RED, 1)] {
            let pts: Vec<(f64, f64)> = (params.min_obstacles..=params.max_obstacles)
                .filter_map(|n| {
                    let sel: Vec<&MapRow> = rows
                        .iter()
                        .filter(|r| r.obstacles == n && r.reference_length_m.is_some())
                        .collect();
                    if sel.is_empty() {
                        return None;
                    }
                    let ok = sel
                        .iter()
                        .filter(|r| {
                            if pick == 0 {
                                r.classic.success
                            } else {
                                r.improved.success
                            }
                        })
                        .count();
                    Some((n as f64, 100.0 * ok as f64 / sel.len() as f64))
                })
                .collect();
            fig.push(Layer::line(pts.clone(), Stroke::solid(color, 2)).with_label(name));
            fig.push(Layer::points(pts, color, 4));
        }
        written.plot(dir, write_figure(&fig, dir, "success_by_obstacles")?);
        crate::output::write_job_summary(dir, &mut summary, &mut written)?;
    }
    Ok((summary, written))
}

/// The study's table in Markdown.
pub fn markdown_table(summary: &Value) -> String {
    let f = |v: &Value, d: usize| {
        v.as_f64()
            .map(|x| format!("{x:.d$}"))
            .unwrap_or_else(|| "-".into())
    };
    let mut s = format!(
        "`{}`: the reference (Theta*) solves {} of {} maps.\n\n",
        summary["command"].as_str().unwrap_or(""),
        summary["reference"]["solved"],
        summary["maps"]
    );
    s += "| planner | success (≤ 2°) | reached | local minima | length ratio mean / max | min clearance mean / min [m] | final heading error mean / max [deg] | maps with escapes | plan time mean [ms] |\n";
    s += "|---|---|---|---|---|---|---|---|---|\n";
    if let Some(ps) = summary["planners"].as_array() {
        for p in ps {
            s += &format!(
                "| {} | {} % | {} % | {} | {} / {} | {} / {} | {} / {} | {} | {} |\n",
                p["planner"].as_str().unwrap_or(""),
                f(&p["success_pct"], 1),
                f(&p["reached_pct"], 1),
                p["local_minima"],
                f(&p["mean_length_ratio"], 3),
                f(&p["max_length_ratio"], 3),
                f(&p["mean_min_clearance_m"], 2),
                f(&p["min_min_clearance_m"], 3),
                f(&p["mean_final_heading_error_deg"], 2),
                f(&p["max_final_heading_error_deg"], 2),
                p["maps_with_escapes"],
                f(&p["mean_plan_time_ms"], 2),
            );
        }
    }
    s
}
