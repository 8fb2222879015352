"""`robocourse build` keeps going past broken notebooks and reports them (issue: Bad input)."""
import json
import re
import shutil

import pytest

from robocourse.cli import main
from robocourse.site.execute import THREAD_VARIABLES, run_notebook
from tests.conftest import ROOT


def _notebook(path, *sources):
    import nbformat     # here, not at the top: its import (about 1.5 s) would be paid by every test worker

    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.cells = [nbformat.v4.new_code_cell(s) for s in sources]
    nbformat.write(nb, path)
    return path


# A small course built whole (about 35 s): its tests are slow (`make check` runs them).
@pytest.fixture(scope="module")
def course(tmp_path_factory):
    root = tmp_path_factory.mktemp("course")
    (root / "lessons").mkdir()
    (root / "solutions").mkdir()
    (root / "assignments").mkdir()
    shutil.copytree(ROOT / "book", root / "book")
    _notebook(root / "lessons" / "00_good.ipynb", "import os\nimport math",
              "print('fast', os.environ['ROBOKIT_FAST'])",
              "import matplotlib.pyplot as plt\nplt.plot([0, 1], [1, 0]); plt.xlabel('x [m]'); plt.show()")
    _notebook(root / "lessons" / "01_raises.ipynb", "x = 1", "raise ValueError('boom in lesson one')")
    _notebook(root / "solutions" / "02_hangs.ipynb", "import time\ntime.sleep(600)")
    _notebook(root / "assignments" / "02_hangs.ipynb", "def f():\n    raise NotImplementedError")
    code = main(["build", "--root", str(root), "--timeout", "25", "--fast", "--no-grading",
                 "--no-api-reference"])   # the library reference is built by tests/test_course_site.py
    return root, code


@pytest.mark.slow
def test_build_exits_nonzero_but_builds_everything(course):
    root, code = course
    assert code == 1
    student, instructor = root / "build" / "course", root / "build" / "instructor"
    for site in (student, instructor):
        assert (site / "index.html").exists()
        for page in ("lessons/00_good.html", "lessons/01_raises.html", "assignments/02_hangs.html",
                     "references.html", "search.html"):
            assert (site / page).exists(), page
    assert (instructor / "solutions" / "02_hangs.html").exists()
    assert not (student / "solutions").exists()


@pytest.mark.slow
def test_instructor_build_report_has_status_and_error_tail(course):
    root, _ = course
    report = (root / "build" / "instructor" / "instructor" / "build.html").read_text()
    assert "1 of 3 notebooks ran without error" in report
    assert "boom in lesson one" in report
    assert "timeout" in report and "time limit of 25 s" in report
    assert "instructor/build" not in (root / "build" / "course" / "index.html").read_text()


@pytest.mark.slow
def test_pages_have_outputs_figures_titles_and_folded_imports(course):
    root, _ = course
    page = (root / "build" / "course" / "lessons" / "00_good.html").read_text()
    assert "fast 1" in page
    assert re.search(r'<img[^>]+src="\.\./_images/[^"]+\.png"', page)
    assert re.search(r'class="[^"]*tag_hide-input', page)           # the import-only cell is folded
    assert "<title>" in page and "Notebook</title>" not in page
    broken = (root / "build" / "course" / "lessons" / "01_raises.html").read_text()
    assert "did not run to the end" in broken and "boom in lesson one" in broken
    solution = (root / "build" / "instructor" / "solutions" / "02_hangs.html").read_text()
    assert "did not run to the end when the site was built (timeout)" in solution


@pytest.mark.slow
def test_sites_are_linked_in_lesson_order_with_previous_next(course):
    root, _ = course
    index = (root / "build" / "course" / "index.html").read_text()
    assert index.index("lessons/00_good.html") < index.index("lessons/01_raises.html") \
        < index.index("assignments/02_hangs.html")
    lesson = (root / "build" / "course" / "lessons" / "00_good.html").read_text()
    assert 'class="right-next"' in lesson and "01_raises.html" in lesson


