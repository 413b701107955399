//! The perception pipeline on a survey larger than memory, by tiles.
//!
//! A survey (one LAS/LAZ file or many, in order) is read twice, a chunk at
//! a time. The first pass finds its bounds and count (the scale and
//! spacing of [`crate::perceive::scale_and_spacing`]) and keeps every n-th
//! point as a sample, on which the floor is found and roll and pitch are
//! estimated ([RS eq. 11]–[RS eq. 12]). The second pass levels each point,
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
//! **Memory.** One tile and its halo at a time (their points and the
//! filters' structures, about [`BYTES_PER_POINT`] bytes a point), the
//! sample, the height model, and per tile a buffer of points on their way
//! to disk; a tile that would need more than [`TileOptions::memory_limit`]
//! is an error that names it. The working files live in a folder of their
//! own under [`TileOptions::work_dir`], removed when the run ends, failed
//! or not. Tiles are independent units of work within a stage: the same
//! loop could hand them to other machines.

use std::collections::BTreeMap;
use std::fs::{self, File, OpenOptions};
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use autoshovel_cloud::filter::{
    bilateral_normal_smoothing, mean_distances_and_reach, mean_distances_and_reach_at,
    pass_through_indices, radius_outlier_removal_indices, voxel_grid, BilateralParams,
    DistanceSums, PassThroughParams, RadiusOutlierParams, StatisticalOutlierParams, VoxelCells,
    VoxelGridParams,
};
use autoshovel_cloud::io::{las_header, read_files_in_order, LasHeader};
use autoshovel_cloud::{CloudError, Point, PointCloud};
use autoshovel_core::config;
use nalgebra::Matrix3;
use serde::Serialize;

use crate::calibrate::{level, level_from_sensor, rotate_point};
use crate::error::{Result, SurfaceError};
use crate::fit::{fit_surface, FitParams, SurfaceFit};
use crate::floor::{estimate_tilt, TiltEstimate, TiltParams};
use crate::frames::HeightModel;
use crate::perceive::{
    in_settings_terms, scale_and_spacing_of, FitSummary, LevelMode, PerceptionParams, StageRecord,
};

/// Working memory a point of a tile needs through the heaviest stage
/// (measured with `/usr/bin/time -v` on 4 M-point tiles: the point and its
/// index twice over, the k-d tree's copy, the neighbour distances, the
/// voxel keys), used to check a tile against the memory limit [bytes].
pub const BYTES_PER_POINT: u64 = 160;

/// Most tiles a survey may be cut into (every tile's list is open at once
/// when the statistical sums are merged).
pub const MAX_TILES: usize = 512;

/// Bytes of a point on disk: its index (u64) and x, y, z (f32), little-endian.
const RECORD: usize = 20;

/// Points a tile buffers before appending them to its file.
const FLUSH_POINTS: usize = 1 << 14;

/// Points per chunk read from the survey.
const READ_CHUNK: usize = 1 << 16;

/// Points the files ahead of the one being read may buffer (decoded by
/// other threads; 12 bytes a point).
const LOOKAHEAD: usize = 8 << 20;

/// How the survey is cut and held.
#[derive(Debug, Clone, PartialEq)]
pub struct TileOptions {
    /// Side of a square tile in the levelled (x, y) plane [m]; `None`:
    /// chosen so that a tile takes about a million points (less if a
    /// quarter of the memory limit holds fewer).
    pub tile_m: Option<f64>,
    /// Most working memory a tile may take [bytes].
    pub memory_limit: u64,
    /// Points of the sample for the floor and the tilt, and of the fit.
    pub sample_points: usize,
    /// Cell of the survey's height model [m].
    pub model_cell_m: f64,
    /// Where the working folder is made (removed at the end).
    pub work_dir: PathBuf,
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

    /// The origin the survey is read relative to [m], per axis: zero where
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
    /// The tile's box in the levelled (x, y) plane: min x, min y, max x, max y [m].
    pub bounds: [f64; 4],
    /// The cleaned points whose first point lies in the tile (levelled frame), in survey order.
    pub cloud: PointCloud,
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
    /// Roll α [rad] and pitch β [rad] of [RS eq. 11].
    pub roll_rad: f64,
    /// Pitch β [rad].
    pub pitch_rad: f64,
    /// The floor found in the levelled sample.
    pub floor: TiltEstimate,
    /// Length scale.
    pub scale: f64,
    /// Point spacing [m].
    pub spacing_m: f64,
    /// Tile side [m].
    pub tile_m: f64,
    /// Tiles along x and y.
    pub grid: [usize; 2],
    /// Tiles that held points.
    pub tiles_used: usize,
    /// Halo width [m].
    pub halo_m: f64,
    /// Most points a tile held with its halo.
    pub largest_tile_points: u64,
    /// Statistical-filter points searched again past the halo.
    pub statistical_researched: u64,
    /// Each stage's count and time, as [`crate::perceive::Perceived::stages`]
    /// ("read" is both passes over the files; "write" hands the cleaned
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
    /// Peak resident memory of the process [bytes], where the system tells.
    pub peak_memory: Option<u64>,
    /// The origin subtracted from the files' coordinates ([`Survey::origin`]) [m].
    pub origin_m: [f64; 3],
}

