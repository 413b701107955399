//! The rope-shovel paper's combined filtering process (§3, SPEC §4.1) as one
//! call: level (`[RS eq. 11]`–`[RS eq. 12]`, roll and pitch given or
//! estimated from the floor by RANSAC) → pass-through floor removal →
//! radius outlier removal (`[RS eq. 13]`) → statistical outlier removal
//! (`[RS eq. 14]`–`[RS eq. 16]`) → voxel grid (`[RS eq. 17]`–`[RS eq. 18]`)
//! → normal-based bilateral smoothing (`[RS eq. 19]`–`[RS eq. 20]`) →
//! surface fit on the 8 × 8 grid (`[RS eq. 21]`) with R². Every stage is
//! counted and timed.
//!
//! The paper gives no filter parameters. Filter lengths are given in units of
//! the scan's mean point spacing (`spacing = "auto"`: √(horizontal extent
//! area / points)), so the same settings serve a 100 k-point and a 10 M-point
//! scan; the floor margin, the RANSAC inlier threshold and the smoothing's
//! σ_n are given at the scale of a full-size 10 m face and multiplied by
//! `scale` (`"auto"`: the larger horizontal extent over 30 m, so the paper's
//! 1:30 model gets 1:30). [`PerceptionParams::default`] is the one set of
//! defaults; `tests/pipeline.rs` checks it on the four pile shapes of Fig. 7.
//!
//! ```
//! use autoshovel_terrain::perceive::PerceptionParams;
//!
//! // The settings file of `autoshovel perceive --config`: any key may be left out.
//! let toml = "[statistical]\nmean_k = 30\n";
//! let p: PerceptionParams = autoshovel_core::config::TomlFile::from_toml(toml, "my.toml").unwrap();
//! assert_eq!(p.statistical.mean_k, 30);
//! assert_eq!(p.voxel, PerceptionParams::default().voxel);
//! // A bad value is refused naming the file, the line and the key.
//! let err = <PerceptionParams as autoshovel_core::config::TomlFile>::from_toml(
//!     "[voxel]\nleaf_spacings = -1\n", "my.toml").unwrap_err();
//! assert!(err.to_string().starts_with("my.toml:2: [voxel] leaf_spacings = -1"), "{err}");
//! ```

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use autoshovel_core::config::{self, TomlFile};
use autoshovel_point_cloud::filter::{
    bilateral_normal_smoothing, pass_through_indices, radius_outlier_removal_indices,
    radius_outlier_removal_then, range_indices, statistical_outlier_removal_indices, voxel_grid,
    BilateralParams, OutlierSides, PassThroughParams, RadiusKept, RadiusOutlierParams, RangeLimits,
    StatisticalOutlierParams, VoxelGridParams,
};
use autoshovel_point_cloud::{CloudError, PointCloud};
use serde::{Deserialize, Serialize};

use crate::calibrate::level;
use crate::dem::{Change, GridSummary, HeightGrid};
use crate::error::{Result, SurfaceError};
use crate::fit::{fit_surface, FitParams, SurfaceFit, Term};
use crate::floor::{TiltEstimate, TiltParams};
use crate::ground::{level_and_ground, GroundMode, GroundUsed, LevelAsked, Levelled};

/// How the scan is levelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LevelMode {
    /// A survey in a projected CRS is level; otherwise estimate from the
    /// floor when one is in view, else take the scan as level (ground.rs).
    Auto,
    /// Estimate roll and pitch from the floor (RANSAC plane).
    Estimate,
    /// Use the given roll and pitch.
    Given,
    /// The scan is level already.
    None,
}

/// A length scale: a number, or "auto" (from the scan).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ScaleSetting {
    /// A fixed value.
    Factor(f64),
    /// "auto".
    Word(AutoWord),
}

// By hand, so that a wrong word is named in the user's terms rather than as
// serde's "untagged enum ScaleSetting".
impl<'de> Deserialize<'de> for ScaleSetting {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = ScaleSetting;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or \"auto\"")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> std::result::Result<Self::Value, E> {
                Ok(ScaleSetting::Factor(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> std::result::Result<Self::Value, E> {
                Ok(ScaleSetting::Factor(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<Self::Value, E> {
                Ok(ScaleSetting::Factor(v as f64))
            }
            fn visit_str<E: serde::de::Error>(
                self,
                v: &str,
            ) -> std::result::Result<Self::Value, E> {
                if v == "auto" {
                    Ok(ScaleSetting::Word(AutoWord::Auto))
                } else {
                    Err(E::custom(format!(
                        "\"{v}\" is not a length: expected a number or \"auto\""
                    )))
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// The word "auto".
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AutoWord {
    /// From the scan's extent.
    Auto,
}

/// The settings of [`perceive`] (the TOML of `autoshovel perceive --config`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PerceptionParams {
    /// Length scale of the scene: a number, or "auto" (larger horizontal extent / 30 m).
    pub scale: ScaleSetting,
    /// Mean point spacing (m): a number, or "auto" (√(area / points)).
    pub spacing: ScaleSetting,
    /// Selection by dimension ranges, before anything else.
    pub range: RangeStage,
    /// Levelling.
    pub level: LevelStage,
    /// Floor removal.
    pub ground: GroundStage,
    /// Radius outlier removal.
    pub radius: RadiusStage,
    /// Statistical outlier removal.
    pub statistical: StatisticalStage,
    /// Voxel grid.
    pub voxel: VoxelStage,
    /// Bilateral smoothing.
    pub smooth: SmoothStage,
    /// Surface fit.
    pub fit: FitStage,
}

/// Selection settings: PDAL's range filter (`filters.range`) on the
/// file's dimensions, first of all the stages, e.g. `limits =
/// "Classification[2:2]"` to perceive a classified survey's ground
/// without its trees and buildings. Unset, every point goes on.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RangeStage {
    /// PDAL's ranges (`Dimension[MIN:MAX]`, `!` negates, `(`/`)` open
    /// ends, comma-separated; one dimension's ranges ORed, different
    /// dimensions' ANDed); X, Y and Z are the file's coordinates.
    pub limits: Option<String>,
}

/// Levelling settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LevelStage {
    /// auto, estimate, given or none (ground.rs).
    pub mode: LevelMode,
    /// Roll α (deg) when given.
    pub roll_deg: f64,
    /// Pitch β (deg) when given.
    pub pitch_deg: f64,
    /// Smallest share of the points the floor must hold (the floor is the
    /// plane with the most points and almost nothing below it; see
    /// `autoshovel_terrain::estimate_tilt`).
    pub min_floor_share: f64,
}

/// Floor removal settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroundStage {
    /// auto, floor, height or none (ground.rs).
    pub mode: GroundMode,
    /// The base's height for mode "height" (the file's frame).
    pub height_m: Option<f64>,
    /// The base's scan for mode "surface": a cloud file of the same place
    /// in the same frame (CRS, or sensor pose), read as `--input` is;
    /// a relative path is from the working folder.
    pub surface: Option<String>,
    /// Keep points this far above the floor and higher (m at scale 1).
    pub margin_m: f64,
}

/// Most neighbour visits per point one filter stage may cost (all its
/// passes). The defaults cost about 28 (radius), 20 (statistical) and 113
/// (smoothing); 10⁴ keeps a million-point cloud's stage within minutes.
pub const MAX_NEIGHBOUR_VISITS: f64 = 1e4;

/// One neighbourhood stage's cost: the setting that sizes it and the
/// neighbour visits per point it implies.
struct StageWork {
    table: &'static str,
    key: &'static str,
    value: f64,
    visits: f64,
    how: String,
}

/// Radius outlier removal settings (`[RS eq. 13]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RadiusStage {
    /// Run it.
    pub enabled: bool,
    /// Search radius K_s (point spacings).
    pub radius_spacings: f64,
    /// Fewest neighbours to keep a point.
    pub min_neighbors: usize,
}

/// Statistical outlier removal settings (`[RS eq. 14]`–`[RS eq. 16]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StatisticalStage {
    /// Run it.
    pub enabled: bool,
    /// Neighbours k.
    pub mean_k: usize,
    /// Threshold factor α of `[RS eq. 16]`.
    pub std_mul: f64,
    /// `"above"` (PCL's one-sided rule, the default) or `"both"`
    /// (`[RS eq. 16]` as printed, |d̄_i − d̄| > α·δ).
    pub sides: OutlierSides,
}

/// Voxel grid settings (`[RS eq. 17]`–`[RS eq. 18]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VoxelStage {
    /// Run it.
    pub enabled: bool,
    /// Leaf size r (point spacings).
    pub leaf_spacings: f64,
}

/// Bilateral smoothing settings (`[RS eq. 19]`–`[RS eq. 20]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SmoothStage {
    /// Run it.
    pub enabled: bool,
    /// Neighbourhood radius (point spacings).
    pub radius_spacings: f64,
    /// σ of w_d (point spacings).
    pub sigma_d_spacings: f64,
    /// σ of w_n (m at scale 1).
    pub sigma_n_m: f64,
    /// Passes.
    pub iterations: usize,
}

