"""The type stubs say what the package holds: every function, and for each
result class exactly the fields of the summary the library makes."""

import ast
import inspect
import tempfile
from pathlib import Path

import pytest

import autoshovel

STUB = Path(autoshovel.__file__).with_name("__init__.pyi")
# Arrays and the table that a result carries beside its summary's fields,
# by class (a perception's `height_model` is a summary field; a survey's is
# its array).
EXTRAS = {
    "DigPlan": {"tooth_path", "pile_profile"},
    "PathPlan": {"waypoints"},
    "Tracking": {"trajectory"},
    "StudySummary": {"table"},
    "SurveyPerception": {"height_model", "model_origin", "tile_files"},
}


def as_laz(points):
    path = Path(tempfile.mkdtemp()) / "survey.laz"
    autoshovel.write_cloud(path, points)
    return path


def stub_classes():
    tree = ast.parse(STUB.read_text())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            out[node.name] = {
                n.target.id for n in node.body if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)
            } - EXTRAS.get(node.name, set())
    return out, {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}


def test_every_public_function_has_a_stub():
    _, functions = stub_classes()
    public = {n for n in autoshovel.__all__ if inspect.isfunction(getattr(autoshovel, n))}
    assert public == functions


@pytest.mark.parametrize(
    "cls,make",
    [
        ("Perception", lambda pile: autoshovel.perceive(pile)),
        ("DigPlan", lambda pile: autoshovel.plan_dig("typical", polish=50)),
        ("PathPlan", lambda pile: autoshovel.plan_path("curve")),
        ("Tracking", lambda pile: autoshovel.track("fig9a")),
        ("Excavation", lambda pile: autoshovel.plan_excavate("paper-over")),
        ("StudySummary", lambda pile: autoshovel.study_paths(3)),
        ("SurveyPerception", lambda pile: autoshovel.perceive_survey(as_laz(pile), tile_m=4.0)),
    ],
)
def test_stub_fields_are_the_summary_fields(pile, cls, make):
    classes, _ = stub_classes()
    result = make(pile)
    assert type(result).__name__ == cls
    assert classes[cls] == set(result), sorted(classes[cls] ^ set(result))


def test_stub_signatures_match_the_functions():
    tree = ast.parse(STUB.read_text())
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            real = inspect.signature(getattr(autoshovel, node.name))
            stub_args = [a.arg for a in node.args.args + node.args.kwonlyargs]
            if node.args.kwarg:
                stub_args.append(node.args.kwarg.arg)
            assert stub_args == list(real.parameters), node.name
