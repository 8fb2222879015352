"""World builders following the source papers' environments (all seeded, deterministic).

* :func:`box_room` - a plain rectangular room (tests, first experiments);
* :func:`lab_room` - the 10 m x 10 m lab of Se, Lowe & Little (2002, Sec. 3.6) with furniture
  and posters;
* :func:`long_corridor` - the 36.10 m x 2.17 m corridor of Ge et al. (2023, Sec. 4.1) with 0.07 m
  door recesses, 1.00 m and 2.25 m doors, facing and staggered layouts;
* :func:`office_floor` - four rooms and a horizontal corridor (the omnidirectional-vision paper
  of lesson 02, Fig. 6a).

Worlds are cached per parameter set (they are immutable), so calling a builder twice is cheap.

References
----------
.. [1] S. Se, D. Lowe and J. Little, "Global localization using distinctive visual features",
   IEEE/RSJ International Conference on Intelligent Robots and Systems (IROS), 2002.
.. [2] Ge et al., "Visual-feature-assisted mobile robot localization in a long corridor
   environment", *Frontiers of Information Technology & Electronic Engineering*, 2023,
   doi:10.1631/FITEE.2200208.
.. [3] Li M., Sun L., Huang Q., Cai Z. and Piao S., "Robust omnidirectional vision based mobile robot
   hierarchical localization and autonomous navigation", *Information Technology Journal* 10(1),
   29-39, 2011.
"""
from __future__ import annotations

import functools

import numpy as np

from ..validation import as_choice, as_int, as_positive
from . import textures as tx
from .build import Builder, random_decoration, wall_with_doors
from .world import World

__all__ = ["box_room", "lab_room", "long_corridor", "office_floor"]


def _rect_walls(b: Builder, name: str, x0: float, y0: float, x1: float, y1: float, height: float) -> None:
    """Four walls of a room, walked clockwise so that they face inwards."""
    corners = [(x0, y0), (x0, y1), (x1, y1), (x1, y0)]
    for k in range(4):
        b.wall(f"{name}/{k}", corners[k], corners[(k + 1) % 4], 0.0, height)


def _hang(b: Builder, name: str, a, t, s: float, width: float, z_top: float, height: float, fn) -> None:
    b.decal(name, np.asarray(a) + s * np.asarray(t), np.asarray(a) + (s + width) * np.asarray(t), z_top, height, fn)


@functools.lru_cache(maxsize=8)
def box_room(width: float = 6.0, depth: float = 4.0, height: float = 2.5, seed: int = 0) -> World:
    """A rectangular room ``[0, width] x [0, depth]`` with plain walls, tiled floor and ceiling.

    Parameters
    ----------
    width, depth, height : float
        Room size in metres.
    seed : int, default 0
        Texture seed.

    Returns
    -------
    World
        Footprint: the four walls; ``info`` holds the size.

    Raises
    ------
    ValueError
        For non-positive sizes.

    Notes
    -----
    The simplest test world: LiDAR ranges have closed-form values (ray-line intersection).

    Examples
    --------
    >>> box_room()
    World('box_room', 22 surfaces, 10 wall segments, 6.00 m x 4.00 m)
    """
    w, d, h = (as_positive(v, n) for v, n in ((width, "width"), (depth, "depth"), (height, "height")))
    b = Builder(as_int(seed, "seed", minimum=0), density=100)
    _rect_walls(b, "wall", 0, 0, w, d, h)
    b.horizontal("floor", 0, 0, w, d, 0.0, True, tx.floor_tiles)
    b.horizontal("ceiling", 0, 0, w, d, h, False, tx.ceiling_panels)
    return b.world("box_room", (w / 2, d / 2), h, info={"width": w, "depth": d, "seed": seed})