impl TiledPerceived {
    /// Total time of the stages [ms].
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
    /// Roll α used to level [deg].
    pub roll_deg: f64,
    /// Pitch β used to level [deg].
    pub pitch_deg: f64,
    /// Floor height, levelled frame [m].
    pub floor_height_m: f64,
    /// Sample points on the floor plane.
    pub floor_points: usize,
    /// Their share of the sample.
    pub floor_share: f64,
    /// Sample points more than the below margin under the floor.
    pub points_below_floor: usize,
    /// RMS distance of the floor points from the plane [m].
    pub floor_rms_m: f64,
    /// Points of the sample the floor and tilt came from.
    pub sample_points: usize,
    /// Length scale used.
    pub scale: f64,
    /// Point spacing used [m].
    pub spacing_m: f64,
    /// R² of the fit on the grid samples.
    pub r2: f64,
    /// Wall time of each stage [ms].
    pub timings_ms: BTreeMap<&'static str, f64>,
    /// Wall time of all stages [ms].
    pub total_ms: f64,
    /// Points read per second of the whole run.
    pub points_per_s: f64,
    /// Tile side [m].
    pub tile_m: f64,
    /// Tiles along x and y.
    pub grid: [usize; 2],
    /// Tiles that held points.
    pub tiles_used: usize,
    /// Halo width [m].
    pub halo_m: f64,
    /// Most points a tile held with its halo.
    pub largest_tile_points: u64,
    /// Statistical-filter points searched again past the halo.
    pub statistical_researched: u64,
    /// The origin subtracted from the files' coordinates before levelling
    /// (zero near the origin; a kilometre corner for UTM) [m]: the cleaned
    /// tiles and the height model are relative to it.
    pub origin_m: [f64; 3],
    /// The memory limit of a tile [bytes].
    pub memory_limit_bytes: u64,
    /// Peak resident memory of the process [bytes] (null where unknown).
    pub peak_memory_bytes: Option<u64>,
    /// Height model cell [m] and cells along x and y.
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
        }
    }
}

/// A point on its way: its index in the survey and its position.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rec {
    id: u64,
    p: Point,
}

/// The working folder, removed when dropped.
struct WorkDir(PathBuf);

impl Drop for WorkDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

/// The tile grid in the levelled (x, y) plane.
#[derive(Debug, Clone, Copy)]
struct Grid {
    origin: [f64; 2],
    side: f64,
    size: [usize; 2],
}

impl Grid {
    fn tiles(&self) -> usize {
        self.size[0] * self.size[1]
    }

    /// The tile of (x, y) (clamped to the grid).
    fn tile_of(&self, p: &Point) -> usize {
        let i = |a: usize| {
            (((f64::from(p[a]) - self.origin[a]) / self.side)
                .floor()
                .max(0.0) as usize)
                .min(self.size[a] - 1)
        };
        i(1) * self.size[0] + i(0)
    }

    /// The box of tile `t`: min x, min y, max x, max y.
    fn bounds(&self, t: usize) -> [f64; 4] {
        let (ix, iy) = (t % self.size[0], t / self.size[0]);
        let x0 = self.origin[0] + ix as f64 * self.side;
        let y0 = self.origin[1] + iy as f64 * self.side;
        [x0, y0, x0 + self.side, y0 + self.side]
    }

    /// The (x, y) distance from `p` to tile `t`'s box (0 inside).
    fn gap(&self, t: usize, p: &Point) -> f64 {
        let b = self.bounds(t);
        let (x, y) = (f64::from(p[0]), f64::from(p[1]));
        let dx = (b[0] - x).max(x - b[2]).max(0.0);
        let dy = (b[1] - y).max(y - b[3]).max(0.0);
        dx.hypot(dy)
    }

