//! Roll and pitch of the sensor from the floor (SPEC §4.1: "also estimate α, β
//! from the floor, since a user rarely knows them"), for the horizontal
//! calibration of [RS eq. 11]–12.
//!
//! The floor is found without assuming how much of the scan it is or where it
//! lies: it is **the plane with the most points that has (almost) nothing
//! below it** — the ground the machine and the pile stand on. A pile's flat
//! top holds many points too, but the floor and the face are below it; a
//! plane along a gentle part of the face has fewer points on it than the
//! floor as long as the floor is a few per cent of the scan.
//!
//! 1. Work on a seeded random subset of at most
//!    [`RansacParams::max_scored_points`] points, drawn by a hash of each
//!    point's coordinates and the seed, in that hash's order: the same
//!    points in another order (LAS, LAZ, COPC, a shuffled copy) give the
//!    same subset in the same order, so the same estimate.
//! 2. Hypotheses (RANSAC, Fischler & Bolles 1981, with *local* sampling as in
//!    NAPSAC, Myatt et al. 2002): a seed point and two more from its
//!    neighbourhood on an x–y grid (about 32 points a cell). A floor that is
//!    a share w of the points is then hit by about w of the draws, where three
//!    independent draws would need w³: 5 % of floor needs a few hundred
//!    hypotheses, not 55 000.
//! 3. Each hypothesis within [`RansacParams::max_tilt_rad`] of horizontal is
//!    grown: its inliers (within [`RansacParams::inlier_threshold_m`]) are
//!    refitted by orthogonal least squares and gathered again until they stop
//!    growing (a local plane from a patch extends to the whole floor).
//! 4. A grown plane is a floor candidate only if at most
//!    [`TiltParams::max_below_share`] of the points lie more than
//!    [`TiltParams::below_margin`] thresholds below it (multipath returns, a
//!    puddle); the candidate with the most inliers wins. Draws stop when the
//!    confidence [`RansacParams::confidence`] is reached for the best
//!    candidate's share (or at [`RansacParams::max_iterations`]).
//! 5. The winner is refined on *all* points ([`RansacParams::refine_rounds`]
//!    least-squares rounds) and must hold [`TiltParams::min_floor_share`] of
//!    them, or the scan has no floor to find ([`SurfaceError::NoFloor`]).
//! 6. The angles that level it: `T(α, β) · n = e_z`, i.e. `α = −asin n_y`,
//!    `β = atan2(n_x, n_z)` ([`crate::angles_from_normal`]). After
//!    [`crate::level`] with them the floor is the horizontal plane `z = d`.

use std::collections::HashMap;

use autoshovel_point_cloud::simd::Isa;
use autoshovel_point_cloud::PointCloud;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::calibrate::angles_from_normal;
use crate::error::{Result, SurfaceError};
use crate::ransac::{inliers_of, least_squares_plane, plane_through, Plane, RansacParams};

/// Largest tilt of the floor in the sensor's frame by default (deg): a
/// sensor is mounted within a few degrees of level, and a muck pile's face
/// stands at 35–45° (its gentlest parts, a concave toe, near 20°), so a
/// plane along the face is not taken for the floor.
pub const MAX_FLOOR_TILT_DEG: f64 = 15.0;
/// Mean points per cell of the grid the local triples are drawn from.
const POINTS_PER_CELL: f64 = 32.0;
/// Cell of the grid on which the ground's rises are found, in inlier
/// thresholds (0.4 m at a mine face's 5 cm).
const RISE_CELL: f64 = 8.0;
/// How far above the plane a point still counts as the foot of a rise, in
/// inlier thresholds.
const RISE_BAND: f64 = 4.0;
/// Fewest hypotheses drawn, whatever the confidence says.
const MIN_HYPOTHESES: usize = 16;
/// Most growing rounds of one hypothesis.
const GROW_ROUNDS: usize = 6;

/// Parameters of [`estimate_tilt`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct TiltParams {
    /// Smallest share of all points the floor must hold, in (0, 1]. Default
    /// 0.03: a floor of 5 % of the scan is found; less is reported as no floor.
    pub min_floor_share: f64,
    /// Largest share of the points that may lie below the floor, in [0, 1).
    /// Default 0.02 (multipath returns, puddles, a rut).
    pub max_below_share: f64,
    /// How far below a plane a point must be to count as below it, in inlier
    /// thresholds (> 0). Default 3.
    pub below_margin: f64,
    /// The plane search (threshold, confidence, hypothesis cap, subset size,
    /// largest tilt — default [`MAX_FLOOR_TILT_DEG`] here —, refinement
    /// rounds, seed).
    pub ransac: RansacParams,
}

impl Default for TiltParams {
    fn default() -> Self {
        Self {
            min_floor_share: 0.03,
            max_below_share: 0.02,
            below_margin: 3.0,
            ransac: RansacParams {
                max_tilt_rad: MAX_FLOOR_TILT_DEG.to_radians(),
                ..RansacParams::default()
            },
        }
    }
}

