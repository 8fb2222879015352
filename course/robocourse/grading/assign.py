"""``robocourse assign``: generate the student notebook of an assignment (and its data) from the solution.

Conventions in ``solutions/NN_slug.ipynb`` (the single source of the assignment):

* a code cell holding a solution has lines ``# BEGIN SOLUTION`` and ``# END SOLUTION``; what lies
  between them (markers included) becomes ``raise NotImplementedError`` at the same indentation,
  so the ``def`` line and the docstring stay;
* a check cell calls ``check("NN.name", function)``; it becomes an nbgrader *grade* cell worth
  the exercise's points (from ``robocourse.exercises``);
* a written answer is a markdown cell with ``<!-- BEGIN SOLUTION NN.name -->`` ...
  ``<!-- END SOLUTION -->``, holding the model answer and then its rubric (:mod:`.rubrics`); the
  whole region becomes "YOUR ANSWER HERE" and the cell a manually graded nbgrader cell worth
  ``WRITTEN[NN.name]`` points;
* every other cell is locked;
* every code cell that can fail only because an exercise is still blank is tagged
  ``raises-exception`` (:func:`mark_stub_failures`): a check cell, a solution cell whose stub
  raises at its top level, and a cell that uses a name such a cell defines. JupyterLab's Run All
  and nbclient then go on past it, so a student sees every exercise's feedback in one run; the
  grader ignores the tag (it runs every cell and scores each check);
* the grading worker runs every code cell not tagged ``skip-grading`` (:data:`~.submission.SKIP_TAGS`)
  and has no robokit: such a cell may import only ``check`` and ``assignment_data`` from
  robocourse. A cell that interprets results with the library (for a written question) carries
  the tag; the generator refuses a notebook that breaks the rule.

An assignment whose lesson's exercises define ``data()`` also gets its data file
(:mod:`robocourse.grading.data`), written from what that function returns. The output is deterministic (same input, same bytes) and carries nbgrader metadata
(``schema_version`` 3) so the same notebooks work with nbgrader's in-kernel autograde.
"""
from __future__ import annotations

import ast
import copy
import dataclasses
import json
import re
from pathlib import Path
from typing import Any

from robocourse.grading.data import data_file, encode_data
from robocourse.grading.submission import SKIP_TAGS
from robocourse.lessons import get_assignment
from robocourse.site.hygiene import strip_notebook

__all__ = ["make_assignment", "write_assignment", "mark_stub_failures", "AssignmentError", "RAISES", "WRITTEN_REGION"]

_BEGIN = re.compile(r"^(\s*)#+\s*BEGIN SOLUTION\s*$")
_END = re.compile(r"^\s*#+\s*END SOLUTION\s*$")
_CHECK = re.compile(r"""\bcheck\(\s*["'](\d\d\.[a-z][a-z0-9_]*)["']""")
_MD_BEGIN = re.compile(r"<!--\s*BEGIN SOLUTION\s+(\d\d\.[a-z][a-z0-9_]*)\s*-->")
#: A written answer's solution region in a markdown cell: group 1 the question's id, group 2 what the
#: generator replaces (the model answer and its rubric, :mod:`.rubrics`).
WRITTEN_REGION = re.compile(r"<!--\s*BEGIN SOLUTION\s+(\d\d\.[a-z][a-z0-9_]*)\s*-->(.*?)<!--\s*END SOLUTION\s*-->",
                            re.S)
_DEF = re.compile(r"^def\s+([A-Za-z_]\w*)\s*\(", re.M)


#: The cell tag with which JupyterLab's Run All (and nbclient) go on past a cell's error.
RAISES = "raises-exception"


class AssignmentError(ValueError):
    """The solution notebook breaks the conventions (unbalanced markers, unknown exercise, ...)."""


def _source(cell: dict) -> str:
    src = cell.get("source", "")
    return "".join(src) if isinstance(src, list) else src


def _clear_code(src: str, where: str) -> str:
    out, inside, indent = [], False, ""
    for line in src.splitlines():
        begin = _BEGIN.match(line)
        if begin:
            if inside:
                raise AssignmentError(f"{where}: nested '# BEGIN SOLUTION'")
            inside, indent = True, begin.group(1)
            out.append(f"{indent}raise NotImplementedError")
            continue
        if _END.match(line):
            if not inside:
                raise AssignmentError(f"{where}: '# END SOLUTION' without BEGIN")
            inside = False
            continue
        if not inside:
            out.append(line)
    if inside:
        raise AssignmentError(f"{where}: '# BEGIN SOLUTION' without END")
    return "\n".join(out)


#: What a cell the grading worker runs may import from our packages.
WORKER_IMPORTS = {"robocourse": {"check", "assignment_data"}}


def _parse(src: str) -> ast.Module | None:
    """The syntax tree of a code cell (IPython magics and shell lines left out), None if it has none."""
    code = "\n".join("" if line.lstrip().startswith(("%", "!")) else line for line in src.splitlines())
    try:
        return ast.parse(code)
    except SyntaxError:
        return None


