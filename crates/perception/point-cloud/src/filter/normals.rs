//! Normals by principal component analysis of each point's neighbourhood,
//! the first half of the rope-shovel paper's bilateral smoothing (§3.2, "the
//! unit normal vector of point P is first calculated using the points within
//! the neighborhood range of point P", before [RS eq. 19]).
//!
//! The normal is the eigenvector of the smallest eigenvalue of the
//! neighbourhood's covariance matrix (the point itself included, as in PCL's
//! `NormalEstimation`, whose k nearest include the query point), in f64,
//! in closed form as PCL's `eigen33` (cyclic Jacobi rotations where the
//! two smallest eigenvalues nearly meet; see `smallest_axis`). It is
//! oriented towards a viewpoint (PCL's
//! `flipNormalTowardsViewpoint`: n·(v − p) ≥ 0), towards +z (a pile seen from
//! above; Open3D's default when a cloud has no normals yet), or left as the
//! solver returns it. A neighbourhood of fewer than three points, or one
//! whose points are collinear (the smallest eigenvalue not unique), has no
//! normal: `None` (PCL writes NaN).

use super::common::{bad, empty_input, f32_at_most};
use crate::search::kdtree::{KdTree, Nearest};
use crate::{Point, Result};

const FILTER: &str = "normal estimation";

/// Which points make up a point's neighbourhood.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Neighbourhood {
    /// The k nearest points, the point itself included (PCL's `setKSearch`).
    Nearest(usize),
    /// The points within this radius (m), inclusive (PCL's `setRadiusSearch`).
    Radius(f64),
}

/// Which way normals point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Orientation {
    /// Towards this viewpoint (m), e.g. the sensor: n·(v − p) ≥ 0.
    Viewpoint([f64; 3]),
    /// Upwards: n_z ≥ 0.
    PositiveZ,
    /// As the eigen-solver returns them (sign arbitrary).
    Unoriented,
}

/// Parameters of [`estimate_normals`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalParams {
    /// The neighbourhood.
    pub neighbourhood: Neighbourhood,
    /// The orientation.
    pub orientation: Orientation,
}

impl Default for NormalParams {
    /// The paper gives no value: the points within 10 cm (documented choice,
    /// a few voxels of the 5 cm default down-sampling), oriented upwards.
    fn default() -> Self {
        Self {
            neighbourhood: Neighbourhood::Radius(0.1),
            orientation: Orientation::PositiveZ,
        }
    }
}

impl NormalParams {
    fn validate(&self) -> Result<()> {
        match self.neighbourhood {
            Neighbourhood::Nearest(k) if k < 3 => {
                return Err(bad(
                    FILTER,
                    format!("Nearest(k) needs k >= 3 points for a plane, got {k}"),
                ))
            }
            Neighbourhood::Radius(r) if !(r.is_finite() && r > 0.0) => {
                return Err(bad(
                    FILTER,
                    format!("Radius(r) must be positive and finite, got {r}"),
                ))
            }
            _ => {}
        }
        if let Orientation::Viewpoint(v) = self.orientation {
            if !v.iter().all(|c| c.is_finite()) {
                return Err(bad(
                    FILTER,
                    format!("the viewpoint must be finite, got {v:?}"),
                ));
            }
        }
        Ok(())
    }
}

