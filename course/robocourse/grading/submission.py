"""Reading a submitted notebook: its code cells, or a rejection that says why it cannot be graded.

A rejection is an exception that carries the gradebook flag it earns (:class:`SubmissionRejected`
and its subclasses); the grader scores such a submission zero with ``str(exc)`` as the reason, and
``robocourse grade`` exits 1, because the file was not graded.

The file is read like the worker's output (:func:`~.transport.read_untrusted`): never through a
symbolic link, regular files only, at most ``MAX_NOTEBOOK_BYTES``. Every way its JSON can be
malformed (invalid UTF-8, syntax, nesting, a number too long to read, a field of the wrong type) is
a :class:`NotANotebook`, never another exception.
"""
from __future__ import annotations

import dataclasses
import json
import os
import re
import unicodedata
from pathlib import Path
from typing import Any

from robocourse.grading.transport import NotWritten, SymlinkRefused, TooLarge, TransportError, open_directory, read_untrusted

__all__ = ["Submission", "read_submission", "student_name", "feedback_stem", "SubmissionRejected", "NotANotebook",
           "WrongAssignment", "UnreadableSubmission", "SymlinkedSubmission", "SKIP_TAGS", "MAX_NOTEBOOK_BYTES"]

#: Cells with one of these tags are not run by the grader (plots, 3D scenes, slow demos).
SKIP_TAGS = {"demo", "visualisation", "visualization", "skip-grading"}
MAX_NOTEBOOK_BYTES = 20_000_000


class SubmissionRejected(ValueError):
    """The file cannot be graded; ``flag`` names the reason in the gradebook."""

    flag: str = ""


class NotANotebook(SubmissionRejected):
    """Empty, too large, not UTF-8 JSON, or not shaped like a notebook (see :func:`read_submission`)."""

    flag = "not-a-notebook"


class WrongAssignment(SubmissionRejected):
    """The notebook declares another assignment in its ``robokit`` metadata."""

    flag = "wrong-assignment"


class UnreadableSubmission(SubmissionRejected):
    """The file could not be read (missing, no permission, not a regular file, ...)."""

    flag = "unreadable"


class SymlinkedSubmission(SubmissionRejected):
    """The file, or the student's folder that names it, is a symbolic link, which is not followed:
    it could point at ``solutions/`` or at another student's work."""

    flag = "symlink"


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


def feedback_stem(student: str) -> str:
    """The name (without ``.md``) of a student's feedback file: letters, digits, ``_``, ``.`` and
    ``-`` only, at most 100 characters and 200 bytes (a file name may have 255), never hidden.
    Two students with the same stem (compared case-insensitively) would share a feedback file, so
    the grader treats them as duplicates.

    Examples
    --------
    >>> feedback_stem("../Zoë <b>")
    '_Zoë_b_'
    """
    stem = re.sub(r"[^\w.-]+", "_", unicodedata.normalize("NFC", student))[:100].lstrip(".")
    while len(stem.encode("utf-8", "surrogatepass")) > 200:  # NFC can turn 3-byte characters into 4-byte ones
        stem = stem[:-1]
    return stem or "student"


def _read_bytes(path: Path, assignment: str) -> bytes:
    """The file's content, without following a link for the components that name the student: the
    file, and its folder when the folder names the student (``alice/NN_slug.ipynb``)."""
    dir_fd = None
    try:
        if path.stem == assignment:
            dir_fd = open_directory(path.parent)
        return read_untrusted(path.name if dir_fd is not None else path, MAX_NOTEBOOK_BYTES, dir_fd=dir_fd,
                              links_ok=True)
    except SymlinkRefused:
        raise SymlinkedSubmission("the file is a symbolic link, which the grader does not follow; "
                                  "submit the notebook itself") from None
    except TooLarge:
        raise NotANotebook(f"the file is larger than {MAX_NOTEBOOK_BYTES // 1_000_000} MB") from None
    except NotWritten:
        raise UnreadableSubmission("the file could not be read (it does not exist)") from None
    except TransportError as exc:
        raise UnreadableSubmission(f"the file could not be read ({exc})") from None
    except OSError as exc:  # opening the student's folder
        if os.path.islink(path.parent):
            raise SymlinkedSubmission(f"the folder {path.parent.name!r} is a symbolic link, which the grader "
                                      "does not follow; submit the notebook itself") from None
        raise UnreadableSubmission(f"the file could not be read ({exc.strerror or exc})") from None
    finally:
        if dir_fd is not None:
            os.close(dir_fd)


