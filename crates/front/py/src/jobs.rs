//! The planning jobs: the rope-shovel dig ([RS eq. 28]–[RS eq. 37]), the
//! walk ([W eq. 6]–[W eq. 15]), tracking ([W eq. 16]–[W eq. 24]), the
//! hydraulic excavator ([HE eq. 1]–[HE eq. 10]) and the random-road study.

use std::path::{Path, PathBuf};

use autoshovel_core::config::TomlFile as _;
use autoshovel_optim::Init;
use autoshovel_rope_shovel_dig::{plan_pile, DigSetup, MachineProfile, Pile, SearchSpace};
use autoshovel_walk_planner::study::{self, MapRow, StudyParams};
use autoshovel_walk_planner::{FieldKind, PlanOutcome, Scenario};
use autoshovel_walk_tracker::scenario::Noise;
use autoshovel_walk_tracker::ControllerKind;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::cloud::Perception;
use crate::{bad_arg, choose, finite, lib_err, rows_to_numpy, summary_json, AutoshovelError};

/// `plan_dig(pile, ...)`: one dig plan ([RS eq. 37], GWO then CMA-ES) on a
/// Fig. 7 pile (its name) or on a perceived scan; the summary, the tooth
/// path `[t_s, x_m, y_m, load_kg]` and the pile's profile `[x_m, y_m]` in
/// the dig frame.
#[pyfunction]
#[pyo3(signature = (pile, profile, seed, polish, search, init))]
#[allow(clippy::type_complexity)]
fn plan_dig<'py>(
    py: Python<'py>,
    pile: &Bound<'py, PyAny>,
    profile: Option<PathBuf>,
    seed: u64,
    polish: usize,
    search: &str,
    init: &str,
) -> PyResult<(String, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    const F: &str = "plan_dig";
    let mut setup = match &profile {
        Some(p) => DigSetup::new(
            MachineProfile::load(p).map_err(lib_err)?,
            p.display().to_string(),
            seed,
        ),
        None => DigSetup::scale_model(seed),
    };
    setup.polish_evaluations = polish;
    setup.search = search
        .parse::<SearchSpace>()
        .map_err(|e| bad_arg(F, format!("search: {e}")))?;
    setup.gwo.init = choose(
        F,
        "init",
        init,
        &[
            ("good-point-set", Init::GoodPointSet),
            ("random", Init::Random),
        ],
    )?;
    let pile = if let Ok(perception) = pile.cast::<Perception>() {
        let p = perception.get();
        Pile::scan(Path::new(&p.source), &p.got, &setup.profile).map_err(lib_err)?
    } else if let Ok(name) = pile.extract::<String>() {
        let shape = name.parse().map_err(|e| bad_arg(F, format!("pile: {e}")))?;
        Pile::shape(shape, &setup.profile).map_err(lib_err)?
    } else {
        return Err(bad_arg(
            F,
            "pile must be a pile shape's name (typical, convex, concave, convex-concave) or what perceive() returned",
        ));
    };
    let planned = py.detach(|| plan_pile(&pile, &setup)).map_err(lib_err)?;
    let path: Vec<[f64; 4]> = planned
        .plan
        .iter()
        .flat_map(|p| &p.samples)
        .map(|s| [s.t_s, s.tip_m[0], s.tip_m[1], s.load_kg])
        .collect();
    let surface = &planned.model.surface;
    let (x0, x1) = path
        .iter()
        .fold((0.0_f64, 0.0_f64), |(a, b), s| (a.min(s[1]), b.max(s[1])));
    let span = (x1 - x0).max(1e-3);
    let profile: Vec<[f64; 2]> = (0..=200)
        .map(|i| {
            let x = x0 - 0.25 * span + 1.5 * span * f64::from(i) / 200.0;
            [x, surface.height(x)]
        })
        .collect();
    Ok((
        summary_json(&planned.summary)?,
        rows_to_numpy(py, path),
        rows_to_numpy(py, profile),
    ))
}

