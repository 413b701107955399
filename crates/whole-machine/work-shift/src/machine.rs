//! The machine's side of a shift: what it knows comes from its scans (as
//! perception cleans and levels them) and its RTK pose. From those it keeps
//! a height model of the pit ([`PileModel`]), cuts dig profiles along its
//! swing angles ([`dig_options`]), chooses its next stand from the face it
//! has perceived ([`next_stands`]) and builds its walking map from its
//! scans ([`walking_map`]). Nothing here reads [`crate::world::World`].

use autoshovel_core::{Pose2, Vec2};
use autoshovel_point_cloud::PointCloud;
use autoshovel_rope_shovel_dig::DigSurface;
use autoshovel_walk_planner::{Map, Obstacle, Shape};

use crate::grid::Layout;

/// Perception as the machine runs it on every scan: the rope-shovel
/// paper's pipeline with its defaults, except that the polynomial surface
/// ([RS eq. 21]) need not pass its R² bar — the machine's pile model is the
/// cleaned cloud on a grid ([`PileModel`]), and a face dug into bays is no
/// polynomial.
pub fn perception() -> autoshovel_terrain::perceive::PerceptionParams {
    let mut p = autoshovel_terrain::perceive::PerceptionParams::default();
    p.fit.r2_threshold = 0.0;
    p
}

/// Returns a cell needs before a scan without perception sets its height.
pub const RAW_RETURNS: usize = 3;

/// Height above which a cell of the model is an obstacle to walking (m).
pub const OBSTACLE_HEIGHT_M: f64 = 0.4;

/// Band width of the walking map's obstacle rectangles (along y) (m).
pub const MAP_BAND_M: f64 = 2.0;

/// Share of the face's height at which the machine reads the face's
/// slope, continued down to the floor, to place its next stand
/// ([`next_stands`]). A dig starts where the profile first rises (the
/// planner's rule for a scan, 3 % of the face: [`autoshovel_rope_shovel_dig::TOE_RISE_SHARE`]),
/// so it takes the low wedge a dug face leaves at its foot; the stand
/// follows the face above it.
pub const FACE_RISE_SHARE: f64 = 0.25;

/// Length of a dig profile from the swing axis (m).
pub const PROFILE_LENGTH_M: f64 = 40.0;

/// How far ahead the machine looks for a face when choosing a stand (m).
pub const LOOK_AHEAD_M: f64 = 90.0;

/// The machine's height model of the pit, from its scans: each cell the
/// mean height above the floor of the cleaned points of the last scan
/// that saw it; a cell the last scan saw only as floor is floor; NaN where
/// no scan has looked.
#[derive(Debug, Clone, PartialEq)]
pub struct PileModel {
    /// Lower-left corner (m).
    pub origin: [f64; 2],
    /// Cell edge (m).
    pub cell_m: f64,
    /// Cells along x and y.
    pub size: [usize; 2],
    /// Heights above the floor (m) (NaN: never seen).
    pub z: Vec<f64>,
}

impl PileModel {
    /// An empty model over the site `min`–`max`.
    pub fn new(min: [f64; 2], max: [f64; 2], cell_m: f64) -> Self {
        let layout = Layout::over(min, max, cell_m);
        Self {
            origin: min,
            cell_m,
            size: layout.size,
            z: vec![f64::NAN; layout.len()],
        }
    }

