//! The random haul-road study: many seeded maps of a bending road with 3–12
//! obstacles (trucks as rectangles, rocks and stockpiles as discs), planned
//! with the classic field, the improved field and the Theta* reference, to
//! measure success rate, local minima, length ratio to the reference,
//! clearance and final heading error.
//!
//! "Success" and the reference comparison are those of
//! [`crate::outcome`], the same rule as `autoshovel plan-path`'s (every leg
//! within the heading tolerance, the reference run leg by leg); the roads
//! here have one leg, so the rule is "the final heading within tolerance".

use autoshovel_core::{angle_diff, heading_vec, perp, Pose2, Vec2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::apf::FieldKind;
use crate::astar::REFERENCE_PLANNER;
use crate::map::{convex_polygon, Boundary, Map, Obstacle, Shape};
use crate::outcome::{reference_length_m, reference_routes, PlanOutcome};
use crate::path::Direction;
use crate::plan::PlanOptions;
use crate::scenario::Scenario;

/// Parameters of the study.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StudyParams {
    /// Number of maps.
    pub maps: usize,
    /// Seed of the map generator.
    pub seed: u64,
    /// Fewest obstacles on a map.
    pub min_obstacles: usize,
    /// Most obstacles on a map.
    pub max_obstacles: usize,
    /// Road length (m).
    pub road_length_m: f64,
    /// Heading tolerance for success (deg).
    pub heading_tolerance_deg: f64,
}

impl Default for StudyParams {
    fn default() -> Self {
        Self {
            maps: 500,
            seed: 1,
            min_obstacles: 3,
            max_obstacles: 12,
            road_length_m: 60.0,
            heading_tolerance_deg: crate::outcome::DEFAULT_HEADING_TOLERANCE_DEG,
        }
    }
}

/// Most maps one study may hold (a million maps take about two hours on
/// two cores; a cluster spreads them by seed ranges, `autoshovel.cluster`).
pub const MAX_STUDY_MAPS: usize = 1_000_000;

/// Most obstacles a map may hold.
pub const MAX_STUDY_OBSTACLES: usize = 60;

impl StudyParams {
    /// Checks the counts: 1 to [`MAX_STUDY_MAPS`] maps, and
    /// `min_obstacles <= max_obstacles <=` [`MAX_STUDY_OBSTACLES`].
    pub fn check(&self) -> crate::Result<()> {
        if self.maps == 0 || self.maps > MAX_STUDY_MAPS {
            return Err(crate::PropelError::BadStudy(format!(
                "maps = {} must be between 1 and {MAX_STUDY_MAPS}",
                self.maps
            )));
        }
        if self.min_obstacles > self.max_obstacles || self.max_obstacles > MAX_STUDY_OBSTACLES {
            return Err(crate::PropelError::BadStudy(format!(
                "min_obstacles = {} and max_obstacles = {} must satisfy min <= max <= {MAX_STUDY_OBSTACLES}",
                self.min_obstacles, self.max_obstacles
            )));
        }
        if !(self.road_length_m.is_finite()
            && self.road_length_m > 20.0
            && self.road_length_m <= 10_000.0)
        {
            return Err(crate::PropelError::BadStudy(format!(
                "road_length_m = {} must be above 20 m and at most 10 km",
                self.road_length_m
            )));
        }
        if !(self.heading_tolerance_deg.is_finite() && self.heading_tolerance_deg >= 0.0) {
            return Err(crate::PropelError::BadStudy(format!(
                "heading_tolerance_deg = {} must be a non-negative number",
                self.heading_tolerance_deg
            )));
        }
        Ok(())
    }
}