impl TiltParams {
    /// The defaults for a scene of this length scale (1 for a mine face,
    /// 1/30 for the paper's model): the inlier threshold scales with it.
    pub fn for_scale(scale: f64) -> Self {
        let mut p = Self::default();
        p.ransac.inlier_threshold_m *= scale;
        p
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
        if !(self.min_floor_share > 0.0 && self.min_floor_share <= 1.0) {
            return bad(
                "TiltParams.min_floor_share",
                self.min_floor_share,
                "a share in (0, 1]",
            );
        }
        if !(self.max_below_share >= 0.0 && self.max_below_share < 1.0) {
            return bad(
                "TiltParams.max_below_share",
                self.max_below_share,
                "a share in [0, 1)",
            );
        }
        if !(self.below_margin.is_finite() && self.below_margin > 0.0) {
            return bad(
                "TiltParams.below_margin",
                self.below_margin,
                "a number of inlier thresholds > 0",
            );
        }
        self.ransac.validate()
    }
}

/// The sensor attitude found from the floor.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TiltEstimate {
    /// Roll α of [RS eq. 11] (rad): pass to [`crate::level`].
    pub roll_rad: f64,
    /// Pitch β of [RS eq. 11] (rad): pass to [`crate::level`].
    pub pitch_rad: f64,
    /// Height of the floor in the levelled cloud (m) (negative the sensor's
    /// height above the floor for a sensor-centred scan).
    pub floor_height_m: f64,
    /// Unit floor normal in sensor coordinates, pointing up.
    pub normal: [f64; 3],
    /// Points on the floor plane (within the inlier threshold).
    pub inliers: usize,
    /// Points searched (the whole cloud).
    pub candidates: usize,
    /// Points more than the below margin under the floor.
    pub below: usize,
    /// Root-mean-square distance of the floor inliers from the plane (m).
    pub rms_m: f64,
    /// Hypotheses drawn.
    pub iterations: usize,
}

/// Estimate roll α and pitch β of [RS eq. 11] from the floor of a raw scan (see
/// the module docs). Same seed, same estimate.
///
/// ```
/// use autoshovel_terrain::{estimate_tilt, generate_pile, level, PileParams, TiltParams};
/// let scan = generate_pile(&PileParams { points: 20_000, ..PileParams::default() }).unwrap();
/// let est = estimate_tilt(&scan, &TiltParams::default()).unwrap();
/// assert!((est.roll_rad.to_degrees() - 3.0).abs() < 0.02);
/// assert!((est.pitch_rad.to_degrees() + 2.0).abs() < 0.02);
/// let levelled = level(&scan, est.roll_rad, est.pitch_rad);
/// # assert_eq!(levelled.len(), scan.len());
/// ```
pub fn estimate_tilt(cloud: &PointCloud, params: &TiltParams) -> Result<TiltEstimate> {
    params.validate()?;
    let n = cloud.len();
    if n < 3 {
        return Err(SurfaceError::TooFewPoints {
            stage: "floor estimate",
            points: n,
            required: 3,
            hint: "",
        });
    }
    let r = &params.ransac;
    let mut rng = ChaCha8Rng::seed_from_u64(r.seed);
    let subset = by_coordinates(&cloud.points, r.max_scored_points, r.seed);
    let scored: Vec<[f64; 3]> = subset.iter().map(|&i| to_f64(&cloud.points[i])).collect();
    let grid = CellBuckets::new(&scored);
    let min_nz = r.max_tilt_rad.cos() - 1e-12;
    let threshold = r.inlier_threshold_m;
    let below_m = params.below_margin * threshold;
    let max_below = (params.max_below_share * scored.len() as f64).floor() as usize;
    let log_fail = (1.0 - r.confidence).ln();

    let mut best: Option<(Plane, usize)> = None;
    let mut needed = r.max_iterations;
    let mut iterations = 0;
    let limit = |needed: usize| needed.max(MIN_HYPOTHESES.min(r.max_iterations));
    // The hypotheses are drawn in order from the one generator, whatever
    // the draws before them gave, so a batch of them is drawn, grown and
    // counted in parallel, then taken in order as one after another would
    // be: the same estimate and count of draws (the batch's draws past the
    // last taken are dropped; nothing draws after). Four a thread: with one
    // a thread, the search took as long on two threads as on one (each
    // batch waits for its slowest hypothesis); 10 → 7.5 ms at 1 M points.
    let batch = 4 * rayon::current_num_threads().max(1);
    while iterations < limit(needed) {
        let draws: Vec<Option<Plane>> = (0..batch.min(limit(needed) - iterations))
            .map(|_| grid.local_plane(&scored, &mut rng))
            .collect();
        let grown: Vec<Option<(Plane, usize)>> = draws
            .into_par_iter()
            .map(|plane| {
                let plane = plane.filter(|plane| plane.normal[2] >= min_nz)?;
                grow(&scored, plane, threshold, min_nz)
            })
            .collect();
        for hypothesis in grown {
            if iterations >= limit(needed) {
                break;
            }
            iterations += 1;
            let Some((plane, count)) = hypothesis else {
                continue;
            };
            // The points below counted only for a plane that would be the
            // best (a few of the draws): a pass over the subset each.
            if matches!(best, Some((_, c)) if c >= count)
                || count_below(&scored, &plane, below_m) > max_below
            {
                continue;
            }
            best = Some((plane, count));
            // A draw lands on the floor with probability ≈ w (its share),
            // and about half of those grow to it.
            let w = 0.5 * count as f64 / scored.len() as f64;
            let k = (log_fail / (1.0 - w).ln()).ceil();
            if k.is_finite() && k >= 1.0 {
                needed = needed.min(k as usize);
            }
        }
    }
    let required = ((params.min_floor_share * n as f64).ceil() as usize).max(3);
    let no_floor = |inliers| SurfaceError::NoFloor {
        inliers,
        candidates: n,
        required,
        max_tilt_deg: r.max_tilt_rad.to_degrees(),
    };
    let Some((mut plane, _)) = best else {
        return Err(no_floor(0));
    };

    // Refine on every point, away from where the ground rises: each plane
    // in one pass over the cloud (its inliers, where the ground rises off
    // it, the points below it), the f32 points widened as they are read.
    let at = |i: usize| to_f64(&cloud.points[i]);
    let all_grid = CellBuckets::with_cell(&cloud.points, to_f64, RISE_CELL * threshold, false);
    let mut split = Split::of(&cloud.points, &all_grid.of, &plane, threshold, below_m);
    for _ in 0..r.refine_rounds {
        let flat = all_grid.away_from_rises(&split.rising, &split.inliers);
        let every;
        let used: &[usize] = if flat.len() >= 3 {
            &flat
        } else {
            every = split.inliers.concat();
            &every
        };
        match plane_through(used, at) {
            Some(refined) if refined.normal[2] >= min_nz => plane = refined,
            _ => break,
        }
        split = Split::of(&cloud.points, &all_grid.of, &plane, threshold, below_m);
    }
    let (inliers, below) = (split.count(), split.below);
    if inliers < required {
        return Err(no_floor(inliers));
    }
    let rms_m = (split
        .inliers
        .iter()
        .flatten()
        .map(|&i| plane.signed_distance(at(i)).powi(2))
        .sum::<f64>()
        / inliers as f64)
        .sqrt();
    let (roll_rad, pitch_rad) =
        angles_from_normal(plane.normal).expect("a fitted plane has a unit normal");
    Ok(TiltEstimate {
        roll_rad,
        pitch_rad,
        floor_height_m: plane.offset_m,
        normal: plane.normal,
        inliers,
        candidates: n,
        below,
        rms_m,
        iterations,
    })
}

