//! Files of `autoshovel perceive` on a folder of frames: one row a frame
//! (`frames.csv`), the running height model (`model.csv`), the last
//! frame's cleaned cloud (`cleaned.pcd`), the latency of every frame and
//! the model's height map.

use std::path::Path;

use autoshovel_point_cloud::io::{write as write_cloud, Encoding};
use autoshovel_report::{
    write_csv, write_figure, write_heatmap, Figure, Heatmap, Layer, Rgb, Stroke, Written,
};
use autoshovel_terrain::frames::{FrameRun, HeightModel};
use autoshovel_terrain::perceive::STAGES;

use crate::FiguresError;

/// Writes the files of a frame sequence's run into `dir`.
pub fn write(dir: &Path, run: &FrameRun, written: &mut Written) -> Result<(), FiguresError> {
    let cleaned = dir.join("cleaned.pcd");
    write_cloud(&cleaned, &run.last.cloud, Encoding::Binary)?;
    written.file(dir, &cleaned);
    // One row a frame; a skipped frame has ok = 0 and NaN times.
    let stage_columns: Vec<String> = STAGES.iter().map(|s| format!("{s}_ms")).collect();
    let mut header = vec![
        "frame",
        "ok",
        "relevelled",
        "input_points",
        "output_points",
        "read_ms",
        "pipeline_ms",
        "model_ms",
        "latency_ms",
    ];
    header.extend(stage_columns.iter().map(String::as_str));
    header.extend(["r2", "model_cells_updated", "model_change_rms_m"]);
    let frames = dir.join("frames.csv");
    write_csv(
        &frames,
        &header,
        run.records.iter().map(|r| {
            let mut row = vec![
                r.index as f64,
                f64::from(u8::from(r.ok)),
                f64::from(u8::from(r.relevelled)),
                r.input_points as f64,
                r.output_points as f64,
                r.read_ms,
                r.pipeline_ms,
                r.model_ms,
                r.latency_ms,
            ];
            row.extend(STAGES.iter().map(|s| {
                r.stages
                    .iter()
                    .find(|x| x.stage == *s)
                    .map_or(f64::NAN, |x| x.ms)
            }));
            row.extend([
                r.r2,
                r.model.map_or(f64::NAN, |m| m.cells_updated as f64),
                r.model.map_or(f64::NAN, |m| m.change_rms_m),
            ]);
            row
        }),
    )?;
    written.file(dir, &frames);
    let m = &run.model;
    let model = dir.join("model.csv");
    write_csv(
        &model,
        &["x_m", "y_m", "z_m", "frames_seen", "last_frame"],
        (0..m.z.len()).filter(|&i| m.seen[i] > 0).map(|i| {
            let [x, y] = m.centre(i);
            vec![x, y, m.z[i], f64::from(m.seen[i]), f64::from(m.last[i])]
        }),
    )?;
    written.file(dir, &model);
    // Latency of every frame, the skipped ones marked.
    let s = &run.summary;
    let mut fig = Figure::new(
        format!(
            "Frame latency: median {:.1} ms, 95 % {:.1} ms ({} of {} frames perceived)",
            s.latency.median_ms, s.latency.p95_ms, s.frames_ok, s.frames
        ),
        "frame",
        "time [ms]",
    );
    let ok = || run.records.iter().filter(|r| r.ok);
    fig.push(
        Layer::line(
            ok().map(|r| (r.index as f64, r.latency_ms)),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("latency (read, pipeline, model)"),
    );
    fig.push(
        Layer::line(
            ok().map(|r| (r.index as f64, r.pipeline_ms)),
            Stroke::solid(Rgb::GREEN, 1),
        )
        .with_label("pipeline"),
    );
    fig.push(
        Layer::points(
            ok().filter(|r| r.relevelled)
                .map(|r| (r.index as f64, r.latency_ms)),
            Rgb::BLACK,
            5,
        )
        .with_label("floor searched, levelled"),
    );
    let skipped: Vec<(f64, f64)> = run
        .records
        .iter()
        .filter(|r| !r.ok)
        .map(|r| (r.index as f64, 0.0))
        .collect();
    if !skipped.is_empty() {
        fig.push(Layer::points(skipped, Rgb::RED, 5).with_label("skipped frame"));
    }
    written.plot(dir, write_figure(&fig, dir, "latency")?);
    // The running model's height map.
    height_map(
        dir,
        m,
        format!(
            "Running height model after {} frames ({:.0} % of cells seen, {:.2} m cells)",
            s.frames_ok,
            100.0 * s.model_coverage,
            m.cell_m
        ),
        "model",
        written,
    )
}

/// Most cells a height map draws (one SVG rectangle each, some 85 bytes):
/// a finer model is drawn in blocks (a 1 km² survey at 1 m cells, 10⁶
/// cells, as 250 × 250 blocks of 4 × 4).
pub const MAX_MAP_CELLS: usize = 65_536;

/// Writes the height map of `m` as `name`.svg/png under `dir`.
pub fn height_map(
    dir: &Path,
    m: &HeightModel,
    title: String,
    name: &str,
    written: &mut Written,
) -> Result<(), FiguresError> {
    // A model finer than the map can draw is drawn in blocks of k × k
    // cells, each the mean of its cells with a height (the CSV keeps
    // every cell).
    let cells = m.size[0].saturating_mul(m.size[1]);
    let k = (1..)
        .find(|k: &usize| cells.div_ceil(k * k) <= MAX_MAP_CELLS)
        .unwrap_or(1);
    let [nx, ny] = [m.size[0].div_ceil(k), m.size[1].div_ceil(k)];
    let block = |bi: usize, bj: usize| {
        let (mut sum, mut n) = (0.0, 0u32);
        for j in bj * k..((bj + 1) * k).min(m.size[1]) {
            for i in bi * k..((bi + 1) * k).min(m.size[0]) {
                let z = m.z[j * m.size[0] + i];
                if z.is_finite() {
                    sum += z;
                    n += 1;
                }
            }
        }
        if n > 0 {
            sum / f64::from(n)
        } else {
            f64::NAN
        }
    };
    let x0 = m.centre(0)[0] - m.cell_m / 2.0;
    let y0 = m.centre(0)[1] - m.cell_m / 2.0;
    let side = m.cell_m * k as f64;
    let xs: Vec<f64> = (0..nx).map(|i| x0 + (i as f64 + 0.5) * side).collect();
    let ys: Vec<f64> = (0..ny).map(|j| y0 + (j as f64 + 0.5) * side).collect();
    let z: Vec<Vec<f64>> = (0..ny)
        .map(|j| (0..nx).map(|i| block(i, j)).collect())
        .collect();
    let title = if k > 1 {
        format!("{title} (drawn in blocks of {k} × {k} cells)")
    } else {
        title
    };
    let hm = Heatmap::new(title, "x [m]", "y [m]", xs, ys, z)
        .z_label("height [m]")
        .equal_aspect();
    written.plot(dir, write_heatmap(&hm, dir, name)?);
    Ok(())
}
