//! Figures and tables of the `plan-excavate` job, built from the planner's
//! [`Excavation`]: `samples.csv` (every executed sample, every field),
//! `contacts.csv`, `planned_path.csv` (the level-1 plan made before any
//! contact) and the plots of the hydraulic-excavator paper's Figs. 5–6:
//! `tooth_path` (ground, boulder envelopes, contacts with V_c and F_f, the
//! planned and the executed path, the level-1 midpoint and end point),
//! `excavator` (the whole front at the start, the first contact and the
//! end), `digging_force` (|F| against time, contacts marked) and `joints`
//! (θ₁, θ₂, θ₃ and the attitude angle φ in degrees, and the Lagrange joint
//! torques).

use std::path::Path;

use autoshovel_excavator_dig::segment::SegmentKind;
use autoshovel_excavator_dig::{
    Backhoe, ContactReport, Excavation, Joints, MachineProfile, Sample, Setup,
};
use autoshovel_report::{
    format_f64, rating_line, time_panel, write_csv, write_csv_cells, write_panels, Figure, Layer,
    ReportError, Rgb, Stroke, Written,
};

/// Length of the V_c and F_f direction arrows drawn at a contact (m).
const ARROW_M: f64 = 0.3;

/// Writes the job's CSV tables and plots of `ex`, planned from `setup`,
/// into `dir`, recording each file in `written`.
pub fn write(
    dir: &Path,
    setup: &Setup,
    ex: &Excavation,
    written: &mut Written,
) -> Result<(), ReportError> {
    let samples = dir.join("samples.csv");
    let rows: Vec<Vec<String>> = ex.samples.iter().map(sample_row).collect();
    write_csv_cells(&samples, &SAMPLE_COLUMNS, &rows)?;
    written.file(dir, &samples);
    let contacts = dir.join("contacts.csv");
    let rows: Vec<Vec<String>> = ex
        .contacts
        .iter()
        .enumerate()
        .map(|(i, c)| contact_row(i, c, ex))
        .collect();
    write_csv_cells(&contacts, &CONTACT_COLUMNS, &rows)?;
    written.file(dir, &contacts);
    let planned = dir.join("planned_path.csv");
    write_csv(
        &planned,
        &["x_m", "y_m"],
        ex.planned_path().iter().map(|p| p.to_vec()),
    )?;
    written.file(dir, &planned);
    let profile = &setup.profile;
    written.plot(
        dir,
        write_panels(&[tooth_path_figure(ex)], dir, "tooth_path")?,
    );
    written.plot(
        dir,
        write_panels(&[excavator_figure(profile, ex)], dir, "excavator")?,
    );
    written.plot(
        dir,
        write_panels(&[force_figure(profile, ex)], dir, "digging_force")?,
    );
    written.plot(dir, write_panels(&joint_figures(ex), dir, "joints")?);
    Ok(())
}

/// The columns of `samples.csv`: every field of [`Sample`], vectors split.
pub const SAMPLE_COLUMNS: [&str; 22] = [
    "t_s",
    "tip_x_m",
    "tip_y_m",
    "theta1_rad",
    "theta2_rad",
    "theta3_rad",
    "theta1_rate_rad_s",
    "theta2_rate_rad_s",
    "theta3_rate_rad_s",
    "attitude_rad",
    "torque1_nm",
    "torque2_nm",
    "torque3_nm",
    "digging_force_x_n",
    "digging_force_y_n",
    "digging_force_magnitude_n",
    "load_kg",
    "swept_volume_m3",
    "segment",
    "kind",
    "contact",
    "attitude_deg",
];

/// One row of `samples.csv` ([`SAMPLE_COLUMNS`]).
pub fn sample_row(s: &Sample) -> Vec<String> {
    let mut row: Vec<String> = [
        s.t_s,
        s.tip_m[0],
        s.tip_m[1],
        s.joints_rad[0],
        s.joints_rad[1],
        s.joints_rad[2],
        s.joint_rates_rad_s[0],
        s.joint_rates_rad_s[1],
        s.joint_rates_rad_s[2],
        s.attitude_rad,
        s.torques_nm[0],
        s.torques_nm[1],
        s.torques_nm[2],
        s.digging_force_n[0],
        s.digging_force_n[1],
        s.digging_force_magnitude_n,
        s.load_kg,
        s.swept_volume_m3,
    ]
    .into_iter()
    .map(format_f64)
    .collect();
    row.push(s.segment.to_string());
    row.push(s.kind.name().to_string());
    row.push(s.contact.to_string());
    row.push(format_f64(s.attitude_rad.to_degrees()));
    row
}