/// `plan_path(scenario, planner, heading_tolerance_deg)`: the walk of a
/// built-in or TOML scenario; the summary and the smoothed path
/// `[x_m, y_m, heading_rad, s_m, curvature_per_m]` (empty on failure).
#[pyfunction]
fn plan_path<'py>(
    py: Python<'py>,
    scenario: &str,
    planner: &str,
    heading_tolerance_deg: f64,
) -> PyResult<(String, Bound<'py, PyArray2<f64>>)> {
    const F: &str = "plan_path";
    let field = choose(
        F,
        "planner",
        planner,
        &[
            ("improved-apf", FieldKind::Improved),
            ("apf", FieldKind::Classic),
        ],
    )?;
    let tol = finite(F, "heading_tolerance_deg", heading_tolerance_deg)?;
    if tol < 0.0 {
        return Err(bad_arg(
            F,
            format!("heading_tolerance_deg = {tol}: expected at least 0"),
        ));
    }
    let scenario = Scenario::resolve(scenario).map_err(lib_err)?;
    let outcome = py.detach(|| PlanOutcome::plan(&scenario, field));
    let summary = outcome.summary(&scenario, tol);
    let path: Vec<[f64; 5]> = outcome
        .plan
        .as_ref()
        .map(|plan| {
            plan.path
                .samples()
                .map(|(_, p)| [p.pose.x, p.pose.y, p.pose.theta, p.s_m, p.curvature_per_m])
                .collect()
        })
        .unwrap_or_default();
    Ok((summary_json(&summary)?, rows_to_numpy(py, path)))
}

/// `track(scenario, controller, noise, seed, compare, controllers)`: the
/// crawler driven along a scenario's path in the simulator; the summary
/// and the main run's samples `[t_s, x_m, y_m, heading_rad, measured_x_m,
/// measured_y_m, centroid_dev_m, heading_error_rad, d_m]`. `controllers`
/// lays gains over the scenario's `[controller.*]` tables.
#[pyfunction]
#[pyo3(signature = (scenario, controller, noise, seed, compare, controllers=None))]
fn track<'py>(
    py: Python<'py>,
    scenario: &str,
    controller: &str,
    noise: Option<&str>,
    seed: u64,
    compare: bool,
    controllers: Option<&Bound<'py, PyDict>>,
) -> PyResult<(String, Bound<'py, PyArray2<f64>>)> {
    const F: &str = "track";
    let kind = choose(
        F,
        "controller",
        controller,
        &[
            ("fuzzy", ControllerKind::Fuzzy),
            ("pid", ControllerKind::Pid),
            ("pure-pursuit", ControllerKind::PurePursuit),
            ("stanley", ControllerKind::Stanley),
        ],
    )?;
    let noise = noise
        .map(|n| choose(F, "noise", n, &[("off", Noise::Off), ("rtk", Noise::Rtk)]))
        .transpose()?;
    let mut scenario =
        autoshovel_walk_tracker::scenario::resolve(scenario, noise, seed).map_err(lib_err)?;
    if let Some(d) = controllers.filter(|d| !d.is_empty()) {
        let mut table = toml::Table::try_from(scenario.controllers).map_err(lib_err)?;
        crate::overlay(F, "controllers.", &mut table, d)?;
        scenario.controllers = table.try_into().map_err(|e: toml::de::Error| {
            AutoshovelError::new_err(format!("{F}(): controllers: {}", e.message()))
        })?;
    }
    let tracking = py.detach(|| autoshovel_walk_tracker::track(&scenario, kind, compare));
    let summary = tracking.summary(&scenario);
    let samples: Vec<[f64; 9]> = tracking
        .main()
        .run
        .samples
        .iter()
        .map(|s| {
            [
                s.t_s,
                s.truth.x,
                s.truth.y,
                s.truth.theta,
                s.measured.x,
                s.measured.y,
                s.centroid_dev_m,
                s.heading_error_rad,
                s.d_m,
            ]
        })
        .collect();
    Ok((summary_json(&summary)?, rows_to_numpy(py, samples)))
}

/// `plan_excavate(scenario, profile)`: the hydraulic excavator's dig
/// planned and executed round hidden boulders; the summary.
#[pyfunction]
#[pyo3(signature = (scenario, profile=None))]
fn plan_excavate(py: Python<'_>, scenario: &str, profile: Option<PathBuf>) -> PyResult<String> {
    let setup =
        autoshovel_excavator_dig::Setup::load(scenario, profile.as_deref()).map_err(lib_err)?;
    let ex = py.detach(|| setup.run()).map_err(|e| {
        AutoshovelError::new_err(format!(
            "plan-excavate {} ({}): {}",
            setup.scenario.name,
            setup.scenario_source,
            crate::message(&e)
        ))
    })?;
    summary_json(&autoshovel_excavator_dig::ExcavateSummary::new(&setup, &ex))
}

