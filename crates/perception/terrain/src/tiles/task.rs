//! A stage's work on one tile as a unit that can run anywhere that sees
//! the run's working folder: [`TileTask`] in, [`TileReport`] out, through
//! [`run_tile_task`]. The driver ([`super::perceive_tiled_with`]) makes a
//! stage's tasks, hands them to a [`TileExecutor`] (this process, a tile
//! per core: [`InProcess`]; or another machine's workers, as the
//! Python package's Ray executor does), and waits for every report before
//! the next stage.

use std::path::PathBuf;
use std::sync::{mpsc, Condvar, Mutex};

use autoshovel_core::config;
use autoshovel_point_cloud::filter::{
    bilateral_normal_smoothing, mean_distances_and_reach, mean_distances_and_reach_at,
    radius_outlier_removal_indices, voxel_grid, BilateralParams, DistanceSums, RadiusOutlierParams,
    StatisticalOutlierParams, VoxelCells, VoxelGridParams,
};
use autoshovel_point_cloud::{CloudError, Point, PointCloud};
use serde::{Deserialize, Serialize};

use super::store::{
    dist_path, f32_at, file_tile, halo_path, own_path, read_bytes_checked, read_checked,
    write_whole, Loaded, Rec, TileLayout, Writer, DIST_RECORD,
};
use super::BYTES_PER_POINT;
use crate::error::{Result, SurfaceError};

/// What a task does to its tile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum Step {
    /// Radius outlier removal [RS eq. 13].
    Radius(RadiusOutlierParams),
    /// The statistical filter's first half: d̄_i of the tile's points
    /// [RS eq. 14], written beside the stage's files for the driver's sums.
    Distances { mean_k: usize },
    /// Its second half: the cut [RS eq. 15]–[RS eq. 16] the sums give.
    Cut {
        sums: DistanceSums,
        params: StatisticalOutlierParams,
    },
    /// The voxel grid [RS eq. 17]–[RS eq. 18].
    Voxel(VoxelGridParams),
    /// One pass of bilateral normal smoothing [RS eq. 19]–[RS eq. 20].
    Smooth(BilateralParams),
}

impl Step {
    pub fn stage(&self) -> &'static str {
        match self {
            Step::Radius(_) => "radius",
            Step::Distances { .. } | Step::Cut { .. } => "statistical",
            Step::Voxel(_) => "voxel",
            Step::Smooth(_) => "smooth",
        }
    }
}

/// One tile's work in one stage of a tiled run: serialisable (serde), so
/// that it can be sent to another process or machine and run there by
/// [`run_tile_task`]. Its files are named by absolute path, in the run's
/// working folder ([`super::TileOptions::work_dir`]), which every worker
/// must see.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TileTask {
    pub(super) tile: usize,
    pub(super) step: Step,
    /// The stage folder read.
    pub(super) input: PathBuf,
    /// The stage folder written (unused by `Distances`).
    pub(super) output: PathBuf,
    pub(super) grid: TileLayout,
    pub(super) halo_m: f64,
    pub(super) memory_limit: u64,
    /// Points of every tile's own file in `input` (the statistical filter
    /// reads past the halo).
    pub(super) own: Vec<u64>,
    /// This tile's halo pieces in `input`.
    pub(super) halo: Vec<(Writer, u64)>,
}

impl TileTask {
    /// The tile's index (row-major over the grid).
    pub fn tile(&self) -> usize {
        self.tile
    }

    /// The stage: "radius", "statistical", "voxel" or "smooth".
    pub fn stage(&self) -> &'static str {
        self.step.stage()
    }

    /// Points the tile holds with its halo (what its memory follows).
    pub fn points(&self) -> u64 {
        self.own[self.tile] + self.halo.iter().map(|h| h.1).sum::<u64>()
    }

    /// Working memory the task needs (bytes) (its points at
    /// [`BYTES_PER_POINT`]).
    pub fn need(&self) -> u64 {
        self.points().saturating_mul(BYTES_PER_POINT)
    }
}

/// What a task did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TileReport {
    /// The tile.
    pub tile: usize,
    /// Its own points written for the next stage (d̄_i written, for the
    /// statistical filter's first half).
    pub kept: u64,
    /// The halo pieces written: the tile each went to, and its points.
    pub halo: Vec<(usize, u64)>,
    /// Points loaded with the halo.
    pub loaded: u64,
    /// Points searched again past the halo (the statistical filter).
    pub researched: u64,
}

/// Runs a stage's tasks and returns their reports, one for each task, in
/// any order. Tasks of one stage are independent: they may run one after
/// another, at once, or on other machines that see the run's folder.
pub trait TileExecutor {
    /// Runs `tasks`, all of stage `stage`; `progress(stage, done, total)`
    /// may report them.
    fn run(
        &mut self,
        stage: &str,
        tasks: Vec<TileTask>,
        progress: &mut dyn FnMut(&str, u64, u64),
    ) -> Result<Vec<TileReport>>;
}