/// The columns of `contacts.csv`: every field of [`ContactReport`], vectors
/// split, with |F_f| and the attitude angle at the contact.
pub const CONTACT_COLUMNS: [&str; 20] = [
    "contact",
    "obstacle",
    "t_s",
    "point_x_m",
    "point_y_m",
    "velocity_x_m_s",
    "velocity_y_m_s",
    "force_x_n",
    "force_y_n",
    "force_magnitude_n",
    "gamma_deg",
    "decision",
    "attitude_deg",
    "measured_force_x_n",
    "measured_force_y_n",
    "estimated_normal_x",
    "estimated_normal_y",
    "estimate_center_x_m",
    "estimate_center_y_m",
    "estimate_radius_m",
];

/// Row of contact `i` (0-based) of `contacts.csv` ([`CONTACT_COLUMNS`]).
pub fn contact_row(i: usize, c: &ContactReport, ex: &Excavation) -> Vec<String> {
    let attitude = ex
        .contact_sample(c)
        .map_or(f64::NAN, |s| s.attitude_rad.to_degrees());
    vec![
        (i + 1).to_string(),
        c.obstacle.to_string(),
        format_f64(c.t_s),
        format_f64(c.point_m[0]),
        format_f64(c.point_m[1]),
        format_f64(c.velocity_m_s[0]),
        format_f64(c.velocity_m_s[1]),
        format_f64(c.force_n[0]),
        format_f64(c.force_n[1]),
        format_f64(c.force_n[0].hypot(c.force_n[1])),
        format_f64(c.gamma_deg),
        c.decision.to_string(),
        format_f64(attitude),
        format_f64(c.measured_force_n[0]),
        format_f64(c.measured_force_n[1]),
        format_f64(c.estimated_normal[0]),
        format_f64(c.estimated_normal[1]),
        format_f64(c.estimated_envelope.center_m[0]),
        format_f64(c.estimated_envelope.center_m[1]),
        format_f64(c.estimated_envelope.radius_m),
    ]
}

fn pt(p: [f64; 2]) -> (f64, f64) {
    (p[0], p[1])
}

/// Bounds (x0, x1, y0, y1) of the dig: every path, boulder and the start.
fn dig_bounds(ex: &Excavation) -> (f64, f64, f64, f64) {
    let mut b = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64, 0.0f64);
    let mut take = |x: f64, y: f64| {
        b.0 = b.0.min(x);
        b.1 = b.1.max(x);
        b.2 = b.2.min(y);
        b.3 = b.3.max(y);
    };
    for p in ex
        .planned_path()
        .iter()
        .chain(ex.samples.iter().map(|s| &s.tip_m))
    {
        take(p[0], p[1]);
    }
    for e in &ex.obstacles {
        let [x, y] = e.center_m;
        take(x - e.radius_m, y - e.radius_m);
        take(x + e.radius_m, y + e.radius_m);
    }
    b
}

/// The ground line from `x0` to `x1`, with its vertices in between.
fn ground_line(ex: &Excavation, x0: f64, x1: f64) -> Layer {
    let mut pts = vec![(x0, ex.ground.height(x0))];
    pts.extend(
        ex.ground
            .points
            .iter()
            .filter(|p| p[0] > x0 && p[0] < x1)
            .map(|p| (p[0], p[1])),
    );
    pts.push((x1, ex.ground.height(x1)));
    Layer::line(pts, Stroke::solid(Rgb::BLACK, 2)).with_label("ground")
}

