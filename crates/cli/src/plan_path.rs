//! `autoshovel plan-path`: travel planning with the classic or improved
//! potential field on a built-in or user scenario (SPEC §2, §6).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use autoshovel_core::Vec2;
use autoshovel_propel::{
    astar, plan_path, AstarParams, FieldKind, Plan, PlanOptions, PropelError, Scenario,
};
use autoshovel_report::{write_csv, write_figure, write_panels, Figure, Layer, Rgb, Stroke};
use serde_json::{json, Value};

use crate::output::{num, prepare_dir, print_json, Written};
use crate::PlannerArg;
use autoshovel_figures::map::{heading_arrow, map_figure};

/// Arguments of `plan-path`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Built-in scenario (straight, straight-reverse, curve, curve-reverse, v-shape) or a TOML file.
    #[arg(long, default_value = "curve")]
    pub scenario: String,
    /// Potential field to descend.
    #[arg(long, value_enum, default_value = "improved-apf")]
    pub planner: PlannerArg,
    /// Write summary.json, CSV and plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
    /// Success needs every leg to end within this of its required heading [deg].
    #[arg(long, default_value_t = 2.0)]
    pub heading_tolerance_deg: f64,
}

/// Result of one plan-path job.
pub struct Job {
    /// The summary.
    pub summary: Value,
    /// Files written (when an output folder was given).
    pub written: Written,
    /// Why the job failed, if it did.
    pub error: Option<String>,
}

/// Runs `plan-path` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let scenario = Scenario::resolve(&args.scenario)?;
    let out = args.out.as_deref().map(prepare_dir).transpose()?;
    if !(args.heading_tolerance_deg.is_finite() && args.heading_tolerance_deg >= 0.0) {
        anyhow::bail!(
            "--heading-tolerance-deg {} must be a non-negative number",
            args.heading_tolerance_deg
        );
    }
    let job = job(
        &scenario,
        args.planner.into(),
        args.heading_tolerance_deg,
        out.as_deref(),
    )?;
    if args.json {
        print_json(&job.summary)?;
    } else {
        print_human(&job.summary);
        if let Some(dir) = &out {
            crate::say!(
                "wrote {} (summary.json, CSV, SVG and PNG plots)",
                dir.display()
            );
        }
    }
    match job.error {
        Some(e) => Err(anyhow::anyhow!(
            "{} could not plan scenario '{}': {e}",
            job.summary["planner"].as_str().unwrap_or("planner"),
            scenario.name
        )),
        None => Ok(()),
    }
}

fn print_human(s: &Value) {
    let f = |k: &str| {
        s[k].as_f64()
            .map(|v| format!("{v:.3}"))
            .unwrap_or_else(|| "-".into())
    };
    crate::say!(
        "{} on {}: {}",
        s["planner"].as_str().unwrap_or(""),
        s["scenario"].as_str().unwrap_or(""),
        if s["success"].as_bool() == Some(true) {
            "success"
        } else {
            "FAILED"
        }
    );
    crate::say!(
        "  length            {} m (reference {} m, ratio {})",
        f("length_m"),
        s["reference"]["length_m"]
            .as_f64()
            .map(|v| format!("{v:.3}"))
            .unwrap_or("-".into()),
        s["reference"]["length_ratio"]
            .as_f64()
            .map(|v| format!("{v:.3}"))
            .unwrap_or("-".into())
    );
    crate::say!("  min clearance     {} m", f("min_clearance_m"));
    crate::say!(
        "  heading error     {} deg at the goal, {} deg at the start",
        f("final_heading_error_deg"),
        f("start_heading_error_deg")
    );
    crate::say!("  max curvature     {} 1/m", f("max_curvature_per_m"));
    crate::say!("  escapes           {}", s["escapes"]);
    crate::say!("  plan time         {} ms", f("plan_time_ms"));
}

