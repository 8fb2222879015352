"""The ``robocourse`` command: build the course, keep notebooks clean, generate assignments, grade, hand out."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from robocourse import __version__

__all__ = ["main", "build_parser"]


def _cmd_build(args: argparse.Namespace) -> int:
    from robocourse.site.build import build_course

    root = Path(args.root)
    if not (root / "lessons").is_dir() and not args.notebooks:
        print(f"robocourse build: no lessons/ directory under {root.resolve()} "
              "(run it from the course repository or pass --root)", file=sys.stderr)
        return 2
    from robocourse.grading.selfcheck import course_grading_step

    steps = [] if args.no_grading else [course_grading_step]
    return build_course(root, args.out, instructor_out=args.instructor_out, jobs=args.jobs, timeout=args.timeout,
                        fast=args.fast, notebooks=[Path(p) for p in args.notebooks] or None, extra_steps=steps,
                        api_reference=not args.no_api_reference)


def _cmd_strip(args: argparse.Namespace) -> int:
    from robocourse.site.hygiene import strip_file

    for p in args.paths:
        if strip_file(p):
            print(f"stripped {p}")
    return 0


def _cmd_lint(args: argparse.Namespace) -> int:
    from robocourse.site.build import ALL_DIRS, discover
    from robocourse.site.hygiene import notebook_problems

    paths = [Path(p) for p in args.paths] or discover(args.root, ALL_DIRS)
    problems = [msg for p in paths for msg in notebook_problems(p)]
    for msg in problems:
        print(msg)
    print(f"{len(paths)} notebooks checked, {len(problems)} problems")
    return 1 if problems else 0


def _cmd_assign(args: argparse.Namespace) -> int:
    from robocourse.grading.assign import AssignmentError, write_assignment
    from robocourse.lessons import assignments

    root = Path(args.root)
    slugs = args.slugs or sorted(p.stem for p in (root / "solutions").glob("*.ipynb"))
    known = assignments()
    status = 0
    for slug in slugs:
        if slug not in known:
            print(f"robocourse assign: solutions/{slug}.ipynb has no lesson whose exercises module declares "
                  f"ASSIGNMENT = {slug!r} (robocourse/lessons/<name>/exercises.py)", file=sys.stderr)
            status = 1
            continue
        try:
            changed = write_assignment(root, slug, verify=args.verify)
        except AssignmentError as exc:
            print(f"robocourse assign: {exc}", file=sys.stderr)
            status = 1
            continue
        if args.verify and changed:
            print(f"assignments/{slug}.ipynb or its data is out of date: run `robocourse assign {slug}`")
            status = 1
        elif changed:
            print(f"wrote assignments/{slug}.ipynb (and its data file, if it has one)")
        else:
            print(f"assignments/{slug}.ipynb is up to date")
    return status


def _cmd_grade(args: argparse.Namespace) -> int:
    import os

    from robocourse.grading.grader import GradingError, grade_batch, isolation_note, needs_review
    from robocourse.grading.reports import write_feedback, write_gradebook, write_gradescope
    from robocourse.grading.rubrics import write_grading_guide
    from robocourse.grading.safetext import clean
    from robocourse.grading.sandbox import Limits

    seed = args.seed or os.environ.get("ROBOKIT_GRADING_SEED", "")
    if not seed:
        print("robocourse grade: error: a secret seed is required: --seed SECRET (or set "
              "ROBOKIT_GRADING_SEED); keep it private so students cannot predict the cases", file=sys.stderr)
        return 2
    if args.gradescope and len(args.submissions) != 1:
        print("robocourse grade: error: --gradescope writes one results.json, so give exactly one submission",
              file=sys.stderr)
        return 2
    limits = Limits(wall_seconds=args.timeout, cpu_seconds=int(args.timeout),
                    memory_bytes=int(args.memory_mb) * 1024 * 1024)
    root = Path(args.root).resolve()
    guide = Path(args.guide) if args.guide else Path(args.out).with_name(f"{Path(args.out).stem}-guide.md")
    hide = [p for p in (root / "solutions", Path(args.out).resolve().parent, guide.resolve().parent,
                        Path(args.feedback).resolve() if args.feedback else None, Path.home(),
                        *[Path(h).resolve() for h in args.hide]) if p]
    print(f"grading {len(args.submissions)} submission(s) of {args.assignment} with {args.jobs} job(s); "
          f"{isolation_note()}")
    try:
        results = grade_batch(args.submissions, args.assignment, seed, jobs=args.jobs, limits=limits, hide=hide)
    except GradingError as exc:
        print(f"robocourse grade: error: {exc}", file=sys.stderr)
        return 2
    write_gradebook(results, args.out)
    print(f"gradebook: {args.out}")
    guide, complete = write_grading_guide(args.assignment, root, guide)
    print(f"grading guide for TAs (model answers and rubrics: keep it private): {guide}")
    if not complete:
        print(f"robocourse grade: no solutions/{args.assignment}.ipynb under {root}: the grading guide has no "
              "model answers or rubrics (pass --root)", file=sys.stderr)
    if args.feedback:
        write_feedback(results, args.feedback, args.assignment)
        print(f"feedback: {args.feedback}/")
    if args.gradescope:
        write_gradescope(results[0], args.assignment, args.gradescope)
        print(f"gradescope results: {args.gradescope}")
    problems = needs_review(results)  # files not graded, duplicate student names
    for line in problems:
        print(f"robocourse grade: {clean(line, 1000)}", file=sys.stderr)
    return 1 if problems else 0


def _cmd_gradescope(args: argparse.Namespace) -> int:
    import os

    from robocourse.lessons import UnknownAssignmentError
    from robocourse.grading.gradescope import build_autograder

    seed = args.seed or os.environ.get("ROBOKIT_GRADING_SEED", "")
    try:
        path = build_autograder(args.assignment, seed, args.output, root=args.root, timeout=args.timeout)
    except (UnknownAssignmentError, RuntimeError) as exc:
        print(f"robocourse gradescope: error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {path} (upload it as the autograder of {args.assignment}; it contains the seed: keep it private)")
    return 0


def _cmd_student_kit(args: argparse.Namespace) -> int:
    from robocourse.grading.handout import write_handout

    path, count = write_handout(args.root, args.output)
    print(f"wrote {path} ({count} files: lessons, assignments, robokit, the course package; no solutions)")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser of the ``robocourse`` command."""
    parser = argparse.ArgumentParser(
        prog="robocourse",
        description="robokit courseware: build the course sites, keep notebooks clean, generate assignments, grade.",
    )
    parser.add_argument("--version", action="version", version=f"robocourse {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    build = sub.add_parser("build", help="execute lessons/ and solutions/, write the student site "
                                         "build/course/ and the instructor site build/instructor/")
    build.add_argument("notebooks", nargs="*", help="only these notebooks (default: all)")
    build.add_argument("--root", default=".", help="course repository root (default: .)")
    build.add_argument("--out", default="build/course",
                       help="student site folder, to publish (default: build/course under --root)")
    build.add_argument("--instructor-out", default="build/instructor",
                       help="instructor site folder, with the solutions: keep it private (default: build/instructor)")
    build.add_argument("--jobs", type=int, default=None, help="notebooks run at once (default: cores)")
    build.add_argument("--timeout", type=float, default=900, help="per-notebook limit in s (default: 900)")
    build.add_argument("--fast", action="store_true", help="run with ROBOKIT_FAST=1 (shrunk experiments)")
    build.add_argument("--no-api-reference", action="store_true",
                       help="leave the library reference out of the sites (a quicker preview build)")
    build.add_argument("--no-grading", action="store_true",
                       help="skip grading solutions (full marks) and blank assignments (zero)")
    build.set_defaults(func=_cmd_build)
    strip = sub.add_parser("strip", help="remove outputs and execution counts from notebooks")
    strip.add_argument("paths", nargs="+")
    strip.set_defaults(func=_cmd_strip)
    lint = sub.add_parser("lint", help="report notebooks with outputs or without a kernelspec")
    lint.add_argument("paths", nargs="*")
    lint.add_argument("--root", default=".")
    lint.set_defaults(func=_cmd_lint)

    assign = sub.add_parser("assign", help="generate assignments/ (and their data) from solutions/ (deterministic)")
    assign.add_argument("slugs", nargs="*", help="e.g. 05_gps_sonar_truck (default: every solution)")
    assign.add_argument("--root", default=".", help="course repository root (default: .)")
    assign.add_argument("--verify", action="store_true", help="only report assignments that are out of date")
    assign.set_defaults(func=_cmd_assign)

    grade = sub.add_parser("grade", help="grade submitted notebooks in sandboxed workers")
    grade.add_argument("submissions", nargs="+", help="submitted .ipynb files")
    grade.add_argument("--assignment", required=True, help="e.g. 01_visual_slam")
    grade.add_argument("--seed", help="instructor's secret seed (or env ROBOKIT_GRADING_SEED)")
    grade.add_argument("--out", default="grades.csv", help="gradebook CSV (default: grades.csv)")
    grade.add_argument("--feedback", help="folder for per-student feedback (markdown)")
    grade.add_argument("--guide", help="grading guide for TAs: exercises by kind, written questions with model "
                                       "answers and rubrics (default: <gradebook>-guide.md beside the gradebook)")
    grade.add_argument("--jobs", type=int, default=1, help="submissions graded at once (default: 1)")
    grade.add_argument("--gradescope", help="also write Gradescope's results.json (one submission)")
    grade.add_argument("--timeout", type=float, default=300, help="seconds per submission (default: 300)")
    grade.add_argument("--memory-mb", type=int, default=4096, help="address-space limit (default: 4096)")
    grade.add_argument("--root", default=".", help="course root; its solutions/ is covered if a folder the worker sees holds it")
    grade.add_argument("--hide", action="append", default=[], metavar="PATH",
                       help="another path student code must not see (repeatable)")
    grade.set_defaults(func=_cmd_grade)

    gs = sub.add_parser("gradescope", help="build a Gradescope autograder zip for an assignment")
    gs.add_argument("--assignment", required=True)
    gs.add_argument("--seed", help="instructor's secret seed (or env ROBOKIT_GRADING_SEED)")
    gs.add_argument("-o", "--output", default="autograder.zip")
    gs.add_argument("--root", default=".")
    gs.add_argument("--timeout", type=float, default=600)
    gs.set_defaults(func=_cmd_gradescope)

    kit = sub.add_parser("student-kit", help="zip what students get: lessons, assignments, robokit and the "
                                             "course package, without solutions/")
    kit.add_argument("-o", "--output", default="build/robokit-student.zip", help="the zip to write "
                     "(default: build/robokit-student.zip)")
    kit.add_argument("--root", default=".", help="course repository root (default: .)")
    kit.set_defaults(func=_cmd_student_kit)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``robocourse`` console script; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    func = getattr(args, "func", None)
    if func is None:
        parser.parse_args(["--help"])
        return 2
    try:
        return int(func(args) or 0)
    except (ValueError, TypeError, FileNotFoundError, PermissionError) as exc:
        print(f"robocourse {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
