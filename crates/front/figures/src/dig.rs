//! Figures and tables of `plan-dig` (rope-shovel paper Figs. 13–16 and
//! Tables 4–5), built from `autoshovel_rope_shovel_dig`'s typed results: the CSVs of a
//! plan (`samples.csv`, `convergence.csv`, `polish.csv`, `pack.csv`, `surface.csv`), the
//! plots `dig_path` (tooth path over the pile with the machine at the start
//! and end of the dig: our reading of the paper's missing Fig. 2),
//! `speeds`, `forces` (with the powers) and `convergence`; for
//! `--all-surfaces` one folder per pile, `table.csv`, the `paths` panels
//! and the markdown table.

use std::path::Path;

use autoshovel_report::{
    markdown_table as md_table, rating_line, write_csv, write_csv_cells, write_figure,
    write_job_summary, write_panels, Figure, Layer, Rgb, Stroke, Written,
};
use autoshovel_rope_shovel_dig::{
    write_pack, AllSurfaces, AllSurfacesSummary, ComparedPile, Decision, DigModel, DigPlan,
    DigSample, PlannedPile, TableRow, SAMPLE_COLUMNS, TABLE_COLUMNS,
};

use crate::shovel::{pile_layers, shovel_frame_layers, shovel_pose_layers};

/// Errors of the writers here: a report file or the pack file.
pub type Error = crate::FiguresError;

/// Writes the files of one planned pile into `dir` (nothing but the
/// summary's own file, which the caller writes, when no plan came out).
pub fn write_plan(dir: &Path, planned: &PlannedPile, written: &mut Written) -> Result<(), Error> {
    let Some(plan) = &planned.plan else {
        return Ok(());
    };
    let model = &planned.model;
    let name = &planned.summary.header.surface;
    let samples = dir.join("samples.csv");
    write_samples_csv(&samples, &plan.samples)?;
    written.file(dir, &samples);
    let conv = dir.join("convergence.csv");
    write_csv(
        &conv,
        &[
            "iteration",
            "best_objective",
            "best_violation",
            "mean_objective",
            "feasible_share",
        ],
        plan.search.history.iter().map(|g| {
            vec![
                g.iteration as f64,
                g.best_objective,
                g.best_violation,
                g.mean_objective,
                g.feasible_share,
            ]
        }),
    )?;
    written.file(dir, &conv);
    if let Some(polish) = &plan.polish {
        // The CMA-ES polish of the α wolf, after GWO's evaluations.
        let path = dir.join("polish.csv");
        write_csv(
            &path,
            &["evaluations", "run", "best_objective", "best_violation"],
            polish.history.iter().map(|g| {
                vec![
                    (plan.search.evaluations + g.evaluations) as f64,
                    g.run as f64,
                    g.best_objective,
                    g.best_violation,
                ]
            }),
        )?;
        written.file(dir, &path);
    }
    let pack = dir.join("pack.csv");
    write_pack(&pack, model, &plan.search.population)?;
    written.file(dir, &pack);
    let (x0, x1) = view_x_range(model, &plan.outcome.decision);
    let surface = dir.join("surface.csv");
    write_csv(
        &surface,
        &["x_m", "y_m"],
        model
            .surface
            .polyline(x0, x1, 0.001)
            .into_iter()
            .map(|p| p.to_vec()),
    )?;
    written.file(dir, &surface);
    written.plot(
        dir,
        write_figure(&dig_path_figure(name, model, plan), dir, "dig_path")?,
    );
    let [speeds, forces, powers] = drive_figures(name, model, plan);
    written.plot(dir, write_figure(&speeds, dir, "speeds")?);
    written.plot(dir, write_panels(&[forces, powers], dir, "forces")?);
    written.plot(
        dir,
        write_panels(&convergence_figures(plan, name), dir, "convergence")?,
    );
    Ok(())
}