/// What one plane makes of the whole cloud, in one pass.
struct Split {
    /// The points within the threshold of it, ascending, in parts (one a
    /// chunk of the cloud, in order: put together, they were a serial
    /// copy of a third of the cloud each time).
    inliers: Vec<Vec<usize>>,
    /// The cell of each point just above the inlier band (up to
    /// [`RISE_BAND`] thresholds above the plane), in no order.
    rising: Vec<u32>,
    /// The points more than the below margin under it.
    below: usize,
}

impl Split {
    /// The split of `points` (filed in the cells `of`) by `plane`.
    fn of(points: &[[f32; 3]], of: &[u32], plane: &Plane, threshold: f64, below_m: f64) -> Self {
        Self::of_on(Isa::best(), points, of, plane, threshold, below_m)
    }

    /// [`Split::of`] on the path of `isa` (AVX-512: `wide::avx512`).
    fn of_on(
        isa: Isa,
        points: &[[f32; 3]],
        of: &[u32],
        plane: &Plane,
        threshold: f64,
        below_m: f64,
    ) -> Self {
        const CHUNK: usize = 1 << 16;
        let rise = RISE_BAND * threshold;
        let parts: Vec<Split> = points
            .par_chunks(CHUNK)
            .zip(of.par_chunks(CHUNK))
            .enumerate()
            .map(|(c, (chunk, cells))| {
                let base = c * CHUNK;
                #[cfg(target_arch = "x86_64")]
                if let Some(t) = isa.avx512() {
                    // SAFETY: `t` proves AVX-512F and POPCNT; the chunks of
                    // the points and of their cells are alike.
                    let (inliers, rising, below) = unsafe {
                        crate::wide::avx512::split(
                            t,
                            chunk,
                            cells,
                            base,
                            (plane.normal, plane.offset_m),
                            [threshold, rise, below_m],
                        )
                    };
                    return Split {
                        inliers: vec![inliers],
                        rising,
                        below,
                    };
                }
                let _ = isa;
                Self::portable(chunk, cells, base, plane, [threshold, rise, below_m])
            })
            .collect();
        let mut all = Split {
            inliers: Vec::with_capacity(parts.len()),
            rising: Vec::new(),
            below: 0,
        };
        for part in parts {
            all.inliers.extend(part.inliers);
            all.rising.extend_from_slice(&part.rising);
            all.below += part.below;
        }
        all
    }