    /// The tiles other than `t` whose boxes lie within `reach` of `t`'s.
    fn around(&self, t: usize, reach: f64) -> Vec<usize> {
        let most = self.size[0].max(self.size[1]) as f64;
        let n = (reach / self.side).ceil().min(most) as isize;
        let (ix, iy) = ((t % self.size[0]) as isize, (t / self.size[0]) as isize);
        let mut out = Vec::new();
        for y in (iy - n).max(0)..=(iy + n).min(self.size[1] as isize - 1) {
            for x in (ix - n).max(0)..=(ix + n).min(self.size[0] as isize - 1) {
                if (x, y) != (ix, iy) {
                    out.push(y as usize * self.size[0] + x as usize);
                }
            }
        }
        out
    }

    fn name(&self, t: usize) -> String {
        let b = self.bounds(t);
        format!(
            "({}, {}) [x {:.1}…{:.1} m, y {:.1}…{:.1} m]",
            t % self.size[0],
            t / self.size[0],
            b[0],
            b[2],
            b[1],
            b[3]
        )
    }
}

/// The tiles' files of one stage: each tile's own points and its halo,
/// written through per-tile buffers.
struct Lists {
    dir: PathBuf,
    tag: String,
    own: Vec<Vec<Rec>>,
    halo: Vec<Vec<Rec>>,
    counts: Vec<u64>,
}

impl Lists {
    fn new(dir: &Path, tag: &str, tiles: usize) -> Self {
        Self {
            dir: dir.to_path_buf(),
            tag: tag.into(),
            own: vec![Vec::new(); tiles],
            halo: vec![Vec::new(); tiles],
            counts: vec![0; tiles],
        }
    }

    fn path(&self, t: usize, halo: bool) -> PathBuf {
        self.dir.join(format!(
            "{}-{t}.{}",
            self.tag,
            if halo { "halo" } else { "own" }
        ))
    }

    /// Files `recs` (in survey order) under tile `t`, with a copy of each
    /// in the halo of every other tile within `halo_m`.
    fn put(&mut self, grid: &Grid, t: usize, recs: &[Rec], halo_m: f64) -> Result<()> {
        for r in recs {
            self.own[t].push(*r);
            self.counts[t] += 1;
        }
        if self.own[t].len() >= FLUSH_POINTS {
            self.flush_one(t, false)?;
        }
        // Only a point within halo_m of its tile's edge (or outside it)
        // can lie within halo_m of another tile's box.
        let b = grid.bounds(t);
        let edge: Vec<Rec> = recs
            .iter()
            .filter(|r| {
                let (x, y) = (f64::from(r.p[0]), f64::from(r.p[1]));
                (x - b[0]).min(b[2] - x).min(y - b[1]).min(b[3] - y) <= halo_m
            })
            .copied()
            .collect();
        if edge.is_empty() {
            return Ok(());
        }
        // The tiles whose halo may take a point of `t`: its neighbours
        // within halo_m (points may lie a little outside their tile).
        for u in grid.around(t, 2.0 * halo_m) {
            let before = self.halo[u].len();
            self.halo[u].extend(edge.iter().filter(|r| grid.gap(u, &r.p) <= halo_m));
            if self.halo[u].len() >= FLUSH_POINTS && self.halo[u].len() > before {
                self.flush_one(u, true)?;
            }
        }
        Ok(())
    }

    fn flush_one(&mut self, t: usize, halo: bool) -> Result<()> {
        let path = self.path(t, halo);
        let buf = if halo {
            &mut self.halo[t]
        } else {
            &mut self.own[t]
        };
        if buf.is_empty() {
            return Ok(());
        }
        let spill = |source| SurfaceError::Spill {
            path: path.clone(),
            source,
        };
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(spill)?;
        // Encoded on every core, written in one piece.
        use rayon::prelude::*;
        let mut bytes = vec![0u8; buf.len() * RECORD];
        bytes
            .par_chunks_exact_mut(RECORD)
            .zip(buf.par_iter())
            .for_each(|(b, r)| {
                b[..8].copy_from_slice(&r.id.to_le_bytes());
                for a in 0..3 {
                    b[8 + 4 * a..12 + 4 * a].copy_from_slice(&r.p[a].to_le_bytes());
                }
            });
        let mut file = file;
        file.write_all(&bytes).map_err(spill)?;
        // A whole tile's survivors pass through at once: keep no more
        // than a buffer's worth, or every tile would hold its size.
        buf.clear();
        buf.shrink_to(FLUSH_POINTS);
        Ok(())
    }

    /// Writes every buffer out.
    fn flush(&mut self) -> Result<()> {
        for t in 0..self.own.len() {
            self.flush_one(t, false)?;
            self.flush_one(t, true)?;
        }
        Ok(())
    }

    /// Tile `t`'s own points (or its halo), as written.
    fn read(&self, t: usize, halo: bool) -> Result<Vec<Rec>> {
        read_recs(&self.path(t, halo))
    }

