//! One plan attempt judged: what "success" means for a travel plan, the
//! comparison with the Theta* reference, and the `plan-path` job's summary.
//!
//! The rule is defined here once and used by `autoshovel plan-path`, the
//! random-road study ([`crate::study`]) and the tests alike:
//!
//! - **Success**: the plan exists (no bad pose, local minimum or collision)
//!   and *every* leg ends within the heading tolerance of the heading
//!   required there (the goal's, and on a V-shape the midpoint's too). A
//!   NaN heading error is a failure. A leg that arrives off its heading
//!   would leave the crawler to turn on the spot, which is what the walking
//!   paper's improved field is built to avoid.
//! - **Reference**: Theta* on the same map, leg by leg (start → midpoint →
//!   goal on a V-shape), summed; heading-free, so a near lower bound on the
//!   length of any path that visits the same poses.

use serde::Serialize;

use crate::apf::{ApfParams, FieldKind, ESCAPE_STRATEGY};
use crate::astar::{astar, AstarParams, Route, REFERENCE_PLANNER};
use crate::error::{PropelError, Result};
use crate::plan::{plan_path, LegStats, Plan, PlanOptions};
use crate::scenario::Scenario;
use crate::smooth::SmoothParams;

/// The heading tolerance of "success" unless told otherwise (deg).
pub const DEFAULT_HEADING_TOLERANCE_DEG: f64 = 2.0;

/// The first leg whose end misses its required heading by more than
/// `tolerance_deg` (NaN misses), as [`PropelError::HeadingNotMet`].
pub fn heading_failure(legs: &[LegStats], tolerance_deg: f64) -> Option<PropelError> {
    legs.iter()
        .enumerate()
        .find(|(_, l)| l.end_heading_error_deg.is_nan() || l.end_heading_error_deg > tolerance_deg)
        .map(|(leg, l)| PropelError::HeadingNotMet {
            leg,
            legs: legs.len(),
            error_deg: l.end_heading_error_deg,
            tolerance_deg,
        })
}

/// The Theta* reference route of a scenario, one route per leg (see the
/// module docs); `None` when any leg has no route.
pub fn reference_routes(scenario: &Scenario) -> Option<Vec<Route>> {
    scenario
        .legs()
        .iter()
        .map(|(from, to, _)| {
            astar(
                &scenario.map,
                from.position(),
                to.position(),
                scenario.footprint_radius_m,
                &AstarParams::default(),
            )
            .ok()
        })
        .collect()
}

/// Total length of a per-leg reference (m).
pub fn reference_length_m(routes: &[Route]) -> f64 {
    routes.iter().map(|r| r.length_m).sum()
}

/// A plan's length against the reference's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReferenceComparison {
    /// The reference planner's name.
    pub planner: &'static str,
    /// Reference length (m) (null when the reference finds no route).
    pub length_m: Option<f64>,
    /// Plan length over reference length (null without a plan or a reference).
    pub length_ratio: Option<f64>,
}

/// Compares a plan's length with a per-leg reference (see the module docs).
pub fn reference_comparison(
    plan_length_m: Option<f64>,
    reference: Option<&[Route]>,
) -> ReferenceComparison {
    let length_m = reference.map(reference_length_m);
    ReferenceComparison {
        planner: REFERENCE_PLANNER,
        length_m,
        length_ratio: plan_length_m.zip(length_m).map(|(p, r)| p / r),
    }
}

/// Why a plan attempt is not a success.
#[derive(Debug)]
pub enum Failure<'a> {
    /// Planning itself failed.
    Plan(&'a PropelError),
    /// A plan exists but a leg misses its heading ([`PropelError::HeadingNotMet`]).
    Heading(PropelError),
}

impl Failure<'_> {
    /// The error behind the failure.
    pub fn error(&self) -> &PropelError {
        match self {
            Failure::Plan(e) => e,
            Failure::Heading(e) => e,
        }
    }
}

impl std::fmt::Display for Failure<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.error().fmt(f)
    }
}

/// One plan attempt on a scenario: the options, the plan (or why it
/// failed) and the per-leg reference.
#[derive(Debug)]
pub struct PlanOutcome {
    /// The options planned with.
    pub options: PlanOptions,
    /// The plan, or why planning failed.
    pub plan: Result<Plan>,
    /// The Theta* reference, leg by leg (`None` when it finds no route).
    pub reference: Option<Vec<Route>>,
}

