//! The perception pipeline on a survey larger than memory, by tiles.
//!
//! A survey (one LAS/LAZ file or many, in order) is decoded once, a chunk
//! at a time, and passed over twice. The first pass finds its bounds and
//! count (the scale and spacing of [`crate::perceive::scale_and_spacing`]),
//! keeps every n-th point as a sample, on which the floor is found and
//! roll and pitch are estimated ([RS eq. 11]–[RS eq. 12]), and writes every
//! point as read to the working folder (12 bytes a point: decoding LAZ
//! again would cost more than reading them back), and, when tiles are
//! written, every point's LAS record (its attributes, the point format's
//! bytes a point), read back by point index for each tile written. The
//! second pass reads
//! them back, levels each point,
//! removes the floor (the ground pass-through) and files it under the tile
//! of the levelled (x, y) grid its position falls in. Then each stage of
//! the pipeline ([RS eq. 13]–[RS eq. 20]) runs tile by tile, each tile
//! with a *halo*: the other tiles' points within a width `H` of its box.
//! Every stage writes its survivors back to their tile, and a copy of those
//! within `H` of another tile to that tile's halo, so the next stage finds
//! them there.
//!
//! **Same result as the whole cloud.** A stage's result on a point depends
//! only on the points within its reach: the radius for radius removal and
//! smoothing, a voxel's diagonal for the voxel grid, the k-th neighbour's
//! distance for the statistical filter. `H` is the largest reach plus how
//! far points can have moved from their tile (a voxel centroid lies within
//! a diagonal of its first point, smoothing moves a point by at most its
//! radius). The statistical filter's reach is not known in advance: a
//! point whose k-th neighbour lies farther than the halo can vouch for
//! (an outlier near a tile edge) is searched again among the neighbouring
//! tiles' points out to that distance, which gives its exact k nearest.
//! The global mean and deviation of [RS eq. 14] are summed in the survey's
//! point order (a merge of the tiles' lists), as the whole-cloud filter
//! sums them; a voxel belongs to the tile of its first point and is
//! averaged in point order; smoothing sums neighbours in point order. So
//! every stage keeps, and computes, bit for bit what it keeps and
//! computes on the whole levelled cloud: `tests/tiles.rs` checks this
//! against [`crate::perceive::perceive_after`] with the same roll, pitch
//! and floor, with tiles much smaller than the pile so that many points lie
//! near an edge.
//!
//! **What differs from the whole cloud, by choice.** Roll, pitch and the
//! floor come from the sample (every n-th point, [`TileOptions::sample_points`]
//! of them), not from every point: the floor search's cost grows with the
//! points, and two million points fix a plane to far below the scanner's
//! noise. The surface fit ([RS eq. 21]) takes every n-th cleaned point the
//! same way. The cleaned cloud is handed on tile by tile, and a height
//! model (mean height per cell) is kept over the whole survey.
//!
//! **Memory.** The tiles running at once with their halos (their points
//! and the filters' structures, about [`BYTES_PER_POINT`] bytes a point,
//! together within [`TileOptions::memory_limit`] in [`InProcess`]), the
//! sample, the height model, and per tile a buffer of points on their way
//! to disk; a tile that would need more than [`TileOptions::memory_limit`]
//! is an error that names it. The working files live in a folder of their
//! own under [`TileOptions::work_dir`], removed when the run ends, failed
//! or not: on disk, about 12 bytes per point read until the second pass
//! ends, and a stage's points with their halo copies (20 bytes a point).
//!
//! **Anywhere.** Within a stage, tiles are independent: each is a
//! [`TileTask`] (serialisable) that [`run_tile_task`] runs wherever the
//! run's working folder can be seen, writing files no other task writes
//! (the layout of `tiles/store.rs`). [`perceive_tiled_with`] hands each stage's tasks to
//! a [`TileExecutor`] and waits for all of them before the next; the
//! statistical filter is two rounds, the mean distances and then the cut,
//! with the sums of [RS eq. 14] added in survey order by the driver
//! between them. [`perceive_tiled`] runs the tasks here ([`InProcess`]:
//! as many tiles at once as there are cores, while they fit the memory
//! limit together); the Python package's Ray executor spreads them over a
//! cluster, with the same result bit for bit.

mod store;
mod task;

use std::collections::BTreeMap;
use std::fs::{self, File};
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};
use std::time::Instant;

use autoshovel_point_cloud::filter::{
    pass_through_indices, BilateralParams, DistanceSums, PassThroughParams, RadiusOutlierParams,
    StatisticalOutlierParams, VoxelGridParams,
};
use autoshovel_point_cloud::io::{las_header, read_files_in_order, InOrder, LasHeader};
use autoshovel_point_cloud::{CloudError, Point, PointCloud};
use nalgebra::Matrix3;
use serde::Serialize;

use store::{
    dist_path, f32_at, Filing, RawSpill, Rec, RowBack, RowSpill, StageFiles, TileLayout,
    DIST_RECORD,
};
use task::{filter_err, Step};
pub use task::{run_tile_task, InProcess, TileExecutor, TileReport, TileTask};

use crate::calibrate::{level_from_sensor, rotate_point};
use crate::error::{Result, SurfaceError};
use crate::fit::{fit_surface, FitParams, SurfaceFit};
use crate::floor::{TiltEstimate, TiltParams};
use crate::frames::HeightModel;
use crate::perceive::{
    in_settings_terms, scale_and_spacing_of, FitSummary, PerceptionParams, StageRecord,
};

/// Working memory a point of a tile needs through the heaviest stage
/// (measured with `/usr/bin/time -v` on 4 M-point tiles: the point and its
/// index twice over, the k-d tree's copy, the neighbour distances, the
/// voxel keys), used to check a tile against the memory limit (bytes).
pub const BYTES_PER_POINT: u64 = 160;

/// Most tiles a survey may be cut into (every tile's list is open at once
/// when the statistical sums are merged).
pub const MAX_TILES: usize = 512;

/// Points per chunk read from the survey.
const READ_CHUNK: usize = 1 << 16;

/// Points the files ahead of the one being read may buffer (decoded by
/// other threads; 12 bytes a point).
const LOOKAHEAD: usize = 8 << 20;

