//! Frame mode: the perception pipeline ([`crate::perceive`]) on a live
//! sensor's sequence of frames, as a LiDAR on the machine delivers them
//! (an 80-line sensor at 20 Hz, walking paper Table 2).
//!
//! A [`FramePerceiver`] keeps, between frames, what a frame from the same
//! sensor pose does not need to find again: the roll and pitch of
//! [RS eq. 11] and the floor found by the first frame's two RANSAC fits,
//! and the scale and spacing it settled ([`Prior`]); it re-levels every
//! `relevel_every` frames when asked. Each frame's cleaned cloud updates a
//! running height model of the pile ([`HeightModel`]: a grid of cells, each
//! holding the mean height of the latest frame that saw it, since the pile
//! changes under the dipper and the model must follow it). A frame that
//! cannot be read or perceived is skipped, with its reason, and counted;
//! the sequence goes on.
//!
//! ```
//! use autoshovel_terrain::frames::{FrameOptions, FramePerceiver};
//! use autoshovel_terrain::perceive::PerceptionParams;
//! use autoshovel_terrain::{generate_pile, PileParams};
//!
//! let mut run = FramePerceiver::new(PerceptionParams::default(), FrameOptions::default());
//! for seed in 1..=3 {
//!     let frame = generate_pile(&PileParams { points: 20_000, seed, ..PileParams::default() });
//!     run.push(&format!("frame {seed}"), frame.map_err(Into::into));
//! }
//! let done = run.finish().unwrap();
//! assert_eq!(done.summary.frames_ok, 3);
//! // Levelled once, on the first frame.
//! assert_eq!(done.records.iter().filter(|r| r.relevelled).count(), 1);
//! assert!(done.model.coverage() > 0.5);
//! ```

use std::path::{Path, PathBuf};
use std::time::Instant;

use autoshovel_point_cloud::PointCloud;
use serde::Serialize;

use crate::perceive::{perceive_after, Perceived, PerceptionParams, Prior, StageRecord};
use crate::{Result, SurfaceError};

/// The file extensions read as frames (those of `autoshovel_point_cloud::io`).
pub const FRAME_EXTENSIONS: [&str; 7] = ["pcd", "ply", "las", "laz", "xyz", "csv", "txt"];

/// The frames of folder `dir`: its point-cloud files (by extension), in
/// name order (numbers within names compared as numbers, so `frame-9`
/// comes before `frame-10`).
pub fn frames_in(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| SurfaceError::Frames {
        dir: dir.display().to_string(),
        problem: format!("cannot list the folder: {e}"),
    })?;
    let mut frames: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.is_file()
                && p.extension()
                    .and_then(|e| e.to_str())
                    .is_some_and(|e| FRAME_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        })
        .collect();
    if frames.is_empty() {
        return Err(SurfaceError::Frames {
            dir: dir.display().to_string(),
            problem: format!(
                "no frame in it (files ending .{})",
                FRAME_EXTENSIONS.join(", .")
            ),
        });
    }
    frames.sort_by(|a, b| natural_order(&a.to_string_lossy(), &b.to_string_lossy()));
    Ok(frames)
}

/// The files of an `n`-frame sequence written as `out`: `out` itself for
/// one frame, else `out`'s name with `-0000`, `-0001`, … before its
/// extension (`generate-pile --frames`; [`frames_in`] reads them back in
/// this order).
pub fn sequence_paths(out: &Path, n: usize) -> Vec<PathBuf> {
    if n == 1 {
        return vec![out.to_path_buf()];
    }
    let stem = out.file_stem().unwrap_or_default().to_string_lossy();
    let ext = out.extension().unwrap_or_default().to_string_lossy();
    (0..n)
        .map(|i| out.with_file_name(format!("{stem}-{i:04}.{ext}")))
        .collect()
}

/// Perceives every frame of folder `dir` ([`frames_in`]) in order with one
/// [`FramePerceiver`], calling `on_frame(done, total, record)` after each.
pub fn perceive_folder(
    dir: &Path,
    params: &PerceptionParams,
    options: FrameOptions,
    on_frame: &mut dyn FnMut(usize, usize, &FrameRecord),
) -> Result<FrameRun> {
    let files = frames_in(dir)?;
    perceive_files(
        &dir.display().to_string(),
        &files,
        params,
        options,
        on_frame,
    )
}