/// Generates map `index` of the study (same seed and index, same map).
pub fn random_road(params: &StudyParams, index: usize) -> Scenario {
    let mut rng =
        ChaCha8Rng::seed_from_u64(params.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ index as u64);
    let len = params.road_length_m;
    let amp = rng.gen_range(0.0..4.0);
    let wavelength = rng.gen_range(1.0..2.0) * len;
    let phase = rng.gen_range(0.0..std::f64::consts::TAU);
    let width = rng.gen_range(12.0..16.0);
    let center = |x: f64| amp * (std::f64::consts::TAU * x / wavelength + phase).sin();
    let slope = |x: f64| {
        amp * std::f64::consts::TAU / wavelength
            * (std::f64::consts::TAU * x / wavelength + phase).cos()
    };
    let at = |x: f64, off: f64| {
        let t = Vec2::new(1.0, slope(x)).normalize();
        Vec2::new(x, center(x)) + perp(t) * off
    };
    let xs: Vec<f64> = (0..=40).map(|i| len * i as f64 / 40.0).collect();
    let north: Vec<Vec2> = xs.iter().map(|&x| at(x, 0.5 * width)).collect();
    let south: Vec<Vec2> = xs.iter().map(|&x| at(x, -0.5 * width)).collect();
    let ymin = south.iter().map(|p| p.y).fold(f64::INFINITY, f64::min) - 2.0;
    let ymax = north.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max) + 2.0;
    let mut map = Map::new(
        Vec2::new(north[0].x.min(south[0].x).min(0.0), ymin),
        Vec2::new(len.max(north[40].x).max(south[40].x), ymax),
    );
    map.boundaries.push(Boundary {
        name: "north edge".into(),
        points: north,
    });
    map.boundaries.push(Boundary {
        name: "south edge".into(),
        points: south,
    });
    let heading = |x: f64| slope(x).atan();
    let start = Pose2::new(3.0, center(3.0), heading(3.0));
    let goal = Pose2::new(len - 3.0, center(len - 3.0), heading(len - 3.0));
    let r_fp = 1.0;
    let count = rng.gen_range(params.min_obstacles..=params.max_obstacles);
    let mut tries = 0;
    while map.obstacles.len() < count && tries < 1000 {
        tries += 1;
        let x = rng.gen_range(10.0..len - 10.0);
        let off = rng.gen_range(-0.5 * width..0.5 * width);
        let c = at(x, off);
        let shape = if rng.gen_bool(0.5) {
            Shape::Circle {
                center: c,
                radius: rng.gen_range(0.5..2.0),
            }
        } else {
            let (l, w) = (rng.gen_range(2.0..7.0), rng.gen_range(1.5..3.5));
            let a = heading(x) + rng.gen_range(-0.6..0.6);
            let (u, v) = (heading_vec(a), perp(heading_vec(a)));
            let verts = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
                .iter()
                .map(|(p, q)| c + u * (p * l) + v * (q * w))
                .collect();
            Shape::Polygon {
                vertices: convex_polygon(verts).expect("a rectangle is convex"),
            }
        };
        let ok = |p: Pose2| shape.nearest(p.position()).0 - r_fp > 1.5;
        if ok(start) && ok(goal) {
            let kind = if matches!(shape, Shape::Circle { .. }) {
                "rock"
            } else {
                "truck"
            };
            map.obstacles.push(Obstacle {
                name: format!("{kind} {}", map.obstacles.len() + 1),
                shape,
            });
        }
    }
    Scenario {
        name: format!("road-{}-{index}", params.seed),
        map,
        footprint_radius_m: r_fp,
        start,
        midpoint: None,
        goal,
        direction: Direction::Forward,
    }
}

/// One planner's result on one map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// Reached the goal with a collision-free smoothed path.
    pub reached: bool,
    /// Reached and within the heading tolerance.
    pub success: bool,
    /// Failed in a local minimum.
    pub local_minimum: bool,
    /// Smoothed length (m) (NaN on failure).
    #[serde(deserialize_with = "nan_if_null")]
    pub length_m: f64,
    /// Smallest footprint clearance (m) (NaN on failure).
    #[serde(deserialize_with = "nan_if_null")]
    pub min_clearance_m: f64,
    /// Final heading error (deg) (NaN on failure).
    #[serde(deserialize_with = "nan_if_null")]
    pub final_heading_error_deg: f64,
    /// Escapes used.
    pub escapes: usize,
    /// Planning time (ms).
    #[serde(deserialize_with = "nan_if_null")]
    pub plan_time_ms: f64,
    /// The error, if any.
    pub error: Option<String>,
}