    /// The cell of (x, y), if inside.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<usize> {
        self.layout().cell_of(x, y)
    }

    /// The centre of cell `k`.
    pub fn centre(&self, k: usize) -> [f64; 2] {
        self.layout().centre(k)
    }

    /// The grid's layout.
    pub fn layout(&self) -> Layout {
        Layout {
            origin: self.origin,
            cell_m: self.cell_m,
            size: self.size,
        }
    }

    /// Folds in one scan: `seen` is the whole scan levelled, `cleaned` what
    /// perception kept of it (both in the levelled sensor frame, the floor
    /// at `floor_z`), taken at `pose` (the machine's own estimate; the
    /// sensor on the swing axis). Returns the cells updated.
    pub fn update(
        &mut self,
        seen: &PointCloud,
        cleaned: &PointCloud,
        floor_z: f64,
        pose: Pose2,
    ) -> usize {
        let (c, s) = (pose.theta.cos(), pose.theta.sin());
        let world = |p: &[f32; 3]| {
            let (x, y) = (f64::from(p[0]), f64::from(p[1]));
            (pose.x + x * c - y * s, pose.y + x * s + y * c)
        };
        // Cells with cleaned points (perception's surface) take the median
        // height of the whole scan's points in them: the cleaned cloud is
        // thinned and smoothed, which rounds off the edges the dipper
        // leaves; the median of the raw returns keeps them and ignores dust.
        let mut count = vec![0u32; self.z.len()];
        for p in &cleaned.points {
            let (x, y) = world(p);
            if let Some(k) = self.cell_of(x, y) {
                count[k] += 1;
            }
        }
        let mut raw: Vec<Vec<f32>> = vec![Vec::new(); self.z.len()];
        let (mut low_sum, mut low_count) = (vec![0.0f64; self.z.len()], vec![0u32; self.z.len()]);
        for p in &seen.points {
            let (x, y) = world(p);
            let Some(k) = self.cell_of(x, y) else {
                continue;
            };
            let h = f64::from(p[2]) - floor_z;
            if count[k] > 0 {
                raw[k].push(h as f32);
            } else if h.abs() < OBSTACLE_HEIGHT_M {
                // Returns near the floor that perception set aside with the
                // ground say "floor, or the foot of the face, here" (dust
                // in the air says nothing about the ground under it).
                low_sum[k] += h;
                low_count[k] += 1;
            }
        }
        let mut sum = vec![0.0f64; self.z.len()];
        for k in 0..self.z.len() {
            if count[k] > 0 {
                let v = &mut raw[k];
                if v.is_empty() {
                    count[k] = 0;
                    continue;
                }
                let mid = v.len() / 2;
                v.select_nth_unstable_by(mid, f32::total_cmp);
                sum[k] = f64::from(v[mid]);
                count[k] = 1;
            }
        }
        let mut updated = 0;
        for k in 0..self.z.len() {
            if count[k] > 0 {
                self.z[k] = (sum[k] / f64::from(count[k])).max(0.0);
                updated += 1;
            } else if low_count[k] > 0 {
                self.z[k] = (low_sum[k] / f64::from(low_count[k])).max(0.0);
                updated += 1;
            }
        }
        updated
    }

    /// Folds in a scan of ground without a face (the machine looking round
    /// before it walks): no perception to keep or set points aside, so each
    /// cell with at least [`RAW_RETURNS`] returns takes their median height
    /// (dust, a few returns in the air, does not move a median of many
    /// floor returns, and a cell that only dust reached is left as it
    /// was); cells within `own_m` of the machine are its own body and
    /// left out. `seen` is levelled with the mounting's tilt perception
    /// found on the face, the floor at `floor_z`.
    pub fn update_raw(
        &mut self,
        seen: &PointCloud,
        floor_z: f64,
        pose: Pose2,
        own_m: f64,
    ) -> usize {
        let (c, s) = (pose.theta.cos(), pose.theta.sin());
        let mut raw: Vec<Vec<f32>> = vec![Vec::new(); self.z.len()];
        for p in &seen.points {
            let (x, y) = (f64::from(p[0]), f64::from(p[1]));
            if let Some(k) = self.cell_of(pose.x + x * c - y * s, pose.y + x * s + y * c) {
                raw[k].push((f64::from(p[2]) - floor_z) as f32);
            }
        }
        let mut updated = 0;
        for (k, v) in raw.iter_mut().enumerate() {
            let [x, y] = self.centre(k);
            if v.len() < RAW_RETURNS || (x - pose.x).hypot(y - pose.y) < own_m {
                continue;
            }
            let mid = v.len() / 2;
            v.select_nth_unstable_by(mid, f32::total_cmp);
            self.z[k] = f64::from(v[mid]).max(0.0);
            updated += 1;
        }
        updated
    }

    /// Lowers the model along a dig the machine made (`cut` in its own
    /// belief of where it stood: its RTK pose, the swing angle and the toe
    /// it planned from), as the dipper lowered the pit: until the next
    /// scan sees the result, the machine expects what it planned.
    pub fn dug(&mut self, cut: &crate::grid::Cut) {
        self.layout().cut(&mut self.z, cut);
    }

    /// The model's height at (x, y): its cell's, 0 outside the site, NaN
    /// where never seen.
    pub fn height(&self, x: f64, y: f64) -> f64 {
        self.cell_of(x, y).map_or(0.0, |k| self.z[k])
    }

    /// What the model holds above the floor (m³) (unseen cells count nothing).
    pub fn volume_m3(&self) -> f64 {
        self.layout().volume_m3(&self.z)
    }

    /// The width-averaged profile along the line from `origin` at
    /// `heading`, from `origin` out to `length_m`
    /// (x along the line); cells no scan point fell in (perception thins
    /// the cloud to a voxel grid) are bridged linearly between the seen
    /// cells either side along the line, held past the last.
    pub fn profile(
        &self,
        origin: [f64; 2],
        heading: f64,
        width_m: f64,
        length_m: f64,
    ) -> DigSurface {
        let (c, s) = (heading.cos(), heading.sin());
        let step = 0.5 * self.cell_m;
        // At least two samples (a cell as long as the profile).
        let n = ((length_m / step) as usize + 1).max(2);
        // Along the line, each of five lines across the width, holding the
        // last seen height over unseen cells.
        let across = [-0.4, -0.2, 0.0, 0.2, 0.4].map(|f| f * width_m);
        let tracks: Vec<Vec<f64>> = across
            .iter()
            .map(|&w| {
                let mut track: Vec<f64> = (0..n)
                    .map(|i| {
                        let t = i as f64 * step;
                        self.height(origin[0] + t * c - w * s, origin[1] + t * s + w * c)
                    })
                    .collect();
                fill_gaps(&mut track);
                track
            })
            .collect();
        let at = |track: &[f64], t: f64| {
            let u = (t / step).clamp(0.0, (n - 1) as f64);
            let i = (u as usize).min(n - 2);
            let f = u - i as f64;
            track[i] * (1.0 - f) + track[i + 1] * f
        };
        DigSurface::from_fn(
            |t, w| {
                // The nearest of the five tracks across.
                let j = (((w / width_m) + 0.4) / 0.2).round().clamp(0.0, 4.0) as usize;
                at(&tracks[j], t)
            },
            width_m,
            0.0,
            length_m,
            "the machine's pile model",
        )
    }
}

