//! Synthetic LiDAR scans of a muck pile (SPEC §4.1), in the four shapes of the
//! rope-shovel paper's Fig. 7: typical (a 40° face), concave, convex and
//! convex–concave — so calibration, filtering and the surface fit of [RS eq. 21]
//! can run without a LiDAR.
//!
//! # Scene (level frame, before the sensor tilt)
//! Sensor-centred and right-handed: the sensor at the origin, x horizontal
//! towards the pile (the dig direction), y to the left, z up. The floor is
//! `z = −h_s` (sensor height). The toe line is `x_toe(y) = D − A cos(π y / W)`
//! (D toe distance, W scan width, A bow: the pile spreads towards the machine
//! by A at the centre), and the pile surface is
//!
//! ```text
//!     z(x, y) = −h_s + H · g(s),   s = (x − x_toe(y)) / L,   L = H / tan φ
//! ```
//!
//! with face height H and repose angle φ = 40°, so every shape climbs H over
//! the same run L (a mean face slope of 40°) and `g(s) = 0` for s ≤ 0 (floor),
//! `g(s) = 1` for s ≥ 1 (the flat top, which reaches back `top_depth` beyond
//! the crest). The normalised profiles `g` on [0, 1]:
//!
//! | shape | g(s) | slope at toe / crest |
//! |---|---|---|
//! | typical | s, with parabolic fillets `(s + e)²/4e` at the toe and `1 − (1 + e − s)²/4e` at the crest, e = 0.05 | 0 → 40° face → 0 |
//! | convex (bulges out) | sin(π s / 2) | 52.8° → 0°, smooth into the top |
//! | concave (sags in) | (e^{k s} − 1)/(e^k − 1), k = 1.5 | 19.9° → 58.3° |
//! | convex–concave (S) | s + (c / 2π) sin(2π s), c = 0.6 | 53.3° at toe and crest, 18.6° at mid-height: bulging below, sagging above |
//!
//! (slopes in the y = ±W/2 plane where x_toe is D; with mean slope tan 40°.)
//! The typical fillets extend e·L before the toe and after the crest.
//!
//! # Scan
//! - **Sampling:** `points` points exactly. The surface share is spread
//!   uniformly by area over the visible part of the window
//!   `x ∈ [near, x_toe + L + top_depth]`, `|y| ≤ W/2`: (x, y) uniform, kept
//!   with probability ∝ `sqrt(1 + |∇z|²)` (area element of the height field),
//!   then kept only if the ray from the sensor reaches it (ray marching
//!   against z(x, y)). With the sensor at or above the top (the default)
//!   everything in the window is visible — along a ray the terrain only
//!   rises towards the point, and the ray never drops below the point's
//!   height — and the march is skipped.
//! - **Range noise:** Gaussian, σ = `range_noise_m`, along the ray from the sensor.
//! - **Outliers:** `outlier_fraction` of the points. Of these, the share
//!   `1 − isolated_share` lies uniformly in the scan's bounding box *above*
//!   the surface (dust, spray; box top 10 % of H above the crest); the rest
//!   are isolated points uniform in a box 1.5 × the scan's in every
//!   direction, some below the floor (multipath).
//! - **Tilt:** the scan is returned in sensor coordinates, `tilt(scene, α, β)`
//!   of [`crate::tilt`], so [`crate::level`] with the same angles undoes it.
//! - **Scale:** every length (H, W, D, A, near, top depth, sensor height and
//!   the noise σ) is given at full scale and multiplied by `scale`;
//!   [`PileParams::paper_model`] is the paper's 1:30 model (H ≈ 0.33 m).
//! - Points are shuffled (seeded), so outliers are not all at the end.

use std::f64::consts::{FRAC_PI_2, PI};
use std::str::FromStr;

use autoshovel_point_cloud::PointCloud;
use nalgebra::Vector3;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::calibrate::sensor_from_level;
use crate::error::{Result, SurfaceError};

/// Fillet half-width of the typical profile, in units of the run L.
const TYPICAL_FILLET: f64 = 0.05;
/// Growth rate k of the concave profile.
const CONCAVE_K: f64 = 1.5;
/// Amplitude c of the convex–concave profile's slope modulation.
const S_AMPLITUDE: f64 = 0.6;
/// Ray-marching steps of the visibility test.
const MARCH_STEPS: usize = 48;

/// The four pile shapes of the rope-shovel paper's Fig. 7.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum PileShape {
    /// Fig. 7a: a straight face at the repose angle, rounded at toe and crest.
    #[default]
    Typical,
    /// Fig. 7c: the face bulges out (steep at the toe, rounding into the top).
    Convex,
    /// Fig. 7b: the face sags in (gentle at the toe, steep at the crest).
    Concave,
    /// Fig. 7d: an S-profile, bulging in the lower half and sagging in the upper.
    ConvexConcave,
}

impl PileShape {
    /// All four, in the paper's order of Table 5 (typical, concave, convex,
    /// convex–concave).
    pub const ALL: [PileShape; 4] = [
        PileShape::Typical,
        PileShape::Concave,
        PileShape::Convex,
        PileShape::ConvexConcave,
    ];

