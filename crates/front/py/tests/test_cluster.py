"""Studies on a local Ray cluster (a head and two worker processes on
loopback) give the single-machine numbers for the same seeds."""

import os
import re

import numpy as np
import pytest

import autoshovel

if os.environ.get("AUTOSHOVEL_REQUIRE_RAY"):
    import ray  # noqa: F401  (CI: fail, do not skip, without Ray)
else:
    pytest.importorskip("ray")

from autoshovel import cluster  # noqa: E402
from test_jobs import same_but_times  # noqa: E402


@pytest.fixture(scope="module")
def local():
    with cluster.LocalCluster(workers=2) as c:
        yield c


def without_time_column(table: str) -> str:
    # The last column is the measured mean plan time.
    return "\n".join(re.sub(r"\| [^|]* \|$", "|", line) for line in table.splitlines())


def test_shards_cover_every_index_once():
    for total, shards in [(10, 3), (3, 10), (0, 2), (100_000, 7)]:
        ranges = cluster.shard_ranges(total, shards)
        assert [i for r in ranges for i in r] == list(range(total))
        sizes = [len(r) for r in ranges]
        assert not sizes or max(sizes) - min(sizes) <= 1


def test_balanced_groups_hold_every_index_once_and_near_equal_sums():
    weights = [5, 1, 1, 200, 3, 0, 40, 40, 39, 2, 7, 7]
    for bins in (1, 3, 5, 20):
        groups = cluster.balanced(weights, bins)
        assert sorted(i for g in groups for i in g) == list(range(len(weights)))
        assert len(groups) <= bins and all(groups)
        sums = [sum(weights[i] for i in g) for g in groups]
        # Greedy heaviest-first: no group exceeds the lightest by more than
        # its own lightest item, unless that item stands alone.
        for g, s in zip(groups, sums):
            assert len(g) == 1 or s - min(sums) <= min(weights[i] for i in g)
    assert cluster.balanced(weights, 3) == cluster.balanced(list(weights), 3)
    with pytest.raises(ValueError, match="bins = 0"):
        cluster.balanced(weights, 0)


def test_study_on_the_cluster_equals_one_machine(local):
    import ray

    assert ray.cluster_resources().get("CPU") == 2
    alone = autoshovel.study_paths(300, seed=3)
    spread = cluster.study_paths(300, seed=3, shards=7)
    same_but_times(spread.to_dict(), alone.to_dict())
    assert without_time_column(spread.table) == without_time_column(alone.table)


def test_study_refuses_missing_or_doubled_maps():
    from autoshovel import _native

    one = _native.study_paths_rows(4, 1, 3, 12, 0, 2, 1)
    with pytest.raises(autoshovel.AutoshovelError, match="expected 4"):
        _native.study_paths_summary(4, 1, 3, 12, [one])
    with pytest.raises(autoshovel.AutoshovelError, match="map 0 where map 1 belongs"):
        _native.study_paths_summary(4, 1, 3, 12, [one, one])


def test_track_grid_equals_direct_runs(local):
    rows = cluster.track_grid("fig9a", controller="pid", gains={"pid.kp": [400.0, 900.0]}, seeds=[1, 2])
    assert [(r["gains"]["pid.kp"], r["seed"]) for r in rows] == [(400.0, 1), (400.0, 2), (900.0, 1), (900.0, 2)]
    for r in rows:
        direct = autoshovel.track("fig9a", controller="pid", seed=r["seed"], noise="rtk", controllers={"pid": {"kp": r["gains"]["pid.kp"]}})
        same_but_times(r["summary"], direct.to_dict())


def test_plan_dig_over_a_folder_of_scans(local, tmp_path):
    for seed in (1, 2):
        autoshovel.write_cloud(tmp_path / f"scan{seed}.pcd", autoshovel.generate_pile("convex", 40_000, seed=seed))
    (tmp_path / "notes.txt").write_text("not a scan")
    rows = cluster.plan_dig_folder(tmp_path, polish=100)
    assert [os.path.basename(r["file"]) for r in rows] == ["scan1.pcd", "scan2.pcd"]
    for r in rows:
        assert r["error"] is None
        direct = autoshovel.plan_dig(autoshovel.perceive(r["file"]), polish=100)
        same_but_times(r["dig"], direct.to_dict())


def test_a_survey_on_the_cluster_equals_one_machine(local, tmp_path, pile):
    survey = tmp_path / "pile.laz"
    autoshovel.write_cloud(survey, pile)
    alone = autoshovel.perceive_survey(survey, tile_m=4.0, tiles_dir=tmp_path / "alone")
    spread = cluster.perceive_survey(survey, tile_m=4.0, tiles_dir=tmp_path / "spread", work_dir=tmp_path)
    drop = ("peak_memory_bytes", "points_per_s")
    same_but_times(
        {k: v for k, v in spread.to_dict().items() if k not in drop},
        {k: v for k, v in alone.to_dict().items() if k not in drop},
    )
    assert np.array_equal(spread.height_model, alone.height_model, equal_nan=True)
    assert [os.path.basename(f) for f in spread.tile_files] == [os.path.basename(f) for f in alone.tile_files]
    for a, b in zip(alone.tile_files, spread.tile_files):
        np.testing.assert_array_equal(autoshovel.read_cloud(a), autoshovel.read_cloud(b))
    # The run's working files are gone.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["alone", "pile.laz", "spread"]
