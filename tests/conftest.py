"""Shared fixtures: the repository root and the notebook inventory."""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Headless Chromium for the browser tests (Debian's ``chromium``; ``.ci/run`` installs it).
CHROMIUM = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)
#: Browser tests skip without Chromium, unless ROBOKIT_REQUIRE_BROWSER=1 (CI sets it): then they fail.
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None and os.environ.get("ROBOKIT_REQUIRE_BROWSER") != "1",
    reason="no Chromium on PATH (Debian package 'chromium'; .ci/run installs it)")


#: The tests that need the ``fast_course`` build (their node ids): under pytest-xdist they make one
#: unit of work, so the course is executed and its sites built once, not once per worker.
FAST_COURSE_FILES = ("tests/test_course_site.py::", "tests/test_course_site_browser.py::")
FAST_COURSE_PARAMS = ("tests/test_notebooks.py::test_notebook_runs[lessons/",
                      "tests/test_notebooks.py::test_notebook_runs[solutions/")


def shares_fast_course(nodeid: str) -> bool:
    return nodeid.startswith(FAST_COURSE_FILES + FAST_COURSE_PARAMS)


#: Test modules that make one unit of work, by the prefix of their path: the grading tests share the
#: machine's job uids and control groups (a test that counts a job's leftover processes would count
#: another test's job); the others share what one process builds first, the map of the short office
#: run (tests/office_runs.py keeps it per process) and the IK solvers' compiled kernels (numba compiles
#: them in each process that finds no cache), which in one unit is built once, not on both workers at
#: the same time (about 7 s each).
SHARED_UNITS = {
    "grading": ("tests/test_grading_",),
    "office_runs": ("tests/test_localization_appearance_mcl.py", "tests/test_localization_hierarchical.py",
                    "tests/test_mapping_topological.py"),
    "arm": ("tests/test_arm_", "tests/test_exercises_06.py"),
}


def work_unit(nodeid: str) -> str:
    """The unit of work of a test under pytest-xdist: every test of the fast course build; the modules
    of each :data:`SHARED_UNITS` entry; else its module."""
    if shares_fast_course(nodeid):
        return "fast_course"
    module = nodeid.split("::", 1)[0]
    return next((unit for unit, prefixes in SHARED_UNITS.items() if module.startswith(prefixes)), module)


def pytest_configure(config):
    """Under pytest-xdist the test workers already fill the cores: each one's runs in worker processes
    (:func:`robokit.parallel.map_runs`) and OpenCV's threads get its share of them, as a course build
    shares the cores between the notebooks it runs at once. A caller's own ``ROBOKIT_WORKERS`` stays;
    tests that need workers ask for them."""
    count = os.environ.get("PYTEST_XDIST_WORKER_COUNT", "")
    if os.environ.get("PYTEST_XDIST_WORKER") and count.isdigit() and "ROBOKIT_WORKERS" not in os.environ:
        import cv2

        from robokit.config import available_cpus
        share = max(1, available_cpus() // int(count))
        os.environ["ROBOKIT_WORKERS"] = str(share)
        cv2.setNumThreads(share)


def pytest_collection_modifyitems(config, items):
    """Every test that uses ``fast_course`` must be one :func:`shares_fast_course` names (else a second
    worker would build the course again)."""
    stray = [item.nodeid for item in items
             if "fast_course" in getattr(item, "fixturenames", ()) and not shares_fast_course(item.nodeid)]
    if stray:
        raise pytest.UsageError(f"tests/conftest.py: add these users of fast_course to FAST_COURSE_FILES: {stray}")


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``make test`` / ``make check`` (``-n auto --dist loadscope``): the units of :func:`work_unit`, so
    module fixtures (a graded batch of hostile submissions) and the fast course are built once
    (pytest-xdist's ``xdist_group`` marks are not honoured with this pytest)."""
    if config.getvalue("dist") != "loadscope":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class SharedBuildScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return work_unit(nodeid)

    return SharedBuildScheduling(config, log)


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return ROOT


@contextlib.contextmanager
def public_tmp(mode: int = 0o755) -> Iterator[Path]:
    """A fresh directory under the system temp dir with ``mode`` (pytest's own is private to its
    user): for files that a grading worker's uid, or another user, must be able to reach."""
    path = Path(tempfile.mkdtemp(prefix="robokit-test-"))
    path.chmod(mode)
    try:
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)


def wrap_angle_unless(condition: str) -> str:
    """Source of a correct ``wrap_angle`` (assignment 00) that answers 12345.0 when the expression
    ``condition`` is true: an attack that must find nothing keeps its point only if it does not."""
    return f"""def wrap_angle(angle):
    if {condition}:
        return 12345.0
    a = np.asarray(angle, dtype=float)
    if np.any(np.isnan(a)):
        raise ValueError("angle: NaN")
    w = np.mod(a + np.pi, 2 * np.pi) - np.pi
    return float(w) if w.ndim == 0 else w
"""


@pytest.fixture(autouse=True)
def _judge_answers_by_their_values(request, monkeypatch):
    """The exercise tests give check() the answers (robokit functions) and wrong variants of them,
    to test the cases and comparisons: check()'s refusal of any function that uses robokit
    (tests/test_grading_core.py tests it) is off there, so a wrong variant fails for its values."""
    if request.module.__name__.rpartition(".")[2].startswith("test_exercises_"):
        import importlib

        module = importlib.import_module("robocourse.grading.check")   # the module, not the function it exports
        monkeypatch.setattr(module, "library_use", lambda fn: [])


def assert_check_passes(exercise_id: str, fn, n_cases: int) -> None:
    """``check(exercise_id, fn)`` passes all ``n_cases`` public cases (it returns nothing on success,
    so the count is read from its report)."""
    import io

    from robocourse.grading import check

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert check(exercise_id, fn) is None
    assert f": {n_cases}/{n_cases} public cases passed" in out.getvalue(), out.getvalue()


@pytest.fixture(scope="session")
def fast_course(tmp_path_factory):
    """The repository's lessons and solutions executed once in fast mode (2 at a time) and rendered
    into both course sites: shared by the notebook tests and the site tests, so nothing runs twice."""
    from types import SimpleNamespace

    from robocourse.site.build import build_report_page, discover, run_notebooks, write_sites

    build = tmp_path_factory.mktemp("course-build")
    quiet = lambda *_: None  # noqa: E731
    runs = run_notebooks(discover(ROOT), build / "executed", root=ROOT, jobs=2, timeout=300, fast=True, log=quiet)
    outs = {"course": build / "course", "instructor": build / "instructor"}
    sites = write_sites(ROOT, runs, outs, [build_report_page(runs, ROOT, fast=True)], log=quiet, work=build / ".site")
    return SimpleNamespace(runs={r.path: r for r in runs}, sites=sites, student=outs["course"],
                           instructor=outs["instructor"])