/// Perceives the frame files `files` in order with one [`FramePerceiver`]
/// (`input` names what they came from, for the summary), calling
/// `on_frame(done, total, record)` after each: [`perceive_folder`] for a
/// caller that has listed the folder already.
pub fn perceive_files(
    input: &str,
    files: &[PathBuf],
    params: &PerceptionParams,
    options: FrameOptions,
    on_frame: &mut dyn FnMut(usize, usize, &FrameRecord),
) -> Result<FrameRun> {
    let mut run = FramePerceiver::new(params.clone(), options).with_input(input);
    for (i, f) in files.iter().enumerate() {
        on_frame(i + 1, files.len(), run.push_file(f));
    }
    run.finish()
}

/// Compares names with runs of digits compared as numbers.
fn natural_order(a: &str, b: &str) -> std::cmp::Ordering {
    fn parts(s: &str) -> Vec<(bool, String)> {
        let mut out: Vec<(bool, String)> = Vec::new();
        for c in s.chars() {
            let digit = c.is_ascii_digit();
            match out.last_mut() {
                Some((d, run)) if *d == digit => run.push(c),
                _ => out.push((digit, c.to_string())),
            }
        }
        out
    }
    let (pa, pb) = (parts(a), parts(b));
    for (x, y) in pa.iter().zip(&pb) {
        let ord = match (x.0, y.0) {
            (true, true) => {
                let (tx, ty) = (x.1.trim_start_matches('0'), y.1.trim_start_matches('0'));
                tx.len().cmp(&ty.len()).then_with(|| tx.cmp(ty))
            }
            _ => x.1.cmp(&y.1),
        };
        if ord.is_ne() {
            return ord;
        }
    }
    pa.len().cmp(&pb.len()).then_with(|| a.cmp(b))
}

/// Settings of frame mode (default: level once, cells of four spacings).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameOptions {
    /// Search for the floor and level again every this many frames; 0
    /// (the default) levels once, on the first frame perceived, as for a
    /// sensor fixed on a standing machine.
    pub relevel_every: usize,
    /// Edge of a cell of the running height model (m); `None` (the
    /// default): four times the first frame's point spacing.
    pub model_cell_m: Option<f64>,
    /// The real-time (`SCHED_FIFO`) priority the caller runs the frames'
    /// threads at, for the summary; `None`: ordinary scheduling. The
    /// library does not set it: a process's scheduling is its owner's
    /// (`autoshovel perceive --realtime`).
    pub realtime_priority: Option<u8>,
}

/// The running height model of the pile: a grid over the first perceived
/// frame's cleaned cloud (grown by a tenth on every side), each cell the
/// mean height of the cleaned points of the latest frame that saw it, in
/// the levelled frame.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightModel {
    /// x, y of the grid's lower corner (m).
    pub origin: [f64; 2],
    /// Cell edge (m).
    pub cell_m: f64,
    /// Cells along x and y.
    pub size: [usize; 2],
    /// Height of each cell (row-major, x fastest); NaN where never seen (m).
    pub z: Vec<f64>,
    /// Frames that saw each cell.
    pub seen: Vec<u32>,
    /// The last frame (index in the sequence) that saw each cell.
    pub last: Vec<u32>,
}

/// What one frame did to the [`HeightModel`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModelUpdate {
    /// Cells this frame saw.
    pub cells_updated: usize,
    /// Of them, cells no frame had seen before.
    pub cells_new: usize,
    /// RMS change of the height of the cells seen before (m).
    pub change_rms_m: f64,
    /// Cleaned points outside the grid (not in the model).
    pub points_outside: usize,
}

impl HeightModel {
    /// An empty model over `cloud`'s extent grown by a tenth a side, of
    /// cells `cell_m` wide.
    pub fn over(cloud: &PointCloud, cell_m: f64) -> Result<Self> {
        if !(cell_m.is_finite() && cell_m > 0.0) {
            return Err(SurfaceError::BadParameter {
                name: "model cell",
                value: cell_m,
                expected: "a finite length > 0 [m]",
            });
        }
        let (lo, hi) = cloud.bounds().ok_or(SurfaceError::NoFinitePoints {
            non_finite_dropped: 0,
        })?;
        let grow = |a: usize| 0.1 * f64::from(hi[a] - lo[a]);
        Ok(Self::over_box(
            [0, 1].map(|a| f64::from(lo[a]) - grow(a)),
            [0, 1].map(|a| f64::from(hi[a]) + grow(a)),
            cell_m,
        ))
    }

