//! The walk's jobs: planning it ([W eq. 6]–[W eq. 15]), the random-road
//! study, tracking ([W eq. 16]–[W eq. 24]) in the simulator, the tuning of
//! every tracker, and driving the machine over its OPC UA link.

use std::path::Path;

use autoshovel_figures as figures;
use autoshovel_walk_planner::study::{run_map, summarize, MapRow, StudyParams, StudySummary};
use autoshovel_walk_planner::{FieldKind, PlanOutcome, PlanPathSummary, Scenario};
use autoshovel_walk_tracker::scenario::TrackScenario;
use autoshovel_walk_tracker::{ControllerKind, TrackSummary};
use indicatif::ParallelProgressIterator;
use rayon::prelude::*;

use crate::error::During as _;
use crate::{progress_bar, Job, JobError, OutDir, Result};

/// `plan-path`: plan `scenario` with `field`; success within
/// `heading_tolerance_deg` of every leg's heading.
pub fn plan_path(
    scenario: &Scenario,
    field: FieldKind,
    heading_tolerance_deg: f64,
    out: Option<&OutDir>,
) -> Result<Job<PlanPathSummary>> {
    if !(heading_tolerance_deg.is_finite() && heading_tolerance_deg >= 0.0) {
        return Err(JobError::setting(
            "--heading-tolerance-deg",
            heading_tolerance_deg,
            "must be a non-negative number",
        ));
    }
    let outcome = PlanOutcome::plan(scenario, field);
    let summary = outcome.summary(scenario, heading_tolerance_deg);
    Job::finish(summary, out, |dir, written| {
        Ok(figures::map::write_plan_path(
            dir, scenario, &outcome, written,
        )?)
    })
}

/// `study-paths`: the seeded random-road study, maps in parallel (with a
/// progress bar when `progress`).
pub fn study(
    params: &StudyParams,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<StudySummary>> {
    // The library's limits (StudyParams::check), said in the flags' names.
    use autoshovel_walk_planner::study::{MAX_STUDY_MAPS, MAX_STUDY_OBSTACLES};
    if params.maps == 0 || params.maps > MAX_STUDY_MAPS {
        return Err(JobError::setting(
            "--maps",
            params.maps,
            format!("must be between 1 and {MAX_STUDY_MAPS}"),
        ));
    }
    if params.min_obstacles > params.max_obstacles || params.max_obstacles > MAX_STUDY_OBSTACLES {
        return Err(JobError::setting(
            "--min-obstacles",
            format!(
                "{} and --max-obstacles {}",
                params.min_obstacles, params.max_obstacles
            ),
            format!("must satisfy min <= max <= {MAX_STUDY_OBSTACLES}"),
        ));
    }
    params.check()?;
    let bar = progress_bar(progress, "{msg} [{bar:40}] {pos}/{len} maps, {eta} left");
    bar.set_length(params.maps as u64);
    bar.set_message("planning");
    let rows: Vec<MapRow> = (0..params.maps)
        .into_par_iter()
        .progress_with(bar.clone())
        .map(|i| run_map(params, i))
        .collect();
    bar.finish_and_clear();
    Job::finish(summarize(params, &rows), out, |dir, written| {
        Ok(figures::study::write_study(dir, params, &rows, written)?)
    })
}

/// `tune-trackers`: every tracker tuned with `budget` evaluations (seeded),
/// trackers in parallel, then scored on every set.
pub fn tune_trackers(
    budget: usize,
    seed: u64,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<autoshovel_walk_tracker::tune::TuneSummary>> {
    use autoshovel_walk_tracker::tune::{summarize, tune, CaseSets, Tunable, Tuned};
    if !(1..=100_000).contains(&budget) {
        return Err(JobError::setting(
            "--budget",
            budget,
            "must be between 1 and 100000",
        ));
    }
    let sets = CaseSets::standard().during(|| "building the tuning runs".into())?;
    let bar = progress_bar(
        progress,
        "{msg} [{bar:40}] {pos}/{len} trackers, {eta} left",
    );
    bar.set_length(Tunable::ALL.len() as u64);
    bar.set_message("tuning");
    let tuned: Vec<Tuned> = Tunable::ALL
        .into_par_iter()
        .enumerate()
        .progress_with(bar.clone())
        .map(|(i, t)| tune(t, &sets.training, budget, seed.wrapping_add(i as u64)))
        .collect();
    bar.finish_and_clear();
    let summary = summarize(&sets, &tuned, budget, seed);
    Job::finish(summary.clone(), out, |dir, written| {
        Ok(figures::tune::write(dir, &summary, &tuned, written)?)
    })
}

/// `track`: drive `scenario` with `controller` (all three with `compare`).
pub fn track(
    scenario: &TrackScenario,
    controller: ControllerKind,
    compare: bool,
    out: Option<&OutDir>,
) -> Result<Job<TrackSummary>> {
    let tracking = autoshovel_walk_tracker::track(scenario, controller, compare);
    Job::finish(tracking.summary(scenario), out, |dir, written| {
        figures::track::write(dir, scenario, &tracking, written)
            .during(|| "writing the track figures".into())
    })
}

/// The async runtime a drive (and the simulated PLC) runs on: two workers,
/// one a core of the 2-core workstation.
pub fn runtime() -> Result<tokio::runtime::Runtime> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| JobError::During {
            step: "starting the async runtime".into(),
            source: Box::new(JobError::io("tokio runtime", e)),
        })
}

