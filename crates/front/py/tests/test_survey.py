"""A survey by tiles from Python: the command line's result field for field,
its cleaned tiles point for point, and the same result whoever runs the
tiles (here, or a Python executor taking them in another order)."""

import json
import os

import numpy as np
import pytest

import autoshovel
from autoshovel import _native
from test_jobs import same_but_times

# Measured, or named by the caller: not the result.
MEASURED = ("peak_memory_bytes", "points_per_s", "input", "files")


def same_survey(a, b):
    a = {k: v for k, v in a.items() if k not in MEASURED}
    b = {k: v for k, v in b.items() if k not in MEASURED}
    same_but_times(a, b)


@pytest.fixture(scope="module")
def survey(tmp_path_factory, pile):
    path = tmp_path_factory.mktemp("survey") / "pile.laz"
    autoshovel.write_cloud(path, pile)
    return path


def tiles_of(files):
    return {os.path.basename(f): autoshovel.read_cloud(f) for f in files}


def test_a_survey_is_the_command_lines_field_for_field_and_tile_for_tile(tmp_path, survey, cli):
    got = autoshovel.perceive_survey(survey, tile_m=4.0, tiles_dir=tmp_path / "tiles")
    assert isinstance(got, autoshovel.SurveyPerception)
    assert got.mode == "tiles" and got.tiles_used > 4 and got.success
    out = tmp_path / "cli"
    code, ref, err = cli("perceive", "--input", str(survey), "--tile-size", "4", "--out", str(out))
    assert code == 0, err
    same_survey(got.to_dict(), ref)
    mine = tiles_of(got.tile_files)
    theirs = tiles_of(sorted(str(p) for p in (out / "tiles").glob("tile-*.laz")))
    assert mine.keys() == theirs.keys() and len(mine) == got.tiles_used
    for name in mine:
        np.testing.assert_array_equal(mine[name], theirs[name])
    assert sum(len(t) for t in mine.values()) == got.output_points
    # The height model: one cell per model_cell_m, NaN where no point.
    ny, nx = got.height_model.shape
    assert [nx, ny] == list(got.model_size)
    seen = ~np.isnan(got.height_model)
    assert 0 < seen.sum() < seen.size
    pts = np.concatenate(list(mine.values()))
    ix = np.floor((pts[:, 0] - got.model_origin[0]) / got.model_cell_m).astype(int)
    iy = np.floor((pts[:, 1] - got.model_origin[1]) / got.model_cell_m).astype(int)
    # Each cell is the mean height of its cleaned points (LAZ keeps a mm).
    cells = iy * nx + ix
    sums = np.bincount(cells, weights=pts[:, 2], minlength=nx * ny)
    counts = np.bincount(cells, minlength=nx * ny)
    means = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan).reshape(ny, nx)
    assert np.array_equal(np.isnan(means), ~seen)
    assert np.nanmax(np.abs(means - got.height_model)) < 1e-3


def test_tasks_run_by_an_executor_in_another_order_give_the_same_survey(tmp_path, survey):
    here = autoshovel.perceive_survey(survey, tile_m=4.0, tiles_dir=tmp_path / "here")
    stages = []

    def backwards(stage, tasks):
        stages.append((stage, len(tasks)))
        replies = [_native.run_tile_task(t, 1) for t in reversed(tasks)]
        return replies[::-1][::2] + replies[::-1][1::2]

    there = autoshovel.perceive_survey(survey, tile_m=4.0, tiles_dir=tmp_path / "there", executor=backwards)
    same_survey(here.to_dict(), there.to_dict())
    assert np.array_equal(here.height_model, there.height_model, equal_nan=True)
    a, b = tiles_of(here.tile_files), tiles_of(there.tile_files)
    assert a.keys() == b.keys()
    for name in a:
        np.testing.assert_array_equal(a[name], b[name])
    assert [s for s, _ in stages] == ["radius", "statistical", "statistical", "voxel", "smooth"]
    # A task is JSON text a worker can read.
    seen = []

    def spy(stage, tasks):
        seen.extend(json.loads(t) for t in tasks)
        return [_native.run_tile_task(t) for t in tasks]

    autoshovel.perceive_survey(survey, tile_m=4.0, executor=spy)
    assert {"tile", "step", "input", "output", "grid", "halo_m"} <= set(seen[0])