/// Tasks in this process: as many at once as rayon has threads, while
/// the tiles running fit the memory limit together (each tile's loaded
/// points at [`BYTES_PER_POINT`]); a tile too large to share the limit
/// runs alone. Each tile's filters use every core too, so one tile's
/// serial parts (reading and writing its files, merging its halo) overlap
/// another's parallel ones. A failed task stops the handing out; the
/// error of the first failed task in the stage's order is returned.
#[derive(Debug, Clone, Copy, Default)]
pub struct InProcess;

impl TileExecutor for InProcess {
    fn run(
        &mut self,
        stage: &str,
        tasks: Vec<TileTask>,
        progress: &mut dyn FnMut(&str, u64, u64),
    ) -> Result<Vec<TileReport>> {
        let n = tasks.len() as u64;
        progress(stage, 0, n);
        let workers = rayon::current_num_threads().min(tasks.len());
        if workers <= 1 {
            let mut reports = Vec::with_capacity(tasks.len());
            for (i, task) in tasks.iter().enumerate() {
                reports.push(run_tile_task(task)?);
                progress(stage, i as u64 + 1, n);
            }
            return Ok(reports);
        }
        let limit = tasks.iter().map(|t| t.memory_limit).min().unwrap_or(0);
        let gate = Gate::new(tasks.iter().map(TileTask::need).collect(), limit);
        let (sent, got) = mpsc::channel();
        std::thread::scope(|scope| {
            for _ in 0..workers {
                let sent = sent.clone();
                let (gate, tasks) = (&gate, &tasks);
                scope.spawn(move || {
                    while let Some(i) = gate.claim() {
                        // A panic is the task's error, and its memory is
                        // released: the other workers never wait for it.
                        let report = std::panic::catch_unwind(|| run_tile_task(&tasks[i]))
                            .unwrap_or_else(|payload| {
                                Err(SurfaceError::TileExecutor {
                                    stage: stage.into(),
                                    problem: format!(
                                        "the task of tile {} failed: {}",
                                        tasks[i].tile,
                                        autoshovel_core::panic_message(payload.as_ref())
                                            .unwrap_or_else(|| "a panic".into())
                                    ),
                                })
                            });
                        gate.release(i, report.is_err());
                        if sent.send((i, report)).is_err() {
                            return;
                        }
                    }
                });
            }
            drop(sent);
            let mut reports = Vec::with_capacity(tasks.len());
            let mut failed: Option<(usize, SurfaceError)> = None;
            for (i, report) in got {
                match report {
                    Ok(r) => reports.push(r),
                    Err(e) if failed.as_ref().is_none_or(|f| i < f.0) => failed = Some((i, e)),
                    Err(_) => {}
                }
                progress(stage, reports.len() as u64, n);
            }
            match failed {
                Some((_, e)) => Err(e),
                None => Ok(reports),
            }
        })
    }
}

/// Hands out [`InProcess`]'s tasks in order, each when its memory fits
/// beside those running (or nothing runs).
struct Gate {
    need: Vec<u64>,
    limit: u64,
    state: Mutex<GateState>,
    freed: Condvar,
}

#[derive(Default)]
struct GateState {
    next: usize,
    running: usize,
    in_use: u64,
    failed: bool,
}

impl Gate {
    fn new(need: Vec<u64>, limit: u64) -> Self {
        Self {
            need,
            limit,
            state: Mutex::new(GateState::default()),
            freed: Condvar::new(),
        }
    }

    /// The next task to run, once it fits; `None` when all are handed out
    /// or one failed.
    fn claim(&self) -> Option<usize> {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if s.failed || s.next >= self.need.len() {
                return None;
            }
            let need = self.need[s.next];
            if s.running == 0 || s.in_use.saturating_add(need) <= self.limit {
                let i = s.next;
                s.next += 1;
                s.running += 1;
                s.in_use += need;
                return Some(i);
            }
            s = self.freed.wait(s).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// Task `i` is done (or failed).
    fn release(&self, i: usize, failed: bool) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        s.running -= 1;
        s.in_use -= self.need[i];
        s.failed |= failed;
        drop(s);
        self.freed.notify_all();
    }
}