def _library_imports(src: str) -> list[str]:
    """The imports of robokit or robocourse in ``src`` beyond :data:`WORKER_IMPORTS` (IPython magics
    and shell lines are left out of the parse)."""
    tree = _parse(src)
    if tree is None:
        return []
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.split(".")[0] in ("robokit", "robocourse")]
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] in ("robokit", "robocourse"):
            allowed = WORKER_IMPORTS.get(node.module, set())
            found += [f"{node.module}.{a.name}" for a in node.names if a.name not in allowed]
    return found


def _executed(tree: ast.Module):
    """The nodes a cell runs when it runs: everything but the bodies of the functions it defines."""
    stack = list(tree.body)
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            stack.extend(node.decorator_list)           # the body runs only when called
        elif not isinstance(node, ast.Lambda):
            stack.extend(ast.iter_child_nodes(node))


def _base_name(node: ast.AST) -> str | None:
    """``res`` of ``res``, ``res[k]``, ``res.a.b`` or ``res[k].append``."""
    while isinstance(node, (ast.Attribute, ast.Subscript)):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


@dataclasses.dataclass
class _CellNames:
    binds: set[str]      # names the cell (re)binds when it runs, its imports among them
    changes: set[str]    # names whose object it changes in place (res[k] = ..., res.append(...), x += 1)
    modules: set[str]    # names it binds by import
    runs_reading: set[str]   # names read by what it runs
    reads: set[str]      # names read anywhere, the bodies of its functions included
    raises: bool         # a raise statement runs (a stub left at the top level)


def _cell_names(tree: ast.Module) -> _CellNames:
    binds, changes, modules, runs_reading, raises = set(), set(), set(), set(), False
    for node in _executed(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            binds.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names = {(a.asname or a.name).split(".")[0] for a in node.names}
            binds |= names
            modules |= names
        elif isinstance(node, ast.Name):
            (binds if isinstance(node.ctx, ast.Store) else runs_reading).add(node.id)   # del x reads x
            if isinstance(node.ctx, ast.Del):
                changes.add(node.id)
        elif isinstance(node, (ast.Attribute, ast.Subscript)) and isinstance(node.ctx, (ast.Store, ast.Del)):
            changes.add(_base_name(node))
        elif isinstance(node, ast.AugAssign):
            changes.add(_base_name(node.target))
            runs_reading.add(_base_name(node.target))        # x += 1 reads x
        elif isinstance(node, ast.Expr) and isinstance(node.value, ast.Call) \
                and isinstance(node.value.func, ast.Attribute):
            changes.add(_base_name(node.value.func.value))     # res.append(f(x)) changes res
        elif isinstance(node, ast.Raise):
            raises = True
    reads = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, (ast.Load, ast.Del))}
    reads |= {_base_name(n.target) for n in ast.walk(tree) if isinstance(n, ast.AugAssign)}
    return _CellNames(binds, changes - {None}, modules, runs_reading - {None}, reads - {None}, raises)


def mark_stub_failures(nb: dict[str, Any]) -> dict[str, Any]:
    """Tag ``raises-exception`` every code cell of a blank assignment that can fail because of a stub.

    A name is *tainted* when a solution cell binds it (a student's function) or a tagged cell binds
    or changes it (a result computed from a stub, perhaps never made); an untagged cell that binds
    it afresh clears it. A cell is tagged when it is a grade (check) cell, when a ``raise`` runs
    at its top level (a stub left in module-level code), or when it reads a tainted name (a solution
    cell: only in what it runs, since defining a function that calls a stub raises nothing). Cells
    that use only imports and given data stay untagged, so a real error there still stops Run All.
    Changes ``nb`` in place and returns it.

    Raises
    ------
    TypeError
        If ``nb`` is not a notebook (a dict whose ``cells`` is a list of dicts).
    """
    if not isinstance(nb, dict) or not isinstance(nb.get("cells", []), list) \
            or not all(isinstance(c, dict) for c in nb.get("cells", [])):
        raise TypeError(f"nb: expected a notebook (a dict with a list of cells), got {type(nb).__name__}")
    tainted: set[str] = set()
    for cell in nb.get("cells", []):
        if cell.get("cell_type") != "code":
            continue
        meta = cell.setdefault("metadata", {})
        grading = meta.get("nbgrader", {})
        names = _cell_names(_parse(_source(cell)) or ast.Module(body=[], type_ignores=[]))   # unparsable: no names
        solution = bool(grading.get("solution"))
        if solution:
            tainted |= names.binds | names.changes
        reads = names.runs_reading if solution else names.reads
        if grading.get("grade") or names.raises or reads & tainted:
            tainted |= (names.binds | names.changes) - names.modules
            tags = meta.setdefault("tags", [])
            if RAISES not in tags:
                tags.append(RAISES)
        elif not solution:
            tainted -= names.binds
    return nb


