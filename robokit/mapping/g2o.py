"""Planar pose graphs in the g2o text format: ``VERTEX_SE2``, ``EDGE_SE2`` and ``FIX`` lines.

The format of g2o (Kummerle et al. 2011) in which the public 2-D pose-graph benchmarks are
distributed (Olson's M3500, Intel, MIT, CSAIL, Manhattan ...)::

    VERTEX_SE2 id x y theta
    EDGE_SE2 id_i id_j dx dy dtheta I11 I12 I13 I22 I23 I33
    FIX id

An edge's measurement is the pose of ``id_j`` in ``id_i``'s frame and ``I..`` the upper triangle,
row by row, of its 3 x 3 information matrix. Vertex ids need be neither 0..N-1 nor sorted; the
graph keeps them in :attr:`PoseGraph.ids` and its rows in file order.

What the reader accepts: blank lines, comments (from ``#`` to the end of a line), fields separated
by any whitespace, edges before the vertices they name, and ``FIX`` of one vertex (the gauge;
without one, the first vertex is fixed, as g2o does). What it refuses, with a
:class:`G2OFormatError` giving the file and line: any other tag (3-D poses such as
``VERTEX_SE3:QUAT``, landmarks such as ``VERTEX_XY`` / ``EDGE_SE2_XY`` and parameters are named as
unsupported: this is a 2-D pose-graph reader), a wrong number of fields, a field that is not a
number, a value that is not finite, a repeated vertex id, an edge naming an unknown vertex or one
vertex twice, an information matrix that is not positive definite, and ``FIX`` of a second vertex.

References
----------
.. [1] R. Kummerle, G. Grisetti, H. Strasdat, K. Konolige and W. Burgard, "g2o: A general framework
   for graph optimization", Proc. IEEE Int. Conf. on Robotics and Automation (ICRA), 3607-3613, 2011.
"""
from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from ..files import as_file_path, read_regular, write_atomically
from ..validation import describe
from .pose_graph import PoseGraph, as_pose_graph, positive_definite

__all__ = ["G2OFormatError", "read_g2o", "write_g2o", "MAX_G2O_BYTES"]

#: The largest g2o file :func:`read_g2o` reads (bytes): about 45,000 vertices and as many edges.
MAX_G2O_BYTES = 4 * 1024**2

#: Tags of other g2o types, named in the error so a 3-D or landmark file is recognised as such.
UNSUPPORTED = ("VERTEX_SE3:QUAT", "EDGE_SE3:QUAT", "VERTEX_XY", "EDGE_SE2_XY", "VERTEX_TRACKXYZ", "EDGE_SE2_TRACKXYZ",
               "VERTEX_POINTXYZ", "EDGE_SE3_POINTXYZ", "PARAMS_SE2OFFSET", "PARAMS_SE3OFFSET", "EDGE_SE2_PRIOR",
               "EDGE_SE3_PRIOR", "VERTEX_SE2_XY", "EDGE_SE2_POINTXY")

#: Upper-triangle positions of ``I11 I12 I13 I22 I23 I33``.
_UPPER = (np.array([0, 0, 0, 1, 1, 2]), np.array([0, 1, 2, 1, 2, 2]))


class G2OFormatError(ValueError):
    """A g2o file that cannot be read; ``where`` (a path or ``"<text>"``) and ``line`` (1-based) say where."""

    def __init__(self, where: str, line: int, message: str) -> None:
        super().__init__(f"source: {where}, line {line}: {message}")
        self.where = where
        self.line = line


def _numbers(fields: list[str], count: int, tag: str, fail) -> list[float]:
    if len(fields) != count:
        fail(f"{tag} expects {count} numbers after the tag, got {len(fields)}")
    out = []
    for f in fields:
        try:
            v = float(f)
        except ValueError:
            fail(f"{tag}: {f!r} is not a number")
        if not math.isfinite(v):
            fail(f"{tag}: expected finite numbers, got {f!r}")
        out.append(v)
    return out


def _vertex_id(text: str, tag: str, fail) -> int:
    try:
        vid = int(text)
    except ValueError:
        fail(f"{tag}: vertex id {text!r} is not an integer")
    if not -2**63 <= vid < 2**63:          # ids are kept as int64: a larger one would wrap around
        fail(f"{tag}: vertex id {text[:30]!r} does not fit in 64 bits")
    return vid