/// How the survey is cut and held.
#[derive(Debug, Clone, PartialEq)]
pub struct TileOptions {
    /// Side of a square tile in the levelled (x, y) plane (m); `None`:
    /// chosen so that a tile takes about a million points (less if a
    /// quarter of the memory limit holds fewer).
    pub tile_m: Option<f64>,
    /// Most working memory a tile may take (bytes); in [`InProcess`], the
    /// tiles running at once together.
    pub memory_limit: u64,
    /// Points of the sample for the floor and the tilt, and of the fit.
    pub sample_points: usize,
    /// Cell of the survey's height model (m).
    pub model_cell_m: f64,
    /// Where the working folder is made (removed at the end).
    pub work_dir: PathBuf,
    /// Whether the tiles handed on carry the survey's attributes (its LAS
    /// records kept in the working folder beside the points, a point
    /// format's bytes a point, and read back by point index for each
    /// tile). Off where no tile is written.
    pub attributes: bool,
}

impl Default for TileOptions {
    /// Auto tiles, 2 GiB, 2 M sample points, 1 m model cells, the system's
    /// temporary folder.
    fn default() -> Self {
        Self {
            tile_m: None,
            memory_limit: 2 << 30,
            sample_points: 2_000_000,
            model_cell_m: 1.0,
            work_dir: std::env::temp_dir(),
            attributes: true,
        }
    }
}

/// The files of a survey, in order, with their headers checked to agree.
#[derive(Debug, Clone, PartialEq)]
pub struct Survey {
    /// The LAS/LAZ files.
    pub files: Vec<PathBuf>,
    /// Their headers.
    pub headers: Vec<LasHeader>,
}

impl Survey {
    /// The survey in `inputs`: LAS/LAZ files, or folders whose `.las` and
    /// `.laz` files are taken in natural order. Every file must share the
    /// first one's scale factors and coordinate system records (offsets may
    /// differ): a survey mixing them is refused, naming the file.
    pub fn open(inputs: &[PathBuf]) -> Result<Self> {
        let mut files = Vec::new();
        for input in inputs {
            if input.is_dir() {
                let found = crate::frames::frames_in(input)?;
                let las: Vec<PathBuf> = found
                    .into_iter()
                    .filter(|p| {
                        p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                            e.eq_ignore_ascii_case("las") || e.eq_ignore_ascii_case("laz")
                        })
                    })
                    .collect();
                if las.is_empty() {
                    return Err(SurfaceError::Survey {
                        path: input.clone(),
                        problem: "the folder holds no .las or .laz file".into(),
                    });
                }
                files.extend(las);
            } else {
                files.push(input.clone());
            }
        }
        if files.is_empty() {
            return Err(SurfaceError::Frames {
                dir: "the survey".into(),
                problem: "no input file given".into(),
            });
        }
        let mut headers: Vec<LasHeader> = Vec::with_capacity(files.len());
        for f in &files {
            let h = las_header(f).map_err(|e| match e {
                CloudError::Format { what, .. }
                    if what.starts_with("not a LAS or LAZ file") =>
                {
                    SurfaceError::Survey {
                        path: f.clone(),
                        problem: format!("{what}: a survey is read by tiles from LAS or LAZ files; perceive other formats whole"),
                    }
                }
                e => e.into(),
            })?;
            if let Some(first) = headers.first() {
                if h.scale != first.scale {
                    return Err(SurfaceError::Survey {
                        path: f.clone(),
                        problem: format!(
                            "scale factors {:?} differ from {:?} of {}: the files of a survey must share one scale",
                            h.scale,
                            first.scale,
                            files[0].display()
                        ),
                    });
                }
                if h.crs != first.crs {
                    return Err(SurfaceError::Survey {
                        path: f.clone(),
                        problem: format!(
                            "its coordinate system ({}) differs from that of {} ({}): the files of a survey must share one",
                            crs_words(&h.crs),
                            files[0].display(),
                            crs_words(&first.crs)
                        ),
                    });
                }
            }
            headers.push(h);
        }
        Ok(Self { files, headers })
    }

    /// The origin the survey is read relative to (m), per axis: zero where
    /// every coordinate the headers bound lies within 10 km of zero (f32
    /// keeps a millimetre there); otherwise the headers' smallest value
    /// rounded down to a kilometre, so that UTM coordinates keep their
    /// millimetres in f32.
    pub fn origin(&self) -> [f64; 3] {
        [0, 1, 2].map(|a| {
            let far = self
                .headers
                .iter()
                .any(|h| h.min[a].abs() > 1e4 || h.max[a].abs() > 1e4);
            let lo = self
                .headers
                .iter()
                .map(|h| h.min[a])
                .fold(f64::INFINITY, f64::min);
            if far && lo.is_finite() {
                (lo / 1000.0).floor() * 1000.0
            } else {
                0.0
            }
        })
    }

    /// `points` (about `origin`) as a cloud of this survey: its first
    /// file's CRS and header, no attributes.
    pub fn cloud(&self, points: Vec<Point>, origin: [f64; 3]) -> PointCloud {
        PointCloud {
            points,
            origin,
            attributes: Default::default(),
            georef: self
                .headers
                .first()
                .map(|h| h.georef.clone())
                .unwrap_or_default(),
        }
    }

    /// Points the headers claim.
    pub fn header_points(&self) -> u64 {
        self.headers.iter().map(|h| h.points).sum()
    }
}

