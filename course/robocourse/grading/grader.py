"""``robocourse grade``: grade a folder of notebooks safely.

The trusted parent (this module) reads each submission (:mod:`~robocourse.grading.submission`),
generates the input cases from the instructor's secret seed, computes the expected answers, and
starts one sandboxed worker per submission (:mod:`~robocourse.grading.sandbox`,
:mod:`~robocourse.grading.worker`) that receives only the code cells and the inputs. The worker runs
from a kit (:mod:`~robocourse.grading.kit`): its own modules and the assignment's data, no robokit; as
root it sees nothing else of the disk but the interpreter and the installed packages' code
(:mod:`~robocourse.grading.filesystem_view`). The worker's replies are plain data that
:mod:`~robocourse.grading.protocol` bounds and validates before anything here judges them; student
objects never reach the parent.

Nothing the worker or the submission gives is trusted: a file that cannot be read is a rejection
with its flag (:mod:`~robocourse.grading.submission`); worker output that is unusable costs only the
part it concerns and flags ``unusable-results``; reading and judging it run in a child process
under a memory and time budget (:mod:`~robocourse.grading.budget`), whose breach costs that
submission alone (``unusable-results`` too); any other failure on one submission is that
submission's ``grader-error``. The batch always completes, and names every student once.
"""
from __future__ import annotations

import collections
import dataclasses
import functools
import hashlib
import json
import shutil
import tempfile
import threading
import time
import traceback
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Callable, Sequence

from robocourse.lessons import UnknownAssignmentError, get_assignment
from robocourse.exercises.spec import PUBLIC_SEED, Case, Exercise
from robocourse.exercises.trivial import data_values, explained, trivial_passes
from robocourse.grading.data import assignment_data, data_file
from robocourse.grading.filesystem_view import View, installed_package_dirs, runtime_paths
from robocourse.grading.job_cgroup import cgroup_note
from robocourse.grading.judge import expected_output, judge
from robocourse.grading.kit import WORKER, Kit, KitError, build_kit
from robocourse.grading.barrier import RobokitWithheld
from robocourse.grading.budget import BudgetExceeded, run_within
from robocourse.grading.protocol import CallResult, CellRecord, DoneReport, JobDir, JobSpec
from robocourse.grading.safetext import clean
from robocourse.grading.sandbox import Limits, WorkerExit, conceal_secret, is_root, job_space, run_sandboxed
from robocourse.grading.syscall_filter import probe as probe_filter
from robocourse.grading.submission import Submission, SubmissionRejected, feedback_stem, read_submission, student_name
from robocourse.grading.transport import TransportError

__all__ = ["SubmissionResult", "ExerciseScore", "PreparedCases", "BatchSeed", "prepare_cases", "draw_cases", "cases_seed",
           "job_spec", "score_exercise", "worker_view", "grade_submission", "grade_batch", "GradingError",
           "isolation_note", "unique_students", "needs_review"]


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
    """Everything the gradebook and the feedback need about one submission.

    ``reason`` is set when the file was not graded (a rejection, a grader error); ``notes`` are
    remarks for the instructor (e.g. a duplicate student name); ``problems`` say which of the
    worker's files were unusable. Strings that come from the student (names, messages, the log)
    are raw here: the reports escape them.
    """

    student: str
    path: Path
    scores: list[ExerciseScore]
    flags: list[str]
    reason: str = ""
    seconds: float = 0.0
    compute_seconds: float = 0.0
    cell_errors: list[str] = dataclasses.field(default_factory=list)
    worker_log: str = ""
    notes: list[str] = dataclasses.field(default_factory=list)
    problems: list[str] = dataclasses.field(default_factory=list)

    @property
    def graded(self) -> bool:
        """Whether the file was graded (``robocourse grade`` exits 1 otherwise)."""
        return not self.reason

    @property
    def total(self) -> float:
        return round(sum(s.points for s in self.scores), 4)

    @property
    def max_total(self) -> float:
        return round(sum(s.max_points for s in self.scores), 4)


