"""The ``robokit`` command: build the course, keep notebooks clean (and, as they land, grade)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import __version__

__all__ = ["main", "build_parser"]


def _cmd_course_build(args: argparse.Namespace) -> int:
    from .course.build import build_course

    root = Path(args.root)
    if not (root / "lessons").is_dir() and not args.notebooks:
        print(f"robokit course build: no lessons/ directory under {root.resolve()} "
              "(run it from the course repository or pass --root)", file=sys.stderr)
        return 2
    return build_course(root, args.out, jobs=args.jobs, timeout=args.timeout, fast=args.fast,
                        notebooks=[Path(p) for p in args.notebooks] or None)


def _cmd_course_strip(args: argparse.Namespace) -> int:
    from .course.hygiene import strip_file

    for p in args.paths:
        if strip_file(p):
            print(f"stripped {p}")
    return 0


def _cmd_course_check(args: argparse.Namespace) -> int:
    from .course.build import ALL_DIRS, discover
    from .course.hygiene import notebook_problems

    paths = [Path(p) for p in args.paths] or discover(args.root, ALL_DIRS)
    problems = [msg for p in paths for msg in notebook_problems(p)]
    for msg in problems:
        print(msg)
    print(f"{len(paths)} notebooks checked, {len(problems)} problems")
    return 1 if problems else 0


def build_parser() -> argparse.ArgumentParser:
    """Return the argument parser of the ``robokit`` command."""
    parser = argparse.ArgumentParser(
        prog="robokit",
        description="robokit courseware: build the course site, keep notebooks clean, grade.",
    )
    parser.add_argument("--version", action="version", version=f"robokit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    course = sub.add_parser("course", help="build the course site, strip and check notebooks")
    csub = course.add_subparsers(dest="course_command", metavar="ACTION")
    build = csub.add_parser("build", help="execute lessons/ and solutions/ and write build/course/")
    build.add_argument("notebooks", nargs="*", help="only these notebooks (default: all)")
    build.add_argument("--root", default=".", help="course repository root (default: .)")
    build.add_argument("--out", default="build/course", help="site directory (default: build/course)")
    build.add_argument("--jobs", type=int, default=None, help="notebooks run at once (default: cores)")
    build.add_argument("--timeout", type=float, default=900, help="per-notebook limit in s (default: 900)")
    build.add_argument("--fast", action="store_true", help="run with ROBOKIT_FAST=1 (shrunk experiments)")
    build.set_defaults(func=_cmd_course_build)
    strip = csub.add_parser("strip", help="remove outputs and execution counts from notebooks")
    strip.add_argument("paths", nargs="+")
    strip.set_defaults(func=_cmd_course_strip)
    check = csub.add_parser("check", help="report notebooks with outputs or without a kernelspec")
    check.add_argument("paths", nargs="*")
    check.add_argument("--root", default=".")
    check.set_defaults(func=_cmd_course_check)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``robokit`` console script; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    func = getattr(args, "func", None)
    if func is None:
        target = {"course": "course"}.get(args.command)
        parser.parse_args([target, "--help"] if target else ["--help"])
        return 2
    try:
        return int(func(args) or 0)
    except (ValueError, TypeError, FileNotFoundError, PermissionError) as exc:
        print(f"robokit {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
