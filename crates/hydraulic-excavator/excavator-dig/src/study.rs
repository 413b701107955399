//! The seeded boulder study (`autoshovel study-boulders`): the paper's dig
//! with one buried boulder of random size and place on the planned path, run
//! by the planner that knows only what it touches (`planner.rs`), and
//! measured on the truth: completed digs, volume error, extra contacts and
//! clearance.
//!
//! Each case draws a radius in `radius_m` and a point on the boulder-free
//! level-1 path (between 15 % and 85 % of its samples), and puts the centre
//! off the path along its normal by u·r, u uniform in (−0.8, 0.8), so the
//! path always meets the boulder; a boulder not wholly buried (top within
//! 5 cm of the ground) or holding the start is drawn again. Every case runs
//! twice, with the same boulder and sensor noise:
//!
//! - `class prior`: the planner assumes the paper's class, a boulder of 30 %
//!   of the bucket, at a first touch (the default);
//! - `true size`: the planner is told the boulder's real radius — a reference
//!   showing how much of the error is the unknown size, not the planner.

use autoshovel_core::Vec2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::excavation::excavate;
use crate::obstacle::Envelope;
use crate::profile::MachineProfile;
use crate::scenario::Scenario;

/// The study's settings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoulderStudyParams {
    /// Number of boulders (cases).
    pub cases: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// Range of radii (m).
    pub radius_m: [f64; 2],
}

impl Default for BoulderStudyParams {
    /// 200 cases, seed 1, radii from 0.15 m (below the class) to 0.5 m.
    fn default() -> Self {
        Self {
            cases: 200,
            seed: 1,
            radius_m: [0.15, 0.5],
        }
    }
}

/// The planners compared.
pub const VARIANTS: [&str; 2] = ["class prior", "true size"];

/// One planner's result on one case.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaseOutcome {
    /// The dig completed (no error).
    pub completed: bool,
    /// The error's message when it did not.
    pub error: Option<String>,
    /// (achieved − target)/target on the real boulder.
    pub volume_error: f64,
    /// (believed − target)/target: the planner's own count.
    pub believed_error: f64,
    /// Contacts.
    pub contacts: usize,
    /// Contacts beyond the first with each boulder.
    pub extra_contacts: usize,
    /// Least clearance of a detour from the real boulder (m) (NaN without one).
    pub min_detour_clearance_m: f64,
    /// Estimated radius after the last touch (m) (NaN without contact).
    pub estimated_radius_m: f64,
}

/// One case: the boulder and every planner's outcome (in [`VARIANTS`] order).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaseRow {
    /// Case index.
    pub index: usize,
    /// The boulder.
    pub boulder: Envelope,
    /// Outcomes.
    pub outcomes: Vec<CaseOutcome>,
}

/// One planner over the study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VariantSummary {
    /// Its name.
    pub planner: &'static str,
    /// Completed digs (%).
    pub completed_pct: f64,
    /// Median |volume error| over completed digs (%).
    pub median_abs_volume_error_pct: f64,
    /// 90th percentile |volume error| over completed digs (%).
    pub p90_abs_volume_error_pct: f64,
    /// Completed digs within 2 % of the target (%).
    pub within_2pct: f64,
    /// Mean contacts per case.
    pub mean_contacts: f64,
    /// Cases with a second touch on the same boulder (%).
    pub extra_contact_pct: f64,
    /// Least detour clearance from the real boulder over the study (m).
    pub min_detour_clearance_m: f64,
}

/// The study's summary (SPEC §6 style: the job, its settings, one row per planner).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoulderStudySummary {
    /// `study-boulders`.
    pub job: &'static str,
    /// The settings.
    pub params: BoulderStudyParams,
    /// The base scenario.
    pub scenario: String,
    /// The class prior radius for this bucket (m).
    pub class_radius_m: f64,
    /// One row per planner.
    pub planners: Vec<VariantSummary>,
}

/// The boulder of case `index` for `base` on `profile`.
pub fn draw_boulder(
    base: &Scenario,
    path: &[[f64; 2]],
    params: &BoulderStudyParams,
    index: usize,
) -> Envelope {
    let mut rng = ChaCha8Rng::seed_from_u64(
        params
            .seed
            .wrapping_mul(0x9E37_79B9)
            .wrapping_add(index as u64),
    );
    let start = Vec2::new(base.dig.start_x_m, base.ground.height(base.dig.start_x_m));
    loop {
        let r = rng.gen_range(params.radius_m[0]..=params.radius_m[1]);
        let k = rng.gen_range(
            (path.len() * 15 / 100)..(path.len() * 85 / 100).max(path.len() * 15 / 100 + 1),
        );
        let k = k.clamp(1, path.len() - 2);
        let p = Vec2::new(path[k][0], path[k][1]);
        let t = Vec2::new(
            path[k + 1][0] - path[k - 1][0],
            path[k + 1][1] - path[k - 1][1],
        );
        let n = Vec2::new(-t.y, t.x).normalize();
        let u: f64 = rng.gen_range(-0.8..0.8);
        let c = p + n * (u * r);
        let e = Envelope::new(c, r);
        if c.y + r <= base.ground.height(c.x) - 0.05 && !e.contains(start) {
            return e;
        }
    }
}

