//! The `study-paths` job's files and table: `maps.csv` (one row per map),
//! the success-rate-by-obstacle-count plot and the Markdown table printed
//! and shown in the README, all from propel's typed study results.

use std::path::Path;

use autoshovel_report::{
    finite_cell as cell, write_csv_cells, write_figure, Figure, Layer, ReportError, Rgb, Stroke,
    Written,
};
use autoshovel_walk_planner::study::{
    success_by_obstacles, MapRow, StudyParams, StudySummary, FIELDS,
};

/// The per-planner columns of `maps.csv`, each prefixed with the planner
/// (`apf_success`, `improved_apf_success`, ...).
const OUTCOME_COLUMNS: [&str; 7] = [
    "success",
    "local_minimum",
    "length_m",
    "min_clearance_m",
    "final_heading_error_deg",
    "escapes",
    "error",
];

/// Writes `maps.csv` and the `success_by_obstacles` plot into `dir`.
pub fn write_study(
    dir: &Path,
    params: &StudyParams,
    rows: &[MapRow],
    written: &mut Written,
) -> Result<(), ReportError> {
    let csv = dir.join("maps.csv");
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut v = vec![
                r.index.to_string(),
                r.obstacles.to_string(),
                r.reference_length_m.map(cell).unwrap_or_default(),
            ];
            for field in FIELDS {
                let o = r.outcome(field);
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
    let mut header: Vec<String> = ["map", "obstacles", "reference_length_m"]
        .map(String::from)
        .to_vec();
    for field in FIELDS {
        let prefix = field.name().replace('-', "_");
        header.extend(OUTCOME_COLUMNS.iter().map(|c| format!("{prefix}_{c}")));
    }
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    write_csv_cells(&csv, &header, &cells)?;
    written.file(dir, &csv);

    let mut fig = Figure::new(
        "Success rate by obstacle count (maps the reference solves)",
        "obstacles on the map",
        "success within heading tolerance [%]",
    )
    .y_range(0.0, 100.0);
    for (field, color) in FIELDS.into_iter().zip([Rgb::BLUE, Rgb::RED]) {
        let pts: Vec<(f64, f64)> = success_by_obstacles(params, rows, field)
            .into_iter()
            .map(|(n, pct)| (n as f64, pct))
            .collect();
        fig.push(Layer::line(pts.clone(), Stroke::solid(color, 2)).with_label(field.name()));
        fig.push(Layer::points(pts, color, 4));
    }
    written.plot(dir, write_figure(&fig, dir, "success_by_obstacles")?);
    Ok(())
}

/// The study's table in Markdown (the README's), read from the summary's
/// fields; the success column names the tolerance the study used.
pub fn markdown_table(summary: &StudySummary) -> String {
    let f = |x: f64, d: usize| {
        if x.is_finite() {
            format!("{x:.d$}")
        } else {
            "-".into()
        }
    };
    let success = format!("success (≤ {}°)", summary.heading_tolerance_deg);
    let header = [
        "planner",
        success.as_str(),
        "reached",
        "local minima",
        "length ratio mean / max",
        "min clearance mean / min [m]",
        "final heading error mean / max [deg]",
        "maps with escapes",
        "plan time mean [ms]",
    ];
    let rows = summary.planners.iter().map(|p| {
        vec![
            p.planner.to_string(),
            format!("{} %", f(p.success_pct, 1)),
            format!("{} %", f(p.reached_pct, 1)),
            p.local_minima.to_string(),
            format!(
                "{} / {}",
                f(p.mean_length_ratio, 3),
                f(p.max_length_ratio, 3)
            ),
            format!(
                "{} / {}",
                f(p.mean_min_clearance_m, 2),
                f(p.min_min_clearance_m, 3)
            ),
            format!(
                "{} / {}",
                f(p.mean_final_heading_error_deg, 2),
                f(p.max_final_heading_error_deg, 2)
            ),
            p.maps_with_escapes.to_string(),
            f(p.mean_plan_time_ms, 2),
        ]
    });
    format!(
        "`{}`: the reference (Theta*) solves {} of {} maps.\n\n{}",
        summary.command,
        summary.reference.solved,
        summary.maps,
        autoshovel_report::markdown_table(&header, rows)
    )
}