/// A number that JSON wrote as `null` because it was NaN (serde_json
/// writes non-finite numbers so).
fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Rows as JSON text (exact: every finite number round-trips bit for bit,
/// NaN as `null`).
pub fn rows_to_json(rows: &[MapRow]) -> String {
    serde_json::to_string(rows).expect("rows serialise")
}

/// Rows written by [`rows_to_json`].
pub fn rows_from_json(text: &str) -> crate::Result<Vec<MapRow>> {
    serde_json::from_str(text).map_err(|e| crate::PropelError::BadStudy(format!("rows: {e}")))
}

/// One map's row (read back by [`rows_from_json`]: a study's rows can be
/// made in many places and summarised in one).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapRow {
    /// Map index.
    pub index: usize,
    /// Obstacles on the map.
    pub obstacles: usize,
    /// Reference length (m), `None` when the reference finds no path.
    pub reference_length_m: Option<f64>,
    /// Classic field.
    pub classic: Outcome,
    /// Improved field.
    pub improved: Outcome,
}

impl MapRow {
    /// The outcome of one field on this map.
    pub fn outcome(&self, field: FieldKind) -> &Outcome {
        match field {
            FieldKind::Classic => &self.classic,
            FieldKind::Improved => &self.improved,
        }
    }
}

/// Judges one attempt with the rule of [`crate::outcome`] (the same as
/// `plan-path`'s).
fn outcome(attempt: &PlanOutcome, tol_deg: f64) -> Outcome {
    let error = attempt.failure(tol_deg).map(|f| f.to_string());
    match &attempt.plan {
        Ok(plan) => {
            let m = &plan.metrics;
            Outcome {
                reached: true,
                success: error.is_none(),
                local_minimum: false,
                length_m: m.length_m,
                min_clearance_m: m.min_clearance_m,
                final_heading_error_deg: m.final_heading_error_deg,
                escapes: m.escapes,
                plan_time_ms: m.plan_time_ms,
                error,
            }
        }
        Err(e) => Outcome {
            reached: false,
            success: false,
            local_minimum: e.is_local_minimum(),
            length_m: f64::NAN,
            min_clearance_m: f64::NAN,
            final_heading_error_deg: f64::NAN,
            escapes: 0,
            plan_time_ms: f64::NAN,
            error,
        },
    }
}

/// Runs the study on map `index`: the reference once (leg by leg, as
/// `plan-path` runs it), then both fields against it.
pub fn run_map(params: &StudyParams, index: usize) -> MapRow {
    let s = random_road(params, index);
    let reference = reference_routes(&s);
    let judge = |field: FieldKind| {
        let attempt = PlanOutcome::with_reference(&s, PlanOptions::new(field), reference.clone());
        outcome(&attempt, params.heading_tolerance_deg)
    };
    MapRow {
        index,
        obstacles: s.map.obstacles.len(),
        reference_length_m: reference.as_deref().map(reference_length_m),
        classic: judge(FieldKind::Classic),
        improved: judge(FieldKind::Improved),
    }
}

/// Aggregates of one planner over the maps the reference solves.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Aggregate {
    /// Planner name.
    pub planner: &'static str,
    /// Maps counted (those the reference solves).
    pub maps: usize,
    /// Share reaching the goal collision-free (%).
    pub reached_pct: f64,
    /// Share reaching it within the heading tolerance (%).
    pub success_pct: f64,
    /// Local minima (failures).
    pub local_minima: usize,
    /// Other failures (collisions of the smoothed path).
    pub other_failures: usize,
    /// Mean length ratio to the reference over reached maps.
    pub mean_length_ratio: f64,
    /// Largest length ratio.
    pub max_length_ratio: f64,
    /// Mean of the minimum clearance (m).
    pub mean_min_clearance_m: f64,
    /// Smallest minimum clearance (m).
    pub min_min_clearance_m: f64,
    /// Mean final heading error over reached maps (deg).
    pub mean_final_heading_error_deg: f64,
    /// Largest final heading error over reached maps (deg).
    pub max_final_heading_error_deg: f64,
    /// Maps where an escape was used.
    pub maps_with_escapes: usize,
    /// Mean planning time (ms).
    pub mean_plan_time_ms: f64,
}