def _text_of(source: Any) -> tuple[str, str]:
    """(text, where) of a path or of g2o text (a str with a newline)."""
    if isinstance(source, str) and "\n" in source:
        if len(source) > MAX_G2O_BYTES:
            raise G2OFormatError("<text>", 0, f"{len(source)} characters, more than the {MAX_G2O_BYTES} read_g2o reads")
        return source, "<text>"
    path = as_file_path(source, "source")
    data = read_regular(path, MAX_G2O_BYTES, lambda reason: G2OFormatError(str(path), 0, reason))
    try:
        return data.decode("utf-8"), str(path)
    except UnicodeDecodeError:
        raise G2OFormatError(str(path), 0, "not a text file (not UTF-8)") from None


def read_g2o(source: Any) -> PoseGraph:
    """Read a planar pose graph from a g2o file or text.

    Parameters
    ----------
    source : str or os.PathLike
        A path, or the file's text itself (a ``str`` containing a newline).

    Returns
    -------
    PoseGraph
        Nodes in the order of the ``VERTEX_SE2`` lines (``ids`` keeps the file's ids), edges in
        the order of the ``EDGE_SE2`` lines; the ``FIX`` vertex (or the first) is fixed.

    Raises
    ------
    G2OFormatError
        A ``ValueError`` naming the file and line, for what the module docstring lists.
    FileNotFoundError
        If the path does not exist.
    TypeError
        If ``source`` is neither a str nor a path.

    Notes
    -----
    The g2o format (Kummerle et al. 2011); information matrices are read from their upper
    triangle, row-major.

    Examples
    --------
    >>> text = '''# a triangle
    ... VERTEX_SE2 10 0 0 0
    ... VERTEX_SE2 11 1 0 0
    ... VERTEX_SE2 12 1 1 1.5708
    ... EDGE_SE2 10 11 1 0 0 100 0 0 100 0 400
    ... EDGE_SE2 11 12 0 1 1.5708 100 0 0 100 0 400
    ... EDGE_SE2 12 10 -1 1 1.5708 100 0 0 100 0 400
    ... '''
    >>> g = read_g2o(text)
    >>> g.ids.tolist(), g.edges.tolist(), g.information[0].diagonal().tolist()
    ([10, 11, 12], [[0, 1], [1, 2], [2, 0]], [100.0, 100.0, 400.0])
    >>> read_g2o("VERTEX_SE2 0 0 0 0\\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0\\n")
    Traceback (most recent call last):
    ...
    robokit.mapping.g2o.G2OFormatError: source: <text>, line 2: EDGE_SE2 expects 11 numbers after the tag, got 10
    """
    if not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"source: expected a path or g2o text (a str), got {describe(source)}")
    text, where = _text_of(source)
    if "VERTEX_SE2" not in text and not any(tag in text for tag in UNSUPPORTED):
        raise G2OFormatError(where, 0, "no VERTEX_SE2 line")   # before the parse (a 3-D file is named below)
    index: dict[int, int] = {}
    poses, edge_ids, edge_lines, measurements, upper = [], [], [], [], []
    fixed: tuple[int, int] | None = None                  # (vertex id, line)
    for number, raw in enumerate(text.splitlines(), start=1):
        def fail(message: str, number: int = number) -> None:
            raise G2OFormatError(where, number, message)
        fields = raw.split("#", 1)[0].split()
        if not fields:
            continue
        tag = fields[0]
        if tag == "VERTEX_SE2":
            if len(fields) != 5:
                fail(f"VERTEX_SE2 expects an id and 3 numbers, got {len(fields) - 1} fields")
            vid = _vertex_id(fields[1], tag, fail)
            if vid in index:
                fail(f"VERTEX_SE2: vertex id {vid} was defined before")
            index[vid] = len(poses)
            poses.append(_numbers(fields[2:], 3, tag, fail))
        elif tag == "EDGE_SE2":
            if len(fields) != 12:
                fail(f"EDGE_SE2 expects 11 numbers after the tag, got {len(fields) - 1}")
            ids = (_vertex_id(fields[1], tag, fail), _vertex_id(fields[2], tag, fail))
            if ids[0] == ids[1]:
                fail(f"EDGE_SE2: joins vertex {ids[0]} to itself")
            values = _numbers(fields[3:], 9, tag, fail)
            edge_ids.append(ids)
            edge_lines.append(number)
            measurements.append(values[:3])
            upper.append(values[3:])
        elif tag == "FIX":
            vids = [_vertex_id(f, tag, fail) for f in fields[1:]]
            if not vids:
                fail("FIX expects a vertex id")
            for vid in vids:
                if fixed is not None and fixed[0] != vid:
                    fail(f"FIX: vertex {vid} after vertex {fixed[0]}; one fixed vertex is supported")
                fixed = (vid, number)
        elif tag in UNSUPPORTED:
            fail(f"{tag} is not supported: this reader takes 2-D pose graphs (VERTEX_SE2, EDGE_SE2, FIX)")
        else:
            fail(f"unknown tag {tag!r} (expected VERTEX_SE2, EDGE_SE2 or FIX)")
    if not poses:
        raise G2OFormatError(where, 0, "no VERTEX_SE2 line")
    edges = np.zeros((len(edge_ids), 2), np.int64)
    for k, (ids, line) in enumerate(zip(edge_ids, edge_lines)):
        for side, vid in enumerate(ids):
            if vid not in index:
                raise G2OFormatError(where, line, f"EDGE_SE2: vertex {vid} has no VERTEX_SE2 line")
            edges[k, side] = index[vid]
    information = np.zeros((len(upper), 3, 3))
    information[:, _UPPER[0], _UPPER[1]] = np.array(upper).reshape(-1, 6)
    information[:, _UPPER[1], _UPPER[0]] = np.array(upper).reshape(-1, 6)
    bad = np.flatnonzero(~positive_definite(information))
    if bad.size:
        raise G2OFormatError(where, edge_lines[bad[0]], "EDGE_SE2: information matrix is not positive definite "
                                                        f"(eigenvalues {np.linalg.eigvalsh(information[bad[0]])})")
    if fixed is not None and fixed[0] not in index:
        raise G2OFormatError(where, fixed[1], f"FIX: vertex {fixed[0]} has no VERTEX_SE2 line")
    return PoseGraph(np.array(poses), edges, np.array(measurements).reshape(-1, 3), information,
                     ids=np.array(list(index)), fixed=0 if fixed is None else index[fixed[0]])