    /// The name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            PileShape::Typical => "typical",
            PileShape::Convex => "convex",
            PileShape::Concave => "concave",
            PileShape::ConvexConcave => "convex-concave",
        }
    }

    /// The normalised profile g(s): 0 on the floor (s ≤ 0, or s ≤ −e for the
    /// typical fillet), 1 on the top (s ≥ 1, or 1 + e), see the module docs.
    pub fn profile(self, s: f64) -> f64 {
        if self == PileShape::Typical {
            let e = TYPICAL_FILLET;
            return if s <= -e {
                0.0
            } else if s < e {
                (s + e).powi(2) / (4.0 * e)
            } else if s <= 1.0 - e {
                s
            } else if s < 1.0 + e {
                1.0 - (1.0 + e - s).powi(2) / (4.0 * e)
            } else {
                1.0
            };
        }
        if s <= 0.0 {
            return 0.0;
        }
        if s >= 1.0 {
            return 1.0;
        }
        match self {
            PileShape::Typical => unreachable!("handled above"),
            PileShape::Convex => (FRAC_PI_2 * s).sin(),
            PileShape::Concave => ((CONCAVE_K * s).exp() - 1.0) / (CONCAVE_K.exp() - 1.0),
            PileShape::ConvexConcave => s + S_AMPLITUDE / (2.0 * PI) * (2.0 * PI * s).sin(),
        }
    }

    /// The derivative g'(s).
    pub fn profile_slope(self, s: f64) -> f64 {
        if self == PileShape::Typical {
            let e = TYPICAL_FILLET;
            return if s <= -e || s >= 1.0 + e {
                0.0
            } else if s < e {
                (s + e) / (2.0 * e)
            } else if s <= 1.0 - e {
                1.0
            } else {
                (1.0 + e - s) / (2.0 * e)
            };
        }
        if !(0.0..1.0).contains(&s) {
            return 0.0;
        }
        match self {
            PileShape::Typical => unreachable!("handled above"),
            PileShape::Convex => FRAC_PI_2 * (FRAC_PI_2 * s).cos(),
            PileShape::Concave => CONCAVE_K * (CONCAVE_K * s).exp() / (CONCAVE_K.exp() - 1.0),
            PileShape::ConvexConcave => 1.0 + S_AMPLITUDE * (2.0 * PI * s).cos(),
        }
    }

    /// The largest g'(s).
    fn max_slope(self) -> f64 {
        match self {
            PileShape::Typical => 1.0,
            PileShape::Convex => FRAC_PI_2,
            PileShape::Concave => self.profile_slope(1.0 - 1e-12),
            PileShape::ConvexConcave => 1.0 + S_AMPLITUDE,
        }
    }

    /// How far the profile reaches beyond [0, 1] on either side (the typical fillets).
    fn overhang(self) -> f64 {
        if self == PileShape::Typical {
            TYPICAL_FILLET
        } else {
            0.0
        }
    }
}

impl std::fmt::Display for PileShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PileShape {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().replace('_', "-").as_str() {
            "typical" => Ok(PileShape::Typical),
            "convex" => Ok(PileShape::Convex),
            "concave" => Ok(PileShape::Concave),
            "convex-concave" | "convexconcave" => Ok(PileShape::ConvexConcave),
            _ => Err(format!(
                "unknown pile shape '{s}' (use typical, convex, concave or convex-concave)"
            )),
        }
    }
}

/// How the scan's surface points are spread (see the module docs).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum ScanPattern {
    /// Uniform by area over the visible window (an idealised, evenly spread
    /// survey). The default.
    #[default]
    Area,
    /// Rays from the sensor in a non-repetitive rosette over a circular field
    /// of view (`fov_rad`), as a Livox-type Risley-prism LiDAR scans, cast
    /// onto the terrain: dense near the sensor and on the pattern's petals,
    /// sparse far away, with the floor's share set by the geometry.
    Rosette,
}

impl ScanPattern {
    /// The name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            ScanPattern::Area => "area",
            ScanPattern::Rosette => "rosette",
        }
    }
}

impl std::fmt::Display for ScanPattern {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ScanPattern {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "area" => Ok(ScanPattern::Area),
            "rosette" => Ok(ScanPattern::Rosette),
            _ => Err(format!("unknown scan pattern '{s}' (use area or rosette)")),
        }
    }
}

/// Smallest length scale [`generate_pile`] accepts (a 1 mm face).
pub const MIN_SCALE: f64 = 1e-4;
/// Largest length scale [`generate_pile`] accepts (a 10 km face): f32
/// coordinates still resolve centimetres there.
pub const MAX_SCALE: f64 = 1e3;

