//! Dig-plane drawings of the rope shovel and its pile (our reading of the
//! rope-shovel paper's Fig. 2, which the text lacks).

use autoshovel_report::{Layer, Rgb, Stroke};
use autoshovel_rope_shovel_dig::{DigSurface, Joints, MachineProfile, RopeShovel};

fn pt(p: [f64; 2]) -> (f64, f64) {
    (p[0], p[1])
}

/// The fixed part of the rope shovel in the dig plane: boom from the foot A
/// to the boom point sheave centre B, the sheave (radius R1), the saddle
/// block centre O on the boom, each named.
pub fn shovel_frame_layers(shovel: &RopeShovel) -> Vec<Layer> {
    let g = &shovel.geometry;
    let o = (g.l1, g.l2);
    let (a, b) = (pt(g.boom_foot), pt(g.sheave));
    let at = |p: (f64, f64)| (p.0 + 0.02, p.1 + 0.015);
    vec![
        Layer::line([a, b], Stroke::solid(Rgb::BLACK, 5)).with_label("boom A–B"),
        Layer::circle(b, g.sheave_radius, None, Stroke::solid(Rgb::BLACK, 2))
            .with_label("boom point sheave (R1)"),
        Layer::points([a, b, o], Rgb::BLACK, 5),
        Layer::text(at(a), "A boom foot", Rgb::BLACK),
        Layer::text(at(b), "B sheave", Rgb::BLACK),
        Layer::text(at(o), "O saddle", Rgb::BLACK),
    ]
}

/// The moving part at joint values `q`: the handle on its axis (a rod of
/// length L_d ending at the dipper), the dipper (from the tooth tip D back
/// L_c along the handle, l₃ deep), the bail pin C and the hoist rope from C
/// to where it leaves the sheave. `label` names the pose in the legend;
/// `names` adds the C and D letters.
pub fn shovel_pose_layers(
    shovel: &RopeShovel,
    profile: &MachineProfile,
    q: Joints,
    color: Rgb,
    label: &str,
    names: bool,
) -> Vec<Layer> {
    let g = &shovel.geometry;
    let (u, _) = autoshovel_rope_shovel_dig::kinematics::handle_axes(q.theta1);
    let o = [g.l1, g.l2];
    let along = |d: f64| [o[0] + d * u[0], o[1] + d * u[1]];
    let reach = q.d2 + g.d20;
    let tip = shovel.forward(q);
    let foot = along(reach);
    let back = |p: [f64; 2]| {
        let l = profile.dipper.length_m;
        (p[0] - l * u[0], p[1] - l * u[1])
    };
    let mut layers = vec![
        Layer::line(
            [pt(along(reach - g.handle_length)), pt(foot)],
            Stroke::solid(color, 4),
        )
        .with_label(format!("handle, {label}")),
        Layer::polygon(
            [pt(foot), pt(tip), back(tip), back(foot)],
            Some(color),
            Stroke::solid(color, 2),
        ),
    ];
    let bail = shovel.bail(q);
    if let Some((dir, len)) = shovel.rope(bail) {
        let leave = [bail[0] + len * dir[0], bail[1] + len * dir[1]];
        layers.push(
            Layer::line([pt(bail), pt(leave)], Stroke::dashed(color, 2))
                .with_label(format!("hoist rope C–sheave, {label}")),
        );
    }
    layers.push(Layer::points([pt(bail), pt(tip)], color, 4));
    if names {
        layers.push(Layer::text((bail[0] + 0.02, bail[1]), "C bail", Rgb::BLACK));
        layers.push(Layer::text(
            (tip[0] + 0.02, tip[1] - 0.015),
            "D tooth tip",
            Rgb::BLACK,
        ));
    }
    layers
}

/// The pile in the dig plane from `x0` to `x1`: the width-averaged profile
/// filled down to the floor, the floor line, and the ideal face at the
/// repose angle `alpha_deg` from the toe up to the pile's top.
pub fn pile_layers(surface: &DigSurface, x0: f64, x1: f64, alpha_deg: f64) -> Vec<Layer> {
    let line = surface.polyline(x0, x1, 0.002);
    let mut outline: Vec<(f64, f64)> = line.iter().map(|p| (p[0], p[1])).collect();
    outline.push((x1, 0.0));
    outline.push((x0, 0.0));
    let top = surface.top();
    let run = top / alpha_deg.to_radians().tan();
    vec![
        Layer::polygon(outline, Some(Rgb::BROWN), Stroke::solid(Rgb::BROWN, 1)),
        Layer::line(
            line.iter().map(|p| (p[0], p[1])),
            Stroke::solid(Rgb::BROWN, 2),
        )
        .with_label("pile surface (mean across the dipper)"),
        Layer::line([(x0, 0.0), (x1, 0.0)], Stroke::solid(Rgb::GREY, 1)),
        Layer::line([(0.0, 0.0), (run, top)], Stroke::dashed(Rgb::GREEN, 2))
            .with_label(format!("ideal {alpha_deg}° face from the toe")),
    ]
}
