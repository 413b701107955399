//! Map and path figures built from propel's types (like the walking paper's
//! Fig. 4): the site, its roads and obstacles, heading arrows; and the
//! `plan-path` job's files (`path` and `profile` plots, `path.csv`,
//! `raw_path.csv`).

use std::path::Path;

use autoshovel_core::{heading_vec, Pose2, Vec2};
use autoshovel_report::{
    write_csv, write_figure, write_panels, Figure, Layer, ReportError, Rgb, Stroke, Written,
};
use autoshovel_walk_planner::{Direction, Map, Plan, PlanOutcome, Scenario, Shape};

fn xy(v: Vec2) -> (f64, f64) {
    (v.x, v.y)
}

/// The site outline, road boundaries and obstacles (named), in map units.
pub fn map_layers(map: &Map) -> Vec<Layer> {
    let mut layers = Vec::new();
    let (lo, hi) = (map.min, map.max);
    layers.push(Layer::polygon(
        [(lo.x, lo.y), (hi.x, lo.y), (hi.x, hi.y), (lo.x, hi.y)],
        None,
        Stroke::dashed(Rgb::GREY, 1),
    ));
    for (i, b) in map.boundaries.iter().enumerate() {
        let l = Layer::line(
            b.points.iter().map(|p| xy(*p)),
            Stroke::solid(Rgb::BLACK, 2),
        );
        layers.push(if i == 0 {
            l.with_label("road boundary")
        } else {
            l
        });
    }
    for (i, o) in map.obstacles.iter().enumerate() {
        let fill = Some(Rgb::BROWN);
        let (layer, at) = match &o.shape {
            Shape::Circle { center, radius } => (
                Layer::circle(xy(*center), *radius, fill, Stroke::solid(Rgb::BROWN, 1)),
                *center,
            ),
            Shape::Polygon { vertices } => {
                let c = vertices.iter().sum::<Vec2>() / vertices.len() as f64;
                (
                    Layer::polygon(
                        vertices.iter().map(|p| xy(*p)),
                        fill,
                        Stroke::solid(Rgb::BROWN, 1),
                    ),
                    c,
                )
            }
        };
        layers.push(if i == 0 {
            layer.with_label("obstacle")
        } else {
            layer
        });
        layers.push(Layer::text(xy(at), o.name.clone(), Rgb::BLACK));
    }
    layers
}

/// An arrow of `len_m` showing a pose's heading.
pub fn heading_arrow(pose: Pose2, len_m: f64, color: Rgb, label: &str) -> Layer {
    let to = pose.position() + heading_vec(pose.theta) * len_m;
    Layer::arrow((pose.x, pose.y), xy(to), Stroke::solid(color, 3)).with_label(label)
}

/// An empty map figure with the site and its obstacles.
pub fn map_figure(title: &str, map: &Map) -> Figure {
    let mut fig = Figure::new(title, "east x [m]", "north y [m]").equal_aspect();
    for l in map_layers(map) {
        fig.push(l);
    }
    fig
}

/// The `plan-path` map: the site, the Theta* reference (dashed), the raw and
/// smoothed legs (or the point where planning failed) and the start,
/// midpoint and goal headings.
pub fn path_figure(scenario: &Scenario, outcome: &PlanOutcome) -> Figure {
    let title = format!("{} — {}", scenario.name, outcome.options.field.name());
    let mut fig = map_figure(&title, &scenario.map);
    for (i, route) in outcome.reference.iter().flatten().enumerate() {
        let l = Layer::line(
            route.points.iter().map(|p| xy(*p)),
            Stroke::dashed(Rgb::GREY, 1),
        );
        fig.push(if i == 0 {
            l.with_label("Theta* reference")
        } else {
            l
        });
    }
    match &outcome.plan {
        Ok(plan) => {
            for (i, leg) in plan.path.legs.iter().enumerate() {
                let raw = Layer::line(leg.raw.iter().map(|p| xy(*p)), Stroke::solid(Rgb::BLUE, 1));
                fig.push(if i == 0 {
                    raw.with_label("raw APF path")
                } else {
                    raw
                });
                let color = if leg.direction == Direction::Reverse {
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
                fig.push(Layer::points([xy(p)], Rgb::RED, 8).with_label("local minimum / failure"));
            }
        }
    }
    let arrow = 3.0 * scenario.footprint_radius_m;
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
    fig
}

/// Heading, curvature and footprint clearance along a plan, one panel each.
pub fn profile_panels(scenario: &Scenario, plan: &Plan) -> [Figure; 3] {
    let samples: Vec<_> = plan.path.samples().map(|(_, p)| p).collect();
    let goal_deg = scenario.goal.theta.to_degrees();
    let heading = Figure::new(
        "Heading along the path",
        "arc length s [m]",
        "heading [deg]",
    )
    .layer(
        Layer::line(
            samples.iter().map(|p| (p.s_m, p.pose.theta.to_degrees())),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("machine heading"),
    )
    .layer(
        Layer::line(
            [(0.0, goal_deg), (plan.metrics.length_m, goal_deg)],
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
            samples.iter().map(|p| (p.s_m, p.curvature_per_m)),
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
            samples.iter().map(|p| {
                let c = scenario
                    .map
                    .clearance(p.pose.position(), scenario.footprint_radius_m);
                (p.s_m, c)
            }),
            Stroke::solid(Rgb::GREEN, 2),
        )
        .with_label("clearance"),
    );
    [heading, curvature, clearance]
}

/// Writes the `plan-path` files into `dir`: the `path` plot always; with a
/// plan also `path.csv` (leg, direction, s, pose, curvature per sample),
/// `raw_path.csv` (the descent's points) and the `profile` plot.
pub fn write_plan_path(
    dir: &Path,
    scenario: &Scenario,
    outcome: &PlanOutcome,
    written: &mut Written,
) -> Result<(), ReportError> {
    written.plot(
        dir,
        write_figure(&path_figure(scenario, outcome), dir, "path")?,
    );
    let Ok(plan) = &outcome.plan else {
        return Ok(());
    };
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
    written.plot(
        dir,
        write_panels(&profile_panels(scenario, plan), dir, "profile")?,
    );
    Ok(())
}