impl PlanOutcome {
    /// Plans `scenario` with `field`'s default options and runs the reference.
    pub fn plan(scenario: &Scenario, field: FieldKind) -> Self {
        Self::with_reference(
            scenario,
            PlanOptions::new(field),
            reference_routes(scenario),
        )
    }

    /// Plans `scenario` with `options` against an already computed reference.
    pub fn with_reference(
        scenario: &Scenario,
        options: PlanOptions,
        reference: Option<Vec<Route>>,
    ) -> Self {
        Self {
            options,
            plan: plan_path(scenario, &options),
            reference,
        }
    }

    /// Why this attempt is not a success within `tolerance_deg`, if it is not.
    pub fn failure(&self, tolerance_deg: f64) -> Option<Failure<'_>> {
        match &self.plan {
            Err(e) => Some(Failure::Plan(e)),
            Ok(plan) => heading_failure(&plan.legs, tolerance_deg).map(Failure::Heading),
        }
    }

    /// Planned, and every leg within `tolerance_deg` of its required heading.
    pub fn success(&self, tolerance_deg: f64) -> bool {
        self.failure(tolerance_deg).is_none()
    }

    /// The plan's length against the reference's.
    pub fn reference_comparison(&self) -> ReferenceComparison {
        reference_comparison(
            self.plan.as_ref().ok().map(|p| p.metrics.length_m),
            self.reference.as_deref(),
        )
    }

    /// The `plan-path` summary of this attempt on `scenario`.
    pub fn summary(&self, scenario: &Scenario, tolerance_deg: f64) -> PlanPathSummary {
        let failure = self.failure(tolerance_deg);
        let plan = self.plan.as_ref().ok();
        let m = plan.map(|p| &p.metrics);
        let f = |pick: fn(&crate::plan::PlanMetrics) -> f64| m.map(pick);
        let plan_error = self.plan.as_ref().err();
        PlanPathSummary {
            job: "plan-path",
            scenario: scenario.name.clone(),
            planner: self.options.field.name(),
            success: failure.is_none(),
            error: failure.as_ref().map(ToString::to_string),
            error_at_m: plan_error.and_then(|e| e.position()).map(|p| [p.x, p.y]),
            local_minimum: plan_error.is_some_and(|e| e.is_local_minimum()),
            heading_tolerance_deg: tolerance_deg,
            length_m: f(|m| m.length_m),
            min_clearance_m: f(|m| m.min_clearance_m),
            min_clearance_at_m: m.map(|m| m.min_clearance_at),
            final_heading_error_deg: f(|m| m.final_heading_error_deg),
            start_heading_error_deg: f(|m| m.start_heading_error_deg),
            cusp_heading_error_deg: f(|m| m.cusp_heading_error_deg),
            max_curvature_per_m: f(|m| m.max_curvature_per_m),
            mean_abs_curvature_per_m: f(|m| m.mean_abs_curvature_per_m),
            plan_time_ms: f(|m| m.plan_time_ms),
            iterations: m.map(|m| m.iterations),
            escapes: match (m, plan_error) {
                (Some(m), _) => m.escapes,
                (None, Some(e)) => e.escapes(),
                (None, None) => 0,
            },
            escape_strategy: m.filter(|m| m.escapes > 0).map(|_| ESCAPE_STRATEGY),
            footprint_radius_m: scenario.footprint_radius_m,
            legs: plan.map(|p| p.legs.clone()).unwrap_or_default(),
            reference: self.reference_comparison(),
            params: PlanParams {
                apf: self.options.apf,
                smooth: self.options.smooth,
            },
        }
    }
}

/// The field and smoothing parameters of a plan, as the summary shows them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlanParams {
    /// Field and descent parameters.
    pub apf: ApfParams,
    /// Smoothing parameters.
    pub smooth: SmoothParams,
}