fn study_params(
    maps: usize,
    seed: u64,
    min_obstacles: usize,
    max_obstacles: usize,
) -> PyResult<StudyParams> {
    let params = StudyParams {
        maps,
        seed,
        min_obstacles,
        max_obstacles,
        ..Default::default()
    };
    params.check().map_err(lib_err)?;
    Ok(params)
}

/// The rows of maps `start..stop` of a study, as JSON text: one shard of
/// a study spread by seed ranges; on `threads` threads (default: all cores;
/// a cluster's task runs on one).
#[pyfunction]
#[pyo3(signature = (maps, seed, min_obstacles, max_obstacles, start, stop, threads=None))]
#[allow(clippy::too_many_arguments)]
fn study_paths_rows(
    py: Python<'_>,
    maps: usize,
    seed: u64,
    min_obstacles: usize,
    max_obstacles: usize,
    start: usize,
    stop: usize,
    threads: Option<usize>,
) -> PyResult<String> {
    let params = study_params(maps, seed, min_obstacles, max_obstacles)?;
    if start > stop || stop > maps {
        return Err(bad_arg(
            "study_paths_rows",
            format!("maps {start}..{stop} must lie within 0..{maps}"),
        ));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(lib_err)?;
    let rows: Vec<MapRow> = py.detach(|| {
        pool.install(|| {
            (start..stop)
                .into_par_iter()
                .map(|i| study::run_map(&params, i))
                .collect()
        })
    });
    Ok(study::rows_to_json(&rows))
}

/// The summary (JSON) and the table of `autoshovel study-paths` from the
/// rows of every shard, in any order; every map must be there once.
#[pyfunction]
fn study_paths_summary(
    maps: usize,
    seed: u64,
    min_obstacles: usize,
    max_obstacles: usize,
    shards: Vec<String>,
) -> PyResult<(String, String)> {
    let params = study_params(maps, seed, min_obstacles, max_obstacles)?;
    let mut rows: Vec<MapRow> = Vec::with_capacity(maps);
    for text in &shards {
        rows.extend(study::rows_from_json(text).map_err(lib_err)?);
    }
    rows.sort_by_key(|r| r.index);
    if let Some((i, r)) = rows.iter().enumerate().find(|(i, r)| r.index != *i) {
        return Err(AutoshovelError::new_err(format!(
            "study-paths: the shards hold map {} where map {i} belongs (each of 0..{maps} exactly once)",
            r.index
        )));
    }
    if rows.len() != maps {
        return Err(AutoshovelError::new_err(format!(
            "study-paths: the shards hold {} maps; expected {maps}",
            rows.len()
        )));
    }
    let summary = study::summarize(&params, &rows);
    Ok((
        summary_json(&summary)?,
        autoshovel_figures::study::markdown_table(&summary),
    ))
}

/// The whole study on this machine (all cores): the summary and the table.
#[pyfunction]
fn study_paths(
    py: Python<'_>,
    maps: usize,
    seed: u64,
    min_obstacles: usize,
    max_obstacles: usize,
) -> PyResult<(String, String)> {
    let params = study_params(maps, seed, min_obstacles, max_obstacles)?;
    let rows: Vec<MapRow> = py.detach(|| {
        (0..maps)
            .into_par_iter()
            .map(|i| study::run_map(&params, i))
            .collect()
    });
    let summary = study::summarize(&params, &rows);
    Ok((
        summary_json(&summary)?,
        autoshovel_figures::study::markdown_table(&summary),
    ))
}

/// Adds this module's functions to `m`.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(plan_dig, m)?)?;
    m.add_function(wrap_pyfunction!(plan_path, m)?)?;
    m.add_function(wrap_pyfunction!(track, m)?)?;
    m.add_function(wrap_pyfunction!(plan_excavate, m)?)?;
    m.add_function(wrap_pyfunction!(study_paths_rows, m)?)?;
    m.add_function(wrap_pyfunction!(study_paths_summary, m)?)?;
    m.add_function(wrap_pyfunction!(study_paths, m)?)?;
    Ok(())
}
