"""The grading worker's robokit (issue 12): what student code may import while grading.

The worker runs from a kit that holds only its own modules and the assignment's declared helpers;
an author who adds a robokit import to a notebook without declaring it, or declares a helper that
lives beside a reference, is stopped here rather than by a student's zero.
"""
import ast
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from robokit.exercises import Assignment, catalog, get_assignment
from robokit.grading.kit import KitError, build_kit
from tests.conftest import ROOT

SLUGS = sorted(catalog())


def _robokit_imports(notebook: Path) -> set[str]:
    """Dotted robokit names a notebook's code cells import (``from a.b import c`` -> ``a.b.c``)."""
    names = set()
    for cell in json.loads(notebook.read_text())["cells"]:
        if cell["cell_type"] != "code":
            continue
        source = "".join(cell["source"])
        source = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.Import):
                names.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module:
                names.update(f"{node.module}.{a.name}" for a in node.names)
    return {n for n in names if n == "robokit" or n.startswith("robokit.")}


@pytest.mark.parametrize("slug", SLUGS)
def test_notebooks_import_only_what_the_worker_provides(slug):
    # a robokit import the assignment does not declare fails in the grader (the worker refuses it),
    # so every solution would lose marks: declare it in HELPERS of robokit/exercises/<module>.py
    provided = {"robokit.grading.check", *get_assignment(slug).helpers}
    for folder in ("solutions", "assignments"):
        extra = _robokit_imports(ROOT / folder / f"{slug}.ipynb") - provided
        assert not extra, (f"{folder}/{slug}.ipynb imports {sorted(extra)}: add them to HELPERS of the exercise "
                           f"module (from a module without references), or do not import them")


@pytest.mark.parametrize("slug", SLUGS)
def test_kit_holds_no_reference(slug, tmp_path):
    assignment = get_assignment(slug)
    kit = build_kit(assignment, tmp_path / "kit")
    files = {p.relative_to(kit.root).as_posix() for p in kit.root.rglob("*") if p.is_file()}
    modules = {*kit.manifest.modules, *kit.manifest.stand_ins}
    expected = {"kit.json"} | {m.replace(".", "/") + ("/__init__.py" if m in kit.manifest.stand_ins
                                                       or (ROOT / m.replace(".", "/")).is_dir() else ".py")
                               for m in modules}
    assert files == expected
    defined = {node.name for path in kit.root.rglob("*.py")
               for node in ast.walk(ast.parse(path.read_text())) if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
    references = {r.rpartition(".")[2] for ex in assignment.exercises for r in ex.references}
    assert not defined & references
    for stand_in in kit.manifest.stand_ins:
        tree = ast.parse((kit.root / stand_in.replace(".", "/") / "__init__.py").read_text())
        assert len(tree.body) == 1 and isinstance(tree.body[0], ast.Expr)  # a docstring only
    assert set(kit.manifest.helpers) == set(assignment.helpers)


def test_a_helper_beside_a_reference_is_refused(tmp_path):
    a = get_assignment("05_gps_sonar_truck")
    beside = Assignment(a.slug, a.exercises, a.written, ("robokit.controllers.heading.HeadingController",))
    with pytest.raises(KitError, match="robokit.controllers.heading, which holds a reference"):
        build_kit(beside, tmp_path / "kit")
    with pytest.raises(KitError, match="does not exist"):
        build_kit(Assignment(a.slug, a.exercises, a.written, ("robokit.outdoor.no_such_helper",)), tmp_path / "k2")


def test_helpers_must_be_dotted_robokit_names():
    a = get_assignment("00_getting_started")
    for bad in ("numpy.sum", "robokit.wrap_angle", "robokit.geometry.", 3):
        with pytest.raises(ValueError, match="HELPERS"):
            Assignment(a.slug, a.exercises, a.written, (bad,))
    with pytest.raises(ValueError, match="HELPERS must be a tuple"):
        Assignment(a.slug, a.exercises, a.written, "robokit.outdoor.loop_metrics")


PROBE = """
import json, sys
from pathlib import Path
from robokit.grading.barrier import Manifest, seal
flagged = []
seal(Manifest.read(Path(sys.argv[1])), flagged.append)
out = {}
from robokit.grading import check
from robokit.grading.check import check as check2
check("00.wrap_angle", None)
out["check"] = check is check2
from robokit.outdoor import loop_metrics
out["helper"] = round(loop_metrics(4.479, 0.6, 0.3)["overshoot"], 3)
for name in ["from robokit.outdoor import fix_position", "import robokit.outdoor.nmea",
             "from robokit.controllers import design_heading_gains", "import robokit.controllers.heading",
             "from robokit import outdoor; outdoor.nmea_checksum", "import robokit.exercises.gps_sonar_truck",
             "import robokit.sim", "from robokit.outdoor import Field"]:
    try:
        exec(name)
        out[name] = "imported"
    except BaseException as exc:
        out[name] = type(exc).__name__
out["flagged"] = flagged
out["loaded"] = sorted(m for m in sys.modules if m.startswith("robokit"))
print(json.dumps(out))
"""


def test_the_worker_provides_helpers_and_refuses_the_rest(tmp_path):
    kit = build_kit(get_assignment("05_gps_sonar_truck"), tmp_path / "kit")
    proc = subprocess.run([sys.executable, "-c", textwrap.dedent(PROBE), str(kit.root)], capture_output=True,
                          text=True, env={"PYTHONPATH": str(kit.root), "PYTHONSAFEPATH": "1", "PATH": "/usr/bin"},
                          cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["check"] and out["helper"] == 0.05
    refused = {k: v for k, v in out.items() if k.startswith(("from", "import"))}
    assert refused == {
        "from robokit.outdoor import fix_position": "ReferenceSolutionDisabled",
        "import robokit.outdoor.nmea": "ReferenceSolutionDisabled",
        "from robokit.controllers import design_heading_gains": "ReferenceSolutionDisabled",
        "import robokit.controllers.heading": "ReferenceSolutionDisabled",
        "from robokit import outdoor; outdoor.nmea_checksum": "AttributeError",
        "import robokit.exercises.gps_sonar_truck": "ReferenceSolutionDisabled",
        "import robokit.sim": "ModuleNotFoundError",
        "from robokit.outdoor import Field": "ModuleNotFoundError",
    }
    assert len(out["flagged"]) == 5
    assert set(out["loaded"]) <= {*kit.manifest.modules, *kit.manifest.stand_ins, "robokit.outdoor",
                                  "robokit.grading.check"}
    # a package that re-exports a reference is only ever its empty stand-in or the helpers' facade
    assert not set(out["loaded"]) & set(kit.manifest.forbidden) - {*kit.manifest.stand_ins, "robokit.outdoor"}
