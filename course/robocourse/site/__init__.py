"""Course tooling: run notebooks headless, check their hygiene, build the HTML course site."""
from robocourse.site.execute import NotebookRun, run_notebook
from robocourse.site.hygiene import notebook_problems, strip_notebook

__all__ = ["NotebookRun", "run_notebook", "notebook_problems", "strip_notebook"]
