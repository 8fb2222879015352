"""Every notebook in the repository runs top to bottom in a fresh kernel (ROBOKIT_FAST=1, no
network, cwd a temp dir, time limit). Lessons and solutions must not raise; assignments may only
raise NotImplementedError from their stubs. Lessons and solutions are run once for the whole
session (the ``fast_course`` fixture, which also builds the course sites from them)."""
import pytest

from robocourse.site.build import ALL_DIRS, discover
from robocourse.site.execute import run_notebook
from tests.conftest import ROOT

TIME_LIMIT = 300  # seconds per notebook under ROBOKIT_FAST=1 (the fast_course fixture uses the same)


def _params():
    """Assignments run here (their raises-exception tags are what is under test): `make test`. Lessons
    and solutions come from the ``fast_course`` build, which also builds the sites: slow, `make check`."""
    for path in discover(ROOT, ALL_DIRS):
        marks = [] if path.parent.name == "assignments" else [pytest.mark.slow]
        yield pytest.param(path, marks=marks, id=f"{path.parent.name}/{path.name}")


@pytest.mark.notebook
@pytest.mark.parametrize("path", list(_params()))
def test_notebook_runs(path, request):
    if path.parent.name == "assignments":
        run = run_notebook(path, timeout=TIME_LIMIT, fast=True)
    else:
        run = request.getfixturevalue("fast_course").runs[path]
    assert run.status == "ok", f"{path.name}: {run.status} after {run.seconds:.0f}s\n{run.error}"