/// The unit normal of every point, in input order (`None` where the
/// neighbourhood is too small or degenerate, or the point is not finite).
///
/// ```
/// use autoshovel_point_cloud::{filter, PointCloud};
/// // A tilted plane z = 0.5 x: its upward normal is (−0.5, 0, 1)/|·|.
/// let cloud = PointCloud::new(
///     (0..100).map(|i| { let (x, y) = ((i % 10) as f32 * 0.1, (i / 10) as f32 * 0.1); [x, y, 0.5 * x] }).collect(),
/// );
/// let params = filter::NormalParams { neighbourhood: filter::Neighbourhood::Nearest(8), ..Default::default() };
/// let normals = filter::estimate_normals(&cloud, &params).unwrap();
/// let n = normals[55].unwrap();
/// let s = 1.25_f64.sqrt();
/// assert!((n[0] + 0.5 / s).abs() < 1e-6 && n[1].abs() < 1e-6 && (n[2] - 1.0 / s).abs() < 1e-6);
/// ```
pub fn estimate_normals(cloud: &[Point], params: &NormalParams) -> Result<Vec<Option<[f64; 3]>>> {
    params.validate()?;
    if cloud.is_empty() {
        return Err(empty_input(FILTER));
    }
    // Search among the finite points only.
    let finite: Vec<usize> = (0..cloud.len())
        .filter(|&i| super::common::is_finite(&cloud[i]))
        .collect();
    let points: Vec<Point> = finite.iter().map(|&i| cloud[i]).collect();
    let tree = KdTree::new(&points);
    let normals: Vec<Option<[f64; 3]>> = tree.map_points(
        || Scratch::new(params.neighbourhood),
        |scratch, _, p| {
            let (neighbours, columns) = scratch.neighbourhood(&tree, p);
            columns.gather(p, tree.points(), neighbours);
            let n = pca_normal(columns)?;
            Some(orient(n, p, params.orientation))
        },
    );
    let mut out = vec![None; cloud.len()];
    for (&i, n) in finite.iter().zip(normals) {
        out[i] = n;
    }
    Ok(out)
}

/// Per-task buffers of a neighbourhood search.
struct Scratch {
    which: Neighbourhood,
    knn: Nearest,
    found: Vec<u32>,
    columns: Columns,
}

impl Scratch {
    fn new(which: Neighbourhood) -> Self {
        let k = match which {
            Neighbourhood::Nearest(k) => k,
            Neighbourhood::Radius(_) => 1,
        };
        Self {
            which,
            knn: Nearest::new(k),
            found: Vec::new(),
            columns: Columns::default(),
        }
    }

    /// Tree positions of the neighbourhood of `p`, and the buffer to
    /// gather its points into.
    fn neighbourhood(&mut self, tree: &KdTree, p: &Point) -> (&[u32], &mut Columns) {
        let found = match self.which {
            Neighbourhood::Nearest(_) => {
                tree.nearest(p, &mut self.knn);
                self.knn.positions()
            }
            Neighbourhood::Radius(r) => {
                tree.within(p, f32_at_most(r * r), &mut self.found);
                &self.found
            }
        };
        (found, &mut self.columns)
    }
}

/// `n` flipped to the requested side.
pub(crate) fn orient(n: [f64; 3], p: &Point, orientation: Orientation) -> [f64; 3] {
    let flip = match orientation {
        Orientation::Viewpoint(v) => {
            let d = [0, 1, 2].map(|a| v[a] - f64::from(p[a]));
            n[0] * d[0] + n[1] * d[1] + n[2] * d[2] < 0.0
        }
        Orientation::PositiveZ => n[2] < 0.0,
        Orientation::Unoriented => false,
    };
    if flip {
        n.map(|c| -c)
    } else {
        n
    }
}

/// The unit normal (smallest principal axis) of these points (their offsets
/// from one point), `None` for fewer than 3 points or collinear ones.
pub(crate) fn pca_normal(d: &Columns) -> Option<[f64; 3]> {
    let count = d.x.len();
    if count < 3 {
        return None;
    }
    // One pass over the offsets: Σd and the six distinct entries of Σddᵀ,
    // LANES sums of each side by side (rather than one chain a sum, whose
    // additions wait on each other), then added in a fixed order.
    let whole = count / LANES * LANES;
    let mut lanes = [[0.0_f64; LANES]; 9];
    for ((x, y), z) in d.x[..whole]
        .chunks_exact(LANES)
        .zip(d.y.chunks_exact(LANES))
        .zip(d.z.chunks_exact(LANES))
    {
        for l in 0..LANES {
            lanes[0][l] += x[l];
            lanes[1][l] += y[l];
            lanes[2][l] += z[l];
            lanes[3][l] += x[l] * x[l];
            lanes[4][l] += x[l] * y[l];
            lanes[5][l] += x[l] * z[l];
            lanes[6][l] += y[l] * y[l];
            lanes[7][l] += y[l] * z[l];
            lanes[8][l] += z[l] * z[l];
        }
    }
    let mut t = lanes.map(add_lanes);
    for j in whole..count {
        let (x, y, z) = (d.x[j], d.y[j], d.z[j]);
        for (sum, v) in t
            .iter_mut()
            .zip([x, y, z, x * x, x * y, x * z, y * y, y * z, z * z])
        {
            *sum += v;
        }
    }
    // Σ(d − m)(d − m)ᵀ = Σddᵀ − (Σd) mᵀ: the offsets are from a point of the
    // neighbourhood, so both terms are of the neighbourhood's own size.
    let n = count as f64;
    let m = [t[0] / n, t[1] / n, t[2] / n];
    let c = [
        t[3] - t[0] * m[0],
        t[4] - t[0] * m[1],
        t[5] - t[0] * m[2],
        t[6] - t[1] * m[1],
        t[7] - t[1] * m[2],
        t[8] - t[2] * m[2],
    ];
    smallest_axis([[c[0], c[1], c[2]], [c[1], c[3], c[4]], [c[2], c[4], c[5]]])
}

