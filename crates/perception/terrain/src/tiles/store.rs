//! The working files of a tiled run.
//!
//! A stage's points live in a folder of their own, `s{n}/` under the run's
//! folder: `own-{t}` holds tile `t`'s points, and the copies of other
//! tiles' points that lie within the halo of `t` come in pieces, one per
//! writer: `to-{t}.halo` from the driver's filing of the survey, and
//! `to-{t}.from-{u}` from the task that ran tile `u`. Writers never share
//! a file, so a stage's tiles may run anywhere at once; a piece is written
//! beside its name and moved there whole, so a task run again (a worker
//! lost) leaves the same file. Every file's count is recorded by whoever
//! wrote it and checked by whoever reads it: a worker that does not see
//! the run's folder fails naming the file rather than reading nothing.
//!
//! The first pass over the survey also keeps every point it read, as read
//! (x, y, z as f32, 12 bytes a point), in `read` under the run's folder:
//! the second pass reads them back rather than decoding the files again
//! ([`RawSpill`], [`RawBack`]). When tiles are written it keeps each
//! point's LAS record too, in `rows`, read back by point index for a
//! tile's attributes ([`RowSpill`], [`RowBack`]).

use std::fs::{self, File, OpenOptions};
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use autoshovel_point_cloud::{Point, PointCloud};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Result, SurfaceError};

/// Bytes of a point on disk: its index (u64) and x, y, z (f32), little-endian.
pub(super) const RECORD: usize = 20;

/// Bytes of a mean distance on disk: the point's index (u64) and d̄_i (f32).
pub(super) const DIST_RECORD: usize = 12;

/// Points the driver buffers per tile before appending them to its file.
const FLUSH_POINTS: usize = 1 << 14;

/// Bytes of a point as read: x, y, z (f32), little-endian.
const RAW_RECORD: usize = 12;

/// The points of the first pass, written as they come ([`RawSpill::put`]).
pub(super) struct RawSpill {
    path: PathBuf,
    file: BufWriter<File>,
    bytes: Vec<u8>,
    points: u64,
}

impl RawSpill {
    pub fn create(path: PathBuf) -> Result<Self> {
        let file = File::create(&path).map_err(spill(&path))?;
        Ok(Self {
            file: BufWriter::with_capacity(1 << 20, file),
            path,
            bytes: Vec::new(),
            points: 0,
        })
    }

