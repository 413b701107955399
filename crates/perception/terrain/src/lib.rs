//! Muck-pile surfaces (SPEC §4.1; rope-shovel paper §3): horizontal
//! calibration of a scan by roll and pitch ([RS eq. 11]–[RS eq. 12]), their estimate from
//! the floor by RANSAC, the surface `z = f(x, y)` of [RS eq. 21] fitted by least
//! squares to an 8 × 8 sample grid with the paper's R² > 0.95 check, volumes
//! under a fitted surface, and synthetic scans of the four pile shapes of the
//! paper's Fig. 7.
//!
//! The paper's whole §3 pipeline is one call, [`perceive::perceive`], with
//! one set of defaults ([`perceive::PerceptionParams`]); the stages are
//! public for other uses:
//!
//! ```
//! use autoshovel_terrain::perceive::{perceive, PerceptionParams};
//! use autoshovel_terrain::{generate_pile, PileParams, PileShape};
//!
//! // A tilted scan of a concave pile: roll 3°, pitch −2°.
//! let p = PileParams { shape: PileShape::Concave, points: 30_000, ..PileParams::default() };
//! let scan = generate_pile(&p).unwrap();
//! // Calibrate from the floor, level, filter, fit: every stage counted and timed.
//! let got = perceive(&scan, &PerceptionParams::default()).unwrap();
//! assert!((got.roll_rad - p.roll_rad).abs().to_degrees() < 0.2);
//! assert!((got.pitch_rad - p.pitch_rad).abs().to_degrees() < 0.2);
//! assert!(got.fit.r2 > 0.95);
//! assert_eq!(got.stages.last().unwrap().stage, "fit");
//! ```

mod calibrate;
pub mod chain;
pub mod dem;
mod error;
mod fit;
mod floor;
pub mod frames;
pub mod ground;
pub mod perceive;
mod ransac;
mod sample;
mod synthetic;
pub mod tiles;
mod volume;
mod wide;

pub use calibrate::{angles_from_normal, level, level_from_sensor, sensor_from_level, tilt};
pub use error::{Result, SurfaceError};
pub use fit::{fit_samples, fit_surface, DegreeScore, FitParams, HeightMap, SurfaceFit, Term};
pub use floor::{estimate_tilt, TiltEstimate, TiltParams, MAX_FLOOR_TILT_DEG};
pub use ransac::{least_squares_plane, ransac_plane, Plane, PlaneFit, RansacParams};
pub use sample::{sample_grid, Extent, GridSample, SampleParams, Samples};
pub use synthetic::{
    generate_pile, GeneratePileSummary, PileParams, PileShape, ScanPattern, MAX_SCALE, MIN_SCALE,
};