/// Aggregates rows for one field.
pub fn aggregate(rows: &[MapRow], field: FieldKind) -> Aggregate {
    let pick = |r: &MapRow| r.outcome(field).clone();
    let solved: Vec<&MapRow> = rows
        .iter()
        .filter(|r| r.reference_length_m.is_some())
        .collect();
    let n = solved.len().max(1) as f64;
    let reached: Vec<(&MapRow, Outcome)> = solved
        .iter()
        .map(|r| (*r, pick(r)))
        .filter(|(_, o)| o.reached)
        .collect();
    let m = reached.len().max(1) as f64;
    let ratio = |(r, o): &(&MapRow, Outcome)| o.length_m / r.reference_length_m.unwrap_or(f64::NAN);
    let max = |it: &mut dyn Iterator<Item = f64>| it.fold(f64::NAN, f64::max);
    let min = |it: &mut dyn Iterator<Item = f64>| it.fold(f64::NAN, f64::min);
    Aggregate {
        planner: field.name(),
        maps: solved.len(),
        reached_pct: 100.0 * reached.len() as f64 / n,
        success_pct: 100.0 * solved.iter().filter(|r| r.outcome(field).success).count() as f64 / n,
        local_minima: solved
            .iter()
            .filter(|r| r.outcome(field).local_minimum)
            .count(),
        other_failures: solved
            .iter()
            .filter(|r| !r.outcome(field).reached && !r.outcome(field).local_minimum)
            .count(),
        mean_length_ratio: reached.iter().map(ratio).sum::<f64>() / m,
        max_length_ratio: max(&mut reached.iter().map(ratio)),
        mean_min_clearance_m: reached.iter().map(|(_, o)| o.min_clearance_m).sum::<f64>() / m,
        min_min_clearance_m: min(&mut reached.iter().map(|(_, o)| o.min_clearance_m)),
        mean_final_heading_error_deg: reached
            .iter()
            .map(|(_, o)| o.final_heading_error_deg)
            .sum::<f64>()
            / m,
        max_final_heading_error_deg: max(&mut reached
            .iter()
            .map(|(_, o)| o.final_heading_error_deg)),
        maps_with_escapes: reached.iter().filter(|(_, o)| o.escapes > 0).count(),
        mean_plan_time_ms: reached.iter().map(|(_, o)| o.plan_time_ms).sum::<f64>() / m,
    }
}

/// Success rate (%) of `field` by obstacle count, over the maps the
/// reference solves: `(obstacles, percent)` for each count in
/// `min_obstacles..=max_obstacles` that has such maps.
pub fn success_by_obstacles(
    params: &StudyParams,
    rows: &[MapRow],
    field: FieldKind,
) -> Vec<(usize, f64)> {
    (params.min_obstacles..=params.max_obstacles)
        .filter_map(|n| {
            let sel: Vec<&MapRow> = rows
                .iter()
                .filter(|r| r.obstacles == n && r.reference_length_m.is_some())
                .collect();
            if sel.is_empty() {
                return None;
            }
            let ok = sel.iter().filter(|r| r.outcome(field).success).count();
            Some((n, 100.0 * ok as f64 / sel.len() as f64))
        })
        .collect()
}

/// The fields the study compares, in the order of its tables.
pub const FIELDS: [FieldKind; 2] = [FieldKind::Classic, FieldKind::Improved];

/// The reference's part of the study summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudyReference {
    /// The reference planner's name.
    pub planner: &'static str,
    /// Maps it solves.
    pub solved: usize,
    /// Share of maps it solves (%).
    pub solved_pct: f64,
}

/// The summary of `autoshovel study-paths` (SPEC §6).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudySummary {
    /// Always `study-paths`.
    pub job: &'static str,
    /// The command that reproduces the study.
    pub command: String,
    /// Maps planned.
    pub maps: usize,
    /// Seed of the map generator.
    pub seed: u64,
    /// Heading tolerance of success (deg).
    pub heading_tolerance_deg: f64,
    /// The reference planner's record.
    pub reference: StudyReference,
    /// One aggregate per field, in [`FIELDS`] order.
    pub planners: Vec<Aggregate>,
    /// The study ran (its findings are in `planners`).
    pub success: bool,
}

impl StudyParams {
    /// The command line that reproduces a study with these parameters.
    pub fn command(&self) -> String {
        format!(
            "autoshovel study-paths --maps {} --seed {} --min-obstacles {} --max-obstacles {}",
            self.maps, self.seed, self.min_obstacles, self.max_obstacles
        )
    }
}

/// Summarises the rows of a study run with `params`.
pub fn summarize(params: &StudyParams, rows: &[MapRow]) -> StudySummary {
    let solved = rows
        .iter()
        .filter(|r| r.reference_length_m.is_some())
        .count();
    StudySummary {
        job: "study-paths",
        command: params.command(),
        maps: params.maps,
        seed: params.seed,
        heading_tolerance_deg: params.heading_tolerance_deg,
        reference: StudyReference {
            planner: REFERENCE_PLANNER,
            solved,
            solved_pct: 100.0 * solved as f64 / params.maps as f64,
        },
        planners: FIELDS.iter().map(|f| aggregate(rows, *f)).collect(),
        success: true,
    }
}

