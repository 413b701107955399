//! Properties of the filters checked against brute force and closed forms:
//! the k-d tree results equal an O(n²) search with PCL's arithmetic, the
//! voxel grid equals a hash-map reference, results do not depend on the
//! number of threads, non-finite points are dropped, and every parameter
//! error and emptied cloud is reported with the value at fault.

use std::collections::BTreeMap;

use autoshovel_point_cloud::filter::{self, Axis};
use autoshovel_point_cloud::{CloudError, Point, PointCloud};
use proptest::prelude::*;

/// A seeded LCG cloud: `n` points in a `size` cube, a quarter of them in a
/// tight clump so that neighbourhoods vary.
fn lcg_cloud(n: usize, size: f32, seed: u64) -> PointCloud {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    PointCloud::new(
        (0..n)
            .map(|i| {
                let scale = if i % 4 == 0 { 0.1 * size } else { size };
                [next() * scale, next() * scale, next() * scale]
            })
            .collect(),
    )
}

/// FLANN's (and kiddo's) f32 squared distance.
fn d2(a: &Point, b: &Point) -> f32 {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    ((0.0 + dx * dx) + dy * dy) + dz * dz
}

/// Sorted squared distances from `p` to every point (itself included).
fn sorted_d2(points: &[Point], p: &Point) -> Vec<f32> {
    let mut d: Vec<f32> = points.iter().map(|q| d2(p, q)).collect();
    d.sort_by(f32::total_cmp);
    d
}

fn brute_radius(points: &[Point], radius_m: f64, min_neighbors: usize) -> Vec<usize> {
    (0..points.len())
        .filter(|&i| {
            let d = sorted_d2(points, &points[i]);
            d.get(min_neighbors)
                .is_some_and(|&x| f64::from(x) <= radius_m * radius_m)
        })
        .collect()
}