@functools.lru_cache(maxsize=4)
def lab_room(seed: int = 3) -> World:
    """The 10 m x 10 m robotics lab of Se, Lowe & Little (2002): desks, cabinets, shelves, posters, boards.

    Parameters
    ----------
    seed : int, default 3
        Seeds the textures and the placement of decorations.

    Returns
    -------
    World
        ``[0, 10] x [0, 10]`` m, ceiling 2.8 m; ``info["furniture"]`` lists the boxes
        ``(name, centre, size, yaw)``.

    Raises
    ------
    ValueError, TypeError
        For a negative or non-integer seed.

    Notes
    -----
    Se, Lowe & Little (2002), Sec. 3.6: the robot maps "our 10m by 10m lab"; the furniture and
    posters give SIFT texture.

    Examples
    --------
    >>> lab = lab_room()
    >>> lab
    World('lab_room', 123 surfaces, 52 wall segments, 10.00 m x 10.00 m)
    >>> bool(lab.is_free([5.0, 2.0])[0])      # where lesson 01's robot stands
    True
    """
    rng = np.random.default_rng(as_int(seed, "seed", minimum=0))
    H = 2.8
    b = Builder(rng, density=110)
    _rect_walls(b, "wall", 0, 0, 10, 10, H)
    b.horizontal("floor", 0, 0, 10, 10, 0.0, True, tx.floor_tiles)
    b.horizontal("ceiling", 0, 0, 10, 10, H, False, tx.ceiling_panels)
    walls = [((0, 0), (0, 1)), ((0, 10), (1, 0)), ((10, 10), (0, -1)), ((10, 0), (-1, 0))]
    k = 0
    for a, t in walls:  # three or four decorations per wall at irregular spacing
        s = rng.uniform(0.4, 1.2)
        while s < 8.6:
            width = rng.uniform(0.6, 1.3)
            if s + width > 9.6:
                break
            height = width * rng.uniform(0.7, 1.4)
            _hang(b, f"poster/{k}", a, t, s, width, rng.uniform(1.6, 2.1), height, random_decoration(rng))
            k += 1
            s += width + rng.uniform(0.8, 2.2)
    furniture = [
        ("desk/0", (1.2, 3.0), (1.6, 0.8, 0.75), np.pi / 2), ("desk/1", (1.2, 6.5), (1.6, 0.8, 0.75), np.pi / 2),
        ("cabinet/0", (4.0, 9.55), (1.0, 0.5, 1.8), 0.0), ("cabinet/1", (9.55, 3.0), (1.0, 0.5, 1.9), np.pi / 2),
        ("shelf/0", (6.5, 9.6), (1.8, 0.4, 1.6), 0.0), ("table/0", (5.5, 5.0), (1.8, 0.9, 0.75), 0.3),
        ("crate/0", (8.2, 1.0), (0.6, 0.6, 0.6), 0.5), ("crate/1", (3.2, 0.8), (0.8, 0.5, 1.0), 0.0),
    ]
    for name, centre, size, yaw in furniture:
        b.box(name, centre, size, yaw, texture_fn=tx.wood if rng.random() < 0.6 else tx.notice_board)
    return b.world("lab_room", (5.0, 2.5), H, info={"size": (10.0, 10.0), "seed": seed,
                                                     "furniture": furniture})


def _door_plan(layout: str) -> tuple[list, list]:
    """Door centres and widths (north side, south side) along the 36.10 m corridor."""
    north = [(3.0, 1.00), (7.5, 1.00), (12.0, 2.25), (16.5, 1.00), (21.0, 1.00), (25.5, 2.25), (30.0, 1.00),
             (33.6, 1.00)]
    facing = [(c, w) for c, w in north]
    staggered = [(c + 2.25, w) for c, w in north if c + 2.25 + w / 2 < 35.5]
    if layout == "facing":
        south = facing
    elif layout == "staggered":
        south = staggered
    else:  # first half facing (Ge et al. Fig. 3a), second half staggered (their inequality (3))
        south = [d for d in facing if d[0] < 18] + [d for d in staggered if d[0] > 18]
    south = [(c, 2.25 if i % 3 == 1 else 1.00) for i, (c, _) in enumerate(south)]
    return north, south


def long_corridor(layout: str = "mixed", seed: int = 2, clutter: float = 0.0) -> World:
    """The long corridor of Ge et al. (2023): 36.10 m x 2.17 m, 0.07 m door recesses, 1.00/2.25 m doors.

    Parameters
    ----------
    layout : {"mixed", "facing", "staggered"}, default "mixed"
        Door layout: doors face each other, are staggered, or (default) facing in the first half
        and staggered in the second.
    seed : int, default 2
        Seeds textures, posters, boards and room-number plates.
    clutter : float, default 0
        How much the corridor departs from its repeating door pattern, as a laser sees it: the share
        (0 to 1) of the wall stretches between doors that hold a cabinet (0.3-0.9 m long, 0.2-0.45 m
        deep, 0.6-1.2 m high) against the wall, each at its own place. Every stretch draws its
        cabinet and its chance whatever the share, so a larger share keeps the cabinets of a
        smaller one and adds others. 0 (default): no cabinet, only the doors along the walls.

    Returns
    -------
    World
        The corridor runs along +x from 0 to 36.10 m with its middle line on y = 0; walls at
        y = +-1.085 m; ``info`` has ``length``, ``width``, ``recess``, ``doors`` (side, x0, x1).

    Raises
    ------
    ValueError, TypeError
        For an unknown layout, a bad seed or a clutter share outside [0, 1].

    Notes
    -----
    Ge et al. (2023), Sec. 4.1 (dimensions) and Sec. 3.1, Fig. 3 and Eqs. (1)-(3) (door recesses
    in facing and staggered layouts). The doors stand every 4.5 m on each wall (the last north one 3.6 m after its
    neighbour), in two widths, so LiDAR scans alias;
    plates, posters and boards make each stretch look different to a camera (their Sec. 3.2).
    The cabinets are our device for grading how repetitive the corridor is to a laser, not the
    paper's: its corridor has many symmetrical and similar areas (Sec. 4; Sec. 4.2 names two pairs),
    and it removed fire extinguishers and garbage cans before its runs (Sec. 4).
    ``info["clutter"]`` lists them as ``(side, x0, x1, depth)``.

    The world is built once per set of arguments and shared (``long_corridor.cache_clear()`` forgets
    the built ones).

    Examples
    --------
    >>> corridor = long_corridor()
    >>> corridor.info["length"], corridor.info["width"], corridor.info["doors"][0]
    (36.1, 2.17, ('north', 2.5, 3.5))
    """
    layout = as_choice(layout, "layout", ["mixed", "facing", "staggered"])
    seed = as_int(seed, "seed", minimum=0)
    share = as_positive(clutter, "clutter", allow_zero=True)
    if share > 1:
        raise ValueError(f"clutter: expected a share between 0 and 1, got {share}")
    return _long_corridor(layout, seed, share)