/// `drive`: `scenario` driven over the link of `params` with `controller`,
/// the run logged to `log_path` (kept whatever happens: it is the record),
/// the same figures as `track`; `stop` set (Ctrl-C) zeroes the setpoints
/// and ends the run.
#[allow(clippy::too_many_arguments)]
pub fn drive(
    rt: &tokio::runtime::Runtime,
    scenario: &TrackScenario,
    controller: ControllerKind,
    params: &autoshovel_plc_link::LinkParams,
    log_path: &Path,
    overwrite_log: bool,
    out: Option<&OutDir>,
    stop: &'static std::sync::atomic::AtomicBool,
) -> Result<Job<autoshovel_plc_link::drive::DriveSummary>> {
    use autoshovel_plc_link::drive::{DriveSummary, LinkSummary};
    use autoshovel_plc_link::DriveOptions;
    use autoshovel_walk_tracker::{ControllerRun, Tracking};
    use std::sync::atomic::Ordering;
    if let Some(dir) = log_path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| JobError::io(dir, e))?;
    }
    let mut ctl = controller.build(&scenario.controllers);
    let t0 = std::time::Instant::now();
    let metadata = [
        ("job", "drive".to_string()),
        ("scenario", scenario.name.clone()),
        ("endpoint", params.endpoint.clone()),
        ("controller", format!("{controller:?}")),
        ("seed", scenario.setup.rtk.seed.to_string()),
    ];
    let (run, log_path) = rt.block_on(async {
        let opts = DriveOptions::new(&scenario.setup, params);
        // Ctrl-C (the front end's flag) reaches the drive's own stop switch.
        let flag = opts.stop.clone();
        let watcher = tokio::spawn(async move {
            loop {
                if stop.load(Ordering::Relaxed) {
                    flag.store(true, Ordering::Relaxed);
                }
                tokio::time::sleep(std::time::Duration::from_millis(5)).await;
            }
        });
        let got = autoshovel_plc_link::drive_logged(
            params,
            &scenario.setup,
            ctl.as_mut(),
            &opts,
            log_path,
            &metadata,
            overwrite_log,
        )
        .await;
        watcher.abort();
        got
    })?;
    let mut link = LinkSummary::of(&run, params);
    link.log = Some(log_path.display().to_string());
    let tracking = Tracking::single(ControllerRun {
        kind: controller,
        name: ctl.name(),
        gains: ctl.gains(),
        run: run.run,
        sim_time_ms: t0.elapsed().as_secs_f64() * 1e3,
    });
    let mut track = tracking.summary(scenario);
    track.job = "drive";
    Job::finish(DriveSummary { track, link }, out, |dir, written| {
        figures::track::write(dir, scenario, &tracking, written)
            .during(|| "writing the drive figures".into())
    })
}

/// `replay`: the tracking metrics of a logged run, recomputed. `log` is a
/// `drive` MCAP log (which carries its own path; `planned` must be `None`)
/// or a CSV of RTK fixes with the `planned` scenario whose path was driven.
/// The same figures as `track`.
pub fn replay(
    log: &Path,
    planned: Option<&TrackScenario>,
    out: Option<&OutDir>,
) -> Result<Job<autoshovel_run_log::ReplaySummary>> {
    use autoshovel_run_log::{read_rtk_csv, replay_mcap, replay_rtk};
    use autoshovel_walk_tracker::{ControllerRun, Noise, Tracking};
    let is_csv = log
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    let r = match (is_csv, planned) {
        (true, Some(sc)) => replay_rtk(
            &read_rtk_csv(log)?,
            sc.setup.legs.clone(),
            &log.display().to_string(),
        )?,
        (true, None) => {
            return Err(JobError::setting(
                "--path",
                "(none)",
                format!(
                    "is needed for {}, a CSV of fixes (the planned path: a built-in or a scenario TOML)",
                    log.display()
                ),
            ))
        }
        (false, None) => replay_mcap(log)?,
        (false, Some(sc)) => {
            return Err(JobError::setting(
                "--path",
                &sc.name,
                "is for a CSV of fixes; an MCAP log carries its own path",
            ))
        }
    };
    // The log's own path and start, in a noise-free scenario for the figures.
    let scenario = match planned {
        Some(sc) => sc.clone(),
        None => {
            let mut sc =
                autoshovel_walk_tracker::scenario::resolve("straight", Some(Noise::Off), 1)?;
            sc.name = format!("replay of {}", log.display());
            sc.setup.legs = r.legs.clone();
            sc.setup.start = r
                .run
                .samples
                .first()
                .map(|s| s.truth)
                .unwrap_or(sc.setup.start);
            sc.map = None;
            sc
        }
    };
    let summary = r.summary();
    let tracking = Tracking::single(ControllerRun {
        kind: ControllerKind::Fuzzy,
        name: "replay",
        gains: ControllerKind::Fuzzy.build(&Default::default()).gains(),
        run: r.run,
        sim_time_ms: 0.0,
    });
    Job::finish(summary, out, |dir, written| {
        figures::track::write(dir, &scenario, &tracking, written)
            .during(|| "writing the replay figures".into())
    })
}
