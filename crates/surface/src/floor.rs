//! Roll and pitch of the sensor from the floor (SPEC §4.1: "also estimate α, β
//! from the floor, since a user rarely knows them"), for the horizontal
//! calibration of [RS eq. 11]–12.
//!
//! 1. Candidates: the lowest [`TiltParams::floor_fraction`] of the points by
//!    z (the floor in front of a pile is the lowest part of a scan as long as
//!    the sensor is tilted by much less than the pile face is steep).
//! 2. The floor plane `n · p = d` among them by RANSAC with least-squares
//!    refinement ([`crate::ransac_plane`]).
//! 3. The angles that level it: `T(α, β) · n = e_z`, i.e. `α = −asin n_y`,
//!    `β = atan2(n_x, n_z)` ([`crate::angles_from_normal`]). After
//!    [`crate::level`] with them the floor is the horizontal plane `z = d`.

use autoshovel_cloud::PointCloud;

use crate::calibrate::angles_from_normal;
use crate::error::{Result, SurfaceError};
use crate::ransac::{ransac_plane, RansacParams};

/// Parameters of [`estimate_tilt`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct TiltParams {
    /// Share of the points, lowest z first, searched for the floor, in
    /// (0, 1]. Default 0.3: the synthetic scans of [`crate::generate_pile`]
    /// have about a third of their points on the floor.
    pub floor_fraction: f64,
    /// Share of the candidates the floor plane must hold, in (0, 1].
    /// Default 0.2.
    pub min_inlier_fraction: f64,
    /// The RANSAC plane fit (threshold, confidence, seed, largest tilt).
    pub ransac: RansacParams,
}

impl Default for TiltParams {
    fn default() -> Self {
        Self {
            floor_fraction: 0.3,
            min_inlier_fraction: 0.2,
            ransac: RansacParams::default(),
        }
    }
}

impl TiltParams {
    /// The defaults for a scene of this length scale (1 for a mine face,
    /// 1/30 for the paper's model): the inlier threshold scales with it.
    pub fn for_scale(scale: f64) -> Self {
        let mut p = Self::default();
        p.ransac.inlier_threshold_m *= scale;
        p
    }

    /// Check the ranges once, at the edge.
    pub fn validate(&self) -> Result<()> {
        if !(self.floor_fraction > 0.0 && self.floor_fraction <= 1.0) {
            return Err(SurfaceError::BadParameter {
                name: "TiltParams.floor_fraction",
                value: self.floor_fraction,
                expected: "a share in (0, 1]",
            });
        }
        if !(self.min_inlier_fraction > 0.0 && self.min_inlier_fraction <= 1.0) {
            return Err(SurfaceError::BadParameter {
                name: "TiltParams.min_inlier_fraction",
                value: self.min_inlier_fraction,
                expected: "a share in (0, 1]",
            });
        }
        self.ransac.validate()
    }
}

/// The sensor attitude found from the floor.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TiltEstimate {
    /// Roll α of [RS eq. 11] [rad]: pass to [`crate::level`].
    pub roll_rad: f64,
    /// Pitch β of [RS eq. 11] [rad]: pass to [`crate::level`].
    pub pitch_rad: f64,
    /// Height of the floor in the levelled cloud [m] (negative the sensor's
    /// height above the floor for a sensor-centred scan).
    pub floor_height_m: f64,
    /// Unit floor normal in sensor coordinates, pointing up.
    pub normal: [f64; 3],
    /// Points on the floor plane (within the inlier threshold).
    pub inliers: usize,
    /// Low points searched.
    pub candidates: usize,
    /// Root-mean-square distance of the floor inliers from the plane [m].
    pub rms_m: f64,
    /// RANSAC hypotheses drawn.
    pub iterations: usize,
}