def test_run_notebook_cwd_is_a_fresh_temp_dir(tmp_path):
    nb = _notebook(tmp_path / "cwd.ipynb", "import os\nassert os.listdir('.') == [], os.listdir('.')\n"
                   "assert 'robokit-nb-' in os.getcwd()")
    run = run_notebook(nb, timeout=120)
    assert run.status == "ok", run.error


def test_run_notebook_blocks_network(tmp_path):
    nb = _notebook(tmp_path / "net.ipynb", "import urllib.request\nurllib.request.urlopen('http://example.com', timeout=5)")
    run = run_notebook(nb, timeout=120)
    assert run.status == "failed" and "network access is disabled" in run.error


def test_assignment_stubs_are_allowed_in_tagged_cells_but_real_errors_are_not(tmp_path):
    folder = tmp_path / "assignments"
    folder.mkdir()
    stub = _notebook(folder / "a.ipynb", "def f():\n    raise NotImplementedError", "f()", "print('went on')")
    tagged = json.loads(stub.read_text())
    tagged["cells"][1]["metadata"]["tags"] = ["raises-exception"]
    stub.write_text(json.dumps(tagged))
    run = run_notebook(stub, timeout=120)
    assert run.status == "ok", run.error
    untagged = _notebook(folder / "c.ipynb", "def f():\n    raise NotImplementedError", "f()", "print('went on')")
    assert run_notebook(untagged, timeout=120).status == "failed"   # Run All would stop there
    broken = _notebook(folder / "b.ipynb", "f = None", "f()")
    broken_tagged = json.loads(broken.read_text())
    broken_tagged["cells"][1]["metadata"]["tags"] = ["raises-exception"]
    broken.write_text(json.dumps(broken_tagged))
    assert run_notebook(broken, timeout=120).status == "failed"     # a TypeError is no stub


def test_bad_arguments():
    with pytest.raises(FileNotFoundError, match="path"):
        run_notebook("/nonexistent.ipynb")


def test_cli_without_lessons_is_a_clear_error(tmp_path, capsys):
    assert main(["build", "--root", str(tmp_path)]) == 2
    assert "no lessons/ directory" in capsys.readouterr().err


def test_check_in_a_notebook_shows_its_message_not_a_traceback(tmp_path):
    """A passing check() leaves no Out[...]; a failing one ends the cell in an error whose only text
    is the message (no frames through robokit); a stub's NotImplementedYet is allowed in assignments."""
    import nbformat as nbf

    good = ("import numpy as np\nfrom robocourse.grading import check\n"
            "def wrap_angle(angle):\n    a = np.asarray(angle, float)\n"
            "    if np.isnan(a).any():\n        raise ValueError('angle: NaN')\n"
            "    r = np.mod(a + np.pi, 2 * np.pi) - np.pi\n    return float(r) if r.ndim == 0 else r\n")
    folder = tmp_path / "assignments"
    folder.mkdir()
    nb = _notebook(folder / "a.ipynb", good, 'check("00.wrap_angle", wrap_angle)',
                   "def stub(angle):\n    raise NotImplementedError", 'check("00.wrap_angle", stub)',
                   'check("00.wrap_angle", lambda angle: angle)')
    tagged = nbf.read(nb, as_version=4)
    for cell in tagged.cells[1:]:                        # as robocourse assign tags check cells
        if "check(" in cell.source:
            cell.metadata["tags"] = ["raises-exception"]
    nbf.write(tagged, nb)
    run = run_notebook(nb, timeout=120, output=tmp_path / "out.ipynb")
    assert run.status == "failed"                       # the wrong answer is not a stub: not allowed
    cells = nbf.read(tmp_path / "out.ipynb", as_version=4).cells
    passed, stubbed = cells[1], cells[3]
    assert not [o for o in passed.outputs if o.output_type == "execute_result"]
    assert "6/6 public cases passed" in "".join(o.get("text", "") for o in passed.outputs)
    stub_error = [o for o in stubbed.outputs if o.output_type == "error"]
    assert stub_error and stub_error[0].ename == "NotImplementedYet"
    assert stub_error[0].traceback == ["NotImplementedYet: 00.wrap_angle is not implemented yet"]
    wrong = [o for o in cells[4].outputs if o.output_type == "error"]
    assert wrong and wrong[0].ename == "CheckFailed"
    assert len(wrong[0].traceback) == 1 and "robokit" not in wrong[0].traceback[0]
    assert "4 of 6 public cases failed" in wrong[0].traceback[0]


