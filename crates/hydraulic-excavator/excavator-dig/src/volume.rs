//! Dig volume by trapezoids ([HE eq. 2]): V = h_b·∫ f(x) dx ≈
//! h_b·Σ ½(y_{i−1} + y_i)·Δx, the area between the ground line and the tooth
//! path times the bucket width.
//!
//! The planner samples the path in time (as the paper does: "按采样时间分成若干
//! 窄小曲边梯形"), so the Δx are not equal and may even change sign where the
//! path turns back (a joint-space quintic can bulge outwards, a detour can back
//! off a boulder). [`swept_area`] therefore sums ½(d_{i−1} + d_i)(x_{i−1} − x_i)
//! with the depth d = max(0, ground − y): for a path moving towards the
//! machine (−x) this is [HE eq. 2] exactly, and where the path doubles back the
//! signed strips cancel, so the sum is the area enclosed by the path and the
//! ground (Green's theorem). Parts of the path above the ground add nothing.

use autoshovel_core::Vec2;

use crate::ground::Ground;
use crate::obstacle::Envelope;

/// [HE eq. 2] as printed: equal intervals on [a, b] with depths y₀ … yₙ, times h_b (m³).
pub fn trapezoid_volume(a: f64, b: f64, depths: &[f64], width_m: f64) -> f64 {
    if depths.len() < 2 {
        return 0.0;
    }
    let n = (depths.len() - 1) as f64;
    let dx = (b - a) / n;
    depths
        .windows(2)
        .map(|w| 0.5 * (w[0] + w[1]) * dx) // [HE eq. 2]
        .sum::<f64>()
        * width_m
}

/// Area between the ground and a sampled tip path (m²): [HE eq. 2] on
/// time samples (module docs).
pub fn swept_area(ground: &Ground, path: &[Vec2]) -> f64 {
    let mut area = 0.0;
    let mut prev: Option<(f64, f64)> = None;
    for p in path {
        let d = ground.depth(p.x, p.y).max(0.0);
        if let Some((x0, d0)) = prev {
            area += 0.5 * (d0 + d) * (x0 - p.x); // [HE eq. 2]
        }
        prev = Some((p.x, d));
    }
    area
}

/// The strip of one more sample appended to a path: ½(d_prev + d)(x_prev − x),
/// one trapezoid of [HE eq. 2] (m²).
#[inline]
pub fn strip(ground: &Ground, prev: Vec2, next: Vec2) -> f64 {
    let d0 = ground.depth(prev.x, prev.y).max(0.0);
    let d1 = ground.depth(next.x, next.y).max(0.0);
    0.5 * (d0 + d1) * (prev.x - next.x) // [HE eq. 2]
}

/// Area of the part of a disc below the ground (m²): Simpson over
/// x = x₀ + r sin θ (200 intervals), which removes the square-root ends.
pub fn disc_area_below(ground: &Ground, center: Vec2, radius: f64) -> f64 {
    let n = 200;
    let h = std::f64::consts::PI / n as f64;
    let f = |theta: f64| {
        let (s, c) = theta.sin_cos();
        let x = center.x + radius * s;
        let half = radius * c;
        let (lo, hi) = (center.y - half, center.y + half);
        (ground.height(x).min(hi) - lo).max(0.0) * radius * c
    };
    let a = -std::f64::consts::FRAC_PI_2;
    let mut s = f(a) + f(-a);
    for i in 1..n {
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(a + i as f64 * h);
    }
    s * h / 3.0
}

/// (soil, boulders) volume (m³) of a dig whose executed tip path `path` has
/// the [HE eq. 2] area `area` (m²), with a bucket `width_m` wide: the soil is
/// that area less the part of every boulder lying inside it, times the width;
/// a boulder counts whole (π r²·b, a disc across the bucket) when it lies
/// inside the dug area or `met[i]` says the bucket met it (the paper counts a
/// boulder met as dug).
pub fn counted_volume(
    ground: &Ground,
    boulders: &[Envelope],
    met: &[bool],
    path: &[Vec2],
    area: f64,
    width_m: f64,
) -> (f64, f64) {
    let mut soil_area = area;
    let mut rock = 0.0;
    for (i, e) in boulders.iter().enumerate() {
        let c = e.center();
        let probe = Vec2::new(c.x, c.y.min(ground.height(c.x) - 1e-6));
        let inside = e.contains(probe) && inside_dug_region(ground, path, probe);
        if inside {
            soil_area -= disc_area_below(ground, c, e.radius_m);
        }
        if inside || met.get(i).copied().unwrap_or(false) {
            rock += e.area_m2() * width_m;
        }
    }
    (soil_area * width_m, rock) // [HE eq. 2]: area × h_b
}