    /// An empty model over the rectangle `lo`–`hi` (x, y) (m), of cells
    /// `cell_m` wide (at most 16 384 a side: coarser cells past that).
    pub fn over_box(lo: [f64; 2], hi: [f64; 2], cell_m: f64) -> Self {
        let origin = lo;
        let side = (0..2)
            .map(|a| (hi[a] - lo[a]) / 16384.0)
            .fold(cell_m, f64::max);
        let cell_m = side;
        let size =
            [0, 1].map(|a| (((hi[a] - origin[a]) / cell_m).ceil() as usize).clamp(1, 1 << 14));
        let cells = size[0] * size[1];
        Self {
            origin,
            cell_m,
            size,
            z: vec![f64::NAN; cells],
            seen: vec![0; cells],
            last: vec![0; cells],
        }
    }

    /// The cell of (x, y), if inside.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<usize> {
        let ix = ((x - self.origin[0]) / self.cell_m).floor();
        let iy = ((y - self.origin[1]) / self.cell_m).floor();
        (ix >= 0.0 && iy >= 0.0 && (ix as usize) < self.size[0] && (iy as usize) < self.size[1])
            .then(|| iy as usize * self.size[0] + ix as usize)
    }

    /// The centre (x, y) of cell `i`.
    pub fn centre(&self, i: usize) -> [f64; 2] {
        let (ix, iy) = (i % self.size[0], i / self.size[0]);
        [
            self.origin[0] + (ix as f64 + 0.5) * self.cell_m,
            self.origin[1] + (iy as f64 + 0.5) * self.cell_m,
        ]
    }

    /// Share of the cells some frame has seen.
    pub fn coverage(&self) -> f64 {
        self.seen.iter().filter(|&&s| s > 0).count() as f64 / self.seen.len().max(1) as f64
    }

    /// Folds frame `frame`'s cleaned cloud into the model: each cell it
    /// covers takes the mean height of its points there.
    pub fn update(&mut self, cloud: &PointCloud, frame: u32) -> ModelUpdate {
        let mut sum = vec![0.0_f64; self.z.len()];
        let mut count = vec![0_u32; self.z.len()];
        let mut outside = 0;
        for p in &cloud.points {
            match self.cell_of(f64::from(p[0]), f64::from(p[1])) {
                Some(i) => {
                    sum[i] += f64::from(p[2]);
                    count[i] += 1;
                }
                None => outside += 1,
            }
        }
        let (mut updated, mut new, mut change2) = (0, 0, 0.0);
        for i in 0..self.z.len() {
            if count[i] == 0 {
                continue;
            }
            let z = sum[i] / f64::from(count[i]);
            if self.seen[i] == 0 {
                new += 1;
            } else {
                change2 += (z - self.z[i]).powi(2);
            }
            updated += 1;
            self.z[i] = z;
            self.seen[i] += 1;
            self.last[i] = frame;
        }
        let old = updated - new;
        ModelUpdate {
            cells_updated: updated,
            cells_new: new,
            change_rms_m: if old > 0 {
                (change2 / old as f64).sqrt()
            } else {
                0.0
            },
            points_outside: outside,
        }
    }
}

/// One frame of a sequence: what happened to it and how long it took.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameRecord {
    /// Position in the sequence, from 0.
    pub index: usize,
    /// The frame's file or name.
    pub file: String,
    /// Whether it was perceived (false: skipped, see `reason`).
    pub ok: bool,
    /// Why it was skipped.
    pub reason: Option<String>,
    /// Finite points read.
    pub input_points: usize,
    /// Points of the cleaned cloud.
    pub output_points: usize,
    /// Whether this frame searched the floor and levelled (the first
    /// perceived frame, and every `relevel_every`-th after it).
    pub relevelled: bool,
    /// Time to read the frame (ms) (0 for a frame given in memory).
    pub read_ms: f64,
    /// Time of the pipeline (ms).
    pub pipeline_ms: f64,
    /// Time to update the height model (ms).
    pub model_ms: f64,
    /// From the start of the read to the updated model (ms).
    pub latency_ms: f64,
    /// The pipeline's stages (counts and times).
    pub stages: Vec<StageRecord>,
    /// R² of the frame's surface fit.
    pub r2: f64,
    /// What the frame did to the height model.
    pub model: Option<ModelUpdate>,
}