/// Runs one tile's work of one stage (module docs): reads its tile and
/// halo from the stage's files, writes its survivors and their halo copies
/// for the next stage, and says what it did. The same task run twice
/// writes the same files.
pub fn run_tile_task(task: &TileTask) -> Result<TileReport> {
    let t = task.tile;
    if t >= task.grid.tiles() || task.own.len() != task.grid.tiles() {
        return Err(SurfaceError::TileExecutor {
            stage: task.stage().into(),
            problem: format!(
                "task of tile {t} does not fit its grid of {} tiles ({} counts)",
                task.grid.tiles(),
                task.own.len()
            ),
        });
    }
    let filed = |kept: Vec<Rec>, loaded: u64| -> Result<TileReport> {
        let halo = file_tile(&task.output, &task.grid, t, &kept, task.halo_m)?;
        Ok(TileReport {
            tile: t,
            kept: kept.len() as u64,
            halo,
            loaded,
            researched: 0,
        })
    };
    match &task.step {
        Step::Radius(params) => {
            let loaded = load(task)?;
            let kept = match radius_outlier_removal_indices(&loaded.cloud(), params) {
                Ok(kept) => kept,
                Err(CloudError::Emptied { .. }) => Vec::new(),
                Err(e) => return Err(filter_err("radius", e)),
            };
            let kept = kept
                .into_iter()
                .filter(|&i| loaded.own[i])
                .map(|i| loaded.recs[i])
                .collect();
            filed(kept, loaded.recs.len() as u64)
        }
        Step::Distances { mean_k } => distances(task, *mean_k),
        Step::Cut { sums, params } => {
            let own = read_checked(&own_path(&task.input, t), task.own[t])?;
            let bytes = read_bytes_checked(&dist_path(&task.input, t), task.own[t], DIST_RECORD)?;
            let cut = sums.cut(params);
            let kept = own
                .into_iter()
                .zip(bytes.chunks_exact(DIST_RECORD))
                .filter(|(_, b)| cut.keeps(f32_at(b, 8)))
                .map(|(r, _)| r)
                .collect();
            filed(kept, task.own[t])
        }
        Step::Voxel(params) => {
            let loaded = load(task)?;
            let cells = VoxelCells::new(params).map_err(|e| filter_err("voxel", e))?;
            let kept = voxels_of_tile(&loaded, params, &cells)?;
            filed(kept, loaded.recs.len() as u64)
        }
        Step::Smooth(params) => {
            let loaded = load(task)?;
            let moved = bilateral_normal_smoothing(&loaded.cloud(), params)
                .map_err(|e| filter_err("smooth", e))?;
            let kept = loaded
                .recs
                .iter()
                .zip(&moved.points)
                .zip(&loaded.own)
                .filter(|(_, &own)| own)
                .map(|((r, q), _)| Rec { id: r.id, p: *q })
                .collect();
            filed(kept, loaded.recs.len() as u64)
        }
    }
}

pub(super) fn filter_err(stage: &'static str, source: CloudError) -> SurfaceError {
    SurfaceError::Filter { stage, source }
}

/// The error of a tile (or search) over the memory limit.
fn too_large(task: &TileTask, tile: String, points: u64) -> SurfaceError {
    SurfaceError::TileTooLarge {
        tile,
        points,
        need: config::bytes((points * BYTES_PER_POINT) as f64),
        limit: config::bytes(task.memory_limit as f64),
    }
}

/// The task's tile with its halo, checked against the memory limit.
fn load(task: &TileTask) -> Result<Loaded> {
    let t = task.tile;
    let points = task.points();
    if task.need() > task.memory_limit {
        return Err(too_large(task, task.grid.name(t), points));
    }
    let own = read_checked(&own_path(&task.input, t), task.own[t])?;
    let mut halo = Vec::new();
    for &(writer, n) in &task.halo {
        halo.extend(read_checked(&halo_path(&task.input, t, writer), n)?);
    }
    Ok(Loaded::merge(own, halo))
}