/// True when `p` lies in the region between the ground and the tip path
/// (closed by the vertical at the path's last point and the ground back to
/// its first), by the crossing-number test.
fn inside_dug_region(ground: &Ground, path: &[Vec2], p: Vec2) -> bool {
    let (Some(first), Some(last)) = (path.first(), path.last()) else {
        return false;
    };
    let mut poly: Vec<Vec2> = path.to_vec();
    poly.push(Vec2::new(last.x, ground.height(last.x)));
    let (lo, hi) = (last.x.min(first.x), last.x.max(first.x));
    let mut between: Vec<Vec2> = ground
        .points
        .iter()
        .filter(|v| v[0] > lo && v[0] < hi)
        .map(|v| Vec2::new(v[0], v[1]))
        .collect();
    if last.x > first.x {
        between.reverse();
    }
    poly.extend(between);
    poly.push(Vec2::new(first.x, ground.height(first.x)));
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if x > p.x {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn eq_2_integrates_a_triangle_exactly_and_a_parabola_to_second_order() {
        // Triangle of base 2 m and depth 0.7 m: area 0.7 m².
        let n = 40;
        let tri: Vec<f64> = (0..=n)
            .map(|i| {
                let x = 2.0 * i as f64 / n as f64;
                0.7 * (1.0 - (x - 1.0).abs())
            })
            .collect();
        assert_relative_eq!(trapezoid_volume(0.0, 2.0, &tri, 1.0), 0.7, epsilon = 1e-12);
        // Parabola depth h(1 − (x/L)²) on [−L, L]: area 4hL/3; trapezoid error
        // is exactly (b − a)·Δx²·|f''|/12 = 2L·Δx²·(2h/L²)/12.
        let (h, l, n) = (0.7, 1.3, 50);
        let dx = 2.0 * l / n as f64;
        let par: Vec<f64> = (0..=n)
            .map(|i| {
                let x = -l + i as f64 * dx;
                h * (1.0 - (x / l).powi(2))
            })
            .collect();
        let exact = 4.0 * h * l / 3.0;
        let err = 2.0 * l * dx * dx * (2.0 * h / (l * l)) / 12.0;
        assert_relative_eq!(
            trapezoid_volume(-l, l, &par, 1.0),
            exact - err,
            epsilon = 1e-12
        );
        // The width multiplies.
        assert_relative_eq!(
            trapezoid_volume(-l, l, &par, 0.5),
            0.5 * (exact - err),
            epsilon = 1e-12
        );
    }

    #[test]
    fn the_swept_area_of_a_path_towards_the_machine_is_eq_2() {
        let g = Ground::flat();
        // A V down to 0.7 m from x = 7 to x = 5.
        let path: Vec<Vec2> = (0..=40)
            .map(|i| {
                let x = 7.0 - 2.0 * i as f64 / 40.0;
                Vec2::new(x, -0.7 * (1.0 - (x - 6.0).abs()))
            })
            .collect();
        assert_relative_eq!(swept_area(&g, &path), 0.7, epsilon = 1e-12);
        // Above the ground adds nothing.
        let up: Vec<Vec2> = path.iter().map(|p| Vec2::new(p.x, -p.y)).collect();
        assert_relative_eq!(swept_area(&g, &up), 0.0);
    }

    #[test]
    fn a_path_that_doubles_back_counts_the_enclosed_area_once() {
        let g = Ground::flat();
        // Rectangle 1 m × 0.5 m entered with a back-and-forth wiggle at the bottom.
        let path = [
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, -0.5),
            Vec2::new(1.5, -0.5),
            Vec2::new(1.7, -0.5),
            Vec2::new(1.0, -0.5),
            Vec2::new(1.0, 0.0),
        ];
        assert_relative_eq!(swept_area(&g, &path), 0.5, epsilon = 1e-12);
        let total: f64 = path.windows(2).map(|w| strip(&g, w[0], w[1])).sum();
        assert_relative_eq!(total, 0.5, epsilon = 1e-12);
    }

    #[test]
    fn a_buried_disc_counts_whole_and_a_cut_one_in_part() {
        let g = Ground::flat();
        let r = 0.25;
        let full = disc_area_below(&g, Vec2::new(5.0, -0.6), r);
        assert_relative_eq!(full, std::f64::consts::PI * r * r, max_relative = 1e-4);
        let half = disc_area_below(&g, Vec2::new(5.0, 0.0), r);
        assert_relative_eq!(
            half,
            0.5 * std::f64::consts::PI * r * r,
            max_relative = 1e-3
        );
    }
}
