"""``robokit grade``: grade a folder of notebooks safely.

The trusted parent (this module) reads each submission, generates the input cases from the
instructor's secret seed, computes the reference answers, and starts one sandboxed worker per
submission (:mod:`robokit.grading.sandbox`, :mod:`robokit.grading.worker`) that receives only the
code cells and the inputs. The worker's replies are plain data (JSON + ``.npz`` without pickle)
that the parent validates before judging; student objects never reach the parent.
"""
from __future__ import annotations

import dataclasses
import json
import queue
import shutil
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Sequence

from ..exercises.catalog import UnknownAssignmentError, exercises_for
from ..exercises.spec import Case, Exercise
from .judge import expected_output, judge
from .sandbox import Limits, is_root, run_sandboxed
from .transport import TransportError, read_plain, write_plain

__all__ = ["SubmissionResult", "ExerciseScore", "prepare_cases", "grade_submission", "grade_batch",
           "GradingError", "SKIP_TAGS", "MAX_NOTEBOOK_BYTES"]

#: Cells with one of these tags are not run by the grader (plots, 3D scenes, slow demos).
SKIP_TAGS = {"demo", "visualisation", "visualization", "skip-grading"}
MAX_NOTEBOOK_BYTES = 20_000_000


class GradingError(ValueError):
    """A problem with the grading request itself (unknown assignment, missing seed, ...)."""


@dataclasses.dataclass
class ExerciseScore:
    """Score of one exercise: points, cases passed, feedback lines."""

    id: str
    points: float
    max_points: float
    passed: int
    total: int
    messages: list[str]


@dataclasses.dataclass
class SubmissionResult:
    """Everything the gradebook and the feedback need about one submission."""

    student: str
    path: Path
    scores: list[ExerciseScore]
    flags: list[str]
    reason: str = ""
    seconds: float = 0.0
    compute_seconds: float = 0.0
    cell_errors: list[str] = dataclasses.field(default_factory=list)
    read_error: bool = False
    worker_log: str = ""

    @property
    def total(self) -> float:
        return round(sum(s.points for s in self.scores), 4)

    @property
    def max_total(self) -> float:
        return round(sum(s.max_points for s in self.scores), 4)


@dataclasses.dataclass
class PreparedCases:
    """The trusted side of a grading run: exercises, their cases for the secret seed, and the
    reference answers. It stays in the grader's process; workers receive only the case inputs."""

    exercises: tuple[Exercise, ...]
    cases: list[list[Case]]
    expected: list[list[Any]]


def prepare_cases(assignment: str, seed: str) -> PreparedCases:
    """Generate every exercise's cases from ``seed`` and compute the reference answers (trusted)."""
    if not isinstance(seed, str) or not seed:
        raise GradingError("seed: a non-empty secret seed is required (--seed or ROBOKIT_GRADING_SEED)")
    exercises = exercises_for(assignment)
    cases = [ex.make_cases(seed) for ex in exercises]
    expected = [[expected_output(ex, c) for c in cs] for ex, cs in zip(exercises, cases)]
    return PreparedCases(exercises, cases, expected)


def student_name(path: Path, assignment: str) -> str:
    """``alice.ipynb`` -> ``alice``; ``alice/01_visual_slam.ipynb`` -> ``alice``."""
    return path.parent.name if path.stem == assignment else path.stem


def _read_submission(path: Path, assignment: str) -> tuple[list[str], list[bool]] | str:
    """Return (cell sources, skip flags) or a reason string for a zero."""
    try:
        size = path.stat().st_size
        if size > MAX_NOTEBOOK_BYTES:
            return f"the file is larger than {MAX_NOTEBOOK_BYTES // 1_000_000} MB"
        if size == 0:
            return "the file is empty"
        nb = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError):
        return "the file is not a Jupyter notebook (it is not valid JSON)"
    if not isinstance(nb, dict) or not isinstance(nb.get("cells"), list):
        return "the file is not a Jupyter notebook (no list of cells)"
    meta = nb.get("metadata") if isinstance(nb.get("metadata"), dict) else {}
    declared = (meta.get("robokit") or {}).get("assignment") if isinstance(meta.get("robokit"), dict) else None
    if declared and declared != assignment:
        return f"this notebook is assignment {declared!r}, not {assignment!r}"
    sources, skips = [], []
    for cell in nb["cells"]:
        if not isinstance(cell, dict) or cell.get("cell_type") != "code":
            continue
        src = cell.get("source", "")
        src = "".join(src) if isinstance(src, list) else src
        if not isinstance(src, str):
            continue
        tags = (cell.get("metadata") or {}).get("tags") or []
        sources.append(src)
        skips.append(bool(isinstance(tags, list) and SKIP_TAGS.intersection(map(str, tags))))
    return sources, skips


