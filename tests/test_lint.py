"""Static checks: pyflakes finds undefined names (real bugs) and unused imports (dead code)."""
import subprocess
import sys

from tests.conftest import ROOT


def test_pyflakes_is_clean():
    out = subprocess.run([sys.executable, "-m", "pyflakes", "robokit", "tests", "benchmarks", "conftest.py"],
                         cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