    /// Appends `points`.
    pub fn put(&mut self, points: &[Point]) -> Result<()> {
        self.bytes.clear();
        for q in points {
            for c in q {
                self.bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        self.file
            .write_all(&self.bytes)
            .map_err(spill(&self.path))?;
        self.points += points.len() as u64;
        Ok(())
    }

    /// Ends the writing; the file, to read back from its start.
    pub fn finish(self) -> Result<RawBack> {
        let (file, len) = reopen(self.file, &self.path)?;
        if len != self.points * RAW_RECORD as u64 {
            return Err(SurfaceError::TileFile {
                path: self.path,
                problem: format!(
                    "holds {len} bytes where {} points were written",
                    self.points
                ),
            });
        }
        Ok(RawBack {
            file: BufReader::with_capacity(1 << 20, file),
            path: self.path,
            left: self.points,
            bytes: Vec::new(),
        })
    }
}

/// Flushes and closes a spill written through `file`, then opens it again
/// to read back from its start; with its length in bytes.
fn reopen(file: BufWriter<File>, path: &Path) -> Result<(File, u64)> {
    drop(file.into_inner().map_err(|e| spill(path)(e.into_error()))?);
    let file = File::open(path).map_err(spill(path))?;
    let len = file.metadata().map_err(spill(path))?.len();
    Ok((file, len))
}

/// The first pass's points read back, a chunk at a time.
pub(super) struct RawBack {
    pub path: PathBuf,
    file: BufReader<File>,
    left: u64,
    bytes: Vec<u8>,
}

impl RawBack {
    /// The next (up to) `max` points into `chunk`; false when none are left.
    pub fn next_chunk(&mut self, chunk: &mut Vec<Point>, max: usize) -> Result<bool> {
        chunk.clear();
        let take = self.left.min(max as u64) as usize;
        if take == 0 {
            return Ok(false);
        }
        self.bytes.resize(take * RAW_RECORD, 0);
        self.file
            .read_exact(&mut self.bytes)
            .map_err(spill(&self.path))?;
        chunk.extend(
            self.bytes
                .chunks_exact(RAW_RECORD)
                .map(|b| [f32_at(b, 0), f32_at(b, 4), f32_at(b, 8)]),
        );
        self.left -= take as u64;
        Ok(true)
    }

    /// Removes the file.
    pub fn remove(self) {
        let _ = fs::remove_file(&self.path);
    }
}

/// The survey's LAS records, a fixed number of bytes a point in survey
/// order, written in the first pass ([`RowSpill::put`]) and read back by
/// point index for the tiles written ([`RowSpill::rows`]): the attributes
/// travel beside the points without the stages carrying them.
pub(super) struct RowSpill {
    path: PathBuf,
    file: BufWriter<File>,
    len: usize,
    points: u64,
}

impl RowSpill {
    /// A spill of `len` bytes a point.
    pub fn create(path: PathBuf, len: usize) -> Result<Self> {
        let file = File::create(&path).map_err(spill(&path))?;
        Ok(Self {
            file: BufWriter::with_capacity(1 << 20, file),
            path,
            len: len.max(1),
            points: 0,
        })
    }

    /// Appends whole records.
    pub fn put(&mut self, rows: &[u8]) -> Result<()> {
        self.file.write_all(rows).map_err(spill(&self.path))?;
        self.points += (rows.len() / self.len) as u64;
        Ok(())
    }

    /// Ends the writing, checking the records against `points`; the file,
    /// to read records back from.
    pub fn finish(self, points: u64) -> Result<RowBack> {
        let (file, bytes) = reopen(self.file, &self.path)?;
        if self.points != points || bytes != points * self.len as u64 {
            return Err(SurfaceError::TileFile {
                path: self.path,
                problem: format!(
                    "holds {bytes} bytes of {}-byte records where {points} points were read",
                    self.len
                ),
            });
        }
        Ok(RowBack {
            file: BufReader::with_capacity(1 << 16, file),
            path: self.path,
            len: self.len,
            points,
            at: 0,
        })
    }
}

/// The survey's records, read back by point index.
pub(super) struct RowBack {
    pub path: PathBuf,
    file: BufReader<File>,
    len: usize,
    points: u64,
    /// The file position the reader is at.
    at: u64,
}

impl RowBack {
    /// The records of the points `ids` (in survey order for speed: a
    /// tile's points are), one after another.
    pub fn rows(&mut self, ids: impl Iterator<Item = u64>) -> Result<Vec<u8>> {
        let mut out = Vec::new();
        for id in ids {
            if id >= self.points {
                return Err(SurfaceError::TileFile {
                    path: self.path.clone(),
                    problem: format!("has no point {id} (it holds {})", self.points),
                });
            }
            let want = id * self.len as u64;
            if want != self.at {
                // Within the buffer when near: a tile's points come in runs.
                let jump = want as i64 - self.at as i64;
                self.file.seek_relative(jump).map_err(spill(&self.path))?;
            }
            let start = out.len();
            out.resize(start + self.len, 0);
            self.file
                .read_exact(&mut out[start..])
                .map_err(spill(&self.path))?;
            self.at = want + self.len as u64;
        }
        Ok(out)
    }

    /// Removes the file.
    pub fn remove(self) {
        let _ = fs::remove_file(&self.path);
    }
}

/// A point on its way: its index in the survey and its position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Rec {
    pub id: u64,
    pub p: Point,
}

/// The tile grid in the levelled (x, y) plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(super) struct TileLayout {
    pub origin: [f64; 2],
    pub side: f64,
    pub size: [usize; 2],
}

impl TileLayout {
    pub fn tiles(&self) -> usize {
        self.size[0] * self.size[1]
    }

    /// The tile of (x, y) (clamped to the grid).
    pub fn tile_of(&self, p: &Point) -> usize {
        let i = |a: usize| {
            (((f64::from(p[a]) - self.origin[a]) / self.side)
                .floor()
                .max(0.0) as usize)
                .min(self.size[a] - 1)
        };
        i(1) * self.size[0] + i(0)
    }

