"""Matplotlib figures of a LittleDog trial: gait diagram, joint tracking, foot forces, support polygon.

Each helper draws on a given ``matplotlib.axes.Axes`` (or makes one), labels both axes with units
and returns what it drew on, so a lesson can add to it.

* :func:`plot_gait_diagram` - the footfall diagram: one bar per leg, dark while the foot stands.
* :func:`plot_joint_tracking` - what the host sent, what the servo received, what the joint did.
* :func:`plot_foot_forces` - the lower-leg force sensors against the true contacts (and a detector's).
* :func:`plot_support` - a top view: stance feet, support polygon, centre-of-mass projection, margin.
* :func:`support_outline` - the support region's outline to draw (hull, segment or point).

References
----------
.. [1] M. Hildebrand, "Symmetrical gaits of horses", *Science* 150(3697), 701-708, 1965 (the gait
   diagram: one bar per foot over the stride, filled while the foot is on the ground).
.. [2] R. B. McGhee and A. A. Frank, "On the stability properties of quadruped creeping gaits",
   *Mathematical Biosciences* 3, 331-351, 1968 (support pattern, stability margin).
.. [3] Boston Dynamics, *LittleDog User Guide*, version 1.0.2, 2006, Sec. 2 (100 Hz host loop,
   500 Hz servos) and Sec. 3 (lower-leg force sensors "capable of detecting touchdown events").
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..legged.littledog import JOINT_NAMES, LEGS
from ..legged.support import SupportPolygonError, nearest_boundary_point, stability_margin, support_polygon
from ..legged.trial_log import TrialLog
from ..validation import as_array, describe
from .maps import map_axes

__all__ = ["support_outline", "plot_gait_diagram", "plot_joint_tracking", "plot_foot_forces", "plot_support"]

_LEG_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red")


def _new_axes(ax: Any, figsize: tuple):
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=figsize)
    return ax


def support_outline(feet_xy: Any) -> np.ndarray:
    """The outline of the region the stance feet support, to draw: polygon, segment or point.

    Parameters
    ----------
    feet_xy : array_like, shape (k, 2)
        Horizontal positions (m) of the feet on the ground, any order; k may be 0.

    Returns
    -------
    numpy.ndarray, shape (m, 2)
        The convex hull's vertices counter-clockwise (m >= 3) when three or more feet are not on one
        line; else the two feet farthest apart (m = 2: a trot's diagonal); the foot (m = 1); nothing.

    Notes
    -----
    The support pattern of McGhee & Frank (1968), unnumbered: the convex hull of the supporting
    feet (:func:`robokit.legged.support.support_polygon`). Unlike a stability computation it
    never refuses fewer than three feet: a two-foot support is drawn as its segment.

    Examples
    --------
    >>> support_outline([[0, 0], [1, 1], [1, 0], [0, 1], [0.5, 0.5]]).tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    >>> support_outline([[0.2, 0.1], [-0.2, -0.1]]).shape, support_outline(np.zeros((0, 2))).shape
    ((2, 2), (0, 2))
    """
    xy = as_array(feet_xy, "feet_xy")
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise ValueError(f"feet_xy: expected shape (k, 2), got {describe(feet_xy)}")
    if len(xy) >= 3:
        try:
            v = support_polygon(xy)
            start = np.lexsort((v[:, 1], v[:, 0]))[0]            # lowest x (then y) first: a fixed order
            return np.roll(v, -start, axis=0)
        except SupportPolygonError:          # on one line: the segment below
            pass
    if len(xy) >= 2:
        d = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
        a, b = np.unravel_index(np.argmax(d), d.shape)
        return xy[[a, b]]
    return xy


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """(first, last + 1) row of every run of True."""
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))


def _times(t: Any, n_name: str = "t") -> np.ndarray:
    t = as_array(t, n_name)
    if t.ndim != 1 or len(t) < 1:
        raise ValueError(f"{n_name}: expected a 1-D array of at least one time, got {describe(t)}")
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"{n_name}: expected strictly increasing times")
    return t


def plot_gait_diagram(t: Any, stance: Any, ax: Any = None, legs: Sequence[str] = LEGS):
    """The gait (footfall) diagram: one bar per leg against time, dark while the foot is in stance.

    Parameters
    ----------
    t : array_like, shape (N,)
        Times (s), strictly increasing.
    stance : array_like of bool, shape (N, K)
        Which feet are on the ground (``log.contact``, a planned pattern, or detected contacts).
    ax : matplotlib.axes.Axes, optional
    legs : sequence of K str, default LEGS
        Row labels, top to bottom.

    Returns
    -------
    matplotlib.axes.Axes

    Notes
    -----
    The gait diagram of Hildebrand (1965; unnumbered): a bar per foot, filled while it is on the
    ground. Each sample's stance lasts until the next sample (the last one for the median period).

    Examples
    --------
    >>> t = np.arange(8) * 0.1
    >>> stance = np.ones((8, 4), bool); stance[2:4, 0] = False     # FL swings from 0.2 to 0.4 s
    >>> ax = plot_gait_diagram(t, stance)
    >>> ax.get_xlabel(), [tick.get_text() for tick in ax.get_yticklabels()]
    ('time t [s]', ['FL', 'FR', 'HL', 'HR'])
    """
    t = _times(t)
    mask = as_array(stance, "stance", dtype=bool)
    if mask.ndim != 2 or len(mask) != len(t):
        raise ValueError(f"stance: expected shape ({len(t)}, K), one row per time, got {describe(stance)}")
    if isinstance(legs, str) or len(legs) != mask.shape[1] or not all(isinstance(x, str) for x in legs):
        raise ValueError(f"legs: expected {mask.shape[1]} labels (one per column of stance), got {legs!r}")
    period = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    ends = np.append(t[1:], t[-1] + period)
    ax = _new_axes(ax, (8, 2.6))
    k = len(legs)
    for row in range(k):
        y = k - 1 - row
        ax.broken_barh([(t[0], ends[-1] - t[0])], (y - 0.35, 0.7), facecolors="0.92")
        bars = [(t[a], ends[b - 1] - t[a]) for a, b in _runs(mask[:, row])]
        ax.broken_barh(bars, (y - 0.35, 0.7), facecolors="0.15", label="stance" if row == 0 else None)
    ax.set_yticks(range(k)[::-1], list(legs))
    ax.set_ylim(-0.6, k - 0.4)
    ax.set_xlim(t[0], ends[-1])
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("leg")
    ax.set_title("gait diagram (dark: foot on the ground)")
    return ax


def _joint_indices(joints: Any) -> list[int]:
    if isinstance(joints, (str, int, np.integer)):
        joints = [joints]
    if not isinstance(joints, (list, tuple)) or not joints:
        raise TypeError(f"joints: expected joint names (JOINT_NAMES) or indices 0-11, got {describe(joints)}")
    out = []
    for j in joints:
        if isinstance(j, str) and j in JOINT_NAMES:
            out.append(JOINT_NAMES.index(j))
        elif isinstance(j, (int, np.integer)) and not isinstance(j, bool) and 0 <= j < 12:
            out.append(int(j))
        else:
            raise ValueError(f"joints: expected names among {list(JOINT_NAMES)} or indices 0-11, got {j!r}")
    return out


def plot_joint_tracking(log: TrialLog, joints: Any = ("FL_hip_pitch", "FL_knee"), ax: Any = None):
    """Joint tracking: the set-point the host sent, the one the robot servoed to, and the measured angle.

    Parameters
    ----------
    log : TrialLog
    joints : sequence of str or int, default ("FL_hip_pitch", "FL_knee")
        Names from :data:`~robokit.legged.littledog.JOINT_NAMES` or indices 0-11.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.axes.Axes

    Notes
    -----
    One colour per joint; dashed ``q_cmd`` (sent every 10 ms), dotted ``q_ref`` (what arrived over
    the wireless link, late or lost), solid ``q`` (encoders): the gap between dashed and dotted is
    the link, between dotted and solid the 500 Hz servo (LittleDog User Guide, Sec. 2).

    Examples
    --------
    >>> from robokit.legged import TrialLog
    >>> from robokit.legged.trial_log import empty_streams, trial_meta
    >>> ax = plot_joint_tracking(TrialLog(empty_streams(5), trial_meta()), ["FR_knee"])
    >>> ax.get_xlabel(), ax.get_ylabel(), len(ax.lines)
    ('time t [s]', 'joint angle [rad]', 3)
    """
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a robokit.legged.TrialLog, got {describe(log)}")
    idx = _joint_indices(joints)
    ax = _new_axes(ax, (8, 3.2))
    for c, j in enumerate(idx):
        color = f"C{c % 10}"
        ax.plot(log.t, log.q_cmd[:, j], "--", color=color, lw=1.2, label=f"{JOINT_NAMES[j]} q_cmd (sent)")
        ax.plot(log.t, log.q_ref[:, j], ":", color=color, lw=1.6, label=f"{JOINT_NAMES[j]} q_ref (received)")
        ax.plot(log.t, log.q[:, j], "-", color=color, lw=1.0, label=f"{JOINT_NAMES[j]} q (measured)")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("joint angle [rad]")
    ax.set_title("joint tracking")
    ax.legend(fontsize="small", ncol=len(idx), loc="best")
    return ax


def _leg_axes(ax: Any, legs: Sequence[str]) -> list:
    if ax is None:
        import matplotlib.pyplot as plt

        _, axes = plt.subplots(len(legs), 1, sharex=True, figsize=(8, 1.6 * len(legs) + 0.6), squeeze=False)
        return list(axes[:, 0])
    axes = list(ax) if isinstance(ax, (list, tuple, np.ndarray)) else [ax]
    if len(axes) != len(legs) or not all(hasattr(a, "plot") for a in axes):
        raise ValueError(f"ax: expected {len(legs)} matplotlib Axes (one per leg of legs) or None, got {describe(ax)}")
    return axes


def plot_foot_forces(log: TrialLog, ax: Any = None, detected: Any = None, legs: Sequence[str] = LEGS):
    """The lower-leg force sensors against time, with the true contacts shaded (and detected ones).

    Parameters
    ----------
    log : TrialLog
    ax : matplotlib.axes.Axes or sequence of them, optional
        One per leg of ``legs``; a new stacked figure if omitted.
    detected : array_like of bool, shape (N, 4), optional
        Contacts a detector found (e.g. a threshold on ``foot_force``), drawn as a band at the top.
    legs : sequence of str, default LEGS
        Which legs, one axes each.

    Returns
    -------
    list of matplotlib.axes.Axes

    Notes
    -----
    The guide's single-axis sensors measure the lower leg's axial force, "capable of detecting
    touchdown events" (LittleDog User Guide, Sec. 3); compression is positive.

    Examples
    --------
    >>> from robokit.legged import TrialLog
    >>> from robokit.legged.trial_log import empty_streams, trial_meta
    >>> axes = plot_foot_forces(TrialLog(empty_streams(5), trial_meta()), legs=["FL", "HR"])
    >>> len(axes), axes[0].get_ylabel(), axes[-1].get_xlabel()
    (2, 'FL axial force [N]', 'time t [s]')
    """
    if not isinstance(log, TrialLog):
        raise TypeError(f"log: expected a robokit.legged.TrialLog, got {describe(log)}")
    if isinstance(legs, str) or not legs or not all(isinstance(x, str) and x in LEGS for x in legs):
        raise ValueError(f"legs: expected a non-empty sequence of names among {list(LEGS)}, got {legs!r}")
    found = None
    if detected is not None:
        found = as_array(detected, "detected", dtype=bool)
        if found.shape != (len(log), 4):
            raise ValueError(f"detected: expected shape ({len(log)}, 4), one row per log row, got shape {found.shape}")
    axes = _leg_axes(ax, legs)
    for a, leg in zip(axes, legs):
        i = LEGS.index(leg)
        band = a.get_xaxis_transform()                    # x in data, y in axes fraction
        a.fill_between(log.t, 0, 1, where=log.contact[:, i], step="post", transform=band, color="0.85",
                       label="true contact")
        if found is not None:
            a.fill_between(log.t, 0.9, 1, where=found[:, i], step="post", transform=band, color="tab:orange",
                           alpha=0.8, label="detected contact")
        a.plot(log.t, log.foot_force[:, i], color=_LEG_COLORS[i], lw=1.0, label="force sensor")
        a.set_ylabel(f"{leg} axial force [N]")
    axes[-1].set_xlabel("time t [s]")
    axes[0].set_title("lower-leg force sensors (shaded: foot on the ground)")
    axes[0].legend(fontsize="small", loc="upper right")
    return axes


def plot_support(feet_xy: Any, stance: Any, com_xy: Any, ax: Any = None, legs: Sequence[str] = LEGS):
    """Top view of one instant: feet (filled in stance), support polygon, centre of mass, margin.

    Parameters
    ----------
    feet_xy : array_like, shape (K, 2) or (K, 3)
        Foot positions (m); a third column (height) is ignored.
    stance : array_like of bool, shape (K,)
    com_xy : array_like, shape (2,) or (3,)
        The centre of mass; its vertical projection is drawn.
    ax : matplotlib.axes.Axes, optional
    legs : sequence of K str, default LEGS
        Labels written beside the feet.

    Returns
    -------
    matplotlib.axes.Axes
        Its title gives the signed stability margin (mm): positive inside the polygon.

    Notes
    -----
    The support polygon is the convex hull of the stance feet; the margin is the distance from the
    centre-of-mass projection to its nearest edge, drawn as a segment (McGhee & Frank 1968,
    unnumbered). Fewer than three feet (or feet on a line) support no polygon: no margin.

    Examples
    --------
    >>> from robokit.legged.littledog import STANCE_FEET
    >>> ax = plot_support(STANCE_FEET, [True, True, True, False], [0.0, 0.0])
    >>> ax.get_title(), ax.get_xlabel()
    ('support: stability margin 0 mm', 'x [m]')
    """
    feet = as_array(feet_xy, "feet_xy")
    if feet.ndim != 2 or feet.shape[1] not in (2, 3) or len(feet) < 1:
        raise ValueError(f"feet_xy: expected shape (K, 2) or (K, 3), got {describe(feet_xy)}")
    feet = feet[:, :2]
    mask = as_array(stance, "stance", dtype=bool)
    if mask.shape != (len(feet),):
        raise ValueError(f"stance: expected shape ({len(feet)},), one flag per foot, got shape {mask.shape}")
    p = as_array(com_xy, "com_xy")
    if p.shape not in ((2,), (3,)):
        raise ValueError(f"com_xy: expected shape (2,) or (3,), got shape {p.shape}")
    p = p[:2]
    if isinstance(legs, str) or len(legs) != len(feet) or not all(isinstance(x, str) for x in legs):
        raise ValueError(f"legs: expected {len(feet)} labels (one per foot), got {legs!r}")
    v = support_outline(feet[mask])
    title = "support: no polygon (fewer than three feet down)"
    ax = map_axes(ax, figsize=(5, 4))
    if len(v) >= 3:
        closed = np.vstack([v, v[:1]])
        ax.fill(v[:, 0], v[:, 1], color="tab:green", alpha=0.25, label="support polygon")
        ax.plot(closed[:, 0], closed[:, 1], color="tab:green", lw=1.5)
        margin = stability_margin(v, p)                    # validates com_xy by name
        near = nearest_boundary_point(v, p, validate=False)[0]
        color = "tab:green" if margin >= 0 else "tab:red"
        ax.plot([p[0], near[0]], [p[1], near[1]], "--", color=color, lw=1.5, label=f"margin {1000 * margin:.0f} mm")
        title = f"support: stability margin {1000 * margin:.0f} mm"
    elif len(v) == 2:
        ax.plot(v[:, 0], v[:, 1], color="tab:green", lw=2, label="support line")
    ax.plot(feet[mask, 0], feet[mask, 1], "o", color="0.15", ms=9, label="stance foot")
    if (~mask).any():
        ax.plot(feet[~mask, 0], feet[~mask, 1], "o", mfc="white", mec="0.15", ms=9, label="swing foot")
    for (x, y), name in zip(feet, legs):
        ax.annotate(name, (x, y), textcoords="offset points", xytext=(8, 6), fontsize="small")
    ax.plot(*p, "*", color="gold", mec="k", ms=14, label="centre of mass (projection)")
    ax.set_title(title)
    ax.legend(fontsize="small", loc="center left", bbox_to_anchor=(1.02, 0.5))
    ax.margins(0.15)
    return ax