@dataclasses.dataclass
class PreparedCases:
    """The trusted side of a grading run: exercises, their cases for the secret seed, the expected
    answers and, per case, the trivial answers that pass it (:mod:`~robocourse.exercises.trivial`).
    It stays in the grader's process; workers receive only the case inputs."""

    exercises: tuple[Exercise, ...]
    cases: list[list[Case]]
    expected: list[list[Any]]
    trivial: list[list[frozenset[str]]]
    assignment: str = ""
    seed: str = dataclasses.field(default="", repr=False)

    def for_submission(self, submission: Submission) -> PreparedCases:
        """The cases one submission is graded on: drawn from the secret seed and a hash of the
        submission's code cells (:func:`cases_seed`)."""
        return prepare_cases(self.assignment, cases_seed(self.seed, submission))

    def zero(self, message: str) -> list[ExerciseScore]:
        """Every exercise at zero on these cases, with one message."""
        return [ExerciseScore.zero(ex, len(cs), message) for ex, cs in zip(self.exercises, self.cases)]


class BatchSeed:
    """A batch's assignment and secret seed, before any draw: each submission's cases are drawn from
    it and the submission (:meth:`for_submission`). The seed's own draw is made only if a file is
    rejected or the grader fails on it, to name the cases it scores zero on (:meth:`zero`), and then
    once for the batch: preparing an assignment's cases takes up to 2.8 s, and every graded file
    draws its own."""

    def __init__(self, assignment: str, seed: str):
        self.assignment, self.seed = assignment, seed
        self._drawn: PreparedCases | None = None
        self._lock = threading.Lock()

    def __repr__(self) -> str:
        return f"BatchSeed(assignment={self.assignment!r})"     # never the seed

    def for_submission(self, submission: Submission) -> PreparedCases:
        """As :meth:`PreparedCases.for_submission`."""
        return prepare_cases(self.assignment, cases_seed(self.seed, submission))

    def zero(self, message: str) -> list[ExerciseScore]:
        """Every exercise at zero on the seed's own cases (drawn on first use), with one message."""
        with self._lock:            # the batch's threads share one draw
            if self._drawn is None:
                self._drawn = prepare_cases(self.assignment, self.seed)
        return self._drawn.zero(message)


def cases_seed(seed: str, submission: Submission) -> str:
    """The seed of one submission's hidden cases: the secret ``seed`` and a SHA-256 of its code
    cells and skip flags.

    Feedback shows a case's input when the student's code raised on it (their own message may
    even print it). With one set of cases per seed, a student could collect those inputs, compute
    the answers at home with robokit's public functions and submit a lookup table. Any change to
    the code draws new cases, so what one submission learns is worthless to the next; the same
    file still regrades identically under the same seed.
    """
    code = json.dumps([list(submission.sources), list(submission.skip)]).encode()
    return f"{seed}\x00{hashlib.sha256(code).hexdigest()}"


@functools.lru_cache(maxsize=None)
def _public(ex: Exercise) -> tuple[tuple[Case, Any], ...]:
    """An exercise's valid public cases and their answers (``check()`` shows them to the student)."""
    return tuple((c, expected_output(ex, c)) for c in ex.make_cases(PUBLIC_SEED) if not c.raises)


#: How many further draws :func:`prepare_cases` tries when a draw's cases would let a trivial
#: answer pass every valid case (so that a right function could not show its work).
REDRAWS = 20