    /// The box of tile `t`: min x, min y, max x, max y.
    pub fn bounds(&self, t: usize) -> [f64; 4] {
        let (ix, iy) = (t % self.size[0], t / self.size[0]);
        let x0 = self.origin[0] + ix as f64 * self.side;
        let y0 = self.origin[1] + iy as f64 * self.side;
        [x0, y0, x0 + self.side, y0 + self.side]
    }

    /// The (x, y) distance from `p` to tile `t`'s box (0 inside).
    pub fn gap(&self, t: usize, p: &Point) -> f64 {
        let b = self.bounds(t);
        let (x, y) = (f64::from(p[0]), f64::from(p[1]));
        let dx = (b[0] - x).max(x - b[2]).max(0.0);
        let dy = (b[1] - y).max(y - b[3]).max(0.0);
        dx.hypot(dy)
    }

    /// The tiles other than `t` whose boxes lie within `reach` of `t`'s
    /// (a relation that is symmetric: `u` is around `t` if `t` is around `u`).
    pub fn around(&self, t: usize, reach: f64) -> Vec<usize> {
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

    /// The tiles whose halo may hold a copy of one of `t`'s points, with
    /// the copies: `recs` lying within `halo_m` of another tile's box.
    pub fn halo_copies(&self, t: usize, recs: &[Rec], halo_m: f64) -> Vec<(usize, Vec<Rec>)> {
        // Only a point within halo_m of its tile's edge (or outside it)
        // can lie within halo_m of another tile's box.
        let b = self.bounds(t);
        let edge: Vec<Rec> = recs
            .iter()
            .filter(|r| {
                let (x, y) = (f64::from(r.p[0]), f64::from(r.p[1]));
                (x - b[0]).min(b[2] - x).min(y - b[1]).min(b[3] - y) <= halo_m
            })
            .copied()
            .collect();
        if edge.is_empty() {
            return Vec::new();
        }
        // Its neighbours within 2 halo_m (points may lie a little outside
        // their tile).
        self.around(t, 2.0 * halo_m)
            .into_iter()
            .map(|u| {
                let copies: Vec<Rec> = edge
                    .iter()
                    .filter(|r| self.gap(u, &r.p) <= halo_m)
                    .copied()
                    .collect();
                (u, copies)
            })
            .filter(|(_, copies)| !copies.is_empty())
            .collect()
    }

    /// Tile `t` in words, for messages.
    pub fn name(&self, t: usize) -> String {
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

/// Who wrote a halo piece: the driver's filing (`None`) or tile `u`'s task.
pub(super) type Writer = Option<usize>;

/// One stage's files (module docs) and the points each holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct StageFiles {
    /// The stage's folder.
    pub dir: PathBuf,
    /// Points of each tile's own file.
    pub own: Vec<u64>,
    /// The halo pieces of each tile: who wrote them, and their points.
    pub halo: Vec<Vec<(Writer, u64)>>,
}

impl StageFiles {
    /// An empty stage `s{n}` of `tiles` tiles under `run`, its folder made.
    pub fn create(run: &Path, n: usize, tiles: usize) -> Result<Self> {
        let dir = run.join(format!("s{n}"));
        fs::create_dir_all(&dir).map_err(|source| SurfaceError::Spill {
            path: dir.clone(),
            source,
        })?;
        Ok(Self {
            dir,
            own: vec![0; tiles],
            halo: vec![Vec::new(); tiles],
        })
    }

    pub fn total(&self) -> u64 {
        self.own.iter().sum()
    }

    /// Removes the stage's folder.
    pub fn remove(&self) {
        let _ = fs::remove_dir_all(&self.dir);
    }

    /// Tile `t`'s own points.
    pub fn read_own(&self, t: usize) -> Result<Vec<Rec>> {
        read_checked(&own_path(&self.dir, t), self.own[t])
    }
}

pub(super) fn own_path(dir: &Path, t: usize) -> PathBuf {
    dir.join(format!("own-{t}"))
}

pub(super) fn halo_path(dir: &Path, t: usize, writer: Writer) -> PathBuf {
    match writer {
        None => dir.join(format!("to-{t}.halo")),
        Some(u) => dir.join(format!("to-{t}.from-{u}")),
    }
}

pub(super) fn dist_path(dir: &Path, t: usize) -> PathBuf {
    dir.join(format!("dist-{t}"))
}

fn spill(path: &Path) -> impl Fn(std::io::Error) -> SurfaceError + '_ {
    move |source| SurfaceError::Spill {
        path: path.to_path_buf(),
        source,
    }
}

fn encode(recs: &[Rec]) -> Vec<u8> {
    let mut bytes = vec![0u8; recs.len() * RECORD];
    bytes
        .par_chunks_exact_mut(RECORD)
        .zip(recs.par_iter())
        .for_each(|(b, r)| {
            b[..8].copy_from_slice(&r.id.to_le_bytes());
            for a in 0..3 {
                b[8 + 4 * a..12 + 4 * a].copy_from_slice(&r.p[a].to_le_bytes());
            }
        });
    bytes
}

/// The little-endian f32 at byte `at` of a working file's record.
#[inline]
pub(super) fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

#[inline]
fn decode(b: &[u8]) -> Rec {
    let f = |at: usize| f32_at(b, at);
    Rec {
        id: u64::from_le_bytes(b[..8].try_into().expect("8 bytes")),
        p: [f(8), f(12), f(16)],
    }
}

/// Writes `bytes` to `path` whole: beside it first, then moved there.
pub(super) fn write_whole(path: &Path, bytes: &[u8]) -> Result<()> {
    // Beside it under its whole name and a suffix (`with_extension` would
    // give `to-7.from-3` and `to-7.from-4` the same one).
    let mut part = path.as_os_str().to_owned();
    part.push(".part");
    let part = PathBuf::from(part);
    fs::write(&part, bytes).map_err(spill(&part))?;
    fs::rename(&part, path).map_err(spill(path))
}

/// Writes a piece of points (nothing when there are none).
pub(super) fn write_recs(path: &Path, recs: &[Rec]) -> Result<()> {
    if recs.is_empty() {
        return Ok(());
    }
    write_whole(path, &encode(recs))
}

/// The bytes of a working file that must hold `expect` records of `size`
/// bytes (none is read, nor need exist, when `expect` is 0).
pub(super) fn read_bytes_checked(path: &Path, expect: u64, size: usize) -> Result<Vec<u8>> {
    if expect == 0 {
        return Ok(Vec::new());
    }
    let bytes = match fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(SurfaceError::TileFile {
                path: path.to_path_buf(),
                problem: format!(
                    "missing (it should hold {expect} points): does every worker see the run's working folder?"
                ),
            })
        }
        Err(e) => return Err(spill(path)(e)),
    };
    if bytes.len() as u64 != expect * size as u64 {
        return Err(SurfaceError::TileFile {
            path: path.to_path_buf(),
            problem: format!(
                "holds {} bytes, {} points' worth, where {expect} points were written",
                bytes.len(),
                bytes.len() / size
            ),
        });
    }
    Ok(bytes)
}

