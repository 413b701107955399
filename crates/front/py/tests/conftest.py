"""Shared fixtures: a generated pile scan, and the CLI binary when CI names it."""

import os
import shutil
import subprocess
import json

import numpy as np
import pytest

import autoshovel


@pytest.fixture(scope="session")
def pile() -> np.ndarray:
    """A 60 000-point scan of the typical pile (seeded)."""
    return autoshovel.generate_pile("typical", 60_000, seed=7)


@pytest.fixture(scope="session")
def cli():
    """Runs the `autoshovel` binary with --json and returns the summary.

    AUTOSHOVEL_BIN (set by .ci/run) names it; without it the test is
    skipped, with it set and missing the test fails."""
    path = os.environ.get("AUTOSHOVEL_BIN") or shutil.which("autoshovel")
    if not path:
        pytest.skip("no autoshovel binary (set AUTOSHOVEL_BIN)")
    assert os.path.exists(path), f"AUTOSHOVEL_BIN={path} does not exist"

    def run(*args: str):
        got = subprocess.run([path, *args, "--json"], capture_output=True, text=True, timeout=600)
        return got.returncode, (json.loads(got.stdout) if got.stdout.strip() else None), got.stderr

    return run