    /// Removes the stage's files.
    fn remove(&self) {
        for t in 0..self.own.len() {
            let _ = fs::remove_file(self.path(t, false));
            let _ = fs::remove_file(self.path(t, true));
        }
    }

    fn total(&self) -> u64 {
        self.counts.iter().sum()
    }
}

/// The records of a working file (none if it does not exist).
fn read_recs(path: &Path) -> Result<Vec<Rec>> {
    let spill = |source| SurfaceError::Spill {
        path: path.to_path_buf(),
        source,
    };
    let bytes = match fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(spill(e)),
    };
    use rayon::prelude::*;
    Ok(bytes.par_chunks_exact(RECORD).map(decode).collect())
}

#[inline]
fn decode(b: &[u8]) -> Rec {
    let f = |at: usize| f32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
    Rec {
        id: u64::from_le_bytes(b[..8].try_into().expect("8 bytes")),
        p: [f(8), f(12), f(16)],
    }
}

/// A tile with its halo: all points in survey order, and which are its own.
struct Loaded {
    recs: Vec<Rec>,
    own: Vec<bool>,
}

impl Loaded {
    fn cloud(&self) -> PointCloud {
        PointCloud::new(self.recs.iter().map(|r| r.p).collect())
    }
}

/// Merges two lists in survey order.
fn merge(a: Vec<Rec>, b: Vec<Rec>) -> Loaded {
    let mut recs = Vec::with_capacity(a.len() + b.len());
    let mut own = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        if j == b.len() || (i < a.len() && a[i].id < b[j].id) {
            recs.push(a[i]);
            own.push(true);
            i += 1;
        } else {
            recs.push(b[j]);
            own.push(false);
            j += 1;
        }
    }
    Loaded { recs, own }
}