/// A coordinate system's records in words, for messages.
fn crs_words(crs: &[(u16, Vec<u8>)]) -> String {
    if crs.is_empty() {
        return "none stated".into();
    }
    crs.iter()
        .map(|(id, data)| match id {
            2112 => format!(
                "WKT \"{}\"",
                String::from_utf8_lossy(data)
                    .trim_end_matches('\0')
                    .chars()
                    .take(60)
                    .collect::<String>()
            ),
            34735 => format!("GeoTIFF keys, {} bytes", data.len()),
            id => format!("record {id}, {} bytes", data.len()),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// One tile's share of the cleaned survey, handed on as it is done.
#[derive(Debug, Clone, PartialEq)]
pub struct TileOutput {
    /// Column and row of the tile.
    pub tile: [usize; 2],
    /// The tile's box in the levelled (x, y) plane: min x, min y, max x, max y (m).
    pub bounds: [f64; 4],
    /// The cleaned points whose first point lies in the tile (levelled
    /// frame), in survey order, about the survey's origin and with its
    /// first file's CRS and header (a survey's files share their CRS).
    pub cloud: PointCloud,
}

impl TileOutput {
    /// The file name of the tile's cleaned points, `tile-{column}-{row}.laz`
    /// (three digits each, so that names sort as the grid).
    pub fn file_name(&self) -> String {
        format!("tile-{:03}-{:03}.laz", self.tile[0], self.tile[1])
    }
}

/// What [`perceive_tiled`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct TiledPerceived {
    /// Finite points read.
    pub input_points: u64,
    /// Points dropped for a non-finite coordinate.
    pub non_finite_dropped: u64,
    /// The files' format, e.g. `"laz 1.4"` (the first file's).
    pub format: &'static str,
    /// Points of the sample the floor and tilt came from.
    pub sample_points: usize,
    /// Roll α (rad) and pitch β (rad) of [RS eq. 11].
    pub roll_rad: f64,
    /// Pitch β (rad).
    pub pitch_rad: f64,
    /// The floor found in the levelled sample.
    pub floor: TiltEstimate,
    /// Length scale.
    pub scale: f64,
    /// Point spacing (m).
    pub spacing_m: f64,
    /// Tile side (m).
    pub tile_m: f64,
    /// Tiles along x and y.
    pub grid: [usize; 2],
    /// Tiles that held points.
    pub tiles_used: usize,
    /// Halo width (m).
    pub halo_m: f64,
    /// Most points a tile held with its halo.
    pub largest_tile_points: u64,
    /// Statistical-filter points searched again past the halo.
    pub statistical_researched: u64,
    /// Each stage's count and time, as [`crate::perceive::Perceived::stages`]
    /// ("read" is both passes over the points, decoding and filing by
    /// tile; "write" hands the cleaned
    /// tiles on and fills the height model).
    pub stages: Vec<StageRecord>,
    /// Points of the cleaned survey.
    pub output_points: u64,
    /// The surface fit on every n-th cleaned point ([RS eq. 21]); `None`
    /// when the points do not determine one (see `fit_note`).
    pub fit: Option<SurfaceFit>,
    /// Why the fit is missing, or that it falls below the settings' R²
    /// threshold: a survey of many piles is not one face, so neither stops
    /// the run (the height model is the survey's surface).
    pub fit_note: Option<String>,
    /// Mean height of the cleaned points per cell.
    pub model: HeightModel,
    /// Peak resident memory of the process (bytes), where the system tells.
    pub peak_memory: Option<u64>,
    /// The origin subtracted from the files' coordinates ([`Survey::origin`]) (m).
    pub origin_m: [f64; 3],
    /// What the run could not do as asked ([`attribute_layout`]).
    pub warnings: Vec<String>,
}

impl TiledPerceived {
    /// Total time of the stages (ms).
    pub fn total_ms(&self) -> f64 {
        self.stages.iter().map(|s| s.ms).sum()
    }
}

/// The summary of `autoshovel perceive --tiles` (`summary.json`): the
/// fields of [`crate::perceive::PerceiveSummary`] (SPEC §6) and the tiles'.
#[derive(Debug, Clone, Serialize)]
pub struct TiledSummary {
    /// "perceive".
    pub job: &'static str,
    /// "tiles".
    pub mode: &'static str,
    /// The survey as given.
    pub input: String,
    /// Its files.
    pub files: Vec<String>,
    /// The format read (the first file's).
    pub format: &'static str,
    /// Finite points read.
    pub input_points: u64,
    /// Non-finite points dropped while reading.
    pub non_finite_dropped: u64,
    /// Points of the cleaned survey.
    pub output_points: u64,
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
    /// Sample points on the floor plane.
    pub floor_points: usize,
    /// Their share of the sample.
    pub floor_share: f64,
    /// Sample points more than the below margin under the floor.
    pub points_below_floor: usize,
    /// RMS distance of the floor points from the plane (m).
    pub floor_rms_m: f64,
    /// Points of the sample the floor and tilt came from.
    pub sample_points: usize,
    /// Length scale used.
    pub scale: f64,
    /// Point spacing used (m).
    pub spacing_m: f64,
    /// R² of the fit on the grid samples.
    pub r2: f64,
    /// Wall time of each stage (ms).
    pub timings_ms: BTreeMap<&'static str, f64>,
    /// Wall time of all stages (ms).
    pub total_ms: f64,
    /// Points read per second of the whole run.
    pub points_per_s: f64,
    /// Tile side (m).
    pub tile_m: f64,
    /// Tiles along x and y.
    pub grid: [usize; 2],
    /// Tiles that held points.
    pub tiles_used: usize,
    /// Halo width (m).
    pub halo_m: f64,
    /// Most points a tile held with its halo.
    pub largest_tile_points: u64,
    /// Statistical-filter points searched again past the halo.
    pub statistical_researched: u64,
    /// The origin subtracted from the files' coordinates before levelling
    /// (zero near the origin; a kilometre corner for UTM) (m): the cleaned
    /// tiles and the height model are relative to it.
    pub origin_m: [f64; 3],
    /// The memory limit of a tile (bytes).
    pub memory_limit_bytes: u64,
    /// Peak resident memory of the process (bytes) (null where unknown).
    pub peak_memory_bytes: Option<u64>,
    /// Height model cell (m) and cells along x and y.
    pub model_cell_m: f64,
    /// Cells of the height model along x and y.
    pub model_size: [usize; 2],
    /// The fit (null when the points did not determine one).
    pub fit: Option<FitSummary>,
    /// Why the fit is missing or below the R² threshold.
    pub fit_note: Option<String>,
    /// The settings used.
    pub pipeline: PerceptionParams,
    /// Always true (a failed run is an error).
    pub success: bool,
    /// What the run could not do as asked: the tiles' attributes (see
    /// [`attribute_layout`]). Also printed on stderr.
    pub warnings: Vec<String>,
}

/// The layout the tiles' attributes are carried in: the survey's LAS
/// point format when every file has the same fields and `options` asks
/// for attributes. Otherwise none, with a warning when tiles will still
/// be written in the first file's point format, whose attribute fields
/// then hold zero.
pub fn attribute_layout(
    survey: &Survey,
    options: &TileOptions,
) -> (Option<autoshovel_point_cloud::LasLayout>, Vec<String>) {
    let layouts: Vec<_> = survey
        .headers
        .iter()
        .filter_map(|h| h.georef.las.as_ref())
        .collect();
    let Some(first) = layouts.first().copied().filter(|_| options.attributes) else {
        return (None, Vec::new());
    };
    if let Some(other) = layouts.iter().find(|l| !first.same_fields(l)) {
        let warning = format!(
            "the survey's files differ in point format ({} and {}): the tiles keep coordinates, CRS and point format {} \
             but not the attributes, whose fields are written as zero; convert the files to one point format to keep them",
            first.point_format(),
            other.point_format(),
            first.point_format()
        );
        return (None, vec![warning]);
    }
    (Some(first.clone()), Vec::new())
}

impl TiledSummary {
    /// The summary of `got`, a run on `survey` (given as `input`).
    pub fn new(
        input: &str,
        survey: &Survey,
        params: &PerceptionParams,
        options: &TileOptions,
        got: &TiledPerceived,
    ) -> Self {
        let total_ms = got.total_ms();
        Self {
            job: "perceive",
            mode: "tiles",
            input: input.into(),
            files: survey
                .files
                .iter()
                .map(|f| f.display().to_string())
                .collect(),
            format: got.format,
            input_points: got.input_points,
            non_finite_dropped: got.non_finite_dropped,
            output_points: got.output_points,
            stage_points: got.stages.iter().map(|s| (s.stage, s.points)).collect(),
            stages: got.stages.clone(),
            roll_deg: got.roll_rad.to_degrees(),
            pitch_deg: got.pitch_rad.to_degrees(),
            floor_height_m: got.floor.floor_height_m,
            floor_points: got.floor.inliers,
            floor_share: got.floor.inliers as f64 / got.floor.candidates.max(1) as f64,
            points_below_floor: got.floor.below,
            floor_rms_m: got.floor.rms_m,
            sample_points: got.sample_points,
            scale: got.scale,
            spacing_m: got.spacing_m,
            r2: got.fit.as_ref().map_or(f64::NAN, |f| f.r2),
            timings_ms: got.stages.iter().map(|s| (s.stage, s.ms)).collect(),
            total_ms,
            points_per_s: got.input_points as f64 / (total_ms / 1e3).max(1e-9),
            tile_m: got.tile_m,
            grid: got.grid,
            tiles_used: got.tiles_used,
            halo_m: got.halo_m,
            largest_tile_points: got.largest_tile_points,
            statistical_researched: got.statistical_researched,
            origin_m: got.origin_m,
            memory_limit_bytes: options.memory_limit,
            peak_memory_bytes: got.peak_memory,
            model_cell_m: got.model.cell_m,
            model_size: got.model.size,
            fit: got.fit.as_ref().map(FitSummary::of),
            fit_note: got.fit_note.clone(),
            pipeline: params.clone(),
            success: true,
            warnings: got.warnings.clone(),
        }
    }
}

/// The working folder, removed when dropped.
struct WorkDir(PathBuf);

impl Drop for WorkDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

/// The process's peak resident memory (bytes) (Linux: VmHWM).
pub fn peak_memory() -> Option<u64> {
    let status = fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The pipeline of [`crate::perceive`] on a survey by tiles (module docs),
/// each stage's tiles run in this process ([`InProcess`]).
/// `progress(what, done, total)` reports each pass; `on_tile` receives each
/// tile's cleaned points as they are done (its error stops the run).
pub fn perceive_tiled(
    survey: &Survey,
    params: &PerceptionParams,
    options: &TileOptions,
    progress: &mut dyn FnMut(&str, u64, u64),
    on_tile: &mut dyn FnMut(&TileOutput) -> Result<()>,
) -> Result<TiledPerceived> {
    perceive_tiled_with(survey, params, options, &mut InProcess, progress, on_tile)
}

/// Refuses a model cell or tile side that is not a finite length > 0.
fn check_options(options: &TileOptions) -> Result<()> {
    let lengths = [
        ("model cell", Some(options.model_cell_m)),
        ("tile size", options.tile_m),
    ];
    for (name, value) in lengths {
        if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(SurfaceError::BadParameter {
                name,
                value: v,
                expected: "a finite length > 0 [m]",
            });
        }
    }
    Ok(())
}

/// Refuses, before any work, what the survey path cannot do rightly: a
/// survey in degrees (as `perceive` does), one in another length than the
/// metre (the path does not convert; settings are metres), and `[range]`
/// (the tiles are read as coordinates alone).
fn refuse_what_tiles_cannot_do(survey: &Survey, p: &PerceptionParams) -> Result<()> {
    // Degrees are refused as by `perceive`; a length other than the metre
    // too, since the survey path does not convert (settings are metres).
    if let (Some(first), Some(h)) = (survey.files.first(), survey.headers.first()) {
        let crs = &h.georef.crs;
        if crs.is_geographic() {
            return Err(SurfaceError::Survey {
                path: first.clone(),
                problem: SurfaceError::Geographic {
                    crs: crs.to_string(),
                }
                .to_string(),
            });
        }
        if [crs.unit, crs.z_unit()]
            .iter()
            .any(|u| u.metres().is_some_and(|m| m != 1.0))
        {
            return Err(SurfaceError::Survey {
                path: first.clone(),
                problem: format!(
                    "its CRS is {crs}: --tiles works in metres and does not convert; perceive it \
                     without --tiles (which converts to metres), or reproject it to a metre CRS first"
                ),
            });
        }
    }
    // The tiles are read as coordinates alone, so no dimension to select
    // on: the range is refused, never ignored.
    if let Some(limits) = &p.range.limits {
        return Err(SurfaceError::NotWithTiles {
            setting: format!("[range] limits = {limits:?}"),
            instead:
                "select first with `autoshovel filter --input IN --output OUT --range LIMITS` \
                      for each file, or perceive without --tiles",
        });
    }
    Ok(())
}

/// [`perceive_tiled`] with each stage's tiles run by `executor` (module
/// docs): the survey is read, and the cleaned tiles handed on, here; the
/// stages' tasks run wherever `executor` sends them, which must see
/// [`TileOptions::work_dir`]. The result is the same whichever runs them.
pub fn perceive_tiled_with(
    survey: &Survey,
    params: &PerceptionParams,
    options: &TileOptions,
    executor: &mut dyn TileExecutor,
    progress: &mut dyn FnMut(&str, u64, u64),
    on_tile: &mut dyn FnMut(&TileOutput) -> Result<()>,
) -> Result<TiledPerceived> {
    let p = params;
    check_options(options)?;
    refuse_what_tiles_cannot_do(survey, p)?;
    let mut stages = Vec::new();
    // Pass 1: bounds, count, sample.
    let t0 = Instant::now();
    let claimed = survey.header_points().max(1);
    let stride = claimed.div_ceil(options.sample_points.max(1) as u64).max(1);
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    let mut n = 0u64;
    let mut sample: Vec<Point> = Vec::new();
    let threads = rayon::current_num_threads();
    let origin = survey.origin();
    let work = tempdir_in(&options.work_dir)?;
    // The points as read, for the second pass (decoding a LAZ survey
    // again costs more than reading them back).
    let mut raw = RawSpill::create(work.0.join("read"))?;
    // The survey's records, for the attributes of the tiles written.
    let (layout, warnings) = attribute_layout(survey, options);
    let mut rows = layout
        .as_ref()
        .map(|l| RowSpill::create(work.0.join("rows"), l.record_len()))
        .transpose()?;
    let mut spill_failed: Option<SurfaceError> = None;
    let reports = read_files_in_order(
        &survey.files,
        origin,
        InOrder {
            chunk: READ_CHUNK,
            threads,
            lookahead: LOOKAHEAD,
            rows: rows.is_some(),
        },
        &mut |done, _| progress("reading (1 of 2)", done, claimed),
        &mut |f, chunk: &[Point], chunk_rows: &[u8]| {
            for q in chunk {
                for a in 0..3 {
                    lo[a] = lo[a].min(q[a]);
                    hi[a] = hi[a].max(q[a]);
                }
                if n.is_multiple_of(stride) {
                    sample.push(*q);
                }
                n += 1;
            }
            let put = raw.put(chunk).and_then(|()| match &mut rows {
                Some(r) => r.put(chunk_rows),
                None => Ok(()),
            });
            if let Err(e) = put {
                spill_failed = Some(e);
                return Err(CloudError::Format {
                    path: survey.files[f].clone(),
                    what: "stopped: the working copy of the points failed".into(),
                });
            }
            Ok(())
        },
    );
    if let Some(e) = spill_failed.take() {
        return Err(e);
    }
    let reports = reports?;
    let mut raw = raw.finish()?;
    let mut rows = rows.map(|r| r.finish(n)).transpose()?;
    let non_finite: u64 = reports.iter().map(|r| r.non_finite_dropped as u64).sum();
    let format = reports.first().map_or("", |r| r.format);
    if n == 0 {
        return Err(SurfaceError::NoFinitePoints {
            non_finite_dropped: non_finite as usize,
        });
    }
    let (scale, spacing) = scale_and_spacing_of(lo, hi, n, p)?;
    p.check_work(1.0, usize::try_from(n).unwrap_or(usize::MAX))?;
    // Level [RS eq. 11]–[RS eq. 12], from the sample.
    let mut tilt_params = TiltParams::for_scale(scale);
    tilt_params.min_floor_share = p.level.min_floor_share;
    // The sample with the survey's CRS: a survey in a projected CRS is
    // level (ground.rs), as `perceive` of one file decides.
    let sample = survey.cloud(sample, origin);
    // The same level and ground decisions as a single scan (ground.rs).
    let crate::ground::Levelled {
        roll,
        pitch,
        floor,
        used,
        cloud: levelled_sample,
    } = crate::ground::level_and_ground(&sample, &p.level_asked(scale), &tilt_params)?;
    let sample_points = sample.len();
    drop((sample, levelled_sample));
    stages.push(StageRecord {
        stage: "read",
        points: n as usize,
        ms: elapsed_ms(t0),
    });
    // The tile grid over the levelled box of the survey's bounds.
    let r = level_from_sensor(roll, pitch);
    let grid = grid_over(&r, lo, hi, n, options)?;
    // The halo: the largest reach of any stage, plus how far points may
    // have moved from their tile by then.
    let leaf = p.voxel.leaf_spacings * spacing;
    let diagonal = if p.voxel.enabled {
        leaf * 3f64.sqrt()
    } else {
        0.0
    };
    let smooth_r = p.smooth.radius_spacings * spacing;
    let stat_reach = 2.0 * spacing * (p.statistical.mean_k as f64).sqrt();
    let mut halo: f64 = 0.0;
    if p.radius.enabled {
        halo = halo.max(p.radius.radius_spacings * spacing);
    }
    if p.statistical.enabled {
        halo = halo.max(stat_reach);
    }
    halo = halo.max(2.0 * diagonal);
    if p.smooth.enabled {
        halo = halo.max(diagonal + p.smooth.iterations as f64 * smooth_r + smooth_r);
    }
    // Rounding of f32 positions far from the origin.
    let halo = halo * (1.0 + 1e-6) + 1e-6 * (grid.origin[0].abs() + grid.origin[1].abs());
    // Pass 2: level, remove the floor, file by tile.
    let t1 = Instant::now();
    let ground = PassThroughParams::ground_removal(used.cut_at.unwrap_or(f64::NEG_INFINITY));
    let mut lists = Filing::new(StageFiles::create(&work.0, 0, grid.tiles())?);
    let mut id = 0u64;
    let mut by_tile: Vec<Vec<Rec>> = vec![Vec::new(); grid.tiles()];
    let mut level_ms = 0.0;
    let mut chunk = Vec::with_capacity(READ_CHUNK);
    while raw.next_chunk(&mut chunk, READ_CHUNK)? {
        progress("reading (2 of 2)", id, n);
        let t = Instant::now();
        let levelled = PointCloud::new(chunk.iter().map(|q| rotate_point(&r, q)).collect());
        level_ms += elapsed_ms(t);
        // A chunk wholly at or below the floor keeps nothing (an error
        // only if the whole survey does).
        let kept = match pass_through_indices(&levelled, &ground) {
            Ok(k) => k,
            Err(CloudError::Emptied { .. }) => Vec::new(),
            Err(e) => return Err(e.into()),
        };
        for i in kept {
            let q = levelled.points[i];
            by_tile[grid.tile_of(&q)].push(Rec {
                id: id + i as u64,
                p: q,
            });
        }
        id += chunk.len() as u64;
        for (t, pending) in by_tile.iter_mut().enumerate() {
            if !pending.is_empty() {
                let recs = std::mem::take(pending);
                lists.put(&grid, t, &recs, halo)?;
            }
        }
    }
    progress("reading (2 of 2)", n, n);
    if id != n {
        return Err(SurfaceError::TileFile {
            path: raw.path.clone(),
            problem: format!("holds {id} points where {n} were written"),
        });
    }
    raw.remove();
    let mut lists = lists.finish()?;
    let read2_ms = elapsed_ms(t1);

    stages[0].ms += read2_ms - level_ms;
    stages.push(StageRecord {
        stage: "level",
        points: n as usize,
        ms: level_ms,
    });
    let ground_points = lists.total();
    let emptied =
        |stage: &'static str, filter: &'static str, input: u64, hint: &str| SurfaceError::Filter {
            stage,
            source: in_settings_terms(
                stage,
                CloudError::Emptied {
                    filter,
                    input: input as usize,
                    hint: hint.into(),
                },
                p,
                spacing,
                scale,
            ),
        };
    if ground_points == 0 {
        return Err(emptied(
            "ground",
            "pass-through",
            n,
            "every point lies at or below the floor cut",
        ));
    }
    stages.push(StageRecord {
        stage: "ground",
        points: ground_points as usize,
        ms: 0.0,
    });
    let mut run = Driver {
        grid,
        halo,
        limit: options.memory_limit,
        run: work.0.clone(),
        next: 1,
        largest: 0,
        researched: 0,
        executor,
    };
    // The stages, in the paper's order.
    if p.radius.enabled {
        let t = Instant::now();
        let params = RadiusOutlierParams {
            radius_m: p.radius.radius_spacings * spacing,
            min_neighbors: p.radius.min_neighbors,
        };
        let before = lists.total();
        lists = run.pass(lists, Step::Radius(params), progress)?;
        if lists.total() == 0 {
            return Err(emptied(
                "radius",
                "radius outlier removal",
                before,
                "lower min_neighbors or raise radius_m",
            ));
        }
        stages.push(record("radius", &lists, t));
    }
    if p.statistical.enabled {
        let t = Instant::now();
        let params = StatisticalOutlierParams {
            mean_k: p.statistical.mean_k,
            std_mul: p.statistical.std_mul,
            sides: p.statistical.sides,
        };
        lists = run.statistical(lists, params, progress)?;
        stages.push(record("statistical", &lists, t));
    }
    if p.voxel.enabled {
        let t = Instant::now();
        lists = run.pass(lists, Step::Voxel(VoxelGridParams::cube(leaf)), progress)?;
        stages.push(record("voxel", &lists, t));
    }
    if p.smooth.enabled {
        let t = Instant::now();
        let params = BilateralParams {
            radius_m: smooth_r,
            sigma_d_m: p.smooth.sigma_d_spacings * spacing,
            sigma_n_m: p.smooth.sigma_n_m * scale,
            iterations: 1,
        };
        for _ in 0..p.smooth.iterations {
            lists = run.pass(lists, Step::Smooth(params), progress)?;
        }
        stages.push(record("smooth", &lists, t));
    }
    // The cleaned survey: handed on, into the model, sampled for the fit.
    let t = Instant::now();
    let output_points = lists.total();
    let fit_stride = output_points
        .div_ceil(options.sample_points.max(1) as u64)
        .max(1);
    let gb = [0, grid.tiles() - 1].map(|t| grid.bounds(t));
    let mut model = HeightModel::over_box(
        [gb[0][0], gb[0][1]],
        [gb[1][2], gb[1][3]],
        options.model_cell_m,
    );
    let mut sum = vec![0.0_f64; model.z.len()];
    let mut count = vec![0_u32; model.z.len()];
    let mut fit_points = Vec::new();
    let mut used = 0;
    for tile in 0..grid.tiles() {
        progress("writing", tile as u64, grid.tiles() as u64);
        let recs = lists.read_own(tile)?;
        if recs.is_empty() {
            continue;
        }
        used += 1;
        for r in &recs {
            if let Some(i) = model.cell_of(f64::from(r.p[0]), f64::from(r.p[1])) {
                sum[i] += f64::from(r.p[2]);
                count[i] += 1;
            }
            if r.id.is_multiple_of(fit_stride) {
                fit_points.push(r.p);
            }
        }
        on_tile(&TileOutput {
            tile: [tile % grid.size[0], tile / grid.size[0]],
            bounds: grid.bounds(tile),
            // About the survey's origin, with its first file's CRS and
            // header: a tile written is in the survey's coordinates.
            cloud: tile_cloud(survey, &recs, origin, layout.as_ref().zip(rows.as_mut()))?,
        })?;
    }
    progress("writing", grid.tiles() as u64, grid.tiles() as u64);
    lists.remove();
    if let Some(r) = rows {
        r.remove();
    }
    for i in 0..model.z.len() {
        if count[i] > 0 {
            model.z[i] = sum[i] / f64::from(count[i]);
            model.seen[i] = 1;
        }
    }
    // Fit [RS eq. 21], on every n-th cleaned point.
    stages.push(StageRecord {
        stage: "write",
        points: output_points as usize,
        ms: elapsed_ms(t),
    });
    let t = Instant::now();
    // One survey may hold many piles: the fit is reported, never enforced.
    let fit_params = FitParams {
        max_degree: p.fit.max_degree,
        r2_threshold: None,
        ..FitParams::default()
    };
    let (fit, fit_note) = match fit_surface(&PointCloud::new(fit_points), &fit_params) {
        Ok(fit) => {
            let note = (p.fit.r2_threshold > 0.0 && fit.r2 <= p.fit.r2_threshold).then(|| {
                format!(
                    "R² = {:.4} <= the threshold {}: one polynomial does not describe this survey (many piles?); its height model does",
                    fit.r2, p.fit.r2_threshold
                )
            });
            (Some(fit), note)
        }
        Err(e) => (None, Some(format!("no surface fit: {e}"))),
    };
    stages.push(StageRecord {
        stage: "fit",
        points: fit.as_ref().map_or(0, |f| f.samples.len()),
        ms: elapsed_ms(t),
    });
    Ok(TiledPerceived {
        input_points: n,
        non_finite_dropped: non_finite,
        format,
        sample_points,
        roll_rad: roll,
        pitch_rad: pitch,
        floor,
        scale,
        spacing_m: spacing,
        tile_m: grid.side,
        grid: grid.size,
        tiles_used: used,
        halo_m: halo,
        largest_tile_points: run.largest,
        statistical_researched: run.researched,
        stages,
        output_points,
        fit,
        fit_note,
        model,
        peak_memory: peak_memory(),
        origin_m: origin,
        warnings,
    })
}

/// A tile's cleaned points as a cloud of the survey (about `origin`, its
/// first file's CRS and header), with each point's attributes from the
/// survey's records when they are carried: a point keeps its own; a
/// voxel's centroid, filed under its first point, takes that point's
/// (PDAL's `filters.voxeldownsize` keeps the first point too).
fn tile_cloud(
    survey: &Survey,
    recs: &[Rec],
    origin: [f64; 3],
    rows: Option<(&autoshovel_point_cloud::LasLayout, &mut RowBack)>,
) -> Result<PointCloud> {
    let mut cloud = survey.cloud(recs.iter().map(|r| r.p).collect(), origin);
    if let Some((layout, back)) = rows {
        let bytes = back.rows(recs.iter().map(|r| r.id))?;
        cloud.attributes =
            layout
                .attributes_of_rows(&bytes)
                .map_err(|problem| SurfaceError::TileFile {
                    path: back.path.clone(),
                    problem,
                })?;
    }
    Ok(cloud)
}

fn record(stage: &'static str, lists: &StageFiles, t: Instant) -> StageRecord {
    StageRecord {
        stage,
        points: lists.total() as usize,
        ms: elapsed_ms(t),
    }
}

fn elapsed_ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// The tiles' spill folder in `dir`: made by one `mkdir` under a random
/// name (never through an existing entry), removed on drop.
fn tempdir_in(dir: &Path) -> Result<WorkDir> {
    let made = tempfile::Builder::new()
        .prefix(".autoshovel-tiles-")
        .rand_bytes(12)
        .tempdir_in(dir)
        .map_err(|source| SurfaceError::Spill {
            path: dir.to_path_buf(),
            source: autoshovel_core::os_error(source),
        })?;
    Ok(WorkDir(made.keep()))
}

/// The grid of tiles over the levelled box of the raw bounds `lo`–`hi`.
fn grid_over(
    r: &Matrix3<f64>,
    lo: [f32; 3],
    hi: [f32; 3],
    n: u64,
    options: &TileOptions,
) -> Result<TileLayout> {
    let mut blo = [f64::INFINITY; 2];
    let mut bhi = [f64::NEG_INFINITY; 2];
    for c in 0..8 {
        let corner = [0, 1, 2].map(|a| if c & (1 << a) == 0 { lo[a] } else { hi[a] });
        let q = rotate_point(r, &corner);
        for a in 0..2 {
            blo[a] = blo[a].min(f64::from(q[a]));
            bhi[a] = bhi[a].max(f64::from(q[a]));
        }
    }
    let extent = [0, 1].map(|a| (bhi[a] - blo[a]).max(1e-3));
    let side = match options.tile_m {
        Some(t) => t,
        None => {
            // A tile and its halo in a quarter of the limit, and about a
            // million points at most: the filters' k-d trees stay close
            // to the cache, and the halo is still thin beside the tile.
            let per_tile = (options.memory_limit / BYTES_PER_POINT / 4).clamp(1 << 16, 1 << 20);
            let density = n as f64 / (extent[0] * extent[1]);
            let mut side = (per_tile as f64 / density).sqrt();
            while ((extent[0] / side).ceil() * (extent[1] / side).ceil()) as usize > MAX_TILES {
                side *= 1.25;
            }
            side
        }
    };
    let size = [0, 1].map(|a| ((extent[a] / side).ceil() as usize).max(1));
    let tiles = size[0].saturating_mul(size[1]);
    if tiles > MAX_TILES {
        return Err(SurfaceError::BadParameter {
            name: "tile size",
            value: side,
            expected: "a tile large enough that the survey makes at most 512 tiles",
        });
    }
    // Centre the grid on the box.
    let origin = [0, 1].map(|a| blo[a] - (size[a] as f64 * side - extent[a]) / 2.0);
    Ok(TileLayout { origin, side, size })
}

/// The stages of one run, each a round of tasks handed to the executor.
struct Driver<'a> {
    grid: TileLayout,
    halo: f64,
    limit: u64,
    run: PathBuf,
    next: usize,
    largest: u64,
    researched: u64,
    executor: &'a mut dyn TileExecutor,
}

impl Driver<'_> {
    /// A task of `step` for every tile of `input` that holds points.
    fn tasks(&self, input: &StageFiles, output: &Path, step: &Step) -> Vec<TileTask> {
        (0..self.grid.tiles())
            .filter(|&t| input.own[t] > 0)
            .map(|t| TileTask {
                tile: t,
                step: step.clone(),
                input: input.dir.clone(),
                output: output.to_path_buf(),
                grid: self.grid,
                halo_m: self.halo,
                memory_limit: self.limit,
                own: input.own.clone(),
                halo: input.halo[t].clone(),
            })
            .collect()
    }

    /// Runs `tasks` and checks that their reports answer them one for one
    /// (sorted by tile).
    fn execute(
        &mut self,
        stage: &'static str,
        tasks: Vec<TileTask>,
        progress: &mut dyn FnMut(&str, u64, u64),
    ) -> Result<Vec<TileReport>> {
        let asked: Vec<usize> = tasks.iter().map(|t| t.tile).collect();
        let mut reports = self.executor.run(stage, tasks, progress)?;
        reports.sort_by_key(|r| r.tile);
        let answered: Vec<usize> = reports.iter().map(|r| r.tile).collect();
        let bad = |problem: String| SurfaceError::TileExecutor {
            stage: stage.into(),
            problem,
        };
        if answered != asked {
            let missing = asked.iter().filter(|t| !answered.contains(t)).count();
            return Err(bad(format!(
                "{} reports for {} tasks ({missing} tile(s) unanswered, the rest doubled or unknown)",
                answered.len(),
                asked.len()
            )));
        }
        for r in &reports {
            if let Some(&(u, _)) = r.halo.iter().find(|h| h.0 >= self.grid.tiles()) {
                return Err(bad(format!(
                    "tile {} reports a halo piece for tile {u}, outside the grid of {}",
                    r.tile,
                    self.grid.tiles()
                )));
            }
            self.largest = self.largest.max(r.loaded);
            self.researched += r.researched;
        }
        Ok(reports)
    }

    /// One stage: `step` on every tile of `input`, filed as the next stage.
    fn pass(
        &mut self,
        input: StageFiles,
        step: Step,
        progress: &mut dyn FnMut(&str, u64, u64),
    ) -> Result<StageFiles> {
        let mut output = StageFiles::create(&self.run, self.next, self.grid.tiles())?;
        self.next += 1;
        let tasks = self.tasks(&input, &output.dir, &step);
        for r in self.execute(step.stage(), tasks, progress)? {
            output.own[r.tile] = r.kept;
            for (u, n) in r.halo {
                output.halo[u].push((Some(r.tile), n));
            }
        }
        input.remove();
        Ok(output)
    }

    /// The statistical filter [RS eq. 14]–[RS eq. 16]: every tile's d̄_i
    /// (searched again past the halo where a point's k-th neighbour lies
    /// beyond what the halo vouches for), the global sums in survey order
    /// here, then the cut on every tile.
    fn statistical(
        &mut self,
        input: StageFiles,
        params: StatisticalOutlierParams,
        progress: &mut dyn FnMut(&str, u64, u64),
    ) -> Result<StageFiles> {
        let k = params.mean_k;
        let total = input.total();
        if k as u64 >= total {
            return Err(filter_err(
                "statistical",
                CloudError::BadParameter {
                    filter: "statistical outlier removal",
                    what: format!(
                        "mean_k = {k} needs at least {} finite points, the cloud has {total}",
                        k + 1
                    ),
                },
            ));
        }
        let tasks = self.tasks(&input, &input.dir, &Step::Distances { mean_k: k });
        for r in self.execute("statistical", tasks, progress)? {
            if r.kept != input.own[r.tile] {
                return Err(SurfaceError::TileExecutor {
                    stage: "statistical".into(),
                    problem: format!(
                        "tile {} reports {} mean distances for its {} points",
                        r.tile, r.kept, input.own[r.tile]
                    ),
                });
            }
        }
        let sums = distance_sums(&input)?;
        let output = self.pass(input, Step::Cut { sums, params }, progress)?;
        if output.total() == 0 {
            return Err(filter_err(
                "statistical",
                CloudError::Emptied {
                    filter: "statistical outlier removal",
                    input: total as usize,
                    hint: "raise std_mul".into(),
                },
            ));
        }
        Ok(output)
    }
}

