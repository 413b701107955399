//! The `study-boulders` job's files and table: `cases.csv` (one row per
//! boulder, every planner's outcome), the volume error against the boulder's
//! radius for each planner, and the Markdown table printed and shown in the
//! docs, all from the excavate crate's typed study results.

use std::path::Path;

use autoshovel_excavator_dig::study::{BoulderStudySummary, CaseRow, VARIANTS};
use autoshovel_report::{
    finite_cell as cell, write_csv_cells, write_figure, Figure, Layer, ReportError, Rgb, Stroke,
    Written,
};

/// Writes `cases.csv` and the `volume_error_by_radius` plot into `dir`.
pub fn write_study(
    dir: &Path,
    summary: &BoulderStudySummary,
    rows: &[CaseRow],
    written: &mut Written,
) -> Result<(), ReportError> {
    let csv = dir.join("cases.csv");
    let mut header: Vec<String> = ["case", "center_x_m", "center_y_m", "radius_m"]
        .map(String::from)
        .to_vec();
    for v in VARIANTS {
        let p = v.replace(' ', "_");
        for c in [
            "completed",
            "volume_error",
            "believed_error",
            "contacts",
            "extra_contacts",
            "min_detour_clearance_m",
            "estimated_radius_m",
            "error",
        ] {
            header.push(format!("{p}_{c}"));
        }
    }
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut v = vec![
                r.index.to_string(),
                cell(r.boulder.center_m[0]),
                cell(r.boulder.center_m[1]),
                cell(r.boulder.radius_m),
            ];
            for o in &r.outcomes {
                v.extend([
                    o.completed.to_string(),
                    cell(o.volume_error),
                    cell(o.believed_error),
                    o.contacts.to_string(),
                    o.extra_contacts.to_string(),
                    cell(o.min_detour_clearance_m),
                    cell(o.estimated_radius_m),
                    o.error.clone().unwrap_or_default(),
                ]);
            }
            v
        })
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    write_csv_cells(&csv, &header, &cells)?;
    written.file(dir, &csv);

    let mut fig = Figure::new(
        format!(
            "Volume error against the boulder's size ({}, {} boulders, seed {})",
            summary.scenario, summary.params.cases, summary.params.seed
        ),
        "boulder radius [m]",
        "(achieved − target) / target [%]",
    );
    let (mut lo, mut hi) = (-2.0f64, 2.0f64);
    for (v, color) in (0..VARIANTS.len()).zip([Rgb::RED, Rgb::BLUE]) {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.outcomes[v].completed)
            .map(|r| (r.boulder.radius_m, 100.0 * r.outcomes[v].volume_error))
            .collect();
        for p in &pts {
            lo = lo.min(p.1);
            hi = hi.max(p.1);
        }
        fig.push(Layer::points(pts, color, 4).with_label(VARIANTS[v]));
    }
    let r = summary.class_radius_m;
    fig.push(
        Layer::line([(r, lo), (r, hi)], Stroke::dashed(Rgb::GREY, 2))
            .with_label("class prior radius (30 % of the bucket)"),
    );
    written.plot(dir, write_figure(&fig, dir, "volume_error_by_radius")?);
    Ok(())
}

/// The study's table in Markdown, read from the summary's fields.
pub fn markdown_table(summary: &BoulderStudySummary) -> String {
    let f = |x: f64, d: usize| {
        if x.is_finite() {
            format!("{x:.d$}")
        } else {
            "-".into()
        }
    };
    let header = [
        "planner",
        "completed",
        "abs. volume error median / p90",
        "within 2 %",
        "contacts per dig",
        "second touch",
        "least detour clearance [m]",
    ];
    let rows = summary.planners.iter().map(|p| {
        vec![
            p.planner.to_string(),
            format!("{} %", f(p.completed_pct, 1)),
            format!(
                "{} % / {} %",
                f(p.median_abs_volume_error_pct, 1),
                f(p.p90_abs_volume_error_pct, 1)
            ),
            format!("{} %", f(p.within_2pct, 1)),
            f(p.mean_contacts, 2),
            format!("{} %", f(p.extra_contact_pct, 1)),
            f(p.min_detour_clearance_m, 3),
        ]
    });
    format!(
        "{} boulders of radius {}–{} m on `{}`'s path (seed {}); class prior radius {} m.\n\n{}",
        summary.params.cases,
        f(summary.params.radius_m[0], 2),
        f(summary.params.radius_m[1], 2),
        summary.scenario,
        summary.params.seed,
        f(summary.class_radius_m, 3),
        autoshovel_report::markdown_table(&header, rows)
    )
}