/// Parameters of [`generate_pile`]. Lengths are full-scale metres, multiplied
/// by `scale` (see the module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PileParams {
    /// The profile. Default typical.
    pub shape: PileShape,
    /// Points in the scan, exactly. Default 100 000.
    pub points: usize,
    /// Length scale: 1 for a mine face, 1/30 for the paper's model. Default 1.
    pub scale: f64,
    /// Face height H, toe to crest (m). Default 10 m.
    pub face_height_m: f64,
    /// Repose angle φ: the mean slope of the face (rad). Default 40°.
    pub repose_angle_rad: f64,
    /// Scan width W across the dig direction (m). Default 20 m.
    pub width_m: f64,
    /// Horizontal distance D from the sensor to the toe at the sides (m). Default 15 m.
    pub toe_distance_m: f64,
    /// Bow A of the toe line towards the sensor at the centre (m). Default 0.5 m.
    pub toe_bow_m: f64,
    /// Nearest floor in the scan, from the sensor (m). Default 5 m.
    pub near_distance_m: f64,
    /// Depth of the flat top scanned behind the crest (m). Default 8 m.
    pub top_depth_m: f64,
    /// Sensor height h_s above the floor (m). Default 12 m (high on the
    /// machine, above the crest, so the top is seen).
    pub sensor_height_m: f64,
    /// Standard deviation of the range noise along the ray (m). Default 0.02 m.
    pub range_noise_m: f64,
    /// Share of outlier points, in [0, 0.5]. Default 0.01.
    pub outlier_fraction: f64,
    /// Share of the outliers that are isolated points far from the surface
    /// (the rest hover above it), in [0, 1]. Default 0.2.
    pub isolated_share: f64,
    /// Sensor roll α of [RS eq. 11] (rad). Default 3°.
    pub roll_rad: f64,
    /// Sensor pitch β of [RS eq. 11] (rad). Default −2°.
    pub pitch_rad: f64,
    /// How the surface points are spread. Default [`ScanPattern::Area`].
    pub pattern: ScanPattern,
    /// Full angle of the circular field of view of [`ScanPattern::Rosette`],
    /// centred on the middle of the scan window (rad). Default 70.4° (a
    /// Livox Avia's circular pattern).
    pub fov_rad: f64,
    /// Seed of the ChaCha8 generator. Default 1.
    pub seed: u64,
    /// Shift of the whole scene, sensor included, in the level frame's
    /// (x, y) (m), before the tilt: the scans of a survey of many piles
    /// share one frame this way ([`PileParams::survey_step_m`]). Default 0.
    pub offset_m: [f64; 2],
}

impl Default for PileParams {
    fn default() -> Self {
        Self {
            shape: PileShape::Typical,
            points: 100_000,
            scale: 1.0,
            face_height_m: 10.0,
            repose_angle_rad: 40f64.to_radians(),
            width_m: 20.0,
            toe_distance_m: 15.0,
            toe_bow_m: 0.5,
            near_distance_m: 5.0,
            top_depth_m: 8.0,
            sensor_height_m: 12.0,
            range_noise_m: 0.02,
            outlier_fraction: 0.01,
            isolated_share: 0.2,
            roll_rad: 3f64.to_radians(),
            pitch_rad: (-2f64).to_radians(),
            pattern: ScanPattern::Area,
            fov_rad: 70.4f64.to_radians(),
            seed: 1,
            offset_m: [0.0, 0.0],
        }
    }
}

impl PileParams {
    /// The paper's 1:30 scale model: the defaults at `scale = 1/30` (face
    /// about 0.33 m high, 0.67 m wide, noise 0.67 mm).
    pub fn paper_model() -> Self {
        Self {
            scale: 1.0 / 30.0,
            ..Self::default()
        }
    }