/// [RS eq. 14]: the sums of every tile's d̄_i in survey order, merging the
/// tiles' `dist-{t}` files (each in survey order) by point index.
fn distance_sums(stage: &StageFiles) -> Result<DistanceSums> {
    let mut sums = DistanceSums::default();
    // Each tile's file and its next (id, d̄_i).
    type Head = (BufReader<File>, Option<(u64, f32)>, PathBuf);
    let mut heads: Vec<Head> = Vec::new();
    for (t, &n) in stage.own.iter().enumerate() {
        if n == 0 {
            continue;
        }
        let path = dist_path(&stage.dir, t);
        let spill = |source| SurfaceError::Spill {
            path: path.clone(),
            source,
        };
        let f = File::open(&path).map_err(spill)?;
        let len = f.metadata().map_err(spill)?.len();
        if len != n * DIST_RECORD as u64 {
            return Err(SurfaceError::TileFile {
                path,
                problem: format!("holds {len} bytes where {n} mean distances were written"),
            });
        }
        let mut r = BufReader::with_capacity(1 << 16, f);
        let first = next_dist(&mut r, &path)?;
        heads.push((r, first, path));
    }
    let mut queue: std::collections::BinaryHeap<std::cmp::Reverse<(u64, usize)>> = heads
        .iter()
        .enumerate()
        .filter_map(|(i, h)| h.1.map(|(id, _)| std::cmp::Reverse((id, i))))
        .collect();
    while let Some(std::cmp::Reverse((_, i))) = queue.pop() {
        let (_, d) = heads[i].1.expect("queued heads hold a value");
        sums.add(d);
        let (r, next, path) = &mut heads[i];
        *next = next_dist(r, path)?;
        if let Some((id, _)) = *next {
            queue.push(std::cmp::Reverse((id, i)));
        }
    }
    Ok(sums)
}

/// The next (id, d̄_i) of a tile's list.
fn next_dist(r: &mut BufReader<File>, path: &Path) -> Result<Option<(u64, f32)>> {
    let mut b = [0u8; 12];
    match r.read_exact(&mut b) {
        Ok(()) => Ok(Some((
            u64::from_le_bytes(b[..8].try_into().expect("8 bytes")),
            f32_at(&b, 8),
        ))),
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => Ok(None),
        Err(source) => Err(SurfaceError::Spill {
            path: path.to_path_buf(),
            source,
        }),
    }
}