/// The points of a working file that must hold `expect` of them.
pub(super) fn read_checked(path: &Path, expect: u64) -> Result<Vec<Rec>> {
    let bytes = read_bytes_checked(path, expect, RECORD)?;
    Ok(bytes.par_chunks_exact(RECORD).map(decode).collect())
}

/// Writes `recs` (in survey order) as tile `t`'s own points in the stage
/// folder `dir`, with a halo piece for every tile they lie near; returns
/// the pieces' tiles and points.
pub(super) fn file_tile(
    dir: &Path,
    grid: &TileLayout,
    t: usize,
    recs: &[Rec],
    halo_m: f64,
) -> Result<Vec<(usize, u64)>> {
    write_recs(&own_path(dir, t), recs)?;
    let mut pieces = Vec::new();
    for (u, copies) in grid.halo_copies(t, recs, halo_m) {
        write_recs(&halo_path(dir, u, Some(t)), &copies)?;
        pieces.push((u, copies.len() as u64));
    }
    Ok(pieces)
}

/// The driver's filing of the survey into the first stage: points come in
/// survey order a chunk at a time, and each tile's own points and halo are
/// appended to its files through buffers.
pub(super) struct Filing {
    stage: StageFiles,
    own: Vec<Vec<Rec>>,
    halo: Vec<Vec<Rec>>,
}