/// Replaces the NaN runs of `track` by the straight line between the
/// finite values either side; floor before the first (the ground the
/// machine stands on, under the sensor's view) and the last held after.
fn fill_gaps(track: &mut [f64]) {
    let seen: Vec<usize> = (0..track.len()).filter(|&i| track[i].is_finite()).collect();
    let Some((&first, &last)) = seen.first().zip(seen.last()) else {
        track.fill(0.0);
        return;
    };
    let tail = track[last];
    track[..first].fill(0.0);
    track[last + 1..].fill(tail);
    for w in seen.windows(2) {
        let (a, b) = (w[0], w[1]);
        for i in a + 1..b {
            let f = (i - a) as f64 / (b - a) as f64;
            track[i] = track[a] * (1.0 - f) + track[b] * f;
        }
    }
}

/// One way the machine could dig from where it stands.
#[derive(Debug, Clone)]
pub struct DigOption {
    /// Swing angle from the machine's heading (rad).
    pub swing: f64,
    /// The dig line's direction in the world (rad).
    pub heading: f64,
    /// Distance from the swing axis to the toe along the line (m).
    pub toe_s_m: f64,
    /// The profile in the dig frame (x from the toe).
    pub surface: DigSurface,
    /// Material within the planner's reach along the line (m³) (model).
    pub material_m3: f64,
}

/// The profiles along each swing angle with their toes, most material first;
/// the angles without a pile (a toe the model cannot place) are returned
/// with the reason.
pub fn dig_options(
    model: &PileModel,
    pose: Pose2,
    angles: &[f64],
    width_m: f64,
    reach_m: f64,
    deepest_cut_m: f64,
) -> (Vec<DigOption>, Vec<(f64, String)>) {
    let mut options = Vec::new();
    let mut refused = Vec::new();
    for &swing in angles {
        let heading = pose.theta + swing;
        let raw = model.profile([pose.x, pose.y], heading, width_m, PROFILE_LENGTH_M);
        let face = raw.top();
        if face.is_nan() || face <= 2.0 * OBSTACLE_HEIGHT_M {
            refused.push((swing, format!("no pile along it (highest {face:.2} m)")));
            continue;
        }
        match raw.from_toe(autoshovel_rope_shovel_dig::TOE_RISE_SHARE * face) {
            Ok((surface, toe_s_m)) => {
                let surface = surface.with_deepest_cut(deepest_cut_m);
                let n = 200;
                let material_m3 = (0..n)
                    .map(|i| {
                        surface
                            .height(reach_m * (i as f64 + 0.5) / n as f64)
                            .max(0.0)
                    })
                    .sum::<f64>()
                    * reach_m
                    / n as f64
                    * width_m;
                options.push(DigOption {
                    swing,
                    heading,
                    toe_s_m,
                    surface,
                    material_m3,
                });
            }
            Err(e) => refused.push((swing, e.to_string())),
        }
    }
    options.sort_by(|a, b| b.material_m3.total_cmp(&a.material_m3));
    (options, refused)
}