    /// Check the ranges once, at the edge.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value: f64, expected| {
            Err(SurfaceError::BadParameter {
                name,
                value,
                expected,
            })
        };
        let positive = [
            ("PileParams.scale", self.scale),
            ("PileParams.face_height_m", self.face_height_m),
            ("PileParams.width_m", self.width_m),
            ("PileParams.toe_distance_m", self.toe_distance_m),
            ("PileParams.sensor_height_m", self.sensor_height_m),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "a finite value > 0");
            }
        }
        let non_negative = [
            ("PileParams.toe_bow_m", self.toe_bow_m),
            ("PileParams.near_distance_m", self.near_distance_m),
            ("PileParams.top_depth_m", self.top_depth_m),
            ("PileParams.range_noise_m", self.range_noise_m),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v, "a finite value >= 0");
            }
        }
        if !(MIN_SCALE..=MAX_SCALE).contains(&self.scale) {
            return bad(
                "PileParams.scale",
                self.scale,
                "a length scale in [1e-4, 1e3] (1 = a 10 m face; f32 coordinates hold no more)",
            );
        }
        if self.points == 0 {
            return bad("PileParams.points", 0.0, "at least 1");
        }
        if !(self.repose_angle_rad > 0.0 && self.repose_angle_rad < 80f64.to_radians()) {
            return bad(
                "PileParams.repose_angle_rad",
                self.repose_angle_rad,
                "an angle in (0°, 80°) [rad]",
            );
        }
        let first_toe = self.toe_distance_m
            - self.toe_bow_m
            - self.shape.overhang() * self.face_height_m / self.repose_angle_rad.tan();
        if self.near_distance_m >= first_toe {
            return bad(
                "PileParams.near_distance_m",
                self.near_distance_m,
                "less than the nearest toe (toe_distance_m − toe_bow_m), so the scan has a floor",
            );
        }
        if !(0.0..=0.5).contains(&self.outlier_fraction) {
            return bad(
                "PileParams.outlier_fraction",
                self.outlier_fraction,
                "a share in [0, 0.5]",
            );
        }
        if !(0.0..=1.0).contains(&self.isolated_share) {
            return bad(
                "PileParams.isolated_share",
                self.isolated_share,
                "a share in [0, 1]",
            );
        }
        if !(self.fov_rad > 0.0 && self.fov_rad < 170f64.to_radians()) {
            return bad(
                "PileParams.fov_rad",
                self.fov_rad,
                "a field of view in (0°, 170°) [rad]",
            );
        }
        for (name, v) in [
            ("PileParams.roll_rad", self.roll_rad),
            ("PileParams.pitch_rad", self.pitch_rad),
        ] {
            if v.is_nan() || v.abs() >= 45f64.to_radians() {
                return bad(name, v, "an angle within ±45° [rad]");
            }
        }
        for v in self.offset_m {
            // f32 coordinates resolve a centimetre out to 100 km.
            if !(v.is_finite() && v.abs() <= 1e5) {
                return bad("PileParams.offset_m", v, "a shift within ±100 km [m]");
            }
        }
        Ok(())
    }

    /// Face run L = H / tan φ, scaled (m).
    pub fn face_run_m(&self) -> f64 {
        self.scale * self.face_height_m / self.repose_angle_rad.tan()
    }

    /// Toe line x_toe(y) in the level frame, scaled (m).
    pub fn toe_x_m(&self, y: f64) -> f64 {
        let w = self.scale * self.width_m;
        self.scale * (self.toe_distance_m - self.toe_bow_m * (PI * y / w).cos())
    }

    /// Scan `i` of a sequence made from these parameters: its own seed
    /// (`seed + i`), and in a survey of `columns` scans a row the shift
    /// of its place, column `i mod columns` and row `i div columns`, by
    /// [`PileParams::survey_step_m`] (frames of one sequence stay put).
    pub fn nth_scan(&self, i: usize, survey_columns: Option<usize>) -> PileParams {
        let offset_m = survey_columns.map_or(self.offset_m, |nx| {
            let step = self.survey_step_m();
            [
                self.offset_m[0] + (i % nx) as f64 * step[0],
                self.offset_m[1] + (i / nx) as f64 * step[1],
            ]
        });
        PileParams {
            seed: self.seed.wrapping_add(i as u64),
            offset_m,
            ..self.clone()
        }
    }

    /// The shift from one scan of a survey to the next along x and y (m):
    /// the scan window's extent less 5 %, so that neighbouring scans
    /// overlap a little, as a survey's passes do.
    pub fn survey_step_m(&self) -> [f64; 2] {
        let ([x0, x1], [y0, y1]) = self.window_m();
        [0.95 * (x1 - x0), 0.95 * (y1 - y0)]
    }

    /// The x range `[near, far]` and the y range `[−W/2, W/2]` scanned, scaled (m).
    pub fn window_m(&self) -> ([f64; 2], [f64; 2]) {
        let l = self.face_run_m();
        let far = self.scale * self.toe_distance_m
            + l * (1.0 + self.shape.overhang())
            + self.scale * self.top_depth_m;
        let half = 0.5 * self.scale * self.width_m;
        ([self.scale * self.near_distance_m, far], [-half, half])
    }

    /// The noiseless surface z(x, y) in the level, sensor-centred frame (m)
    /// (the floor is at `−scale · sensor_height_m`).
    pub fn height_at(&self, x: f64, y: f64) -> f64 {
        let s = (x - self.toe_x_m(y)) / self.face_run_m();
        self.scale * (self.face_height_m * self.shape.profile(s) - self.sensor_height_m)
    }

    /// Gradient (∂z/∂x, ∂z/∂y) of [`PileParams::height_at`].
    fn gradient(&self, x: f64, y: f64) -> (f64, f64) {
        let l = self.face_run_m();
        let w = self.scale * self.width_m;
        let s = (x - self.toe_x_m(y)) / l;
        let dz_ds = self.scale * self.face_height_m * self.shape.profile_slope(s);
        let dtoe_dy = self.scale * self.toe_bow_m * PI / w * (PI * y / w).sin();
        (dz_ds / l, -dz_ds * dtoe_dy / l)
    }
}

