"""`robokit course build` keeps going past broken notebooks and reports them (issue: Bad input)."""
import nbformat
import pytest

from robokit.cli import main
from robokit.course.execute import run_notebook


def _notebook(path, *sources):
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.cells = [nbformat.v4.new_code_cell(s) for s in sources]
    nbformat.write(nb, path)
    return path


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    root = tmp_path_factory.mktemp("course")
    (root / "lessons").mkdir()
    (root / "solutions").mkdir()
    _notebook(root / "lessons" / "00_good.ipynb", "import os\nprint('fast', os.environ['ROBOKIT_FAST'])",
              "import matplotlib.pyplot as plt\nplt.plot([0, 1], [1, 0]); plt.xlabel('x [m]'); plt.show()")
    _notebook(root / "lessons" / "01_raises.ipynb", "x = 1", "raise ValueError('boom in lesson one')")
    _notebook(root / "solutions" / "02_hangs.ipynb", "import time\ntime.sleep(600)")
    code = main(["course", "build", "--root", str(root), "--timeout", "25", "--fast", "--no-grading"])
    return root, code


def test_build_exits_nonzero_but_builds_everything(course):
    root, code = course
    assert code == 1
    site = root / "build" / "course"
    assert (site / "index.html").exists()
    for page in ("lessons-00_good.html", "lessons-01_raises.html", "solutions-02_hangs.html"):
        assert (site / page).exists(), page


def test_index_reports_status_and_error_tail(course):
    root, _ = course
    index = (root / "build" / "course" / "index.html").read_text()
    assert "1 of 3 notebooks ran without error" in index
    assert "boom in lesson one" in index
    assert "class='timeout'" in index and "time limit of 25 s" in index
    assert "class='ok'" in index


def test_good_page_has_output_and_figure(course):
    root, _ = course
    page = (root / "build" / "course" / "lessons-00_good.html").read_text()
    assert "fast 1" in page and "data:image/png;base64" in page


def test_run_notebook_cwd_is_a_fresh_temp_dir(tmp_path):
    nb = _notebook(tmp_path / "cwd.ipynb", "import os\nassert os.listdir('.') == [], os.listdir('.')\n"
                   "assert 'robokit-nb-' in os.getcwd()")
    run = run_notebook(nb, timeout=120)
    assert run.status == "ok", run.error


def test_run_notebook_blocks_network(tmp_path):
    nb = _notebook(tmp_path / "net.ipynb", "import urllib.request\nurllib.request.urlopen('http://example.com', timeout=5)")
    run = run_notebook(nb, timeout=120)
    assert run.status == "failed" and "network access is disabled" in run.error


def test_assignment_stubs_are_allowed_but_real_errors_are_not(tmp_path):
    folder = tmp_path / "assignments"
    folder.mkdir()
    stub = _notebook(folder / "a.ipynb", "def f():\n    raise NotImplementedError", "f()", "print('went on')")
    run = run_notebook(stub, timeout=120)
    assert run.status == "ok", run.error
    broken = _notebook(folder / "b.ipynb", "f = None", "f()")
    assert run_notebook(broken, timeout=120).status == "failed"


def test_bad_arguments():
    with pytest.raises(FileNotFoundError, match="path"):
        run_notebook("/nonexistent.ipynb")


def test_cli_without_lessons_is_a_clear_error(tmp_path, capsys):
    assert main(["course", "build", "--root", str(tmp_path)]) == 2
    assert "no lessons/ directory" in capsys.readouterr().err


def test_check_in_a_notebook_shows_its_message_not_a_traceback(tmp_path):
    """A passing check() leaves no Out[...]; a failing one ends the cell in an error whose only text
    is the message (no frames through robokit); a stub's NotImplementedYet is allowed in assignments."""
    import nbformat as nbf

    good = ("import numpy as np\nfrom robokit.grading import check\n"
            "def wrap_angle(angle):\n    a = np.asarray(angle, float)\n"
            "    if np.isnan(a).any():\n        raise ValueError('angle: NaN')\n"
            "    r = np.mod(a + np.pi, 2 * np.pi) - np.pi\n    return float(r) if r.ndim == 0 else r\n")
    folder = tmp_path / "assignments"
    folder.mkdir()
    nb = _notebook(folder / "a.ipynb", good, 'check("00.wrap_angle", wrap_angle)',
                   "def stub(angle):\n    raise NotImplementedError", 'check("00.wrap_angle", stub)',
                   'check("00.wrap_angle", lambda angle: angle)')
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