def test_the_student_site_sources_refuse_solutions(tmp_path):
    from robocourse.site.book import BookPage, write_sources

    solution = _notebook(tmp_path / "01.ipynb", "x = 1")
    with pytest.raises(ValueError, match="solutions"):
        write_sources(tmp_path / "src", ROOT / "book", lessons=[], assignments=[], solutions=[solution])
    with pytest.raises(ValueError, match="solutions"):
        write_sources(tmp_path / "src", ROOT / "book", lessons=[], assignments=[], pages=[BookPage("x", "# x")])
    with pytest.raises(FileNotFoundError, match="book"):
        write_sources(tmp_path / "src", tmp_path, lessons=[], assignments=[])


def test_build_refuses_output_folders_it_would_have_to_wipe(tmp_path, capsys):
    """--out pointing at a folder with other files (the repository, docs/) is refused before any
    notebook runs, and nothing is deleted; so is an instructor site inside the student site."""
    root = tmp_path / "course"
    (root / "lessons").mkdir(parents=True)
    shutil.copytree(ROOT / "book", root / "book")
    _notebook(root / "lessons" / "00.ipynb", "x = 1")
    docs = root / "docs"
    docs.mkdir()
    (docs / "keep.txt").write_text("mine")
    assert main(["build", "--root", str(root), "--out", str(docs), "--no-grading"]) == 2
    assert (docs / "keep.txt").read_text() == "mine" and not (root / "build" / "executed").exists()
    assert "holds other files" in capsys.readouterr().out
    assert main(["build", "--root", str(root), "--out", str(root), "--no-grading"]) == 2
    assert (root / "lessons" / "00.ipynb").exists()
    assert main(["build", "--root", str(root), "--out", "site",
                 "--instructor-out", "site/private", "--no-grading"]) == 2
    assert "instructor_out" in capsys.readouterr().out


def test_build_needs_the_site_sources(tmp_path, capsys):
    root = tmp_path / "course"
    (root / "lessons").mkdir(parents=True)
    _notebook(root / "lessons" / "00.ipynb", "x = 1")
    assert main(["build", "--root", str(root), "--no-grading"]) == 2
    assert "book/" in capsys.readouterr().out and not (root / "build" / "executed").exists()


@pytest.mark.slow
def test_a_solution_starts_after_its_lesson_and_the_longest_goes_first(tmp_path):
    from robocourse.site.build import run_notebooks
    stamp = tmp_path / "stamps.txt"
    record = "import time\nopen({!r}, 'a').write('{} ' + ('start' if {} else 'end') + f' {{time.time()}}\\n')"
    for folder, name, seconds in (("lessons", "01_long.ipynb", 3), ("lessons", "02_short.ipynb", 0),
                                  ("solutions", "01_long.ipynb", 0)):
        (tmp_path / folder).mkdir(exist_ok=True)
        tag = f"{folder}/{name}"
        _notebook(tmp_path / folder / name, record.format(str(stamp), tag, True), f"time.sleep({seconds})",
                  record.format(str(stamp), tag, False))
    paths = [tmp_path / "lessons" / "01_long.ipynb", tmp_path / "lessons" / "02_short.ipynb",
             tmp_path / "solutions" / "01_long.ipynb"]
    executed = tmp_path / "executed"
    runs = run_notebooks(paths, executed, root=tmp_path, jobs=2, timeout=120, fast=True, log=lambda line: None)
    assert [r.status for r in runs] == ["ok"] * 3 and [r.path for r in runs] == paths
    times = {tuple(line.split()[:2]): float(line.split()[2]) for line in stamp.read_text().splitlines()}
    # two jobs: the short lesson runs beside the long one, the solution waits for the long lesson
    assert times[("solutions/01_long.ipynb", "start")] >= times[("lessons/01_long.ipynb", "end")]
    assert times[("lessons/02_short.ipynb", "start")] < times[("solutions/01_long.ipynb", "start")]
    timings = json.loads((executed / "timings-fast.json").read_text())
    assert timings["lessons/01_long.ipynb"] > timings["lessons/02_short.ipynb"]
    # the next build starts the notebook that took longest last time first, whatever the order given
    stamp.unlink()
    run_notebooks(paths[::-1], executed, root=tmp_path, jobs=1, timeout=120, fast=True, log=lambda line: None)
    first = min(times := {tuple(line.split()[:2]): float(line.split()[2]) for line in stamp.read_text().splitlines()},
                key=times.get)
    assert first == ("lessons/01_long.ipynb", "start")


