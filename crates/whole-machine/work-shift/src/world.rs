//! The simulator's truth: the pit as a 2.5-D height grid (the floor at
//! z = 0, the muck pile, boulders, stockpiles, parked vehicles), the LiDAR that scans it
//! from the machine, and the dipper that cuts it. Nothing here is read by
//! the machine's side of the run ([`crate::machine`]) except through a
//! scan.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;

use autoshovel_core::Pose2;
use autoshovel_point_cloud::PointCloud;
use autoshovel_terrain::sensor_from_level;

use crate::grid::{Cut, Layout};
use crate::scenario::{HeapSpec, ShiftScenario};

/// The pit: heights above the floor at cell centres, x fastest.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    /// Lower-left corner of the grid (m).
    pub origin: [f64; 2],
    /// Cell edge (m).
    pub cell_m: f64,
    /// Cells along x and y.
    pub size: [usize; 2],
    /// Height of each cell's centre above the floor (m).
    pub z: Vec<f64>,
}

/// The LiDAR's mounting: its tilt on the machine (unknown to the machine:
/// perception estimates it from the floor), range noise and outliers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lidar {
    /// Height above the floor, on the swing axis (m).
    pub height_m: f64,
    /// Points a scan.
    pub points: usize,
    /// Roll and pitch of the mounting (rad).
    pub roll_rad: f64,
    /// (see `roll_rad`)
    pub pitch_rad: f64,
    /// Range noise, standard deviation (m).
    pub range_noise_m: f64,
    /// Share of returns that are dust or rain: points anywhere in the view.
    pub outlier_share: f64,
}

impl Lidar {
    /// An 80-line sensor's worth of rays over 110° × 72° below the horizon
    /// (walking paper Table 2's class), mounted 0.8° and −1.5° off level,
    /// 2 cm range noise, 0.3 % dust.
    pub fn on_machine(height_m: f64, points: usize) -> Self {
        Self {
            height_m,
            points,
            roll_rad: 0.8f64.to_radians(),
            pitch_rad: (-1.5f64).to_radians(),
            range_noise_m: 0.02,
            outlier_share: 0.003,
        }
    }
}

impl World {
    /// The pit of `scenario`: floor, pile, boulders, stockpiles and parked vehicles.
    pub fn new(scenario: &ShiftScenario) -> Self {
        let w = &scenario.world;
        let cell = w.cell_m;
        let layout = Layout::over(w.min_m, w.max_m, cell);
        let size = layout.size;
        let mut world = Self {
            origin: w.min_m,
            cell_m: cell,
            size,
            z: vec![0.0; layout.len()],
        };
        let pile = &scenario.pile;
        let tan = pile.repose_deg.to_radians().tan();
        let run = pile.face_height_m / tan;
        let crest = pile.toe_x_m + run;
        let back = crest + pile.top_depth_m;
        let heaps: Vec<(&HeapSpec, bool)> = scenario
            .boulder
            .iter()
            .map(|h| (h, true))
            .chain(scenario.stockpile.iter().map(|h| (h, false)))
            .collect();
        let nx = size[0];
        world.z.par_iter_mut().enumerate().for_each(|(i, z)| {
            let (x, y) = (
                w.min_m[0] + (i % nx) as f64 * cell + 0.5 * cell,
                w.min_m[1] + (i / nx) as f64 * cell + 0.5 * cell,
            );
            // The face (the generator's profile across it), the top, the
            // back and the ends at the repose angle.
            let mut h = if x <= back {
                pile.face_height_m * pile.shape.profile((x - pile.toe_x_m) / run)
            } else {
                pile.face_height_m - (x - back) * tan
            };
            h = h
                .min((y - pile.y_m[0]) * tan + pile.face_height_m)
                .min((pile.y_m[1] - y) * tan + pile.face_height_m)
                .max(0.0);
            for &(heap, round) in &heaps {
                let r = (x - heap.center_m[0]).hypot(y - heap.center_m[1]);
                if r < heap.radius_m {
                    let top = if round {
                        heap.height_m * (1.0 - (r / heap.radius_m).powi(2)).sqrt()
                    } else {
                        heap.height_m.min((heap.radius_m - r) * tan)
                    };
                    h = h.max(top);
                }
            }
            for v in &scenario.parked {
                let (c, sn) = (
                    v.heading_deg.to_radians().cos(),
                    v.heading_deg.to_radians().sin(),
                );
                let (dx, dy) = (x - v.center_m[0], y - v.center_m[1]);
                if (dx * c + dy * sn).abs() <= 0.5 * v.size_m[0]
                    && (-dx * sn + dy * c).abs() <= 0.5 * v.size_m[1]
                {
                    h = h.max(v.height_m);
                }
            }
            *z = h;
        });
        world
    }