/// The process's peak resident memory [bytes] (Linux: VmHWM).
pub fn peak_memory() -> Option<u64> {
    let status = fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The pipeline of [`crate::perceive`] on a survey by tiles (module docs).
/// `progress(what, done, total)` reports each pass; `on_tile` receives each
/// tile's cleaned points as they are done (its error stops the run).
pub fn perceive_tiled(
    survey: &Survey,
    params: &PerceptionParams,
    options: &TileOptions,
    progress: &mut dyn FnMut(&str, u64, u64),
    on_tile: &mut dyn FnMut(&TileOutput) -> Result<()>,
) -> Result<TiledPerceived> {
    let p = params;
    if !(options.model_cell_m.is_finite() && options.model_cell_m > 0.0) {
        return Err(SurfaceError::BadParameter {
            name: "model cell",
            value: options.model_cell_m,
            expected: "a finite length > 0 [m]",
        });
    }
    if let Some(t) = options.tile_m {
        if !(t.is_finite() && t > 0.0) {
            return Err(SurfaceError::BadParameter {
                name: "tile size",
                value: t,
                expected: "a finite length > 0 [m]",
            });
        }
    }
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
    let reports = read_files_in_order(
        &survey.files,
        origin,
        READ_CHUNK,
        threads,
        LOOKAHEAD,
        &mut |done, _| progress("reading (1 of 2)", done, claimed),
        &mut |_, chunk: &[Point]| {
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
            Ok(())
        },
    )?;
    let non_finite: u64 = reports.iter().map(|r| r.non_finite_dropped as u64).sum();
    let format = reports.first().map_or("", |r| r.format);
    if n == 0 {
        return Err(SurfaceError::NoFinitePoints {
            non_finite_dropped: non_finite as usize,
        });
    }
    let (scale, spacing) = scale_and_spacing_of(lo, hi, n, p)?;
    p.check_work(1.0, usize::try_from(n).unwrap_or(usize::MAX))?;
    let in_stage = |stage: &'static str| {
        move |source: SurfaceError| SurfaceError::Stage {
            stage,
            source: Box::new(source),
        }
    };
    // Level [RS eq. 11]–[RS eq. 12], from the sample.
    let mut tilt_params = TiltParams::for_scale(scale);
    tilt_params.min_floor_share = p.level.min_floor_share;
    let sample = PointCloud::new(sample);
    let (roll, pitch) = match p.level.mode {
        LevelMode::Estimate => {
            let est = estimate_tilt(&sample, &tilt_params)
                .map_err(in_stage("estimating roll and pitch from the floor"))?;
            (est.roll_rad, est.pitch_rad)
        }
        LevelMode::Given => {
            let (r, q) = (
                p.level.roll_deg.to_radians(),
                p.level.pitch_deg.to_radians(),
            );
            if !(r.is_finite() && q.is_finite()) {
                return Err(SurfaceError::BadParameter {
                    name: "level.roll_deg / level.pitch_deg",
                    value: if r.is_finite() { q } else { r },
                    expected: "finite angles",
                });
            }
            (r, q)
        }
        LevelMode::None => (0.0, 0.0),
    };
    let levelled_sample = level(&sample, roll, pitch);
    let floor = estimate_tilt(&levelled_sample, &tilt_params)
        .map_err(in_stage("finding the floor after levelling"))?;
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
    let work = tempdir_in(&options.work_dir)?;
    // Pass 2: level, remove the floor, file by tile.
    let t1 = Instant::now();
    let threshold = floor.floor_height_m + p.ground.margin_m * scale;
    let ground = PassThroughParams::ground_removal(threshold);
    let mut lists = Lists::new(&work.0, "s0", grid.tiles());
    let mut id = 0u64;
    let mut by_tile: Vec<Vec<Rec>> = vec![Vec::new(); grid.tiles()];
    let mut level_ms = 0.0;
    let mut failed: Option<SurfaceError> = None;
    let read = read_files_in_order(
        &survey.files,
        origin,
        READ_CHUNK,
        threads,
        LOOKAHEAD,
        &mut |done, _| progress("reading (2 of 2)", done, n),
        &mut |f, chunk: &[Point]| {
            let t = Instant::now();
            let levelled = PointCloud::new(chunk.iter().map(|q| rotate_point(&r, q)).collect());
            level_ms += elapsed_ms(t);
            // A chunk wholly at or below the floor keeps nothing (an
            // error only if the whole survey does).
            let kept = match pass_through_indices(&levelled, &ground) {
                Ok(k) => k,
                Err(CloudError::Emptied { .. }) => Vec::new(),
                Err(e) => return Err(e),
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
                    if let Err(e) = lists.put(&grid, t, &recs, halo) {
                        failed = Some(e);
                        return Err(CloudError::Format {
                            path: survey.files[f].clone(),
                            what: "stopped: a tile's working file failed".into(),
                        });
                    }
                }
            }
            Ok(())
        },
    );
    if let Some(e) = failed.take() {
        return Err(e);
    }
    read?;
    lists.flush()?;
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
    let mut run = TileRun {
        grid,
        halo,
        limit: options.memory_limit,
        largest: 0,
        dir: work.0.clone(),
        next: 1,
    };
    // The stages, in the paper's order.
    if p.radius.enabled {
        let t = Instant::now();
        let params = RadiusOutlierParams {
            radius_m: p.radius.radius_spacings * spacing,
            min_neighbors: p.radius.min_neighbors,
        };
        let before = lists.total();
        lists = run.pass(lists, "radius", progress, |loaded| {
            let kept = match radius_outlier_removal_indices(&loaded.cloud(), &params) {
                Ok(kept) => kept,
                Err(CloudError::Emptied { .. }) => Vec::new(),
                Err(e) => return Err(filter_err("radius", e)),
            };
            Ok(kept
                .into_iter()
                .filter(|&i| loaded.own[i])
                .map(|i| loaded.recs[i])
                .collect())
        })?;
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
    let mut researched = 0;
    if p.statistical.enabled {
        let t = Instant::now();
        let (next, again) = run.statistical(lists, p, progress)?;
        lists = next;
        researched = again;
        stages.push(record("statistical", &lists, t));
    }
    if p.voxel.enabled {
        let t = Instant::now();
        let params = VoxelGridParams::cube(leaf);
        let cells = VoxelCells::new(&params).map_err(|e| filter_err("voxel", e))?;
        lists = run.pass(lists, "voxel", progress, |loaded| {
            voxels_of_tile(loaded, &params, &cells)
        })?;
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
            lists = run.pass(lists, "smooth", progress, |loaded| {
                let moved = bilateral_normal_smoothing(&loaded.cloud(), &params)
                    .map_err(|e| filter_err("smooth", e))?;
                Ok(loaded
                    .recs
                    .iter()
                    .zip(&moved.points)
                    .zip(&loaded.own)
                    .filter(|(_, &own)| own)
                    .map(|((r, q), _)| Rec { id: r.id, p: *q })
                    .collect())
            })?;
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
        let recs = lists.read(tile, false)?;
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
            cloud: PointCloud::new(recs.iter().map(|r| r.p).collect()),
        })?;
    }
    progress("writing", grid.tiles() as u64, grid.tiles() as u64);
    lists.remove();
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
        statistical_researched: researched,
        stages,
        output_points,
        fit,
        fit_note,
        model,
        peak_memory: peak_memory(),
        origin_m: origin,
    })
}