/// A synthetic LiDAR scan of a pile in sensor coordinates (see the module
/// docs): exactly `params.points` points, same seed same scan.
///
/// ```
/// use autoshovel_terrain::{generate_pile, level, PileParams, PileShape};
/// let p = PileParams { shape: PileShape::Convex, points: 5_000, ..PileParams::default() };
/// let scan = generate_pile(&p).unwrap();
/// assert_eq!(scan.len(), 5_000);
/// // Levelled, the points lie between the floor (12 m below the sensor) and the top.
/// let flat = level(&scan, p.roll_rad, p.pitch_rad);
/// let inside = flat.points.iter().filter(|q| q[2] > -12.2 && q[2] < -1.8).count();
/// assert!(inside >= 4_950);
/// ```
pub fn generate_pile(params: &PileParams) -> Result<PointCloud> {
    params.validate()?;
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let n_out = (params.points as f64 * params.outlier_fraction).round() as usize;
    let n_iso = (n_out as f64 * params.isolated_share).round() as usize;
    let n_air = n_out - n_iso;
    let n_surface = params.points - n_out;

    let ([x0, x1], [y0, y1]) = params.window_m();
    let floor = -params.scale * params.sensor_height_m;
    let top = floor + params.scale * params.face_height_m;
    let l = params.face_run_m();
    let slope_bound = params.scale * params.face_height_m / l
        * params.shape.max_slope()
        * (1.0 + (params.toe_bow_m * PI / params.width_m).powi(2)).sqrt();
    let area_bound = (1.0 + slope_bound * slope_bound).sqrt() * 1.000_001;
    let noise = Normal::new(0.0, params.scale * params.range_noise_m).expect("σ >= 0, finite");

    let mut scene: Vec<Vector3<f64>> = Vec::with_capacity(params.points);
    match params.pattern {
        ScanPattern::Area => {
            area_surface(params, &mut rng, &noise, n_surface, area_bound, &mut scene)?;
        }
        ScanPattern::Rosette => rosette_surface(params, &mut rng, &noise, n_surface, &mut scene)?,
    }
    let z_hi = top + 0.1 * params.scale * params.face_height_m;
    while scene.len() < n_surface + n_air {
        let x = rng.gen_range(x0..=x1);
        let y = rng.gen_range(y0..=y1);
        let z = rng.gen_range(floor..=z_hi);
        if z > params.height_at(x, y) + 3.0 * params.scale * params.range_noise_m {
            scene.push(Vector3::new(x, y, z));
        }
    }
    let (cx, cy, cz) = (0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (floor + z_hi));
    let (hx, hy, hz) = (0.75 * (x1 - x0), 0.75 * (y1 - y0), 0.75 * (z_hi - floor));
    for _ in 0..n_iso {
        scene.push(Vector3::new(
            cx + rng.gen_range(-hx..=hx),
            cy + rng.gen_range(-hy..=hy),
            cz + rng.gen_range(-hz..=hz),
        ));
    }
    scene.shuffle(&mut rng);

    let sensor_from_level = sensor_from_level(params.roll_rad, params.pitch_rad);
    let offset = Vector3::new(params.offset_m[0], params.offset_m[1], 0.0);
    let points = scene
        .into_iter()
        .map(|p| {
            let q = sensor_from_level * (p + offset);
            [q.x as f32, q.y as f32, q.z as f32]
        })
        .collect();
    Ok(PointCloud::new(points))
}

/// The surface points of [`ScanPattern::Area`]: (x, y) uniform over the window,
/// kept ∝ the area element, then only where the sensor sees them.
fn area_surface(
    params: &PileParams,
    rng: &mut ChaCha8Rng,
    noise: &Normal<f64>,
    n_surface: usize,
    area_bound: f64,
    scene: &mut Vec<Vector3<f64>>,
) -> Result<()> {
    let ([x0, x1], [y0, y1]) = params.window_m();
    let nearest_toe = params.toe_x_m(0.0) - params.shape.overhang() * params.face_run_m();
    // Along a ray from the sensor the terrain height never falls (s grows with
    // the ray parameter while x > A·π/W·|y|, which holds for x ≥ near > A·π/2),
    // so a sensor at or above the top sees every point: no marching needed.
    let sees_all = params.sensor_height_m >= params.face_height_m
        && params.near_distance_m > params.toe_bow_m * FRAC_PI_2;
    let max_attempts = 1000 * n_surface + 1_000_000;
    let mut attempts = 0;
    while scene.len() < n_surface {
        attempts += 1;
        if attempts > max_attempts {
            return Err(SurfaceError::TooFewPoints {
                stage: "pile generator (visible surface)",
                points: scene.len(),
                required: n_surface,
                hint: "; raise PileParams.sensor_height_m: the sensor sees almost none of the scan window",
            });
        }
        let x = rng.gen_range(x0..=x1);
        let y = rng.gen_range(y0..=y1);
        let (gx, gy) = params.gradient(x, y);
        let keep = (1.0 + gx * gx + gy * gy).sqrt() / area_bound;
        if rng.gen::<f64>() >= keep {
            continue;
        }
        let p = Vector3::new(x, y, params.height_at(x, y));
        if !sees_all && x >= nearest_toe && !visible(params, &p) {
            continue;
        }
        let r = p.norm();
        let eps = noise.sample(rng);
        scene.push(if r > 0.0 { p * (1.0 + eps / r) } else { p });
    }
    Ok(())
}

