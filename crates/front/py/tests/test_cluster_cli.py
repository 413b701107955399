"""`python -m autoshovel.cluster` as a user runs it (its own local cluster)."""

import json
import os

import pytest

import autoshovel

if not os.environ.get("AUTOSHOVEL_REQUIRE_RAY"):
    pytest.importorskip("ray")

from autoshovel import cluster  # noqa: E402
from test_jobs import same_but_times  # noqa: E402


def test_the_command_prints_the_study(capsys):
    assert cluster.main(["--address", "local", "--workers", "2", "--json", "study-paths", "--maps", "40", "--seed", "9"]) == 0
    got = json.loads(capsys.readouterr().out)
    same_but_times(got, autoshovel.study_paths(40, seed=9).to_dict())
    import ray

    assert not ray.is_initialized()


def test_the_command_perceives_a_survey(capsys, tmp_path, pile):
    survey = tmp_path / "pile.laz"
    autoshovel.write_cloud(survey, pile)
    tiles = tmp_path / "tiles"
    argv = ["--address", "local", "--workers", "2", "perceive-survey", str(survey), "--tile-size", "4", "--tiles-dir", str(tiles), "--work-dir", str(tmp_path)]
    assert cluster.main(argv) == 0
    said = capsys.readouterr()
    alone = autoshovel.perceive_survey(survey, tile_m=4.0)
    assert f"{alone.input_points} points in {alone.tiles_used} tiles" in said.out
    assert f"-> {alone.output_points} cleaned" in said.out
    assert f"{alone.tiles_used} tile file(s) written" in said.err
    assert len(list(tiles.glob("tile-*.laz"))) == alone.tiles_used