def draw_cases(ex: Exercise, seed: str, data: Sequence[Any] = ()) -> tuple[list[Case], list[Any], list[frozenset[str]]]:
    """One exercise's cases, answers and trivial passes for ``seed``: the first draw in which a
    right function's passes show work (:func:`~robocourse.exercises.trivial.explained`), trying
    ``seed`` and then up to :data:`REDRAWS` seeds derived from it. ``data``: the values of the
    assignment's data (:func:`~robocourse.exercises.trivial.data_values`), trivial answers too.

    Raises
    ------
    GradingError
        If no draw shows work (a course error: the exercise's cases must be changed).
    """
    for k in range(REDRAWS + 1):
        cases = ex.make_cases(seed if k == 0 else f"{seed}\x00redraw {k}")
        expected = [expected_output(ex, c) for c in cases]
        trivial = trivial_passes(ex, cases, expected, _public(ex), data)
        valid = [i for i, c in enumerate(cases) if not c.raises]
        if explained(valid, valid, trivial) is None:
            return cases, expected, trivial
    raise GradingError(f"{ex.id}: in {REDRAWS + 1} draws of its cases, trivial answers pass every valid case; "
                       "the exercise needs cases that show work")


def prepare_cases(assignment: str, seed: str) -> PreparedCases:
    """Generate every exercise's cases from ``seed``, compute the expected answers and which
    trivial answers pass each case (trusted).

    A draw in which trivial answers would pass every valid case (a right function could not be
    told from them) is drawn again from a derived seed, deterministically.

    Raises
    ------
    GradingError
        For a missing seed, or an exercise whose cases never show work (a course error).
    """
    _require_seed(seed)
    exercises = get_assignment(assignment).exercises
    data = data_values(assignment_data(assignment)) if data_file(assignment).is_file() else []
    cases, expected, trivial = zip(*(draw_cases(ex, seed, data) for ex in exercises))
    return PreparedCases(exercises, list(cases), list(expected), list(trivial), assignment, seed)


def _require_seed(seed: Any) -> str:
    if not isinstance(seed, str) or not seed:
        raise GradingError("seed: a non-empty secret seed is required (--seed or ROBOKIT_GRADING_SEED)")
    return seed


def job_spec(submission: Submission, prepared: PreparedCases, limits: Limits) -> JobSpec:
    """The worker's request: cells, limits, and the case inputs only (never the seed, the
    expected answers, what a case expects or its label)."""
    return JobSpec(submission.sources, submission.skip, limits.cell_seconds, limits.call_seconds,
                   tuple((ex.function, tuple((c.args, c.kwargs) for c in cs))
                         for ex, cs in zip(prepared.exercises, prepared.cases)))


def worker_view(kit: Kit, hide: Sequence[Path] = ()) -> View:
    """What a worker's filesystem shows as root: the interpreter and the installed packages' code,
    the kit (also in place of every installed robocourse), no installed robokit, and nothing of
    ``hide``."""
    paths = runtime_paths()
    course = installed_package_dirs(paths, "robocourse")
    library = installed_package_dirs(paths, "robokit")
    return View((*paths, str(kit.root)), tuple((d, str(kit.package)) for d in course),
                (*library, *(str(Path(h).resolve()) for h in hide)))


