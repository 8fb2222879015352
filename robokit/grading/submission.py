"""Reading a submitted notebook: its code cells, or a rejection that says why it cannot be graded.

A rejection is an exception that carries the gradebook flag it earns (:class:`SubmissionRejected`
and its subclasses); the grader scores such a submission zero with ``str(exc)`` as the reason.
"""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

__all__ = ["Submission", "read_submission", "student_name", "SubmissionRejected", "NotANotebook",
           "WrongAssignment", "UnreadableSubmission", "SKIP_TAGS", "MAX_NOTEBOOK_BYTES"]

#: Cells with one of these tags are not run by the grader (plots, 3D scenes, slow demos).
SKIP_TAGS = {"demo", "visualisation", "visualization", "skip-grading"}
MAX_NOTEBOOK_BYTES = 20_000_000


class SubmissionRejected(ValueError):
    """The file cannot be graded; ``flag`` names the reason in the gradebook.

    ``read_error`` is true when the instructor should look (a missing file, a notebook of another
    assignment): ``robokit grade`` then exits non-zero. A file that is simply not a notebook is the
    student's zero, not an error of the grading run.
    """

    flag: str = ""
    read_error: bool = False


class NotANotebook(SubmissionRejected):
    """Empty, too large, not JSON, or JSON without a list of cells."""

    flag = "not-a-notebook"


class WrongAssignment(SubmissionRejected):
    """The notebook declares another assignment in its ``robokit`` metadata."""

    flag = "wrong-assignment"
    read_error = True


class UnreadableSubmission(SubmissionRejected):
    """The file could not be read (missing, no permission, ...)."""

    flag = "unreadable"
    read_error = True


@dataclasses.dataclass(frozen=True)
class Submission:
    """The code cells of a notebook, in order, and whether each is skipped (see ``SKIP_TAGS``)."""

    sources: tuple[str, ...]
    skip: tuple[bool, ...]


def student_name(path: Path, assignment: str) -> str:
    """``alice.ipynb`` -> ``alice``; ``alice/01_visual_slam.ipynb`` -> ``alice``.

    Examples
    --------
    >>> student_name(Path("subs/alice/01_visual_slam.ipynb"), "01_visual_slam")
    'alice'
    """
    return path.parent.name if path.stem == assignment else path.stem


def read_submission(path: Path, assignment: str) -> Submission:
    """Return the code cells of the notebook at ``path``, submitted for ``assignment``.

    Cells that are not code cells, or whose source is not text, are left out.

    Raises
    ------
    UnreadableSubmission
        If the file cannot be read.
    NotANotebook
        If it is empty, larger than ``MAX_NOTEBOOK_BYTES``, not JSON or has no list of cells.
    WrongAssignment
        If its metadata declares another assignment.

    Notes
    -----
    Grading design (DESIGN.md, "Grading"); not from a paper.
    """
    try:
        size = path.stat().st_size
        if size > MAX_NOTEBOOK_BYTES:
            raise NotANotebook(f"the file is larger than {MAX_NOTEBOOK_BYTES // 1_000_000} MB")
        if size == 0:
            raise NotANotebook("the file is empty")
        nb = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise UnreadableSubmission(f"the file could not be read ({exc.strerror or exc})") from None
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError):
        raise NotANotebook("the file is not a Jupyter notebook (it is not valid JSON)") from None
    if not isinstance(nb, dict) or not isinstance(nb.get("cells"), list):
        raise NotANotebook("the file is not a Jupyter notebook (no list of cells)")
    meta = nb.get("metadata") if isinstance(nb.get("metadata"), dict) else {}
    declared = (meta.get("robokit") or {}).get("assignment") if isinstance(meta.get("robokit"), dict) else None
    if declared and declared != assignment:
        raise WrongAssignment(f"this notebook is assignment {declared!r}, not {assignment!r}")
    sources, skip = [], []
    for cell in nb["cells"]:
        if not isinstance(cell, dict) or cell.get("cell_type") != "code":
            continue
        src = cell.get("source", "")
        src = "".join(src) if isinstance(src, list) else src
        if not isinstance(src, str):
            continue
        tags = (cell.get("metadata") or {}).get("tags") or []
        sources.append(src)
        skip.append(bool(isinstance(tags, list) and SKIP_TAGS.intersection(map(str, tags))))
    return Submission(tuple(sources), tuple(skip))
