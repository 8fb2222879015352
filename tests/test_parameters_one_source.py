"""Lesson, solution and assignment take their parameters from one place (issue 37, deliverable 5).

Lesson 02's lesson had used a top-5 coarse stage and ratio 0.7 while its assignment used 3 and 0.8.
Now robokit holds them (``mapping.OMNI_RATIO``, ``localization.TOP_K``), the exercises and the
assignment's data take them from there, and the notebooks read the data instead of writing numbers.
These tests hold that, and check every assignment's function defaults against the grader's answers
and the lessons' own functions.
"""
from __future__ import annotations

import ast
import inspect
import json
import re

import pytest

from robocourse.lessons import catalog, get_assignment
from tests.conftest import ROOT


def _code_cells(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    return ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]


def _defaults(node: ast.FunctionDef) -> dict[str, ast.expr]:
    positional = node.args.args[len(node.args.args) - len(node.args.defaults):]
    found = dict(zip((a.arg for a in positional), node.args.defaults))
    found.update({a.arg: d for a, d in zip(node.args.kwonlyargs, node.args.kw_defaults) if d is not None})
    return found


def _data_names(trees: list[ast.Module], data: dict) -> dict[str, object]:
    """Names a notebook binds from its assignment data: ``p = assignment_data(slug)`` then
    ``A, B = p["a"], p["b"]`` (or ``A = p["a"]``)."""
    holders = {n.targets[0].id for t in trees for n in ast.walk(t)
               if isinstance(n, ast.Assign) and isinstance(n.value, ast.Call)
               and getattr(n.value.func, "id", None) == "assignment_data" and isinstance(n.targets[0], ast.Name)}
    names = {}
    for tree in trees:
        for n in ast.walk(tree):
            if not isinstance(n, ast.Assign):
                continue
            targets = n.targets[0].elts if isinstance(n.targets[0], ast.Tuple) else [n.targets[0]]
            values = n.value.elts if isinstance(n.value, ast.Tuple) else [n.value]
            for t, v in zip(targets, values):
                if isinstance(t, ast.Name) and isinstance(v, ast.Subscript) and getattr(v.value, "id", None) in holders:
                    names[t.id] = data[ast.literal_eval(v.slice)]
    return names


@pytest.mark.parametrize("slug", list(catalog()))
def test_notebook_defaults_are_the_graders(slug):
    """A student's function has the defaults the grader's answer computes with: a number written in
    the notebook equals it, a name is read from the assignment's data."""
    assignment = get_assignment(slug)
    trees = [t for t in (_parse(s) for s in _code_cells(ROOT / "solutions" / f"{slug}.ipynb")) if t]
    from_data = _data_names(trees, assignment.data()) if assignment.data else {}
    functions = {n.name: n for t in trees for n in t.body if isinstance(n, ast.FunctionDef)}
    wrong = []
    for ex in assignment.exercises:
        answer = inspect.signature(ex.answer).parameters
        for name, node in _defaults(functions[ex.function]).items():
            if isinstance(node, ast.Name):
                assert node.id in from_data, f"{ex.id}: default {name}={node.id} is not read from the assignment data"
                value = from_data[node.id]
            else:
                value = ast.literal_eval(node)
            if name in answer and answer[name].default != value:
                wrong.append(f"{ex.id}: {name}={value!r} in the notebook, {answer[name].default!r} in the grader")
    assert not wrong, wrong


def _parse(src: str):
    try:
        return ast.parse("\n".join("" if l.lstrip().startswith(("%", "!")) else l for l in src.splitlines()))
    except SyntaxError:
        return None


def test_lesson_02_parameters_come_from_robokit():
    from robokit import localization, mapping
    from robocourse.lessons.omni_localization import exercises, landmarks

    def default(fn, name):
        return inspect.signature(fn).parameters[name].default

    assert exercises.data() == {"ratio": mapping.OMNI_RATIO, "top_k": localization.TOP_K}
    for fn in (exercises.fine_stage_counts, exercises.recognise_node, localization.HierarchicalLocalizer,
               mapping.build_topological_map, mapping.TopologicalMap.match_counts, landmarks.landmark_map):
        assert default(fn, "ratio") == mapping.OMNI_RATIO, fn
    for fn in (exercises.recognise_node, localization.HierarchicalLocalizer):
        assert default(fn, "top_k") == localization.TOP_K, fn
    assert f"ratio={mapping.OMNI_RATIO}" in next(e.signature for e in exercises.EXERCISES
                                                 if e.id == "02.fine_stage_counts")


@pytest.mark.parametrize("folder", ["lessons", "solutions", "assignments"])
def test_lesson_02_notebooks_write_no_ratio_or_top_k(folder):
    """The notebooks name the parameters (robokit's constants, the data's values), never a number."""
    literal = re.compile(r"\b(ratio|top_k)\s*=\s*[\d.]+|histogram_distance\(.*\[:\s*\d+\s*\]")  # a top-k by hand
    found = [line.strip() for src in _code_cells(ROOT / folder / "02_omni_localization.ipynb")
             for line in src.splitlines() if literal.search(line)]
    assert not found, found


#: Parameters an assignment's exercise shares with the function its lesson runs, by name.
SHARED = [
    ("03.likelihood_field_weight", "robokit.localization.mcl:MonteCarloLocalizer", ("sigma_hit", "z_hit", "z_rand", "r_max")),
    ("03.likelihood_field_weight", "robokit.mapping:likelihood_field", ("max_distance",)),
    ("05.drive_course", "robokit.outdoor.navigator:Navigator", ("front", "side")),
]


@pytest.mark.parametrize("exercise_id, target, names", SHARED)
def test_exercises_share_the_lessons_parameters(exercise_id, target, names):
    import importlib

    from robocourse.lessons import get_exercise

    module, attr = target.split(":")
    lesson = inspect.signature(getattr(importlib.import_module(module), attr)).parameters
    answer = inspect.signature(get_exercise(exercise_id).answer).parameters
    assert {n: answer[n].default for n in names} == {n: lesson[n].default for n in names}