def grade_submission(path: str | Path, assignment: str, prepared: PreparedCases | BatchSeed, *,
                     limits: Limits = Limits(), kit: Kit | None = None, hide: Sequence[Path] = (),
                     work_root: Path | None = None) -> SubmissionResult:
    """Grade one notebook in a sandboxed worker; never raises for a bad submission.

    A file that cannot be graded scores zero with the rejection's flag and reason. ``kit`` is the
    worker's code (:func:`~robocourse.grading.kit.build_kit`; written into the job if not given).
    What the worker wrote is read and judged within ``limits``' judging budget
    (:func:`~robocourse.grading.budget.run_within`); a breach scores this file zero, flagged
    ``unusable-results``.

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
        return SubmissionResult(student, path, prepared.zero(str(exc)), [exc.flag], str(exc))
    prepared = prepared.for_submission(submission)
    job = JobDir.create(work_root)
    try:
        job.write_spec(job_spec(submission, prepared, limits))
        kit = kit or build_kit(get_assignment(assignment), job.root / "kit")
        with job_space(job, limits):
            exit_ = run_sandboxed(["-m", WORKER, str(job.root)], job.root, limits, view=worker_view(kit, hide),
                                  env_extra={"PYTHONPATH": str(kit.root), "PYTHONSAFEPATH": "1"})
            try:
                return run_within(lambda: _score(job, student, path, prepared, exit_, start),
                                  memory_bytes=limits.judge_memory_bytes, seconds=limits.judge_seconds)
            except BudgetExceeded as exc:
                flags = ([] if exit_.isolated else ["sandbox=limited"]) + ["unusable-results"] + \
                    (["timeout"] if exit_.timed_out else [])
                return SubmissionResult(student, path, prepared.zero(f"not graded: {exc}"), flags,
                                        seconds=time.perf_counter() - start, problems=[str(exc)])
    finally:
        shutil.rmtree(job.root, ignore_errors=True)


def score_exercise(ex: Exercise, cases: list[Case], expected: list[Any], trivial: list[frozenset[str]],
                    results: Sequence[CallResult]) -> tuple[ExerciseScore, bool]:
    """Judge one exercise's results (one per case); return its score and whether it tried to
    import robokit.

    The cases count only once the passes show work (:func:`~robocourse.exercises.trivial.explained`):
    a constant, the public answers looked up, an argument returned unchanged or a known shortcut
    earns nothing, and a function that always raises earns no bad-input marks.
    """
    messages, cheated = [], False
    passed_valid, errors_passed = [], 0
    for i, (case, exp, res) in enumerate(zip(cases, expected, results), 1):
        cheated |= res.error is not None and res.error.type == RobokitWithheld.__name__
        outcome = judge(ex, case, exp, res)
        if case.raises:
            errors_passed += outcome.passed
        elif outcome.passed:
            passed_valid.append(i - 1)
        if not outcome.passed and len(messages) < 10:     # the first five failures, each with its input
            messages.append(f"case {i}" + (f" ({case.label})" if case.label else "") + f": {outcome.message}")
            messages.append(f"  input: {case.call_text(ex.function)}")
    passed = len(passed_valid) + errors_passed
    why = explained(passed_valid, [i for i, c in enumerate(cases) if not c.raises], trivial)
    if passed and why == "nothing passed":
        passed = 0
        messages.insert(0, "bad-input cases count once the function returns a right result for a valid input")
    elif passed and why:
        passed = 0
        messages.insert(0, f"the valid cases passed are also passed by trivial answers ({why}): the cases count "
                           "once the passes show work (a case no trivial answer passes, or cases no one trivial "
                           "answer passes all of)")
    if cheated:
        passed = 0
        messages.insert(0, "your code tried to import robokit, the course's library, which graded code may not use")
    points = round(float(ex.points) * passed / len(cases), 4)
    return ExerciseScore(ex.id, points, float(ex.points), passed, len(cases), messages), cheated


_UNUSABLE = object()  # what _Reading.get returns for a file that was written but is unusable


class _Reading:
    """Reads the worker's files through the protocol, noting each one that is unusable."""

    def __init__(self, job: JobDir):
        self.job, self.problems = job, []

    def get(self, what: str, read: Callable[[], Any]) -> Any:
        """``read()``, or ``_UNUSABLE`` (with a problem noted) if it raises a TransportError."""
        try:
            return read()
        except TransportError as exc:
            self.problems.append(f"{what}: {exc}")
            return _UNUSABLE