/// Latency statistics over the perceived frames (ms).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Latency {
    /// Of the first perceived frame (it searches the floor).
    pub first_ms: f64,
    /// Median over the perceived frames after the first.
    pub median_ms: f64,
    /// 95th percentile over them.
    pub p95_ms: f64,
    /// Largest over them.
    pub max_ms: f64,
    /// Mean over them.
    pub mean_ms: f64,
}

/// The summary of `autoshovel perceive` on a folder of frames (SPEC §6
/// fields of `perceive`, for the sequence).
#[derive(Debug, Clone, Serialize)]
pub struct FramesSummary {
    /// "perceive".
    pub job: &'static str,
    /// "frames".
    pub mode: &'static str,
    /// The folder (or what the frames came from).
    pub input: String,
    /// Frames given.
    pub frames: usize,
    /// Frames perceived.
    pub frames_ok: usize,
    /// Frames skipped (unreadable, or refused by the pipeline).
    pub frames_skipped: usize,
    /// Each skipped frame: index, file and reason.
    pub skipped: Vec<SkippedFrame>,
    /// Finite points read, all frames.
    pub input_points: usize,
    /// Points of the last perceived frame's cleaned cloud.
    pub output_points: usize,
    /// Points after each stage of the last perceived frame.
    pub stage_points: std::collections::BTreeMap<&'static str, usize>,
    /// Median time of each stage over the perceived frames (ms).
    pub timings_ms: std::collections::BTreeMap<&'static str, f64>,
    /// Frame latency (read, pipeline and model update) (ms).
    pub latency: Latency,
    /// Frames per second the sequence was perceived at (wall time).
    pub frames_per_s: f64,
    /// Roll α in use at the end (deg).
    pub roll_deg: f64,
    /// Pitch β in use at the end (deg).
    pub pitch_deg: f64,
    /// R² of the last perceived frame's fit.
    pub r2: f64,
    /// Frames that searched the floor and levelled.
    pub relevelled_frames: usize,
    /// Re-level every this many frames (0: once).
    pub relevel_every: usize,
    /// The real-time (`SCHED_FIFO`) priority the frames ran at (`None`:
    /// ordinary scheduling).
    pub realtime_priority: Option<u8>,
    /// The height model's cell edge (m).
    pub model_cell_m: f64,
    /// Its cells along x and y.
    pub model_size: [usize; 2],
    /// Share of its cells seen.
    pub model_coverage: f64,
    /// Median RMS change of the seen cells between frames (m).
    pub model_change_rms_m: f64,
    /// The settings used.
    pub pipeline: PerceptionParams,
    /// True when at least one frame was perceived.
    pub success: bool,
}

/// A frame that was skipped.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkippedFrame {
    /// Its position, from 0.
    pub index: usize,
    /// Its file or name.
    pub file: String,
    /// Why.
    pub reason: String,
}

/// A finished sequence: every frame's record, the height model and the summary.
#[derive(Debug, Clone)]
pub struct FrameRun {
    /// Every frame, in order.
    pub records: Vec<FrameRecord>,
    /// The running height model after the last frame.
    pub model: HeightModel,
    /// The last perceived frame.
    pub last: Perceived,
    /// The summary.
    pub summary: FramesSummary,
}

/// Perception of a frame sequence, frame by frame, with the state kept
/// between frames (module docs).
pub struct FramePerceiver {
    params: PerceptionParams,
    options: FrameOptions,
    input: String,
    prior: Option<Prior>,
    since_level: usize,
    model: Option<HeightModel>,
    last: Option<Perceived>,
    records: Vec<FrameRecord>,
    started: Instant,
}

impl FramePerceiver {
    /// A perceiver with these pipeline settings and options.
    pub fn new(params: PerceptionParams, options: FrameOptions) -> Self {
        Self {
            params,
            options,
            input: "frames".into(),
            prior: None,
            since_level: 0,
            model: None,
            last: None,
            records: Vec::new(),
            started: Instant::now(),
        }
    }

