"""The README's walk through runs: LAZ scan -> perceive -> plan_dig -> matplotlib."""

import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("matplotlib")
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "dig_from_scan.py"


def test_dig_from_scan_example(tmp_path, capsys):
    spec = importlib.util.spec_from_file_location("dig_from_scan", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    png = tmp_path / "dig.png"
    assert mod.main(["--png", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = capsys.readouterr().out
    assert "dig:" in out and "kept" in out