/// Estimate roll α and pitch β of [RS eq. 11] from the floor of a raw scan (see
/// the module docs). Same seed, same estimate.
///
/// ```
/// use autoshovel_surface::{estimate_tilt, generate_pile, level, PileParams, TiltParams};
/// let scan = generate_pile(&PileParams { points: 20_000, ..PileParams::default() }).unwrap();
/// let est = estimate_tilt(&scan, &TiltParams::default()).unwrap();
/// assert!((est.roll_rad.to_degrees() - 3.0).abs() < 0.2);
/// assert!((est.pitch_rad.to_degrees() + 2.0).abs() < 0.2);
/// let levelled = level(&scan, est.roll_rad, est.pitch_rad);
/// # assert_eq!(levelled.len(), scan.len());
/// ```
pub fn estimate_tilt(cloud: &PointCloud, params: &TiltParams) -> Result<TiltEstimate> {
    params.validate()?;
    let n = cloud.len();
    if n < 3 {
        return Err(SurfaceError::TooFewPoints {
            stage: "floor estimate",
            points: n,
            required: 3,
            hint: "",
        });
    }
    let take = ((params.floor_fraction * n as f64).ceil() as usize).clamp(3, n);
    let mut zs: Vec<f32> = cloud.points.iter().map(|p| p[2]).collect();
    let (_, z_cut, _) = zs.select_nth_unstable_by(take - 1, f32::total_cmp);
    let z_cut = *z_cut;
    drop(zs);
    let candidates: Vec<[f64; 3]> = cloud
        .points
        .iter()
        .filter(|p| p[2] <= z_cut)
        .map(|p| [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])])
        .collect();

    let fit = ransac_plane(&candidates, &params.ransac)?;
    let required = ((params.min_inlier_fraction * candidates.len() as f64).ceil() as usize).max(3);
    if fit.inliers.len() < required {
        return Err(SurfaceError::NoFloor {
            inliers: fit.inliers.len(),
            candidates: candidates.len(),
            required,
            max_tilt_deg: params.ransac.max_tilt_rad.to_degrees(),
        });
    }
    let (roll_rad, pitch_rad) =
        angles_from_normal(fit.plane.normal).expect("a RANSAC plane has a unit normal");
    Ok(TiltEstimate {
        roll_rad,
        pitch_rad,
        floor_height_m: fit.plane.offset_m,
        normal: fit.plane.normal,
        inliers: fit.inliers.len(),
        candidates: candidates.len(),
        rms_m: fit.rms_m,
        iterations: fit.iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::{level, tilt};
    use approx::assert_relative_eq;

    /// A level floor z = −2 (20 × 20 grid) and a wall of points above it.
    fn floor_and_wall() -> PointCloud {
        let mut pts = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                pts.push([i as f32 * 0.25, j as f32 * 0.25 - 5.0, -2.0]);
            }
        }
        for i in 0..40 {
            for k in 1..40 {
                pts.push([
                    10.0 + 0.1 * k as f32,
                    i as f32 * 0.25 - 5.0,
                    -2.0 + k as f32 * 0.2,
                ]);
            }
        }
        PointCloud::new(pts)
    }

    #[test]
    fn exact_floor_gives_exact_angles() {
        let (a, b) = (4f64.to_radians(), (-6f64).to_radians());
        let scan = tilt(&floor_and_wall(), a, b);
        let all = TiltParams {
            floor_fraction: 1.0,
            ..TiltParams::default()
        };
        let est = estimate_tilt(&scan, &all).unwrap();
        assert_relative_eq!(est.roll_rad, a, epsilon = 1e-6);
        assert_relative_eq!(est.pitch_rad, b, epsilon = 1e-6);
        assert_relative_eq!(est.floor_height_m, -2.0, epsilon = 1e-5);
        assert_eq!(est.inliers, 1600);
        // Levelling with the estimate puts the floor at z = floor_height_m.
        let flat = level(&scan, est.roll_rad, est.pitch_rad);
        for p in &flat.points[..1600] {
            assert_relative_eq!(f64::from(p[2]), -2.0, epsilon = 1e-4);
        }
    }

    #[test]
    fn too_few_points_and_bad_fraction_are_errors() {
        let err = estimate_tilt(&PointCloud::default(), &TiltParams::default()).unwrap_err();
        assert!(matches!(err, SurfaceError::TooFewPoints { points: 0, .. }));
        let p = TiltParams {
            floor_fraction: 0.0,
            ..TiltParams::default()
        };
        let err = estimate_tilt(&floor_and_wall(), &p).unwrap_err();
        assert!(
            err.to_string().contains("TiltParams.floor_fraction"),
            "{err}"
        );
    }
}
