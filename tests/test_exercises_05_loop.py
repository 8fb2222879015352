"""Assignment 05's loop exercise (05.drive_course): the given plant is robokit's truck, the outcome
is judged on robokit's replay, the feedback shows the run, and the shortcuts score little."""
from __future__ import annotations

import json

import numpy as np
import pytest

from robocourse.lessons.gps_sonar_truck import exercises, loop, plant
from robokit.outdoor import PAPER_LAYOUT, Field, LVMaxSonarEZ, SkidSteerTruck, TruckState, true_ranges
from tests.conftest import ROOT

EXERCISE = next(ex for ex in exercises.EXERCISES if ex.id == "05.drive_course")


def _course(seed=0):
    return loop.course_case(seed)


def test_the_notebook_gives_the_plant_module_as_it_is():
    nb = json.loads((ROOT / "solutions" / "05_gps_sonar_truck.ipynb").read_text(encoding="utf-8"))
    text = (ROOT / "course" / "robocourse" / "lessons" / "gps_sonar_truck" / "plant.py").read_text(encoding="utf-8")
    cell = text.split("# --- the notebook's cell ---\n", 1)[1].rstrip("\n")
    assert any("".join(c["source"]) == cell for c in nb["cells"] if c["cell_type"] == "code")


def test_the_plain_truck_is_robokits():
    rng = np.random.default_rng(1)
    t = {"track": 0.21, "max_wheel_speed": 1.0, "motor_tau": 0.3, "icr_factor": 1.62, "slip": 0.08}
    truck = SkidSteerTruck(**t)
    pose, wheels, state = np.array([3.0, 4.0, 2.5]), np.zeros(2), TruckState(np.array([3.0, 4.0, 2.5]))
    for cmd in rng.uniform(-1.3, 1.3, (300, 2)).tolist() + [[0.5, 0.5]] * 20:
        pose, wheels = plant.truck_step(pose, wheels, cmd, 0.049, t)
        state = truck.step(state, cmd, 0.049)
        assert np.allclose(pose, state.pose, atol=1e-12) and np.allclose(wheels, state.wheels, atol=1e-12)


def test_the_plain_sonar_is_robokits():
    """Each sonar reads robokit's nearest echo in its cone (9 rays), clipped and rounded as the sensor does."""
    args = _course(3).args[0]
    field = Field(size=(40.0, 30.0), circles=args["circles"] or None, boxes=args["boxes"] or None)
    sensor, rng = LVMaxSonarEZ(), np.random.default_rng(2)
    obstacles = np.array([o[:2] for o in args["circles"] + args["boxes"]])
    checked = 0
    for _ in range(60):
        near = obstacles[rng.integers(len(obstacles))] + rng.uniform(-3, 3, 2)
        pose = np.array([*near, rng.uniform(-np.pi, np.pi)])
        if field.clearance(pose[:2][None])[0] < 0.4:
            continue
        ranges, _ = true_ranges(field, pose, PAPER_LAYOUT, sensor, rays=loop.SONAR_RAYS)
        for i in range(4):
            assert plant.sonar_range(pose, args, i) == pytest.approx(float(sensor.quantize(ranges[i])), abs=1e-9)
        checked += 1
    assert checked > 30


def test_the_replay_is_the_run_the_worker_saw():
    case = _course(5)
    commands = exercises.drive_course(*case.args)
    run = loop.replay(case.expected, commands)
    assert run["contact"] is None and len(run["arrivals"]) == len(case.expected["waypoints"])
    assert EXERCISE.compare(case.expected, commands) is None


def test_the_cases_are_the_lessons_course_and_small():
    cases = EXERCISE.make_cases(2024)
    assert [c.raises for c in cases] == [None, None, None, "ValueError"]
    for c in cases[:3]:
        course = c.args[0]
        assert len(json.dumps(course)) < 200_000 and len(course["waypoints"]) == 2
        assert course["navigator"]["front"] == 1.2 and course["model"]["slip"] == 0.05
        assert course["truck"]["slip"] != 0.05                         # the real truck is not the model


def test_feedback_shows_where_a_blind_run_went():
    """GPS only, the sonars ignored: the posts stand where it drives, and the feedback says where it hit."""
    case = _course(0)
    message = EXERCISE.compare(case.expected, exercises.COURSE_SHORTCUTS["GPS only, the sonars ignored"](*case.args))
    assert "touched an obstacle at" in message and "not reached: the closest fix was" in message
    assert "true position (m, east and north) every 20 s" in message