/// The surface points of [`ScanPattern::Rosette`]: rays from the sensor in a
/// non-repetitive rosette about the boresight (the sensor to the middle of the
/// window), each cast onto the terrain; a ray that lands outside the window
/// or never lands is a miss (no return). The angular offsets from the
/// boresight are `u = ½R (cos t + cos ωt)`, `v = ½R (sin t − sin ωt)` with
/// R half the field of view and ω = 5φ (φ the golden ratio, so the curve
/// never closes), t advancing a fixed step per ray from a seeded phase.
fn rosette_surface(
    params: &PileParams,
    rng: &mut ChaCha8Rng,
    noise: &Normal<f64>,
    n_surface: usize,
    scene: &mut Vec<Vector3<f64>>,
) -> Result<()> {
    let ([x0, x1], [y0, y1]) = params.window_m();
    let xc = 0.5 * (x0 + x1);
    let boresight = Vector3::new(xc, 0.0, params.height_at(xc, 0.0)).normalize();
    let e1 = boresight.cross(&Vector3::z()).normalize();
    let e2 = e1.cross(&boresight);
    let half_fov = 0.5 * params.fov_rad;
    let omega = 2.5 * (1.0 + 5f64.sqrt());
    // About 400 turns of the slow rotation over the scan.
    let dt = 400.0 * 2.0 * PI / (2.0 * n_surface.max(1) as f64);
    let mut t = rng.gen_range(0.0..2.0 * PI);
    // March a ray in steps of 1/40 of the face run (the terrain's shortest
    // feature is the typical fillet, 1/10 of it), then bisect to the hit.
    let step = params.face_run_m() / 40.0;
    let floor = -params.scale * params.sensor_height_m;
    let reach = 2.0 * (x1.hypot(y1) + params.scale * params.sensor_height_m);
    let max_rays = 50 * n_surface + 10_000;
    let mut rays = 0;
    while scene.len() < n_surface {
        rays += 1;
        if rays > max_rays {
            return Err(SurfaceError::TooFewPoints {
                stage: "pile generator (rosette pattern)",
                points: scene.len(),
                required: n_surface,
                hint: "; widen PileParams.fov_rad or move the sensor: the pattern misses the scan window",
            });
        }
        t += dt;
        let u = 0.5 * half_fov * (t.cos() + (omega * t).cos());
        let v = 0.5 * half_fov * (t.sin() - (omega * t).sin());
        let d = (boresight + u.tan() * e1 + v.tan() * e2).normalize();
        let above = |s: f64| {
            let q = d * s;
            q.z - params.height_at(q.x, q.y)
        };
        let t_end = if d.z < 0.0 {
            (floor / d.z).min(reach)
        } else {
            reach
        };
        let (mut lo, mut hi) = (0.0, f64::NAN);
        let mut s = step;
        while s < t_end + step {
            let s_clamped = s.min(t_end);
            if above(s_clamped) <= 0.0 {
                hi = s_clamped;
                break;
            }
            lo = s_clamped;
            s += step;
        }
        if hi.is_nan() {
            continue; // into the sky
        }
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if above(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let r = hi;
        let p = d * r;
        if !(x0..=x1).contains(&p.x) || !(y0..=y1).contains(&p.y) {
            continue;
        }
        let p = Vector3::new(p.x, p.y, params.height_at(p.x, p.y));
        scene.push(p * (1.0 + noise.sample(rng) / p.norm()));
    }
    Ok(())
}

/// Whether the straight ray from the sensor (origin) to a surface point stays
/// above the surface (marching, with a tolerance of 1e-4 H).
fn visible(params: &PileParams, p: &Vector3<f64>) -> bool {
    let tol = 1e-4 * params.scale * params.face_height_m;
    (1..MARCH_STEPS).all(|k| {
        let t = k as f64 / MARCH_STEPS as f64;
        let q = p * t;
        q.z >= params.height_at(q.x, q.y) - tol
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::calibrate::level;
    use approx::assert_relative_eq;

    #[test]
    fn the_nth_scan_has_its_own_seed_and_its_place_in_a_survey() {
        let base = PileParams {
            seed: u64::MAX - 1,
            ..PileParams::default()
        };
        let step = base.survey_step_m();
        // Frames: seeds go on (wrapping), the place stays.
        let frame = base.nth_scan(3, None);
        assert_eq!((frame.seed, frame.offset_m), (1, base.offset_m));
        // A survey of 4 columns: scan 6 is column 2 of row 1.
        let tile = base.nth_scan(6, Some(4));
        assert_eq!(tile.seed, 4);
        assert_relative_eq!(tile.offset_m[0], 2.0 * step[0]);
        assert_relative_eq!(tile.offset_m[1], step[1]);
        assert_eq!(base.nth_scan(0, Some(4)), base);
    }

    #[test]
    fn profiles_run_from_floor_to_top_and_rise() {
        for shape in PileShape::ALL {
            let e = shape.overhang();
            assert_relative_eq!(shape.profile(-e - 1e-9), 0.0);
            assert_relative_eq!(shape.profile(1.0 + e + 1e-9), 1.0);
            assert_relative_eq!(shape.profile(0.5), 0.5, epsilon = 0.25);
            let mut last = 0.0;
            for k in 0..=1000 {
                let s = -0.1 + 1.2 * k as f64 / 1000.0;
                let g = shape.profile(s);
                assert!(g >= last - 1e-12, "{shape} falls at s = {s}");
                last = g;
                // The slope is the derivative of the profile.
                let h = 1e-6;
                let fd = (shape.profile(s + h) - shape.profile(s - h)) / (2.0 * h);
                assert!(
                    (fd - shape.profile_slope(s)).abs() < 1e-4
                        || (s.abs() < 1e-5)
                        || ((s - 1.0).abs() < 1e-5),
                    "{shape} at {s}: {fd} vs {}",
                    shape.profile_slope(s)
                );
                assert!(shape.profile_slope(s) <= shape.max_slope() + 1e-12);
            }
        }
    }

    #[test]
    fn shapes_bend_the_documented_way() {
        // Mid-face height relative to the straight 40° face.
        assert_relative_eq!(PileShape::Typical.profile(0.5), 0.5);
        assert!(PileShape::Convex.profile(0.5) > 0.6, "bulges out");
        assert!(PileShape::Concave.profile(0.5) < 0.4, "sags in");
        let s = PileShape::ConvexConcave;
        assert!(
            s.profile(0.25) > 0.3 && s.profile(0.75) < 0.7,
            "bulge below, sag above"
        );
        assert_relative_eq!(s.profile(0.5), 0.5, epsilon = 1e-12);
        // Slopes at the toe quoted in the module docs (φ = 40°).
        let deg = |g: f64| (g * 40f64.to_radians().tan()).atan().to_degrees();
        assert_relative_eq!(
            deg(PileShape::Convex.profile_slope(0.0)),
            52.8,
            epsilon = 0.05
        );
        assert_relative_eq!(
            deg(PileShape::Concave.profile_slope(0.0)),
            19.9,
            epsilon = 0.05
        );
        assert_relative_eq!(
            deg(PileShape::Concave.profile_slope(1.0 - 1e-12)),
            58.3,
            epsilon = 0.05
        );
        assert_relative_eq!(deg(s.profile_slope(0.0)), 53.3, epsilon = 0.05);
        assert_relative_eq!(deg(s.profile_slope(0.5)), 18.6, epsilon = 0.05);
    }

    #[test]
    fn exact_count_same_seed_same_scan() {
        let p = PileParams {
            points: 20_001,
            ..PileParams::default()
        };
        let a = generate_pile(&p).unwrap();
        assert_eq!(a.len(), 20_001);
        assert_eq!(a, generate_pile(&p).unwrap());
        let b = generate_pile(&PileParams { seed: 2, ..p }).unwrap();
        assert_ne!(a, b);
    }

    #[test]
    fn noiseless_scan_lies_on_the_surface_after_levelling() {
        for shape in PileShape::ALL {
            let p = PileParams {
                shape,
                points: 5_000,
                range_noise_m: 0.0,
                outlier_fraction: 0.0,
                ..PileParams::default()
            };
            let flat = level(&generate_pile(&p).unwrap(), p.roll_rad, p.pitch_rad);
            for q in &flat.points {
                let (x, y, z) = (f64::from(q[0]), f64::from(q[1]), f64::from(q[2]));
                assert!((z - p.height_at(x, y)).abs() < 1e-4, "{shape}: {q:?}");
            }
            // About a third on the floor, the rest on the pile.
            let on_floor = flat.points.iter().filter(|q| q[2] < -11.99).count();
            assert!((1_200..2_200).contains(&on_floor), "{shape}: {on_floor}");
        }
    }

    #[test]
    fn outliers_and_noise_as_asked() {
        let p = PileParams {
            points: 50_000,
            outlier_fraction: 0.02,
            ..PileParams::default()
        };
        let flat = level(&generate_pile(&p).unwrap(), p.roll_rad, p.pitch_rad);
        let off: Vec<f64> = flat
            .points
            .iter()
            .map(|q| f64::from(q[2]) - p.height_at(f64::from(q[0]), f64::from(q[1])))
            .collect();
        let far = off.iter().filter(|d| d.abs() > 0.2).count();
        // 1000 outliers, a few of which land within 0.2 m of the surface.
        assert!((900..=1000).contains(&far), "{far}");
        let near: Vec<f64> = off.iter().copied().filter(|d| d.abs() <= 0.2).collect();
        let rms = (near.iter().map(|d| d * d).sum::<f64>() / near.len() as f64).sqrt();
        // Range noise of 2 cm along rays that meet the surface obliquely.
        assert!(rms > 0.005 && rms < 0.03, "{rms}");
    }

    #[test]
    fn paper_model_is_one_thirtieth() {
        let p = PileParams::paper_model();
        assert_relative_eq!(
            p.face_run_m(),
            10.0 / 30.0 / 40f64.to_radians().tan(),
            epsilon = 1e-12
        );
        let flat = level(
            &generate_pile(&PileParams {
                points: 2_000,
                ..p.clone()
            })
            .unwrap(),
            p.roll_rad,
            p.pitch_rad,
        );
        let (lo, hi) = flat.bounds().unwrap();
        assert!(lo[2] > -0.45 && hi[2] < -0.02, "{lo:?} {hi:?}");
    }

    #[test]
    fn a_high_sensor_sees_everything_so_skipping_the_march_is_exact() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for shape in PileShape::ALL {
            let p = PileParams {
                shape,
                ..PileParams::default()
            };
            let ([x0, x1], [y0, y1]) = p.window_m();
            for _ in 0..2_000 {
                let (x, y) = (rng.gen_range(x0..=x1), rng.gen_range(y0..=y1));
                assert!(
                    visible(&p, &Vector3::new(x, y, p.height_at(x, y))),
                    "{shape} ({x}, {y})"
                );
            }
        }
    }

    #[test]
    fn a_low_sensor_does_not_see_the_top() {
        let p = PileParams {
            points: 5_000,
            sensor_height_m: 6.0,
            range_noise_m: 0.0,
            outlier_fraction: 0.0,
            ..PileParams::default()
        };
        let flat = level(&generate_pile(&p).unwrap(), p.roll_rad, p.pitch_rad);
        let crest_x = p.toe_x_m(0.0) + p.face_run_m() * 1.05 + 1.0;
        let behind = flat
            .points
            .iter()
            .filter(|q| f64::from(q[0]) > crest_x)
            .count();
        assert_eq!(behind, 0);
    }

    #[test]
    fn bad_parameters_are_named() {
        let err = generate_pile(&PileParams {
            near_distance_m: 20.0,
            ..PileParams::default()
        })
        .unwrap_err();
        assert!(
            err.to_string().contains("PileParams.near_distance_m"),
            "{err}"
        );
        let err = generate_pile(&PileParams {
            scale: 0.0,
            ..PileParams::default()
        })
        .unwrap_err();
        assert!(err.to_string().contains("PileParams.scale"), "{err}");
        // Scales whose coordinates overflow f32 (all inf) or the sampler's
        // range (a panic, issue 11) are refused, the value printed short.
        for (scale, shown) in [(1e39, "1e39"), (1e307, "1e307"), (1e-9, "1e-9")] {
            let err = generate_pile(&PileParams {
                scale,
                ..PileParams::default()
            })
            .unwrap_err()
            .to_string();
            assert!(
                err.starts_with(&format!("PileParams.scale = {shown}: ")),
                "{err}"
            );
        }
        for scale in [MIN_SCALE, MAX_SCALE] {
            let cloud = generate_pile(&PileParams {
                scale,
                points: 2_000,
                ..PileParams::default()
            })
            .unwrap();
            assert!(cloud.points.iter().flatten().all(|v| v.is_finite()));
        }
        assert_eq!(
            "convex-concave".parse::<PileShape>().unwrap(),
            PileShape::ConvexConcave
        );
        assert!("wavy".parse::<PileShape>().is_err());
    }
}

/// The summary of `autoshovel generate-pile` (SPEC §6): what was generated
/// and where it was written.
#[derive(Debug, Clone, serde::Serialize)]
pub struct GeneratePileSummary {
    /// "generate-pile".
    pub job: &'static str,
    /// Shape name (Fig. 7).
    pub shape: &'static str,
    /// Points written.
    pub points: usize,
    /// How the points are spread (`area` or `rosette`).
    pub pattern: &'static str,
    /// Sensor height above the floor (m).
    pub sensor_height_m: f64,
    /// Sensor roll α (deg).
    pub roll_deg: f64,
    /// Sensor pitch β (deg).
    pub pitch_deg: f64,
    /// Length scale (1 = a 10 m face).
    pub scale: f64,
    /// Seed of the noise and sampling.
    pub seed: u64,
    /// The file written (the first, for a sequence).
    pub file: String,
    /// Files written: 1, or the frames of a sequence (`--frames`), each
    /// from the same sensor pose with the next seed.
    pub frames: usize,
    /// The last file written.
    pub last_file: String,
    /// Its encoding.
    pub encoding: &'static str,
    /// Time to generate (ms).
    pub generate_ms: f64,
    /// Time to write (ms).
    pub write_ms: f64,
    /// Always true (a failed run is an error).
    pub success: bool,
}

impl GeneratePileSummary {
    /// The summary of `points` generated with `p` and written to `file`.
    pub fn new(
        p: &PileParams,
        points: usize,
        file: &std::path::Path,
        encoding: &'static str,
        (generate_ms, write_ms): (f64, f64),
    ) -> Self {
        Self {
            job: "generate-pile",
            frames: 1,
            last_file: file.display().to_string(),
            shape: p.shape.name(),
            points,
            pattern: p.pattern.name(),
            sensor_height_m: p.scale * p.sensor_height_m,
            roll_deg: p.roll_rad.to_degrees(),
            pitch_deg: p.pitch_rad.to_degrees(),
            scale: p.scale,
            seed: p.seed,
            file: file.display().to_string(),
            encoding,
            generate_ms,
            write_ms,
            success: true,
        }
    }
}
