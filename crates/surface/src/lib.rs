//! Muck-pile surfaces (SPEC §4.1; rope-shovel paper §3): horizontal
//! calibration of a scan by roll and pitch (eqs. 11–12), their estimate from
//! the floor by RANSAC, the surface `z = f(x, y)` of eq. 21 fitted by least
//! squares to an 8 × 8 sample grid with the paper's R² > 0.95 check, volumes
//! under a fitted surface, and synthetic scans of the four pile shapes of the
//! paper's Fig. 7.
//!
//! ```
//! use autoshovel_surface::{estimate_tilt, fit_surface, generate_pile, level};
//! use autoshovel_surface::{FitParams, PileParams, PileShape, TiltParams};
//! use autoshovel_cloud::PointCloud;
//!
//! // A tilted scan of a concave pile: roll 3°, pitch −2°.
//! let p = PileParams { shape: PileShape::Concave, points: 30_000, ..PileParams::default() };
//! let scan = generate_pile(&p).unwrap();
//! // Calibrate from the floor, level, cut the floor away (pass-through), fit.
//! let tilt = estimate_tilt(&scan, &TiltParams::default()).unwrap();
//! assert!((tilt.roll_rad - p.roll_rad).abs().to_degrees() < 0.2);
//! assert!((tilt.pitch_rad - p.pitch_rad).abs().to_degrees() < 0.2);
//! let flat = level(&scan, tilt.roll_rad, tilt.pitch_rad);
//! let pile = PointCloud::new(
//!     flat.points.into_iter().filter(|q| f64::from(q[2]) > tilt.floor_height_m + 0.2).collect(),
//! );
//! let surface = fit_surface(&pile, &FitParams::default()).unwrap();
//! assert!(surface.r2 > 0.95);
//! ```

// Units in brackets ("[m]", "[rad]") are the house style, not intra-doc links.
#![allow(rustdoc::broken_intra_doc_links)]

mod calibrate;
mod error;
mod fit;
mod floor;
mod pile;
mod ransac;
mod sample;
mod volume;

pub use calibrate::{angles_from_normal, level, level_from_sensor, sensor_from_level, tilt};
pub use error::{Result, SurfaceError};
pub use fit::{fit_samples, fit_surface, DegreeScore, FitParams, HeightMap, SurfaceFit, Term};
pub use floor::{estimate_tilt, TiltEstimate, TiltParams};
pub use pile::{generate_pile, PileParams, PileShape};
pub use ransac::{least_squares_plane, ransac_plane, Plane, PlaneFit, RansacParams};
pub use sample::{sample_grid, Extent, GridSample, SampleParams, Samples};
