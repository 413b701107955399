//! Files of `autoshovel perceive --tiles` besides the cleaned tiles: the
//! survey's height model (`model.csv` and its map), each stage's count and
//! time (`stages.csv` and a plot).

use std::path::Path;

use autoshovel_report::{write_csv, write_figure, Figure, Layer, Rgb, Stroke, Written};
use autoshovel_terrain::tiles::{TiledPerceived, TiledSummary};

use crate::FiguresError;

/// Writes the files of a tiled run into `dir`.
pub fn write(
    dir: &Path,
    got: &TiledPerceived,
    summary: &TiledSummary,
    written: &mut Written,
) -> Result<(), FiguresError> {
    let m = &got.model;
    let model = dir.join("model.csv");
    write_csv(
        &model,
        &["x_m", "y_m", "z_m"],
        (0..m.z.len()).filter(|&i| m.seen[i] > 0).map(|i| {
            let [x, y] = m.centre(i);
            vec![x, y, m.z[i]]
        }),
    )?;
    written.file(dir, &model);
    crate::frames::height_map(
        dir,
        m,
        format!(
            "Survey height model: {} points in {} tiles of {:.0} m, {:.2} m cells",
            summary.output_points, summary.tiles_used, summary.tile_m, m.cell_m
        ),
        "model",
        written,
    )?;
    let stages = dir.join("stages.csv");
    write_csv(
        &stages,
        &["stage", "points", "ms", "ns_per_input_point"],
        got.stages.iter().enumerate().map(|(i, s)| {
            vec![
                i as f64,
                s.points as f64,
                s.ms,
                s.ms * 1e6 / got.input_points.max(1) as f64,
            ]
        }),
    )?;
    written.file(dir, &stages);
    let names: Vec<&str> = got.stages.iter().map(|s| s.stage).collect();
    let mut fig = Figure::new(
        format!(
            "Time per stage ({}), {:.1} M points, {:.2} M points/s, peak memory {}",
            names.join(", "),
            got.input_points as f64 / 1e6,
            summary.points_per_s / 1e6,
            summary
                .peak_memory_bytes
                .map_or("unknown".into(), |b| format!(
                    "{:.2} GiB",
                    b as f64 / f64::from(1u32 << 30)
                ))
        ),
        "stage (in the order of the title)",
        "time [s]",
    );
    fig.push(
        Layer::line(
            got.stages
                .iter()
                .enumerate()
                .map(|(i, s)| (i as f64, s.ms / 1e3)),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("wall time"),
    );
    written.plot(dir, write_figure(&fig, dir, "stages")?);
    Ok(())
}
