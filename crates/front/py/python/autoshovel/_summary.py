"""Typed results: a job's summary with the fields of the CLI's summary.json."""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any, Iterator


def _wrap(value: Any) -> Any:
    if isinstance(value, dict):
        return Summary(value)
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


class Summary(Mapping):
    """A job's summary: every field of the command line's ``summary.json``
    (SPEC §6) as an attribute (``s.success``) and as a key (``s["success"]``);
    a nested table is a ``Summary`` too; ``None`` stands for JSON's ``null``
    (a number that was not finite, or a value not there).

    ``to_dict()`` gives the plain JSON value, ``to_json()`` its text.
    """

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[str, Any]):
        object.__setattr__(self, "_data", dict(data))

    @classmethod
    def _from_json(cls, text: str, **extra: Any) -> "Summary":
        s = cls(json.loads(text))
        for k, v in extra.items():
            object.__setattr__(s, k, v)
        return s

    def __getattr__(self, name: str) -> Any:
        try:
            return _wrap(self._data[name])
        except KeyError:
            raise AttributeError(
                f"{type(self).__name__} has no field {name!r} (fields: {', '.join(self._data)})"
            ) from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is read-only")

    def __getitem__(self, key: str) -> Any:
        return _wrap(self._data[key])

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __dir__(self) -> list[str]:
        return sorted(set(super().__dir__()) | set(self._data))

    def to_dict(self) -> dict[str, Any]:
        """The summary as plain JSON values (a deep copy)."""
        return json.loads(json.dumps(self._data))

    def to_json(self, indent: int | None = 2) -> str:
        """The summary as JSON text, as ``--json`` prints it."""
        return json.dumps(self._data, indent=indent, ensure_ascii=False)

    def __repr__(self) -> str:
        head = ", ".join(
            f"{k}={self._data[k]!r}" for k in ("job", "success") if k in self._data
        )
        return f"{type(self).__name__}({head}, {len(self._data)} fields)"


# One class per job, so editors and type checkers know the fields
# (python/autoshovel/__init__.pyi lists them; a test holds the stubs to the
# summaries the library makes).


class Perception(Summary):
    """What :func:`autoshovel.perceive` made: the fields of
    ``autoshovel perceive --json``, the cleaned points and the fitted surface."""

    __slots__ = ("_native",)

    @property
    def points(self):
        """The cleaned, levelled points, an (N, 3) float32 array."""
        return self._native.points()

    def surface_height(self, x, y):
        """The fitted surface z = f(x, y) [RS eq. 21] at arrays x and y [m]."""
        import numpy as np

        x = np.ascontiguousarray(x, dtype=np.float64).ravel()
        y = np.ascontiguousarray(y, dtype=np.float64).ravel()
        return self._native.surface_height(x, y)


class SurveyPerception(Summary):
    """What :func:`autoshovel.perceive_survey` made: the fields of
    ``autoshovel perceive --tiles --json``, ``height_model`` (mean cleaned
    height per cell, rows y and columns x, NaN where no point) with its
    lower corner ``model_origin`` (x, y) [m], and ``tile_files``, the
    cleaned tiles written (empty without ``tiles_dir``)."""

    __slots__ = ("height_model", "model_origin", "tile_files")


class DigPlan(Summary):
    """A dig plan (``autoshovel plan-dig --json``) with the tooth path
    ``tooth_path`` [t_s, x_m, y_m, load_kg] and the pile's profile
    ``pile_profile`` [x_m, y_m] in the dig frame."""

    __slots__ = ("tooth_path", "pile_profile")


class PathPlan(Summary):
    """A walk plan (``autoshovel plan-path --json``) with ``waypoints``
    [x_m, y_m, heading_rad, s_m, curvature_per_m] (empty on failure)."""

    __slots__ = ("waypoints",)


class Tracking(Summary):
    """A tracking run (``autoshovel track --json``) with the main run's
    ``trajectory`` [t_s, x_m, y_m, heading_rad, measured_x_m, measured_y_m,
    centroid_dev_m, heading_error_rad, d_m]."""

    __slots__ = ("trajectory",)


class Excavation(Summary):
    """A hydraulic-excavator dig (``autoshovel plan-excavate --json``)."""

    __slots__ = ()


class StudySummary(Summary):
    """The random-road study (``autoshovel study-paths --json``) with
    ``table``, the Markdown table the command prints."""

    __slots__ = ("table",)