@functools.lru_cache(maxsize=6)
def _long_corridor(layout: str, seed: int, share: float) -> World:
    """:func:`long_corridor` from checked arguments (the cache sees only those: a list would not hash)."""
    rng = np.random.default_rng(seed)
    L, W, D, H = 36.10, 2.17, 0.07, 2.6
    b = Builder(rng, density=100)
    north, south = _door_plan(layout)
    doors = []
    # north wall y = +W/2 walked east (room on the right), south wall y = -W/2 walked west
    nd = [(c - w / 2, c + w / 2) for c, w in north]
    wall_with_doors(b, "wall/north", (0, W / 2), (L, W / 2), nd, height=H, depth=D)
    sd = [(L - c - w / 2, L - c + w / 2) for c, w in south]
    wall_with_doors(b, "wall/south", (L, -W / 2), (0, -W / 2), sd, height=H, depth=D)
    b.wall("wall/west", (0, -W / 2), (0, W / 2), 0.0, H)
    b.wall("wall/east", (L, W / 2), (L, -W / 2), 0.0, H)
    b.horizontal("floor", 0, -W / 2 - D, L, W / 2 + D, 0.0, True, tx.floor_tiles)
    b.horizontal("ceiling", 0, -W / 2, L, W / 2, H, False, tx.ceiling_panels)
    for side, plan, y, t in (("north", north, W / 2, (1, 0)), ("south", south, -W / 2, (-1, 0))):
        a = (0.0, y) if side == "north" else (L, y)
        for k, (c, w) in enumerate(plan):
            x0, x1 = c - w / 2, c + w / 2
            doors.append((side, x0, x1))
            number = f"B{(2 * k + 1) if side == 'north' else (2 * k + 2):02d}"
            s_plate = (x1 + 0.15) if side == "north" else (L - x0 + 0.15)
            _hang(b, f"plate/{number}", a, t, s_plate, 0.22, 1.65, 0.09,
                  lambda w_, h_, r, n=number: tx.room_plate(n, w_, h_, r))
        # decorations between doors: a poster or a board in most gaps, none in some (repetition)
        edges = sorted([(c - w / 2, c + w / 2) for c, w in plan])
        gaps = [(e0[1] + 0.5, e1[0] - 0.2) for e0, e1 in zip(edges[:-1], edges[1:])]
        for k, (g0, g1) in enumerate(gaps):
            width = min(1.2, g1 - g0 - 0.2)
            if width < 0.5 or rng.random() < 0.25:
                continue
            s = (g0 + 0.1) if side == "north" else (L - g0 - 0.1 - width)
            _hang(b, f"decor/{side}/{k}", a, t, s, width, 1.9, width * rng.uniform(0.6, 0.9),
                  random_decoration(rng))
    cabinets = _cabinets(b, share, seed, L, W, doors)
    return b.world("long_corridor", (1.0, 0.0), H,
                   info={"length": L, "width": W, "recess": D, "layout": layout, "doors": doors, "seed": seed,
                         "clutter": cabinets})