    /// [`Split::of`]'s part of `points` (cells `cells`, the first at index
    /// `first`), on the portable path.
    fn portable(
        points: &[[f32; 3]],
        cells: &[u32],
        first: usize,
        plane: &Plane,
        [threshold, rise, below_m]: [f64; 3],
    ) -> Self {
        const BLOCK: usize = 256;
        // The inliers kept without a branch (about a third of a scan's
        // points, in no pattern a branch predicts), into room for every
        // point of which only the kept are touched.
        let mut inliers: Vec<usize> = Vec::with_capacity(points.len());
        let room = inliers.spare_capacity_mut();
        let (mut kept, mut rising, mut below) = (0, Vec::new(), 0);
        // The distances a block at a time first (a loop with no
        // dependence between points, which runs by vector).
        let mut distance = [0.0_f64; BLOCK];
        for (b, (block, cells)) in points.chunks(BLOCK).zip(cells.chunks(BLOCK)).enumerate() {
            for (d, p) in distance.iter_mut().zip(block) {
                *d = plane.signed_distance(to_f64(p));
            }
            let start = first + b * BLOCK;
            for (j, (&d, &cell)) in distance.iter().zip(cells).enumerate() {
                room[kept].write(start + j);
                kept += usize::from(d.abs() <= threshold);
                if d > threshold && d <= rise {
                    rising.push(cell);
                }
                below += usize::from(d < -below_m);
            }
        }
        // SAFETY: the first `kept` were written (each slot before the
        // count moved past it).
        unsafe { inliers.set_len(kept) };
        Split {
            inliers: vec![inliers],
            rising,
            below,
        }
    }

    /// The number of inliers.
    fn count(&self) -> usize {
        self.inliers.iter().map(Vec::len).sum()
    }
}

