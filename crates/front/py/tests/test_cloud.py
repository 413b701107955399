"""Point clouds from Python: files, filters, arrays in and out."""

import numpy as np
import pytest

import autoshovel
from autoshovel import AutoshovelError


def test_generate_pile_is_seeded_and_shaped(pile):
    again = autoshovel.generate_pile("typical", 60_000, seed=7)
    other = autoshovel.generate_pile("typical", 60_000, seed=8)
    assert pile.shape == (60_000, 3) and pile.dtype == np.float32
    assert pile.flags["C_CONTIGUOUS"] and pile.flags["OWNDATA"] is False or pile.base is not None
    assert np.array_equal(pile, again)
    assert not np.array_equal(pile, other)


@pytest.mark.parametrize("name,encoding", [("a.pcd", None), ("b.pcd", "binary_compressed"), ("c.pcd", "ascii"), ("d.ply", None), ("e.ply", "binary_big_endian"), ("f.xyz", None)])
def test_write_read_round_trip(tmp_path, pile, name, encoding):
    path = tmp_path / name
    autoshovel.write_cloud(path, pile, encoding=encoding)
    back, fmt, dropped = autoshovel.read_cloud(path, with_info=True)
    assert dropped == 0
    assert fmt.split()[0] == name.rsplit(".", 1)[1]
    if name.endswith(".xyz") or encoding == "ascii":
        # Text keeps the shortest decimal that reads back to the same f32.
        np.testing.assert_array_equal(back, pile)
    else:
        np.testing.assert_array_equal(back, pile)


@pytest.mark.parametrize("name", ["g.las", "h.laz"])
def test_las_round_trip_at_its_scale(tmp_path, pile, name):
    path = tmp_path / name
    autoshovel.write_cloud(path, pile)
    back = autoshovel.read_cloud(path)
    assert back.shape == pile.shape
    # LAS stores integers at 1 mm: every point within half of it.
    assert np.abs(back - pile).max() <= 0.0005 + 1e-6


def test_write_keeps_an_existing_file(tmp_path, pile):
    path = tmp_path / "kept.pcd"
    path.write_text("mine")
    with pytest.raises(FileExistsError):
        autoshovel.write_cloud(path, pile)
    assert path.read_text() == "mine"
    autoshovel.write_cloud(path, pile, overwrite=True)
    assert autoshovel.read_cloud(path).shape == pile.shape
    assert [p.name for p in tmp_path.iterdir()] == ["kept.pcd"]


def test_pass_through_matches_a_numpy_mask(pile):
    z = pile[:, 2]
    lo, hi = float(np.quantile(z, 0.2)), float(np.quantile(z, 0.7))
    kept = autoshovel.pass_through(pile, "z", lo, hi)
    mask = (z >= np.float32(lo)) & (z <= np.float32(hi))
    np.testing.assert_array_equal(kept, pile[mask])
    idx = autoshovel.pass_through(pile, "z", lo, hi, keep_inside=False, return_indices=True)
    np.testing.assert_array_equal(idx, np.flatnonzero(~mask))
    assert idx.dtype == np.int64


def test_voxel_grid_matches_numpy_centroids(pile):
    leaf = 0.25
    got = autoshovel.voxel_grid(pile, leaf)
    # Independent: cells by floor(p / leaf) in f32 as PCL, means in f64.
    cells = np.floor(pile * np.float32(1.0 / leaf)).astype(np.int64)
    _, inverse, counts = np.unique(cells, axis=0, return_inverse=True, return_counts=True)
    sums = np.zeros((len(counts), 3))
    np.add.at(sums, inverse.ravel(), pile.astype(np.float64))
    want = sums / counts[:, None]
    assert len(got) == len(want)
    # Order both by the cell each centroid lies in.
    def by_cell(a):
        c = np.floor(a / leaf).astype(np.int64)
        return a[np.lexsort(c.T[::-1])]
    np.testing.assert_allclose(by_cell(got.astype(np.float64)), by_cell(want), atol=2e-6)


def test_statistical_and_radius_keep_the_pile_and_drop_strays(pile):
    strays = np.array([[100, 100, 100], [-50, 20, 40]], dtype=np.float32)
    cloud = np.ascontiguousarray(np.vstack([pile, strays]))
    kept = autoshovel.statistical_outlier_removal(cloud, 20, 1.0, return_indices=True)
    assert len(cloud) - 1 not in kept and len(cloud) - 2 not in kept
    assert len(kept) > 0.8 * len(pile)
    r = autoshovel.radius_outlier_removal(cloud, 0.5, 2, return_indices=True)
    assert len(cloud) - 1 not in r and len(cloud) - 2 not in r


