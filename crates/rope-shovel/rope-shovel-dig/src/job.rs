//! One dig-planning job, as `autoshovel plan-dig` runs it: a machine and
//! optimiser setup ([`DigSetup`]), a pile ([`Pile`]: a pile of Fig. 7 or a
//! scan), the plan ([`plan_pile`], [RS eqs. 22–37] through
//! [`crate::plan_dig`]) and its typed summary ([`DigSummary`]: header,
//! decision, objective, c1–c18 with value, measured quantity, limit, bound
//! and units).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use autoshovel_optim::GwoParams;
use autoshovel_terrain::perceive::Perceived;
use autoshovel_terrain::PileShape;
use serde::Serialize;

use crate::dig_surface::DigSurface;
use crate::error::{DigError, Result};
use crate::pack::read_pack;
use crate::plan::{
    plan_dig, search_preset, Bound, DigModel, DigOutcome, DigPlan, DigSearch, SearchSpace,
};
use crate::profile::{Geometry, MachineProfile};
use crate::scan::{cut_scan, PerceptionSummary, ScanSource};
use crate::trajectory::Decision;

/// The machine and the optimiser settings of a run.
#[derive(Debug, Clone)]
pub struct DigSetup {
    /// The checked machine profile.
    pub profile: MachineProfile,
    /// Where it came from: a path or "builtin scale-model".
    pub profile_name: String,
    /// Optimiser settings ([`search_preset`]: the paper's 50 wolves, 100
    /// iterations).
    pub gwo: GwoParams,
    /// Evaluations of the CMA-ES polish after GWO ([`search_preset`]: 20 000).
    pub polish_evaluations: usize,
    /// Search coordinates.
    pub search: SearchSpace,
    /// Wolves to start from (an earlier plan's final pack).
    pub warm_start: Option<WarmStart>,
}

/// Wolves of an earlier plan's `pack.csv` to start from.
#[derive(Debug, Clone, PartialEq)]
pub struct WarmStart {
    /// The pack file.
    pub file: PathBuf,
    /// Its wolves, best first.
    pub wolves: Vec<Decision>,
}

impl WarmStart {
    /// Reads the pack at `file` ([`read_pack`]).
    pub fn load(file: &Path) -> Result<Self> {
        Ok(Self {
            file: file.to_path_buf(),
            wolves: read_pack(file)?,
        })
    }
}

/// Name of the built-in profile in summaries.
pub const BUILTIN_PROFILE_NAME: &str = "builtin scale-model";

impl DigSetup {
    /// The built-in 1:30 scale model with the dig planner's search preset
    /// ([`search_preset`]) at `seed`, in the bends coordinates.
    pub fn scale_model(seed: u64) -> Self {
        Self::new(MachineProfile::scale_model(), BUILTIN_PROFILE_NAME, seed)
    }

    /// `profile` (named `profile_name` in summaries) with [`search_preset`]
    /// at `seed`, in the bends coordinates and without a warm start.
    pub fn new(profile: MachineProfile, profile_name: impl Into<String>, seed: u64) -> Self {
        let preset = search_preset();
        Self {
            profile,
            profile_name: profile_name.into(),
            gwo: GwoParams { seed, ..preset.gwo },
            polish_evaluations: preset.polish_evaluations,
            search: SearchSpace::default(),
            warm_start: None,
        }
    }
}

impl DigSetup {
    /// The optimiser settings as one [`DigSearch`].
    pub fn search_settings(&self) -> DigSearch {
        DigSearch {
            gwo: self.gwo,
            polish_evaluations: self.polish_evaluations,
            ..search_preset()
        }
    }
}