    /// Names what the frames come from (a folder), for the summary.
    pub fn with_input(mut self, input: impl Into<String>) -> Self {
        self.input = input.into();
        self
    }

    /// Reads frame file `path` and perceives it ([`FramePerceiver::push`]).
    pub fn push_file(&mut self, path: &Path) -> &FrameRecord {
        let t = Instant::now();
        let read = autoshovel_point_cloud::io::read(path, &mut |_, _| {})
            .map_err(SurfaceError::from)
            .and_then(|r| {
                if r.cloud.is_empty() {
                    Err(SurfaceError::NoFinitePoints {
                        non_finite_dropped: r.non_finite_dropped,
                    })
                } else {
                    Ok(r.cloud)
                }
            });
        let read_ms = t.elapsed().as_secs_f64() * 1e3;
        self.push_timed(&path.display().to_string(), read, read_ms)
    }

    /// Perceives the next frame, `cloud` (or the error that reading it
    /// gave, which skips it), named `name`; returns its record.
    pub fn push(&mut self, name: &str, cloud: Result<PointCloud>) -> &FrameRecord {
        self.push_timed(name, cloud, 0.0)
    }

    fn push_timed(&mut self, name: &str, cloud: Result<PointCloud>, read_ms: f64) -> &FrameRecord {
        let index = self.records.len();
        let relevel = self.prior.is_none()
            || (self.options.relevel_every > 0 && self.since_level >= self.options.relevel_every);
        let t = Instant::now();
        let got = cloud.and_then(|c| {
            let prior = if relevel { None } else { self.prior.as_ref() };
            perceive_after(&c, &self.params, prior, &mut |_| {}).map(|g| (c.len(), g))
        });
        let pipeline_ms = t.elapsed().as_secs_f64() * 1e3;
        let record = match got {
            Err(e) => FrameRecord {
                index,
                file: name.to_string(),
                ok: false,
                reason: Some(full_reason(&e)),
                input_points: 0,
                output_points: 0,
                relevelled: false,
                read_ms,
                pipeline_ms,
                model_ms: 0.0,
                latency_ms: read_ms + pipeline_ms,
                stages: Vec::new(),
                r2: f64::NAN,
                model: None,
            },
            Ok((input_points, got)) => {
                if relevel {
                    self.prior = Some(Prior::of(&got));
                    self.since_level = 0;
                }
                self.since_level += 1;
                let t = Instant::now();
                let cell = self.options.model_cell_m.unwrap_or(4.0 * got.spacing_m);
                let update = match &mut self.model {
                    Some(m) => Some(m.update(&got.cloud, index as u32)),
                    None => match HeightModel::over(&got.cloud, cell) {
                        Ok(mut m) => {
                            let u = m.update(&got.cloud, index as u32);
                            self.model = Some(m);
                            Some(u)
                        }
                        Err(_) => None,
                    },
                };
                let model_ms = t.elapsed().as_secs_f64() * 1e3;
                let record = FrameRecord {
                    index,
                    file: name.to_string(),
                    ok: true,
                    reason: None,
                    input_points,
                    output_points: got.cloud.len(),
                    relevelled: relevel,
                    read_ms,
                    pipeline_ms,
                    model_ms,
                    latency_ms: read_ms + pipeline_ms + model_ms,
                    stages: got.stages.clone(),
                    r2: got.fit.r2,
                    model: update,
                };
                self.last = Some(got);
                record
            }
        };
        self.records.push(record);
        self.records.last().expect("just pushed")
    }