fn record(stage: &'static str, lists: &Lists, t: Instant) -> StageRecord {
    StageRecord {
        stage,
        points: lists.total() as usize,
        ms: elapsed_ms(t),
    }
}

fn elapsed_ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn filter_err(stage: &'static str, source: CloudError) -> SurfaceError {
    SurfaceError::Filter { stage, source }
}

/// A fresh working folder under `dir`.
fn tempdir_in(dir: &Path) -> Result<WorkDir> {
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    let path = dir.join(format!(".autoshovel-tiles-{}-{stamp}", std::process::id()));
    fs::create_dir_all(&path).map_err(|source| SurfaceError::Spill {
        path: path.clone(),
        source,
    })?;
    Ok(WorkDir(path))
}

/// The grid of tiles over the levelled box of the raw bounds `lo`–`hi`.
fn grid_over(
    r: &Matrix3<f64>,
    lo: [f32; 3],
    hi: [f32; 3],
    n: u64,
    options: &TileOptions,
) -> Result<Grid> {
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
    Ok(Grid { origin, side, size })
}

/// The tiles of one run, stage after stage.
struct TileRun {
    grid: Grid,
    halo: f64,
    limit: u64,
    largest: u64,
    dir: PathBuf,
    next: usize,
}

impl TileRun {
    /// Tile `t` with its halo, checked against the memory limit.
    fn load(&mut self, lists: &Lists, t: usize) -> Result<Loaded> {
        let own = lists.read(t, false)?;
        let mut halo = lists.read(t, true)?;
        let points = (own.len() + halo.len()) as u64;
        self.largest = self.largest.max(points);
        if points * BYTES_PER_POINT > self.limit {
            return Err(SurfaceError::TileTooLarge {
                tile: self.grid.name(t),
                points,
                need: config::bytes((points * BYTES_PER_POINT) as f64),
                limit: config::bytes(self.limit as f64),
            });
        }
        halo.sort_unstable_by_key(|r| r.id);
        Ok(merge(own, halo))
    }

    /// One stage over every tile: `stage` maps a tile with its halo to the
    /// tile's own survivors (in survey order), filed for the next stage.
    fn pass(
        &mut self,
        lists: Lists,
        name: &str,
        progress: &mut dyn FnMut(&str, u64, u64),
        mut stage: impl FnMut(&Loaded) -> Result<Vec<Rec>>,
    ) -> Result<Lists> {
        let tiles = self.grid.tiles();
        let mut next = Lists::new(&self.dir, &format!("s{}", self.next), tiles);
        self.next += 1;
        for t in 0..tiles {
            progress(name, t as u64, tiles as u64);
            if lists.counts[t] == 0 {
                continue;
            }
            let loaded = self.load(&lists, t)?;
            let survivors = stage(&loaded)?;
            next.put(&self.grid, t, &survivors, self.halo)?;
        }
        progress(name, tiles as u64, tiles as u64);
        next.flush()?;
        lists.remove();
        Ok(next)
    }