/// Runs case `index`: the boulder, then each planner.
pub fn run_case(
    base: &Scenario,
    profile: &MachineProfile,
    path: &[[f64; 2]],
    params: &BoulderStudyParams,
    index: usize,
) -> CaseRow {
    let boulder = draw_boulder(base, path, params, index);
    let outcomes = VARIANTS
        .iter()
        .map(|variant| {
            let mut s = base.clone();
            s.obstacles = vec![boulder];
            s.sensing.seed = params.seed.wrapping_add(index as u64);
            if *variant == "true size" {
                s.planner.boulder_radius_m = Some(boulder.radius_m);
            }
            outcome(&s, profile)
        })
        .collect();
    CaseRow {
        index,
        boulder,
        outcomes,
    }
}

fn outcome(s: &Scenario, profile: &MachineProfile) -> CaseOutcome {
    match excavate(s, profile) {
        Ok(ex) => {
            let mut per_boulder = vec![0usize; s.obstacles.len()];
            for c in &ex.contacts {
                per_boulder[c.obstacle] += 1;
            }
            CaseOutcome {
                completed: true,
                error: None,
                volume_error: ex.volume_error(),
                believed_error: (ex.believed_volume_m3 - ex.target_volume_m3) / ex.target_volume_m3,
                contacts: ex.contacts.len(),
                extra_contacts: per_boulder.iter().map(|n| n.saturating_sub(1)).sum(),
                min_detour_clearance_m: ex
                    .detours
                    .iter()
                    .map(|d| d.clearance_m)
                    .fold(f64::NAN, f64::min),
                estimated_radius_m: ex
                    .estimates
                    .last()
                    .map_or(f64::NAN, |e| e.envelope.radius_m),
            }
        }
        Err(e) => CaseOutcome {
            completed: false,
            error: Some(e.to_string()),
            volume_error: f64::NAN,
            believed_error: f64::NAN,
            contacts: 0,
            extra_contacts: 0,
            min_detour_clearance_m: f64::NAN,
            estimated_radius_m: f64::NAN,
        },
    }
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let k = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[k]
}

/// The study's summary from its rows.
pub fn summarize(
    params: &BoulderStudyParams,
    base: &Scenario,
    profile: &MachineProfile,
    rows: &[CaseRow],
) -> BoulderStudySummary {
    let n = rows.len().max(1) as f64;
    let planners = VARIANTS
        .iter()
        .enumerate()
        .map(|(v, name)| {
            let outs: Vec<&CaseOutcome> = rows.iter().map(|r| &r.outcomes[v]).collect();
            let done: Vec<&&CaseOutcome> = outs.iter().filter(|o| o.completed).collect();
            let mut errs: Vec<f64> = done.iter().map(|o| 100.0 * o.volume_error.abs()).collect();
            errs.sort_by(f64::total_cmp);
            VariantSummary {
                planner: name,
                completed_pct: 100.0 * done.len() as f64 / n,
                median_abs_volume_error_pct: percentile(&errs, 0.5),
                p90_abs_volume_error_pct: percentile(&errs, 0.9),
                within_2pct: 100.0 * errs.iter().filter(|e| **e < 2.0).count() as f64
                    / done.len().max(1) as f64,
                mean_contacts: done.iter().map(|o| o.contacts as f64).sum::<f64>()
                    / done.len().max(1) as f64,
                extra_contact_pct: 100.0
                    * done.iter().filter(|o| o.extra_contacts > 0).count() as f64
                    / done.len().max(1) as f64,
                min_detour_clearance_m: done
                    .iter()
                    .map(|o| o.min_detour_clearance_m)
                    .filter(|c| c.is_finite())
                    .fold(f64::INFINITY, f64::min),
            }
        })
        .collect();
    let b = &profile.bucket;
    BoulderStudySummary {
        job: "study-boulders",
        params: params.clone(),
        scenario: base.name.clone(),
        class_radius_m: crate::estimate::BoulderPrior::class_radius_m(b.capacity_m3, b.width_m),
        planners,
    }
}

/// The boulder-free level-1 path of `base` (where the study puts boulders).
pub fn boulder_free_path(
    base: &Scenario,
    profile: &MachineProfile,
) -> crate::Result<Vec<[f64; 2]>> {
    let mut s = base.clone();
    s.obstacles.clear();
    Ok(excavate(&s, profile)?.executed_path())
}