def test_level_undoes_a_known_tilt():
    rng = np.random.default_rng(3)
    flat = np.column_stack([rng.uniform(-10, 10, 5000), rng.uniform(-10, 10, 5000), np.zeros(5000)]).astype(np.float32)
    # Tilt by rotating about x by 4 degrees; levelling with the matching roll undoes it.
    a = np.radians(4.0)
    rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    tilted = (flat.astype(np.float64) @ rx.T).astype(np.float32)
    spreads = []
    for roll in (4.0, -4.0):
        z = autoshovel.level(tilted, roll, 0.0)[:, 2]
        spreads.append(float(np.ptp(z)))
    assert min(spreads) < 1e-4 < max(spreads)


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "bad,error,words",
    [
        (np.zeros((10, 3), dtype=np.float64), TypeError, ["points", "float32", "float64", "(10, 3)"]),
        (np.zeros((10, 2), dtype=np.float32), ValueError, ["points", "(N, 3)", "[10, 2]"]),
        (np.zeros((3, 10), dtype=np.float32).T, ValueError, ["points", "C-contiguous"]),
        ([[0.0, 0.0, 0.0]], TypeError, ["points", "list"]),
        (np.zeros(9, dtype=np.float32), TypeError, ["points", "(N, 3)"]),
    ],
)
def test_bad_arrays_name_the_argument(bad, error, words):
    with pytest.raises(error) as e:
        autoshovel.voxel_grid(bad, 0.1)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_nan_and_bad_parameters_are_named(pile):
    with pytest.raises(ValueError, match=r"voxel_grid\(\): leaf_m = nan"):
        autoshovel.voxel_grid(pile, float("nan"))
    with pytest.raises(ValueError, match="std_mul"):
        autoshovel.statistical_outlier_removal(pile, 10, float("nan"))
    with pytest.raises(ValueError, match="radius_m"):
        autoshovel.radius_outlier_removal(pile, float("inf"), 3)
    with pytest.raises(ValueError, match="axis"):
        autoshovel.pass_through(pile, "w", 0, 1)
    with pytest.raises(ValueError, match="mean_k = -3"):
        autoshovel.statistical_outlier_removal(pile, -3, 1.0)
    # The library's own refusal, with its message.
    with pytest.raises(AutoshovelError, match="mean_k must be at least 1"):
        autoshovel.statistical_outlier_removal(pile, 0, 1.0)
    with pytest.raises(AutoshovelError, match="removed every point"):
        autoshovel.pass_through(pile, "z", 1e6, 2e6)


def test_missing_and_broken_files(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        autoshovel.read_cloud(tmp_path / "nope.pcd")
    assert "nope.pcd" in str(e.value)
    broken = tmp_path / "broken.pcd"
    broken.write_text("VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3\n4 5\n")
    with pytest.raises(AutoshovelError) as e:
        autoshovel.read_cloud(broken)
    assert "broken.pcd" in str(e.value)


@pytest.mark.parametrize(
    "kw,words",
    [
        (dict(points=0), "points = 0: expected at least 1"),
        (dict(roll_deg=80.0), "roll_deg = 80: expected an angle within ±45°"),
        (dict(fov_deg=0.0), "fov_deg = 0: expected a field of view"),
        (dict(scale=-1.0), "scale = -1"),
        (dict(shape="cube"), "shape: unknown pile shape 'cube'"),
        (dict(pattern="x"), "pattern: unknown scan pattern"),
        (dict(seed=-1), "seed = -1: expected 0 to 2**64 - 1"),
        (dict(points=1.5), "points must be a whole number"),
    ],
)
def test_generate_pile_names_the_keyword(kw, words):
    with pytest.raises((ValueError, TypeError)) as e:
        autoshovel.generate_pile(**kw)
    assert words in str(e.value)


def test_a_failed_write_names_the_file_and_leaves_nothing(tmp_path, pile):
    with pytest.raises(AutoshovelError) as e:
        autoshovel.write_cloud(tmp_path / "no-such-folder" / "x.pcd", pile)
    assert "no-such-folder/x.pcd" in str(e.value)
    with pytest.raises(AutoshovelError, match="encoding"):
        # PLY has no compressed encoding: the writer refuses before writing.
        autoshovel.write_cloud(tmp_path / "y.ply", pile, encoding="binary_compressed")
    assert list(tmp_path.iterdir()) == []