/// Figs. 13–16 (b)–(d): hoist and crowd speeds, forces (with the digging
/// resistance) and powers against time, with the machine's ratings.
pub fn drive_figures(name: &str, model: &DigModel, plan: &DigPlan) -> [Figure; 3] {
    let l = &model.profile.limits;
    let span = (0.0, plan.outcome.decision.td_s);
    let limit = |v: f64, label: &str| rating_line(v, span, Rgb::GREY, label);
    let series = |f: fn(&DigSample) -> f64| -> Vec<(f64, f64)> {
        plan.samples.iter().map(|s| (s.t_s, f(s))).collect()
    };
    let title = |what: &str| format!("{what} during the dig ({name} pile)");
    let line = |f: fn(&DigSample) -> f64, color: Rgb, label: &str| {
        Layer::line(series(f), Stroke::solid(color, 2)).with_label(label)
    };
    let mut speeds = Figure::new(title("Hoist and crowd speeds"), "time [s]", "speed [m/s]");
    speeds.push(line(
        |s| s.drive.hoist_speed_m_s,
        Rgb::BLUE,
        "hoist rope speed v_h",
    ));
    speeds.push(line(
        |s| s.drive.crowd_speed_m_s,
        Rgb::RED,
        "crowd speed v_c",
    ));
    if (l.hoist_speed_max_m_s - l.crowd_speed_max_m_s).abs() < 1e-12 {
        speeds.push(limit(l.hoist_speed_max_m_s, "speed limit (c8, c10)"));
    } else {
        speeds.push(limit(l.hoist_speed_max_m_s, "hoist speed limit (c8)"));
        speeds.push(limit(l.crowd_speed_max_m_s, "crowd speed limit (c10)"));
    }
    let mut forces =
        Figure::new(title("Hoist and crowd forces"), "time [s]", "force [N]").size(900, 520);
    forces.push(line(
        |s| s.drive.hoist_force_n,
        Rgb::BLUE,
        "hoist rope force F_h",
    ));
    forces.push(line(|s| s.drive.crowd_force_n, Rgb::RED, "crowd force F_c"));
    forces.push(limit(l.hoist_force_max_n, "hoist force rating (c11)"));
    forces.push(limit(l.crowd_force_max_n, "crowd force rating (c12)"));
    forces.push(
        Layer::line(
            series(|s| s.drive.resistance_tangential_n),
            Stroke::dashed(Rgb::BROWN, 2),
        )
        .with_label("digging resistance F_τ"),
    );
    let mut powers =
        Figure::new(title("Hoist and crowd powers"), "time [s]", "power [W]").size(900, 420);
    powers.push(line(|s| s.drive.hoist_power_w(), Rgb::BLUE, "hoist P_h"));
    powers.push(line(|s| s.drive.crowd_power_w(), Rgb::RED, "crowd P_c"));
    if (l.hoist_power_max_w - l.crowd_power_max_w).abs() < 1e-12 {
        powers.push(limit(l.hoist_power_max_w, "power rating (c13, c14)"));
    } else {
        powers.push(limit(l.hoist_power_max_w, "hoist power rating (c13)"));
        powers.push(limit(l.crowd_power_max_w, "crowd power rating (c14)"));
    }
    [speeds, forces, powers]
}

/// Writes every sample of the planned dig to `path` (the columns of
/// [`SAMPLE_COLUMNS`]).
pub fn write_samples_csv(path: &Path, samples: &[DigSample]) -> Result<(), Error> {
    write_csv(
        path,
        &SAMPLE_COLUMNS,
        samples.iter().map(|s| s.csv_row().to_vec()),
    )?;
    Ok(())
}

/// The x range worth drawing: the machine behind the toe to a little past
/// the end of the dig and the top of the ideal face.
fn view_x_range(model: &DigModel, d: &Decision) -> (f64, f64) {
    let g = &model.shovel.geometry;
    let (lo, hi) = model.surface.x_range();
    let alpha = model.profile.geometry.pile_angle_deg.to_radians();
    let x0 = (g.boom_foot[0].min(g.l1) - 0.05).min(lo);
    let want = d.gx_m.max(model.surface.top() / alpha.tan()) + 0.15;
    (x0, want.min(hi).max(d.gx_m))
}

/// Figs. 13–16 (a) with our reading of Fig. 2: the tooth path over the pile
/// and the machine at the start and end of the dig.
pub fn dig_path_figure(name: &str, model: &DigModel, plan: &DigPlan) -> Figure {
    let p = &model.profile;
    let d = &plan.outcome.decision;
    let (x0, x1) = view_x_range(model, d);
    let mut fig = Figure::new(
        format!("Tooth path and the machine at the start and end of the dig ({name} pile)"),
        "x from the toe [m]",
        "y above the floor [m]",
    )
    .equal_aspect()
    .size(1100, 800);
    for l in pile_layers(&model.surface, x0, x1, p.geometry.pile_angle_deg) {
        fig.push(l);
    }
    let h = p.limits.hopper_height_m + p.dipper.height_m;
    fig.push(
        Layer::line([(x0, h), (x1, h)], Stroke::dashed(Rgb::GREY, 1))
            .with_label("c16: end height H_kk + H_cd"),
    );
    for l in shovel_frame_layers(&model.shovel) {
        fig.push(l);
    }
    let (first, last) = (plan.samples.first(), plan.samples.last());
    for (s, color, label, names) in [
        (first, Rgb::BLUE, "start", true),
        (last, Rgb::ORANGE, "end", false),
    ] {
        if let Some(s) = s {
            for l in shovel_pose_layers(&model.shovel, p, s.joints, color, label, names) {
                fig.push(l);
            }
        }
    }
    fig.push(
        Layer::line(
            plan.samples.iter().map(|s| (s.tip_m[0], s.tip_m[1])),
            Stroke::solid(Rgb::RED, 3),
        )
        .with_label(format!(
            "tooth path, t_d = {:.2} s, m_dig = {:.3} kg",
            d.td_s, plan.outcome.m_dig_kg
        )),
    );
    fig
}

