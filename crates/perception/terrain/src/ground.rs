//! How `perceive` levels a scan and what it takes for the ground, for the
//! clouds users have: a sensor's scan with the floor in view (the paper's
//! case), a survey already in a projected CRS (z is up), a bin or a slope
//! seen from above with no floor at all.
//!
//! | `[level] mode` | what runs |
//! |---|---|
//! | `auto` (default) | a georeferenced survey is level already; otherwise estimate from the floor if one is in view, else take the scan as level and say so |
//! | `estimate` | roll and pitch from the floor; no floor is an error |
//! | `given` | the `roll_deg`, `pitch_deg` given |
//! | `none` | the scan is level |
//!
//! | `[ground] mode` | the cut below the material, and the volume's base |
//! |---|---|
//! | `auto` (default) | `floor` when the scan shows one, else `none` |
//! | `floor` | the floor found by RANSAC ([`crate::estimate_tilt`]), cut `margin_m` above it |
//! | `height` | the plane z = `height_m` (the file's frame), cut `margin_m` above it |
//! | `none` | no cut; the volume's base is the lowest cleaned point |
//! | `surface` | no cut; the base is another scan of the same place (`surface`, a file): the empty bin, the pad before the stockpile, last month's survey; the volume is the fill above it, and the change (fill, cut, net) is reported |
//!
//! What ran is named in the summary (`level_mode`, `ground_mode`) with the
//! reason when `auto` chose, and the advice of a refusal names the modes
//! that would work.

use autoshovel_point_cloud::PointCloud;
use serde::{Deserialize, Serialize};

use crate::calibrate::level;
use crate::error::{Result, SurfaceError};
use crate::floor::{estimate_tilt, TiltEstimate, TiltParams};

/// How the ground is taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum GroundMode {
    /// `floor` when the scan shows one, else `none`.
    #[default]
    Auto,
    /// The floor found by RANSAC.
    Floor,
    /// A given height.
    Height,
    /// No ground cut.
    None,
    /// Another scan's surface as the base, no cut.
    Surface,
}

impl GroundMode {
    /// Its name in settings and summaries.
    pub fn name(self) -> &'static str {
        match self {
            GroundMode::Auto => "auto",
            GroundMode::Floor => "floor",
            GroundMode::Height => "height",
            GroundMode::None => "none",
            GroundMode::Surface => "surface",
        }
    }
}

/// What the level and ground stages did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroundUsed {
    /// The levelling that ran: estimate, given or none.
    pub level_mode: &'static str,
    /// The ground that ran: floor, height or none.
    pub ground_mode: &'static str,
    /// Why, where `auto` chose.
    pub note: Option<String>,
    /// The cut's height in the levelled frame, when there is a cut.
    pub cut_at: Option<f64>,
}

/// The levelled cloud, its angles, the ground taken and the floor record.
pub(crate) struct Levelled {
    pub(crate) cloud: PointCloud,
    pub(crate) roll: f64,
    pub(crate) pitch: f64,
    pub(crate) floor: TiltEstimate,
    pub(crate) used: GroundUsed,
}

/// The level settings the steps read.
pub(crate) struct LevelAsked {
    pub(crate) mode: crate::perceive::LevelMode,
    pub(crate) roll_rad: f64,
    pub(crate) pitch_rad: f64,
    pub(crate) ground: GroundMode,
    pub(crate) height_m: Option<f64>,
    pub(crate) margin: f64,
}

/// A record for a ground that is not a found floor: the plane z = `height`
/// with no points counted on it.
fn no_floor_found(height: f64, n: usize) -> TiltEstimate {
    TiltEstimate {
        roll_rad: 0.0,
        pitch_rad: 0.0,
        floor_height_m: height,
        normal: [0.0, 0.0, 1.0],
        inliers: 0,
        candidates: n,
        below: 0,
        rms_m: 0.0,
        iterations: 0,
    }
}

/// Whether the cloud's CRS says it is a map projection (x, y, z in a
/// length unit with z up): a survey, level already.
fn is_survey(cloud: &PointCloud) -> bool {
    cloud.georef.crs.unit.metres().is_some()
}