/// The lanes of a sum taken side by side, added in a fixed order.
#[inline]
pub(crate) fn add_lanes(s: [f64; LANES]) -> f64 {
    (s[0] + s[1]) + (s[2] + s[3])
}

/// Sums side by side in [`pca_normal`] and the smoothing's weights.
pub(crate) const LANES: usize = 4;

/// A neighbourhood's offsets from a point (its own, for a search's) in f64,
/// a column an axis: gathered from the cloud once, then read by every pass
/// over it (the sums of the covariance, a smoothing's weights) from
/// contiguous memory.
#[derive(Debug, Default)]
pub(crate) struct Columns {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
}

impl Columns {
    /// The offsets from `origin` of `cloud[ids]`, in this order.
    pub fn gather(&mut self, origin: &Point, cloud: &[Point], ids: &[u32]) {
        for (a, column) in [&mut self.x, &mut self.y, &mut self.z]
            .into_iter()
            .enumerate()
        {
            let o = f64::from(origin[a]);
            column.clear();
            column.extend(ids.iter().map(|&q| f64::from(cloud[q as usize][a]) - o));
        }
    }

    /// Gathered into a new set, from the first point.
    #[cfg(test)]
    pub fn of(points: impl Iterator<Item = Point>) -> Self {
        let points: Vec<Point> = points.collect();
        let ids: Vec<u32> = (0..points.len() as u32).collect();
        let mut c = Self::default();
        c.gather(&points[0], &points, &ids);
        c
    }
}

/// The unit eigenvector of the smallest eigenvalue of a symmetric positive
/// semi-definite 3 × 3 matrix (a covariance), or `None` when that
/// eigenvalue is not unique (λ₁ ≤ 10⁻¹² λ₂: collinear or coincident
/// points, no plane).
///
/// In closed form where the smallest eigenvalue stands clear of the next,
/// as on any surface, as PCL's `pcl::eigen33` and Eigen's
/// `SelfAdjointEigenSolver::computeDirect` do (Jacobi rotations, which it
/// replaced, were a third of the smoothing's time): the matrix shifted by
/// the mean of its diagonal and scaled by its largest entry, the
/// eigenvalues as the roots of its characteristic cubic by the
/// trigonometric method, and the eigenvector as the longest cross product
/// of two rows of A − λ₀I (each orthogonal to the kernel); its error is
/// about ε·λ₂/(λ₁ − λ₀), 10⁻¹⁰ at most here. Near a repeated root the
/// cubic's roots are good only to about √ε of the largest, so where λ₁ − λ₀
/// is under 10⁻⁶ of λ₂ − λ₀ the Jacobi rotations ([`symmetric_eigen3`])
/// decide, exactly as before the closed form.
pub(crate) fn smallest_axis(a: [[f64; 3]; 3]) -> Option<[f64; 3]> {
    cubic_axis(a).or_else(|| jacobi_axis(a))
}