def _zero(prepared: PreparedCases, message: str) -> list[ExerciseScore]:
    return [ExerciseScore(ex.id, 0.0, float(ex.points), 0, len(cs), [message])
            for ex, cs in zip(prepared.exercises, prepared.cases)]


def _validate_results(raw: Any, n_cases: int) -> list[dict]:
    if not isinstance(raw, dict) or not isinstance(raw.get("results"), list):
        raise TransportError("malformed results")
    results = raw["results"]
    if len(results) != n_cases:
        raise TransportError(f"expected {n_cases} results, got {len(results)}")
    clean = []
    for r in results:
        if isinstance(r, dict) and set(r) == {"value"}:
            clean.append({"value": r["value"]})
        elif isinstance(r, dict) and set(r) == {"error"} and isinstance(r["error"], dict):
            e = r["error"]
            mro = e.get("mro") if isinstance(e.get("mro"), list) else []
            clean.append({"error": {"type": str(e.get("type"))[:100], "mro": [str(m)[:100] for m in mro[:12]],
                                    "message": str(e.get("message"))[:500]}})
        else:
            raise TransportError("malformed result entry")
    return clean


def grade_submission(path: str | Path, assignment: str, prepared: PreparedCases, *,
                     limits: Limits = Limits(), slot: int = 0, hide: Sequence[Path] = (),
                     work_root: Path | None = None) -> SubmissionResult:
    """Grade one notebook in a sandboxed worker; never raises for a bad submission.

    Notes
    -----
    Grading design (DESIGN.md, "Grading"; issue "Autograding"); not from a paper.
    """
    path = Path(path)
    student = student_name(path, assignment)
    start = time.perf_counter()
    try:
        read = _read_submission(path, assignment)
    except OSError as exc:
        reason = f"the file could not be read ({exc.strerror or exc})"
        return SubmissionResult(student, path, _zero(prepared, reason), ["unreadable"], reason, read_error=True)
    if isinstance(read, str):
        flag = "wrong-assignment" if "not '" in read else "not-a-notebook"
        return SubmissionResult(student, path, _zero(prepared, read), [flag], read,
                                read_error=flag == "wrong-assignment")
    sources, skips = read
    job = Path(tempfile.mkdtemp(prefix="job-", dir=work_root))
    try:
        for sub in ("in", "work", "out"):
            (job / sub).mkdir()
        references = sorted({r for ex in prepared.exercises for r in ex.references})
        write_plain({
            "cells": sources, "skip": skips, "references": references,
            "cell_seconds": limits.cell_seconds, "call_seconds": limits.call_seconds,
            "exercises": [{"id": ex.id, "function": ex.function,
                           "cases": [{"args": list(c.args), "kwargs": c.kwargs} for c in cs]}
                          for ex, cs in zip(prepared.exercises, prepared.cases)],
        }, job / "in" / "job")
        exit_ = run_sandboxed(["-m", "robokit.grading.worker", str(job)], job, limits, slot=slot,
                              hide=[*hide, path.resolve().parent])
        return _score(job, student, path, prepared, exit_, start)
    finally:
        shutil.rmtree(job, ignore_errors=True)