    /// Ends the sequence: the records, the model and the summary; an error
    /// when no frame could be perceived (naming the first frame's reason).
    pub fn finish(self) -> Result<FrameRun> {
        let (Some(model), Some(last), Some(prior)) = (self.model, self.last, self.prior) else {
            return Err(SurfaceError::Frames {
                dir: self.input,
                problem: match self.records.first() {
                    Some(r) => format!(
                        "none of its {} frames could be perceived; the first, {}: {}",
                        self.records.len(),
                        r.file,
                        r.reason.as_deref().unwrap_or("?")
                    ),
                    None => "no frames were given".into(),
                },
            });
        };
        let wall_s = self.started.elapsed().as_secs_f64();
        let ok: Vec<&FrameRecord> = self.records.iter().filter(|r| r.ok).collect();
        let later: Vec<f64> = ok.iter().skip(1).map(|r| r.latency_ms).collect();
        let latency = Latency {
            first_ms: ok[0].latency_ms,
            median_ms: quantile(&later, 0.5),
            p95_ms: quantile(&later, 0.95),
            max_ms: later.iter().copied().fold(f64::NAN, f64::max),
            mean_ms: later.iter().sum::<f64>() / later.len().max(1) as f64,
        };
        let mut timings_ms = std::collections::BTreeMap::new();
        for s in &last.stages {
            let times: Vec<f64> = ok
                .iter()
                .filter_map(|r| r.stages.iter().find(|x| x.stage == s.stage).map(|x| x.ms))
                .collect();
            timings_ms.insert(s.stage, quantile(&times, 0.5));
        }
        let changes: Vec<f64> = ok
            .iter()
            .skip(1)
            .filter_map(|r| r.model.map(|m| m.change_rms_m))
            .collect();
        let skipped: Vec<SkippedFrame> = self
            .records
            .iter()
            .filter(|r| !r.ok)
            .map(|r| SkippedFrame {
                index: r.index,
                file: r.file.clone(),
                reason: r.reason.clone().unwrap_or_default(),
            })
            .collect();
        let summary = FramesSummary {
            job: "perceive",
            mode: "frames",
            input: self.input,
            frames: self.records.len(),
            frames_ok: ok.len(),
            frames_skipped: skipped.len(),
            skipped,
            input_points: ok.iter().map(|r| r.input_points).sum(),
            output_points: last.cloud.len(),
            stage_points: last.stages.iter().map(|s| (s.stage, s.points)).collect(),
            timings_ms,
            latency,
            frames_per_s: self.records.len() as f64 / wall_s.max(1e-9),
            roll_deg: prior.roll_rad.to_degrees(),
            pitch_deg: prior.pitch_rad.to_degrees(),
            r2: last.fit.r2,
            relevelled_frames: ok.iter().filter(|r| r.relevelled).count(),
            relevel_every: self.options.relevel_every,
            realtime_priority: self.options.realtime_priority,
            model_cell_m: model.cell_m,
            model_size: model.size,
            model_coverage: model.coverage(),
            model_change_rms_m: quantile(&changes, 0.5),
            pipeline: self.params,
            success: true,
        };
        Ok(FrameRun {
            records: self.records,
            model,
            last,
            summary,
        })
    }
}

/// An error with its causes, on one line.
fn full_reason(e: &SurfaceError) -> String {
    let mut out = e.to_string();
    let mut source = std::error::Error::source(e);
    while let Some(s) = source {
        out.push_str(": ");
        out.push_str(&s.to_string());
        source = s.source();
    }
    out
}

