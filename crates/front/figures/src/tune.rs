//! The `tune-trackers` job's files and table: `trackers.csv` (one row per
//! tracker: its scores on the training, held-out and unseen runs),
//! `progress.csv` and the `tuning_progress` plot (the best training objective
//! after each evaluation: every tracker had the same budget), and the
//! Markdown table, all from the track crate's typed results.

use std::path::Path;

use autoshovel_report::{
    format_f64, write_csv_cells, write_figure, Figure, Layer, ReportError, Rgb, Stroke, Written,
};
use autoshovel_walk_tracker::tune::{TuneSummary, Tuned};

const COLORS: [Rgb; 7] = [
    Rgb::RED,
    Rgb::ORANGE,
    Rgb::BROWN,
    Rgb::BLUE,
    Rgb::PURPLE,
    Rgb::GREEN,
    Rgb::BLACK,
];

/// Writes the job's tables and plot into `dir`.
pub fn write(
    dir: &Path,
    summary: &TuneSummary,
    tuned: &[Tuned],
    written: &mut Written,
) -> Result<(), ReportError> {
    let csv = dir.join("trackers.csv");
    let mut header = vec!["tracker".to_string(), "evaluations".to_string()];
    for set in ["training", "held_out", "unseen"] {
        for c in [
            "cost",
            "mean_dev_m",
            "max_dev_m",
            "mean_abs_final_heading_deg",
            "completed_pct",
        ] {
            header.push(format!("{set}_{c}"));
        }
    }
    let rows: Vec<Vec<String>> = summary
        .trackers
        .iter()
        .map(|t| {
            let mut v = vec![t.tracker.to_string(), t.evaluations.to_string()];
            for s in [&t.training, &t.held_out, &t.unseen] {
                v.extend(
                    [
                        s.cost,
                        s.mean_dev_m,
                        s.max_dev_m,
                        s.mean_abs_final_heading_deg,
                        s.completed_pct,
                    ]
                    .map(|x| format!("{x}")),
                );
            }
            v
        })
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    write_csv_cells(&csv, &header, &rows)?;
    written.file(dir, &csv);

    let progress = dir.join("progress.csv");
    let rows: Vec<Vec<String>> = tuned
        .iter()
        .flat_map(|t| {
            t.progress
                .iter()
                .enumerate()
                .map(|(k, c)| vec![t.name.to_string(), (k + 1).to_string(), format_f64(*c)])
        })
        .collect();
    write_csv_cells(
        &progress,
        &["tracker", "evaluation", "best_training_cost"],
        &rows,
    )?;
    written.file(dir, &progress);

    let mut fig = Figure::new(
        format!(
            "Tuning on equal terms: best training objective ({} evaluations each, seed {})",
            summary.budget, summary.seed
        ),
        "evaluations of the training set",
        "best objective J so far (log10)",
    );
    for (t, color) in tuned.iter().zip(COLORS) {
        let pts: Vec<(f64, f64)> = t
            .progress
            .iter()
            .enumerate()
            .map(|(k, c)| ((k + 1) as f64, c.max(1e-6).log10()))
            .collect();
        fig.push(Layer::line(pts, Stroke::solid(color, 2)).with_label(t.name));
    }
    written.plot(dir, write_figure(&fig, dir, "tuning_progress")?);
    Ok(())
}

/// The comparison in Markdown, read from the summary.
pub fn markdown_table(summary: &TuneSummary) -> String {
    let header = [
        "tracker",
        "tuned",
        "J training",
        "J held out",
        "J unseen",
        "mean dev held out / unseen [m]",
        "max dev held out / unseen [m]",
        "final heading held out / unseen [deg]",
        "completed unseen",
    ];
    let rows = summary.trackers.iter().map(|t| {
        vec![
            t.tracker.to_string(),
            if t.evaluations > 0 {
                format!("{} evals", t.evaluations)
            } else {
                "as published".into()
            },
            format!("{:.4}", t.training.cost),
            format!("{:.4}", t.held_out.cost),
            format!("{:.4}", t.unseen.cost),
            format!("{:.3} / {:.3}", t.held_out.mean_dev_m, t.unseen.mean_dev_m),
            format!("{:.3} / {:.3}", t.held_out.max_dev_m, t.unseen.max_dev_m),
            format!(
                "{:.2} / {:.2}",
                t.held_out.mean_abs_final_heading_deg, t.unseen.mean_abs_final_heading_deg
            ),
            format!("{:.0} %", t.unseen.completed_pct),
        ]
    });
    format!(
        "Tuned on {} runs ({}), scored on {} held-out runs and {} runs of unseen scenarios.\n\n{}",
        summary.training_runs.len(),
        summary.training_runs.join(", "),
        summary.held_out_runs.len(),
        summary.unseen_runs.len(),
        autoshovel_report::markdown_table(&header, rows)
    )
}