/// Surface fit settings (`[RS eq. 21]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitStage {
    /// The surface model perceive stands on: "grid" (a height model of
    /// cells, which holds real terrain; the default) or "polynomial" (the
    /// paper's 8 × 8 samples and polynomial, `[RS eq. 21]`, which the
    /// rope-shovel dig planner uses). Both are always made; only the
    /// chosen one can refuse a scan.
    pub model: SurfaceModel,
    /// Refuse a polynomial fit with R² at or under this (0 to accept any);
    /// applies with `model = "polynomial"`.
    pub r2_threshold: f64,
    /// Highest total polynomial degree tried.
    pub max_degree: usize,
    /// The height model's cell edge (point spacings).
    pub cell_spacings: f64,
}

/// The surface model a perception stands on ([`FitStage::model`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum SurfaceModel {
    /// The gridded height model (dem.rs).
    #[default]
    Grid,
    /// The paper's polynomial of [RS eq. 21].
    Polynomial,
}

impl Default for PerceptionParams {
    fn default() -> Self {
        Self {
            scale: ScaleSetting::Word(AutoWord::Auto),
            spacing: ScaleSetting::Word(AutoWord::Auto),
            range: RangeStage::default(),
            level: LevelStage::default(),
            ground: GroundStage::default(),
            radius: RadiusStage::default(),
            statistical: StatisticalStage::default(),
            voxel: VoxelStage::default(),
            smooth: SmoothStage::default(),
            fit: FitStage::default(),
        }
    }
}
impl Default for LevelStage {
    fn default() -> Self {
        Self {
            mode: LevelMode::Auto,
            roll_deg: 0.0,
            pitch_deg: 0.0,
            min_floor_share: TiltParams::default().min_floor_share,
        }
    }
}
impl Default for GroundStage {
    fn default() -> Self {
        Self {
            mode: GroundMode::Auto,
            height_m: None,
            surface: None,
            margin_m: 0.2,
        }
    }
}
// The paper gives no filter settings. These (in point spacings) are checked
// on the four synthetic pile shapes at full size and at 1:30 in
// tests/pipeline.rs: the tilt comes back within 0.2° and R² > 0.95.
impl Default for RadiusStage {
    fn default() -> Self {
        Self {
            enabled: true,
            radius_spacings: 3.0,
            min_neighbors: 3,
        }
    }
}
impl Default for StatisticalStage {
    fn default() -> Self {
        Self {
            enabled: true,
            mean_k: 20,
            std_mul: 2.0,
            sides: OutlierSides::Above,
        }
    }
}
impl Default for VoxelStage {
    fn default() -> Self {
        Self {
            enabled: true,
            leaf_spacings: 2.0,
        }
    }
}
impl Default for SmoothStage {
    fn default() -> Self {
        Self {
            enabled: true,
            radius_spacings: 6.0,
            sigma_d_spacings: 3.0,
            sigma_n_m: 0.02,
            iterations: 1,
        }
    }
}
impl Default for FitStage {
    fn default() -> Self {
        let p = FitParams::default();
        Self {
            model: SurfaceModel::Grid,
            r2_threshold: p.r2_threshold.unwrap_or(0.95),
            max_degree: p.max_degree,
            // Three spacings: about nine raw points, two or three voxel
            // centroids a cell; finer leaves holes, coarser smooths a
            // face's toe and crest away.
            cell_spacings: 3.0,
        }
    }
}

impl TomlFile for PerceptionParams {
    type Error = SurfaceError;

    /// Every number in range, named by its TOML key.
    fn check(&self, text: &str, file: &str) -> Result<()> {
        let surface_mode = self.ground.mode == GroundMode::Surface;
        if surface_mode != self.ground.surface.is_some() {
            let (key, value, expected) = if surface_mode {
                (
                    "mode",
                    "\"surface\"".to_string(),
                    "a surface file too: [ground] surface = \"before.laz\"",
                )
            } else {
                (
                    "surface",
                    format!("{:?}", self.ground.surface.as_deref().unwrap_or_default()),
                    "set only with [ground] mode = \"surface\"",
                )
            };
            return Err(config::invalid(text, file, ("ground", 0), key, value, expected).into());
        }
        if let Some(spec) = &self.range.limits {
            if let Err(problem) = RangeLimits::parse(spec) {
                return Err(config::invalid(
                    text,
                    file,
                    ("range", 0),
                    "limits",
                    format!("{spec:?}"),
                    format!("PDAL's ranges, e.g. \"Classification[2:2]\" ({problem})"),
                )
                .into());
            }
        }
        for (key, s) in [("scale", self.scale), ("spacing", self.spacing)] {
            if let ScaleSetting::Factor(v) = s {
                if !(v.is_finite() && v > 0.0) {
                    return Err(config::invalid(
                        text,
                        file,
                        ("", 0),
                        key,
                        v,
                        "a finite value > 0 or \"auto\"",
                    )
                    .into());
                }
            }
        }
        config::check_each(
            text,
            file,
            &[
                ("radius", "radius_spacings", self.radius.radius_spacings),
                ("voxel", "leaf_spacings", self.voxel.leaf_spacings),
                ("smooth", "radius_spacings", self.smooth.radius_spacings),
                ("smooth", "sigma_d_spacings", self.smooth.sigma_d_spacings),
                ("smooth", "sigma_n_m", self.smooth.sigma_n_m),
                ("statistical", "std_mul", self.statistical.std_mul),
            ],
            config::POSITIVE,
        )?;
        let finite: (fn(f64) -> bool, &str) = (|v: f64| v.is_finite(), "a finite number");
        config::check_each(
            text,
            file,
            &[
                ("level", "roll_deg", self.level.roll_deg),
                ("level", "pitch_deg", self.level.pitch_deg),
                ("ground", "margin_m", self.ground.margin_m),
            ],
            finite,
        )?;
        let checks: [(&str, &str, f64, bool, &str); 4] = [
            (
                "level",
                "min_floor_share",
                self.level.min_floor_share,
                self.level.min_floor_share > 0.0 && self.level.min_floor_share <= 1.0,
                "a share in (0, 1]",
            ),
            (
                "level",
                "roll_deg",
                self.level.roll_deg,
                self.level.roll_deg.abs() < 90.0,
                "an angle within ±90°",
            ),
            (
                "level",
                "pitch_deg",
                self.level.pitch_deg,
                self.level.pitch_deg.abs() < 90.0,
                "an angle within ±90°",
            ),
            (
                "fit",
                "r2_threshold",
                self.fit.r2_threshold,
                (0.0..1.0).contains(&self.fit.r2_threshold),
                "a value in [0, 1) (0 accepts any fit)",
            ),
        ];
        for (table, key, v, ok, expected) in checks {
            if !ok {
                return Err(config::invalid(
                    text,
                    file,
                    (table, 0),
                    key,
                    config::short(v),
                    expected,
                )
                .into());
            }
        }
        let counts = [
            ("radius", "min_neighbors", self.radius.min_neighbors, 1),
            ("statistical", "mean_k", self.statistical.mean_k, 1),
            ("smooth", "iterations", self.smooth.iterations, 1),
            ("fit", "max_degree", self.fit.max_degree, 1),
        ];
        for (table, key, v, min) in counts {
            if v < min {
                return Err(config::invalid(
                    text,
                    file,
                    (table, 0),
                    key,
                    v,
                    format!("at least {min}"),
                )
                .into());
            }
        }
        if self.fit.max_degree > 8 {
            return Err(config::invalid(
                text,
                file,
                ("fit", 0),
                "max_degree",
                self.fit.max_degree,
                "at most 8",
            )
            .into());
        }
        // The work per point at the spacing the settings scale by (the
        // run checks again on the cloud's true spacing).
        for w in self.neighbour_work(1.0, f64::INFINITY) {
            if w.visits > MAX_NEIGHBOUR_VISITS {
                return Err(config::invalid(
                    text,
                    file,
                    (w.table, 0),
                    w.key,
                    config::short(w.value),
                    format!(
                        "at most {} neighbour visits per point; this is about {} ({})",
                        config::approx(MAX_NEIGHBOUR_VISITS),
                        config::approx(w.visits),
                        w.how
                    ),
                )
                .into());
            }
        }
        Ok(())
    }
}

