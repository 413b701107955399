//! Files of `autoshovel perceive`: the cleaned cloud (`cleaned.pcd`), the
//! fitted surface on a grid (`surface_grid.csv`), the 8 × 8 samples with
//! their residuals (`fit_samples.csv`), the height map, the residuals and a
//! side view with the fitted profile.

use std::path::Path;

use autoshovel_point_cloud::io::{write as write_cloud, Encoding};
use autoshovel_report::{
    write_csv, write_figure, write_heatmap, Figure, Heatmap, Layer, Rgb, Stroke, Written,
};
use autoshovel_terrain::perceive::Perceived;

use crate::FiguresError;

/// Writes the files of a perception run into `dir`.
pub fn write(dir: &Path, got: &Perceived, written: &mut Written) -> Result<(), FiguresError> {
    let (cloud, fit) = (&got.cloud, &got.fit);
    let cleaned = dir.join("cleaned.pcd");
    write_cloud(&cleaned, cloud, Encoding::Binary)?;
    written.file(dir, &cleaned);
    let map = fit.grid(60, 60);
    let grid = dir.join("surface_grid.csv");
    write_csv(
        &grid,
        &["x_m", "y_m", "z_m"],
        (0..map.ys.len())
            .flat_map(|iy| (0..map.xs.len()).map(move |ix| (ix, iy)))
            .map(|(ix, iy)| vec![map.xs[ix], map.ys[iy], map.at(ix, iy)]),
    )?;
    written.file(dir, &grid);
    let samples = dir.join("fit_samples.csv");
    write_csv(
        &samples,
        &["ix", "iy", "x_m", "y_m", "z_m", "fitted_m", "residual_m"],
        fit.samples.iter().zip(&fit.residuals_m).map(|(s, r)| {
            vec![
                s.ix as f64,
                s.iy as f64,
                s.x_m,
                s.y_m,
                s.z_m,
                fit.height(s.x_m, s.y_m),
                *r,
            ]
        }),
    )?;
    written.file(dir, &samples);
    let z: Vec<Vec<f64>> = (0..map.ys.len())
        .map(|iy| (0..map.xs.len()).map(|ix| map.at(ix, iy)).collect())
        .collect();
    let mut hm = Heatmap::new(
        format!(
            "Fitted surface z = f(x, y) (degree {}, R² {:.4})",
            fit.degree, fit.r2
        ),
        "x [m]",
        "y [m]",
        map.xs.clone(),
        map.ys.clone(),
        z,
    )
    .z_label("height [m]")
    .equal_aspect();
    hm = hm.layer(
        Layer::points(fit.samples.iter().map(|s| (s.x_m, s.y_m)), Rgb::BLACK, 3)
            .with_label("8 × 8 samples"),
    );
    written.plot(dir, write_heatmap(&hm, dir, "height_map")?);
    // Residuals at the samples.
    let mut res = Figure::new(
        "Fit residuals at the grid samples",
        "sample",
        "residual [m]",
    );
    res.push(
        Layer::points(
            fit.residuals_m
                .iter()
                .enumerate()
                .map(|(i, r)| (i as f64, *r)),
            Rgb::RED,
            4,
        )
        .with_label("residual"),
    );
    res.push(Layer::line(
        [(0.0, 0.0), (fit.residuals_m.len() as f64, 0.0)],
        Stroke::dashed(Rgb::GREY, 1),
    ));
    written.plot(dir, write_figure(&res, dir, "residuals")?);
    // Side view: cleaned points (thinned) and the fitted profile at the middle y.
    let step = (cloud.len() / 20_000).max(1);
    let ymid = 0.5 * (map.ys[0] + map.ys[map.ys.len() - 1]);
    let mut side = Figure::new(
        "Side view: cleaned points and the fitted profile at mid-width",
        "x [m]",
        "z [m]",
    )
    .equal_aspect();
    side.push(
        Layer::points(
            cloud
                .points
                .iter()
                .step_by(step)
                .map(|p| (f64::from(p[0]), f64::from(p[2]))),
            Rgb::GREY,
            1,
        )
        .with_label("cleaned points"),
    );
    side.push(
        Layer::line(
            map.xs.iter().map(|&x| (x, fit.height(x, ymid))),
            Stroke::solid(Rgb::RED, 2),
        )
        .with_label("fitted profile"),
    );
    written.plot(dir, write_figure(&side, dir, "profile")?);
    Ok(())
}
