"""The grading worker's code (its kit): no robokit, and what student code may import while grading.

The worker runs from a kit that holds only its own robocourse modules and the assignment's data
file. An author who adds a library import to a cell the grader runs is stopped here (and by
``robocourse assign``) rather than by a student's zero.
"""
import ast
import json
import subprocess
import sys
import textwrap

import pytest

from robocourse.grading.assign import AssignmentError, make_assignment
from robocourse.grading.data import assignment_data, data_file
from robocourse.grading.kit import WORKER, build_kit
from robocourse.grading.submission import SKIP_TAGS
from robocourse.lessons import catalog, get_assignment
from robocourse.source import closure
from tests.conftest import ROOT

SLUGS = sorted(catalog())


def _imports(source: str) -> set[str]:
    """Dotted names a cell imports (``from a.b import c`` -> ``a.b.c``), magics left out."""
    source = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
    names = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.update(f"{node.module}.{a.name}" for a in node.names)
    return {n for n in names if n.split(".")[0] in ("robokit", "robocourse")}


@pytest.mark.parametrize("slug", SLUGS)
def test_the_cells_the_grader_runs_import_only_what_the_worker_has(slug):
    for folder in ("solutions", "assignments"):
        for cell in json.loads((ROOT / folder / f"{slug}.ipynb").read_text())["cells"]:
            if cell["cell_type"] == "code" and not SKIP_TAGS & set(cell["metadata"].get("tags", [])):
                extra = _imports("".join(cell["source"])) - {"robocourse.check", "robocourse.assignment_data"}
                assert not extra, f"{folder}/{slug}.ipynb imports {sorted(extra)} in a cell the grader runs"


def test_assign_refuses_a_graded_cell_that_imports_the_library():
    solution = json.loads((ROOT / "solutions" / "05_gps_sonar_truck.ipynb").read_text())
    cell = next(c for c in solution["cells"] if "loop_metrics" in "".join(c["source"]) and c["cell_type"] == "code")
    cell["metadata"]["tags"] = []
    with pytest.raises(AssignmentError, match="robokit.controllers.loop_metrics.*skip-grading"):
        make_assignment(solution, "05_gps_sonar_truck")


def test_the_worker_runs_on_no_library_code():
    modules = closure([WORKER, "robocourse.grading.data"], parents=False)
    assert not [m for m in modules if m.startswith("robokit") or m.startswith("robocourse.lessons")]


@pytest.mark.parametrize("slug", SLUGS)
def test_the_kit_holds_the_worker_and_the_data_and_nothing_else(slug, tmp_path):
    kit = build_kit(get_assignment(slug), tmp_path / "kit")
    files = {p.relative_to(kit.root).as_posix() for p in kit.root.rglob("*") if p.is_file()}
    expected = {"kit.json"} | {m.replace(".", "/") + ".py" for m in kit.manifest.modules} \
        | {m.replace(".", "/") + "/__init__.py" for m in kit.manifest.stand_ins}
    if data_file(slug).is_file():
        expected.add(f"robocourse/data/{slug}.json")
        assert kit.manifest.data == slug
    assert files == expected
    assert not any(f.startswith("robokit") for f in files)
    for stand_in in kit.manifest.stand_ins:
        tree = ast.parse((kit.root / stand_in.replace(".", "/") / "__init__.py").read_text())
        assert len(tree.body) == 1 and isinstance(tree.body[0], ast.Expr)  # a docstring only


def test_assignment_data_is_what_the_lesson_made_and_plain():
    data = assignment_data("04_littledog")
    assert data == json.loads(json.dumps(get_assignment("04_littledog").data()))
    with pytest.raises(ValueError, match="slug: expected an assignment with data"):
        assignment_data("05_gps_sonar_truck")
    for bad in ("../04_littledog", "4_littledog", 4):
        with pytest.raises(ValueError, match="slug"):
            assignment_data(bad)


PROBE = """
import json, sys
from pathlib import Path
from robocourse.grading.barrier import Manifest, seal
flagged = []
seal(Manifest.read(Path(sys.argv[1])), flagged.append)
out = {}
from robocourse import check, assignment_data
from robokit.grading import check as old_check
check("04.leg_fk", None)
out["check"] = check is old_check
out["data"] = assignment_data("04_littledog")["model_facts"]["UPPER_LEG"]
for name in ["import robokit.legged", "from robokit.legged import leg_ik", "from robokit import legged",
             "import robokit; robokit.geometry", "import robocourse.lessons.littledog.exercises",
             "from robocourse.lessons import catalog", "import robocourse.grading.check",
             "assignment_data('05_gps_sonar_truck')"]:
    try:
        exec(name)
        out[name] = "ok"
    except BaseException as exc:
        out[name] = type(exc).__name__
del sys.modules["robokit"], sys.modules["robokit.grading"]
import robokit                                   # served again by the barrier, never from a file
from robokit.grading import check as again
out["served again"] = getattr(robokit, "__file__", None) is None and again is check
out["flagged"] = flagged
out["loaded"] = sorted(m for m in sys.modules if m.split(".")[0] in ("robokit", "robocourse"))
print(json.dumps(out))
"""


def test_the_worker_offers_check_and_the_data_and_refuses_the_rest(tmp_path):
    kit = build_kit(get_assignment("04_littledog"), tmp_path / "kit")
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(PROBE), str(kit.root)], capture_output=True,
                          text=True, env={"PYTHONPATH": str(kit.root), "PYTHONSAFEPATH": "1", "PATH": "/usr/bin"},
                          cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["check"] and out["data"] == 0.0751
    refused = {k: v for k, v in out.items() if k.startswith(("from", "import", "assignment_data"))}
    assert refused == {
        "import robokit.legged": "RobokitWithheld",
        "from robokit.legged import leg_ik": "RobokitWithheld",
        "from robokit import legged": "RobokitWithheld",
        "import robokit; robokit.geometry": "RobokitWithheld",
        "import robocourse.lessons.littledog.exercises": "RobokitWithheld",
        "from robocourse.lessons import catalog": "RobokitWithheld",
        "import robocourse.grading.check": "RobokitWithheld",
        "assignment_data('05_gps_sonar_truck')": "ValueError",
    }
    assert len(out["flagged"]) == 7 and out["served again"]
    assert set(out["loaded"]) <= {*kit.manifest.modules, *kit.manifest.stand_ins, "robokit", "robokit.grading"}
