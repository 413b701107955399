"""The jobs from Python: the same numbers as the command line, typed results,
the library's errors."""

import math

import numpy as np
import pytest

import autoshovel
from autoshovel import AutoshovelError

# Measured wall times differ from run to run; everything else must not.
TIMES = ("_ms", "_time_s", "ms_per", "realtime_factor")


def same_but_times(a, b, path=""):
    """Asserts two JSON values equal except fields named as timings."""
    if isinstance(a, dict):
        assert set(a) == set(b), (path, set(a) ^ set(b))
        for k in a:
            if k == "ms" or any(t in k for t in TIMES):
                continue
            same_but_times(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            same_but_times(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and isinstance(b, float):
        assert a == b or (math.isnan(a) and math.isnan(b)), (path, a, b)
    else:
        assert a == b, (path, a, b)


def test_perceive_an_array_and_a_file_alike(tmp_path, pile):
    seen = autoshovel.perceive(pile)
    assert isinstance(seen, autoshovel.Perception)
    assert seen.job == "perceive" and seen.success is True
    pts = seen.points
    assert pts.dtype == np.float32 and pts.shape[1] == 3 and 1000 < len(pts) < len(pile)
    path = tmp_path / "pile.pcd"
    autoshovel.write_cloud(path, pile)
    from_file = autoshovel.perceive(path)
    a, b = seen.to_dict(), from_file.to_dict()
    # A file adds its read stage; where the points came from differs.
    for k in ("input", "format", "stages", "stage_points", "timings_ms"):
        a.pop(k, None), b.pop(k, None)
    same_but_times(a, b)
    # The fitted surface passes through the cleaned points (R² of the summary).
    z = seen.surface_height(pts[:, 0], pts[:, 1])
    resid = pts[:, 2] - z
    r2 = 1 - resid.var() / pts[:, 2].var()
    assert r2 > 0.9


def test_perceive_settings_as_keywords(pile):
    base = autoshovel.perceive(pile)
    fewer = autoshovel.perceive(pile, voxel={"leaf_spacings": 6.0})
    assert len(fewer.points) < len(base.points)
    with pytest.raises(AutoshovelError, match="nope"):
        autoshovel.perceive(pile, nope=1)
    with pytest.raises(AutoshovelError, match="mean_k"):
        autoshovel.perceive(pile, statistical={"mean_k": 0})
    with pytest.raises(ValueError, match=r"statistical\.std_mul = nan"):
        autoshovel.perceive(pile, statistical={"std_mul": float("nan")})
    with pytest.raises(FileNotFoundError):
        autoshovel.perceive("/no/such/scan.laz")
    with pytest.raises(TypeError, match="cloud"):
        autoshovel.perceive(42)


def test_perceive_errors_name_the_file(tmp_path):
    # A pipeline error on a file is prefixed with it, as the CLI's are; a
    # read error names it by itself.
    few = tmp_path / "three.xyz"
    few.write_text("0 0 0\n1 0 0\n0 1 0\n")
    with pytest.raises(AutoshovelError) as e:
        autoshovel.perceive(few)
    assert str(e.value).startswith(f"{few}: "), str(e.value)
    bad = tmp_path / "bad.pcd"
    bad.write_text("not a point cloud\n")
    with pytest.raises(AutoshovelError, match="bad.pcd"):
        autoshovel.perceive(bad)


def test_perceive_matches_the_cli(tmp_path, pile, cli):
    path = tmp_path / "pile.pcd"
    autoshovel.write_cloud(path, pile)
    rc, want, err = cli("perceive", "--input", str(path))
    assert rc == 0, err
    same_but_times(autoshovel.perceive(path).to_dict(), want)


def test_plan_dig_on_a_perceived_scan():
    # The planner's built-in machine is the paper's 1:30 model: a pile at that scale.
    seen = autoshovel.perceive(autoshovel.generate_pile("typical", 60_000, scale=1 / 30, seed=2))
    plan = autoshovel.plan_dig(seen, polish=300)
    assert isinstance(plan, autoshovel.DigPlan) and plan.job == "plan-dig"
    assert plan.success, plan.error
    assert plan.tooth_path.shape[1] == 4 and plan.pile_profile.shape[1] == 2
    assert plan.m_dig_kg > 0 and 0.5 < plan.fill_factor <= 1.0
    # The tooth path starts on the pile's profile and ends above it, and its
    # time column ends at the dig time t_d.
    x0, y0 = plan.tooth_path[0, 1:3]
    assert abs(np.interp(x0, *plan.pile_profile.T) - y0) < 0.01
    x1, y1 = plan.tooth_path[-1, 1:3]
    assert y1 > np.interp(x1, *plan.pile_profile.T)
    assert abs(plan.tooth_path[-1, 0] - plan.td_s) < 1e-9


def test_a_full_size_scan_is_no_pile_for_the_scale_model(pile):
    plan = autoshovel.plan_dig(autoshovel.perceive(pile), polish=0)
    assert not plan.success and "1:30 scale" in plan.error or "scale" in plan.error


def test_plan_dig_matches_the_cli(cli):
    rc, want, err = cli("plan-dig", "--surface", "convex", "--seed", "3", "--polish", "200")
    assert rc == 0, err
    got = autoshovel.plan_dig("convex", seed=3, polish=200)
    same_but_times(got.to_dict(), want)


def test_plan_path_track_excavate_match_the_cli(cli):
    rc, want, err = cli("plan-path", "--scenario", "v-shape")
    assert rc == 0, err
    got = autoshovel.plan_path("v-shape")
    same_but_times(got.to_dict(), want)
    assert got.waypoints.shape[1] == 5 and got.success

    rc, want, err = cli("track", "--scenario", "fig9a", "--controller", "pid", "--seed", "4")
    assert rc == 0, err
    same_but_times(autoshovel.track("fig9a", controller="pid", seed=4).to_dict(), want)

    rc, want, err = cli("plan-excavate", "--scenario", "paper-under")
    assert rc == 0, err
    same_but_times(autoshovel.plan_excavate("paper-under").to_dict(), want)


def test_study_paths_matches_the_cli(cli):
    rc, want, err = cli("study-paths", "--maps", "24", "--seed", "5")
    assert rc == 0, err
    got = autoshovel.study_paths(24, seed=5)
    same_but_times(got.to_dict(), want)
    assert "| improved-apf |" in got.table


def test_track_gains_reach_the_controller():
    a = autoshovel.track("fig9a", controller="pid", noise="off")
    b = autoshovel.track("fig9a", controller="pid", noise="off", controllers={"pid": {"kp": 100.0}})
    assert a.trajectory.shape[1] == 9
    assert not np.array_equal(a.trajectory, b.trajectory)
    with pytest.raises(AutoshovelError, match="kq"):
        autoshovel.track("fig9a", controller="pid", controllers={"pid": {"kq": 1.0}})
    with pytest.raises(ValueError, match="controller"):
        autoshovel.track("fig9a", controller="lqr")


def test_library_errors_keep_their_messages(cli):
    with pytest.raises(AutoshovelError) as e:
        autoshovel.plan_path("no-such-scenario")
    rc, _, err = cli("plan-path", "--scenario", "no-such-scenario")
    assert rc != 0 and str(e.value) in err
    with pytest.raises(AutoshovelError, match="maps = 0"):
        autoshovel.study_paths(0)


def test_summaries_are_read_only_mappings(pile):
    s = autoshovel.study_paths(4)
    assert s["job"] == s.job == "study-paths"
    assert set(s) == set(s.to_dict())
    with pytest.raises(AttributeError):
        s.job = "x"
    with pytest.raises(AttributeError, match="no field"):
        s.nothing