def _score_exercises(reading: _Reading, prepared: PreparedCases, ended: str) -> tuple[list[ExerciseScore], float, bool]:
    """Every exercise's score from its report; return the scores, the seconds of the calls, and
    whether a call tried to import robokit."""
    scores, compute, imported_robokit = [], 0.0, False
    for k, (ex, cases, expected, trivial) in enumerate(zip(prepared.exercises, prepared.cases, prepared.expected,
                                                           prepared.trivial)):
        report = reading.get(f"the results of {ex.id}", lambda: reading.job.read_exercise(k, len(cases)))
        if report is _UNUSABLE:
            scores.append(ExerciseScore.zero(ex, len(cases), f"not graded: its results were unusable "
                                                             f"({reading.problems[-1]})"))
        elif report is None:
            scores.append(ExerciseScore.zero(ex, len(cases), f"not graded: {ended}"))
        elif not report.defined:
            scores.append(ExerciseScore.zero(ex, len(cases), f"function not defined: no function named "
                                                             f"{ex.function!r} in the notebook"))
        else:
            compute += report.seconds
            score, cheated = score_exercise(ex, cases, expected, trivial, report.results)
            scores.append(score)
            imported_robokit |= cheated
    return scores, compute, imported_robokit


def _cell_errors(cells: Sequence[CellRecord]) -> list[str]:
    return [f"code cell {c.cell}: {c.status}: {c.error.type[:80]}: {c.error.message[:200]}"
            for c in cells if c.status in ("error", "timeout") and c.error]


def _score(job: JobDir, student: str, path: Path, prepared: PreparedCases, exit_: WorkerExit,
           start: float) -> SubmissionResult:
    """Read what the worker wrote (through the protocol's validating readers) and score it.

    A file that is unusable costs what it holds: an exercise's report that exercise; the log of
    withheld imports every exercise (the grader can no longer tell whether robokit was imported).
    """
    flags = [] if exit_.isolated else ["sandbox=limited"]
    reading = _Reading(job)
    cells = reading.get("the record of your cells", job.read_cells)
    ended = "the grader stopped your notebook at its time limit" if exit_.timed_out else \
        "your notebook ended the grading process early"
    scores, compute, imported_robokit = _score_exercises(reading, prepared, ended)
    calls = reading.get("the log of withheld imports", job.read_withheld_imports)
    if calls is _UNUSABLE:
        scores = prepared.zero("not graded: the grading process's log of withheld imports was unusable")
    elif calls:
        imported_robokit = True
    if imported_robokit:
        flags.append("imported-robokit")
    done = reading.get("the final report", job.read_done)
    if reading.problems:
        flags.append("unusable-results")
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
                            compute_seconds=done.compute_seconds if isinstance(done, DoneReport) else compute,
                            cell_errors=_cell_errors(cells if isinstance(cells, tuple) else ()), worker_log=log,
                            problems=reading.problems)


def unique_students(paths: Sequence[Path], assignment: str) -> list[tuple[str, str]]:
    """Each path's student name, and a note: names that would share a feedback file (same
    :func:`~.submission.feedback_stem`, ignoring case) are all numbered ``name#1``, ``name#2``, ...
    in the order given, none keeping the bare name, with a note that lists the files.

    Examples
    --------
    >>> unique_students([Path("alice.ipynb"), Path("alice/00_x.ipynb"), Path("bob.ipynb")], "00_x")[1]
    ('alice#2', "2 files map to student 'alice': alice.ipynb, alice/00_x.ipynb")
    """
    # the name as the gradebook and the terminal show it (invisible characters dropped), so that
    # 'bob' and 'bob' + a zero-width space are one name, numbered, not two rows that read 'bob'
    names = [clean(student_name(p, assignment), 200) or 'student' for p in paths]
    groups = collections.defaultdict(list)
    for i, name in enumerate(names):
        groups[feedback_stem(name).casefold()].append(i)
    taken = set(groups)
    out = [(name, "") for name in names]
    for members in (m for m in groups.values() if len(m) > 1):
        note = (f"{len(members)} files map to student {names[members[0]]!r}: "
                + ", ".join(str(paths[i]) for i in members))
        n = 0
        for i in members:
            n += 1
            while feedback_stem(_numbered(names[i], n)).casefold() in taken:
                n += 1
            name = _numbered(names[i], n)
            taken.add(feedback_stem(name).casefold())
            out[i] = (name, note)
    return out


