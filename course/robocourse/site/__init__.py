"""The course build: notebooks run headless and kept clean, the two Sphinx sites, browser checks.

execute       one notebook in a fresh kernel, in its own process, with a time limit and no network
netguard      the kernel's guard that refuses the network
hygiene       committed notebooks carry no outputs; strip them
build         robocourse build: every notebook run (longest first, a solution after its lesson),
              then both sites written from the executed notebooks
book          the Sphinx sources of a site (pages, tables of contents, the library reference)
slim          a built site without what its pages never load (one 3D viewer, clean downloads)
cdp           a client of Chromium's DevTools protocol over a pipe
browser       a page opened offline in headless Chromium, and what a student would meet there
page_report   what a page check found: failed requests, console errors, maths, scenes
screenshots   PNG decoding and how much of a scene differs from an empty one
"""
from robocourse.site.execute import NotebookRun, run_notebook
from robocourse.site.hygiene import notebook_problems, strip_notebook

__all__ = ["NotebookRun", "run_notebook", "notebook_problems", "strip_notebook"]
