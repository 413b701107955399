//! The filters keep exactly the points PCL 1.13 keeps on the same input and
//! parameters (radius, statistical, pass-through: the same points, bit for
//! bit, in the same order), and the voxel grid gives PCL's centroids within
//! 1e-5 m, in PCL's order. The reference outputs were made with Debian's
//! pcl-tools 1.13.0 by `peer/make_filter_refs.py`; see
//! `tests/data/filters/README.md` for the commands.
//!
//! PCD files are read by the few lines below (x y z float fields, ascii or
//! binary), not by the crate's `io` module, so that these tests check the
//! filters alone.

use std::path::PathBuf;

use autoshovel_point_cloud::filter::{self, Axis};
use autoshovel_point_cloud::{Point, PointCloud};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/filters")
        .join(name)
}

/// x, y, z of an ascii or binary PCD whose fields are x y z, 4-byte floats.
fn read_pcd(name: &str) -> Vec<Point> {
    let bytes = std::fs::read(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut pos = 0;
    let mut points = 0usize;
    let mut fields = String::new();
    let kind = loop {
        let end = pos
            + bytes[pos..]
                .iter()
                .position(|&b| b == b'\n')
                .expect("header line");
        let line = std::str::from_utf8(&bytes[pos..end])
            .expect("ascii header")
            .trim()
            .to_string();
        pos = end + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("FIELDS") => fields = words.collect::<Vec<_>>().join(" "),
            Some("POINTS") => points = words.next().expect("count").parse().expect("count"),
            Some("DATA") => break words.next().expect("data kind").to_string(),
            _ => {}
        }
    };
    assert_eq!(fields, "x y z", "{name}: fields");
    let out: Vec<Point> = match kind.as_str() {
        "ascii" => {
            let text = std::str::from_utf8(&bytes[pos..]).expect("ascii data");
            let v: Vec<f32> = text
                .split_whitespace()
                .map(|w| w.parse().expect("float"))
                .collect();
            v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
        }
        "binary" => bytes[pos..pos + 12 * points]
            .chunks_exact(12)
            .map(|c| {
                [0, 4, 8].map(|o| f32::from_le_bytes(c[o..o + 4].try_into().expect("4 bytes")))
            })
            .collect(),
        other => panic!("{name}: DATA {other} not handled"),
    };
    assert_eq!(out.len(), points, "{name}: point count");
    out
}

fn cloud(name: &str) -> PointCloud {
    PointCloud::new(read_pcd(&format!("{name}.pcd")))
}

/// Our kept points equal PCL's, bit for bit and in order.
fn assert_same_points(ours: &PointCloud, reference: &str) {
    let pcl = read_pcd(&format!("{reference}.pcl.pcd"));
    assert_eq!(
        ours.len(),
        pcl.len(),
        "{reference}: {} kept here, {} by PCL",
        ours.len(),
        pcl.len()
    );
    for (i, (a, b)) in ours.points.iter().zip(&pcl).enumerate() {
        assert_eq!(
            a.map(f32::to_bits),
            b.map(f32::to_bits),
            "{reference}: point {i}: {a:?} here, {b:?} in PCL"
        );
    }
}

fn radius(input: &str, radius_m: f64, min_neighbors: usize, reference: &str) {
    let params = filter::RadiusOutlierParams {
        radius_m,
        min_neighbors,
    };
    let ours = filter::radius_outlier_removal(&cloud(input), &params).expect("filter");
    assert_same_points(&ours, reference);
}

fn statistical(input: &str, mean_k: usize, std_mul: f64, reference: &str) {
    let params = filter::StatisticalOutlierParams {
        mean_k,
        std_mul,
        ..Default::default()
    };
    let ours = filter::statistical_outlier_removal(&cloud(input), &params).expect("filter");
    assert_same_points(&ours, reference);
}

#[test]
fn radius_outlier_removal_keeps_what_pcl_keeps() {
    radius("pile", 0.05, 5, "pile_radius_r0.05_min5");
    radius("pile", 0.04, 3, "pile_radius_r0.04_min3");
    radius("clusters", 0.1, 3, "clusters_radius_r0.1_min3");
}

#[test]
fn radius_outlier_removal_agrees_with_pcl_at_the_boundary() {
    // Neighbours at exactly r = 0.25 count (interior grid points have 6).
    radius("grid", 0.25, 6, "grid_radius_r0.25_min6");
    // f32 squared distances against the f64 radius squared, on both sides.
    radius("grid", 0.1, 3, "grid_radius_r0.1_min3");
    radius("grid", 0.1, 2, "grid_radius_r0.1_min2");
}

#[test]
fn statistical_outlier_removal_keeps_what_pcl_keeps() {
    statistical("pile", 50, 1.0, "pile_statistical_k50_s1");
    statistical("pile", 8, 0.5, "pile_statistical_k8_s0.5");
    statistical("clusters", 10, 1.0, "clusters_statistical_k10_s1");
    // Many equal mean distances and exact duplicates.
    statistical("grid", 6, 0.2, "grid_statistical_k6_s0.2");
}

#[test]
fn pass_through_keeps_what_pcl_keeps() {
    let pile = cloud("pile");
    let run = |axis, min_m, max_m, keep_inside, reference| {
        let params = filter::PassThroughParams {
            axis,
            min_m,
            max_m,
            keep_inside,
        };
        assert_same_points(
            &filter::pass_through(&pile, &params).expect("filter"),
            reference,
        );
        // The indices variant agrees with the points variant.
        let idx = filter::pass_through_indices(&pile, &params).expect("filter");
        let gathered: Vec<Point> = idx.iter().map(|&i| pile.points[i]).collect();
        assert_eq!(
            gathered,
            filter::pass_through(&pile, &params).expect("filter").points
        );
    };
    // The paper's ground removal, with points at and next to z = 0.1.
    run(Axis::Z, 0.1, 1e30, true, "pile_passthrough_z0.1");
    run(Axis::Z, 0.1, 0.5, true, "pile_passthrough_z0.1_0.5");
    // Outside: no point lies exactly on these limits (where PCL's tool and
    // PassThrough<PointT> differ, see pass_through.rs).
    run(Axis::X, 0.2, 0.7, false, "pile_passthrough_x_outside");
}

fn voxel(input: &str, leaf_m: [f64; 3], reference: &str) {
    let ours =
        filter::voxel_grid(&cloud(input), &filter::VoxelGridParams { leaf_m }).expect("filter");
    let pcl = read_pcd(&format!("{reference}.pcl.pcd"));
    assert_eq!(
        ours.len(),
        pcl.len(),
        "{reference}: {} voxels here, {} in PCL",
        ours.len(),
        pcl.len()
    );
    // Same order too (PCL sorts by linear voxel index, x fastest).
    for (i, (a, b)) in ours.points.iter().zip(&pcl).enumerate() {
        for k in 0..3 {
            assert!(
                (a[k] - b[k]).abs() <= 1e-5,
                "{reference}: centroid {i}: {a:?} here, {b:?} in PCL"
            );
        }
    }
}

#[test]
fn voxel_grid_centroids_match_pcl() {
    voxel("pile", [0.05; 3], "pile_voxel_0.05");
    // Points on voxel faces.
    voxel("grid", [0.25; 3], "grid_voxel_0.25");
    voxel("clusters", [0.1, 0.1, 0.2], "clusters_voxel_0.1_0.1_0.2");
}