/// A stand the machine could walk to, and what it could dig there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StandCandidate {
    /// Where the swing axis would stand, facing the face.
    pub pose: Pose2,
    /// Material within reach over the dig angles (m³) (model).
    pub material_m3: f64,
    /// Sideways from the current stand (left positive) (m).
    pub lateral_m: f64,
}

/// The stands the machine could dig from next, best first: facing the
/// face at `face_heading` (the mine plan's digging direction, so that
/// the small heading errors of each walk do not add up), at lateral
/// offsets of 0, ±1, … ±8 `step_m` from the machine, each where
/// the perceived toe straight ahead lies `stand_off_m` from the swing
/// axis; a candidate must have at least `least_m3` within reach, a
/// footprint clear of the walking map and lie inside the site. Best: most
/// material within reach, discounted by e^(−d / 60 m) for the distance d
/// to walk there.
#[allow(clippy::too_many_arguments)]
pub fn next_stands(
    model: &PileModel,
    map: &Map,
    pose: Pose2,
    face_heading: f64,
    angles: &[f64],
    width_m: f64,
    reach_m: f64,
    stand_off_m: f64,
    step_m: f64,
    footprint_m: f64,
    least_m3: f64,
) -> (Vec<StandCandidate>, Vec<String>) {
    let pose = Pose2::new(pose.x, pose.y, face_heading);
    let (c, s) = (pose.theta.cos(), pose.theta.sin());
    let mut out = Vec::new();
    let mut refused = Vec::new();
    for k in -8..=8 {
        let lateral = f64::from(k) * step_m;
        // Look for the toe from 10 m behind the current stand.
        let base = [
            pose.x - 10.0 * c - lateral * s,
            pose.y - 10.0 * s + lateral * c,
        ];
        let raw = model.profile(base, pose.theta, width_m, LOOK_AHEAD_M);
        let face = raw.top();
        if face.is_nan() || face <= 2.0 * OBSTACLE_HEIGHT_M {
            refused.push(format!("{lateral:+.0} m: no pile ahead"));
            continue;
        }
        let Ok((_, toe_s)) = raw.from_toe(FACE_RISE_SHARE * face) else {
            refused.push(format!("{lateral:+.0} m: no toe ahead"));
            continue;
        };
        // Back off from there until the footprint is clear of everything
        // the scans show above the floor (the toe line need not be straight).
        let Some(stand) = (0..12).find_map(|k| {
            let along = toe_s - stand_off_m - 0.5 * k as f64;
            let stand = Pose2::new(base[0] + along * c, base[1] + along * s, pose.theta);
            footprint_clear(map, stand, footprint_m).then_some(stand)
        }) else {
            refused.push(format!(
                "{lateral:+.0} m: no clear footprint within 6 m of the toe's stand-off"
            ));
            continue;
        };
        let material_m3 = fan_material(
            model,
            stand,
            angles,
            toe_s - along_of(base, stand, pose.theta),
            reach_m,
        );
        if material_m3 >= least_m3 {
            out.push(StandCandidate {
                pose: stand,
                material_m3,
                lateral_m: lateral,
            });
        } else {
            refused.push(format!("{lateral:+.0} m: {material_m3:.0} m³ within reach"));
        }
    }
    let score = |c: &StandCandidate| {
        c.material_m3 * (-(c.pose.position() - pose.position()).norm() / 60.0).exp()
    };
    out.sort_by(|a, b| score(b).total_cmp(&score(a)));
    (out, refused)
}

/// Distance along `heading` from `base` to `stand`.
fn along_of(base: [f64; 2], stand: Pose2, heading: f64) -> f64 {
    (stand.x - base[0]) * heading.cos() + (stand.y - base[1]) * heading.sin()
}