impl PerceptionParams {
    /// What the level and ground stages are asked (ground.rs), with the
    /// scene's `scale`.
    pub(crate) fn level_asked(&self, scale: f64) -> LevelAsked {
        LevelAsked {
            mode: self.level.mode,
            roll_rad: self.level.roll_deg.to_radians(),
            pitch_rad: self.level.pitch_deg.to_radians(),
            ground: self.ground.mode,
            height_m: self.ground.height_m,
            margin: self.ground.margin_m * scale,
        }
    }

    /// Neighbour visits per point of each enabled neighbourhood stage on a
    /// cloud of `n` points whose true spacing is `ratio` times smaller than
    /// the spacing the settings scale by (1 for "auto"); neighbours within
    /// r of a scanned surface ≈ π·(r / spacing)², never more than `n`.
    fn neighbour_work(&self, ratio: f64, n: f64) -> Vec<StageWork> {
        let within = |r_spacings: f64| (std::f64::consts::PI * (r_spacings * ratio).powi(2)).min(n);
        let mut out = Vec::new();
        if self.radius.enabled {
            let k = within(self.radius.radius_spacings);
            out.push(StageWork {
                table: "radius",
                key: "radius_spacings",
                value: self.radius.radius_spacings,
                visits: k,
                how: format!("about {} neighbours within the radius", config::approx(k)),
            });
        }
        if self.statistical.enabled {
            let k = (self.statistical.mean_k as f64).min(n);
            out.push(StageWork {
                table: "statistical",
                key: "mean_k",
                value: self.statistical.mean_k as f64,
                visits: k,
                how: format!("{} nearest neighbours", config::approx(k)),
            });
        }
        if self.smooth.enabled {
            let k = within(self.smooth.radius_spacings);
            let passes = self.smooth.iterations as f64;
            // Blame the passes when one pass is within the ceiling.
            let (key, value) = if k <= MAX_NEIGHBOUR_VISITS {
                ("iterations", passes)
            } else {
                ("radius_spacings", self.smooth.radius_spacings)
            };
            out.push(StageWork {
                table: "smooth",
                key,
                value,
                visits: k * passes,
                how: format!(
                    "about {} neighbours within radius_spacings = {} × {} pass(es)",
                    config::approx(k),
                    config::short(self.smooth.radius_spacings),
                    self.smooth.iterations
                ),
            });
        }
        out
    }

    /// Refuses settings that would cost more than [`MAX_NEIGHBOUR_VISITS`]
    /// per point on a cloud of `n` points whose true spacing is `ratio`
    /// times smaller than the one the settings scale by.
    pub fn check_work(&self, ratio: f64, n: usize) -> Result<()> {
        for w in self.neighbour_work(ratio, n as f64) {
            if w.visits > MAX_NEIGHBOUR_VISITS {
                return Err(SurfaceError::TooMuchWork {
                    key: format!("[{}] {}", w.table, w.key),
                    value: config::short(w.value),
                    estimate: format!(
                        "{} neighbour visits per point ({}), {} for the {n} points",
                        config::approx(w.visits),
                        w.how,
                        config::approx(w.visits * n as f64)
                    ),
                    ceiling: format!("{} per point", config::approx(MAX_NEIGHBOUR_VISITS)),
                });
            }
        }
        Ok(())
    }

    /// Reads and checks a settings file (errors name the file, line and key).
    pub fn load(path: &Path) -> Result<Self> {
        <Self as TomlFile>::load(path)
    }

    /// The settings as TOML (`autoshovel perceive --print-config`).
    pub fn to_toml(&self) -> String {
        <Self as TomlFile>::to_toml(self)
    }
}

/// The pipeline's stages after the read, in order (a disabled filter is
/// skipped, so a run may record fewer).
pub const STAGES: [&str; 7] = [
    "level",
    "ground",
    "radius",
    "statistical",
    "voxel",
    "smooth",
    "fit",
];

/// One stage's record: its name, the points after it and its wall time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageRecord {
    /// Stage name: read, level, ground, radius, statistical, voxel, smooth, fit.
    pub stage: &'static str,
    /// Points after it (grid samples for the fit).
    pub points: usize,
    /// Wall-clock time (ms).
    pub ms: f64,
}

/// What the pipeline made of a scan: the cleaned cloud and the fitted
/// surface in the levelled frame, with every stage's count and time.
#[derive(Debug, Clone)]
pub struct Perceived {
    /// The cleaned, levelled cloud.
    pub cloud: PointCloud,
    /// The fitted surface z = f(x, y) (`[RS eq. 21]`), levelled frame.
    pub fit: SurfaceFit,
    /// Floor height in the levelled frame (m).
    pub floor_height_m: f64,
    /// The floor found in the levelled scan (the plane the pass-through cut
    /// stands on): its points, those below it, its RMS.
    pub floor: TiltEstimate,
    /// Roll α used to level (rad).
    pub roll_rad: f64,
    /// Pitch β used to level (rad).
    pub pitch_rad: f64,
    /// Length scale of the scene.
    pub scale: f64,
    /// Mean point spacing (m).
    pub spacing_m: f64,
    /// Every stage run, in order.
    pub stages: Vec<StageRecord>,
    /// Finite points given (read).
    pub input_points: usize,
    /// The file format read (`None` for a cloud given in memory).
    pub format: Option<&'static str>,
    /// Non-finite points dropped while reading.
    pub non_finite_dropped: usize,
    /// The height model and the volume above the base.
    pub model: Model,
    /// What the level and ground stages did.
    pub used: GroundUsed,
    /// What the result does not hold well, with what to do: a height
    /// model whose residual passes [`LAYERED_RESIDUAL_PER_CELL`] cell
    /// edges (points on several surfaces), with the setting that keeps a
    /// classified file's ground.
    pub warnings: Vec<String>,
}