def _nbgrader(grade_id: str, *, grade: bool, solution: bool, locked: bool, points: float | None = None) -> dict:
    md = {"grade": grade, "grade_id": grade_id, "locked": locked, "schema_version": 3, "solution": solution}
    if points is not None:
        md["points"] = points
    return md


def make_assignment(solution: dict[str, Any], slug: str) -> dict[str, Any]:
    """Return the student notebook generated from a solution notebook (pure, deterministic).

    Raises
    ------
    AssignmentError
        If markers are unbalanced, a check cell names an unknown exercise, an exercise of the
        assignment has no solution or no check cell, or a cell the grading worker runs imports
        what it does not have.
    """
    assignment = get_assignment(slug)
    exercises = {ex.id: ex for ex in assignment.exercises}
    by_function = {ex.function: ex for ex in exercises.values()}
    written = assignment.written
    nb = strip_notebook(copy.deepcopy(solution))
    seen_checks, seen_solutions, seen_written = set(), set(), set()
    for i, cell in enumerate(nb.get("cells", [])):
        src = _source(cell)
        meta = cell.setdefault("metadata", {})
        where = f"solutions/{slug}.ipynb cell {i}"
        library = _library_imports(src) if cell.get("cell_type") == "code" else []
        if library and not SKIP_TAGS & set(meta.get("tags", [])):
            raise AssignmentError(f"{where}: imports {library[0]}, which the grading worker does not have; "
                                  "tag the cell 'skip-grading' if it only interprets results")
        if cell.get("cell_type") == "code" and any(_BEGIN.match(l) for l in src.splitlines()):
            names = _DEF.findall(src)
            ex = next((by_function[n] for n in names if n in by_function), None)
            grade_id = f"{ex.id}.solution" if ex else f"solution-{i:02d}"
            if ex:
                seen_solutions.add(ex.id)
            cell["source"] = _clear_code(src, where)
            meta["nbgrader"] = _nbgrader(grade_id, grade=False, solution=True, locked=False)
        elif cell.get("cell_type") == "code" and _CHECK.search(src):
            ex_id = _CHECK.search(src).group(1)
            if ex_id not in exercises:
                raise AssignmentError(f"{where}: check() names {ex_id!r}, not an exercise of {slug}")
            seen_checks.add(ex_id)
            meta["nbgrader"] = _nbgrader(ex_id, grade=True, solution=False, locked=True,
                                         points=float(exercises[ex_id].points))
        elif cell.get("cell_type") == "markdown" and _MD_BEGIN.search(src):
            qid = _MD_BEGIN.search(src).group(1)
            if qid not in written:
                raise AssignmentError(f"{where}: written question {qid!r} is not in WRITTEN of {slug}")
            if not WRITTEN_REGION.search(src):
                raise AssignmentError(f"{where}: '<!-- BEGIN SOLUTION {qid} -->' without END")
            seen_written.add(qid)
            cell["source"] = WRITTEN_REGION.sub("YOUR ANSWER HERE", src)
            meta["nbgrader"] = _nbgrader(qid, grade=True, solution=True, locked=False, points=float(written[qid]))
        else:
            meta["nbgrader"] = _nbgrader(f"locked-{i:02d}", grade=False, solution=False, locked=True)
        meta["editable"] = not meta["nbgrader"]["locked"]
        meta["deletable"] = False
    missing = [(k, "solution cell") for k in exercises if k not in seen_solutions] + \
              [(k, "check cell") for k in exercises if k not in seen_checks] + \
              [(k, "written answer cell") for k in written if k not in seen_written]
    if missing:
        raise AssignmentError(f"solutions/{slug}.ipynb: missing " +
                              ", ".join(f"{what} for {k}" for k, what in missing))
    mark_stub_failures(nb)
    nb.setdefault("metadata", {})["robokit"] = {"assignment": slug, "generated_from": f"solutions/{slug}.ipynb"}
    return nb


def _dumps(nb: dict) -> str:
    return json.dumps(nb, indent=1, sort_keys=True, ensure_ascii=False) + "\n"


def _update(path: Path, text: str, write: bool) -> bool:
    """Whether ``path`` differs from ``text``; if so and ``write``, write it."""
    old = path.read_text(encoding="utf-8") if path.exists() else None
    if old != text and write:
        path.parent.mkdir(exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return old != text


def write_assignment(root: str | Path, slug: str, *, verify: bool = False) -> bool:
    """Generate ``assignments/<slug>.ipynb`` and the assignment's data file; return whether either
    differed from what was there.

    With ``verify`` nothing is written (used by the tests and CI to detect stale assignments).
    """
    root = Path(root)
    src = root / "solutions" / f"{slug}.ipynb"
    if not src.is_file():
        raise FileNotFoundError(f"slug: no solution notebook {src}")
    text = _dumps(make_assignment(json.loads(src.read_text(encoding="utf-8")), slug))
    changed = _update(root / "assignments" / f"{slug}.ipynb", text, not verify)
    data = get_assignment(slug).data
    if data is not None:
        changed |= _update(data_file(slug), encode_data(data()), not verify)
    return changed
