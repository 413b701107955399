//! One call per job, shared by its subcommand and the demo: the library
//! call, then [`Job::finish`] with the figures crate's writer. Subcommand
//! modules and the demo import this module, never each other.

use std::path::Path;

use anyhow::{bail, Context, Result};
use autoshovel_dig::{
    all_surfaces, plan_pile, AllSurfaces, AllSurfacesSummary, DigSetup, DigSummary, MachineProfile,
    Pile, PlannedPile, SurfaceComparison,
};
use autoshovel_excavate::{ExcavateSummary, Setup};
use autoshovel_figures as figures;
use autoshovel_propel::study::{run_map, summarize, MapRow, StudyParams, StudySummary};
use autoshovel_propel::{FieldKind, PlanOutcome, PlanPathSummary, Scenario};
use autoshovel_surface::perceive::{
    perceive_file_with, PerceiveSummary, Perceived, PerceptionParams,
};
use autoshovel_track::scenario::TrackScenario;
use autoshovel_track::{ControllerKind, TrackSummary};
use indicatif::ParallelProgressIterator;
use rayon::prelude::*;

use crate::output::{progress_bar, Job, OutDir};

/// `plan-path`: plan `scenario` with `field`; success within
/// `heading_tolerance_deg` of every leg's heading.
pub fn plan_path(
    scenario: &Scenario,
    field: FieldKind,
    heading_tolerance_deg: f64,
    out: Option<&OutDir>,
) -> Result<Job<PlanPathSummary>> {
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
    use autoshovel_propel::study::{MAX_STUDY_MAPS, MAX_STUDY_OBSTACLES};
    if params.maps == 0 || params.maps > MAX_STUDY_MAPS {
        bail!(
            "--maps {} must be between 1 and {MAX_STUDY_MAPS}",
            params.maps
        );
    }
    if params.min_obstacles > params.max_obstacles || params.max_obstacles > MAX_STUDY_OBSTACLES {
        bail!(
            "--min-obstacles {} and --max-obstacles {} must satisfy min <= max <= {MAX_STUDY_OBSTACLES}",
            params.min_obstacles,
            params.max_obstacles
        );
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

/// `study-boulders`: the seeded boulder study on `base`, cases in parallel
/// (with a progress bar when `progress`).
pub fn study_boulders(
    base: &autoshovel_excavate::Scenario,
    profile: &autoshovel_excavate::MachineProfile,
    params: &autoshovel_excavate::study::BoulderStudyParams,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<autoshovel_excavate::study::BoulderStudySummary>> {
    use autoshovel_excavate::study::{boulder_free_path, run_case, summarize, CaseRow};
    if params.cases == 0 || params.cases > 100_000 {
        bail!("--cases {} must be between 1 and 100000", params.cases);
    }
    let [r0, r1] = params.radius_m;
    if !(r0.is_finite() && r1.is_finite() && r0 > 0.0 && r0 <= r1 && r1 <= 2.0) {
        bail!("--min-radius {r0} and --max-radius {r1} must satisfy 0 < min <= max <= 2 m");
    }
    let path = boulder_free_path(base, profile)
        .with_context(|| format!("planning `{}` without boulders", base.name))?;
    let bar = progress_bar(
        progress,
        "{msg} [{bar:40}] {pos}/{len} boulders, {eta} left",
    );
    bar.set_length(params.cases as u64);
    bar.set_message("digging");
    let rows: Vec<CaseRow> = (0..params.cases)
        .into_par_iter()
        .progress_with(bar.clone())
        .map(|i| run_case(base, profile, &path, params, i))
        .collect();
    bar.finish_and_clear();
    let summary = summarize(params, base, profile, &rows);
    Job::finish(summary.clone(), out, |dir, written| {
        Ok(figures::boulders::write_study(
            dir, &summary, &rows, written,
        )?)
    })
}

/// `tune-trackers`: every tracker tuned with `budget` evaluations (seeded),
/// trackers in parallel, then scored on every set.
pub fn tune_trackers(
    budget: usize,
    seed: u64,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<autoshovel_track::tune::TuneSummary>> {
    use autoshovel_track::tune::{summarize, tune, CaseSets, Tunable, Tuned};
    if !(1..=100_000).contains(&budget) {
        bail!("--budget {budget} must be between 1 and 100000");
    }
    let sets = CaseSets::standard().context("building the tuning runs")?;
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
    let tracking = autoshovel_track::track(scenario, controller, compare);
    Job::finish(tracking.summary(scenario), out, |dir, written| {
        figures::track::write(dir, scenario, &tracking, written)
            .context("writing the track figures")
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
    params: &autoshovel_link::LinkParams,
    log_path: &Path,
    overwrite_log: bool,
    out: Option<&OutDir>,
    stop: &'static std::sync::atomic::AtomicBool,
) -> Result<Job<autoshovel_link::drive::DriveSummary>> {
    use autoshovel_link::drive::{DriveSummary, LinkSummary};
    use autoshovel_link::DriveOptions;
    use autoshovel_track::{ControllerRun, Tracking};
    use std::sync::atomic::Ordering;
    if let Some(dir) = log_path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
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
        // Ctrl-C (the binary's flag) reaches the drive's own stop switch.
        let flag = opts.stop.clone();
        let watcher = tokio::spawn(async move {
            loop {
                if stop.load(Ordering::Relaxed) {
                    flag.store(true, Ordering::Relaxed);
                }
                tokio::time::sleep(std::time::Duration::from_millis(5)).await;
            }
        });
        let got = autoshovel_link::drive_logged(
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
            .context("writing the drive figures")
    })
}

/// Reads `input` (with a progress bar when `progress`) and perceives it;
/// errors name the file.
pub fn read_and_perceive(
    input: &Path,
    params: &PerceptionParams,
    progress: bool,
) -> Result<Perceived> {
    let bar = progress_bar(progress, "reading [{bar:40}] {bytes}/{total_bytes} ({eta})");
    let spinner = progress_bar(progress, "{spinner} {msg} ({elapsed})");
    let mut ticking = false;
    let got = perceive_file_with(
        input,
        params,
        &mut |done, total| {
            bar.set_length(total);
            bar.set_position(done);
        },
        &mut |stage| {
            bar.finish_and_clear();
            // Once, and only when shown: each call starts a ticking
            // thread anew, hidden or not.
            if progress && !ticking {
                spinner.enable_steady_tick(std::time::Duration::from_millis(120));
                ticking = true;
            }
            spinner.set_message(match stage {
                "level" => "levelling",
                "ground" => "removing the floor",
                "radius" => "radius outlier removal",
                "statistical" => "statistical outlier removal",
                "voxel" => "voxel grid",
                "smooth" => "bilateral smoothing",
                "fit" => "fitting the surface",
                other => other,
            });
        },
    );
    bar.finish_and_clear();
    spinner.finish_and_clear();
    // A read error names the file itself; the pipeline's do not.
    got.map_err(|e| match e {
        autoshovel_surface::SurfaceError::Cloud(e) => anyhow::Error::from(e),
        e => anyhow::Error::from(e).context(input.display().to_string()),
    })
}

/// `perceive`: the §3 pipeline on `input`.
pub fn perceive(
    input: &Path,
    params: &PerceptionParams,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<PerceiveSummary>> {
    let got = read_and_perceive(input, params, progress)?;
    let summary = PerceiveSummary::new(input, params, &got);
    Job::finish(summary, out, |dir, written| {
        Ok(figures::perceive::write(dir, &got, written)?)
    })
}

/// `perceive` on a folder of frames (frame mode), with a progress bar
/// over the frames.
pub fn perceive_frames(
    dir: &Path,
    params: &PerceptionParams,
    options: autoshovel_surface::frames::FrameOptions,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<autoshovel_surface::frames::FramesSummary>> {
    let bar = progress_bar(
        progress,
        "frames [{bar:40}] {pos}/{len} ({per_sec}, {eta}) {msg}",
    );
    let done =
        autoshovel_surface::frames::perceive_folder(dir, params, options, &mut |done, total, r| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            bar.set_message(if r.ok {
                format!("{:.0} ms", r.latency_ms)
            } else {
                format!("skipped {}", r.file)
            });
        });
    bar.finish_and_clear();
    let done = done?;
    Job::finish(done.summary.clone(), out, |dir, written| {
        Ok(figures::frames::write(dir, &done, written)?)
    })
}

/// `perceive --tiles`: a survey by tiles, with a progress bar over each
/// pass; the cleaned tiles are written into the output's `tiles/` as LAZ
/// as they come (staged: nothing is left of a failed run).
pub fn perceive_tiles(
    input: &Path,
    params: &PerceptionParams,
    mut options: autoshovel_surface::tiles::TileOptions,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<autoshovel_surface::tiles::TiledSummary>> {
    use autoshovel_surface::tiles::{perceive_tiled, Survey, TiledSummary};
    let survey = Survey::open(&[input.to_path_buf()])?;
    let staging = out.map(OutDir::stage).transpose()?;
    let tiles_dir = staging.as_ref().map(|s| s.path().join("tiles"));
    if let Some(s) = &staging {
        options.work_dir = s.path().to_path_buf();
    }
    if let Some(d) = &tiles_dir {
        std::fs::create_dir_all(d).with_context(|| format!("creating {}", d.display()))?;
    }
    let bar = progress_bar(
        progress,
        "{prefix:>18} [{bar:40}] {pos}/{len} ({eta}) {msg}",
    );
    let mut tile_files = Vec::new();
    let got = perceive_tiled(
        &survey,
        params,
        &options,
        &mut |what, done, total| {
            if bar.prefix() != what {
                bar.set_prefix(what.to_string());
                bar.reset();
            }
            bar.set_length(total);
            bar.set_position(done);
        },
        &mut |tile| {
            if let Some(d) = &tiles_dir {
                let f = d.join(tile.file_name());
                autoshovel_cloud::io::write(
                    &f,
                    &tile.cloud,
                    autoshovel_cloud::io::Encoding::Binary,
                )?;
                tile_files.push(f);
            }
            Ok(())
        },
    );
    bar.finish_and_clear();
    let got = got?;
    let summary = TiledSummary::new(
        &input.display().to_string(),
        &survey,
        params,
        &options,
        &got,
    );
    Job::finish_in(summary.clone(), staging, |dir, written| {
        for f in &tile_files {
            written.file(dir, f);
        }
        Ok(figures::tiles::write(dir, &got, &summary, written)?)
    })
}

/// The pile of a scan for `plan-dig --cloud`: the perception pipeline, then
/// the dig profile cut by the library's rule.
pub fn scan_pile(
    path: &Path,
    params: &PerceptionParams,
    profile: &MachineProfile,
    progress: bool,
) -> Result<Pile> {
    let got = read_and_perceive(path, params, progress)?;
    Ok(Pile::scan(path, &got, profile)?)
}

/// `plan-dig`: one plan on `pile` (a summary with `error` set when no
/// feasible plan came out).
pub fn plan_dig(pile: &Pile, setup: &DigSetup, out: Option<&OutDir>) -> Result<Job<DigSummary>> {
    let planned: PlannedPile = plan_pile(pile, setup)?;
    Job::finish(planned.summary.clone(), out, |dir, written| {
        Ok(figures::dig::write_plan(dir, &planned, written)?)
    })
}

/// `plan-dig --all-surfaces`: the four piles beside Tables 4–5, each in
/// its own folder under `out`; `on_pile` hears of each plan as it ends.
pub fn plan_dig_all_surfaces(
    setup: &DigSetup,
    out: Option<&OutDir>,
    on_pile: impl FnMut(&SurfaceComparison),
) -> Result<Job<AllSurfacesSummary>> {
    let mut all: AllSurfaces = all_surfaces(setup, on_pile)?;
    let staging = out.map(OutDir::stage).transpose()?;
    let piles = match &staging {
        Some(s) => figures::dig::write_piles(s.path(), &mut all)?,
        None => Default::default(),
    };
    Job::finish_in(all.summary.clone(), staging, |dir, written| {
        written.plots.extend(piles.plots);
        written.files.extend(piles.files);
        Ok(figures::dig::write_comparison(dir, &all, written)?)
    })
}

/// `validate-dig`: `measured` against `planned`, aligned with `params`.
pub fn validate_dig(
    planned: &autoshovel_dig::validate::PlannedRecord,
    measured: &autoshovel_dig::validate::MeasuredRecord,
    params: &autoshovel_dig::validate::AlignParams,
    out: Option<&OutDir>,
) -> Result<Job<autoshovel_dig::validate::ValidateSummary>> {
    let v = autoshovel_dig::validate::validate(planned, measured, params)?;
    Job::finish(v.summary.clone(), out, |dir, written| {
        Ok(figures::validate::write(dir, &v, written)?)
    })
}

/// `plan-excavate`: plan and execute the dig of `setup`; an impossible dig
/// is an error naming the scenario; `out` is made only for a plan.
pub fn plan_excavate(setup: &Setup, out: Option<&OutDir>) -> Result<Job<ExcavateSummary>> {
    let ex = setup.run().with_context(|| {
        format!(
            "plan-excavate {} ({})",
            setup.scenario.name, setup.scenario_source
        )
    })?;
    Job::finish(ExcavateSummary::new(setup, &ex), out, |dir, written| {
        Ok(figures::excavate::write(dir, setup, &ex, written)?)
    })
}

/// `shift`: a whole shift of `scenario` with the dig planner's `profile`
/// (1:30, scaled by the scenario's λ), with a progress bar when `show`.
pub fn shift(
    scenario: &autoshovel_shift::ShiftScenario,
    profile: &autoshovel_dig::MachineProfile,
    options: &autoshovel_shift::ShiftOptions,
    out: Option<&OutDir>,
    show: bool,
) -> Result<Job<autoshovel_shift::ShiftSummary>> {
    let bar =
        crate::output::progress_bar(show, "shift {bar:40} {percent:>3}% of the shift {elapsed}");
    bar.set_length(1000);
    let run = autoshovel_shift::run_shift(scenario, profile, options, &mut |share| {
        bar.set_position((share * 1000.0) as u64)
    })
    .with_context(|| format!("shift {}", scenario.name))?;
    bar.finish_and_clear();
    Job::finish(run.summary.clone(), out, |dir, written| {
        Ok(figures::shift::write(dir, &run, written)?)
    })
}