/// What step 1 decided: roll, pitch, the floor found while finding them,
/// the mode that ran and why.
type Angles = (f64, f64, Option<TiltEstimate>, &'static str, Option<String>);

/// Step 1: the angles, and the floor found while finding them.
fn angles(cloud: &PointCloud, a: &LevelAsked, tilt: &TiltParams) -> Result<Angles> {
    use crate::perceive::LevelMode;
    let estimate = |why: &'static str| -> Result<_> {
        let est = estimate_tilt(cloud, tilt).map_err(|e| stage(why, e))?;
        Ok((est.roll_rad, est.pitch_rad, Some(est), "estimate", None))
    };
    match a.mode {
        LevelMode::Estimate => estimate("estimating roll and pitch from the floor"),
        LevelMode::Given => {
            if !(a.roll_rad.is_finite() && a.pitch_rad.is_finite()) {
                return Err(SurfaceError::BadParameter {
                    name: "level.roll_deg / level.pitch_deg",
                    value: if a.roll_rad.is_finite() { a.pitch_rad } else { a.roll_rad },
                    expected: "finite angles",
                });
            }
            Ok((a.roll_rad, a.pitch_rad, None, "given", None))
        }
        LevelMode::None => Ok((0.0, 0.0, None, "none", None)),
        LevelMode::Auto if is_survey(cloud) => Ok((
            0.0,
            0.0,
            None,
            "none",
            Some(format!(
                "level: none, the scan is a survey in {} (z is up)",
                cloud.georef.crs
            )),
        )),
        LevelMode::Auto => match estimate_tilt(cloud, tilt) {
            Ok(est) => Ok((est.roll_rad, est.pitch_rad, Some(est), "estimate", None)),
            Err(SurfaceError::NoFloor { inliers, .. }) => Ok((
                0.0,
                0.0,
                None,
                "none",
                Some(format!(
                    "level: none, no floor in view (the best floor holds {inliers} points): the scan is taken as level; \
                     give roll and pitch ([level] mode = \"given\") if it is not"
                )),
            )),
            Err(e) => Err(stage("estimating roll and pitch from the floor", e)),
        },
    }
}

fn stage(what: &'static str, e: SurfaceError) -> SurfaceError {
    SurfaceError::Stage {
        stage: what,
        source: Box::new(e),
    }
}

/// Levels `cloud` and takes its ground as `a` asks (module docs).
pub(crate) fn level_and_ground(
    cloud: &PointCloud,
    a: &LevelAsked,
    tilt: &TiltParams,
) -> Result<Levelled> {
    let (roll, pitch, found, level_mode, level_note) = angles(cloud, a, tilt)?;
    let levelled = PointCloud {
        points: if roll != 0.0 || pitch != 0.0 {
            level(cloud, roll, pitch).points
        } else {
            cloud.points.clone()
        },
        origin: cloud.origin,
        attributes: cloud.attributes.clone(),
        georef: cloud.georef.clone(),
    };
    // A floor found while levelling is the levelled cloud's floor too:
    // levelling turns its normal onto z and keeps its offset ([RS eq. 11]–12).
    let found = found.map(|est| TiltEstimate {
        roll_rad: 0.0,
        pitch_rad: 0.0,
        normal: [0.0, 0.0, 1.0],
        ..est
    });
    let n = levelled.len();
    let lowest = || levelled.bounds().map_or(0.0, |(lo, _)| f64::from(lo[2]));
    let (floor, ground_mode, ground_note) = match a.ground {
        GroundMode::Floor => match found {
            Some(f) => (f, "floor", None),
            None => (
                estimate_tilt(&levelled, tilt).map_err(|e| {
                    stage(
                        "finding the floor (set [ground] mode = \"none\" for no ground cut, or \"height\" with height_m)",
                        e,
                    )
                })?,
                "floor",
                None,
            ),
        },
        GroundMode::Height => {
            let Some(h) = a.height_m.filter(|h| h.is_finite()) else {
                return Err(SurfaceError::BadParameter {
                    name: "ground.height_m",
                    value: a.height_m.unwrap_or(f64::NAN),
                    expected: "a finite height (the file's frame) with [ground] mode = \"height\"",
                });
            };
            let h = h - cloud.origin[2];
            (no_floor_found(h, n), "height", None)
        }
        GroundMode::None => (no_floor_found(lowest(), n), "none", None),
        GroundMode::Surface => (no_floor_found(lowest(), n), "surface", None),
        GroundMode::Auto => match found.map_or_else(|| estimate_tilt(&levelled, tilt), Ok) {
            Ok(f) => (f, "floor", None),
            Err(SurfaceError::NoFloor { inliers, .. }) => (
                no_floor_found(lowest(), n),
                "none",
                Some(format!(
                    "ground: none, no floor in view (the best floor holds {inliers} points): nothing is cut, \
                     and the volume's base is the lowest cleaned point; give [ground] mode = \"height\" with height_m for a known base"
                )),
            ),
            Err(e) => return Err(stage("finding the floor", e)),
        },
    };
    let cut_at =
        (!matches!(ground_mode, "none" | "surface")).then_some(floor.floor_height_m + a.margin);
    let note = match (level_note, ground_note) {
        (Some(l), Some(g)) => Some(format!("{l}; {g}")),
        (l, g) => l.or(g),
    };
    Ok(Levelled {
        cloud: levelled,
        roll,
        pitch,
        floor,
        used: GroundUsed {
            level_mode,
            ground_mode,
            note,
            cut_at,
        },
    })
}