/// Plans one scenario, writes the outputs into `out` if given, and returns the summary.
pub fn job(
    scenario: &Scenario,
    field: FieldKind,
    heading_tolerance_deg: f64,
    out: Option<&Path>,
) -> Result<Job> {
    let opts = PlanOptions::new(field);
    let result = plan_path(scenario, &opts);
    // The reference route, leg by leg (heading-free, so a near lower bound on length).
    let mut reference: Option<(f64, Vec<Vec<Vec2>>)> = Some((0.0, Vec::new()));
    for (from, to, _) in scenario.legs() {
        match astar(
            &scenario.map,
            from.position(),
            to.position(),
            scenario.footprint_radius_m,
            &AstarParams::default(),
        ) {
            Ok(r) => {
                if let Some((len, pts)) = reference.as_mut() {
                    *len += r.length_m;
                    pts.push(r.points);
                }
            }
            Err(_) => reference = None,
        }
    }
    let mut summary = match &result {
        Ok(plan) => summary_ok(
            scenario,
            field,
            &opts,
            plan,
            reference.as_ref().map(|r| r.0),
        ),
        Err(e) => summary_err(scenario, field, &opts, e, reference.as_ref().map(|r| r.0)),
    };
    // A path that arrives off its heading would need a turn on the spot: not a success.
    let mut error = result.as_ref().err().map(|e| e.to_string());
    if let Ok(plan) = &result {
        if let Some((i, l)) = plan.legs.iter().enumerate().find(|(_, l)| {
            l.end_heading_error_deg.is_nan() || l.end_heading_error_deg > heading_tolerance_deg
        }) {
            let which = if i + 1 == plan.legs.len() {
                "the goal".to_string()
            } else {
                format!("the midpoint (end of leg {})", i + 1)
            };
            let e = format!(
                "the required heading cannot be met: the path arrives at {which} {:.2} deg off it (tolerance {heading_tolerance_deg} deg); the machine would have to turn on the spot",
                l.end_heading_error_deg
            );
            summary["success"] = json!(false);
            summary["error"] = json!(e);
            error = Some(e);
        }
    }
    summary["heading_tolerance_deg"] = json!(heading_tolerance_deg);
    let mut written = Written::default();
    if let Some(dir) = out {
        write_outputs(
            dir,
            scenario,
            field,
            &result,
            reference.as_ref().map(|r| &r.1),
            &mut written,
        )?;
        crate::output::write_job_summary(dir, &mut summary, &mut written)?;
    }
    Ok(Job {
        summary,
        written,
        error,
    })
}

fn escape_strategy(plan: &Plan) -> Value {
    if plan.metrics.escapes > 0 {
        json!("boundary-following")
    } else {
        Value::Null
    }
}

fn summary_ok(
    scenario: &Scenario,
    field: FieldKind,
    opts: &PlanOptions,
    plan: &Plan,
    reference_m: Option<f64>,
) -> Value {
    let m = &plan.metrics;
    json!({
        "job": "plan-path",
        "scenario": scenario.name,
        "planner": field.name(),
        "success": true,
        "error": Value::Null,
        "length_m": num(m.length_m),
        "min_clearance_m": num(m.min_clearance_m),
        "min_clearance_at_m": [num(m.min_clearance_at[0]), num(m.min_clearance_at[1])],
        "final_heading_error_deg": num(m.final_heading_error_deg),
        "start_heading_error_deg": num(m.start_heading_error_deg),
        "cusp_heading_error_deg": num(m.cusp_heading_error_deg),
        "max_curvature_per_m": num(m.max_curvature_per_m),
        "mean_abs_curvature_per_m": num(m.mean_abs_curvature_per_m),
        "plan_time_ms": num(m.plan_time_ms),
        "iterations": m.iterations,
        "escapes": m.escapes,
        "escape_strategy": escape_strategy(plan),
        "footprint_radius_m": scenario.footprint_radius_m,
        "legs": plan.legs.iter().map(|l| json!({
            "direction": l.direction.name(),
            "length_m": num(l.length_m),
            "raw_length_m": num(l.raw_length_m),
            "iterations": l.iterations,
            "escapes": l.escapes,
            "end_heading_error_deg": num(l.end_heading_error_deg),
            "control_spacing_m": num(l.control_spacing_m),
        })).collect::<Vec<_>>(),
        "reference": {
            "planner": "theta-star",
            "length_m": reference_m.map(num).unwrap_or(Value::Null),
            "length_ratio": reference_m.map(|r| num(m.length_m / r)).unwrap_or(Value::Null),
        },
        "params": { "apf": opts.apf, "smooth": opts.smooth },
    })
}

fn summary_err(
    scenario: &Scenario,
    field: FieldKind,
    opts: &PlanOptions,
    e: &PropelError,
    reference_m: Option<f64>,
) -> Value {
    let at = e.position();
    json!({
        "job": "plan-path",
        "scenario": scenario.name,
        "planner": field.name(),
        "success": false,
        "error": e.to_string(),
        "error_at_m": at.map(|p| json!([p.x, p.y])).unwrap_or(Value::Null),
        "local_minimum": matches!(e, PropelError::LocalMinimum { .. }),
        "length_m": Value::Null,
        "min_clearance_m": Value::Null,
        "final_heading_error_deg": Value::Null,
        "plan_time_ms": Value::Null,
        "escapes": match e { PropelError::LocalMinimum { escapes, .. } => json!(escapes), _ => json!(0) },
        "footprint_radius_m": scenario.footprint_radius_m,
        "reference": {
            "planner": "theta-star",
            "length_m": reference_m.map(num).unwrap_or(Value::Null),
        },
        "params": { "apf": opts.apf, "smooth": opts.smooth },
    })
}