/// The `q` quantile of `values` (nearest rank; NaN when empty).
fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perceive::perceive;
    use crate::{generate_pile, PileParams};

    fn frame(seed: u64) -> PointCloud {
        generate_pile(&PileParams {
            points: 20_000,
            seed,
            ..PileParams::default()
        })
        .unwrap()
    }

    #[test]
    fn a_sequence_is_named_in_the_order_frames_in_reads_it() {
        let one = sequence_paths(Path::new("s/scan.pcd"), 1);
        assert_eq!(one, [PathBuf::from("s/scan.pcd")]);
        let names: Vec<String> = sequence_paths(Path::new("s/f.laz"), 12)
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        assert_eq!(
            (names[0].as_str(), names[11].as_str()),
            ("s/f-0000.laz", "s/f-0011.laz")
        );
        let mut sorted = names.clone();
        sorted.reverse();
        sorted.sort_by(|a, b| natural_order(a, b));
        assert_eq!(sorted, names);
    }

    #[test]
    fn names_sort_with_numbers_as_numbers() {
        let mut v = vec!["f-10.pcd", "f-9.pcd", "f-100.pcd", "f-09b.pcd", "a.pcd"];
        v.sort_by(|a, b| natural_order(a, b));
        assert_eq!(
            v,
            ["a.pcd", "f-9.pcd", "f-09b.pcd", "f-10.pcd", "f-100.pcd"]
        );
    }

    #[test]
    fn a_later_frame_equals_perceiving_it_with_the_first_frames_levelling() {
        let params = PerceptionParams::default();
        let mut run = FramePerceiver::new(params.clone(), FrameOptions::default());
        run.push("0", Ok(frame(1)));
        run.push("1", Ok(frame(2)));
        let done = run.finish().unwrap();
        let first = perceive(&frame(1), &params).unwrap();
        // The second frame alone, with the first frame's prior, by hand.
        let second =
            perceive_after(&frame(2), &params, Some(&Prior::of(&first)), &mut |_| {}).unwrap();
        assert_eq!(done.last.cloud, second.cloud);
        assert_eq!(done.records[1].stages.len(), second.stages.len());
        assert!(done.records[0].relevelled && !done.records[1].relevelled);
        // The same sensor pose: the angles found once serve both frames,
        // and are those the second frame would have found itself.
        let own = perceive(&frame(2), &params).unwrap();
        assert!((own.roll_rad - first.roll_rad).abs().to_degrees() < 0.05);
        assert!((own.pitch_rad - first.pitch_rad).abs().to_degrees() < 0.05);
    }

    #[test]
    fn broken_frames_are_skipped_and_counted_and_the_sequence_goes_on() {
        let mut run = FramePerceiver::new(PerceptionParams::default(), FrameOptions::default());
        run.push(
            "bad.pcd",
            Err(SurfaceError::NoFinitePoints {
                non_finite_dropped: 3,
            }),
        );
        run.push("0", Ok(frame(1)));
        // A frame of three points: the pipeline refuses it.
        run.push(
            "tiny",
            Ok(PointCloud::new(vec![
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
            ])),
        );
        run.push("1", Ok(frame(2)));
        let done = run.finish().unwrap();
        assert_eq!((done.summary.frames, done.summary.frames_ok), (4, 2));
        let skipped: Vec<usize> = done.summary.skipped.iter().map(|s| s.index).collect();
        assert_eq!(skipped, [0, 2]);
        assert!(done.summary.skipped[0].reason.contains("no finite points"));
        // The first good frame levelled; the skipped one did not count.
        assert!(done.records[1].relevelled && !done.records[3].relevelled);
    }

    #[test]
    fn nothing_perceived_is_an_error_naming_the_first_reason() {
        let mut run = FramePerceiver::new(PerceptionParams::default(), FrameOptions::default())
            .with_input("seq/");
        run.push("a.pcd", Err(SurfaceError::NoHorizontalExtent));
        let err = run.finish().unwrap_err().to_string();
        assert!(
            err.contains("seq/") && err.contains("a.pcd") && err.contains("horizontal"),
            "{err}"
        );
    }

    #[test]
    fn the_model_keeps_the_latest_height_and_reports_the_change() {
        // A flat plate at z = 1, then the same plate at z = 1.5.
        let plate = |z: f32| {
            PointCloud::new(
                (0..400)
                    .map(|i| [(i % 20) as f32 * 0.1, (i / 20) as f32 * 0.1, z])
                    .collect(),
            )
        };
        let mut m = HeightModel::over(&plate(1.0), 0.5).unwrap();
        let u = m.update(&plate(1.0), 0);
        assert_eq!(u.cells_new, u.cells_updated);
        assert_eq!(u.change_rms_m, 0.0);
        let u = m.update(&plate(1.5), 1);
        assert_eq!(u.cells_new, 0);
        assert!((u.change_rms_m - 0.5).abs() < 1e-6);
        let i = m.cell_of(0.7, 0.7).unwrap();
        assert!((m.z[i] - 1.5).abs() < 1e-6 && m.seen[i] == 2 && m.last[i] == 1);
        assert!(m.cell_of(-10.0, 0.0).is_none());
        assert!(HeightModel::over(&plate(1.0), 0.0).is_err());
    }

    #[test]
    fn relevel_every_searches_the_floor_again() {
        let options = FrameOptions {
            relevel_every: 2,
            ..FrameOptions::default()
        };
        let mut run = FramePerceiver::new(PerceptionParams::default(), options);
        for s in 1..=5 {
            run.push(&s.to_string(), Ok(frame(s)));
        }
        let done = run.finish().unwrap();
        let relevelled: Vec<bool> = done.records.iter().map(|r| r.relevelled).collect();
        assert_eq!(relevelled, [true, false, true, false, true]);
    }
}
