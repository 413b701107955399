//! Errors of calibration, floor estimation, surface fitting and pile generation.

/// Everything that can go wrong in this crate. Each variant names the value at
/// fault and, where there is one, what to change.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceError {
    /// A parameter out of its valid range.
    #[error("{name} = {}: expected {expected}", autoshovel_core::config::short(*value))]
    BadParameter {
        /// The parameter, as `Struct.field`.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The valid range, in words.
        expected: &'static str,
    },
    /// A setting sizes more work than the stated ceiling (checked before
    /// the work, once the cloud is known).
    #[error("{key} = {value} asks too much: {estimate}; the ceiling is {ceiling}")]
    TooMuchWork {
        /// The setting, as written in the settings file (`[smooth] iterations`).
        key: String,
        /// Its value.
        value: String,
        /// The work it implies.
        estimate: String,
        /// The ceiling.
        ceiling: String,
    },
    /// Too few points for a stage to work with.
    #[error("{stage}: {points} points, at least {required} needed{hint}")]
    TooFewPoints {
        /// The stage ("floor RANSAC", "surface fit", ...).
        stage: &'static str,
        /// Points available.
        points: usize,
        /// Points needed.
        required: usize,
        /// What to change (may be empty; starts with "; " otherwise).
        hint: &'static str,
    },
    /// No plane within the allowed tilt with almost nothing below it holds
    /// enough of the points to be the floor.
    #[error(
        "no floor: the best plane within {max_tilt_deg:.1} deg of horizontal with almost no points \
         below it holds {inliers} of {candidates} points (at least {required} needed); the scan \
         shows no floor to level by: give roll and pitch (`[level] mode = \"given\"` in \
         perceive's settings), or, if the floor is a smaller share of the scan, lower \
         `[level] min_floor_share` (TiltParams.min_floor_share in the library)"
    )]
    NoFloor {
        /// Inliers of the best plane found.
        inliers: usize,
        /// Points searched.
        candidates: usize,
        /// Inliers required.
        required: usize,
        /// The largest accepted tilt of the floor (deg).
        max_tilt_deg: f64,
    },
    /// The 8 × 8 samples do not determine even a plane (e.g. all on one line).
    #[error(
        "degenerate samples: {samples} grid samples have rank {rank} for the {terms} terms of a \
         degree-{degree} polynomial; the cloud must span an area in x and y"
    )]
    DegenerateSamples {
        /// Grid samples taken.
        samples: usize,
        /// Numerical rank of the design matrix.
        rank: usize,
        /// Polynomial terms.
        terms: usize,
        /// Polynomial total degree.
        degree: usize,
    },
    /// The fitted surface explains too little of the samples' height variance
    /// (rope-shovel paper §3.2 asks R² > 0.95).
    #[error(
        "poor surface fit: R² = {r2:.4} <= threshold {threshold} (degree {degree}, {samples} \
         samples); clean the cloud first, or lower the threshold (`[fit] r2_threshold` in \
         perceive's settings, 0 accepts any fit; FitParams.r2_threshold in the library)"
    )]
    PoorFit {
        /// Coefficient of determination on the grid samples.
        r2: f64,
        /// The threshold it had to exceed.
        threshold: f64,
        /// Total degree of the best polynomial.
        degree: usize,
        /// Grid samples used.
        samples: usize,
    },
    /// A settings file could not be read, parsed or checked (names the file, line and key).
    #[error(transparent)]
    Config(#[from] autoshovel_core::config::ConfigError),
    /// A point-cloud file could not be read, or a filter refused its input.
    #[error(transparent)]
    Cloud(#[from] autoshovel_point_cloud::CloudError),
    /// A filter-chain stage's value could not be read (`autoshovel filter`).
    #[error("--{flag} {spec}: {problem}; expected {syntax}")]
    BadStage {
        /// The stage's flag, without dashes.
        flag: &'static str,
        /// The value given.
        spec: String,
        /// What is wrong with it.
        problem: String,
        /// What a value looks like.
        syntax: &'static str,
    },
    /// The cloud's x and y are degrees (a geographic CRS): perception
    /// measures in metres.
    #[error(
        "the scan's x and y are degrees of longitude and latitude ({crs}), not metres: project it first \
         (e.g. `pdal translate IN OUT reprojection --filters.reprojection.out_srs=EPSG:326NN` for its UTM zone)"
    )]
    Geographic {
        /// The CRS the file states.
        crs: String,
    },
    /// A filter-chain stage refused its value or emptied the cloud
    /// (`autoshovel filter`), said in the flag's own terms.
    #[error("--{flag} {spec}: {problem}")]
    StageFailed {
        /// The stage's flag, without dashes.
        flag: &'static str,
        /// The value given.
        spec: String,
        /// What went wrong and what to change, in the flag's terms.
        problem: String,
    },
    /// A filter-chain stage's value sizes more work than the ceiling
    /// (checked before any work).
    #[error("--{flag} {spec} asks too much: {estimate}; the ceiling is {ceiling}")]
    StageTooMuchWork {
        /// The stage's flag, without dashes.
        flag: &'static str,
        /// The value given.
        spec: String,
        /// The work it implies on this cloud.
        estimate: String,
        /// The ceiling.
        ceiling: String,
    },
    /// A filter stage of the perception pipeline failed.
    #[error("{stage} filter")]
    Filter {
        /// The stage (ground, radius, statistical, voxel, smooth).
        stage: &'static str,
        /// Why.
        #[source]
        source: autoshovel_point_cloud::CloudError,
    },
    /// A setting the tiled survey path (`perceive --tiles`) does not
    /// apply: refused rather than ignored.
    #[error("{setting} is not applied with --tiles: {instead}")]
    NotWithTiles {
        /// The setting as written (`[range] limits = "..."`).
        setting: String,
        /// What to do instead.
        instead: &'static str,
    },
    /// A stage of the perception pipeline failed.
    #[error("{stage}")]
    Stage {
        /// What the pipeline was doing.
        stage: &'static str,
        /// Why.
        #[source]
        source: Box<SurfaceError>,
    },
    /// A frame sequence could not be listed, or no frame of it perceived.
    #[error("{dir}: {problem}")]
    Frames {
        /// The folder (or what the frames came from).
        dir: String,
        /// What is wrong.
        problem: String,
    },
    /// The files of a survey do not belong together (scale or coordinate
    /// system differ), or one is not a LAS/LAZ file.
    #[error("{path}: {problem}")]
    Survey {
        /// The file at fault.
        path: std::path::PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// A tile (with its margin) needs more memory than the limit allows.
    #[error(
        "tile {tile} holds {points} points with its margin, about {need} of working memory, \
         more than the limit of {limit}: give a smaller tile (--tile-size) or a larger limit \
         (--memory-limit)"
    )]
    TileTooLarge {
        /// The tile, as `(column, row)` and its box.
        tile: String,
        /// Points of the tile and its margin.
        points: u64,
        /// The memory they need, in words.
        need: String,
        /// The limit, in words.
        limit: String,
    },
    /// A tile's working file could not be written or read back.
    #[error("tile working file {path}: {source}")]
    Spill {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A tile's working file is not what the run wrote: missing, or of
    /// another size (a worker that does not see the run's working folder,
    /// or a file changed under the run).
    #[error("tile working file {path}: {problem}")]
    TileFile {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// The executor of a stage's tiles failed, or its reports do not
    /// answer its tasks one for one.
    #[error("the {stage} stage's tiles: {problem}")]
    TileExecutor {
        /// The stage.
        stage: String,
        /// What went wrong.
        problem: String,
    },
    /// The scan holds no finite point.
    #[error("the scan holds no finite points ({non_finite_dropped} non-finite dropped)")]
    NoFinitePoints {
        /// Points dropped for a NaN or infinite coordinate.
        non_finite_dropped: usize,
    },
    /// The scan's points span no area in x and y, so the point spacing is unknown.
    #[error("the scan has no horizontal extent; give spacing in the settings")]
    NoHorizontalExtent,
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, SurfaceError>;
