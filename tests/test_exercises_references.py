"""Every registered exercise: its reference passes its own cases, bad input included, for any seed.

One test for all assignments (discovered from robokit/exercises/), so a new lesson's exercises are
covered without copying this test.
"""
import pytest

from robokit.grading import assignments
from robokit.grading.judge import call_student, expected_output, judge

ALL = [ex for exercises in assignments().values() for ex in exercises]


def test_every_assignment_has_exercises():
    assert len(assignments()) >= 4 and all(assignments().values())


@pytest.mark.parametrize("seed", [7, 2024, "instructor-secret"])
@pytest.mark.parametrize("exercise", ALL, ids=lambda e: e.id)
def test_reference_passes_its_own_cases(exercise, seed):
    cases = exercise.make_cases(seed)
    assert any(c.raises for c in cases), f"{exercise.id}: every exercise needs a bad-input case"
    for case in cases:
        outcome = judge(exercise, case, expected_output(exercise, case), call_student(exercise.reference, case))
        assert outcome.passed, f"{exercise.id} {case.label}: {outcome.message}"


def _same_module_callees(fn) -> set[str]:
    """Dotted names of the functions of ``fn``'s own module that ``fn`` calls, directly or through
    each other (the kernels behind a reference)."""
    import ast
    import importlib
    import inspect
    import textwrap

    module = importlib.import_module(fn.__module__)
    found, todo = set(), [fn]
    while todo:
        tree = ast.parse(textwrap.dedent(inspect.getsource(todo.pop())))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
                callee = getattr(module, node.func.id, None)
                name = f"{module.__name__}.{node.func.id}"
                if inspect.isfunction(callee) and callee.__module__ == module.__name__ and name not in found:
                    found.add(name)
                    todo.append(callee)
    return found


@pytest.mark.parametrize("slug", sorted(assignments()))
def test_the_trap_covers_the_kernels_behind_each_reference(slug):
    # the grading worker never loads the modules of the names an assignment's exercises list
    # (grading.kit), and flags an attempt to import them; a helper in the reference's module that
    # computes the answer must be on that list too, so that calling it is named in the flag (06's
    # _link_matrices and 05's _xor once were reachable)
    import importlib

    trapped = {r for ex in assignments()[slug] for r in ex.references}
    for name in trapped:
        module, _, attr = name.rpartition(".")
        assert hasattr(importlib.import_module(module), attr), f"{slug}: {name} does not exist"
    missing = {ex.id: sorted(_same_module_callees(ex.reference) - trapped) for ex in assignments()[slug]}
    assert not any(missing.values()), f"{slug}: kernels a submission could call untrapped: {missing}"