/// A point's place in the draw: a hash of its coordinates' bits and the
/// seed (SplitMix64's finaliser), so that which points are drawn, and in
/// which order, depends on where they are and not on where they stand in
/// the file.
fn rank(p: &[f32; 3], seed: u64) -> u64 {
    let mut z = seed ^ 0x9e37_79b9_7f4a_7c15;
    for v in p {
        z = (z ^ u64::from(v.to_bits())).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z ^= z >> 31;
    }
    z = (z ^ (z >> 30)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The (at most) `k` points of lowest [`rank`], in rank order: a random
/// subset, and its order, that are the same for the same points in any
/// order (the same scan as LAS, LAZ, COPC or shuffled levels the same).
/// One parallel pass keeps the points under a rank cut set for about 5 %
/// more than `k`; only those are sorted.
fn by_coordinates(points: &[[f32; 3]], k: usize, seed: u64) -> Vec<usize> {
    let n = points.len();
    let cut = if k >= n {
        u64::MAX
    } else {
        let share = (k as f64 / n as f64 * CUT_SLACK).min(1.0);
        (share * u64::MAX as f64) as u64
    };
    let mut picked: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .filter_map(|(i, p)| {
            let h = rank(p, seed);
            (h <= cut).then_some((h, i as u32))
        })
        .collect();
    if picked.len() < k.min(n) {
        // Unlucky under the cut: rank every point.
        picked = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| (rank(p, seed), i as u32))
            .collect();
    }
    // Equal ranks are equal points: which of them comes first is immaterial.
    picked.par_sort_unstable();
    picked.truncate(k);
    picked.into_iter().map(|(_, i)| i as usize).collect()
}

/// How far past `k / n` the rank cut of [`by_coordinates`] goes: the
/// count under it is binomial, and 5 % over its mean misses `k` with odds
/// far below one in a million for the default 20 000 points.
const CUT_SLACK: f64 = 1.05;

/// The points more than `below_m` under `plane`.
fn count_below(points: &[[f64; 3]], plane: &Plane, below_m: f64) -> usize {
    points
        .iter()
        .map(|p| usize::from(plane.signed_distance(*p) < -below_m))
        .sum()
}

/// `v.floor() as i64` (saturating, 0 for NaN) without the call to libm's
/// `floor` that the baseline x86-64 makes of it (no rounding instruction
/// before SSE4.1): a third of the time of filing a million points.
#[inline]
fn floor_i64(v: f64) -> i64 {
    let t = v as i64;
    t.saturating_sub(i64::from(t as f64 > v))
}

/// A point widened to f64 (exactly).
fn to_f64(p: &[f32; 3]) -> [f64; 3] {
    [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]
}

/// Grow a plane hypothesis: refit its inliers and gather them again until they
/// stop growing. `None` if it tilts past the limit or holds fewer than 3.
fn grow(
    points: &[[f64; 3]],
    mut plane: Plane,
    threshold: f64,
    min_nz: f64,
) -> Option<(Plane, usize)> {
    let mut inliers = inliers_of(points, &plane, threshold);
    for _ in 0..GROW_ROUNDS {
        let refined = least_squares_plane(points, &inliers)?;
        if refined.normal[2] < min_nz {
            return None;
        }
        let next = inliers_of(points, &refined, threshold);
        if next.len() <= inliers.len() {
            break;
        }
        plane = refined;
        inliers = next;
    }
    (inliers.len() >= 3).then_some((plane, inliers.len()))
}

/// The points bucketed on an x–y grid, for drawing triples from one
/// neighbourhood and for finding where the ground rises: cells numbered
/// densely over the box of their keys when it is not much larger than the
/// points (a scan's footprint at these cell sizes), else in the order first
/// met through a hash map of their keys (points kilometres apart); the
/// points of each cell listed by a counting sort, in point order.
/// foldhash's fixed hasher: hashing a million keys with the standard
/// library's SipHash took a third of the levelling; a fixed seed keeps
/// every run alike.
struct CellBuckets {
    cell_m: f64,
    cells: Cells,
    /// Each point's cell.
    of: Vec<u32>,
    /// The points of cell `c`: `members[start[c]..start[c + 1]]` (empty
    /// when not listed).
    start: Vec<u32>,
    members: Vec<u32>,
}

/// How a grid's cells are numbered (see [`CellBuckets`]).
enum Cells {
    /// Cell (x, y) is `(y − y0) · nx + (x − x0)`, over the keys' box.
    Dense { x0: i64, y0: i64, nx: i64, ny: i64 },
    /// In the order first met.
    Hashed(HashMap<(i64, i64), u32, foldhash::fast::FixedState>),
}

/// Dense cells allowed per point before a grid hashes its keys instead.
const DENSE_CELLS_PER_POINT: i128 = 4;

impl Cells {
    /// The number of the cell with key `k`, if the grid has it.
    fn id(&self, k: (i64, i64)) -> Option<u32> {
        match self {
            Cells::Dense { x0, y0, nx, ny } => {
                let (x, y) = (k.0.checked_sub(*x0)?, k.1.checked_sub(*y0)?);
                ((0..*nx).contains(&x) && (0..*ny).contains(&y)).then(|| (y * nx + x) as u32)
            }
            Cells::Hashed(index) => index.get(&k).copied(),
        }
    }

    /// Every cell's key and number.
    fn each(&self, mut f: impl FnMut((i64, i64), usize)) {
        match self {
            Cells::Dense { x0, y0, nx, ny } => {
                for c in 0..(nx * ny) {
                    f((x0 + c % nx, y0 + c / nx), c as usize);
                }
            }
            Cells::Hashed(index) => {
                for (&key, &c) in index {
                    f(key, c as usize);
                }
            }
        }
    }
}

impl CellBuckets {
    fn new(points: &[[f64; 3]]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(f64::MIN_POSITIVE);
        let cell_m = (area * POINTS_PER_CELL / points.len() as f64).sqrt();
        let cell_m = if cell_m.is_finite() && cell_m > 0.0 {
            cell_m
        } else {
            1.0
        };
        Self::with_cell(points, |p| *p, cell_m, true)
    }

    /// Cells of side `cell_m` over the points `at(p)`; with each cell's
    /// points listed when `listed` (for drawing triples; finding rises
    /// needs only counts).
    fn with_cell<P: Sync>(
        points: &[P],
        at: impl Fn(&P) -> [f64; 3] + Sync,
        cell_m: f64,
        listed: bool,
    ) -> Self {
        // The keys are computed where needed, not stored (16 bytes a
        // point, most of this function's time when written out). Their box
        // is the keys of the points' box (a key is monotone in each
        // coordinate), and a NaN coordinate's key is 0.
        let key = |p: &P| Self::key(cell_m, &at(p));
        let none = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2], [false; 2]);
        let (lo, hi, nan) = points
            .par_iter()
            .fold(
                || none,
                |(mut lo, mut hi, mut nan), p| {
                    let v = at(p);
                    for a in 0..2 {
                        lo[a] = lo[a].min(v[a]);
                        hi[a] = hi[a].max(v[a]);
                        nan[a] |= v[a].is_nan();
                    }
                    (lo, hi, nan)
                },
            )
            .reduce(
                || none,
                |(l1, h1, n1), (l2, h2, n2)| {
                    (
                        [l1[0].min(l2[0]), l1[1].min(l2[1])],
                        [h1[0].max(h2[0]), h1[1].max(h2[1])],
                        [n1[0] || n2[0], n1[1] || n2[1]],
                    )
                },
            );
        let (mut lo, mut hi) = (
            Self::key(cell_m, &[lo[0], lo[1], 0.0]),
            Self::key(cell_m, &[hi[0], hi[1], 0.0]),
        );
        if nan[0] {
            (lo.0, hi.0) = (lo.0.min(0), hi.0.max(0));
        }
        if nan[1] {
            (lo.1, hi.1) = (lo.1.min(0), hi.1.max(0));
        }
        let span = |a: i64, b: i64| i128::from(b) - i128::from(a) + 1;
        let dense = !points.is_empty()
            && span(lo.0, hi.0) * span(lo.1, hi.1)
                <= DENSE_CELLS_PER_POINT * points.len() as i128 + 1024;
        let (cells, of, count) = if dense {
            let (nx, ny) = (span(lo.0, hi.0) as i64, span(lo.1, hi.1) as i64);
            let of: Vec<u32> = points
                .par_iter()
                .map(|p| {
                    let k = key(p);
                    ((k.1 - lo.1) * nx + (k.0 - lo.0)) as u32
                })
                .collect();
            let cells = Cells::Dense {
                x0: lo.0,
                y0: lo.1,
                nx,
                ny,
            };
            (cells, of, (nx * ny) as usize)
        } else {
            let mut index: HashMap<(i64, i64), u32, foldhash::fast::FixedState> =
                HashMap::with_hasher(foldhash::fast::FixedState::default());
            let of: Vec<u32> = points
                .iter()
                .map(|p| {
                    let next = index.len() as u32;
                    *index.entry(key(p)).or_insert(next)
                })
                .collect();
            let count = index.len();
            (Cells::Hashed(index), of, count)
        };
        let mut start = vec![0u32; count + 1];
        for &c in &of {
            start[c as usize + 1] += 1;
        }
        for c in 0..count {
            start[c + 1] += start[c];
        }
        let mut members = Vec::new();
        if listed {
            let mut next = start.clone();
            members = vec![0u32; of.len()];
            for (i, &c) in of.iter().enumerate() {
                members[next[c as usize] as usize] = i as u32;
                next[c as usize] += 1;
            }
        }
        Self {
            cell_m,
            cells,
            of,
            start,
            members,
        }
    }

    /// The points of the cell with key `k` (none if it has none).
    fn cell(&self, k: (i64, i64)) -> &[u32] {
        match self.cells.id(k) {
            Some(c) => {
                let c = c as usize;
                &self.members[self.start[c] as usize..self.start[c + 1] as usize]
            }
            None => &[],
        }
    }

    /// The `inliers` of a plane none of whose 3 × 3 cells rises off it
    /// (`rising`: the cells of the points just above its band, from
    /// [`Split`]): a cell rises when at least 3 of its points, and more
    /// than a tenth of them, lie just above the inlier band (up to [`RISE_BAND`] thresholds above
    /// the plane: the foot of a face; dust and spray higher up are not a
    /// rise). This leaves out the floor at the toe of a
    /// pile, where the bottom of the face lies inside the band and would tilt
    /// the plane towards the pile (a bias that grows as the floor's share
    /// of the scan falls).
    fn away_from_rises(&self, rising: &[u32], inliers: &[Vec<usize>]) -> Vec<usize> {
        // Points just above the band (`rising`, their cells), per cell.
        let cells = self.start.len() - 1;
        let mut above = vec![0u32; cells];
        for &c in rising {
            above[c as usize] += 1;
        }
        // Every cell next to (or at) a rising one.
        let mut near = vec![false; cells];
        let rises =
            |above: u32, c: usize| above >= 3 && 10 * above > self.start[c + 1] - self.start[c];
        let mut mark = |key: (i64, i64)| {
            for dx in -1..=1 {
                for dy in -1..=1 {
                    if let Some(n) = self.cells.id((key.0 + dx, key.1 + dy)) {
                        near[n as usize] = true;
                    }
                }
            }
        };
        match self.cells {
            // The cells with points above the band only (a few thousand,
            // where the box holds millions), each once.
            Cells::Dense { x0, y0, nx, .. } => {
                for &c in rising {
                    let c = c as usize;
                    if rises(above[c], c) {
                        above[c] = 0;
                        let i = c as i64;
                        mark((x0 + i % nx, y0 + i / nx));
                    }
                }
            }
            Cells::Hashed(_) => self.cells.each(|key, c| {
                if rises(above[c], c) {
                    mark(key);
                }
            }),
        }
        inliers
            .par_iter()
            .flat_map_iter(|part| part.iter().copied().filter(|&i| !near[self.of[i] as usize]))
            .collect()
    }

    fn key(cell_m: f64, p: &[f64; 3]) -> (i64, i64) {
        (floor_i64(p[0] / cell_m), floor_i64(p[1] / cell_m))
    }

    /// The plane through a random point and two random points of its 3 × 3
    /// cells; `None` if they are too few or collinear.
    fn local_plane(&self, points: &[[f64; 3]], rng: &mut ChaCha8Rng) -> Option<Plane> {
        let i = rng.gen_range(0..points.len());
        let (cx, cy) = Self::key(self.cell_m, &points[i]);
        let near: Vec<usize> = (-1..=1)
            .flat_map(|dx| (-1..=1).map(move |dy| (cx + dx, cy + dy)))
            .flat_map(|k| self.cell(k))
            .map(|&j| j as usize)
            .filter(|&j| j != i)
            .collect();
        if near.len() < 2 {
            return None;
        }
        let a = rng.gen_range(0..near.len());
        let mut b = rng.gen_range(0..near.len() - 1);
        if b >= a {
            b += 1;
        }
        let (p, q, r) = (
            nalgebra::Vector3::from(points[i]),
            nalgebra::Vector3::from(points[near[a]]),
            nalgebra::Vector3::from(points[near[b]]),
        );
        let cross = (q - p).cross(&(r - p));
        let area = cross.norm();
        if area.is_nan() || area <= 1e-9 * (q - p).norm() * (r - p).norm() {
            return None;
        }
        Plane::from_point_normal(p.into(), cross.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::{level, tilt};
    use approx::assert_relative_eq;

    #[test]
    fn the_split_by_a_plane_is_the_same_on_every_path() {
        use rand::{Rng, SeedableRng};
        let plane = Plane::from_point_normal([0.0, 0.0, -2.0], [0.05, 0.02, 1.0]).unwrap();
        let (threshold, below_m) = (0.05, 0.15);
        // Points within, just above (rising), far above and below the
        // plane, a few not numbers, in every count of a step's tail and
        // over more than one chunk.
        for n in (0..=24).chain([1000, 70_001]) {
            let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
            let points: Vec<[f32; 3]> = (0..n)
                .map(|i| {
                    let (x, y) = (rng.gen_range(-8.0..8.0_f64), rng.gen_range(-8.0..8.0_f64));
                    let on = -2.0 - 0.05 * x - 0.02 * y;
                    let z = on + rng.gen_range(-0.3..0.4);
                    if i % 97 == 5 {
                        [f32::NAN, y as f32, z as f32]
                    } else {
                        [x as f32, y as f32, z as f32]
                    }
                })
                .collect();
            let of: Vec<u32> = (0..n as u32).map(|i| i % 13).collect();
            let portable = Split::of_on(Isa::PORTABLE, &points, &of, &plane, threshold, below_m);
            if n >= 1000 {
                assert!(portable.count() > 0 && portable.below > 0 && !portable.rising.is_empty());
            }
            for isa in Isa::available() {
                let got = Split::of_on(isa, &points, &of, &plane, threshold, below_m);
                assert_eq!(
                    got.inliers.concat(),
                    portable.inliers.concat(),
                    "{isa:?}, {n}"
                );
                assert_eq!(got.rising, portable.rising, "{isa:?}, {n}");
                assert_eq!(got.below, portable.below, "{isa:?}, {n}");
            }
        }
    }

    #[test]
    fn floor_i64_is_floor_as_i64() {
        for v in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.999_999,
            -2.000_001,
            1e18,
            -1e18,
            9.3e18,
            -9.3e18,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ] {
            assert_eq!(floor_i64(v), v.floor() as i64, "{v}");
        }
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..10_000 {
            let v: f64 = rng.gen_range(-1e6..1e6) / 0.37;
            assert_eq!(floor_i64(v), v.floor() as i64, "{v}");
        }
    }

    /// A flat patch of `n` points, `per_row` a row at `step` apart, and
    /// the same with a second patch 10 km away (a grid's cells between
    /// them too many to number densely).
    fn patch_and_far(n: u32, per_row: u32, step: [f64; 2]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let patch: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let (x, y) = (i % per_row, i / per_row);
                [f64::from(x) * step[0], f64::from(y) * step[1], 0.0]
            })
            .collect();
        let mut far = patch.clone();
        far.extend(patch.iter().map(|p| [p[0] + 1e4, p[1] - 1e4, 1.0]));
        (patch, far)
    }

    #[test]
    fn cells_list_their_points_numbered_densely_or_hashed() {
        // One patch (dense numbering), and the same with a second patch
        // 10 km away (too many cells between: hashed); each cell lists
        // exactly the points whose key is its own, in point order.
        let (patch, far) = patch_and_far(500, 23, [0.37, 0.29]);
        // A point with a NaN coordinate is filed where its key says (0).
        let mut odd = patch
            .iter()
            .map(|p| [p[0] + 3.0, p[1] + 2.0, 0.0])
            .collect::<Vec<_>>();
        odd.push([f64::NAN, 4.1, 0.0]);
        odd.push([5.2, f64::NAN, 0.0]);
        for (points, dense) in [(patch, true), (far, false), (odd, true)] {
            let grid = CellBuckets::with_cell(&points, |p| *p, 0.5, true);
            assert_eq!(matches!(grid.cells, Cells::Dense { .. }), dense);
            let mut seen = 0;
            grid.cells.each(|key, c| {
                let want: Vec<u32> = (0..points.len() as u32)
                    .filter(|&i| CellBuckets::key(0.5, &points[i as usize]) == key)
                    .collect();
                assert_eq!(grid.cell(key), &want[..]);
                assert!(want.iter().all(|&i| grid.of[i as usize] as usize == c));
                seen += want.len();
            });
            assert_eq!(seen, points.len());
            assert!(grid.cell((-7, 99)).is_empty());
        }
    }

    #[test]
    fn away_from_rises_drops_the_cells_round_a_rise() {
        // Against brute force: an inlier is dropped when a cell within one
        // of its own in x and y holds 3 or more rising points, more than a
        // tenth of its points; on a dense grid and a hashed one.
        let (patch, far) = patch_and_far(600, 30, [0.1, 0.1]);
        for (points, dense) in [(patch, true), (far, false)] {
            let grid = CellBuckets::with_cell(&points, |p| *p, 0.5, true);
            assert_eq!(matches!(grid.cells, Cells::Dense { .. }), dense);
            let is_rising = |i: usize| i.is_multiple_of(7) && i < 300;
            let rising: Vec<u32> = (0..points.len())
                .filter(|&i| is_rising(i))
                .map(|i| grid.of[i])
                .collect();
            let inliers: Vec<usize> = (0..points.len()).filter(|i| !i.is_multiple_of(3)).collect();
            let parts = vec![inliers[..150].to_vec(), inliers[150..].to_vec()];
            let got = grid.away_from_rises(&rising, &parts);
            let key = |i: usize| CellBuckets::key(0.5, &points[i]);
            let rises = |k: (i64, i64)| {
                let all = (0..points.len()).filter(|&i| key(i) == k).count();
                let above = (0..points.len())
                    .filter(|&i| is_rising(i) && key(i) == k)
                    .count();
                above >= 3 && 10 * above > all
            };
            let want: Vec<usize> = inliers
                .iter()
                .copied()
                .filter(|&i| {
                    let (x, y) = key(i);
                    !(-1..=1).any(|dx| (-1..=1).any(|dy| rises((x + dx, y + dy))))
                })
                .collect();
            assert_eq!(got, want);
            assert!(!got.is_empty() && got.len() < inliers.len());
        }
    }

    #[test]
    fn the_estimate_does_not_depend_on_the_order_of_the_points() {
        // A tilted pile scan of more points than are scored, and the same
        // points reversed and interleaved.
        let scan = crate::generate_pile(&crate::PileParams {
            points: 60_000,
            ..Default::default()
        })
        .unwrap();
        let params = TiltParams::default();
        let a = estimate_tilt(&scan, &params).unwrap();
        let n = scan.len();
        let orders: [Vec<usize>; 2] = [
            (0..n).rev().collect(),
            (0..n).map(|i| (i * 7919) % n).collect(),
        ];
        for order in orders {
            let mut seen = vec![false; n];
            order.iter().for_each(|&i| seen[i] = true);
            assert!(seen.iter().all(|&s| s), "a permutation");
            let b = estimate_tilt(&scan.select(&order), &params).unwrap();
            assert!(
                (a.roll_rad - b.roll_rad).abs() < 1e-9,
                "{} {}",
                a.roll_rad,
                b.roll_rad
            );
            assert!((a.pitch_rad - b.pitch_rad).abs() < 1e-9);
            assert_eq!(a.inliers, b.inliers);
            assert_eq!(a.iterations, b.iterations);
        }
    }

    /// A level floor z = −2 (20 × 20 grid) and a wall of points above it.
    fn floor_and_wall() -> PointCloud {
        let mut pts = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                pts.push([i as f32 * 0.25, j as f32 * 0.25 - 5.0, -2.0]);
            }
        }
        for i in 0..40 {
            for k in 1..40 {
                pts.push([
                    10.0 + 0.1 * k as f32,
                    i as f32 * 0.25 - 5.0,
                    -2.0 + k as f32 * 0.2,
                ]);
            }
        }
        PointCloud::new(pts)
    }

    #[test]
    fn exact_floor_gives_exact_angles() {
        let (a, b) = (4f64.to_radians(), (-6f64).to_radians());
        let scan = tilt(&floor_and_wall(), a, b);
        let est = estimate_tilt(&scan, &TiltParams::default()).unwrap();
        assert_relative_eq!(est.roll_rad, a, epsilon = 1e-6);
        assert_relative_eq!(est.pitch_rad, b, epsilon = 1e-6);
        assert_relative_eq!(est.floor_height_m, -2.0, epsilon = 1e-5);
        assert_eq!(est.inliers, 1600);
        // Levelling with the estimate puts the floor at z = floor_height_m.
        let flat = level(&scan, est.roll_rad, est.pitch_rad);
        for p in &flat.points[..1600] {
            assert_relative_eq!(f64::from(p[2]), -2.0, epsilon = 1e-4);
        }
    }

    #[test]
    fn too_few_points_and_bad_fraction_are_errors() {
        let err = estimate_tilt(&PointCloud::default(), &TiltParams::default()).unwrap_err();
        assert!(matches!(err, SurfaceError::TooFewPoints { points: 0, .. }));
        let p = TiltParams {
            min_floor_share: 0.0,
            ..TiltParams::default()
        };
        let err = estimate_tilt(&floor_and_wall(), &p).unwrap_err();
        assert!(
            err.to_string().contains("TiltParams.min_floor_share"),
            "{err}"
        );
    }
}