/// The gridded height model of a perceived scan and the volume it holds.
#[derive(Debug, Clone)]
pub struct Model {
    /// The grid (levelled frame).
    pub grid: HeightGrid,
    /// Its cells, holes and residuals on the cleaned points.
    pub summary: GridSummary,
    /// The base the volume stands on: the floor or the given height, or,
    /// with no ground, the lowest cleaned point (levelled frame).
    pub base: f64,
    /// Volume between the model and the base.
    pub volume_m3: f64,
    /// With `[ground] mode = "surface"`: fill, cut and net from the base
    /// scan to this one, over the cells both saw.
    pub change: Option<Change>,
}

impl Model {
    fn of(
        cloud: &PointCloud,
        cell: f64,
        used: &GroundUsed,
        floor: &TiltEstimate,
        before: Option<&PointCloud>,
    ) -> Result<Self> {
        let grid = HeightGrid::of(cloud, cell)?;
        let summary = grid.summary(cloud);
        if let Some(before) = before {
            let change = grid.change_from(&HeightGrid::like(before, &grid)?);
            return Ok(Self {
                volume_m3: change.fill_m3,
                change: Some(change),
                grid,
                summary,
                // No one height: the base is a surface.
                base: f64::NAN,
            });
        }
        let base = match used.ground_mode {
            "none" => cloud.bounds().map_or(0.0, |(lo, _)| f64::from(lo[2])),
            _ => floor.floor_height_m,
        };
        Ok(Self {
            volume_m3: grid.volume_above(base),
            grid,
            summary,
            base,
            change: None,
        })
    }
}

impl Perceived {
    /// Wall time of every stage (ms).
    pub fn total_ms(&self) -> f64 {
        self.stages.iter().map(|s| s.ms).sum()
    }
}

