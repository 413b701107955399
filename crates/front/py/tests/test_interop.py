"""autoshovel beside the libraries its users already have: Open3D and laspy.

Where the semantics are the same the results must agree exactly; where
they differ, the test says how and checks the documented relation.
"""

import numpy as np
import pytest

import autoshovel

o3d = pytest.importorskip("open3d")
laspy = pytest.importorskip("laspy")


def o3d_cloud(points: np.ndarray):
    pc = o3d.geometry.PointCloud()
    pc.points = o3d.utility.Vector3dVector(points.astype(np.float64))
    return pc


# ---------------------------------------------------------------- files


@pytest.mark.parametrize("name", ["o.pcd", "o.ply"])
def test_open3d_files_read_the_same(tmp_path, pile, name):
    path = str(tmp_path / name)
    # Open3D writes float32 binary PCD / PLY (double PLY for Vector3dVector:
    # pass float32 through its tensor API to keep the stored type f32).
    pc = o3d.t.geometry.PointCloud(o3d.core.Tensor(pile))
    assert o3d.t.io.write_point_cloud(path, pc)
    ours = autoshovel.read_cloud(path)
    theirs = o3d.t.io.read_point_cloud(path).point.positions.numpy()
    np.testing.assert_array_equal(ours, theirs.astype(np.float32))
    np.testing.assert_array_equal(ours, pile)


@pytest.mark.parametrize("name", ["ours.pcd", "ours.ply"])
def test_open3d_reads_our_files(tmp_path, pile, name):
    path = tmp_path / name
    autoshovel.write_cloud(path, pile)
    theirs = np.asarray(o3d.io.read_point_cloud(str(path)).points)
    np.testing.assert_array_equal(theirs.astype(np.float32), pile)


@pytest.mark.parametrize("name", ["l.las", "l.laz"])
def test_laspy_and_autoshovel_read_the_same_las(tmp_path, pile, name):
    path = tmp_path / name
    header = laspy.LasHeader(point_format=3, version="1.4")
    header.scales = np.array([0.001, 0.001, 0.001])
    header.offsets = np.floor(pile.min(axis=0).astype(np.float64))
    las = laspy.LasData(header)
    las.x, las.y, las.z = (pile[:, i].astype(np.float64) for i in range(3))
    las.write(str(path))
    theirs = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    back = laspy.read(str(path))
    theirs = np.column_stack([np.asarray(back.x), np.asarray(back.y), np.asarray(back.z)])
    ours = autoshovel.read_cloud(path)
    # Both scale the stored integers in f64; ours then keeps f32.
    np.testing.assert_array_equal(ours, theirs.astype(np.float32))


@pytest.mark.parametrize("name", ["w.las", "w.laz"])
def test_laspy_reads_our_las(tmp_path, pile, name):
    path = tmp_path / name
    autoshovel.write_cloud(path, pile)
    back = laspy.read(str(path))
    theirs = np.column_stack([np.asarray(back.x), np.asarray(back.y), np.asarray(back.z)])
    np.testing.assert_array_equal(theirs.astype(np.float32), autoshovel.read_cloud(path))
    assert np.abs(theirs - pile).max() <= 0.0005 + 1e-6


# ---------------------------------------------------------------- filters


def test_radius_outlier_removal_agrees_with_open3d(pile):
    # The same rule: a point stays with at least k others within the radius
    # (Open3D's nb_points, PCL's min_neighbors). Distances differ in the last
    # bits (PCL's f32 squares against r² in f64, Open3D's f64 throughout),
    # which on these scans changes no point.
    for radius, k in [(0.3, 4), (0.2, 2), (0.5, 10)]:
        ours = autoshovel.radius_outlier_removal(pile, radius, k, return_indices=True)
        _, theirs = o3d_cloud(pile).remove_radius_outlier(nb_points=k, radius=radius)
        np.testing.assert_array_equal(ours, np.asarray(theirs))


def test_statistical_outlier_removal_against_open3d(pile):
    # Differs by definition: Open3D's mean is over nb_neighbors points
    # counting the point itself (distance 0), PCL's (ours) over mean_k others
    # and its deviation is the sample one (n − 1). Open3D's rule is ours with
    # mean_k = nb_neighbors − 1 and every mean scaled by (k − 1)/k, which
    # leaves the kept set the same up to the n − 1 in the deviation: the sets
    # must agree on all but a few points at the threshold.
    n = 21
    ours = set(autoshovel.statistical_outlier_removal(pile, n - 1, 1.0, return_indices=True).tolist())
    _, theirs = o3d_cloud(pile).remove_statistical_outlier(nb_neighbors=n, std_ratio=1.0)
    theirs = set(np.asarray(theirs).tolist())
    differ = len(ours ^ theirs)
    assert differ <= 1e-3 * len(pile), differ


def test_voxel_grid_agrees_with_open3d_on_the_same_cells(pile):
    # Open3D's voxels start at the cloud's lower bound less half a leaf;
    # PCL's (ours) at the origin. Shift the cloud so both grids coincide.
    leaf = 0.25
    shifted = (pile - pile.min(axis=0) + np.float32(leaf / 2)).astype(np.float32)
    ours = autoshovel.voxel_grid(shifted, leaf).astype(np.float64)
    theirs = np.asarray(o3d_cloud(shifted).voxel_down_sample(leaf).points)
    def by_cell(a):
        c = np.floor(a / leaf).astype(np.int64)
        return a[np.lexsort(c.T[::-1])]
    # The grids coincide up to Open3D's f64 origin (within 1e-9 of ours):
    # the same cells, the same centroids to f32 rounding.
    assert len(ours) == len(theirs)
    np.testing.assert_allclose(by_cell(ours), by_cell(theirs), atol=1e-5)