/// The boulders, the planned and executed paths and the contacts, shared by
/// both dig-plane figures; `detail` adds the legend entries, the search
/// waypoints, the V_c/F_f arrows and the level-1 points' coordinates.
fn dig_layers(ex: &Excavation, x0: f64, x1: f64, detail: bool) -> Vec<Layer> {
    let label = |l: Layer, text: &str| if detail { l.with_label(text) } else { l };
    let mut layers = vec![label(ground_line(ex, x0, x1), "ground")];
    for (i, e) in ex.obstacles.iter().enumerate() {
        let l = Layer::circle(
            pt(e.center_m),
            e.radius_m,
            Some(Rgb::BROWN),
            Stroke::solid(Rgb::BROWN, 1),
        );
        layers.push(if i == 0 {
            label(l, "boulder envelope (unknown to the planner until met)")
        } else {
            l
        });
        if detail {
            layers.push(Layer::text(
                (e.center_m[0] - 0.35 * e.radius_m, e.center_m[1]),
                format!("boulder {i}"),
                Rgb::BLACK,
            ));
        }
    }
    for (i, b) in ex.estimates.iter().enumerate() {
        let e = b.envelope;
        let l = Layer::circle(
            pt(e.center_m),
            e.radius_m,
            None,
            Stroke::dashed(Rgb::RED, 2),
        );
        layers.push(if i == 0 {
            label(l, "boulder as the planner estimated it (from the touches)")
        } else {
            l
        });
    }
    layers.push(label(
        Layer::line(
            ex.planned_path().iter().map(|p| pt(*p)),
            Stroke::dashed(Rgb::GREY, 2),
        ),
        "level-1 plan before any contact",
    ));
    layers.push(label(
        Layer::line(
            ex.samples.iter().map(|s| pt(s.tip_m)),
            Stroke::solid(Rgb::BLUE, 3),
        ),
        "executed tooth path (with re-plans)",
    ));
    // The detours over the executed path, each a run of detour samples.
    let mut first = true;
    let mut run: Vec<(f64, f64)> = Vec::new();
    let mut flush = |run: &mut Vec<(f64, f64)>, layers: &mut Vec<Layer>| {
        if run.len() > 1 {
            let l = Layer::line(run.drain(..), Stroke::solid(Rgb::ORANGE, 4));
            layers.push(if first {
                first = false;
                label(l, "detour (forward search, B-spline smoothed)")
            } else {
                l
            });
        }
        run.clear();
    };
    for s in &ex.samples {
        if s.kind == SegmentKind::Detour {
            run.push(pt(s.tip_m));
        } else {
            flush(&mut run, &mut layers);
        }
    }
    flush(&mut run, &mut layers);
    if detail {
        let waypoints: Vec<(f64, f64)> = ex
            .detours
            .iter()
            .flat_map(|d| d.search.waypoints.iter().map(|p| pt(*p)))
            .collect();
        if !waypoints.is_empty() {
            layers.push(
                Layer::points(waypoints, Rgb::PURPLE, 2).with_label("forward-search grid path"),
            );
        }
    }
    let l1 = &ex.level1;
    layers.push(label(
        Layer::points([pt(l1.start_m), pt(l1.mid_m), pt(l1.end_m)], Rgb::GREEN, 5),
        "level-1 start, midpoint, end point",
    ));
    if detail {
        // The midpoint's label below it, clear of the paths that meet there.
        for (name, p, dy) in [
            ("start", l1.start_m, 0.06),
            ("mid", l1.mid_m, -0.07),
            ("end", l1.end_m, 0.06),
        ] {
            layers.push(Layer::text(
                (p[0] + 0.03, p[1] + dy),
                format!("{name} ({:.2}, {:.2})", p[0], p[1]),
                Rgb::GREEN,
            ));
        }
    }
    for (i, c) in ex.contacts.iter().enumerate() {
        let at = pt(c.point_m);
        layers.push(label(
            Layer::points([at], Rgb::RED, 6),
            &format!(
                "contact {}: t = {:.2} s, γ = {:.1}° → {}",
                i + 1,
                c.t_s,
                c.gamma_deg,
                c.decision
            ),
        ));
        if detail {
            for (v, color, what) in [
                (c.velocity_m_s, Rgb::BLACK, "tip velocity V_c"),
                (c.force_n, Rgb::RED, "contact force F_f"),
            ] {
                let n = v[0].hypot(v[1]);
                if n > 0.0 {
                    let to = (at.0 + ARROW_M * v[0] / n, at.1 + ARROW_M * v[1] / n);
                    let l = Layer::arrow(at, to, Stroke::solid(color, 2));
                    layers.push(if i == 0 {
                        l.with_label(format!("{what} (direction)"))
                    } else {
                        l
                    });
                }
            }
        }
    }
    layers
}