fn elapsed_ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Reads `path` (any format of `autoshovel_point_cloud::io::read`, with
/// `progress(done, total)` in bytes while reading) and runs [`perceive`]
/// on it; the read is the first stage.
pub fn perceive_file(
    path: &Path,
    params: &PerceptionParams,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Perceived> {
    perceive_file_with(path, params, progress, &mut |_| {})
}

/// [`perceive_file`], calling `on_stage(name)` as each stage after the
/// read starts (`"level"`, `"ground"`, `"radius"`, …, `"fit"`).
pub fn perceive_file_with(
    path: &Path,
    params: &PerceptionParams,
    progress: &mut dyn FnMut(u64, u64),
    on_stage: &mut dyn FnMut(&'static str),
) -> Result<Perceived> {
    let t = Instant::now();
    let report = autoshovel_point_cloud::io::read(path, progress)?;
    let read = StageRecord {
        stage: "read",
        points: report.cloud.len(),
        ms: elapsed_ms(t),
    };
    if report.cloud.is_empty() {
        return Err(SurfaceError::NoFinitePoints {
            non_finite_dropped: report.non_finite_dropped,
        });
    }
    let mut got = perceive_with(&report.cloud, params, on_stage)?;
    got.stages.insert(0, read);
    got.format = Some(report.format);
    got.non_finite_dropped = report.non_finite_dropped;
    Ok(got)
}

/// The scale and point spacing of `cloud` as `params` asks (numbers, or
/// "auto" from the horizontal extent).
pub fn scale_and_spacing(cloud: &PointCloud, params: &PerceptionParams) -> Result<(f64, f64)> {
    let (lo, hi) = cloud.bounds().ok_or(SurfaceError::NoFinitePoints {
        non_finite_dropped: 0,
    })?;
    scale_and_spacing_of(lo, hi, cloud.len() as u64, params)
}

/// [`scale_and_spacing`] of a cloud of `n` points with bounds `lo`, `hi`
/// (a survey read in pieces).
pub fn scale_and_spacing_of(
    lo: [f32; 3],
    hi: [f32; 3],
    n: u64,
    params: &PerceptionParams,
) -> Result<(f64, f64)> {
    let scale = match params.scale {
        ScaleSetting::Factor(s) if s.is_finite() && s > 0.0 => s,
        ScaleSetting::Factor(s) => {
            return Err(SurfaceError::BadParameter {
                name: "scale",
                value: s,
                expected: "a finite value > 0 or \"auto\"",
            })
        }
        ScaleSetting::Word(AutoWord::Auto) => {
            let extent = f64::from((hi[0] - lo[0]).max(hi[1] - lo[1]));
            (extent / 30.0).clamp(0.01, 10.0)
        }
    };
    let spacing = match params.spacing {
        ScaleSetting::Factor(s) if s.is_finite() && s > 0.0 => s,
        ScaleSetting::Factor(s) => {
            return Err(SurfaceError::BadParameter {
                name: "spacing",
                value: s,
                expected: "a finite value > 0 or \"auto\"",
            })
        }
        ScaleSetting::Word(AutoWord::Auto) => {
            let area = f64::from(hi[0] - lo[0]) * f64::from(hi[1] - lo[1]);
            let s = (area / n as f64).sqrt();
            if !(s.is_finite() && s > 0.0) {
                return Err(SurfaceError::NoHorizontalExtent);
            }
            s
        }
    };
    Ok((scale, spacing))
}

/// The paper's pipeline on `cloud` (module docs): level, remove the floor,
/// radius and statistical outliers, voxel grid, bilateral smoothing, fit.
/// A stage's failure names the stage.
pub fn perceive(cloud: &PointCloud, params: &PerceptionParams) -> Result<Perceived> {
    perceive_with(cloud, params, &mut |_| {})
}

/// [`perceive`], calling `on_stage(name)` as each stage starts (`"level"`,
/// then the enabled filters by name, then `"fit"`): for progress display.
pub fn perceive_with(
    cloud: &PointCloud,
    params: &PerceptionParams,
    on_stage: &mut dyn FnMut(&'static str),
) -> Result<Perceived> {
    perceive_after(cloud, params, None, on_stage)
}

/// What one scan's perception leaves for the next scan from the same
/// sensor pose ([`Prior::of`]): the attitude and floor it found, and the
/// scale and spacing it used. With a prior, [`perceive_after`] levels with
/// these angles and cuts at this floor without searching for the floor
/// again (the two RANSAC fits of the level stage), and keeps the scale and
/// spacing, so that every frame of a sequence is filtered alike.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prior {
    /// Roll α of [RS eq. 11] (rad).
    pub roll_rad: f64,
    /// Pitch β of [RS eq. 11] (rad).
    pub pitch_rad: f64,
    /// The floor found in the levelled scan.
    pub floor: TiltEstimate,
    /// Length scale.
    pub scale: f64,
    /// Point spacing (m).
    pub spacing_m: f64,
}

impl Prior {
    /// The prior a perceived scan leaves.
    pub fn of(got: &Perceived) -> Self {
        Self {
            roll_rad: got.roll_rad,
            pitch_rad: got.pitch_rad,
            floor: got.floor,
            scale: got.scale,
            spacing_m: got.spacing_m,
        }
    }
}

/// [`perceive_with`] after an earlier scan from the same pose: with
/// `prior`, the level stage applies its roll and pitch and its floor (no
/// floor search), and its scale and spacing are used; without, as
/// [`perceive_with`].
pub fn perceive_after(
    cloud: &PointCloud,
    params: &PerceptionParams,
    prior: Option<&Prior>,
    on_stage: &mut dyn FnMut(&'static str),
) -> Result<Perceived> {
    let p = params;
    let input_points = cloud.len();
    if cloud.georef.crs.is_geographic() {
        return Err(SurfaceError::Geographic {
            crs: cloud.georef.crs.to_string(),
        });
    }
    let given = cloud;
    let ranged = select_range(cloud, p)?;
    let cloud = ranged.as_ref().map_or(cloud, |(c, _)| c);
    // Perception measures in metres: a cloud in feet (a State Plane
    // survey) is converted first, and what perception returns is metres.
    let converted;
    let cloud = match in_metres(cloud) {
        Some(c) => {
            converted = c;
            &converted
        }
        None => cloud,
    };
    if input_points == 0 {
        return Err(SurfaceError::NoFinitePoints {
            non_finite_dropped: 0,
        });
    }
    let (scale, spacing) = match prior {
        Some(prior) => (prior.scale, prior.spacing_m),
        None => scale_and_spacing(cloud, p)?,
    };
    check_work_on(cloud, p, spacing)?;
    p.check_work(1.0, input_points)?;
    let mut stages: Vec<StageRecord> = Vec::new();
    if let Some((c, ms)) = &ranged {
        stages.push(StageRecord {
            stage: "range",
            points: c.len(),
            ms: *ms,
        });
    }
    let in_stage = |stage: &'static str| {
        move |source: SurfaceError| SurfaceError::Stage {
            stage,
            source: Box::new(source),
        }
    };
    // Level [RS eq. 11]–[RS eq. 12], and the ground (ground.rs).
    on_stage("level");
    let t = Instant::now();
    let levelled = level_stage(cloud, p, prior, scale)?;
    let Levelled {
        cloud,
        roll,
        pitch,
        floor,
        used,
    } = levelled;
    stages.push(StageRecord {
        stage: "level",
        points: cloud.len(),
        ms: elapsed_ms(t),
    });
    let cloud = run_filters(cloud, p, &used, (scale, spacing), &mut stages, on_stage)?;
    // Fit [RS eq. 21].
    on_stage("fit");
    let t = Instant::now();
    let gate = p.fit.model == SurfaceModel::Polynomial && p.fit.r2_threshold > 0.0;
    let fit_params = FitParams {
        max_degree: p.fit.max_degree,
        r2_threshold: gate.then_some(p.fit.r2_threshold),
        ..FitParams::default()
    };
    let fit = fit_surface(&cloud, &fit_params).map_err(in_stage("fitting the surface"))?;
    let before =
        base_scan(p, given, &cloud, roll, pitch).map_err(in_stage("reading [ground] surface"))?;
    let model = Model::of(
        &cloud,
        p.fit.cell_spacings * spacing,
        &used,
        &floor,
        before.as_ref(),
    )
    .map_err(in_stage("making the height model"))?;
    stages.push(StageRecord {
        stage: "fit",
        points: fit.samples.len(),
        ms: elapsed_ms(t),
    });
    let warnings = surface_warnings(given, &model.summary, p);
    Ok(Perceived {
        cloud,
        fit,
        floor_height_m: model.base,
        model,
        used,
        floor,
        roll_rad: roll,
        pitch_rad: pitch,
        scale,
        spacing_m: spacing,
        stages,
        input_points,
        format: None,
        non_finite_dropped: 0,
        warnings,
    })
}

/// Refuses, before any work, filter settings whose neighbour searches
/// pass the ceiling on `cloud`: with a spacing given as a number, the
/// cloud's own may be much finer, and then the spacing is what is named.
fn check_work_on(cloud: &PointCloud, p: &PerceptionParams, spacing: f64) -> Result<()> {
    let input_points = cloud.len();
    // The work the filters imply on this cloud, before doing it: with a
    // spacing given as a number, the cloud's own may be much finer.
    if let (Some((lo, hi)), ScaleSetting::Factor(_)) = (cloud.bounds(), p.spacing) {
        let area = f64::from(hi[0] - lo[0]) * f64::from(hi[1] - lo[1]);
        let own = (area / input_points as f64).sqrt();
        if own.is_finite() && own > 0.0 {
            match p.check_work(spacing / own, input_points) {
                // Within the ceiling at the spacing given, beyond it on
                // this cloud: the spacing is what is wrong.
                Err(SurfaceError::TooMuchWork {
                    key,
                    value,
                    estimate,
                    ceiling,
                }) if p.check_work(1.0, input_points).is_ok() => {
                    return Err(SurfaceError::TooMuchWork {
                        key: "spacing".into(),
                        value: config::short(spacing),
                        estimate: format!(
                            "it is {}× this cloud's own spacing ({} m), so {key} = {value} costs {estimate}",
                            config::approx(spacing / own),
                            config::approx(own)
                        ),
                        ceiling,
                    })
                }
                other => other?,
            }
        }
    }
    Ok(())
}

/// Level [RS eq. 11]–[RS eq. 12] and take the ground (ground.rs); with a
/// prior, its angles and floor, no search.
fn level_stage(
    cloud: &PointCloud,
    p: &PerceptionParams,
    prior: Option<&Prior>,
    scale: f64,
) -> Result<Levelled> {
    let mut tilt_params = TiltParams::for_scale(scale);
    tilt_params.min_floor_share = p.level.min_floor_share;
    Ok(match prior {
        // A prior's angles and floor, no search.
        Some(prior) => {
            let c = PointCloud {
                points: level(cloud, prior.roll_rad, prior.pitch_rad).points,
                origin: cloud.origin,
                attributes: cloud.attributes.clone(),
                georef: cloud.georef.clone(),
            };
            Levelled {
                cloud: c,
                roll: prior.roll_rad,
                pitch: prior.pitch_rad,
                floor: prior.floor,
                used: GroundUsed {
                    level_mode: "given",
                    ground_mode: "floor",
                    note: None,
                    cut_at: Some(prior.floor.floor_height_m + p.ground.margin_m * scale),
                },
            }
        }
        None => level_and_ground(cloud, &p.level_asked(scale), &tilt_params)?,
    })
}

/// The filter stages after levelling, in the paper's order, each timed,
/// counted in `stages` and announced to `on_stage`. The radius stage
/// hands its neighbour index to the statistical one.
fn run_filters(
    cloud: PointCloud,
    p: &PerceptionParams,
    used: &GroundUsed,
    (scale, spacing): (f64, f64),
    stages: &mut Vec<StageRecord>,
    on_stage: &mut dyn FnMut(&'static str),
) -> Result<PointCloud> {
    // The filter stages, in the paper's order; each timed and counted. The
    // radius stage hands its neighbour index to the statistical one.
    type Filter<'a> = Box<dyn Fn(&PointCloud) -> autoshovel_point_cloud::Result<PointCloud> + 'a>;
    let after_radius = std::cell::RefCell::new(None::<RadiusKept>);
    let filters: [(&'static str, bool, Filter); 5] = [
        (
            "ground",
            used.cut_at.is_some(),
            Box::new(|c: &PointCloud| {
                let at = used.cut_at.unwrap_or(f64::NEG_INFINITY);
                let kept = pass_through_indices(c, &PassThroughParams::ground_removal(at))?;
                Ok(c.select(&kept))
            }),
        ),
        (
            "radius",
            p.radius.enabled,
            // [RS eq. 13]
            Box::new(|c: &PointCloud| {
                let params = RadiusOutlierParams {
                    radius_m: p.radius.radius_spacings * spacing,
                    min_neighbors: p.radius.min_neighbors,
                };
                if !p.statistical.enabled {
                    return Ok(c.select(&radius_outlier_removal_indices(c, &params)?));
                }
                // The statistical stage searches the same index next.
                let first = radius_outlier_removal_then(c, &params, p.statistical.mean_k)?;
                let kept = c.select(&first.kept);
                *after_radius.borrow_mut() = Some(first);
                Ok(kept)
            }),
        ),
        (
            "statistical",
            p.statistical.enabled,
            // [RS eq. 14]–[RS eq. 16]
            Box::new(|c: &PointCloud| {
                let params = StatisticalOutlierParams {
                    mean_k: p.statistical.mean_k,
                    std_mul: p.statistical.std_mul,
                    sides: p.statistical.sides,
                };
                let kept = match after_radius.borrow_mut().take() {
                    Some(first) => first.statistical_indices(c, &params)?,
                    None => statistical_outlier_removal_indices(c, &params)?,
                };
                Ok(c.select(&kept))
            }),
        ),
        (
            "voxel",
            p.voxel.enabled,
            // [RS eq. 17]–[RS eq. 18]
            // New points: the cloud's frame kept, its attributes not
            // (`filter --voxel` carries them, at the cost of a sort).
            Box::new(|c: &PointCloud| {
                let v = voxel_grid(c, &VoxelGridParams::cube(p.voxel.leaf_spacings * spacing))?;
                Ok(c.derived(v.points, None))
            }),
        ),
        (
            "smooth",
            p.smooth.enabled,
            // [RS eq. 19]–[RS eq. 20]
            Box::new(|c: &PointCloud| {
                let params = BilateralParams {
                    radius_m: p.smooth.radius_spacings * spacing,
                    sigma_d_m: p.smooth.sigma_d_spacings * spacing,
                    sigma_n_m: p.smooth.sigma_n_m * scale,
                    iterations: p.smooth.iterations,
                };
                Ok(c.derived(bilateral_normal_smoothing(c, &params)?.points, None))
            }),
        ),
    ];
    let mut cloud = cloud;
    for (stage, enabled, run) in filters {
        if enabled {
            on_stage(stage);
            let t = Instant::now();
            cloud = run(&cloud).map_err(|source| SurfaceError::Filter {
                stage,
                source: in_settings_terms(stage, source, p, spacing, scale),
            })?;
            stages.push(StageRecord {
                stage,
                points: cloud.len(),
                ms: elapsed_ms(t),
            });
        }
    }
    Ok(cloud)
}

/// The height model's RMS residual, over its cell's edge, past which the
/// cleaned points lie on more than one surface at once (trees over the
/// ground, walls, overhangs): on one surface of any slope up to 45° the
/// points of a cell stray from a bilinear model by well under the cell's
/// edge.
pub const LAYERED_RESIDUAL_PER_CELL: f64 = 1.0;

/// The ASPRS class of ground points in a LAS file (LAS 1.4 R15, table 17).
const ASPRS_GROUND: f64 = 2.0;

/// What the result does not hold well, each with what to do: a height
/// model whose residual says the points lie on several surfaces, with,
/// where the file classifies ground and no `[range]` was given, the
/// setting that perceives the ground alone.
fn surface_warnings(given: &PointCloud, model: &GridSummary, p: &PerceptionParams) -> Vec<String> {
    let mut out = Vec::new();
    let per_cell = model.rms_residual_m / model.cell_m;
    if per_cell.is_nan() || per_cell <= LAYERED_RESIDUAL_PER_CELL {
        return out;
    }
    let ground = match (&p.range.limits, given.attributes.get("Classification")) {
        (None, Some(class)) => (0..class.len())
            .filter(|&i| class.f64_at(i) == ASPRS_GROUND)
            .count(),
        _ => 0,
    };
    let advice = if ground > 0 {
        format!(
            "the file classifies {ground} of its {} points as ground (class 2): \
             [range] limits = \"Classification[2:2]\" perceives them alone",
            given.len()
        )
    } else {
        "keep one surface with [range] limits (e.g. a classification, or Z below the canopy), \
         or classify the ground first (e.g. PDAL's filters.smrf)"
            .to_string()
    };
    out.push(format!(
        "the height model's RMS residual is {} m on cells of {} m: the points lie on more than \
         one surface (trees or buildings over the ground, walls, overhangs); {advice}",
        config::approx(model.rms_residual_m),
        config::approx(model.cell_m)
    ));
    out
}

/// The base scan of `[ground] mode = "surface"` in `cloud`'s frame: read,
/// put through the same `[range]`, in metres, about `cloud`'s origin and
/// levelled by the same roll and pitch; `None` in any other mode. Its CRS
/// must be `given`'s (the input's).
fn base_scan(
    p: &PerceptionParams,
    given: &PointCloud,
    cloud: &PointCloud,
    roll: f64,
    pitch: f64,
) -> Result<Option<PointCloud>> {
    let Some(path) = p
        .ground
        .surface
        .as_deref()
        .filter(|_| p.ground.mode == GroundMode::Surface)
    else {
        return Ok(None);
    };
    let read = autoshovel_point_cloud::io::read(Path::new(path), &mut |_, _| {})?.cloud;
    let (theirs, ours) = (&read.georef.crs, &given.georef.crs);
    if (theirs.epsg, theirs.unit, theirs.z_unit()) != (ours.epsg, ours.unit, ours.z_unit()) {
        return Err(SurfaceError::Survey {
            path: path.into(),
            problem: format!(
                "its CRS ({theirs}) is not the input's ({ours}): a base scan must be in the same frame"
            ),
        });
    }
    let ranged = select_range(&read, p)?;
    let read = ranged.map_or(read, |(c, _)| c);
    let read = in_metres(&read).unwrap_or(read);
    // About the perceived cloud's origin, in f64 until the difference.
    let points = (0..read.len())
        .map(|i| {
            let w = read.world(i);
            [0, 1, 2].map(|a| (w[a] - cloud.origin[a]) as f32)
        })
        .collect();
    let about = PointCloud {
        points,
        origin: cloud.origin,
        ..PointCloud::default()
    };
    Ok(Some(if roll != 0.0 || pitch != 0.0 {
        level(&about, roll, pitch)
    } else {
        about
    }))
}

/// The rows of `cloud` that `[range] limits` keeps, and the stage's time
/// (ms); `None` without limits.
fn select_range(cloud: &PointCloud, p: &PerceptionParams) -> Result<Option<(PointCloud, f64)>> {
    let Some(spec) = &p.range.limits else {
        return Ok(None);
    };
    let t = Instant::now();
    let filter = |source| SurfaceError::Filter {
        stage: "range",
        source,
    };
    let limits = RangeLimits::parse(spec).map_err(|problem| {
        filter(CloudError::BadParameter {
            filter: "range",
            what: format!("[range] limits = {spec:?}: {problem}"),
        })
    })?;
    let rows = range_indices(cloud, &limits).map_err(|e| {
        filter(match e {
            CloudError::BadParameter { filter, what } => CloudError::BadParameter {
                filter,
                what: format!("[range] limits = {spec:?}: {what}"),
            },
            CloudError::Emptied { filter, input, .. } => CloudError::Emptied {
                filter,
                input,
                hint: format!("no point passes [range] limits = {spec:?}: check them against the file's values"),
            },
            other => other,
        })
    })?;
    Ok(Some((cloud.select(&rows), elapsed_ms(t))))
}

/// `cloud` in metres when its CRS's unit is another length (feet, US
/// survey feet): points and origin scaled, the CRS then stated as metres
/// with no code (the file's CRS is in feet); `None` when it is metres or
/// not stated.
fn in_metres(cloud: &PointCloud) -> Option<PointCloud> {
    let crs = &cloud.georef.crs;
    let xy = crs.unit.metres()?;
    // z in its own unit where a compound CRS states one.
    let f = [xy, xy, crs.z_unit().metres().unwrap_or(xy)];
    if f == [1.0; 3] {
        return None;
    }
    let mut c = cloud.clone();
    let ff = f.map(|v| v as f32);
    c.points
        .iter_mut()
        .for_each(|p| *p = [p[0] * ff[0], p[1] * ff[1], p[2] * ff[2]]);
    c.origin = [0, 1, 2].map(|a| c.origin[a] * f[a]);
    c.georef = autoshovel_point_cloud::Georef {
        crs: autoshovel_point_cloud::Crs {
            unit: autoshovel_point_cloud::Unit::Metre,
            ..Default::default()
        },
        las: None,
        viewpoint: None,
    };
    Some(c)
}

/// A filter's error restated in the perceive settings' terms: the hint of
/// an emptied cloud names the TOML keys to change, and a bad value says
/// which setting it came from (the filters speak of `radius_m`, `leaf_m`;
/// the settings of spacings).
pub(crate) fn in_settings_terms(
    stage: &str,
    e: autoshovel_point_cloud::CloudError,
    p: &PerceptionParams,
    spacing: f64,
    scale: f64,
) -> autoshovel_point_cloud::CloudError {
    use autoshovel_point_cloud::CloudError;
    let sp = config::approx(spacing);
    match e {
        CloudError::Emptied { filter, input, .. } => CloudError::Emptied {
            filter,
            input,
            hint: match stage {
                "ground" => "every point is below the floor cut (the floor found by levelling plus [ground] margin_m × scale): lower [ground] margin_m, or check [level]".into(),
                "radius" => "lower [radius] min_neighbors or raise [radius] radius_spacings (or set [radius] enabled = false)".into(),
                "statistical" => "raise [statistical] std_mul (or set [statistical] enabled = false)".into(),
                other => format!("check the [{other}] settings"),
            },
        },
        CloudError::BadParameter { filter, what } => CloudError::BadParameter {
            filter,
            what: format!(
                "{what} [from {}]",
                match stage {
                    "radius" => format!(
                        "[radius] radius_spacings = {} × the spacing {sp} m",
                        config::short(p.radius.radius_spacings)
                    ),
                    "voxel" => format!(
                        "[voxel] leaf_spacings = {} × the spacing {sp} m",
                        config::short(p.voxel.leaf_spacings)
                    ),
                    "smooth" => format!(
                        "[smooth] radius_spacings = {}, sigma_d_spacings = {} × the spacing {sp} m, sigma_n_m = {} × the scale {}",
                        config::short(p.smooth.radius_spacings),
                        config::short(p.smooth.sigma_d_spacings),
                        config::short(p.smooth.sigma_n_m),
                        config::approx(scale)
                    ),
                    "statistical" => format!(
                        "[statistical] mean_k = {}, std_mul = {}",
                        p.statistical.mean_k,
                        config::short(p.statistical.std_mul)
                    ),
                    _ => format!("[ground] margin_m = {} × the scale {}", config::short(p.ground.margin_m), config::approx(scale)),
                }
            ),
        },
        other => other,
    }
}

/// The fit part of a perception summary.
#[derive(Debug, Clone, Serialize)]
pub struct FitSummary {
    /// Total degree chosen.
    pub degree: usize,
    /// R² on the grid samples.
    pub r2: f64,
    /// Adjusted R².
    pub adjusted_r2: f64,
    /// RMS residual on the samples (m).
    pub rms_residual_m: f64,
    /// R² on every cleaned point.
    pub r2_all_points: f64,
    /// RMS residual on every cleaned point (m).
    pub rms_all_points_m: f64,
    /// Grid samples used.
    pub samples: usize,
    /// The polynomial's terms.
    pub coefficients: Vec<Term>,
}

impl FitSummary {
    /// The summary of `fit`.
    pub fn of(fit: &SurfaceFit) -> Self {
        Self {
            degree: fit.degree,
            r2: fit.r2,
            adjusted_r2: fit.adjusted_r2,
            rms_residual_m: fit.rms_residual_m,
            r2_all_points: fit.r2_all_points,
            rms_all_points_m: fit.rms_all_points_m,
            samples: fit.samples.len(),
            coefficients: fit.coefficients_xy(),
        }
    }
}

/// The summary of `autoshovel perceive` (SPEC §6).
#[derive(Debug, Clone, Serialize)]
pub struct PerceiveSummary {
    /// "perceive".
    pub job: &'static str,
    /// The scan file.
    pub input: String,
    /// The format read.
    pub format: Option<&'static str>,
    /// Finite points read.
    pub input_points: usize,
    /// Non-finite points dropped while reading.
    pub non_finite_dropped: usize,
    /// Points of the cleaned cloud.
    pub output_points: usize,
    /// Points after each stage, by stage name.
    pub stage_points: BTreeMap<&'static str, usize>,
    /// Every stage, in order.
    pub stages: Vec<StageRecord>,
    /// Roll α used to level (deg).
    pub roll_deg: f64,
    /// Pitch β used to level (deg).
    pub pitch_deg: f64,
    /// Floor height, levelled frame (m).
    pub floor_height_m: f64,
    /// Points on the floor plane (within its inlier band).
    pub floor_points: usize,
    /// Their share of the points read.
    pub floor_share: f64,
    /// Points more than the below margin under the floor (multipath, ruts).
    pub points_below_floor: usize,
    /// RMS distance of the floor points from the plane (m).
    pub floor_rms_m: f64,
    /// Length scale used.
    pub scale: f64,
    /// Point spacing used (m).
    pub spacing_m: f64,
    /// R² of the fit on the grid samples.
    pub r2: f64,
    /// The levelling that ran: estimate, given or none.
    pub level_mode: &'static str,
    /// The ground that ran: floor, height or none.
    pub ground_mode: &'static str,
    /// Why, where `auto` chose.
    pub ground_note: Option<String>,
    /// What the result does not hold well, each with what to do (also
    /// printed on stderr).
    pub warnings: Vec<String>,
    /// The gridded height model: cells, holes, residuals on the cleaned
    /// points.
    pub height_model: GridSummary,
    /// Volume between the height model and the base.
    pub volume_m3: f64,
    /// The base's height in the file's frame (with `origin`).
    pub volume_base_m: f64,
    /// The f64 origin the points were held about.
    pub origin: [f64; 3],
    /// With `[ground] mode = "surface"`: fill, cut and net volume from
    /// the base scan to this one over the cells both saw (`volume_m3` is
    /// the fill; `volume_base_m` is then null, the base being a surface).
    pub change: Option<Change>,
    /// Wall time of each stage (ms).
    pub timings_ms: BTreeMap<&'static str, f64>,
    /// Wall time of all stages (ms).
    pub total_ms: f64,
    /// The fit.
    pub fit: FitSummary,
    /// The settings used.
    pub pipeline: PerceptionParams,
    /// Always true (a failed run is an error).
    pub success: bool,
}

impl PerceiveSummary {
    /// The summary of `got`, read from `input` with `params`.
    pub fn new(input: &Path, params: &PerceptionParams, got: &Perceived) -> Self {
        let fit = &got.fit;
        Self {
            job: "perceive",
            input: input.display().to_string(),
            format: got.format,
            input_points: got.input_points,
            non_finite_dropped: got.non_finite_dropped,
            output_points: got.cloud.len(),
            stage_points: got.stages.iter().map(|s| (s.stage, s.points)).collect(),
            stages: got.stages.clone(),
            roll_deg: got.roll_rad.to_degrees(),
            pitch_deg: got.pitch_rad.to_degrees(),
            floor_height_m: got.floor_height_m,
            floor_points: got.floor.inliers,
            floor_share: got.floor.inliers as f64 / got.floor.candidates.max(1) as f64,
            points_below_floor: got.floor.below,
            floor_rms_m: got.floor.rms_m,
            scale: got.scale,
            spacing_m: got.spacing_m,
            r2: fit.r2,
            level_mode: got.used.level_mode,
            ground_mode: got.used.ground_mode,
            ground_note: got.used.note.clone(),
            warnings: got.warnings.clone(),
            height_model: got.model.summary.clone(),
            volume_m3: got.model.volume_m3,
            volume_base_m: got.model.base + got.cloud.origin[2],
            change: got.model.change,
            origin: got.cloud.origin,
            timings_ms: got.stages.iter().map(|s| (s.stage, s.ms)).collect(),
            total_ms: got.total_ms(),
            fit: FitSummary::of(fit),
            pipeline: params.clone(),
            success: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{generate_pile, PileParams};

    #[test]
    fn the_defaults_print_and_load_back_equal() {
        let d = PerceptionParams::default();
        let back: PerceptionParams = TomlFile::from_toml(&d.to_toml(), "printed").unwrap();
        assert_eq!(back, d);
    }

    #[test]
    fn bad_values_name_their_key_and_line() {
        for (text, key, line) in [
            ("scale = -2\n", "scale", 1),
            (
                "\n[level]\nmin_floor_share = 1.5\n",
                "[level] min_floor_share",
                3,
            ),
            ("[fit]\nr2_threshold = nan\n", "[fit] r2_threshold", 2),
            ("[statistical]\nstd_mul = -2\n", "[statistical] std_mul", 2),
            ("[smooth]\niterations = 0\n", "[smooth] iterations", 2),
            ("[level]\nroll_deg = 1e308\n", "[level] roll_deg", 2),
        ] {
            let err = <PerceptionParams as TomlFile>::from_toml(text, "p.toml").unwrap_err();
            let msg = err.to_string();
            assert!(
                msg.starts_with(&format!("p.toml:{line}: {key} = ")),
                "{text:?}: {msg}"
            );
        }
    }

    #[test]
    fn settings_that_size_too_much_work_are_refused_with_the_estimate() {
        // π·6² ≈ 113 neighbours per pass: 10⁶ passes is 1.13e8 visits.
        for (text, key, line, estimate) in [
            (
                "[smooth]\niterations = 1000000\n",
                "[smooth] iterations",
                2,
                "1.13e8",
            ),
            (
                "[statistical]\nmean_k = 100000\n",
                "[statistical] mean_k",
                2,
                "1.00e5",
            ),
            (
                "\n[radius]\nradius_spacings = 1000\n",
                "[radius] radius_spacings",
                3,
                "3.14e6",
            ),
        ] {
            let msg = <PerceptionParams as TomlFile>::from_toml(text, "p.toml")
                .unwrap_err()
                .to_string();
            assert!(
                msg.starts_with(&format!("p.toml:{line}: {key} = ")) && msg.contains(estimate),
                "{text:?}: {msg}"
            );
        }
        // 88 passes at the default radius are within the ceiling, 89 not.
        let ok = |passes: usize| {
            let mut p = PerceptionParams::default();
            p.smooth.iterations = passes;
            p.check_work(1.0, 1000).is_ok()
        };
        assert!(ok(88) && !ok(89));
        // A spacing given as a number 20 times the cloud's own: the radius
        // stage meets 400 times the neighbours, and the spacing is named.
        let cloud = PointCloud::new(
            (0..20_000)
                .map(|i| [(i % 200) as f32 * 0.1, (i / 200) as f32 * 0.1, 0.0])
                .collect(),
        );
        let p: PerceptionParams = TomlFile::from_toml("spacing = 2.0\n", "p").unwrap();
        let msg = perceive(&cloud, &p).unwrap_err().to_string();
        assert!(
            msg.starts_with("spacing = 2 asks too much")
                && msg.contains("[radius] radius_spacings"),
            "{msg}"
        );
    }

    /// An error and its sources, as an error chain prints them.
    fn chain(e: &dyn std::error::Error) -> String {
        let mut out = e.to_string();
        let mut next = e.source();
        while let Some(c) = next {
            out += &format!(": {c}");
            next = c.source();
        }
        out
    }

    #[test]
    fn filter_errors_name_the_settings_keys() {
        let cloud = PointCloud::new(
            (0..2_000)
                .map(|i| [(i % 50) as f32 * 0.1, (i / 50) as f32 * 0.1, 0.0])
                .collect(),
        );
        let mut p = PerceptionParams::default();
        p.level.mode = LevelMode::None;
        p.ground.margin_m = -1.0;
        p.radius.min_neighbors = 100_000;
        let msg = chain(&perceive(&cloud, &p).unwrap_err());
        assert!(
            msg.contains("[radius] min_neighbors") && msg.contains("[radius] radius_spacings"),
            "{msg}"
        );
        assert!(!msg.contains("radius_m"), "{msg}");
        p.radius.min_neighbors = 1;
        p.voxel.leaf_spacings = 1e-30;
        let msg = chain(&perceive(&cloud, &p).unwrap_err());
        assert!(msg.contains("[from [voxel] leaf_spacings = 1e-30"), "{msg}");
    }

    #[test]
    fn a_wrong_word_for_a_length_is_named_in_the_users_terms() {
        let err = <PerceptionParams as TomlFile>::from_toml("spacing = \"fine\"\n", "p.toml")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("p.toml:1:"), "{err}");
        assert!(err.contains("\"fine\" is not a length"), "{err}");
        assert!(
            !err.contains("untagged") && !err.contains("ScaleSetting"),
            "{err}"
        );
        let p: PerceptionParams = TomlFile::from_toml("scale = 2\nspacing = 0.05\n", "p").unwrap();
        assert_eq!(p.scale, ScaleSetting::Factor(2.0));
        assert_eq!(p.spacing, ScaleSetting::Factor(0.05));
    }

    #[test]
    fn every_stage_is_counted_in_order_and_counts_never_grow() {
        let scan = generate_pile(&PileParams {
            points: 20_000,
            ..PileParams::default()
        })
        .unwrap();
        let got = perceive(&scan, &PerceptionParams::default()).unwrap();
        let names: Vec<_> = got.stages.iter().map(|s| s.stage).collect();
        assert_eq!(
            names,
            [
                "level",
                "ground",
                "radius",
                "statistical",
                "voxel",
                "smooth",
                "fit"
            ]
        );
        let filtered = &got.stages[..6];
        assert!(filtered.windows(2).all(|w| w[1].points <= w[0].points));
        assert_eq!(got.stages[5].points, got.cloud.len());
        assert_eq!(got.input_points, scan.len());
    }

    #[test]
    fn a_disabled_stage_is_skipped_and_a_failing_one_is_named() {
        let scan = generate_pile(&PileParams {
            points: 20_000,
            ..PileParams::default()
        })
        .unwrap();
        let mut p = PerceptionParams::default();
        p.smooth.enabled = false;
        p.voxel.enabled = false;
        let got = perceive(&scan, &p).unwrap();
        assert!(got
            .stages
            .iter()
            .all(|s| s.stage != "smooth" && s.stage != "voxel"));
        p.ground.margin_m = 1e6; // removes every point
        let err = perceive(&scan, &p).unwrap_err();
        assert!(
            err.to_string().contains("fitting the surface") || err.to_string().contains("filter"),
            "{err}"
        );
    }
}
