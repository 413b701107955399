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
