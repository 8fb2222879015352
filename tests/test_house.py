"""Sizes a student can read, enforced on the source of both packages (docs/DESIGN.md, "Readable sizes").

* A module holds at most ``MAX_MODULE_CODE`` lines of code: docstrings, comments and blank lines are
  free, so documenting a module never forces a split. A longer one holds more than one idea, and
  the ideas go to modules named for them.
* A function's body (its docstring left out) is at most ``MAX_FUNCTION_LINES`` lines: a longer one
  is split into its phases, each a function with a name that says what it does. The speed-tuned
  ``*_kernels.py`` modules are exempt from this one: each keeps a readable version beside it that
  a test compares it against.
"""
from __future__ import annotations

import ast
import io
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = (ROOT / "robokit", ROOT / "course" / "robocourse")

MAX_MODULE_CODE = 500
MAX_FUNCTION_LINES = 70


def code_lines(source: str) -> int:
    """Lines holding code: not blank, not only a comment, not part of a docstring or other string
    statement."""
    tree = ast.parse(source)
    text = {line for node in ast.walk(tree)
            if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)
            for line in range(node.lineno, node.end_lineno + 1)}
    skip = (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.ENDMARKER)
    lines = set()
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type not in skip:
            lines.update(n for n in range(token.start[0], token.end[0] + 1) if n not in text)
    return len(lines)


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


MODULES = sorted(p for package in PACKAGES for p in package.rglob("*.py"))
SOURCES = [p for p in MODULES if not p.stem.endswith("_kernels")]


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_modules_hold_one_idea_in_a_readable_length(path):
    n = code_lines(path.read_text(encoding="utf-8"))
    assert n <= MAX_MODULE_CODE, f"{n} lines of code: split it by idea (at most {MAX_MODULE_CODE} a module)"


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_functions_are_short_enough_to_read(path):
    long = [f"{name}: {n} lines" for name, n in _functions(path) if n > MAX_FUNCTION_LINES]
    assert not long, (f"split into phases (at most {MAX_FUNCTION_LINES} lines of body each): " + ", ".join(long))


def test_the_check_sees_a_long_function(tmp_path):
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_FUNCTION_LINES + 1))
    path = tmp_path / "long.py"
    path.write_text(f'def f():\n    """Doc."""\n{body}\n')
    assert _functions(path) == [("f (line 1)", MAX_FUNCTION_LINES + 1)]


def test_code_lines_leave_out_docstrings_comments_and_blanks():
    source = '"""Module.\n\nMore."""\n\n# a comment\nx = 1  # trailing\n\n\ndef f():\n    """Doc."""\n    return (x +\n            1)\n'
    assert code_lines(source) == 4           # x = 1; def f(); return (x +; 1)