/// The closed form of [`smallest_axis`], `None` where λ₁ − λ₀ is not clear
/// of rounding (or the matrix is a multiple of the identity).
fn cubic_axis(a: [[f64; 3]; 3]) -> Option<[f64; 3]> {
    let shift = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
    let mut m = a;
    for (i, row) in m.iter_mut().enumerate() {
        row[i] -= shift;
    }
    let scale = m.iter().flatten().fold(0.0_f64, |s, v| s.max(v.abs()));
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    let inv = 1.0 / scale;
    let m = m.map(|row| row.map(|v| v * inv));
    // M has trace 0: det(λI − M) = λ³ + c₁λ − c₀, with c₁ the sum of its
    // principal 2 × 2 minors and c₀ its determinant.
    let c1 = m[0][0] * m[1][1] + m[0][0] * m[2][2] + m[1][1] * m[2][2]
        - m[0][1] * m[0][1]
        - m[0][2] * m[0][2]
        - m[1][2] * m[1][2];
    let c0 = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[1][2])
        - m[0][1] * (m[0][1] * m[2][2] - m[1][2] * m[0][2])
        + m[0][2] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
    // Roots 2ρ·cos(θ − 2πj/3), ρ = √(−c₁/3), cos 3θ = (c₀/2)/ρ³.
    let a_over_3 = (-c1 / 3.0).max(0.0);
    let half_b = 0.5 * c0;
    let q = (a_over_3 * a_over_3 * a_over_3 - half_b * half_b).max(0.0);
    let rho = a_over_3.sqrt();
    let theta = q.sqrt().atan2(half_b) / 3.0;
    let (sin, cos) = theta.sin_cos();
    let sqrt3 = 3.0_f64.sqrt();
    // θ ∈ [0, π/3]: the smallest, middle and largest roots.
    let low = -rho * (cos + sqrt3 * sin);
    let mid = -rho * (cos - sqrt3 * sin);
    let high = 2.0 * rho * cos;
    if mid - low <= CLEAR * (high - low) {
        return None;
    }
    let rows = [0, 1, 2].map(|i| {
        let mut r = m[i];
        r[i] -= low;
        r
    });
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let norm2 = |v: &[f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let candidates = [
        cross(rows[0], rows[1]),
        cross(rows[0], rows[2]),
        cross(rows[1], rows[2]),
    ];
    let best = candidates
        .into_iter()
        .max_by(|u, v| norm2(u).total_cmp(&norm2(v)))
        .expect("three candidates");
    let len = norm2(&best).sqrt();
    (len > 0.0).then(|| best.map(|c| c / len))
}

/// Where λ₁ − λ₀ falls below this share of λ₂ − λ₀, [`smallest_axis`]
/// leaves the matrix to the Jacobi rotations.
const CLEAR: f64 = 1e-6;

/// The smallest axis by Jacobi rotations, `None` when λ₁ ≤ 10⁻¹² λ₂.
fn jacobi_axis(a: [[f64; 3]; 3]) -> Option<[f64; 3]> {
    let (values, vectors) = symmetric_eigen3(a);
    // Collinear (or coincident) points: the two smallest eigenvalues vanish.
    let plane_defined = values[1] > 1e-12 * values[2];
    if !plane_defined {
        return None;
    }
    let n = [vectors[0][0], vectors[1][0], vectors[2][0]];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    Some(n.map(|c| c / len))
}