fn brute_statistical(points: &[Point], k: usize, std_mul: f64, both: bool) -> Vec<usize> {
    let dist: Vec<f32> = points
        .iter()
        .map(|p| {
            let d = sorted_d2(points, p);
            let sum = d[1..=k]
                .iter()
                .fold(0.0_f64, |s, &x| s + f64::from(x).sqrt());
            (sum / k as f64) as f32
        })
        .collect();
    let (mut sum, mut sq) = (0.0_f64, 0.0_f64);
    for &d in &dist {
        sum += f64::from(d);
        sq += f64::from(d * d);
    }
    let n = dist.len() as f64;
    let mean = sum / n;
    let delta = ((sq - sum * sum / n) / (n - 1.0)).sqrt();
    let thr = mean + std_mul * delta;
    (0..dist.len())
        .filter(|&i| {
            let d = f64::from(dist[i]);
            // [RS eq. 16] as printed, |d̄_i − d̄| > α·δ, or PCL's one side
            let noise = if both {
                (d - mean).abs() > std_mul * delta
            } else {
                d > thr
            };
            !noise || thr.is_nan()
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn radius_equals_brute_force(seed in any::<u64>(), n in 20usize..300, r in 0.02f64..0.3, m in 0usize..8) {
        let cloud = lcg_cloud(n, 1.0, seed);
        let want = brute_radius(&cloud.points, r, m);
        let params = filter::RadiusOutlierParams { radius_m: r, min_neighbors: m };
        match filter::radius_outlier_removal_indices(&cloud, &params) {
            Ok(got) => prop_assert_eq!(got, want),
            Err(CloudError::Emptied { .. }) => prop_assert!(want.is_empty()),
            Err(e) => prop_assert!(false, "{e}"),
        }
    }

    #[test]
    fn statistical_equals_brute_force(seed in any::<u64>(), n in 20usize..300, k in 1usize..12, s in -0.5f64..2.0, both in any::<bool>()) {
        let cloud = lcg_cloud(n, 1.0, seed);
        let s = if both { s.abs() } else { s };
        let want = brute_statistical(&cloud.points, k, s, both);
        let sides = if both { filter::OutlierSides::Both } else { filter::OutlierSides::Above };
        let params = filter::StatisticalOutlierParams { mean_k: k, std_mul: s, sides };
        match filter::statistical_outlier_removal_indices(&cloud, &params) {
            Ok(got) => prop_assert_eq!(got, want),
            Err(CloudError::Emptied { .. }) => prop_assert!(want.is_empty()),
            Err(e) => prop_assert!(false, "{e}"),
        }
    }

    /// The radius filter keeping its index for the statistical filter
    /// keeps what the two filters keep one after the other, bit for bit
    /// (errors alike), clumped clouds and flat ones, radii narrower and far
    /// wider than the k nearest reach.
    #[test]
    fn radius_then_statistical_is_the_two_filters(
        seed in any::<u64>(), n in 30usize..3000, flat in any::<bool>(),
        radius in 0.005f64..0.5, min_pts in 0usize..6, k in 1usize..25, s in -0.5f64..2.5,
    ) {
        let mut cloud = lcg_cloud(n, 1.0, seed);
        if flat {
            // A surface: heights a gentle slope plus a little noise.
            for p in &mut cloud.points {
                p[2] = 0.3 * p[0] + 0.01 * p[2];
            }
        }
        let radius = filter::RadiusOutlierParams { radius_m: radius, min_neighbors: min_pts };
        let statistical = filter::StatisticalOutlierParams { mean_k: k, std_mul: s, ..Default::default() };
        let apart = filter::radius_outlier_removal_indices(&cloud, &radius).map(|kept| {
            let points: Vec<Point> = kept.iter().map(|&i| cloud.points[i]).collect();
            (filter::statistical_outlier_removal_indices(&points, &statistical).map_err(|e| e.to_string()), kept)
        });
        let together = filter::radius_outlier_removal_then(&cloud, &radius, k).map(|first| {
            let kept = first.kept.clone();
            let points: Vec<Point> = kept.iter().map(|&i| cloud.points[i]).collect();
            (first.statistical_indices(&points, &statistical).map_err(|e| e.to_string()), kept)
        });
        match (apart, together) {
            (Ok((a, kept_a)), Ok((b, kept_b))) => {
                prop_assert_eq!(kept_a, kept_b);
                prop_assert_eq!(a, b);
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
            (a, b) => prop_assert!(false, "{:?} against {:?}", a.map(|_| ()), b.map(|_| ())),
        }
    }

    #[test]
    fn voxel_grid_equals_a_map_of_voxels(seed in any::<u64>(), n in 1usize..400, leaf in 0.01f64..0.5) {
        let cloud = lcg_cloud(n, 1.0, seed);
        let inv = 1.0 / leaf as f32;
        // (z, y, x) keys sort as PCL orders voxels.
        let mut voxels: BTreeMap<[i64; 3], ([f64; 3], f64)> = BTreeMap::new();
        for p in &cloud.points {
            let c = [2, 1, 0].map(|a| (p[a] * inv).floor() as i64);
            let e = voxels.entry(c).or_insert(([0.0; 3], 0.0));
            for (sum, c) in e.0.iter_mut().zip(p) { *sum += f64::from(*c); }
            e.1 += 1.0;
        }
        let got = filter::voxel_grid(&cloud, &filter::VoxelGridParams::cube(leaf)).unwrap();
        prop_assert_eq!(got.len(), voxels.len());
        for (g, (s, c)) in got.points.iter().zip(voxels.values()) {
            for a in 0..3 { prop_assert!((f64::from(g[a]) - s[a] / c).abs() < 1e-6); }
        }
    }

    /// Leaves from 1e-12 m to 1 km on clouds from 1 cm to 10 km across:
    /// the map of voxels, or a refusal naming the leaf when a voxel index
    /// passes 4e18 — never a panic (a 1e-12 leaf on a 100 m pile once
    /// overflowed the voxel count).
    #[test]
    fn voxel_grid_at_any_scale_is_the_map_of_voxels_or_a_refusal(
        seed in any::<u64>(), n in 1usize..200, leaf_exp in -12.0f64..3.0, size_exp in -2.0f32..4.0,
    ) {
        let leaf = 10f64.powf(leaf_exp);
        let cloud = lcg_cloud(n, 10f32.powf(size_exp), seed);
        let inv = 1.0 / leaf as f32;
        let mut voxels: BTreeMap<[i64; 3], usize> = BTreeMap::new();
        let mut too_fine = false;
        for p in &cloud.points {
            let c = [2, 1, 0].map(|a| (p[a] * inv).floor());
            too_fine |= c.iter().any(|v| !v.is_finite() || v.abs() >= 4.0e18);
            *voxels.entry(c.map(|v| v as i64)).or_default() += 1;
        }
        match filter::voxel_grid(&cloud, &filter::VoxelGridParams::cube(leaf)) {
            Ok(got) => {
                prop_assert!(!too_fine);
                prop_assert_eq!(got.len(), voxels.len());
            }
            Err(e) => {
                prop_assert!(too_fine, "{e}");
                prop_assert!(e.to_string().contains("too small"), "{e}");
            }
        }
    }

    #[test]
    fn pass_through_inside_and_outside_split_the_cloud(seed in any::<u64>(), lo in -0.2f64..0.6, w in 0.0f64..0.8) {
        let cloud = lcg_cloud(200, 1.0, seed);
        let params = filter::PassThroughParams { axis: Axis::Y, min_m: lo, max_m: lo + w, keep_inside: true };
        let inside = filter::pass_through_indices(&cloud, &params).unwrap_or_default();
        let outside = filter::pass_through_indices(&cloud, &filter::PassThroughParams { keep_inside: false, ..params })
            .unwrap_or_default();
        let mut all: Vec<usize> = inside.iter().chain(&outside).copied().collect();
        all.sort_unstable();
        prop_assert_eq!(all, (0..cloud.len()).collect::<Vec<_>>());
        for &i in &inside {
            let y = cloud.points[i][1];
            prop_assert!(y >= lo as f32 && y <= (lo + w) as f32);
        }
    }
}

#[test]
fn results_do_not_depend_on_the_number_of_threads() {
    let cloud = lcg_cloud(5000, 1.0, 7);
    let run = || {
        (
            filter::radius_outlier_removal_indices(
                &cloud,
                &filter::RadiusOutlierParams {
                    radius_m: 0.05,
                    min_neighbors: 3,
                },
            )
            .unwrap(),
            filter::statistical_outlier_removal_indices(&cloud, &Default::default()).unwrap(),
            filter::voxel_grid(&cloud, &filter::VoxelGridParams::cube(0.03)).unwrap(),
            filter::estimate_normals(&cloud, &Default::default()).unwrap(),
            filter::bilateral_normal_smoothing(&cloud, &Default::default()).unwrap(),
        )
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(run);
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap()
        .install(run);
    assert_eq!(one.0, three.0);
    assert_eq!(one.1, three.1);
    assert_eq!(one.2, three.2);
    assert_eq!(format!("{:?}", one.3), format!("{:?}", three.3));
    assert_eq!(one.4, three.4);
}

#[test]
fn non_finite_points_are_dropped() {
    let clean = lcg_cloud(500, 1.0, 3);
    let mut dirty = clean.clone();
    // Insert non-finite points at 0, 100 and the end.
    dirty.points.insert(100, [f32::NAN, 0.0, 0.0]);
    dirty.points.insert(0, [0.0, f32::INFINITY, 0.0]);
    dirty.points.push([0.0, 0.0, f32::NEG_INFINITY]);
    let radius = filter::RadiusOutlierParams {
        radius_m: 0.1,
        min_neighbors: 2,
    };
    assert_eq!(
        filter::radius_outlier_removal(&dirty, &radius).unwrap(),
        filter::radius_outlier_removal(&clean, &radius).unwrap()
    );
    let stat = filter::StatisticalOutlierParams {
        mean_k: 8,
        std_mul: 1.0,
        ..Default::default()
    };
    assert_eq!(
        filter::statistical_outlier_removal(&dirty, &stat).unwrap(),
        filter::statistical_outlier_removal(&clean, &stat).unwrap()
    );
    let pass = filter::PassThroughParams {
        axis: Axis::X,
        min_m: f64::NEG_INFINITY,
        max_m: f64::INFINITY,
        keep_inside: true,
    };
    assert_eq!(filter::pass_through(&dirty, &pass).unwrap(), clean);
    let vox = filter::VoxelGridParams::cube(0.1);
    assert_eq!(
        filter::voxel_grid(&dirty, &vox).unwrap(),
        filter::voxel_grid(&clean, &vox).unwrap()
    );
    let normals = filter::estimate_normals(&dirty, &Default::default()).unwrap();
    assert_eq!(normals.len(), dirty.len());
    assert!(normals[0].is_none() && normals[101].is_none() && normals[502].is_none());
    assert_eq!(
        filter::bilateral_normal_smoothing(&dirty, &Default::default()).unwrap(),
        filter::bilateral_normal_smoothing(&clean, &Default::default()).unwrap()
    );
}

fn what(e: CloudError) -> String {
    match e {
        CloudError::BadParameter { what, .. } => what,
        other => panic!("expected BadParameter, got {other}"),
    }
}

#[test]
fn bad_parameters_name_the_value() {
    let cloud = lcg_cloud(100, 1.0, 1);
    let e = filter::radius_outlier_removal(
        &cloud,
        &filter::RadiusOutlierParams {
            radius_m: 0.0,
            min_neighbors: 1,
        },
    );
    assert!(what(e.unwrap_err()).contains("radius_m must be positive and finite, got 0"));
    let e = filter::radius_outlier_removal(
        &cloud,
        &filter::RadiusOutlierParams {
            radius_m: f64::NAN,
            min_neighbors: 1,
        },
    );
    assert!(what(e.unwrap_err()).contains("NaN"));
    let e = filter::statistical_outlier_removal(
        &cloud,
        &filter::StatisticalOutlierParams {
            mean_k: 0,
            std_mul: 1.0,
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err()).contains("mean_k must be at least 1, got 0"));
    let e = filter::statistical_outlier_removal(
        &cloud,
        &filter::StatisticalOutlierParams {
            mean_k: 100,
            std_mul: 1.0,
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err())
        .contains("mean_k = 100 needs at least 101 finite points, the cloud has 100"));
    let e = filter::statistical_outlier_removal(
        &cloud,
        &filter::StatisticalOutlierParams {
            mean_k: 5,
            std_mul: f64::INFINITY,
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err()).contains("std_mul must be finite, got inf"));
    for (leaf, shown) in [
        (0.0, "0"),
        (-0.05, "-0.05"),
        (f64::NAN, "NaN"),
        (f64::INFINITY, "inf"),
        (1e-300, "1e-300"),
        (1e300, "1e300"),
    ] {
        let e = filter::voxel_grid(
            &cloud,
            &filter::VoxelGridParams {
                leaf_m: [0.05, leaf, 0.05],
            },
        );
        assert!(what(e.unwrap_err()).contains(&format!(
            "leaf_m[1] must be positive and finite in f32, got {shown}"
        )));
    }
    let e = filter::pass_through(
        &cloud,
        &filter::PassThroughParams {
            min_m: 1.0,
            max_m: 0.5,
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err()).contains("min_m = 1 is above max_m = 0.5"));
    let e = filter::pass_through(
        &cloud,
        &filter::PassThroughParams {
            min_m: f64::NAN,
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err()).contains("limits must be numbers"));
    let e = filter::estimate_normals(
        &cloud,
        &filter::NormalParams {
            neighbourhood: filter::Neighbourhood::Nearest(2),
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err()).contains("Nearest(k) needs k >= 3"));
    let e = filter::estimate_normals(
        &cloud,
        &filter::NormalParams {
            neighbourhood: filter::Neighbourhood::Radius(-1.0),
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err()).contains("Radius(r) must be positive and finite, got -1"));
    let e = filter::bilateral_normal_smoothing(
        &cloud,
        &filter::BilateralParams {
            sigma_n_m: 0.0,
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err()).contains("sigma_n_m must be positive and finite, got 0"));
    let e = filter::bilateral_normal_smoothing(
        &cloud,
        &filter::BilateralParams {
            iterations: 0,
            ..Default::default()
        },
    );
    assert!(what(e.unwrap_err()).contains("iterations must be at least 1"));
}

#[test]
fn empty_input_and_emptied_output_are_errors_with_a_hint() {
    let empty = PointCloud::default();
    let is_empty_input =
        |r: Result<(), CloudError>| matches!(r, Err(CloudError::Emptied { input: 0, .. }));
    assert!(is_empty_input(
        filter::pass_through(&empty, &Default::default()).map(drop)
    ));
    assert!(is_empty_input(
        filter::radius_outlier_removal(&empty, &Default::default()).map(drop)
    ));
    assert!(is_empty_input(
        filter::statistical_outlier_removal(&empty, &Default::default()).map(drop)
    ));
    assert!(is_empty_input(
        filter::voxel_grid(&empty, &Default::default()).map(drop)
    ));
    assert!(is_empty_input(
        filter::estimate_normals(&empty, &Default::default()).map(drop)
    ));
    assert!(is_empty_input(
        filter::bilateral_normal_smoothing(&empty, &Default::default()).map(drop)
    ));

    // Sparse points: nobody has 5 neighbours within 1 mm.
    let cloud = lcg_cloud(100, 1.0, 2);
    let err = filter::radius_outlier_removal(
        &cloud,
        &filter::RadiusOutlierParams {
            radius_m: 0.001,
            min_neighbors: 5,
        },
    )
    .unwrap_err();
    match &err {
        CloudError::Emptied {
            filter,
            input,
            hint,
        } => {
            assert_eq!((*filter, *input), ("radius outlier removal", 100));
            assert!(hint.contains("lower min_neighbors or raise radius_m"));
        }
        other => panic!("{other}"),
    }
    assert_eq!(
        err.to_string(),
        "radius outlier removal removed every point (100 in, 0 out): lower min_neighbors or raise radius_m"
    );
    let e =
        filter::pass_through(&cloud, &filter::PassThroughParams::ground_removal(5.0)).unwrap_err();
    assert!(matches!(e, CloudError::Emptied { input: 100, .. }), "{e}");
    let e = filter::statistical_outlier_removal(
        &cloud,
        &filter::StatisticalOutlierParams {
            mean_k: 5,
            std_mul: -100.0,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("raise std_mul"), "{e}");
}

#[test]
fn voxel_grid_never_overflows_its_index() {
    // 1 µm voxels over 20 km: PCL 1.13 refuses ("Integer indices would
    // overflow"); here the box has more than 2⁶⁴ voxels and the (z, y, x)
    // triplet path runs.
    let cloud = PointCloud::new(vec![
        [1.0e4, 0.0, 0.0],
        [-1.0e4, 0.0, 0.0],
        [0.0, 1.0e4, -1.0e4],
        [-1.0e4, 0.0, 0.0],
    ]);
    let down = filter::voxel_grid(&cloud, &filter::VoxelGridParams::cube(1e-6)).unwrap();
    assert_eq!(
        down.points,
        vec![[0.0, 1.0e4, -1.0e4], [-1.0e4, 0.0, 0.0], [1.0e4, 0.0, 0.0]]
    );
    // 1 mm voxels over 2 km: beyond i32, within u64.
    let cloud = PointCloud::new(vec![
        [1000.0, 1000.0, 1000.0],
        [-1000.0, -1000.0, -1000.0],
        [0.0005, 0.0, 0.0],
        [0.0, 0.0, 0.0],
    ]);
    let down = filter::voxel_grid(&cloud, &filter::VoxelGridParams::cube(0.001)).unwrap();
    assert_eq!(
        down.points,
        vec![
            [-1000.0, -1000.0, -1000.0],
            [0.00025, 0.0, 0.0],
            [1000.0, 1000.0, 1000.0]
        ]
    );
}

/// A flat grid z = 0 of `n` × `n` points at 1 cm.
fn flat_grid(n: usize) -> Vec<Point> {
    (0..n * n)
        .map(|i| [(i % n) as f32 * 0.01, (i / n) as f32 * 0.01, 0.0])
        .collect()
}

#[test]
fn normals_of_a_plane_point_where_asked() {
    let cloud = PointCloud::new(flat_grid(10));
    let up = filter::estimate_normals(
        &cloud,
        &filter::NormalParams {
            neighbourhood: filter::Neighbourhood::Radius(0.015),
            orientation: filter::Orientation::PositiveZ,
        },
    )
    .unwrap();
    let down = filter::estimate_normals(
        &cloud,
        &filter::NormalParams {
            neighbourhood: filter::Neighbourhood::Nearest(9),
            orientation: filter::Orientation::Viewpoint([0.05, 0.05, -3.0]),
        },
    )
    .unwrap();
    for (u, d) in up.iter().zip(&down) {
        let (u, d) = (u.unwrap(), d.unwrap());
        approx::assert_relative_eq!(u[2], 1.0, epsilon = 1e-9);
        approx::assert_relative_eq!(d[2], -1.0, epsilon = 1e-9);
    }
    // A lone point has no normal.
    let lone = PointCloud::new(vec![
        [0.0, 0.0, 0.0],
        [5.0, 0.0, 0.0],
        [5.01, 0.0, 0.0],
        [5.0, 0.01, 0.0],
    ]);
    let n = filter::estimate_normals(
        &lone,
        &filter::NormalParams {
            neighbourhood: filter::Neighbourhood::Radius(0.1),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(n[0].is_none() && n[1].is_some());
}

#[test]
fn bilateral_smoothing_leaves_a_plane_alone_and_flattens_noise() {
    // Eq. 20 on a plane: every offset ⟨n, q − P⟩ is 0, so δ = 0.
    let plane = PointCloud::new(
        flat_grid(15)
            .into_iter()
            .map(|p| [p[0], p[1], 0.25 * p[0] + 0.1])
            .collect(),
    );
    let params = filter::BilateralParams {
        radius_m: 0.025,
        sigma_d_m: 0.0125,
        sigma_n_m: 0.005,
        iterations: 3,
    };
    let out = filter::bilateral_normal_smoothing(&plane, &params).unwrap();
    for (a, b) in out.points.iter().zip(&plane.points) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-6, "{a:?} moved from {b:?}");
        }
    }
    // Noise of ±1 mm on a flat grid: the first pass removes most of it, and
    // each further pass a little more.
    let mut s = 12345u64;
    let noisy: Vec<Point> = flat_grid(30)
        .into_iter()
        .map(|p| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            [
                p[0],
                p[1],
                ((s >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 0.002,
            ]
        })
        .collect();
    let rms = |c: &PointCloud| {
        (c.points
            .iter()
            .map(|p| f64::from(p[2]).powi(2))
            .sum::<f64>()
            / c.len() as f64)
            .sqrt()
    };
    let noisy = PointCloud::new(noisy);
    let initial = rms(&noisy);
    let mut last = initial;
    for iterations in 1..=3 {
        let params = filter::BilateralParams {
            radius_m: 0.025,
            sigma_d_m: 0.0125,
            sigma_n_m: 0.005,
            iterations,
        };
        let now = rms(&filter::bilateral_normal_smoothing(&noisy, &params).unwrap());
        assert!(now < last, "pass {iterations}: rms {now} after {last}");
        if iterations == 1 {
            assert!(now < 0.5 * initial, "one pass: rms {now} from {initial}");
        }
        last = now;
    }
}

/// [RS eq. 16] as printed is two-sided: a tight cluster (duplicated returns)
/// whose mean neighbour distance is far *below* the mean is noise to the
/// paper's rule and kept by PCL's one-sided rule; the points of the regular
/// grid are judged the same by both.
#[test]
fn the_two_sided_rule_also_drops_what_is_unusually_dense() {
    let mut points: Vec<Point> = (0..400)
        .map(|i| [(i % 20) as f32, (i / 20) as f32, 0.0])
        .collect();
    let grid = points.len();
    points.extend((0..30).map(|i| {
        [
            30.0 + 0.001 * (i % 6) as f32,
            30.0 + 0.001 * (i / 6) as f32,
            0.0,
        ]
    }));
    let cloud = PointCloud::new(points);
    let params = |sides| filter::StatisticalOutlierParams {
        mean_k: 8,
        std_mul: 1.0,
        sides,
    };
    let above =
        filter::statistical_outlier_removal_indices(&cloud, &params(filter::OutlierSides::Above))
            .unwrap();
    let both =
        filter::statistical_outlier_removal_indices(&cloud, &params(filter::OutlierSides::Both))
            .unwrap();
    let cluster = |kept: &[usize]| kept.iter().filter(|&&i| i >= grid).count();
    assert_eq!(cluster(&above), 30, "PCL's rule keeps the dense cluster");
    assert_eq!(cluster(&both), 0, "the paper's rule removes it");
    let grid_of = |kept: &[usize]| {
        kept.iter()
            .copied()
            .filter(|&i| i < grid)
            .collect::<Vec<_>>()
    };
    assert_eq!(grid_of(&above), grid_of(&both));
    assert!(grid_of(&both).len() > 300);
    // A negative α means nothing two-sided.
    let e = filter::statistical_outlier_removal(
        &cloud,
        &filter::StatisticalOutlierParams {
            std_mul: -1.0,
            ..params(filter::OutlierSides::Both)
        },
    );
    assert!(what(e.unwrap_err()).contains("sides = both"));
}

/// A cloud large enough to be cut into many chunks and super-buckets
/// gives the map of voxels bit for bit (each voxel's points summed in f64
/// in input order), whatever the number of threads: points through a cube,
/// and points on a gentle slope in a box of air (a scan's case: few
/// super-buckets occupied, each with many voxels), and the slope in a box
/// made 40 m long by one far point (super-buckets of 2²¹ voxel indices:
/// two radix passes).
#[test]
fn a_large_voxel_grid_is_the_map_of_voxels_bit_for_bit() {
    let cube = lcg_cloud(300_000, 3.0, 11);
    let slope = PointCloud::new(
        lcg_cloud(300_000, 3.0, 12)
            .points
            .iter()
            .map(|p| [p[0], p[1], 0.05 * p[0] + 0.001 * p[2]])
            .chain([[0.0, 0.0, 3.0]])
            .collect(),
    );
    let leaf = 0.02_f64;
    let inv = 1.0 / leaf as f32;
    let mut far = slope.clone();
    far.points.push([40.0, 0.0, 3.0]);
    for cloud in [cube, slope, far] {
        let mut voxels: BTreeMap<[i64; 3], ([f64; 3], f64)> = BTreeMap::new();
        for p in &cloud.points {
            let c = [2, 1, 0].map(|a| (p[a] * inv).floor() as i64);
            let e = voxels.entry(c).or_insert(([0.0; 3], 0.0));
            for (sum, c) in e.0.iter_mut().zip(p) {
                *sum += f64::from(*c);
            }
            e.1 += 1.0;
        }
        let expected: Vec<Point> = voxels
            .values()
            .map(|(s, c)| [0, 1, 2].map(|a| (s[a] / c) as f32))
            .collect();
        for threads in [1, 2, 5] {
            let got = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    filter::voxel_grid(&cloud, &filter::VoxelGridParams::cube(leaf)).unwrap()
                });
            assert!(got.points == expected, "{threads} threads");
        }
    }
}
