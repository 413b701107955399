//! Figures and tables of the `track` job, built from
//! [`Tracking`]: the reference and actual paths
//! on the site, deviation and heading error against time, each run's samples
//! (`track.csv`, or `track_<controller>.csv` with `--compare`), the
//! comparison table (`compare.csv`) and, when the fuzzy tracker ran, the
//! control surface of Table 1 (`fuzzy_surface.csv` and its heat map).

use std::path::Path;

use autoshovel_report::{
    write_csv, write_csv_cells, write_figure, write_heatmap, write_panels, Figure, Heatmap, Layer,
    ReportError, Rgb, Stroke, Written,
};
use autoshovel_walk_tracker::{ControllerKind, ControllerRun, TrackScenario, Tracking};

use crate::map::{heading_arrow, map_figure};

/// Grid of the fuzzy control surface (points per input).
pub const SURFACE_GRID: usize = 61;

/// The colour of a controller's lines.
pub fn color(kind: ControllerKind) -> Rgb {
    match kind {
        ControllerKind::Fuzzy => Rgb::RED,
        ControllerKind::Pid => Rgb::BLUE,
        ControllerKind::PurePursuit => Rgb::GREEN,
        ControllerKind::Stanley => Rgb::PURPLE,
    }
}

/// Writes every figure and table of a `track` job into `dir`, recording them in `written`.
pub fn write(
    dir: &Path,
    scenario: &TrackScenario,
    tracking: &Tracking,
    written: &mut Written,
) -> Result<(), ReportError> {
    written.plot(
        dir,
        write_figure(&path_figure(scenario, &tracking.runs), dir, "track_path")?,
    );
    written.plot(
        dir,
        write_panels(
            &deviation_heading_panels(&tracking.runs),
            dir,
            "track_deviation_heading",
        )?,
    );
    for r in &tracking.runs {
        let path = dir.join(if tracking.compare {
            format!("track_{}.csv", r.name)
        } else {
            "track.csv".to_string()
        });
        write_samples(&path, r)?;
        written.file(dir, &path);
    }
    if tracking.compare {
        let path = dir.join("compare.csv");
        write_compare(&path, &tracking.runs)?;
        written.file(dir, &path);
    }
    if tracking
        .runs
        .iter()
        .any(|r| r.kind == ControllerKind::Fuzzy)
    {
        write_fuzzy_surface(dir, written)?;
    }
    Ok(())
}

/// The site (when there is one), the reference legs, each run's true path
/// and the start heading.
pub fn path_figure(scenario: &TrackScenario, runs: &[ControllerRun]) -> Figure {
    let title = format!("{}: reference and actual path", scenario.name);
    let mut fig = match &scenario.map {
        Some(map) => map_figure(&title, map),
        None => Figure::new(title, "east x [m]", "north y [m]").equal_aspect(),
    };
    let setup = &scenario.setup;
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
    for r in runs {
        fig.push(
            Layer::line(
                r.run.samples.iter().map(|s| (s.truth.x, s.truth.y)),
                Stroke::solid(color(r.kind), 2),
            )
            .with_label(format!("actual ({})", r.name)),
        );
    }
    fig.push(heading_arrow(setup.start, 1.5, Rgb::GREEN, "start heading"));
    fig
}

/// True signed centroid deviation and heading error against time, one line per run.
pub fn deviation_heading_panels(runs: &[ControllerRun]) -> [Figure; 2] {
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
    for r in runs {
        let stroke = Stroke::solid(color(r.kind), 2);
        dev.push(
            Layer::line(
                r.run.samples.iter().map(|s| (s.t_s, s.centroid_dev_m)),
                stroke,
            )
            .with_label(r.name),
        );
        head.push(
            Layer::line(
                r.run
                    .samples
                    .iter()
                    .map(|s| (s.t_s, s.heading_error_rad.to_degrees())),
                stroke,
            )
            .with_label(r.name),
        );
    }
    [dev, head]
}

/// Columns of a run's samples CSV.
pub const SAMPLE_COLUMNS: [&str; 17] = [
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
];

/// A run's control-tick samples as CSV ([`SAMPLE_COLUMNS`]).
pub fn write_samples(path: &Path, r: &ControllerRun) -> Result<(), ReportError> {
    write_csv(
        path,
        &SAMPLE_COLUMNS,
        r.run.samples.iter().map(|s| {
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
    )
}

/// One line per controller: its metrics.
pub fn write_compare(path: &Path, runs: &[ControllerRun]) -> Result<(), ReportError> {
    let cells: Vec<Vec<String>> = runs
        .iter()
        .map(|r| {
            let m = r.run.metrics;
            vec![
                r.name.to_string(),
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
        path,
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
    )
}

/// The fuzzy control surface u(e, ec) of Table 1: `fuzzy_surface.csv` and its heat map.
pub fn write_fuzzy_surface(dir: &Path, written: &mut Written) -> Result<(), ReportError> {
    let surf = autoshovel_walk_tracker::fuzzy_tracker::table1_system()
        .and_then(|sys| sys.surface(SURFACE_GRID, SURFACE_GRID))
        .expect("Table 1 is a valid two-input rule base and the grid has 61 points");
    let path = dir.join("fuzzy_surface.csv");
    std::fs::write(&path, surf.to_csv()).map_err(|source| ReportError::Io {
        path: path.clone(),
        source,
    })?;
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
    Ok(())
}