@pytest.mark.slow
def test_a_fresh_full_build_starts_the_notebook_declaring_the_longest_cold_time(tmp_path):
    import nbformat

    from robocourse.site.build import run_notebooks
    stamp = tmp_path / "stamps.txt"
    paths = []
    for name, declared in (("01_quick.ipynb", None), ("02_slow.ipynb", 120)):
        paths.append(_notebook(tmp_path / name, f"open({str(stamp)!r}, 'a').write('{name}\\n')"))
        if declared:
            nb = nbformat.read(paths[-1], as_version=4)
            nb.metadata["robokit"] = {"cold_seconds": declared}
            nbformat.write(nb, paths[-1])
    run_notebooks(paths, tmp_path / "executed", root=tmp_path, jobs=1, timeout=120, log=lambda line: None)
    assert stamp.read_text().split() == ["02_slow.ipynb", "01_quick.ipynb"]


@pytest.mark.slow
def test_the_notebooks_running_at_once_share_the_cores(tmp_path, monkeypatch):
    # each kernel gets ROBOKIT_WORKERS = cores // notebooks at once, so the build never runs more
    # worker processes than cores (two notebooks on two cores: one worker each, the runs made in
    # place), and a notebook built alone gets every core
    import robokit.config as config
    import robocourse.site.build as build
    monkeypatch.setattr(build, "available_cpus", lambda: 4)
    monkeypatch.setattr(config, "available_cpus", lambda: 4)    # what worker_count falls back to
    out = tmp_path / "workers.txt"
    # ... and as many BLAS and OpenCV threads (OpenCV reads its variable: its own count is written too)
    code = (f"import os, cv2\nopen({str(out)!r}, 'a').write(' '.join([os.environ['ROBOKIT_WORKERS'], "
            f"*(os.environ[v] for v in {THREAD_VARIABLES!r}), str(cv2.getNumThreads())]) + '\\n')")
    path = _notebook(tmp_path / "nb.ipynb", code)
    other = _notebook(tmp_path / "other.ipynb", "1 + 1")
    for name in ("ROBOKIT_WORKERS", *THREAD_VARIABLES):
        monkeypatch.delenv(name, raising=False)
    # (jobs, notebooks, the caller's own setting) -> workers per kernel
    for jobs, paths, own, expected in ((2, [path, other], None, "2"), (4, [path, other], None, "2"),
                                       (1, [path], None, "4"), (None, [path], None, "4"),
                                       (None, [path, other], None, "2"), (None, [path], "3", "3")):
        out.unlink(missing_ok=True)
        if own:
            monkeypatch.setenv("ROBOKIT_WORKERS", own)
        build.run_notebooks(paths, tmp_path / "executed", root=tmp_path, jobs=jobs, timeout=120, fast=True,
                            log=lambda line: None)
        assert out.read_text().split() == [expected] * (len(THREAD_VARIABLES) + 2), (jobs, len(paths), own)
    # a caller's own lower thread cap stays
    out.unlink()
    monkeypatch.delenv("ROBOKIT_WORKERS")
    monkeypatch.setenv(THREAD_VARIABLES[0], "1")
    build.run_notebooks([path, other], tmp_path / "executed", root=tmp_path, jobs=2, timeout=120, fast=True,
                        log=lambda line: None)
    assert out.read_text().split() == ["2", "1"] + ["2"] * len(THREAD_VARIABLES), "a lower cap was raised"
