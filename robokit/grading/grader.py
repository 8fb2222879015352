"""``robokit grade``: grade a folder of notebooks safely.

The trusted parent (this module) reads each submission (:mod:`~robokit.grading.submission`),
generates the input cases from the instructor's secret seed, computes the reference answers, and
starts one sandboxed worker per submission (:mod:`~robokit.grading.sandbox`,
:mod:`~robokit.grading.worker`) that receives only the code cells and the inputs. The worker runs
from a kit (:mod:`~robokit.grading.kit`), a robokit without the assignment's references, and as
root sees nothing else of the disk but the interpreter and the installed packages' code
(:mod:`~robokit.grading.filesystem_view`). The worker's replies are plain data that
:mod:`~robokit.grading.protocol` bounds and validates before anything here judges them; student
objects never reach the parent.
"""
from __future__ import annotations

import dataclasses
import shutil
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Sequence

from ..exercises.discovery import UnknownAssignmentError, get_assignment
from ..exercises.spec import Case, Exercise
from .filesystem_view import View, installed_robokit_dirs, runtime_paths
from .judge import expected_output, judge
from .kit import WORKER, Kit, KitError, build_kit
from .protocol import CallResult, JobDir, JobSpec, ReferenceSolutionDisabled
from .sandbox import Limits, WorkerExit, conceal_secret, is_root, run_sandboxed
from .submission import Submission, SubmissionRejected, read_submission, student_name
from .transport import TransportError

__all__ = ["SubmissionResult", "ExerciseScore", "PreparedCases", "prepare_cases", "job_spec", "worker_view",
           "grade_submission", "grade_batch", "GradingError", "isolation_note"]


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

    @classmethod
    def zero(cls, ex: Exercise, n_cases: int, message: str) -> ExerciseScore:
        """No points for ``ex``, for the reason ``message``."""
        return cls(ex.id, 0.0, float(ex.points), 0, n_cases, [message])


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
    exercises = get_assignment(assignment).exercises
    cases = [ex.make_cases(seed) for ex in exercises]
    expected = [[expected_output(ex, c) for c in cs] for ex, cs in zip(exercises, cases)]
    return PreparedCases(exercises, cases, expected)


def _zero(prepared: PreparedCases, message: str) -> list[ExerciseScore]:
    """Every exercise at zero, with one message."""
    return [ExerciseScore.zero(ex, len(cs), message) for ex, cs in zip(prepared.exercises, prepared.cases)]


def job_spec(submission: Submission, prepared: PreparedCases, limits: Limits) -> JobSpec:
    """The worker's request: cells, references to disable, limits, and the case inputs only (never
    the seed, the expected answers, what a case expects or its label)."""
    return JobSpec(submission.sources, submission.skip,
                   tuple(sorted({r for ex in prepared.exercises for r in ex.references})),
                   limits.cell_seconds, limits.call_seconds,
                   tuple((ex.function, tuple((c.args, c.kwargs) for c in cs))
                         for ex, cs in zip(prepared.exercises, prepared.cases)))


def worker_view(kit: Kit, hide: Sequence[Path] = ()) -> View:
    """What a worker's filesystem shows as root: the interpreter and the installed packages' code,
    the kit (also in place of every installed robokit), and nothing of ``hide``."""
    installed = installed_robokit_dirs(runtime_paths())
    return View((*runtime_paths(), str(kit.root)), tuple((d, str(kit.package)) for d in installed),
                tuple(str(Path(h).resolve()) for h in hide))


def grade_submission(path: str | Path, assignment: str, prepared: PreparedCases, *,
                     limits: Limits = Limits(), kit: Kit | None = None, hide: Sequence[Path] = (),
                     work_root: Path | None = None) -> SubmissionResult:
    """Grade one notebook in a sandboxed worker; never raises for a bad submission.

    A file that cannot be graded scores zero with the rejection's flag and reason. ``kit`` is the
    worker's robokit (:func:`~robokit.grading.kit.build_kit`; written into the job if not given).

    Notes
    -----
    Grading design (DESIGN.md, "Grading"; issue "Autograding"); not from a paper.
    """
    path = Path(path)
    student = student_name(path, assignment)
    start = time.perf_counter()
    try:
        submission = read_submission(path, assignment)
    except SubmissionRejected as exc:
        return SubmissionResult(student, path, _zero(prepared, str(exc)), [exc.flag], str(exc),
                                read_error=exc.read_error)
    job = JobDir.create(work_root)
    try:
        job.write_spec(job_spec(submission, prepared, limits))
        kit = kit or build_kit(get_assignment(assignment), job.root / "kit")
        exit_ = run_sandboxed(["-m", WORKER, str(job.root)], job.root, limits, view=worker_view(kit, hide),
                              env_extra={"PYTHONPATH": str(kit.root), "PYTHONSAFEPATH": "1"})
        return _score(job, student, path, prepared, exit_, start)
    finally:
        shutil.rmtree(job.root, ignore_errors=True)


