//! The dig's jobs: the rope shovel's plan ([RS eq. 28]–[RS eq. 37]) on one
//! pile and on the paper's four, its validation against a measured dig, the
//! hydraulic excavator's plan round buried boulders ([HE eq. 1]–[HE eq. 10])
//! and the seeded boulder study.

use autoshovel_excavator_dig::{ExcavateSummary, Setup};
use autoshovel_figures as figures;
use autoshovel_rope_shovel_dig::{
    all_surfaces, plan_pile, AllSurfaces, AllSurfacesSummary, DigSetup, DigSummary, Pile,
    PlannedPile, SurfaceComparison,
};
use indicatif::ParallelProgressIterator;
use rayon::prelude::*;

use crate::error::During as _;
use crate::{progress_bar, Job, JobError, OutDir, Result};

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
    planned: &autoshovel_rope_shovel_dig::validate::PlannedRecord,
    measured: &autoshovel_rope_shovel_dig::validate::MeasuredRecord,
    params: &autoshovel_rope_shovel_dig::validate::AlignParams,
    out: Option<&OutDir>,
) -> Result<Job<autoshovel_rope_shovel_dig::validate::ValidateSummary>> {
    let v = autoshovel_rope_shovel_dig::validate::validate(planned, measured, params)?;
    Job::finish(v.summary.clone(), out, |dir, written| {
        Ok(figures::validate::write(dir, &v, written)?)
    })
}

/// `plan-excavate`: plan and execute the dig of `setup`; an impossible dig
/// is an error naming the scenario; `out` is made only for a plan.
pub fn plan_excavate(setup: &Setup, out: Option<&OutDir>) -> Result<Job<ExcavateSummary>> {
    let ex = setup.run().during(|| {
        format!(
            "plan-excavate {} ({})",
            setup.scenario.name, setup.scenario_source
        )
    })?;
    Job::finish(ExcavateSummary::new(setup, &ex), out, |dir, written| {
        Ok(figures::excavate::write(dir, setup, &ex, written)?)
    })
}

/// `study-boulders`: the seeded boulder study on `base`, cases in parallel
/// (with a progress bar when `progress`).
pub fn study_boulders(
    base: &autoshovel_excavator_dig::Scenario,
    profile: &autoshovel_excavator_dig::MachineProfile,
    params: &autoshovel_excavator_dig::study::BoulderStudyParams,
    out: Option<&OutDir>,
    progress: bool,
) -> Result<Job<autoshovel_excavator_dig::study::BoulderStudySummary>> {
    use autoshovel_excavator_dig::study::{boulder_free_path, run_case, summarize, CaseRow};
    if params.cases == 0 || params.cases > 100_000 {
        return Err(JobError::setting(
            "--cases",
            params.cases,
            "must be between 1 and 100000",
        ));
    }
    let [r0, r1] = params.radius_m;
    if !(r0.is_finite() && r1.is_finite() && r0 > 0.0 && r0 <= r1 && r1 <= 2.0) {
        return Err(JobError::setting(
            "--min-radius",
            format!("{r0} and --max-radius {r1}"),
            "must satisfy 0 < min <= max <= 2 m",
        ));
    }
    let path = boulder_free_path(base, profile)
        .during(|| format!("planning `{}` without boulders", base.name))?;
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

/// `shift`: a whole shift of `scenario` with the dig planner's `profile`
/// (1:30, scaled by the scenario's λ), with a progress bar when `show`.
pub fn shift(
    scenario: &autoshovel_work_shift::ShiftScenario,
    profile: &autoshovel_rope_shovel_dig::MachineProfile,
    options: &autoshovel_work_shift::ShiftOptions,
    out: Option<&OutDir>,
    show: bool,
) -> Result<Job<autoshovel_work_shift::ShiftSummary>> {
    let bar = progress_bar(show, "shift {bar:40} {percent:>3}% of the shift {elapsed}");
    bar.set_length(1000);
    let run = autoshovel_work_shift::run_shift(scenario, profile, options, &mut |share| {
        bar.set_position((share * 1000.0) as u64)
    })
    .during(|| format!("shift {}", scenario.name))?;
    bar.finish_and_clear();
    Job::finish(run.summary.clone(), out, |dir, written| {
        Ok(figures::shift::write(dir, &run, written)?)
    })
}