def _cabinets(b: Builder, share: float, seed: int, length: float, width: float, doors: list) -> list:
    """Stand a cabinet against the wall in ``share`` of the stretches between doors (and the ends);
    drawn from their own generator, after every other surface, so the rest of the corridor is the
    same whatever the share."""
    rng = np.random.default_rng([seed, 1])
    placed = []
    for side, y in (("north", width / 2), ("south", -width / 2)):
        edges = sorted((x0, x1) for s, x0, x1 in doors if s == side)
        bounds = [0.0] + [e for edge in edges for e in edge] + [length]
        for k, (g0, g1) in enumerate(zip(bounds[::2], bounds[1::2])):
            chance, size = rng.random(), rng.uniform(0.3, 0.9)
            depth, height = rng.uniform([0.2, 0.6], [0.45, 1.2])
            at = rng.random()
            room = g1 - g0 - 0.4 - size          # 0.2 m clear of each door frame (or end wall)
            if chance >= share or room < 0:
                continue
            x0 = g0 + 0.2 + at * room
            inward = -np.sign(y)
            b.box(f"cabinet/{side}/{k}", (x0 + size / 2, y + inward * (depth / 2 + 0.005)), (size, depth, height))
            placed.append((side, float(x0), float(x0 + size), float(depth)))
    return placed


long_corridor.cache_clear = _long_corridor.cache_clear


@functools.lru_cache(maxsize=4)
def office_floor(seed: int = 1) -> World:
    """Four rooms R1-R4 and a horizontal corridor (the test environment of lesson 02's paper).

    Parameters
    ----------
    seed : int, default 1

    Returns
    -------
    World
        ``[0, 16] x [0, 12]`` m: corridor ``y in [5, 7]``; R1 lower right, R2 lower left, R3 upper
        left, R4 upper right (``info["rooms"]``), each opening onto the corridor by a 1 m doorway.

    Raises
    ------
    ValueError, TypeError
        For a negative or non-integer seed.

    Notes
    -----
    "Robust omnidirectional vision based mobile robot hierarchical localization and autonomous
    navigation", Sec. "Experimental results", Fig. 6a: "four rooms R1, R2, R3, R4 and a horizontal
    corridor". Dimensions are our choice (the paper gives none).

    Examples
    --------
    >>> office = office_floor()
    >>> sorted(office.info["rooms"]), office.info["corridor"]
    (['R1', 'R2', 'R3', 'R4'], (5.0, 7.0))
    """
    rng = np.random.default_rng(as_int(seed, "seed", minimum=0))
    H = 2.7
    b = Builder(rng, density=100)
    _rect_walls(b, "wall/outer", 0, 0, 16, 12, H)
    # corridor walls: south one (y = 5) walked west so the corridor is on its right; doorways at x = 4, 12
    wall_with_doors(b, "wall/corridor_s", (16, 5), (0, 5), [(3.5, 4.5), (11.5, 12.5)], height=H, leaf=False)
    wall_with_doors(b, "wall/corridor_n", (0, 7), (16, 7), [(3.5, 4.5), (11.5, 12.5)], height=H, leaf=False)
    b.wall("wall/r1r2", (8, 0), (8, 5), 0.0, H)
    b.wall("wall/r3r4", (8, 12), (8, 7), 0.0, H)
    b.horizontal("floor", 0, 0, 16, 12, 0.0, True, tx.floor_tiles)
    b.horizontal("ceiling", 0, 0, 16, 12, H, False, tx.ceiling_panels)
    rooms = {"R1": (8, 0, 16, 5), "R2": (0, 0, 8, 5), "R3": (0, 7, 8, 12), "R4": (8, 7, 16, 12)}
    k = 0
    for rname, (x0, y0, x1, y1) in rooms.items():
        far_y = y0 if y0 == 0 else y1
        a, t = ((x1, far_y), (-1, 0)) if far_y == 0 else ((x0, far_y), (1, 0))
        for s in (1.0, 3.2, 5.4):
            width = rng.uniform(0.8, 1.4)
            _hang(b, f"poster/{k}", a, t, s, width, 2.0, width * 0.8, random_decoration(rng))
            k += 1
        cx, cy = (x0 + x1) / 2 + rng.uniform(-1, 1), (y0 + y1) / 2 + rng.uniform(-0.5, 0.5)
        b.box(f"{rname}/table", (cx, cy), (1.6, 0.8, 0.75), rng.uniform(0, np.pi))
        b.box(f"{rname}/cabinet", (x0 + 0.4, (y0 + y1) / 2), (1.0, 0.5, 1.8), np.pi / 2, tx.notice_board)
    for s in (2.0, 7.0, 9.5, 14.5):  # boards along the corridor's north wall
        _hang(b, f"corridor_board/{s}", (0, 7), (1, 0), s - 0.5, 1.0, 1.9, 0.7, random_decoration(rng))
    return b.world("office_floor", (2.0, 6.0), H, info={"size": (16.0, 12.0), "corridor": (5.0, 7.0),
                                                         "rooms": rooms, "seed": seed})