/// The optimiser's convergence against evaluations: the best feasible f
/// (α wolf) per GWO iteration, then the CMA-ES polish of it; and the share
/// of feasible wolves.
pub fn convergence_figures(plan: &DigPlan, name: &str) -> Vec<Figure> {
    let h = &plan.search.history;
    // Evaluations after GWO iteration i: one pack per iteration.
    let per_iteration = plan.search.evaluations as f64 / h.len().max(1) as f64;
    let at = |i: usize| per_iteration * (i + 1) as f64;
    let feasible_or_nan = |objective: f64, violation: f64| {
        if violation == 0.0 {
            objective
        } else {
            f64::NAN
        }
    };
    let mut best = Figure::new(
        format!("Dig search convergence ({name} pile)"),
        "evaluations",
        "best objective f",
    )
    .size(900, 520);
    best.push(
        Layer::line(
            h.iter().map(|g| {
                (
                    at(g.iteration),
                    feasible_or_nan(g.best_objective, g.best_violation),
                )
            }),
            Stroke::solid(Rgb::BLUE, 2),
        )
        .with_label("Grey Wolf Optimizer: best feasible f (α wolf)"),
    );
    if let Some(polish) = &plan.polish {
        best.push(
            Layer::line(
                polish.history.iter().map(|g| {
                    (
                        (plan.search.evaluations + g.evaluations) as f64,
                        feasible_or_nan(g.best_objective, g.best_violation),
                    )
                }),
                Stroke::solid(Rgb::ORANGE, 2),
            )
            .with_label("CMA-ES polish of the α wolf"),
        );
    }
    let infeasible: Vec<(f64, f64)> = h
        .iter()
        .filter(|g| g.best_violation > 0.0 && g.best_objective.is_finite())
        .map(|g| (at(g.iteration), g.best_objective))
        .collect();
    if !infeasible.is_empty() {
        best.push(Layer::points(infeasible, Rgb::RED, 4).with_label("best still infeasible"));
    }
    let mut share = Figure::new("Share of feasible wolves", "evaluations", "feasible share")
        .size(900, 360)
        .y_range(0.0, 1.05);
    share.push(
        Layer::line(
            h.iter().map(|g| (at(g.iteration), g.feasible_share)),
            Stroke::solid(Rgb::GREEN, 2),
        )
        .with_label("feasible share"),
    );
    vec![best, share]
}

/// Writes each pile of `all` into `dir/<pile>/` (its files and its own
/// `summary.json`), records the pile's files in its comparison entry
/// (`files`, relative to `dir`) and returns them all, relative to `dir`.
pub fn write_piles(dir: &Path, all: &mut AllSurfaces) -> Result<Written, Error> {
    let mut total = Written::default();
    for (pile, entry) in all.piles.iter().zip(all.summary.surfaces.iter_mut()) {
        let name = pile.paper.shape.name();
        let sub = dir.join(name);
        std::fs::create_dir_all(&sub).map_err(|source| crate::FiguresError::CreateDir {
            path: sub.clone(),
            source,
        })?;
        let mut w = Written::default();
        write_plan(&sub, &pile.planned, &mut w)?;
        write_job_summary(&sub, &pile.planned.summary, &mut w)?;
        let prefix =
            |v: &[String]| -> Vec<String> { v.iter().map(|p| format!("{name}/{p}")).collect() };
        entry.files = Some(prefix(&w.all()));
        total.plots.extend(prefix(&w.plots));
        total.files.extend(prefix(&w.files));
    }
    Ok(total)
}

/// Writes the comparison of `all` into `dir`: `table.csv` and the `paths`
/// panels (our tooth path and the paper's on each pile).
pub fn write_comparison(dir: &Path, all: &AllSurfaces, written: &mut Written) -> Result<(), Error> {
    let path = dir.join("table.csv");
    write_table_csv(&path, &all.summary)?;
    written.file(dir, &path);
    let panels: Vec<Figure> = all
        .piles
        .iter()
        .zip(&all.summary.surfaces)
        .map(|(p, s)| comparison_panel(p, s))
        .collect();
    written.plot(dir, write_panels(&panels, dir, "paths")?);
    Ok(())
}

/// A number with `decimals`, or "-".
fn cell(v: Option<f64>, decimals: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.decimals$}"),
        _ => "-".into(),
    }
}