def _numbered(name: str, n: int) -> str:
    """``name#n``, shortened when the number would fall past the feedback file name's length bound."""
    numbered = f"{name}#{n}"
    return numbered if feedback_stem(numbered).endswith(f"_{n}") else f"{feedback_stem(name)[:80]}#{n}"


def _grader_failed(path: Path, student: str, prepared: PreparedCases | BatchSeed, exc: Exception) -> SubmissionResult:
    """The result of a submission on which the grader itself failed (a bug, a broken environment)."""
    what = "".join(traceback.format_exception_only(type(exc), exc)).strip()[-300:]
    return SubmissionResult(student, path, prepared.zero("not graded: the grader failed on this file"),
                            ["grader-error"], f"the grader failed on this file ({what})")


def needs_review(results: Sequence[SubmissionResult]) -> list[str]:
    """One line per submission that makes ``robocourse grade`` exit 1: not graded, or a duplicate name."""
    return [f"{r.path}: " + "; ".join(filter(None, [r.reason, *r.notes]))
            for r in results if not r.graded or "duplicate-name" in r.flags]


def grade_batch(paths: Sequence[str | Path], assignment: str, seed: str, *, jobs: int = 1,
                limits: Limits = Limits(), hide: Sequence[Path] = (), log=print) -> list[SubmissionResult]:
    """Grade many submissions, ``jobs`` at a time; the batch always completes.

    The seed is concealed from other processes first (:func:`~robocourse.grading.sandbox.conceal_secret`);
    one kit serves the whole batch.

    Raises
    ------
    GradingError
        Only for problems with the request (unknown assignment, missing seed, no submissions), with
        the course (a worker module that would bring library code into the worker) or with the host
        (it refuses the worker's seccomp filter).
    """
    conceal_secret(_require_seed(seed))
    try:
        get_assignment(assignment)
    except UnknownAssignmentError as exc:
        raise GradingError(str(exc)) from None
    prepared = BatchSeed(assignment, seed)      # each file draws its own cases from it
    if not paths:
        raise GradingError("submissions: expected at least one notebook")
    refused = probe_filter()
    if refused:
        raise GradingError(f"this host refuses the worker's no_new_privs or seccomp filter ({refused}); grade on a "
                           "Linux host or container that allows them")
    paths = [Path(p) for p in paths]
    names = unique_students(paths, assignment)
    work_root = Path(tempfile.mkdtemp(prefix="robocourse-grade-"))
    work_root.chmod(0o711)

    def one(path: Path, name: tuple[str, str]) -> SubmissionResult:
        try:
            result = grade_submission(path, assignment, prepared, limits=limits, kit=kit, hide=hide,
                                      work_root=work_root)
        except Exception as exc:  # one submission's failure, whatever it is, must not cost the batch (its
            # draw of cases may fail alone: the draw's seed hashes its code; the zero scores below draw
            # the batch seed's cases, and a course error that fails that draw too stops the batch)
            result = _grader_failed(path, name[0], prepared, exc)
        result.student = name[0]
        if name[1]:
            result.flags.append("duplicate-name")
            result.notes.append(name[1])
        log(f"  {clean(result.student, 40):<24} {result.total:6.2f} / {result.max_total:<6.2f} "
            f"{result.seconds:5.1f}s  {' '.join(result.flags)}")
        return result

    try:
        try:
            kit = build_kit(get_assignment(assignment), work_root / "kit")
        except KitError as exc:
            raise GradingError(str(exc)) from None
        with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            return list(pool.map(one, paths, names))
    finally:
        shutil.rmtree(work_root, ignore_errors=True)


def isolation_note() -> str:
    """One line saying how strongly this run can isolate student code."""
    if is_root():
        return ("full isolation (namespaces, private uid, only the interpreter and packages visible, no network; "
                f"{cgroup_note()})")
    return "limited isolation (not root: resource limits and timeouts only)"