/// Figs. 5a/6a: the tooth path round the boulders in the dig plane.
pub fn tooth_path_figure(ex: &Excavation) -> Figure {
    let (bx0, bx1, by0, by1) = dig_bounds(ex);
    let (x0, x1) = (bx0 - 0.3, bx1 + 0.3);
    // Room above the ground for the legend.
    let (y0, y1) = (by0 - 0.15, by1.max(ex.ground.height(bx1)) + 0.7);
    let height = ((1200.0 * (y1 - y0) / (x1 - x0)) as u32 + 120).clamp(420, 900);
    let mut fig = Figure::new(
        format!(
            "Tooth path round the buried boulders ({}): {:.3} m³ of {:.3} m³",
            ex.scenario, ex.achieved_volume_m3, ex.target_volume_m3
        ),
        "x from the slew axis [m]",
        "y above the ground [m]",
    )
    .equal_aspect()
    .x_range(x0, x1)
    .y_range(y0, y1)
    .size(1200, height);
    for l in dig_layers(ex, x0, x1, true) {
        fig.push(l);
    }
    fig
}

/// The front (boom, stick, bucket link) at joint values `q`.
fn front_layers(machine: &Backhoe, q: [f64; 3], color: Rgb, label: String) -> Vec<Layer> {
    let [stick_pin, bucket_pin, tip] = machine.joint_points(&Joints::new(q[0], q[1], q[2]));
    let foot = machine.foot();
    let xy = |v: autoshovel_core::Vec2| (v.x, v.y);
    vec![
        Layer::line([xy(foot), xy(stick_pin)], Stroke::solid(color, 7)).with_label(label),
        Layer::line([xy(stick_pin), xy(bucket_pin)], Stroke::solid(color, 5)),
        Layer::line([xy(bucket_pin), xy(tip)], Stroke::solid(color, 3)),
        Layer::points([xy(foot), xy(stick_pin), xy(bucket_pin)], color, 4),
    ]
}

/// The whole machine in the dig plane: a schematic body at the slew axis,
/// the front at the start, the first contact and the end, and the dig.
pub fn excavator_figure(profile: &MachineProfile, ex: &Excavation) -> Figure {
    let machine = Backhoe::new(profile);
    let g = &profile.geometry;
    let (_, bx1, by0, _) = dig_bounds(ex);
    let reach = g.boom_length_m + g.stick_length_m + g.bucket_tip_radius_m;
    let x0 = (-2.2f64).min(g.boom_foot_x_m - 1.0);
    let x1 = bx1.max(g.boom_foot_x_m + 0.6 * reach) + 0.4;
    let mut fig = Figure::new(
        format!(
            "The excavator at the start, the first contact and the end ({})",
            ex.scenario
        ),
        "x from the slew axis [m]",
        "y above the ground [m]",
    )
    .equal_aspect()
    .size(1200, 640);
    // Schematic body (not to scale): crawler and upper structure round the slew axis.
    let hb = g.boom_foot_height_m;
    fig.push(
        Layer::polygon(
            [(-1.8, 0.0), (1.8, 0.0), (1.8, 0.8), (-1.8, 0.8)],
            Some(Rgb::GREY),
            Stroke::solid(Rgb::GREY, 1),
        )
        .with_label("crawler and upper structure (schematic)"),
    );
    fig.push(Layer::polygon(
        [
            (-1.6, 0.85),
            (g.boom_foot_x_m + 0.5, 0.85),
            (g.boom_foot_x_m + 0.5, hb + 0.7),
            (-1.6, hb + 0.7),
        ],
        Some(Rgb::GREY),
        Stroke::solid(Rgb::GREY, 1),
    ));
    for l in dig_layers(ex, x0, x1, false) {
        fig.push(l);
    }
    let mut poses: Vec<(&Sample, Rgb, String)> = Vec::new();
    if let Some(s) = ex.samples.first() {
        poses.push((
            s,
            Rgb::BLUE,
            format!("front at the start, t = {:.2} s", s.t_s),
        ));
    }
    if let Some(s) = ex.contacts.first().and_then(|c| ex.contact_sample(c)) {
        poses.push((
            s,
            Rgb::RED,
            format!("at the first contact, t = {:.2} s", s.t_s),
        ));
    }
    if let Some(s) = ex.samples.last() {
        poses.push((s, Rgb::GREEN, format!("at the end, t = {:.2} s", s.t_s)));
    }
    for (s, color, label) in poses {
        for l in front_layers(&machine, s.joints_rad, color, label) {
            fig.push(l);
        }
    }
    fig.x_range = Some((x0, x1));
    fig.y_range = Some((by0 - 0.3, hb + 0.45 * reach));
    fig
}