/// Heading error helper for callers comparing poses (deg).
pub fn heading_error_deg(a: Pose2, b: Pose2) -> f64 {
    angle_diff(a.theta, b.theta).abs().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_are_reproducible_and_vary() {
        let p = StudyParams::default();
        assert_eq!(random_road(&p, 7), random_road(&p, 7));
        assert_ne!(random_road(&p, 7), random_road(&p, 8));
        let s = random_road(&p, 3);
        assert!(
            s.map.obstacles.len() >= p.min_obstacles && s.map.obstacles.len() <= p.max_obstacles
        );
    }

    #[test]
    fn a_small_study_runs_and_the_improved_field_beats_the_classic() {
        let p = StudyParams {
            maps: 20,
            ..Default::default()
        };
        let rows: Vec<MapRow> = (0..p.maps).map(|i| run_map(&p, i)).collect();
        let c = aggregate(&rows, FieldKind::Classic);
        let i = aggregate(&rows, FieldKind::Improved);
        assert!(c.maps > 10);
        assert!(i.success_pct > c.success_pct);
        assert!(
            i.mean_length_ratio >= 1.0 - 1e-9,
            "the reference is a lower bound: {}",
            i.mean_length_ratio
        );
    }

    #[test]
    fn rows_survive_json_and_shards_summarise_as_the_whole() {
        let p = StudyParams {
            maps: 12,
            seed: 4,
            ..Default::default()
        };
        let rows: Vec<MapRow> = (0..p.maps).map(|i| run_map(&p, i)).collect();
        // Failures carry NaN lengths: they must come back NaN, the rest bit for bit.
        assert!(rows.iter().any(|r| r.classic.length_m.is_nan()));
        let back = rows_from_json(&rows_to_json(&rows)).unwrap();
        let bits = |r: &MapRow| {
            serde_json::to_string(r).unwrap() // NaN and null alike; numbers exact
        };
        assert_eq!(
            rows.iter().map(bits).collect::<Vec<_>>(),
            back.iter().map(bits).collect::<Vec<_>>()
        );
        for (a, b) in rows.iter().zip(&back) {
            for (x, y) in [
                (a.classic.length_m, b.classic.length_m),
                (a.improved.min_clearance_m, b.improved.min_clearance_m),
                (
                    a.improved.final_heading_error_deg,
                    b.improved.final_heading_error_deg,
                ),
            ] {
                assert!(
                    x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
                    "{x} {y}"
                );
            }
        }
        // Two shards made apart, read back in the other order, summarise as the whole.
        let (lo, hi) = rows.split_at(5);
        let mut gathered = rows_from_json(&rows_to_json(hi)).unwrap();
        gathered.extend(rows_from_json(&rows_to_json(lo)).unwrap());
        gathered.sort_by_key(|r| r.index);
        let strip = |s: StudySummary| {
            let mut v = serde_json::to_value(s).unwrap();
            for planner in v["planners"].as_array_mut().unwrap() {
                planner.as_object_mut().unwrap().remove("mean_plan_time_ms");
            }
            v
        };
        assert_eq!(strip(summarize(&p, &gathered)), strip(summarize(&p, &rows)));
        assert!(rows_from_json("[{\"index\": 1}]").is_err());
    }

    #[test]
    fn study_counts_are_checked() {
        let ok = StudyParams::default();
        assert!(ok.check().is_ok());
        for bad in [
            StudyParams { maps: 0, ..ok },
            StudyParams {
                maps: MAX_STUDY_MAPS + 1,
                ..ok
            },
            StudyParams {
                min_obstacles: 5,
                max_obstacles: 4,
                ..ok
            },
            StudyParams {
                max_obstacles: 61,
                ..ok
            },
            StudyParams {
                road_length_m: f64::NAN,
                ..ok
            },
            StudyParams {
                heading_tolerance_deg: -1.0,
                ..ok
            },
        ] {
            let e = bad.check().unwrap_err().to_string();
            assert!(e.starts_with("study-paths: "), "{e}");
        }
    }
}