/// The statistical filter's d̄_i [RS eq. 14] of a tile's own points,
/// searched again past the halo where a point's k-th neighbour lies
/// farther than the halo vouches for; written, in survey order, to the
/// tile's `dist-{t}` in the input stage's folder.
fn distances(task: &TileTask, k: usize) -> Result<TileReport> {
    let t = task.tile;
    let (grid, halo_m) = (&task.grid, task.halo_m);
    let loaded = load(task)?;
    let cloud = loaded.cloud();
    // Fewer points than k + 1 in the tile and halo: every own point is
    // searched again.
    let found = if cloud.len() > k {
        mean_distances_and_reach(&cloud.points, k).map_err(|e| filter_err("statistical", e))?
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
        // Points not loaded lie more than `halo` from the box, so more
        // than halo − gap from this point.
        let vouched = halo_m - grid.gap(t, &r.p);
        if f64::from(reach2).sqrt() * (1.0 + 1e-6) > vouched {
            unsure.push((own.len(), f64::from(reach2).sqrt() + grid.gap(t, &r.p)));
        }
        own.push((r.id, r.p, d));
    }
    let loaded_points = loaded.recs.len() as u64;
    drop((loaded, cloud, found));
    if !unsure.is_empty() {
        // Every point within the farthest reach, from the tiles' own
        // files (complete out to that distance).
        let reach = unsure
            .iter()
            .map(|u| u.1)
            .fold(0.0_f64, f64::max)
            .min(f64::from(f32::MAX));
        let mut wide: Vec<Point> = read_checked(&own_path(&task.input, t), task.own[t])?
            .iter()
            .map(|r| r.p)
            .collect();
        for u in grid.around(t, reach + halo_m) {
            if task.own[u] == 0 {
                continue;
            }
            wide.extend(
                read_checked(&own_path(&task.input, u), task.own[u])?
                    .iter()
                    .filter(|r| grid.gap(t, &r.p) <= reach * (1.0 + 1e-6))
                    .map(|r| r.p),
            );
            let points = wide.len() as u64;
            if points * BYTES_PER_POINT > task.memory_limit {
                let what = format!(
                    "{} (searching {} outlier(s) {} m wide)",
                    grid.name(t),
                    unsure.len(),
                    config::approx(reach)
                );
                return Err(too_large(task, what, points));
            }
        }
        let queries: Vec<Point> = unsure.iter().map(|u| own[u.0].1).collect();
        let exact = mean_distances_and_reach_at(&wide, &queries, k)
            .map_err(|e| filter_err("statistical", e))?;
        for (u, (d, _)) in unsure.iter().zip(exact) {
            own[u.0].2 = d;
        }
    }
    let mut bytes = Vec::with_capacity(own.len() * DIST_RECORD);
    for (id, _, d) in &own {
        bytes.extend_from_slice(&id.to_le_bytes());
        bytes.extend_from_slice(&d.to_le_bytes());
    }
    write_whole(&dist_path(&task.input, t), &bytes)?;
    Ok(TileReport {
        tile: t,
        kept: own.len() as u64,
        halo: Vec::new(),
        loaded: loaded_points,
        researched: unsure.len() as u64,
    })
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

    /// Runs `need`'s tasks through a gate of `limit` on `workers` threads,
    /// failing task `fail`; returns how often each ran and the most memory
    /// in use while more than one ran.
    fn through_gate(
        need: &[u64],
        limit: u64,
        workers: usize,
        fail: Option<usize>,
    ) -> (Vec<usize>, u64) {
        let gate = Gate::new(need.to_vec(), limit);
        let ran: Vec<AtomicUsize> = need.iter().map(|_| AtomicUsize::new(0)).collect();
        let (in_use, running, shared_peak) =
            (AtomicU64::new(0), AtomicUsize::new(0), AtomicU64::new(0));
        std::thread::scope(|scope| {
            for _ in 0..workers {
                scope.spawn(|| {
                    while let Some(i) = gate.claim() {
                        let now = in_use.fetch_add(need[i], Ordering::SeqCst) + need[i];
                        if running.fetch_add(1, Ordering::SeqCst) > 0 {
                            shared_peak.fetch_max(now, Ordering::SeqCst);
                        }
                        ran[i].fetch_add(1, Ordering::SeqCst);
                        // The failing task ends at once, the others later.
                        if fail != Some(i) {
                            std::thread::sleep(std::time::Duration::from_millis(10));
                        }
                        running.fetch_sub(1, Ordering::SeqCst);
                        in_use.fetch_sub(need[i], Ordering::SeqCst);
                        gate.release(i, fail == Some(i));
                    }
                });
            }
        });
        (
            ran.iter().map(|r| r.load(Ordering::SeqCst)).collect(),
            shared_peak.load(Ordering::SeqCst),
        )
    }

    #[test]
    fn the_gate_hands_out_every_task_once_and_shares_only_what_fits() {
        // Tasks 3 and 6 alone exceed the limit: they run, but alone.
        let need = [30, 50, 20, 120, 10, 60, 140, 40, 70, 5];
        let (ran, peak) = through_gate(&need, 100, 4, None);
        assert_eq!(ran, vec![1; need.len()]);
        assert!(
            peak <= 100,
            "{peak} bytes in use by tasks sharing a limit of 100"
        );
    }

    #[test]
    fn a_failed_task_stops_the_handing_out() {
        let need = [10; 40];
        let (ran, _) = through_gate(&need, 1000, 2, Some(3));
        assert!(ran.iter().all(|&r| r <= 1));
        assert_eq!(ran[3], 1);
        // Once task 3 failed, only a task already claimed beside it may run.
        let after: usize = ran[4..].iter().sum();
        assert!(after <= 1, "{after} tasks ran after the failure");
    }
}