    /// The statistical filter [RS eq. 14]–[RS eq. 16] over every tile:
    /// d̄_i of each point (searched again past the halo where its k-th
    /// neighbour lies beyond what the halo vouches for), the global sums in
    /// survey order, then the cut. Returns the survivors and how many
    /// points were searched again.
    fn statistical(
        &mut self,
        lists: Lists,
        p: &PerceptionParams,
        progress: &mut dyn FnMut(&str, u64, u64),
    ) -> Result<(Lists, u64)> {
        let tiles = self.grid.tiles();
        let k = p.statistical.mean_k;
        let total = lists.total();
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
        let mut again = 0u64;
        let dir = self.dir.clone();
        let dist_path = |t: usize| dir.join(format!("dist-{t}"));
        for t in 0..tiles {
            progress("statistical", t as u64, tiles as u64);
            if lists.counts[t] == 0 {
                continue;
            }
            let loaded = self.load(&lists, t)?;
            let cloud = loaded.cloud();
            // Fewer points than k + 1 in the tile and halo: every own point
            // is searched again.
            let found = if cloud.len() > k {
                mean_distances_and_reach(&cloud.points, k)
                    .map_err(|e| filter_err("statistical", e))?
            } else {
                vec![(f32::NAN, f32::INFINITY); cloud.len()]
            };
            let mut own: Vec<(u64, Point, f32)> = Vec::new();
            let mut unsure = Vec::new();
            for (i, r) in loaded.recs.iter().enumerate() {
                if !loaded.own[i] {
                    continue;
                }
                let (d, reach2) = found[i];
                // Points not loaded lie more than `halo` from the box, so
                // more than halo − gap from this point.
                let vouched = self.halo - self.grid.gap(t, &r.p);
                if f64::from(reach2).sqrt() * (1.0 + 1e-6) > vouched {
                    unsure.push((own.len(), f64::from(reach2).sqrt() + self.grid.gap(t, &r.p)));
                }
                own.push((r.id, r.p, d));
            }
            drop((loaded, cloud, found));
            if !unsure.is_empty() {
                again += unsure.len() as u64;
                // Every point within the farthest reach, from the tiles'
                // own lists (complete out to that distance).
                let reach = unsure
                    .iter()
                    .map(|u| u.1)
                    .fold(0.0_f64, f64::max)
                    .min(f64::from(f32::MAX));
                let mut wide: Vec<Point> = lists.read(t, false)?.iter().map(|r| r.p).collect();
                for u in self.grid.around(t, reach + self.halo) {
                    if lists.counts[u] == 0 {
                        continue;
                    }
                    wide.extend(
                        lists
                            .read(u, false)?
                            .iter()
                            .filter(|r| self.grid.gap(t, &r.p) <= reach * (1.0 + 1e-6))
                            .map(|r| r.p),
                    );
                    let points = wide.len() as u64;
                    if points * BYTES_PER_POINT > self.limit {
                        return Err(SurfaceError::TileTooLarge {
                            tile: format!(
                                "{} (searching {} outlier(s) {} m wide)",
                                self.grid.name(t),
                                unsure.len(),
                                config::approx(reach)
                            ),
                            points,
                            need: config::bytes((points * BYTES_PER_POINT) as f64),
                            limit: config::bytes(self.limit as f64),
                        });
                    }
                }
                let queries: Vec<Point> = unsure.iter().map(|u| own[u.0].1).collect();
                let exact = mean_distances_and_reach_at(&wide, &queries, k)
                    .map_err(|e| filter_err("statistical", e))?;
                for (u, (d, _)) in unsure.iter().zip(exact) {
                    own[u.0].2 = d;
                }
            }
            // The tile's d̄_i, in survey order.
            let path = dist_path(t);
            let spill = |source| SurfaceError::Spill {
                path: path.clone(),
                source,
            };
            let mut w = BufWriter::new(File::create(&path).map_err(spill)?);
            for (id, _, d) in &own {
                w.write_all(&id.to_le_bytes()).map_err(spill)?;
                w.write_all(&d.to_le_bytes()).map_err(spill)?;
            }
            w.flush().map_err(spill)?;
        }
        // [RS eq. 14]: the sums in survey order, merging the tiles' lists.
        let mut sums = DistanceSums::default();
        {
            // Each tile's list and its next (id, d̄_i).
            type Head = (BufReader<File>, Option<(u64, f32)>);
            let mut heads: Vec<Head> = Vec::new();
            for t in 0..tiles {
                if lists.counts[t] == 0 {
                    continue;
                }
                let path = dist_path(t);
                let f = File::open(&path).map_err(|source| SurfaceError::Spill {
                    path: path.clone(),
                    source,
                })?;
                let mut r = BufReader::with_capacity(1 << 16, f);
                let first = next_dist(&mut r, &path)?;
                heads.push((r, first));
            }
            let mut queue: std::collections::BinaryHeap<std::cmp::Reverse<(u64, usize)>> = heads
                .iter()
                .enumerate()
                .filter_map(|(i, h)| h.1.map(|(id, _)| std::cmp::Reverse((id, i))))
                .collect();
            while let Some(std::cmp::Reverse((_, i))) = queue.pop() {
                let (_, d) = heads[i].1.expect("queued heads hold a value");
                sums.add(d);
                let path = PathBuf::new();
                heads[i].1 = next_dist(&mut heads[i].0, &path)?;
                if let Some((id, _)) = heads[i].1 {
                    queue.push(std::cmp::Reverse((id, i)));
                }
            }
        }
        let cut = sums.cut(&StatisticalOutlierParams {
            mean_k: k,
            std_mul: p.statistical.std_mul,
            sides: p.statistical.sides,
        });
        // [RS eq. 15]–[RS eq. 16]: the cut, tile by tile.
        let mut next = Lists::new(&self.dir, &format!("s{}", self.next), tiles);
        self.next += 1;
        for t in 0..tiles {
            if lists.counts[t] == 0 {
                continue;
            }
            let own = lists.read(t, false)?;
            let path = dist_path(t);
            let bytes = fs::read(&path).map_err(|source| SurfaceError::Spill {
                path: path.clone(),
                source,
            })?;
            let kept: Vec<Rec> = own
                .into_iter()
                .zip(bytes.chunks_exact(12))
                .filter(|(_, b)| cut.keeps(f32::from_le_bytes([b[8], b[9], b[10], b[11]])))
                .map(|(r, _)| r)
                .collect();
            let _ = fs::remove_file(&path);
            next.put(&self.grid, t, &kept, self.halo)?;
        }
        progress("statistical", tiles as u64, tiles as u64);
        next.flush()?;
        lists.remove();
        if next.total() == 0 {
            return Err(filter_err(
                "statistical",
                CloudError::Emptied {
                    filter: "statistical outlier removal",
                    input: total as usize,
                    hint: "raise std_mul".into(),
                },
            ));
        }
        Ok((next, again))
    }
}

