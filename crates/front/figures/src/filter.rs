//! Files of `autoshovel filter`: `stages.csv` (each stage with its spec,
//! points in and out and time) and the `stages` plot (points kept and time
//! per stage).

use std::path::Path;

use autoshovel_report::{
    format_f64, write_csv_cells, write_panels, Figure, Layer, Rgb, Stroke, Written,
};
use autoshovel_terrain::chain::StageReport;

use crate::FiguresError;

/// Writes the files of a filter chain into `dir`.
pub fn write(
    dir: &Path,
    stages: &[StageReport],
    written: &mut Written,
) -> Result<(), FiguresError> {
    let csv = dir.join("stages.csv");
    let rows: Vec<Vec<String>> = stages
        .iter()
        .enumerate()
        .map(|(i, s)| {
            vec![
                (i + 1).to_string(),
                s.stage.to_string(),
                s.spec.clone(),
                s.points_in.to_string(),
                s.points_out.to_string(),
                format_f64(s.ms),
            ]
        })
        .collect();
    write_csv_cells(
        &csv,
        &["step", "stage", "spec", "points_in", "points_out", "ms"],
        &rows,
    )?;
    written.file(dir, &csv);
    // Points after each step (step 0: as read), and each stage's time.
    let mut kept = Figure::new("Points after each stage", "step", "points").size(900, 420);
    let first = stages.first().map_or(0, |s| s.points_in);
    let series: Vec<(f64, f64)> = std::iter::once((0.0, first as f64))
        .chain(
            stages
                .iter()
                .enumerate()
                .map(|(i, s)| ((i + 1) as f64, s.points_out as f64)),
        )
        .collect();
    kept.push(Layer::line(series.clone(), Stroke::solid(Rgb::BLUE, 2)).with_label("points"));
    kept.push(Layer::points(series, Rgb::BLUE, 4));
    let mut time = Figure::new("Time per stage", "step", "ms").size(900, 360);
    time.push(
        Layer::points(
            stages
                .iter()
                .enumerate()
                .map(|(i, s)| ((i + 1) as f64, s.ms)),
            Rgb::ORANGE,
            5,
        )
        .with_label(
            stages
                .iter()
                .enumerate()
                .map(|(i, s)| format!("{} {}", i + 1, s.stage))
                .collect::<Vec<_>>()
                .join(", "),
        ),
    );
    written.plot(dir, write_panels(&[kept, time], dir, "stages")?);
    Ok(())
}