/// The pile to dig and where it came from.
#[derive(Debug, Clone)]
pub struct Pile {
    /// The profile in the dig plane.
    pub surface: DigSurface,
    /// "typical", …, or "cloud".
    pub name: String,
    /// The scan and what perception made of it, for a scanned pile.
    pub scan: Option<ScanSource>,
    /// Why a plan on this pile may fail; added to its errors.
    pub hint: Option<String>,
    /// For a pile of Fig. 7, how it was rebuilt from Tables 4–5.
    pub rebuilt: Option<crate::paper::PaperPile>,
}

impl Pile {
    /// The pile `shape` of Fig. 7 rebuilt from Tables 4–5 for the dipper of
    /// `profile` ([`crate::paper::paper_pile`]): the face height at which
    /// Table 4's decision digs Table 5's fill, toe at the dig start.
    pub fn shape(shape: PileShape, profile: &MachineProfile) -> Result<Self> {
        let rebuilt = crate::paper::paper_pile(profile, shape)?;
        Ok(Self {
            surface: rebuilt.surface(profile.dipper.width_m),
            name: shape.name().to_string(),
            scan: None,
            hint: None,
            rebuilt: Some(rebuilt),
        })
    }

    /// The scanned pile `path` as perception saw it (`got`,
    /// `autoshovel_terrain::perceive::perceive_file`): the dig profile cut
    /// from its fitted surface by [`cut_scan`]'s rule, with what perception
    /// made of it.
    pub fn scan(path: &Path, got: &Perceived, profile: &MachineProfile) -> Result<Self> {
        let cut = cut_scan(path, &got.fit, got.floor_height_m, profile)?;
        let perception = PerceptionSummary::new(got, &cut);
        Ok(Self {
            surface: cut.surface,
            name: "cloud".into(),
            scan: Some(ScanSource {
                cloud: path.display().to_string(),
                perception,
            }),
            hint: cut.hint,
            rebuilt: None,
        })
    }
}

/// What every summary of a plan holds, feasible or not.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DigHeader {
    /// Always "plan-dig".
    pub job: &'static str,
    /// The pile's name.
    pub surface: String,
    /// Where its profile came from.
    pub surface_source: String,
    /// The scan (`cloud`, `perception`), for a scanned pile.
    #[serde(flatten)]
    pub scan: Option<ScanSource>,
    /// Optimiser seed.
    pub seed: u64,
    /// Search coordinates ([`SearchSpace::name`]).
    pub search_space: &'static str,
    /// First-pack placement ([`autoshovel_optim::Init::name`]).
    pub init: &'static str,
    /// Wolves.
    pub population: usize,
    /// Iterations.
    pub iterations: usize,
    /// Evaluations of the CMA-ES polish after GWO.
    pub polish_evaluations: usize,
    /// Constraint handling ([`autoshovel_optim::Constraints::name`]).
    pub constraint_handling: &'static str,
    /// The profile's path or "builtin scale-model".
    pub profile: String,
    /// The warm start, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warm_start: Option<WarmStartSummary>,
    /// Cutting resistance k_F (Pa).
    pub k_f_pa: f64,
    /// Fill resistance ratio ε.
    pub epsilon: f64,
    /// Normal-to-tangential resistance ratio ψ.
    pub psi: f64,
    /// Material density (kg/m³).
    pub density_kg_m3: f64,
    /// Weight of f1 in f.
    pub k1: f64,
    /// Weight of f2 in f.
    pub k2: f64,
}

/// The `warm_start` object of a summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WarmStartSummary {
    /// The pack file.
    pub file: String,
    /// Wolves used (at most the population).
    pub wolves: usize,
}