/// The next (id, d̄_i) of a tile's list.
fn next_dist(r: &mut BufReader<File>, path: &Path) -> Result<Option<(u64, f32)>> {
    let mut b = [0u8; 12];
    match r.read_exact(&mut b) {
        Ok(()) => Ok(Some((
            u64::from_le_bytes(b[..8].try_into().expect("8 bytes")),
            f32::from_le_bytes([b[8], b[9], b[10], b[11]]),
        ))),
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => Ok(None),
        Err(source) => Err(SurfaceError::Spill {
            path: path.to_path_buf(),
            source,
        }),
    }
}

/// The voxel grid [RS eq. 17]–[RS eq. 18] of the voxels a tile owns (those
/// whose first point in survey order is its own), each centroid filed
/// under its first point's index.
fn voxels_of_tile(
    loaded: &Loaded,
    params: &VoxelGridParams,
    cells: &VoxelCells,
) -> Result<Vec<Rec>> {
    use rayon::prelude::*;
    // (voxel z, y, x, position) of every loaded point, sorted: a voxel's
    // run starts with its first point. Packed into one u64 (voxel index
    // above, position below) when the tile's voxels number at most 2³².
    let voxel: Vec<[i64; 3]> = loaded.recs.par_iter().map(|r| cells.of(&r.p)).collect();
    let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
    for c in &voxel {
        for a in 0..3 {
            lo[a] = lo[a].min(c[a]);
            hi[a] = hi[a].max(c[a]);
        }
    }
    let extent = [0, 1, 2].map(|a| (hi[a] - lo[a]) as u128 + 1);
    let keys: Vec<([i64; 3], u32)> = if extent[0] * extent[1] * extent[2] <= 1 << 32 {
        let (ex, exy) = (extent[0] as u64, (extent[0] * extent[1]) as u64);
        let mut packed: Vec<u64> = voxel
            .par_iter()
            .enumerate()
            .map(|(i, c)| {
                let l = (c[0] - lo[0]) as u64
                    + (c[1] - lo[1]) as u64 * ex
                    + (c[2] - lo[2]) as u64 * exy;
                (l << 32) | i as u64
            })
            .collect();
        packed.par_sort_unstable();
        packed
            .into_iter()
            .map(|k| {
                let i = (k & 0xffff_ffff) as usize;
                let c = voxel[i];
                ([c[2], c[1], c[0]], i as u32)
            })
            .collect()
    } else {
        let mut keys: Vec<([i64; 3], u32)> = voxel
            .iter()
            .enumerate()
            .map(|(i, c)| ([c[2], c[1], c[0]], i as u32))
            .collect();
        keys.par_sort_unstable();
        keys
    };
    let mut mine = vec![false; loaded.recs.len()];
    let mut owners = Vec::new();
    let mut s = 0;
    while s < keys.len() {
        let mut e = s;
        while e < keys.len() && keys[e].0 == keys[s].0 {
            e += 1;
        }
        let first = keys[s].1 as usize;
        if loaded.own[first] {
            owners.push(loaded.recs[first].id);
            for k in &keys[s..e] {
                mine[k.1 as usize] = true;
            }
        }
        s = e;
    }
    if owners.is_empty() {
        return Ok(Vec::new());
    }
    // The owned voxels' points in survey order, averaged by the filter
    // itself; its centroids come in (z, y, x) voxel order, as `owners`.
    let points: Vec<Point> = loaded
        .recs
        .iter()
        .zip(&mine)
        .filter(|(_, &m)| m)
        .map(|(r, _)| r.p)
        .collect();
    let centroids =
        voxel_grid(&PointCloud::new(points), params).map_err(|e| filter_err("voxel", e))?;
    debug_assert_eq!(centroids.len(), owners.len());
    let mut out: Vec<Rec> = owners
        .into_iter()
        .zip(centroids.points)
        .map(|(id, p)| Rec { id, p })
        .collect();
    out.sort_unstable_by_key(|r| r.id);
    Ok(out)
}