/// Eigenvalues (ascending) and eigenvectors (as columns, in the same order)
/// of a symmetric 3 × 3 matrix, by cyclic Jacobi rotations, each applied in
/// place to the two rows and columns it changes (Numerical Recipes'
/// `jacobi`; by hand: nalgebra's general solver costs more for a 3 × 3 than
/// the whole neighbourhood sum on a smoothing's 100-point neighbourhoods).
/// Accurate where the closed form of [`smallest_axis`] is not (two nearly
/// equal eigenvalues), and some five times slower.
pub(crate) fn symmetric_eigen3(mut a: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= f64::EPSILON * 1e-3 * diag || off == 0.0 {
            break;
        }
        for (p, q, r) in [(0, 1, 2), (0, 2, 1), (1, 2, 0)] {
            let apq = a[p][q];
            if apq == 0.0 {
                continue;
            }
            // The rotation J in the (p, q) plane that zeroes a[p][q]
            // (J_pp = J_qq = c, J_pq = s, J_qp = −s; A' = Jᵀ A J, V' = V J).
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            let tau = s / (1.0 + c);
            a[p][p] -= t * apq;
            a[q][q] += t * apq;
            a[p][q] = 0.0;
            a[q][p] = 0.0;
            let (g, h) = (a[r][p], a[r][q]);
            a[r][p] = g - s * (h + g * tau);
            a[r][q] = h + s * (g - h * tau);
            a[p][r] = a[r][p];
            a[q][r] = a[r][q];
            for row in &mut v {
                let (g, h) = (row[p], row[q]);
                row[p] = g - s * (h + g * tau);
                row[q] = h + s * (g - h * tau);
            }
        }
    }
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &k| a[i][i].total_cmp(&a[k][k]));
    let values = order.map(|i| a[i][i]);
    let vectors = [0, 1, 2].map(|r| order.map(|i| v[r][i]));
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mul(x: &[[f64; 3]; 3], y: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        [0, 1, 2].map(|r| [0, 1, 2].map(|c| (0..3).map(|k| x[r][k] * y[k][c]).sum()))
    }

    fn transpose(x: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        [0, 1, 2].map(|r| [0, 1, 2].map(|c| x[c][r]))
    }

    /// Covariance-like matrices: a flat neighbourhood with a repeated
    /// largest eigenvalue, one with a repeated eigenvalue, then `n`
    /// random B·Bᵀ (seeded).
    fn covariances(seed: u64, n: usize) -> Vec<[[f64; 3]; 3]> {
        let mut u = crate::testing::uniform(seed);
        let mut cases = vec![
            [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 1e-6]],
            [[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 3.0]],
        ];
        for _ in 0..n {
            let b: [[f64; 3]; 3] = [0, 1, 2].map(|_| [0, 1, 2].map(|_| f64::from(u()) - 0.5));
            cases.push(mul(&b, &transpose(&b)));
        }
        cases
    }

    #[test]
    fn jacobi_gives_orthonormal_eigenvectors_of_any_symmetric_matrix() {
        // A V = V diag(λ), Vᵀ V = I, λ ascending.
        for a in covariances(7, 200) {
            let (values, vectors) = symmetric_eigen3(a);
            assert!(values[0] <= values[1] && values[1] <= values[2]);
            let av = mul(&a, &vectors);
            let scale = values[2].abs().max(1e-300);
            for r in 0..3 {
                for c in 0..3 {
                    assert!((av[r][c] - vectors[r][c] * values[c]).abs() <= 1e-12 * scale);
                    let vtv: f64 = (0..3).map(|k| vectors[k][r] * vectors[k][c]).sum();
                    assert!((vtv - f64::from(u8::from(r == c))).abs() <= 1e-12);
                }
            }
        }
    }

    #[test]
    fn jacobi_recovers_a_rotated_diagonal() {
        // R diag(1, 4, 9) Rᵀ for a rotation R about an oblique axis.
        let (ax, ang) = ([1.0_f64, 2.0, 2.0].map(|c| c / 3.0), 0.7_f64);
        let (s, c) = ang.sin_cos();
        let k = [
            [0.0, -ax[2], ax[1]],
            [ax[2], 0.0, -ax[0]],
            [-ax[1], ax[0], 0.0],
        ];
        let kk = mul(&k, &k);
        let r = [0, 1, 2].map(|i| {
            [0, 1, 2].map(|j| f64::from(u8::from(i == j)) + s * k[i][j] + (1.0 - c) * kk[i][j])
        });
        let d = [[1.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 9.0]];
        let m = mul(&mul(&r, &d), &transpose(&r));
        let (values, vectors) = symmetric_eigen3(m);
        for (got, want) in values.iter().zip([1.0, 4.0, 9.0]) {
            approx::assert_relative_eq!(*got, want, epsilon = 1e-12);
        }
        for i in 0..3 {
            // Each eigenvector is ± the matching column of R.
            let dot: f64 = (0..3).map(|a| vectors[a][i] * r[a][i]).sum();
            approx::assert_relative_eq!(dot.abs(), 1.0, epsilon = 1e-12);
        }
    }

    #[test]
    fn the_closed_form_axis_is_jacobis() {
        // Covariance-like matrices, every other one flattened (its
        // smallest eigenvalue 10⁻¹ to 10⁻⁵ of the largest), scaled to a
        // pile's centimetres: the same axis as the Jacobi rotations to
        // 1e-9 (the closed form's error grows as λ₂/(λ₁ − λ₀)).
        let mut cases = covariances(11, 500);
        for (i, m) in cases.iter_mut().enumerate().skip(2) {
            if i % 2 == 1 {
                let flat = 10f64.powi(-(1 + i as i32 % 5));
                let (_, v) = symmetric_eigen3(*m);
                let d = [[flat, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]];
                *m = mul(&mul(&v, &d), &transpose(&v));
            }
            *m = m.map(|r| r.map(|v| v * 1e-3));
        }
        for a in cases {
            let (_, vectors) = symmetric_eigen3(a);
            let want = [vectors[0][0], vectors[1][0], vectors[2][0]];
            let got = cubic_axis(a).expect("λ₁ clear of λ₀");
            assert_eq!(smallest_axis(a), Some(got));
            let dot: f64 = (0..3).map(|k| got[k] * want[k]).sum();
            assert!(
                (dot.abs() - 1.0).abs() < 1e-9,
                "{a:?}: {got:?} against {want:?}"
            );
            let len: f64 = got.iter().map(|c| c * c).sum();
            assert!((len - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_nearly_repeated_smallest_eigenvalue_is_left_to_jacobi() {
        // A line (two zero eigenvalues) has no axis; a rod (two equal
        // small ones), a ball (all three equal) and two smallest a hair
        // apart get Jacobi's answer, whatever the cubic's rounding.
        let line = [[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 0.0]];
        assert!(cubic_axis(line).is_none() && smallest_axis(line).is_none());
        for a in [
            [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1.0]],
            [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]],
            [
                [1e-4, 1e-13, 0.0],
                [1e-13, 1e-4 + 1e-12, 0.0],
                [0.0, 0.0, 1.0],
            ],
        ] {
            assert!(cubic_axis(a).is_none());
            assert_eq!(smallest_axis(a), jacobi_axis(a));
            assert!(smallest_axis(a).is_some());
        }
    }

    #[test]
    fn the_normal_of_a_plane_far_from_the_origin_is_exact() {
        // Covariance from offsets (Σddᵀ − (Σd)mᵀ, lanes of sums side by
        // side) against the closed form: z = 0.5x − 0.25y on a 7 × 9 grid a
        // kilometre from the origin, every count from 8 (past the first,
        // collinear row) to 63 points.
        let len = (1.0_f64 + 0.25 + 0.0625).sqrt();
        let want = [-0.5 / len, 0.25 / len, 1.0 / len];
        let points: Vec<Point> = (0..63)
            .map(|i| {
                let (x, y) = (f64::from(i % 7) * 0.125, f64::from(i / 7) * 0.125);
                [
                    (1000.0 + x) as f32,
                    (-2000.0 + y) as f32,
                    (300.0 + 0.5 * x - 0.25 * y) as f32,
                ]
            })
            .collect();
        for count in 8..=points.len() {
            let some = &points[..count];
            let n = pca_normal(&Columns::of(some.iter().copied())).unwrap();
            let n = if n[2] < 0.0 { n.map(|c| -c) } else { n };
            for a in 0..3 {
                assert!(
                    (n[a] - want[a]).abs() < 1e-9,
                    "{count} points: {n:?} against {want:?}"
                );
            }
        }
    }

    #[test]
    fn collinear_points_have_no_normal() {
        let line = (0..5).map(|i| [i as f32, 2.0 * i as f32, 0.0]);
        assert!(pca_normal(&Columns::of(line)).is_none());
        let two = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]].into_iter();
        assert!(pca_normal(&Columns::of(two)).is_none());
    }
}