impl DigHeader {
    /// The header of a plan of `pile` with `setup`.
    pub fn new(pile: &Pile, setup: &DigSetup) -> Self {
        let p = &setup.profile;
        Self {
            job: "plan-dig",
            surface: pile.name.clone(),
            surface_source: pile.surface.source.clone(),
            scan: pile.scan.clone(),
            seed: setup.gwo.seed,
            search_space: setup.search.name(),
            init: setup.gwo.init.name(),
            population: setup.gwo.population,
            iterations: setup.gwo.iterations,
            polish_evaluations: setup.polish_evaluations,
            constraint_handling: setup.gwo.constraints.name(),
            profile: setup.profile_name.clone(),
            warm_start: setup.warm_start.as_ref().map(|w| WarmStartSummary {
                file: w.file.display().to_string(),
                wolves: w.wolves.len().min(setup.gwo.population),
            }),
            k_f_pa: p.material.cutting_resistance_pa,
            epsilon: p.material.fill_resistance_ratio,
            psi: p.material.normal_ratio,
            density_kg_m3: p.material.density_kg_m3,
            k1: p.objective.k1,
            k2: p.objective.k2,
        }
    }
}

/// One constraint of c1–c18 in a summary ([RS eqs. 29–35]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ConstraintReport {
    /// Normalised value (≤ 0 met).
    pub value: f64,
    /// Whether it is met.
    pub met: bool,
    /// The measured quantity.
    pub measured: f64,
    /// Its limit.
    pub limit: f64,
    /// Lower or upper bound.
    pub bound: Bound,
    /// Units of the quantity and the limit.
    pub units: &'static str,
}

/// c1–c18 of `o` by name, with the limits of `model`.
pub fn constraint_reports(
    model: &DigModel,
    o: &DigOutcome,
) -> BTreeMap<&'static str, ConstraintReport> {
    let limits = model.constraint_limits(o.decision.gx_m);
    limits
        .iter()
        .zip(&o.constraints)
        .zip(&o.measured)
        .map(|((lim, &value), &measured)| {
            (
                lim.name,
                ConstraintReport {
                    value,
                    met: value <= 0.0,
                    measured,
                    limit: lim.limit,
                    bound: lim.bound,
                    units: lim.units,
                },
            )
        })
        .collect()
}

/// The fields of a plan that came out.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanFields {
    /// a_x6 (m/s⁶).
    pub ax6: f64,
    /// a_y6 (m/s⁶).
    pub ay6: f64,
    /// Dig duration t_d (s).
    pub td_s: f64,
    /// End point g_x (m).
    pub gx_m: f64,
    /// End point g_y (m).
    pub gy_m: f64,
    /// Mid-dig bend in x (m).
    pub bend_x_m: f64,
    /// Mid-dig bend in y (m).
    pub bend_y_m: f64,
    /// f = k1·f1 + k2·f2 ([RS eq. 27]).
    pub f: f64,
    /// f1 (J/kg) ([RS eq. 25]).
    pub f1_j_per_kg: f64,
    /// f2 (s/kg) ([RS eq. 26]).
    pub f2_s_per_kg: f64,
    /// Mass dug (kg).
    pub m_dig_kg: f64,
    /// Volume dug (m³).
    pub volume_m3: f64,
    /// Fill factor V/V_cd.
    pub fill_factor: f64,
    /// Hoist energy (J).
    pub hoist_energy_j: f64,
    /// Crowd energy (J).
    pub crowd_energy_j: f64,
    /// c1–c18 by name.
    pub constraints: BTreeMap<&'static str, ConstraintReport>,
    /// Objective evaluations spent.
    pub evaluations: usize,
    /// First iteration whose best wolf was feasible.
    pub first_feasible_iteration: Option<usize>,
    /// Samples along the planned dig.
    pub samples: usize,
    /// The machine's derived geometry (left out of the all-surfaces summary).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub geometry: Option<Geometry>,
}