def _parse(data: bytes) -> dict:
    """The notebook's JSON object; every way it can be malformed is a :class:`NotANotebook`."""
    if not data.strip():
        raise NotANotebook("the file is empty")
    try:
        nb = json.loads(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise NotANotebook("the file is not a Jupyter notebook (it is not UTF-8 text)") from None
    except json.JSONDecodeError as exc:
        raise NotANotebook(f"the file is not a Jupyter notebook (not valid JSON: {exc.msg} at line "
                           f"{exc.lineno})") from None
    except RecursionError:
        raise NotANotebook("the file is not a Jupyter notebook (its JSON is nested too deeply)") from None
    except ValueError:  # Python's limit on the digits of an integer
        raise NotANotebook("the file is not a Jupyter notebook (its JSON holds a number too long to read)") from None
    if not isinstance(nb, dict) or not isinstance(nb.get("cells"), list):
        raise NotANotebook("the file is not a Jupyter notebook (no list of cells)")
    return nb


def _field(mapping: dict, key: str, kind: type, default: Any, where: str) -> Any:
    """``mapping[key]`` if it has type ``kind``, ``default`` if absent; else a :class:`NotANotebook`."""
    value = mapping.get(key, default)
    if not isinstance(value, kind):
        raise NotANotebook(f"the file is not a valid notebook ({where}{key} is not {kind.__name__})")
    return value


def _declared_assignment(nb: dict) -> str:
    meta = _field(nb, "metadata", dict, {}, "")
    robokit = _field(meta, "robokit", dict, {}, "metadata.")
    return _field(robokit, "assignment", str, "", "metadata.robokit.")


def _code_cell(cell: Any, number: int) -> tuple[str, bool] | None:
    """``(source, skip)`` of a code cell, ``None`` for another kind of cell."""
    if not isinstance(cell, dict):
        raise NotANotebook(f"the file is not a valid notebook (cell {number} is not an object)")
    if cell.get("cell_type") != "code":
        return None
    where = f"cell {number}: "
    source = cell.get("source", "")
    if isinstance(source, list) and all(isinstance(line, str) for line in source):
        source = "".join(source)
    if not isinstance(source, str):
        raise NotANotebook(f"the file is not a valid notebook ({where}source is not text)")
    tags = _field(_field(cell, "metadata", dict, {}, where), "tags", list, [], where + "metadata.")
    if not all(isinstance(tag, str) for tag in tags):
        raise NotANotebook(f"the file is not a valid notebook ({where}metadata.tags are not strings)")
    return source, bool(SKIP_TAGS.intersection(tags))


def read_submission(path: Path, assignment: str) -> Submission:
    """Return the code cells of the notebook at ``path``, submitted for ``assignment``.

    The notebook must be shaped as nbformat says: a list of cells, each an object; code cells with a
    text source (a string or a list of strings) and object metadata whose tags are strings.

    Raises
    ------
    SymlinkedSubmission
        If the file, or the folder that names the student (``alice/NN_slug.ipynb``), is a symbolic
        link. Folders above the student's are the instructor's and may be links.
    UnreadableSubmission
        If the file does not exist, is not a regular file or cannot be read.
    NotANotebook
        If it is empty, larger than ``MAX_NOTEBOOK_BYTES``, not UTF-8 JSON or not shaped as above.
    WrongAssignment
        If its metadata declares another assignment.

    Notes
    -----
    Grading design (DESIGN.md, "Grading"); not from a paper.
    """
    path = Path(path)
    nb = _parse(_read_bytes(path, assignment))
    declared = _declared_assignment(nb)
    if declared and declared != assignment:
        shown = declared if len(declared) <= 60 else declared[:57] + "..."
        raise WrongAssignment(f"this notebook is assignment {shown!r}, not {assignment!r}")
    cells = [c for c in (_code_cell(cell, n) for n, cell in enumerate(nb["cells"], 1)) if c is not None]
    return Submission(tuple(s for s, _ in cells), tuple(skip for _, skip in cells))
