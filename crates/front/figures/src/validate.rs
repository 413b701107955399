//! Figures and tables of `validate-dig` ([RS Fig. 20], [RS Table 6]), built
//! from `autoshovel_rope_shovel_dig::validate`'s typed results: `aligned.csv` (the plan's
//! samples inside the measured record, planned and measured side by side),
//! the plot `forces` (planned and measured hoist force in one panel, crowd
//! force in the other, the measurement moved onto the plan's clock) and,
//! when the record has them, `travel` (rope length and handle extension).

use std::path::Path;

use autoshovel_report::{
    markdown_table, time_panel, write_csv, write_panels, Figure, Rgb, Written,
};
use autoshovel_rope_shovel_dig::validate::{Paired, ValidateSummary, Validation};

/// Errors of the writers here.
pub type Error = crate::FiguresError;

/// Writes `aligned.csv`, `forces` and (when there are travels) `travel`
/// into `dir`.
pub fn write(dir: &Path, v: &Validation, written: &mut Written) -> Result<(), Error> {
    let a = &v.aligned;
    let path = dir.join("aligned.csv");
    let mut header = vec![
        "t_plan_s",
        "t_measured_s",
        "hoist_planned_n",
        "hoist_measured_n",
        "crowd_planned_n",
        "crowd_measured_n",
    ];
    let mut cols: Vec<&[f64]> = vec![
        &a.t_plan_s,
        &a.t_measured_s,
        &a.hoist_force_n.planned,
        &a.hoist_force_n.measured,
        &a.crowd_force_n.planned,
        &a.crowd_force_n.measured,
    ];
    for (names, s) in [
        (
            ["rope_length_planned_m", "rope_length_measured_m"],
            &a.rope_length_m,
        ),
        (
            ["handle_extension_planned_m", "handle_extension_measured_m"],
            &a.handle_extension_m,
        ),
    ] {
        if let Some(s) = s {
            header.extend(names);
            cols.push(&s.planned);
            cols.push(&s.measured);
        }
    }
    write_csv(
        &path,
        &header,
        (0..a.t_plan_s.len()).map(|i| cols.iter().map(|c| c[i]).collect()),
    )?;
    written.file(dir, &path);
    written.plot(dir, write_panels(&force_figures(v), dir, "forces")?);
    let travel = travel_figures(v);
    if !travel.is_empty() {
        written.plot(dir, write_panels(&travel, dir, "travel")?);
    }
    Ok(())
}

/// The planned and the measured series of `s` against plan time.
fn lines(t: &[f64], s: &Paired) -> [Vec<(f64, f64)>; 2] {
    let pts = |v: &[f64]| t.iter().copied().zip(v.iter().copied()).collect();
    [pts(&s.planned), pts(&s.measured)]
}

/// [RS Fig. 20]: planned and measured hoist force, then crowd force,
/// against plan time (the measurement moved by the alignment's clock).
pub fn force_figures(v: &Validation) -> Vec<Figure> {
    let s = &v.summary;
    let a = &v.aligned;
    let m = &v.measured_on_plan_clock;
    let clock = format!(
        "moved by {:+.3} s, time × 1/{:.4}",
        -s.alignment.offset_s, s.alignment.time_scale
    );
    [
        ("Hoist", &a.hoist_force_n, &m.hoist_force_n, &s.hoist_force),
        ("Crowd", &a.crowd_force_n, &m.crowd_force_n, &s.crowd_force),
    ]
    .into_iter()
    .map(|(name, pair, record, cmp)| {
        let [planned, _] = lines(&a.t_plan_s, pair);
        let measured = m.t_s.iter().copied().zip(record.iter().copied()).collect();
        let label = format!(
            "measured ({clock}); R² {:.4}, gain {:.3}",
            cmp.r_squared, cmp.gain
        );
        time_panel(
            format!("{name} force planned and measured ({} pile)", s.surface),
            "force [N]",
            (480, 0.35),
            [
                (measured, Rgb::RED, label.as_str()),
                (planned, Rgb::BLUE, "planned"),
            ],
            |_, _| Vec::new(),
        )
    })
    .collect()
}

/// Rope length and handle extension planned and measured, for those the
/// record has.
pub fn travel_figures(v: &Validation) -> Vec<Figure> {
    let a = &v.aligned;
    [
        ("Free hoist rope length", &a.rope_length_m),
        ("Handle extension d₂", &a.handle_extension_m),
    ]
    .into_iter()
    .filter_map(|(name, s)| {
        let [planned, measured] = lines(&a.t_plan_s, s.as_ref()?);
        Some(time_panel(
            format!("{name} planned and measured"),
            "length [m]",
            (420, 0.3),
            [
                (measured, Rgb::RED, "measured"),
                (planned, Rgb::BLUE, "planned"),
            ],
            |_, _| Vec::new(),
        ))
    })
    .collect()
}

/// The comparison as [RS Table 6]'s row and the force figures, in markdown.
pub fn markdown(s: &ValidateSummary) -> String {
    let cell = |v: Option<f64>, d: usize| match v {
        Some(x) if x.is_finite() => format!("{x:.d$}"),
        _ => "-".into(),
    };
    let m = s.mass_kg;
    let t = &s.dig_time_s;
    let table6 = markdown_table(
        &[
            "surface",
            "mass planned [kg]",
            "mass measured [kg]",
            "deviation [%]",
            "time planned [s]",
            "time measured [s]",
            "deviation [%]",
            "R² hoist",
            "R² crowd",
        ],
        [vec![
            s.surface.clone(),
            cell(m.map(|m| m.planned), 3),
            cell(m.map(|m| m.measured), 3),
            cell(m.map(|m| m.relative_deviation_pct), 2),
            cell(Some(t.planned), 2),
            cell(Some(t.measured), 2),
            cell(Some(t.relative_deviation_pct), 2),
            cell(Some(s.hoist_force.r_squared), 4),
            cell(Some(s.crowd_force.r_squared), 4),
        ]],
    );
    let forces = markdown_table(
        &[
            "force",
            "peak planned [N]",
            "peak measured [N]",
            "RMS diff [N]",
            "r",
            "r²",
            "R²",
            "gain",
        ],
        [("hoist", &s.hoist_force), ("crowd", &s.crowd_force)].map(|(n, f)| {
            vec![
                n.to_string(),
                cell(Some(f.peak_planned_n), 1),
                cell(Some(f.peak_measured_n), 1),
                cell(Some(f.rms_difference_n), 2),
                cell(Some(f.pearson_r), 4),
                cell(Some(f.r2_pearson), 4),
                cell(Some(f.r_squared), 4),
                cell(Some(f.gain), 4),
            ]
        }),
    );
    format!("{table6}\n{forces}").trim_end().to_string()
}