impl PlanFields {
    /// The fields of `plan` on `model`.
    pub fn new(model: &DigModel, plan: &DigPlan) -> Self {
        let o = &plan.outcome;
        let d = &o.decision;
        let [bend_x_m, bend_y_m] = d.bends();
        Self {
            ax6: d.ax6,
            ay6: d.ay6,
            td_s: d.td_s,
            gx_m: d.gx_m,
            gy_m: d.gy_m,
            bend_x_m,
            bend_y_m,
            f: o.f,
            f1_j_per_kg: o.f1_j_per_kg,
            f2_s_per_kg: o.f2_s_per_kg,
            m_dig_kg: o.m_dig_kg,
            volume_m3: o.volume_m3,
            fill_factor: o.fill_factor,
            hoist_energy_j: o.hoist_energy_j,
            crowd_energy_j: o.crowd_energy_j,
            constraints: constraint_reports(model, o),
            evaluations: plan.evaluations(),
            first_feasible_iteration: plan
                .search
                .history
                .iter()
                .find(|g| g.best_violation == 0.0)
                .map(|g| g.iteration),
            samples: plan.samples.len(),
            geometry: Some(model.shovel.geometry),
        }
    }

    /// The decision of the plan.
    pub fn decision(&self) -> Decision {
        Decision {
            ax6: self.ax6,
            ay6: self.ay6,
            td_s: self.td_s,
            gx_m: self.gx_m,
            gy_m: self.gy_m,
        }
    }
}

/// The summary of one `plan-dig` job (SPEC §6 names its fields).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DigSummary {
    /// What the plan was asked for.
    #[serde(flatten)]
    pub header: DigHeader,
    /// The plan, when one came out.
    #[serde(flatten)]
    pub plan: Option<PlanFields>,
    /// Whether the plan meets c1–c18.
    pub feasible: bool,
    /// Whether the job succeeded (a feasible plan).
    pub success: bool,
    /// Why no plan came out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Wall time of the plan (ms).
    pub plan_time_ms: f64,
}

/// A planned pile: the summary, the model and the plan (none when the
/// optimiser found no feasible plan; `summary.error` says why).
#[derive(Debug, Clone)]
pub struct PlannedPile {
    /// The job's summary.
    pub summary: DigSummary,
    /// The planning model of the machine on the pile.
    pub model: DigModel,
    /// The plan, if one came out.
    pub plan: Option<DigPlan>,
}

/// Plans the dig of `pile` with `setup` ([`plan_dig`] from the warm start's
/// wolves, if any). A pile the machine cannot dig at all is an error
/// ([`DigError::Pile`]); a plan that misses a constraint is a
/// [`PlannedPile`] without a plan and with `summary.error` set.
pub fn plan_pile(pile: &Pile, setup: &DigSetup) -> Result<PlannedPile> {
    let mut model =
        DigModel::new(&setup.profile, pile.surface.clone()).map_err(|e| DigError::Pile {
            pile: pile.name.clone(),
            surface_source: pile.surface.source.clone(),
            cause: Box::new(e),
            hint: pile.hint.clone(),
        })?;
    model.set_search_space(setup.search);
    let t0 = Instant::now();
    let warm: Vec<Vec<f64>> = setup
        .warm_start
        .iter()
        .flat_map(|w| w.wolves.iter().take(setup.gwo.population))
        .map(|d| model.vector(d))
        .collect();
    let result = plan_dig(&model, &setup.search_settings(), &warm);
    let plan_time_ms = t0.elapsed().as_secs_f64() * 1e3;
    let header = DigHeader::new(pile, setup);
    let (summary, plan) = match result {
        Ok(plan) => {
            let feasible = plan.outcome.feasible();
            let summary = DigSummary {
                header,
                plan: Some(PlanFields::new(&model, &plan)),
                feasible,
                success: feasible,
                error: None,
                plan_time_ms,
            };
            (summary, Some(plan))
        }
        Err(e) => {
            let note = pile
                .hint
                .as_ref()
                .map(|h| format!("\nnote: {h}"))
                .unwrap_or_default();
            let summary = DigSummary {
                header,
                plan: None,
                feasible: false,
                success: false,
                error: Some(format!("{} pile: {e}{note}", pile.name)),
                plan_time_ms,
            };
            (summary, None)
        }
    };
    Ok(PlannedPile {
        summary,
        model,
        plan,
    })
}