    /// Height above the floor at (x, y), bilinear between cell centres
    /// (held at the edges) (m).
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let u = ((x - self.origin[0]) / self.cell_m - 0.5).clamp(0.0, (self.size[0] - 1) as f64);
        let v = ((y - self.origin[1]) / self.cell_m - 0.5).clamp(0.0, (self.size[1] - 1) as f64);
        if !(u.is_finite() && v.is_finite()) {
            return 0.0;
        }
        let (i, j) = (
            (u as usize).min(self.size[0].saturating_sub(2)),
            (v as usize).min(self.size[1].saturating_sub(2)),
        );
        let (fu, fv) = (u - i as f64, v - j as f64);
        let at = |a: usize, b: usize| {
            let (a, b) = (a.min(self.size[0] - 1), b.min(self.size[1] - 1));
            self.z[b * self.size[0] + a]
        };
        let bottom = at(i, j) * (1.0 - fu) + at(i + 1, j) * fu;
        let top = at(i, j + 1) * (1.0 - fu) + at(i + 1, j + 1) * fu;
        bottom * (1.0 - fv) + top * fv
    }

    /// The centre (x, y) of cell `i`.
    pub fn centre(&self, i: usize) -> [f64; 2] {
        self.layout().centre(i)
    }

    /// Everything above the floor (m³) (each cell a prism).
    pub fn volume_m3(&self) -> f64 {
        self.layout().volume_m3(&self.z)
    }

    /// Whether a disc of `radius` about (x, y) lies on bare floor (nothing
    /// higher than `clear_m` under it) and inside the world.
    pub fn is_clear(&self, x: f64, y: f64, radius: f64, clear_m: f64) -> bool {
        let inside = x - radius >= self.origin[0]
            && y - radius >= self.origin[1]
            && x + radius <= self.origin[0] + self.size[0] as f64 * self.cell_m
            && y + radius <= self.origin[1] + self.size[1] as f64 * self.cell_m;
        inside
            && self
                .cells_within(x, y, radius)
                .all(|i| self.z[i] <= clear_m)
    }

    /// The cells whose centres lie within `radius` of (x, y).
    fn cells_within(&self, x: f64, y: f64, radius: f64) -> impl Iterator<Item = usize> + '_ {
        let c = self.cell_m;
        let lo = |v: f64, o: f64| (((v - radius - o) / c).floor().max(0.0)) as usize;
        let (i0, j0) = (lo(x, self.origin[0]), lo(y, self.origin[1]));
        let hi = |v: f64, o: f64, n: usize| ((((v + radius - o) / c).ceil()) as usize).min(n);
        let (i1, j1) = (
            hi(x, self.origin[0], self.size[0]),
            hi(y, self.origin[1], self.size[1]),
        );
        (j0..j1.max(j0))
            .flat_map(move |j| (i0..i1.max(i0)).map(move |i| j * self.size[0] + i))
            .filter(move |&k| {
                let [cx, cy] = self.centre(k);
                (cx - x).hypot(cy - y) <= radius
            })
    }

    /// Takes the material above `cut`'s tooth path within its width out of
    /// the pit (never below the floor), and returns its volume (m³): each
    /// cell the swept strip covers is lowered to the path, one it covers in
    /// part by that share of its height above the path.
    pub fn cut(&mut self, cut: &Cut) -> f64 {
        self.layout().cut(&mut self.z, cut)
    }

    /// The grid's layout.
    pub fn layout(&self) -> Layout {
        Layout {
            origin: self.origin,
            cell_m: self.cell_m,
            size: self.size,
        }
    }

    /// A scan from the LiDAR on the machine at `pose` (the swing axis on
    /// the floor, heading θ), in the sensor's own frame (x ahead, tilted by
    /// its mounting): rays in 80 lines from 8° to 80° below the horizon
    /// over ±55° of azimuth, each marched over the grid to its first hit;
    /// a ray that leaves the world is lost. Same seed, same scan.
    pub fn scan(&self, pose: Pose2, lidar: &Lidar, seed: u64) -> PointCloud {
        const LINES: usize = 80;
        let per_line = lidar.points.div_ceil(LINES).max(1);
        let eye = [pose.x, pose.y, lidar.height_m];
        let to_sensor = sensor_from_level(lidar.roll_rad, lidar.pitch_rad);
        let (ch, sh) = (pose.theta.cos(), pose.theta.sin());
        let noise = Normal::new(0.0, lidar.range_noise_m).expect("σ ≥ 0");
        let hits: Vec<Option<[f32; 3]>> = (0..LINES * per_line)
            .into_par_iter()
            .map(|ray| {
                let mut rng = ChaCha8Rng::seed_from_u64(
                    seed ^ (ray as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
                );
                let (line, k) = (ray / per_line, ray % per_line);
                let el = (-8.0 - 72.0 * line as f64 / (LINES - 1) as f64).to_radians();
                let az = (-55.0 + 110.0 * (k as f64 + 0.5) / per_line as f64).to_radians();
                // The ray in the machine's level frame, then the world's.
                let d = [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()];
                let d = [d[0] * ch - d[1] * sh, d[0] * sh + d[1] * ch, d[2]];
                let hit = if rng.gen::<f64>() < lidar.outlier_share {
                    // Dust: a return anywhere along the ray's first 30 m.
                    let t = rng.gen_range(2.0..30.0);
                    Some([0, 1, 2].map(|a| eye[a] + t * d[a]))
                } else {
                    self.march(eye, d).map(|t| {
                        let t = t + noise.sample(&mut rng);
                        [0, 1, 2].map(|a| eye[a] + t * d[a])
                    })
                };
                hit.map(|p| {
                    // Back to the machine's level frame, then the sensor's.
                    let (dx, dy, dz) = (p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]);
                    let level = nalgebra::Vector3::new(dx * ch + dy * sh, -dx * sh + dy * ch, dz);
                    let q = to_sensor * level;
                    [q.x as f32, q.y as f32, q.z as f32]
                })
            })
            .collect();
        PointCloud::new(hits.into_iter().flatten().collect())
    }

    /// The distance along the ray from `eye` in direction `d` (unit) to the
    /// first point at or below the terrain, if inside the world: steps of
    /// at most half the height gap (the terrain's slopes stay below 1.2
    /// but at a boulder's rim), at least half a cell, then bisection.
    fn march(&self, eye: [f64; 3], d: [f64; 3]) -> Option<f64> {
        let above = |t: f64| eye[2] + t * d[2] - self.height(eye[0] + t * d[0], eye[1] + t * d[1]);
        let inside = |t: f64| {
            let (x, y) = (eye[0] + t * d[0], eye[1] + t * d[1]);
            x >= self.origin[0]
                && y >= self.origin[1]
                && x <= self.origin[0] + self.size[0] as f64 * self.cell_m
                && y <= self.origin[1] + self.size[1] as f64 * self.cell_m
        };
        let t_floor = if d[2] < 0.0 {
            eye[2] / -d[2]
        } else {
            return None;
        };
        let (mut lo, mut t) = (0.0, 0.0);
        loop {
            let gap = above(t);
            if gap <= 0.0 {
                break;
            }
            lo = t;
            t += (gap / 2.2).max(0.5 * self.cell_m);
            if t > t_floor * 1.01 || !inside(t) {
                return None;
            }
        }
        let mut hi = t;
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            if above(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn the_pile_has_the_volume_of_its_cross_section_times_its_length() {
        // A straight face (convex profile has no fillets): the section is a
        // trapezoid-like shape whose area we integrate on a fine line; the
        // ends add two half-cones' worth at repose. Checked on the middle
        // 40 m only, where the section is the same everywhere.
        let mut s = ShiftScenario::bench();
        s.boulder.clear();
        s.parked.clear();
        s.stockpile.clear();
        let world = World::new(&s);
        let p = &s.pile;
        let tan = p.repose_deg.to_radians().tan();
        let run = p.face_height_m / tan;
        let section = {
            let n = 200_000;
            let (x0, x1) = (p.toe_x_m - 1.0, p.toe_x_m + 2.0 * run + p.top_depth_m + 1.0);
            let dx = (x1 - x0) / n as f64;
            (0..n)
                .map(|i| world.height(x0 + (i as f64 + 0.5) * dx, 60.0))
                .sum::<f64>()
                * dx
        };
        let exact = p.face_height_m * (run + p.top_depth_m); // face + top + back: H·(L/2 + D + L/2)
        assert_relative_eq!(section, exact, max_relative = 0.01);
        // The grid's own sum over a 40 m length is the section × 40.
        let c = world.cell_m;
        let band: f64 = (0..world.z.len())
            .filter(|&i| (40.0..80.0).contains(&world.centre(i)[1]))
            .map(|i| world.z[i])
            .sum::<f64>()
            * c
            * c;
        assert_relative_eq!(band, exact * 40.0, max_relative = 0.01);
    }

    #[test]
    fn a_cut_removes_what_lies_above_the_path_and_nothing_else() {
        let mut s = ShiftScenario::bench();
        s.boulder.clear();
        s.parked.clear();
        s.stockpile.clear();
        let mut world = World::new(&s);
        let before = world.clone();
        let total = world.volume_m3();
        // A flat path 1 m above the floor from the toe, 10 m into the pile.
        let cut = Cut {
            origin: [24.0, 60.0],
            heading: 0.0,
            toe_s_m: 6.0,
            half_width_m: 1.8,
            path: vec![[0.0, 1.0], [10.0, 1.0]],
        };
        let removed = world.cut(&cut);
        // Conservation: the grid lost exactly what the cut reports.
        assert_relative_eq!(world.volume_m3(), total - removed, max_relative = 1e-12);
        // Nothing outside the strip moved, nothing wholly inside is above 1 m.
        for i in 0..world.z.len() {
            let [x, y] = world.centre(i);
            let (across, along) = ((y - 60.0).abs(), x - 30.0);
            if across <= 1.8 - 0.25 && (0.0..=10.0).contains(&along) {
                assert!(world.z[i] <= 1.0 + 1e-12);
            } else if across >= 1.8 + 0.25 || !(0.0..=10.0).contains(&along) {
                assert_eq!(world.z[i], before.z[i]);
            }
        }
        // About a 3.6 m strip × the section above 1 m over those 10 m.
        let expected: f64 = {
            let n = 10_000;
            (0..n)
                .map(|i| {
                    (before.height(30.0 + 10.0 * (i as f64 + 0.5) / n as f64, 60.0) - 1.0).max(0.0)
                })
                .sum::<f64>()
                * 10.0
                / n as f64
                * 3.6
        };
        assert_relative_eq!(removed, expected, max_relative = 0.01);
    }

    #[test]
    fn a_parked_truck_stands_as_a_box() {
        let s = ShiftScenario::bench();
        let world = World::new(&s);
        let v = &s.parked[0];
        let c = world.cell_m;
        let (inside, outside) = world
            .z
            .iter()
            .enumerate()
            .filter(|&(k, _)| {
                let [x, y] = world.centre(k);
                (x - v.center_m[0]).abs() < 10.0 && (y - v.center_m[1]).abs() < 10.0
            })
            .partition::<Vec<_>, _>(|&(_, &z)| z == v.height_m);
        // Heading 90°: its length along y. The cells at its height cover its
        // footprint to a cell's rounding; none around it is raised.
        let area = inside.len() as f64 * c * c;
        assert!(
            (area - v.size_m[0] * v.size_m[1]).abs() < (v.size_m[0] + v.size_m[1]) * c,
            "{area}"
        );
        assert!(outside.iter().all(|&(_, &z)| z == 0.0));
        assert_eq!(world.height(v.center_m[0], v.center_m[1] + 4.0), v.height_m);
        assert_eq!(world.height(v.center_m[0] + 4.0, v.center_m[1]), 0.0);
    }

    #[test]
    fn a_scan_levelled_by_its_mounting_lies_on_the_terrain() {
        let s = ShiftScenario::bench();
        let world = World::new(&s);
        let mut lidar = Lidar::on_machine(12.0, 20_000);
        lidar.range_noise_m = 0.0;
        lidar.outlier_share = 0.0;
        let pose = Pose2::new(24.0, 60.0, 0.3);
        let scan = world.scan(pose, &lidar, 7);
        assert!(scan.points.len() > 15_000, "{}", scan.points.len());
        assert_eq!(scan, world.scan(pose, &lidar, 7), "same seed, same scan");
        let level = autoshovel_terrain::level(&scan, lidar.roll_rad, lidar.pitch_rad);
        let (c, sn) = (pose.theta.cos(), pose.theta.sin());
        let worst = level
            .points
            .iter()
            .map(|p| {
                let (x, y, z) = (f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
                let (wx, wy) = (pose.x + x * c - y * sn, pose.y + x * sn + y * c);
                (z + 12.0 - world.height(wx, wy)).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst < 1e-3, "{worst}");
    }
}