def test_feedback_for_a_truck_that_stops_short():
    case = _course(1)
    commands = exercises.drive_course(*case.args)
    message = EXERCISE.compare(case.expected, commands[: len(commands) // 3])
    assert "waypoint 1 of 2 not reached" in message or "waypoint 2 of 2 not reached" in message
    assert "ended the run after" in message


@pytest.mark.parametrize("bad, words", [({"a": 1}, "expected a list"), ([[1.0, 2.0, 3.0]], "pairs"),
                                        ([[float("nan"), 0.0]], "finite")])
def test_malformed_commands_are_explained(bad, words):
    case = _course(2)
    assert words in EXERCISE.compare(case.expected, bad)


def test_too_many_commands_are_refused():
    case = _course(2)
    assert "more than the course's budget" in EXERCISE.compare(case.expected, [[0.0, 0.0]] * (case.expected["steps"] + 1))


def _scores(seeds):
    """Valid cases passed by the reference and by each shortcut, over the exercise's draws for ``seeds``."""
    passed = {"reference": 0, **{name: 0 for name in exercises.COURSE_SHORTCUTS}}
    total = 0
    for seed in seeds:
        for case in EXERCISE.make_cases(seed):
            if case.raises:
                continue
            total += 1
            passed["reference"] += EXERCISE.compare(case.expected, EXERCISE.answer(*case.args)) is None
            for name, shortcut in exercises.COURSE_SHORTCUTS.items():
                passed[name] += EXERCISE.compare(case.expected, shortcut(*case.args)) is None
    return passed, total


def test_the_reference_passes_and_the_cheap_shortcuts_fail_on_a_draw():
    blind, constant = exercises.COURSE_SHORTCUTS["GPS only, the sonars ignored"], ("stand still", "full speed ahead")
    for case in EXERCISE.make_cases(0)[:3]:
        assert EXERCISE.compare(case.expected, EXERCISE.answer(*case.args)) is None
        assert all(EXERCISE.compare(case.expected, exercises.COURSE_SHORTCUTS[n](*case.args)) for n in constant)
        assert EXERCISE.compare(case.expected, blind(*case.args))


@pytest.mark.slow
def test_shortcut_scores_over_20_draws():
    """The table of the report: the reference passes every course of 20 draws (60 courses); standing
    still and full speed never pass; GPS alone passes at most one course in six; steering by the truth
    instead of the fixes fails most (the arrival test is the fixes')."""
    passed, total = _scores(range(20))
    print(passed, total)
    assert passed["reference"] == total == 60
    assert passed["stand still"] == passed["full speed ahead"] == 0
    assert passed["GPS only, the sonars ignored"] <= total / 6
    assert passed["the true position instead of the fixes"] <= total / 2


@pytest.mark.slow
@pytest.mark.parametrize("block", range(4))
def test_the_reference_drives_every_course(block):
    """150 further courses: the lesson's controller never fails one (so a full-marks answer exists)."""
    for seed in range(1000 + 50 * block, 1050 + 50 * block):
        case = loop.course_case(seed)
        assert EXERCISE.compare(case.expected, loop.drive_course(*case.args)) is None, seed


def test_a_course_without_waypoints_raises():
    course = dict(_course(0).args[0], waypoints=[])
    with pytest.raises(ValueError, match="waypoint"):
        loop.drive_course(course)


def test_arrival_is_judged_by_the_fixes_not_the_truth():
    """A run whose true path reaches every waypoint counts only if its fixes (true position plus the
    GPS error) come within the radius: the arrival test is the one the truck can make."""
    case = _course(7)
    clean = [[0.0, 0.0]] * len(case.expected["gps_errors"])
    truth = loop.drive_course(dict(case.args[0], gps_errors=clean))
    assert len(loop.replay(dict(case.expected, gps_errors=clean), truth)["arrivals"]) == 2
    far = dict(case.expected, gps_errors=[[60.0, 60.0]] * len(clean))
    assert loop.replay(far, truth)["arrivals"] == []
    assert "waypoint 1 of 2 not reached" in EXERCISE.compare(far, truth)