def test_an_executor_that_fails_or_loses_a_task_stops_the_run_and_leaves_nothing(tmp_path, survey):
    work = tmp_path / "work"
    work.mkdir()
    tiles = tmp_path / "tiles"

    def broken(stage, tasks):
        raise RuntimeError(f"worker lost during {stage}")

    with pytest.raises(RuntimeError, match="worker lost during radius"):
        autoshovel.perceive_survey(survey, tile_m=4.0, work_dir=work, tiles_dir=tiles, executor=broken)

    def forgetful(stage, tasks):
        return [_native.run_tile_task(t) for t in tasks[1:]]

    with pytest.raises(autoshovel.AutoshovelError, match=r"radius stage's tiles: \d+ reports for \d+ tasks \(1 tile\(s\) unanswered"):
        autoshovel.perceive_survey(survey, tile_m=4.0, work_dir=work, tiles_dir=tiles, executor=forgetful)

    def garbled(stage, tasks):
        return ["{}" for _ in tasks]

    with pytest.raises(autoshovel.AutoshovelError, match="not a report"):
        autoshovel.perceive_survey(survey, tile_m=4.0, work_dir=work, tiles_dir=tiles, executor=garbled)
    assert list(work.iterdir()) == [] and not tiles.exists()


def test_tiles_written_before_are_kept_unless_overwrite(tmp_path, survey):
    tiles = tmp_path / "tiles"
    first = autoshovel.perceive_survey(survey, tile_m=4.0, tiles_dir=tiles)
    before = {f: os.path.getmtime(f) for f in first.tile_files}
    with pytest.raises(FileExistsError, match="overwrite=True"):
        autoshovel.perceive_survey(survey, tile_m=4.0, tiles_dir=tiles)
    assert {f: os.path.getmtime(f) for f in first.tile_files} == before
    again = autoshovel.perceive_survey(survey, tile_m=4.0, tiles_dir=tiles, overwrite=True)
    assert sorted(again.tile_files) == sorted(first.tile_files)
    assert not [n for n in os.listdir(tiles) if n.startswith(".partial")]


def test_bad_arguments_are_named(tmp_path, survey, pile):
    with pytest.raises(FileNotFoundError, match="inputs"):
        autoshovel.perceive_survey(tmp_path / "missing.laz")
    with pytest.raises(ValueError, match="memory_limit_gib = -1"):
        autoshovel.perceive_survey(survey, memory_limit_gib=-1)
    with pytest.raises(ValueError, match="tile_m = 0"):
        autoshovel.perceive_survey(survey, tile_m=0)
    with pytest.raises(autoshovel.AutoshovelError, match=r"keyword arguments: \[statistical\] mean_k = \"many\": invalid type"):
        autoshovel.perceive_survey(survey, statistical={"mean_k": "many"})
    with pytest.raises(autoshovel.AutoshovelError, match=r"keyword arguments: \[statistical\] mean_k = 0 is invalid"):
        autoshovel.perceive_survey(survey, statistical={"mean_k": 0})
    with pytest.raises(TypeError, match="inputs must be a LAS/LAZ path"):
        autoshovel.perceive_survey(pile)
    ply = tmp_path / "scan.ply"
    autoshovel.write_cloud(ply, pile)
    with pytest.raises(autoshovel.AutoshovelError, match="perceive other formats whole"):
        autoshovel.perceive_survey(ply)
    with pytest.raises(TypeError, match="executor must be callable"):
        autoshovel.perceive_survey(survey, executor=3)
    with pytest.raises(ValueError, match="not a tile task"):
        _native.run_tile_task('{"tile": 1}')


def test_the_cli_and_the_package_agree_on_a_folder_survey(tmp_path, pile, cli):
    # A survey in two files, given as their folder.
    folder = tmp_path / "flights"
    folder.mkdir()
    autoshovel.write_cloud(folder / "a.laz", pile[:25_000])
    autoshovel.write_cloud(folder / "b.laz", pile[25_000:])
    got = autoshovel.perceive_survey(folder, tile_m=5.0)
    code, ref, err = cli("perceive", "--input", str(folder), "--tile-size", "5")
    assert code == 0, err
    same_survey(got.to_dict(), ref)
    assert len(got.files) == 2