/// What the model holds above the floor (m³) in the fan a stand can dig:
/// within the swing angles (and half a dig line's spread more either
/// side), from `toe_m` out to `toe_m + reach_m` from the swing axis.
pub fn fan_material(
    model: &PileModel,
    stand: Pose2,
    angles: &[f64],
    toe_m: f64,
    reach_m: f64,
) -> f64 {
    let spread = 5f64.to_radians();
    let (lo, hi) = angles
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let (r0, r1) = (toe_m.max(0.0), toe_m.max(0.0) + reach_m);
    let c = model.cell_m;
    let cell = |v: f64, o: f64, n: usize| (((v - o) / c).floor().max(0.0) as usize).min(n);
    let (i0, i1) = (
        cell(stand.x - r1, model.origin[0], model.size[0]),
        cell(stand.x + r1, model.origin[0], model.size[0]) + 1,
    );
    let (j0, j1) = (
        cell(stand.y - r1, model.origin[1], model.size[1]),
        cell(stand.y + r1, model.origin[1], model.size[1]) + 1,
    );
    let mut sum = 0.0;
    for j in j0..j1.min(model.size[1]) {
        for i in i0..i1.min(model.size[0]) {
            let k = j * model.size[0] + i;
            let z = model.z[k];
            if z.is_nan() || z <= 0.0 {
                continue;
            }
            let [x, y] = model.centre(k);
            let r = (x - stand.x).hypot(y - stand.y);
            let a = autoshovel_core::wrap_angle((y - stand.y).atan2(x - stand.x) - stand.theta);
            if (r0..=r1).contains(&r) && a >= lo - spread && a <= hi + spread {
                sum += z;
            }
        }
    }
    sum * c * c
}

/// Whether the footprint disc at `pose` keeps [`FOOTPRINT_MARGIN_M`]
/// from everything on the walking map `map` (made by [`walking_map`] from
/// what the scans show), inside the site.
pub fn footprint_clear(map: &Map, pose: Pose2, radius_m: f64) -> bool {
    let p = Vec2::new(pose.x, pose.y);
    let inside = pose.x - radius_m >= map.min.x
        && pose.y - radius_m >= map.min.y
        && pose.x + radius_m <= map.max.x
        && pose.y + radius_m <= map.max.y;
    inside && map.clearance(p, radius_m) >= FOOTPRINT_MARGIN_M
}

/// Clearance a stand keeps from everything on the walking map (m): more
/// than the metre the walk planner wants free ahead of a machine that
/// starts to move (so the next walk may start forward).
pub const FOOTPRINT_MARGIN_M: f64 = 1.2;

/// The walking map from the model: the site, and every run of cells above
/// [`OBSTACLE_HEIGHT_M`] within a band of [`MAP_BAND_M`] along y as one
/// rectangle (a convex polygon for the planner; the machine's footprint
/// radius gives the clearance), so the map follows a face as it has been
/// dug, concave bays included.
pub fn walking_map(model: &PileModel) -> Map {
    let c = model.cell_m;
    let band = (MAP_BAND_M / c).round().max(1.0) as usize;
    let (nx, ny) = (model.size[0], model.size[1]);
    let max = Vec2::new(
        model.origin[0] + nx as f64 * c,
        model.origin[1] + ny as f64 * c,
    );
    let mut map = Map::new(Vec2::new(model.origin[0], model.origin[1]), max);
    for b0 in (0..ny).step_by(band) {
        let rows = b0..(b0 + band).min(ny);
        let high = |i: usize| {
            rows.clone()
                .any(|j| model.z[j * nx + i] > OBSTACLE_HEIGHT_M)
        };
        let mut i = 0;
        while i < nx {
            if !high(i) {
                i += 1;
                continue;
            }
            let start = i;
            while i < nx && high(i) {
                i += 1;
            }
            let (x0, x1) = (
                model.origin[0] + start as f64 * c,
                model.origin[0] + i as f64 * c,
            );
            let (y0, y1) = (
                model.origin[1] + rows.start as f64 * c,
                model.origin[1] + rows.end as f64 * c,
            );
            map.obstacles.push(Obstacle {
                name: format!("scanned ({:.0}, {:.0})", 0.5 * (x0 + x1), 0.5 * (y0 + y1)),
                shape: Shape::Polygon {
                    vertices: vec![
                        Vec2::new(x0, y0),
                        Vec2::new(x1, y0),
                        Vec2::new(x1, y1),
                        Vec2::new(x0, y1),
                    ],
                },
            });
        }
    }
    map
}

