"""Static checks: pyflakes finds undefined names (real bugs) and unused imports (dead code)."""
import subprocess
import sys

from tests.conftest import ROOT


def test_pyflakes_is_clean():
    paths = ["robokit", "course", "tests", "benchmarks", "conftest.py"]
    out = subprocess.run([sys.executable, "-m", "pyflakes", *paths], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