def _score(job: Path, student: str, path: Path, prepared: PreparedCases, exit_, start: float) -> SubmissionResult:
    out = job / "out"
    flags: list[str] = []
    if not exit_.isolated:
        flags.append("sandbox=limited")
    try:
        flag_lines = (out / "flags.log").read_text(errors="replace").splitlines()[:100]
    except OSError:
        flag_lines = []
    cell_errors: list[str] = []
    try:
        cells = read_plain(out / "cells")
        for c in cells.get("cells", [])[:500]:
            if isinstance(c, dict) and c.get("status") in ("error", "timeout") and isinstance(c.get("error"), dict):
                cell_errors.append(f"code cell {c.get('cell')}: {c['status']}: "
                                   f"{str(c['error'].get('type'))[:80]}: {str(c['error'].get('message'))[:200]}")
    except (TransportError, AttributeError):
        cells = None
    ended = "the grader stopped your notebook at its time limit" if exit_.timed_out else \
        "your notebook ended the grading process early"
    scores, compute, called_reference = [], 0.0, False
    for k, (ex, cases, expected) in enumerate(zip(prepared.exercises, prepared.cases, prepared.expected)):
        try:
            raw = read_plain(out / f"ex{k}")
            if isinstance(raw, dict) and raw.get("defined") is False:
                scores.append(ExerciseScore(ex.id, 0.0, float(ex.points), 0, len(cases),
                                            [f"function not defined: no function named {ex.function!r} in the notebook"]))
                continue
            results = _validate_results(raw, len(cases))
            if isinstance(raw.get("seconds"), (int, float)):
                compute += float(raw["seconds"])
        except TransportError as exc:
            why = ended if not (out / f"ex{k}.json").exists() else f"its results were unusable ({exc})"
            scores.append(ExerciseScore(ex.id, 0.0, float(ex.points), 0, len(cases), [f"not graded: {why}"]))
            continue
        passed, messages, ex_cheated = 0, [], False
        for i, (case, exp, res) in enumerate(zip(cases, expected, results), 1):
            if res.get("error", {}).get("type") == "ReferenceSolutionDisabled":
                ex_cheated = called_reference = True
            outcome = judge(ex, case, exp, res)
            passed += outcome.passed
            if not outcome.passed and len(messages) < 5:
                messages.append(f"case {i}" + (f" ({case.label})" if case.label else "") + f": {outcome.message}")
        if ex_cheated:
            passed = 0
            messages.insert(0, "you called the course's reference implementation, which is not allowed")
        points = round(float(ex.points) * passed / len(cases), 4)
        scores.append(ExerciseScore(ex.id, points, float(ex.points), passed, len(cases), messages))
    if called_reference or any(l.startswith("reference:") for l in flag_lines):
        flags.append("called-reference")
    log = ""
    if exit_.timed_out:
        flags.append("timeout")
    elif not (out / "done.json").exists():
        flags.append("worker-ended-early")
        # the last lines the worker process wrote outside Python's captured output (a crash, an
        # import error) say why; shown to the instructor in the feedback
        log = "\n".join(exit_.log.strip().splitlines()[-12:])[-1500:]
        if exit_.returncode is not None and exit_.returncode < 0:
            log = f"(worker killed by signal {-exit_.returncode})\n" + log
    return SubmissionResult(student, path, scores, flags, seconds=time.perf_counter() - start,
                            compute_seconds=compute, cell_errors=cell_errors, worker_log=log)


def grade_batch(paths: Sequence[str | Path], assignment: str, seed: str, *, jobs: int = 1,
                limits: Limits = Limits(), hide: Sequence[Path] = (), log=print) -> list[SubmissionResult]:
    """Grade many submissions, ``jobs`` at a time; the batch always completes.

    Raises
    ------
    GradingError
        Only for problems with the request (unknown assignment, missing seed, no submissions).
    """
    try:
        prepared = prepare_cases(assignment, seed)
    except UnknownAssignmentError as exc:
        raise GradingError(str(exc)) from None
    if not paths:
        raise GradingError("submissions: expected at least one notebook")
    slots: "queue.Queue[int]" = queue.Queue()
    for s in range(max(1, jobs)):
        slots.put(s)
    work_root = Path(tempfile.mkdtemp(prefix="robokit-grade-"))
    work_root.chmod(0o711)

    def one(path):
        slot = slots.get()
        try:
            result = grade_submission(path, assignment, prepared, limits=limits, slot=slot, hide=hide,
                                      work_root=work_root)
        finally:
            slots.put(slot)
        log(f"  {result.student:<24} {result.total:6.2f} / {result.max_total:<6.2f} "
            f"{result.seconds:5.1f}s  {' '.join(result.flags)}")
        return result

    try:
        with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            return list(pool.map(one, [Path(p) for p in paths]))
    finally:
        shutil.rmtree(work_root, ignore_errors=True)


def isolation_note() -> str:
    """One line saying how strongly this run can isolate student code."""
    return ("full isolation (namespaces, private uid, hidden paths, no network)" if is_root()
            else "limited isolation (not root: resource limits and timeouts only)")
