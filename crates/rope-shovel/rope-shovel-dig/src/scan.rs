//! A scanned pile as the dig planner sees it: the dig profile cut from a
//! perceived scan's fitted surface z = f(x, y) ([RS eq. 21]), as
//! `autoshovel_terrain::perceive` returns it.
//!
//! The dig plane is the vertical plane through the middle of the fitted
//! extent in y (the scanner looks along +x at the face). The face height is
//! the highest of the fit's grid samples above the floor — the data, not
//! the polynomial, which may overshoot at the edges of its extent. The toe
//! is where the profile first rises [`TOE_RISE_SHARE`] of that face height
//! (10 mm on the 1:30 model's 0.33 m face, so the same rule serves a scan at
//! any scale); a fitted extent that starts on the face already is
//! continued down the face to the floor ([`DigSurface::from_fit`]).
//!
//! The machine of the profile must fit the pile: a face more than twice as
//! high as the top of its boom point sheave gets a hint (a full-size scan
//! for a scale-model machine?) that plan errors carry.

use std::path::Path;

use autoshovel_terrain::perceive::Perceived;
use autoshovel_terrain::{Extent, SurfaceFit};
use serde::Serialize;

use crate::dig_surface::DigSurface;
use crate::error::{DigError, Result};
use crate::profile::MachineProfile;

/// Share of the face height above the floor that marks the toe of a scanned pile.
pub const TOE_RISE_SHARE: f64 = 0.03;

/// A face higher than this many times the machine's reach (top of its boom
/// point sheave) is taken for a scan at another scale than the machine's.
pub const SCALE_MISMATCH_REACH_RATIO: f64 = 2.0;

/// The dig profile cut from a scan, and the numbers of the rule that cut it.
#[derive(Debug, Clone)]
pub struct ScanCut {
    /// The profile in the dig plane.
    pub surface: DigSurface,
    /// The dig plane y (m) (levelled frame).
    pub dig_plane_y_m: f64,
    /// Face height: the highest grid sample above the floor (m).
    pub face_height_m: f64,
    /// Rise above the floor that marks the toe (m).
    pub toe_rise_m: f64,
    /// Why a plan on this pile may fail (the scale check), if it may.
    pub hint: Option<String>,
}

/// Cuts the dig profile from the fitted surface `fit` of the scan `path`,
/// with the floor at `floor_height_m` (levelled frame), for the machine of
/// `profile` (module docs give the rule).
pub fn cut_scan(
    path: &Path,
    fit: &SurfaceFit,
    floor_height_m: f64,
    profile: &MachineProfile,
) -> Result<ScanCut> {
    // The fitted surface z = f(x, y) of [RS eq. 21], cut along y = dig_plane_y_m.
    let e = &fit.extent;
    let dig_plane_y_m = 0.5 * (e.y_min_m + e.y_max_m);
    let face_height_m = fit
        .samples
        .iter()
        .map(|s| s.z_m - floor_height_m)
        .fold(f64::NEG_INFINITY, f64::max);
    if !(face_height_m.is_finite() && face_height_m > 0.0) {
        return Err(DigError::ScanHasNoPile {
            path: path.to_path_buf(),
            floor_height_m,
        });
    }
    let toe_rise_m = TOE_RISE_SHARE * face_height_m;
    let surface = DigSurface::from_fit(
        fit,
        floor_height_m,
        dig_plane_y_m,
        profile.dipper.width_m,
        toe_rise_m,
    )
    .map_err(|e| DigError::ScanCut {
        path: path.to_path_buf(),
        dig_plane_y_m,
        source: Box::new(e),
    })?;
    let reach_m = profile.geometry().sheave_top_height;
    let hint = (face_height_m > SCALE_MISMATCH_REACH_RATIO * reach_m).then(|| {
        format!(
            "{}: the pile's face is {face_height_m:.2} m high but the machine of the profile \
             reaches {reach_m:.2} m at most (top of its boom point sheave): a full-size scan for \
             a scale-model machine? `autoshovel generate-pile --scale 0.0333` writes a pile at \
             the paper's 1:30 scale",
            path.display()
        )
    });
    Ok(ScanCut {
        surface,
        dig_plane_y_m,
        face_height_m,
        toe_rise_m,
        hint,
    })
}

/// The `perception` object of a plan on a scan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerceptionSummary {
    /// The file format read (none for a cloud given in memory).
    pub format: Option<&'static str>,
    /// Finite points read.
    pub input_points: usize,
    /// Points left after filtering.
    pub output_points: usize,
    /// Roll used to level (deg).
    pub roll_deg: f64,
    /// Pitch used to level (deg).
    pub pitch_deg: f64,
    /// Floor height in the levelled frame (m).
    pub floor_height_m: f64,
    /// Length scale of the scene.
    pub scale: f64,
    /// Degree of the fitted polynomial.
    pub fit_degree: usize,
    /// R² of the fit.
    pub r2: f64,
    /// The fitted extent.
    pub extent: Extent,
    /// The dig plane y (m).
    pub dig_plane_y_m: f64,
    /// Face height above the floor (m).
    pub face_height_m: f64,
    /// Rise that marks the toe (m).
    pub toe_rise_m: f64,
    /// Time spent in perception (ms).
    pub perceive_ms: f64,
}

impl PerceptionSummary {
    /// The summary of what perception made of a scan (`got`) and of the
    /// cut made from it.
    pub fn new(got: &Perceived, cut: &ScanCut) -> Self {
        Self {
            format: got.format,
            input_points: got.input_points,
            output_points: got.cloud.len(),
            roll_deg: got.roll_rad.to_degrees(),
            pitch_deg: got.pitch_rad.to_degrees(),
            floor_height_m: got.floor_height_m,
            scale: got.scale,
            fit_degree: got.fit.degree,
            r2: got.fit.r2,
            extent: got.fit.extent,
            dig_plane_y_m: cut.dig_plane_y_m,
            face_height_m: cut.face_height_m,
            toe_rise_m: cut.toe_rise_m,
            perceive_ms: got.total_ms(),
        }
    }
}

/// The scan a pile came from: the `cloud` and `perception` fields of a plan's summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScanSource {
    /// The scan file.
    pub cloud: String,
    /// What perception made of it.
    pub perception: PerceptionSummary,
}