/// A vertical dashed line at each contact from `lo` to `hi`.
fn contact_marks(ex: &Excavation, lo: f64, hi: f64) -> Vec<Layer> {
    ex.contacts
        .iter()
        .enumerate()
        .map(|(i, c)| {
            Layer::line([(c.t_s, lo), (c.t_s, hi)], Stroke::dashed(Rgb::RED, 2)).with_label(
                format!(
                    "contact {} at {:.2} s (γ {:.1}°, {})",
                    i + 1,
                    c.t_s,
                    c.gamma_deg,
                    c.decision
                ),
            )
        })
        .collect()
}

/// Figs. 5b/6b: the digging force against time, its jump at each contact.
pub fn force_figure(profile: &MachineProfile, ex: &Excavation) -> Figure {
    let rating_kn = profile.force.max_digging_force_n / 1e3;
    let peak_kn = ex
        .samples
        .iter()
        .map(|s| s.digging_force_magnitude_n / 1e3)
        .fold(rating_kn, f64::max);
    let t_end = ex.duration_s;
    let mut fig = Figure::new(
        format!("Digging force on the tooth ({})", ex.scenario),
        "time [s]",
        "|F| [kN]",
    )
    .size(1000, 520)
    .y_range(0.0, 1.1 * peak_kn);
    fig.push(rating_line(
        rating_kn,
        (0.0, t_end),
        Rgb::GREY,
        "machine's digging force rating",
    ));
    for l in contact_marks(ex, 0.0, 1.1 * peak_kn) {
        fig.push(l);
    }
    fig.push(
        Layer::line(
            ex.samples
                .iter()
                .map(|s| (s.t_s, s.digging_force_magnitude_n / 1e3)),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("digging resistance |F| (soil; boulder at a contact)"),
    );
    let jumps: Vec<(f64, f64)> = ex
        .samples
        .iter()
        .filter(|s| s.contact)
        .map(|s| (s.t_s, s.digging_force_magnitude_n / 1e3))
        .collect();
    if !jumps.is_empty() {
        fig.push(Layer::points(jumps, Rgb::RED, 5));
    }
    fig
}

/// Figs. 5c/6c: joint angles and the attitude angle (deg), and the joint torques.
pub fn joint_figures(ex: &Excavation) -> Vec<Figure> {
    let name = &ex.scenario;
    let series = |f: &dyn Fn(&Sample) -> f64| -> Vec<(f64, f64)> {
        ex.samples.iter().map(|s| (s.t_s, f(s))).collect()
    };
    let deg = |i: usize| move |s: &Sample| s.joints_rad[i].to_degrees();
    let angles = [
        (series(&deg(0)), Rgb::BLUE, "boom θ₁"),
        (series(&deg(1)), Rgb::ORANGE, "stick θ₂"),
        (series(&deg(2)), Rgb::GREEN, "bucket θ₃"),
        (
            series(&|s: &Sample| s.attitude_rad.to_degrees()),
            Rgb::PURPLE,
            "attitude φ = θ₁ + θ₂ + θ₃",
        ),
    ];
    let a = time_panel(
        format!("Joint angles and attitude angle ({name})"),
        "angle [deg]",
        (560, 0.45),
        angles,
        |lo, hi| contact_marks(ex, lo, hi),
    );
    let knm = |i: usize| move |s: &Sample| s.torques_nm[i] / 1e3;
    let torques = [
        (series(&knm(0)), Rgb::BLUE, "boom τ₁"),
        (series(&knm(1)), Rgb::ORANGE, "stick τ₂"),
        (series(&knm(2)), Rgb::GREEN, "bucket τ₃"),
    ];
    let t = time_panel(
        format!("Joint torques, Lagrange dynamics ({name})"),
        "torque [kN·m]",
        (460, 0.35),
        torques,
        |lo, hi| contact_marks(ex, lo, hi),
    );
    vec![a, t]
}