fn write_outputs(
    dir: &Path,
    scenario: &Scenario,
    field: FieldKind,
    result: &Result<Plan, PropelError>,
    reference: Option<&Vec<Vec<Vec2>>>,
    written: &mut Written,
) -> Result<()> {
    let title = format!("{} — {}", scenario.name, field.name());
    let mut fig = map_figure(&title, &scenario.map);
    if let Some(legs) = reference {
        for (i, pts) in legs.iter().enumerate() {
            let l = Layer::line(pts.iter().map(|p| (p.x, p.y)), Stroke::dashed(Rgb::GREY, 1));
            fig.push(if i == 0 {
                l.with_label("Theta* reference")
            } else {
                l
            });
        }
    }
    let arrow = 3.0 * scenario.footprint_radius_m;
    match result {
        Ok(plan) => {
            for (i, leg) in plan.path.legs.iter().enumerate() {
                let raw = Layer::line(
                    leg.raw.iter().map(|p| (p.x, p.y)),
                    Stroke::solid(Rgb::BLUE, 1),
                );
                fig.push(if i == 0 {
                    raw.with_label("raw APF path")
                } else {
                    raw
                });
                let color = if leg.direction == autoshovel_propel::Direction::Reverse {
                    Rgb::PURPLE
                } else {
                    Rgb::RED
                };
                let smooth = Layer::line(
                    leg.points.iter().map(|p| (p.pose.x, p.pose.y)),
                    Stroke::solid(color, 2),
                );
                fig.push(smooth.with_label(format!(
                    "smoothed, leg {} ({})",
                    i + 1,
                    leg.direction.name()
                )));
            }
        }
        Err(e) => {
            if let Some(p) = e.position() {
                fig.push(
                    Layer::points([(p.x, p.y)], Rgb::RED, 8).with_label("local minimum / failure"),
                );
            }
        }
    }
    fig.push(heading_arrow(
        scenario.start,
        arrow,
        Rgb::GREEN,
        "start heading",
    ));
    if let Some(m) = scenario.midpoint {
        fig.push(heading_arrow(m, arrow, Rgb::ORANGE, "midpoint heading"));
    }
    fig.push(heading_arrow(
        scenario.goal,
        arrow,
        Rgb::BLACK,
        "required goal heading",
    ));
    written.plot(
        dir,
        write_figure(&fig, dir, "path").context("writing the path plot")?,
    );

    if let Ok(plan) = result {
        let csv = dir.join("path.csv");
        let rows = plan.path.legs.iter().enumerate().flat_map(|(i, leg)| {
            leg.points.iter().map(move |p| {
                vec![
                    i as f64,
                    leg.direction.sign(),
                    p.s_m,
                    p.pose.x,
                    p.pose.y,
                    p.pose.theta.to_degrees(),
                    p.curvature_per_m,
                ]
            })
        });
        write_csv(
            &csv,
            &[
                "leg",
                "direction",
                "s_m",
                "x_m",
                "y_m",
                "heading_deg",
                "curvature_per_m",
            ],
            rows,
        )?;
        written.file(dir, &csv);
        let raw = dir.join("raw_path.csv");
        let rows = plan
            .path
            .legs
            .iter()
            .enumerate()
            .flat_map(|(i, leg)| leg.raw.iter().map(move |p| vec![i as f64, p.x, p.y]));
        write_csv(&raw, &["leg", "x_m", "y_m"], rows)?;
        written.file(dir, &raw);
        // Heading and curvature along the path.
        let samples: Vec<_> = plan.path.samples().collect();
        let heading = Figure::new(
            "Heading along the path",
            "arc length s [m]",
            "heading [deg]",
        )
        .layer(
            Layer::line(
                samples
                    .iter()
                    .map(|(_, p)| (p.s_m, p.pose.theta.to_degrees())),
                Stroke::solid(Rgb::BLUE, 2),
            )
            .with_label("machine heading"),
        )
        .layer(
            Layer::line(
                [
                    (0.0, scenario.goal.theta.to_degrees()),
                    (plan.metrics.length_m, scenario.goal.theta.to_degrees()),
                ],
                Stroke::dashed(Rgb::BLACK, 1),
            )
            .with_label("required at goal"),
        );
        let curvature = Figure::new(
            "Curvature along the path",
            "arc length s [m]",
            "curvature [1/m]",
        )
        .layer(
            Layer::line(
                samples.iter().map(|(_, p)| (p.s_m, p.curvature_per_m)),
                Stroke::solid(Rgb::RED, 2),
            )
            .with_label("curvature"),
        );
        let clearance = Figure::new(
            "Footprint clearance along the path",
            "arc length s [m]",
            "clearance [m]",
        )
        .layer(
            Layer::line(
                samples.iter().map(|(_, p)| {
                    (
                        p.s_m,
                        scenario
                            .map
                            .clearance(p.pose.position(), scenario.footprint_radius_m),
                    )
                }),
                Stroke::solid(Rgb::GREEN, 2),
            )
            .with_label("clearance"),
        );
        written.plot(
            dir,
            write_panels(&[heading, curvature, clearance], dir, "profile")
                .context("writing the profile plot")?,
        );
    }
    Ok(())
}