def _score_exercise(ex: Exercise, cases: list[Case], expected: list[Any],
                    results: Sequence[CallResult]) -> tuple[ExerciseScore, bool]:
    """Judge one exercise's results; return its score and whether it called a disabled reference."""
    passed, messages, cheated = 0, [], False
    for i, (case, exp, res) in enumerate(zip(cases, expected, results), 1):
        cheated |= res.error is not None and res.error.type == ReferenceSolutionDisabled.__name__
        outcome = judge(ex, case, exp, res)
        passed += outcome.passed
        if not outcome.passed and len(messages) < 5:
            messages.append(f"case {i}" + (f" ({case.label})" if case.label else "") + f": {outcome.message}")
    if cheated:
        passed = 0
        messages.insert(0, "you called the course's reference implementation, which is not allowed")
    points = round(float(ex.points) * passed / len(cases), 4)
    return ExerciseScore(ex.id, points, float(ex.points), passed, len(cases), messages), cheated


def _score(job: JobDir, student: str, path: Path, prepared: PreparedCases, exit_: WorkerExit,
           start: float) -> SubmissionResult:
    """Read what the worker wrote (through the protocol's validating readers) and score it."""
    flags = [] if exit_.isolated else ["sandbox=limited"]
    cell_errors = [f"code cell {c.cell}: {c.status}: {c.error.type[:80]}: {c.error.message[:200]}"
                   for c in job.read_cells() or () if c.status in ("error", "timeout") and c.error]
    ended = "the grader stopped your notebook at its time limit" if exit_.timed_out else \
        "your notebook ended the grading process early"
    scores, compute, called_reference = [], 0.0, False
    for k, (ex, cases, expected) in enumerate(zip(prepared.exercises, prepared.cases, prepared.expected)):
        try:
            report = job.read_exercise(k, len(cases))
        except TransportError as exc:
            report, why = None, f"its results were unusable ({exc})"
        else:
            why = ended
        if report is None:
            scores.append(ExerciseScore.zero(ex, len(cases), f"not graded: {why}"))
        elif not report.defined:
            scores.append(ExerciseScore.zero(ex, len(cases), f"function not defined: no function named "
                                                             f"{ex.function!r} in the notebook"))
        else:
            compute += report.seconds
            score, cheated = _score_exercise(ex, cases, expected, report.results)
            scores.append(score)
            called_reference |= cheated
    if called_reference or job.read_reference_calls():
        flags.append("called-reference")
    done = job.read_done()
    log = ""
    if exit_.timed_out:
        flags.append("timeout")
    elif done is None:
        flags.append("worker-ended-early")
        # the last lines the worker process wrote outside Python's captured output (a crash, an
        # import error) say why; shown to the instructor in the feedback
        log = "\n".join(exit_.log.strip().splitlines()[-12:])[-1500:]
        if exit_.returncode is not None and exit_.returncode < 0:
            log = f"(worker killed by signal {-exit_.returncode})\n" + log
    return SubmissionResult(student, path, scores, flags, seconds=time.perf_counter() - start,
                            compute_seconds=done.compute_seconds if done else compute,
                            cell_errors=cell_errors, worker_log=log)


def grade_batch(paths: Sequence[str | Path], assignment: str, seed: str, *, jobs: int = 1,
                limits: Limits = Limits(), hide: Sequence[Path] = (), log=print) -> list[SubmissionResult]:
    """Grade many submissions, ``jobs`` at a time; the batch always completes.

    The seed is concealed from other processes first (:func:`~robokit.grading.sandbox.conceal_secret`);
    one kit serves the whole batch.

    Raises
    ------
    GradingError
        Only for problems with the request (unknown assignment, missing seed, no submissions) or
        with the course (a helper that would bring a reference into the worker).
    """
    if isinstance(seed, str) and seed:
        conceal_secret(seed)
    try:
        prepared = prepare_cases(assignment, seed)
    except UnknownAssignmentError as exc:
        raise GradingError(str(exc)) from None
    if not paths:
        raise GradingError("submissions: expected at least one notebook")
    work_root = Path(tempfile.mkdtemp(prefix="robokit-grade-"))
    work_root.chmod(0o711)

    def one(path):
        result = grade_submission(path, assignment, prepared, limits=limits, kit=kit, hide=hide,
                                  work_root=work_root)
        log(f"  {result.student:<24} {result.total:6.2f} / {result.max_total:<6.2f} "
            f"{result.seconds:5.1f}s  {' '.join(result.flags)}")
        return result

    try:
        try:
            kit = build_kit(get_assignment(assignment), work_root / "kit")
        except KitError as exc:
            raise GradingError(str(exc)) from None
        with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            return list(pool.map(one, [Path(p) for p in paths]))
    finally:
        shutil.rmtree(work_root, ignore_errors=True)


def isolation_note() -> str:
    """One line saying how strongly this run can isolate student code."""
    if is_root():
        return "full isolation (namespaces, private uid, only the interpreter and packages visible, no network)"
    return "limited isolation (not root: resource limits and timeouts only)"
