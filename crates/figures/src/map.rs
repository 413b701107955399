//! Map and path figures built from propel's types (like the walking paper's
//! Fig. 4): the site, its roads and obstacles, heading arrows.

use autoshovel_core::{heading_vec, Pose2, Vec2};
use autoshovel_propel::{Map, Shape};
use autoshovel_report::{Figure, Layer, Rgb, Stroke};

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
