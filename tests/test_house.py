"""Sizes a student can read, enforced on the source with ``ast`` (docs/DESIGN.md, "Readable sizes").

* A module is at most ``MAX_MODULE_LINES`` lines: a longer one holds more than one idea, and the
  ideas go to modules named for them.
* A function's body (its docstring left out) is at most ``MAX_FUNCTION_LINES`` lines: a longer one
  is split into its phases, each a function with a name that says what it does. The speed-tuned
  ``*_kernels.py`` modules are exempt from this one: each keeps a readable reference beside it that
  a test compares it against.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "robokit"

MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 70


def _body_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    body = node.body
    if len(body) > 1 and isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant) \
            and isinstance(body[0].value.value, str):
        body = body[1:]
    return node.end_lineno - body[0].lineno + 1


def _functions(path: Path) -> list[tuple[str, int]]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [(f"{node.name} (line {node.lineno})", _body_lines(node)) for node in ast.walk(tree)
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))]


MODULES = sorted(PACKAGE.rglob("*.py"))
SOURCES = [p for p in MODULES if not p.stem.endswith("_kernels")]


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_modules_hold_one_idea_in_a_readable_length(path):
    n = len(path.read_text(encoding="utf-8").splitlines())
    assert n <= MAX_MODULE_LINES, f"{n} lines: split it by idea (at most {MAX_MODULE_LINES} lines a module)"


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_functions_are_short_enough_to_read(path):
    long = [f"{name}: {n} lines" for name, n in _functions(path) if n > MAX_FUNCTION_LINES]
    assert not long, (f"split into phases (at most {MAX_FUNCTION_LINES} lines of body each): " + ", ".join(long))


def test_the_check_sees_a_long_function(tmp_path):
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_FUNCTION_LINES + 1))
    path = tmp_path / "long.py"
    path.write_text(f'def f():\n    """Doc."""\n{body}\n')
    assert _functions(path) == [("f (line 1)", MAX_FUNCTION_LINES + 1)]