def write_g2o(graph: PoseGraph, path: Any = None) -> str:
    """Write a pose graph in the g2o format (and return the text).

    Parameters
    ----------
    graph : PoseGraph
    path : str or os.PathLike, optional
        Where to write; ``None`` only returns the text.

    Returns
    -------
    str
        ``VERTEX_SE2`` lines (in row order, with ``graph.ids``), ``EDGE_SE2`` lines, then
        ``FIX`` of the fixed vertex. Numbers are written with Python's ``repr`` (the shortest text
        that reads back to the same float), so :func:`read_g2o` gives the graph back exactly.

    Raises
    ------
    TypeError
        If ``graph`` is not a PoseGraph or ``path`` not a path.

    Notes
    -----
    The g2o format (Kummerle et al. 2011).

    Examples
    --------
    >>> g = PoseGraph([[0, 0, 0], [1, 0, 0.1]], [[0, 1]], [[1, 0, 0.1]], information=[np.diag([4.0, 4.0, 9.0])])
    >>> print(write_g2o(g), end="")
    VERTEX_SE2 0 0.0 0.0 0.0
    VERTEX_SE2 1 1.0 0.0 0.1
    EDGE_SE2 0 1 1.0 0.0 0.1 4.0 0.0 0.0 4.0 0.0 9.0
    FIX 0
    """
    as_pose_graph(graph)
    target = None if path is None else as_file_path(path, "path")

    def num(values) -> str:
        return " ".join(repr(float(v)) for v in values)

    lines = [f"VERTEX_SE2 {vid} {num(p)}" for vid, p in zip(graph.ids, graph.poses)]
    upper = graph.information[:, _UPPER[0], _UPPER[1]]
    ids = graph.ids[graph.edges]
    lines += [f"EDGE_SE2 {a} {b} {num(z)} {num(u)}" for (a, b), z, u in zip(ids, graph.measurements, upper)]
    lines.append(f"FIX {graph.ids[graph.fixed]}")
    text = "\n".join(lines) + "\n"
    if target is not None:
        write_atomically(target, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return text