/// The midpoint of a V-shaped move from `from` to `to` (walking paper
/// Fig. 1c): back away `back_m` along the heading, a tenth of the way
/// sideways, turned towards the goal's side by up to 35° (a 1,400 t
/// machine does not turn on the spot), so that the forward leg arrives
/// square to the face.
pub fn v_midpoint(from: Pose2, to: Pose2, back_m: f64) -> Pose2 {
    let (c, s) = (from.theta.cos(), from.theta.sin());
    let d = to.position() - from.position();
    let forward = d.x * c + d.y * s;
    let lateral = -d.x * s + d.y * c;
    let turn =
        lateral.signum() * (0.55 * lateral.abs().atan2(back_m + forward)).min(35f64.to_radians());
    let (mx, my) = (
        from.x - back_m * c - 0.1 * lateral * s,
        from.y - back_m * s + 0.1 * lateral * c,
    );
    Pose2::new(mx, my, from.theta + turn)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::ShiftScenario;
    use crate::world::{Lidar, World};
    use autoshovel_terrain::perceive::perceive;

    fn scanned(pose: Pose2) -> (World, PileModel) {
        let s = ShiftScenario::bench();
        let world = World::new(&s);
        let lidar = Lidar::on_machine(s.machine.sensor_height_m, 30_000);
        let scan = world.scan(pose, &lidar, 3);
        let got = perceive(&scan, &perception()).unwrap();
        let seen = autoshovel_terrain::level(&scan, got.roll_rad, got.pitch_rad);
        let mut model = PileModel::new(s.world.min_m, s.world.max_m, 0.5);
        model.update(&seen, &got.cloud, got.floor_height_m, pose);
        (world, model)
    }

    #[test]
    fn the_model_from_one_scan_agrees_with_the_pit_where_it_looked() {
        let pose = Pose2::new(24.0, 60.0, 0.0);
        let (world, model) = scanned(pose);
        let mut errors: Vec<f64> = (0..model.z.len())
            .filter(|&k| model.z[k].is_finite() && model.z[k] > 0.0)
            .map(|k| {
                let [x, y] = model.centre(k);
                (model.z[k] - world.height(x, y)).abs()
            })
            .collect();
        assert!(errors.len() > 500, "{}", errors.len());
        errors.sort_by(f64::total_cmp);
        let median = errors[errors.len() / 2];
        assert!(median < 0.1, "median error {median} m");
        // The toe straight ahead is where the pit's is (x = 30, 6 m from
        // the axis) within a metre: the first 3 % rise on cells of 0.5 m,
        // whose foot cells hold the mean of the returns there, then the
        // face's slope followed down to the floor.
        let (options, _) = dig_options(&model, pose, &[0.0], 3.6, 15.0, 120.0);
        assert_eq!(options.len(), 1);
        let toe = options[0].toe_s_m;
        assert!((toe - 6.0).abs() < 1.0, "{toe}");
    }

    #[test]
    fn the_walking_map_keeps_the_pile_and_the_boulders_out_and_the_floor_free() {
        let pose = Pose2::new(12.0, 50.0, 0.0);
        let (_, model) = scanned(pose);
        let map = walking_map(&model);
        // The face at x ≥ 31 is inside an obstacle; open floor at x = 20 is not;
        // the boulder at (21, 46) is.
        let blocked = |x: f64, y: f64| {
            map.obstacles.iter().any(|o| match &o.shape {
                Shape::Polygon { vertices } => {
                    x >= vertices[0].x
                        && x <= vertices[1].x
                        && y >= vertices[0].y
                        && y <= vertices[2].y
                }
                Shape::Circle { .. } => false,
            })
        };
        assert!(blocked(33.0, 50.0));
        assert!(!blocked(20.0, 52.0));
        assert!(blocked(21.0, 46.0));
    }

    #[test]
    fn a_v_midpoint_backs_away_and_turns_towards_the_goal() {
        let from = Pose2::new(10.0, 22.0, std::f64::consts::FRAC_PI_2);
        let to = Pose2::new(26.0, 22.0, std::f64::consts::FRAC_PI_2);
        let m = v_midpoint(from, to, 11.0);
        assert!((m.y - 11.0).abs() < 1e-9);
        assert!(m.theta < from.theta, "turns right, towards the goal");
        assert!(from.theta - m.theta <= 35f64.to_radians() + 1e-12);
    }
}