/// A relative difference in per cent with its sign, or "-".
fn pct(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{:+.1} %", 100.0 * x),
        _ => "-".into(),
    }
}

/// The comparison with Tables 4–5 as a markdown table: per pile a row of
/// ours (with Δm_dig and Δf) and a row of the paper's.
pub fn markdown_table(all: &AllSurfacesSummary) -> String {
    let mut header = vec!["surface", ""];
    header.extend(TABLE_COLUMNS.iter().map(|c| c.label));
    header.extend(["Δm_dig", "Δf"]);
    let rows = all.surfaces.iter().flat_map(|s| {
        let r = TableRow::new(s);
        let mut ours = vec![r.surface.clone(), "ours".into()];
        ours.extend(
            TABLE_COLUMNS
                .iter()
                .zip(&r.ours)
                .map(|(c, v)| cell(*v, c.decimals)),
        );
        ours.extend([pct(r.m_dig_rel_diff), pct(r.f_rel_diff)]);
        let mut paper = vec![String::new(), "paper".into()];
        paper.extend(
            TABLE_COLUMNS
                .iter()
                .zip(&r.paper)
                .map(|(c, v)| cell(Some(*v), c.decimals)),
        );
        paper.extend([String::new(), String::new()]);
        [ours, paper]
    });
    md_table(&header, rows).trim_end().to_string()
}

/// `table.csv`: per pile, ours and the paper's value of each column, the
/// relative differences and whether our plan is feasible.
pub fn write_table_csv(path: &Path, all: &AllSurfacesSummary) -> Result<(), Error> {
    let mut header = vec!["surface".to_string()];
    for c in TABLE_COLUMNS {
        header.push(c.key.to_string());
        header.push(format!("{}_paper", c.key));
    }
    header.extend(["m_dig_rel_diff", "f_rel_diff", "feasible"].map(String::from));
    let cells: Vec<Vec<String>> = all
        .surfaces
        .iter()
        .map(|s| {
            let r = TableRow::new(s);
            let mut row = vec![r.surface.clone()];
            for (ours, paper) in r.ours.iter().zip(&r.paper) {
                row.push(ours.map(|v| format!("{v}")).unwrap_or_default());
                row.push(format!("{paper}"));
            }
            for v in [r.m_dig_rel_diff, r.f_rel_diff] {
                row.push(v.map(|v| format!("{v}")).unwrap_or_default());
            }
            row.push(r.feasible.to_string());
            row
        })
        .collect();
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    write_csv_cells(path, &header, &cells)?;
    Ok(())
}

/// One pile of the comparison: our tooth path and the paper's (Table 4's
/// decision drawn on our pile).
pub fn comparison_panel(
    pile: &ComparedPile,
    s: &autoshovel_rope_shovel_dig::SurfaceComparison,
) -> Figure {
    let model = &pile.planned.model;
    let paper = pile.paper;
    let ours = s.plan.plan.as_ref().map(|p| p.decision());
    let theirs = paper.decision();
    let x1 = (model.surface.top() / model.profile.geometry.pile_angle_deg.to_radians().tan())
        .max(paper.gx_m)
        + 0.1;
    let x1 = x1.min(model.surface.x_range().1);
    let mut fig = Figure::new(
        format!(
            "{} pile: planned tooth path and the paper's (Table 4)",
            paper.shape.name()
        ),
        "x from the toe [m]",
        "y above the floor [m]",
    )
    .equal_aspect()
    .size(900, 480);
    for l in pile_layers(
        &model.surface,
        -0.05,
        x1,
        model.profile.geometry.pile_angle_deg,
    ) {
        fig.push(l);
    }
    let path = |d: Option<&Decision>| -> Vec<(f64, f64)> {
        let Some(d) = d.filter(|d| d.td_s.is_finite() && d.td_s > 0.0) else {
            return Vec::new();
        };
        let tr = d.trajectory();
        (0..=200)
            .map(|i| {
                let p = tr.at(d.td_s * i as f64 / 200.0).p;
                (p[0], p[1])
            })
            .collect()
    };
    let ours_fields = s.plan.plan.as_ref();
    fig.push(
        Layer::line(path(ours.as_ref()), Stroke::solid(Rgb::RED, 3)).with_label(format!(
            "planned: m_dig {} kg, f {}",
            cell(ours_fields.map(|p| p.m_dig_kg), 3),
            cell(ours_fields.map(|p| p.f), 2)
        )),
    );
    fig.push(
        Layer::line(path(Some(&theirs)), Stroke::dashed(Rgb::BLACK, 2)).with_label(format!(
            "paper's path: m_dig {} kg, f {} (Table 5); on this model m_dig {} kg",
            paper.m_dig_kg,
            paper.f,
            cell(Some(s.paper_plan_on_this_model.m_dig_kg), 3)
        )),
    );
    fig
}