/// The summary of `autoshovel plan-path` (SPEC §6): measures are null when
/// planning failed (and NaN serialises as null).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanPathSummary {
    /// Always `plan-path`.
    pub job: &'static str,
    /// Scenario name.
    pub scenario: String,
    /// Field descended: `apf` or `improved-apf`.
    pub planner: &'static str,
    /// See [`PlanOutcome::success`].
    pub success: bool,
    /// Why it is not a success.
    pub error: Option<String>,
    /// Where planning failed (m), when the error has a place.
    pub error_at_m: Option<[f64; 2]>,
    /// Planning failed in a local minimum.
    pub local_minimum: bool,
    /// Heading tolerance of success (deg).
    pub heading_tolerance_deg: f64,
    /// Smoothed length (m).
    pub length_m: Option<f64>,
    /// Smallest footprint clearance (m).
    pub min_clearance_m: Option<f64>,
    /// Where it is (m).
    pub min_clearance_at_m: Option<[f64; 2]>,
    /// Heading error on arrival at the goal (deg).
    pub final_heading_error_deg: Option<f64>,
    /// Heading error leaving the start (deg).
    pub start_heading_error_deg: Option<f64>,
    /// Largest heading mismatch at a cusp (deg).
    pub cusp_heading_error_deg: Option<f64>,
    /// Largest |curvature| (1/m).
    pub max_curvature_per_m: Option<f64>,
    /// Mean |curvature| (1/m).
    pub mean_abs_curvature_per_m: Option<f64>,
    /// Wall-clock planning time (ms).
    pub plan_time_ms: Option<f64>,
    /// Descent steps on all legs.
    pub iterations: Option<usize>,
    /// Local-minimum escapes used (or tried, on a local minimum).
    pub escapes: usize,
    /// The escape used, when one was.
    pub escape_strategy: Option<&'static str>,
    /// Footprint radius (m).
    pub footprint_radius_m: f64,
    /// Per-leg statistics (empty when planning failed).
    pub legs: Vec<LegStats>,
    /// Length against the Theta* reference.
    pub reference: ReferenceComparison,
    /// Planner parameters.
    pub params: PlanParams,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::{random_road, StudyParams};

    #[test]
    fn success_needs_every_leg_within_tolerance_and_nan_fails() {
        let leg = |e: f64| LegStats {
            direction: crate::Direction::Forward,
            iterations: 0,
            escapes: 0,
            control_spacing_m: 0.0,
            raw_length_m: 0.0,
            length_m: 0.0,
            end_heading_error_deg: e,
        };
        assert!(heading_failure(&[leg(0.5), leg(2.0)], 2.0).is_none());
        let e = heading_failure(&[leg(3.0), leg(0.0)], 2.0).unwrap();
        assert!(matches!(e, PropelError::HeadingNotMet { leg: 0, .. }));
        assert!(e.to_string().contains("the midpoint (end of leg 1)"), "{e}");
        assert!(heading_failure(&[leg(f64::NAN)], 2.0).is_some());
        assert!(heading_failure(&[leg(2.5)], 3.0).is_none());
    }

    #[test]
    fn on_one_leg_the_reference_is_the_whole_route_and_success_the_final_heading() {
        // The study's roads have no midpoint: per-leg and whole-route
        // reference agree, and so do "every leg" and "the final heading".
        let p = StudyParams::default();
        for i in 0..6 {
            let s = random_road(&p, i);
            let whole = astar(
                &s.map,
                s.start.position(),
                s.goal.position(),
                s.footprint_radius_m,
                &AstarParams::default(),
            )
            .ok()
            .map(|r| r.length_m);
            let per_leg = reference_routes(&s).map(|r| reference_length_m(&r));
            assert_eq!(whole, per_leg, "map {i}");
            let o = PlanOutcome::with_reference(
                &s,
                PlanOptions::new(FieldKind::Improved),
                reference_routes(&s),
            );
            if let Ok(plan) = &o.plan {
                assert_eq!(
                    o.success(p.heading_tolerance_deg),
                    plan.metrics.final_heading_error_deg <= p.heading_tolerance_deg,
                    "map {i}"
                );
            }
        }
    }

    #[test]
    fn the_v_shape_reference_visits_the_midpoint() {
        let s = Scenario::builtin("v-shape").unwrap();
        let legs = reference_routes(&s).unwrap();
        assert_eq!(legs.len(), 2);
        let direct = astar(
            &s.map,
            s.start.position(),
            s.goal.position(),
            s.footprint_radius_m,
            &AstarParams::default(),
        )
        .unwrap();
        assert!(reference_length_m(&legs) >= direct.length_m - 1e-9);
        let o = PlanOutcome::plan(&s, FieldKind::Improved);
        assert!(o.success(DEFAULT_HEADING_TOLERANCE_DEG));
        let r = o.reference_comparison();
        approx::assert_relative_eq!(
            r.length_ratio.unwrap(),
            o.plan.as_ref().unwrap().metrics.length_m / reference_length_m(&legs)
        );
    }
}
