"""A short recorded omni run in the office floor and the topological map built from it (built once
per test session; the run itself is cached by robokit.sim.record), shared by the lesson 02 tests."""
from __future__ import annotations

import functools

import numpy as np

#: A lap of R1 round its table (a loop to close), then out through the corridor into R4; recorded at
#: 0.5 Hz (0.6 m per frame at 0.3 m/s): 41 frames.
SHORT_TOUR = ((14.5, 3.5), (11.2, 3.5), (11.2, 0.7), (14.6, 0.7), (14.6, 3.5), (12.0, 3.5), (12.0, 6.0), (12.0, 8.5))


@functools.cache
def office():
    from robokit.sim import office_floor
    return office_floor()


@functools.cache
def camera():
    from robokit.sim import OmniCamera
    return OmniCamera()


@functools.cache
def short_run():
    from robokit.sim import record, waypoint_path
    return record(office(), waypoint_path(SHORT_TOUR, speed=0.3), {"omni": camera()}, rate=0.5, seed=0)


@functools.cache
def short_map_and_log():
    from robokit.mapping import build_topological_map
    run = short_run()
    lines: list[str] = []
    tmap = build_topological_map(run.images["omni"], run.odometry, camera(), loop_exclude=2, log=lines.append)
    return tmap, tuple(lines)


def short_map():
    return short_map_and_log()[0]


def true_node_map():
    """The short map with its nodes at their true poses (localization errors without map errors)."""
    tmap = short_map()
    return tmap.with_poses(short_run().poses[tmap.frames])


def room_of(xy) -> list[str]:
    """'R1'..'R4' or 'corridor' for floor points of office_floor()."""
    out = []
    for x, y in np.atleast_2d(xy):
        if 5.0 <= y <= 7.0:
            out.append("corridor")
        else:
            rooms = {(True, True): "R1", (False, True): "R2", (False, False): "R3", (True, False): "R4"}
            out.append(rooms[(bool(x >= 8), bool(y < 5))])
    return out
