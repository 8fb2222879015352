"""A student's first hour, in JupyterLab itself: open a lesson and an assignment, Run All, look.

A real JupyterLab server (on a copy of the notebooks, kernels in fast mode) and headless Chromium
driving JupyterLab's own commands (``tests/jupyterlab.py``). What a student must see: every cell of
a lesson runs with no error and no red stderr box, its 3D scenes draw, its sliders are live (a
number typed into one moves it to the nearest computed value and the figure is redrawn); Run All on
a blank assignment runs every cell and shows every exercise's "not implemented yet".
"""
from __future__ import annotations

import re
import time

import pytest

from tests.conftest import needs_chromium

pytestmark = [pytest.mark.slow, pytest.mark.notebook, needs_chromium]

STUB_ERRORS = {"NotImplementedYet", "NotImplementedError"}
WIDGET_ERROR = "Error displaying widget"        # JupyterLab's text where a widget view fails


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    from tests.jupyterlab import LabPage, LabServer

    server = LabServer(tmp_path_factory.mktemp("lab"))
    try:
        page = LabPage(server)
        yield page
        page.close()
    finally:
        server.close()


def _code(report: dict) -> list[dict]:
    return [c for c in report["cells"] if c["type"] == "code"]


def _problems(report: dict) -> list[str]:
    """Error outputs and stderr boxes, one line each."""
    found = []
    for i, cell in enumerate(_code(report)):
        for out in cell["outputs"]:
            if out["type"] == "error":
                found.append(f"code cell {i}: {out['ename']}: {out['evalue'][:120]}")
            elif out["type"] == "stream" and out["name"] == "stderr":
                found.append(f"code cell {i}: stderr: {out['text'][:120]}")
    return found


@pytest.fixture(scope="module")
def lesson_00(lab):
    lab.run_all("lessons/00_getting_started.ipynb")
    return lab.read()


@pytest.fixture(scope="module")
def assignment_00(lab):
    lab.run_all("assignments/00_getting_started.ipynb")
    return lab.read()


@pytest.fixture(scope="module")
def lesson_05(lab):
    lab.run_all("lessons/05_gps_sonar_truck.ipynb")
    return lab.read()


@pytest.mark.parametrize("name", ["lesson_00", "lesson_05"])
def test_run_all_on_a_lesson_runs_every_cell_without_an_error_or_a_red_box(name, request):
    report = request.getfixturevalue(name)
    code = _code(report)
    assert len(code) >= 5 and all(c["count"] is not None for c in code), [c["count"] for c in code]
    assert not _problems(report), _problems(report)
    notes = report["text"].count("Run this cell again.")     # each live slider's note names the error once
    assert report["text"].count(WIDGET_ERROR) == notes, "a widget failed to display"


def test_lesson_00_shows_the_installation_table_and_a_drawn_scene(lesson_00):
    printed = "".join(o["text"] for c in _code(lesson_00) for o in c["outputs"] if o["type"] == "stream")
    assert "mujoco" in printed and "numba" in printed and "broken" not in printed and "missing" not in printed
    scenes = lesson_00["scenes"]
    assert len(scenes) == 1 and scenes[0]["canvas"] and scenes[0]["width"] > 300 and scenes[0]["height"] > 200


def test_run_all_on_a_blank_assignment_shows_every_exercise(assignment_00):
    code = _code(assignment_00)
    assert all(c["count"] is not None for c in code), "Run All stopped before the end"
    errors = [(c, o) for c in code for o in c["outputs"] if o["type"] == "error"]
    assert {o["ename"] for _, o in errors} <= STUB_ERRORS, _problems(assignment_00)
    assert all("raises-exception" in c["tags"] for c, _ in errors)
    said = " ".join(o["evalue"] for _, o in errors)
    assert "00.wrap_angle" in said and "00.se2_compose" in said


def test_lesson_05_scenes_draw_and_its_sliders_are_live(lab, lesson_05):
    assert len(lesson_05["scenes"]) >= 1 and all(s["canvas"] and s["width"] > 300 for s in lesson_05["scenes"])
    sliders = lesson_05["sliders"]
    assert len(sliders) == 2
    lab.show("lessons/05_gps_sonar_truck.ipynb")
    numeric = next(i for i, s in enumerate(sliders) if re.fullmatch(r"-?\d+", s["readout"]))
    before = lab.slider_image(numeric)
    assert before, "the slider shows no figure"
    lab.type_into_slider(numeric, "3")                   # between the computed 0 and 7: snaps to 0
    deadline = time.monotonic() + 30
    while lab.slider_image(numeric) == before and time.monotonic() < deadline:
        time.sleep(0.3)
    assert lab.slider_image(numeric) != before, "the figure was not redrawn"
    assert lab.read()["sliders"][numeric]["readout"] == "0"