impl Filing {
    pub fn new(stage: StageFiles) -> Self {
        let tiles = stage.own.len();
        Self {
            stage,
            own: vec![Vec::new(); tiles],
            halo: vec![Vec::new(); tiles],
        }
    }

    /// Files `recs` (in survey order) under tile `t`, with a copy of each
    /// in the halo of every other tile within `halo_m`.
    pub fn put(&mut self, grid: &TileLayout, t: usize, recs: &[Rec], halo_m: f64) -> Result<()> {
        self.own[t].extend_from_slice(recs);
        self.stage.own[t] += recs.len() as u64;
        if self.own[t].len() >= FLUSH_POINTS {
            self.flush_one(t, false)?;
        }
        for (u, copies) in grid.halo_copies(t, recs, halo_m) {
            self.halo[u].extend_from_slice(&copies);
            if self.halo[u].len() >= FLUSH_POINTS {
                self.flush_one(u, true)?;
            }
        }
        Ok(())
    }

    fn flush_one(&mut self, t: usize, halo: bool) -> Result<()> {
        let (path, buf) = if halo {
            (halo_path(&self.stage.dir, t, None), &mut self.halo[t])
        } else {
            (own_path(&self.stage.dir, t), &mut self.own[t])
        };
        if buf.is_empty() {
            return Ok(());
        }
        let mut file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(spill(&path))?;
        file.write_all(&encode(buf)).map_err(spill(&path))?;
        if halo {
            let pieces = &mut self.stage.halo[t];
            match pieces.first_mut() {
                Some(piece) => piece.1 += buf.len() as u64,
                None => pieces.push((None, buf.len() as u64)),
            }
        }
        // A whole tile's points may pass through at once: keep no more
        // than a buffer's worth, or every tile would hold its size.
        buf.clear();
        buf.shrink_to(FLUSH_POINTS);
        Ok(())
    }

    /// Writes every buffer out: the stage as filed.
    pub fn finish(mut self) -> Result<StageFiles> {
        for t in 0..self.own.len() {
            self.flush_one(t, false)?;
            self.flush_one(t, true)?;
        }
        Ok(self.stage)
    }
}

/// A tile with its halo: all points in survey order, and which are its own.
pub(super) struct Loaded {
    pub recs: Vec<Rec>,
    pub own: Vec<bool>,
}

impl Loaded {
    pub fn cloud(&self) -> PointCloud {
        PointCloud::new(self.recs.iter().map(|r| r.p).collect())
    }

    /// Tile `t`'s own points (in survey order) and its halo (in any order).
    pub fn merge(own: Vec<Rec>, mut halo: Vec<Rec>) -> Self {
        halo.sort_unstable_by_key(|r| r.id);
        let (a, b) = (own, halo);
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
        Self { recs, own }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_spilled_come_back_the_same_in_any_chunks() {
        let dir = std::env::temp_dir().join(format!("autoshovel-raw-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let points: Vec<Point> = (0..1000)
            .map(|i| {
                let t = i as f32;
                [t * 0.37 - 100.0, (t * 1.3).sin() * 1e4, -t * 1e-7]
            })
            .collect();
        let mut raw = RawSpill::create(dir.join("read")).unwrap();
        for c in points.chunks(333) {
            raw.put(c).unwrap();
        }
        raw.put(&[]).unwrap();
        let mut back = raw.finish().unwrap();
        let (mut got, mut chunk) = (Vec::new(), Vec::new());
        while back.next_chunk(&mut chunk, 64).unwrap() {
            assert!(!chunk.is_empty() && chunk.len() <= 64);
            got.extend_from_slice(&chunk);
        }
        assert_eq!(got, points);
        back.remove();
        assert!(!dir.join("read").exists());

        // A copy cut short is an error naming it, not fewer points.
        let mut raw = RawSpill::create(dir.join("short")).unwrap();
        raw.put(&points).unwrap();
        let path = raw.path.clone();
        raw.file.flush().unwrap();
        OpenOptions::new()
            .write(true)
            .open(&path)
            .unwrap()
            .set_len(100)
            .unwrap();
        let err = raw
            .finish()
            .err()
            .expect("a short copy is refused")
            .to_string();
        assert!(
            err.contains("short") && err.contains("1000 points"),
            "{err}"
        );
        fs::remove_dir_all(&dir).unwrap();
    }
}
