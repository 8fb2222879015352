"""Fuzz every public function a lesson uses with invalid inputs: each must give a clear error.

The functions are found as tests/test_docs.py finds them (the robokit names the lesson and solution
notebooks' code uses), plus the references of the graded exercises (students reproduce their
contracts) and the functions the fuzz of issue 12 named. tests/fuzz_specs.py holds a valid call of
each and the kind of every argument; tests/fuzz_kinds.py says what "invalid" means per kind.

One argument at a time is replaced by an invalid value. The call must raise a ``ValueError`` or
``TypeError`` whose message names that argument (DESIGN.md, "Errors"). A failure is:

* a silent result: the call returns (huge values excepted: they may return, without NaN or inf
  unless the valid call's result has them too);
* a crash: any other exception, or a ``ValueError``/``TypeError`` that does not name the argument
  (numpy's own "operands could not be broadcast", "inhomogeneous shape", ...);
* a hang: more than ``BUDGET`` seconds, or more than ``MEMORY`` bytes of new address space.

Fixed invalid values (every argument x every value of its kind) run in one test per function; a
hypothesis test (derandomized, a few examples per function) adds random variants.
"""
from __future__ import annotations

import contextlib
import dataclasses
import inspect
import math
import re
import resource
import signal
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402

from robocourse.lessons import assignments  # noqa: E402
from tests.fuzz_kinds import HUGE, File, Options  # noqa: E402
from tests.fuzz_specs import EXTRA, HUGE_ANGLES, NOT_FUZZED, SPECS, resolve  # noqa: E402
from tests.test_docs import LESSON_API  # noqa: E402

BUDGET = 5.0            # seconds per call
MEMORY = 2 << 30        # bytes of address space a call may add


def _population() -> dict[str, Any]:
    found = dict(LESSON_API)
    for exercises in assignments().values():
        for ex in exercises:
            ref = inspect.unwrap(ex.answer)
            found[f"{ref.__module__}.{ref.__qualname__}"] = ref
    for name in EXTRA:
        found[name] = resolve(name)
    return found


POPULATION = _population()
FUZZED = sorted(n for n in POPULATION if n not in NOT_FUZZED)


class Hang(BaseException):
    """The call took longer than BUDGET (a BaseException, so the function cannot swallow it)."""


def _alarm(signum, frame):
    raise Hang()


def _address_space() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[0]) * resource.getpagesize()


@contextlib.contextmanager
def _bounded():
    """Limit a call's time (SIGALRM) and new memory (RLIMIT_AS), so that a runaway call fails."""
    old_handler = signal.signal(signal.SIGALRM, _alarm)
    old_limit = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (_address_space() + MEMORY, old_limit[1]))
    signal.setitimer(signal.ITIMER_REAL, BUDGET)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        resource.setrlimit(resource.RLIMIT_AS, old_limit)
        signal.signal(signal.SIGALRM, old_handler)


def _arguments(name: str, override: dict[str, Any]) -> tuple[list, dict]:
    """The positional and keyword arguments of a call (valid values built here, outside any budget:
    a fixture such as a cached map may take a while the first time; the budget is the function's)."""
    spec = SPECS[name]
    fn = POPULATION[name]
    args, kwargs = [], {}
    params = _parameters(fn)
    for pname, kind in spec.kinds.items():
        value = override[pname] if pname in override else kind.valid()
        p = params[pname]
        if p.kind is p.VAR_POSITIONAL:
            args.append(value)
        elif p.kind is p.VAR_KEYWORD:
            kwargs.update(value or {})
        elif p.kind is p.POSITIONAL_ONLY:
            args.append(value)
        else:
            kwargs[pname] = value
    return args, kwargs


def _parameters(fn: Any) -> dict[str, inspect.Parameter]:
    return dict(inspect.signature(fn).parameters)


def _nonfinite(value: Any, depth: int = 0) -> bool:
    """Whether a result holds a NaN or an infinity (numbers, arrays, containers, records)."""
    if depth > 3:
        return False
    if isinstance(value, (float, np.floating)):
        return not math.isfinite(value)
    if isinstance(value, np.ndarray):
        return value.dtype.kind in "fc" and not np.all(np.isfinite(value))
    if isinstance(value, dict):
        return any(_nonfinite(v, depth + 1) for v in value.values())
    if isinstance(value, (list, tuple)):
        return any(_nonfinite(v, depth + 1) for v in value[:1000])
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return any(_nonfinite(getattr(value, f.name), depth + 1) for f in dataclasses.fields(value))
    return False


_BASELINE: dict[str, bool] = {}


def _baseline_nonfinite(name: str) -> bool:
    if name not in _BASELINE:
        args, kwargs = _arguments(name, {})
        with _bounded():
            _BASELINE[name] = _nonfinite(POPULATION[name](*args, **kwargs))
    return _BASELINE[name]


def _names(name: str, pname: str, value: Any) -> list[str]:
    spec = SPECS[name]
    out = [pname] + ([spec.aliases[pname]] if pname in spec.aliases else [])
    if isinstance(spec.kinds[pname], Options):
        out = list(value)
    if isinstance(spec.kinds[pname], File) and isinstance(value, str) and value:
        out.append(value)                 # a hostile file: the error may name the file instead,
        if any(c in Path(value).name for c in "-."):          # by a distinctive name ("zero" is not)
            out.append(Path(value).name)
    return out


def _missing(what: str, kind: File, exc: Exception, value: str) -> str | None:
    """A missing file (or a link to one) must get the error the reader documents, naming the file."""
    if isinstance(exc, kind.missing) and Path(value).name in str(exc):
        return None
    return f"{what}: {type(exc).__name__}, not a {kind.missing.__name__} naming the file: {str(exc)[:160]}"


def fuzz_one(name: str, pname: str, label: str, value: Any, *, huge: bool = False) -> str | None:
    """Call with one invalid argument; ``None`` when the error is clear, else what went wrong."""
    what = f"{name}({pname}={label})"
    args, kwargs = _arguments(name, {pname: value})
    try:
        with _bounded():
            result = POPULATION[name](*args, **kwargs)
    except Hang:
        return f"{what}: hang (more than {BUDGET} s)"
    except (ValueError, TypeError) as exc:
        text = str(exc)
        kind = SPECS[name].kinds[pname]
        if isinstance(kind, File) and label in File.MISSING:
            return _missing(what, kind, exc, value)
        if isinstance(kind, File) and kind.hostile(label) and not isinstance(exc, kind.error):
            return f"{what}: {type(exc).__name__}, not the reader's {kind.error.__name__}: {text[:160]}"
        if any(re.search(rf"(?<![\w.]){re.escape(n)}(?!\w)", text) for n in _names(name, pname, value)):
            return None
        return f"{what}: {type(exc).__name__} that does not name {pname!r}: {text[:160]}"
    except FileNotFoundError as exc:
        kind = SPECS[name].kinds[pname]
        if isinstance(kind, File) and label in File.MISSING:
            return _missing(what, kind, exc, value)
        return f"{what}: crash FileNotFoundError: {str(exc)[:160]}"
    except Exception as exc:   # noqa: BLE001 - any other exception is the failure being looked for
        return f"{what}: crash {type(exc).__name__}: {str(exc)[:160]}"
    if huge:
        if _nonfinite(result) and not _baseline_nonfinite(name):
            return f"{what}: returned NaN or inf silently"
        return None
    return f"{what}: returned silently ({type(result).__name__})"


def _fuzzed_kinds(name: str):
    return [(pname, kind) for pname, kind in SPECS[name].kinds.items() if kind.fuzzed]


# --- the inventory ----------------------------------------------------------------------------

def test_every_public_function_a_lesson_uses_is_fuzzed_or_excused():
    missing = sorted(n for n in POPULATION if n not in SPECS and n not in NOT_FUZZED)
    assert not missing, f"give these a valid call in tests/fuzz_specs.py (or a reason in NOT_FUZZED): {missing}"
    assert len(FUZZED) >= 90


def test_every_spec_is_fuzzed():
    """A spec whose function is in no population would never run: it must be listed (EXTRA) or go."""
    dead = sorted(n for n in SPECS if n not in POPULATION)
    assert not dead, f"add these to EXTRA in tests/fuzz_specs.py (or drop their specs): {dead}"


@pytest.mark.parametrize("name", FUZZED)
def test_the_spec_names_every_parameter(name):
    params = _parameters(POPULATION[name])
    if inspect.isclass(POPULATION[name]):
        params.pop("self", None)
    assert set(SPECS[name].kinds) == set(params), f"{name}: spec {sorted(SPECS[name].kinds)} vs signature {sorted(params)}"


@pytest.mark.parametrize("name", FUZZED)
def test_inputs_the_contract_accepts_are_documented(name):
    """An argument that accepts inf says so in its function's docstring (``inf_ok`` in the spec)."""
    doc = inspect.getdoc(POPULATION[name]) or ""
    for pname, kind in SPECS[name].kinds.items():
        if getattr(kind, "inf_ok", False):
            assert re.search(r"\binf(inity)?\b", doc), f"{name}: {pname} accepts inf; its docstring must say so"


# --- the fuzz --------------------------------------------------------------------------------

_WARM: set[str] = set()


def _warm_up(name: str) -> None:
    """Call a JIT-compiled function once with valid arguments, outside the budget: its first call
    compiles or loads numba kernels (11.7 s from an empty cache, bench_ik), which under a loaded
    machine could pass BUDGET and read as a hang of the call being fuzzed."""
    if name in _WARM or not name.startswith("robokit.arm."):
        return
    _WARM.add(name)
    args, kwargs = _arguments(name, {})
    try:
        POPULATION[name](*args, **kwargs)
    except Exception:          # the fuzz below judges the function; the warm-up only compiles it
        pass


@pytest.mark.parametrize("name", FUZZED)
def test_every_invalid_input_gets_a_clear_error(name):
    _warm_up(name)
    failures = []
    for pname, kind in _fuzzed_kinds(name):
        for label, value in kind.cases():
            failures.append(fuzz_one(name, pname, label, value))
        if SPECS[name].cheap:
            for label, value in kind.huge():
                failures.append(fuzz_one(name, pname, label, value, huge=True))
    failures = [f for f in failures if f]
    assert not failures, "\n".join(failures)


@pytest.mark.parametrize("name", [n for n in FUZZED if _fuzzed_kinds(n)])
@settings(derandomize=True, deadline=None, database=None,   # draws: the profile's (tests/conftest.py)
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(data=st.data())
def test_random_invalid_inputs_get_a_clear_error(name, data):
    _warm_up(name)
    pname, kind = data.draw(st.sampled_from(_fuzzed_kinds(name)), label="argument")
    label, value = data.draw(kind.strategy(), label="value")
    failure = fuzz_one(name, pname, label, value)
    assert failure is None, failure


@pytest.mark.parametrize("name, pname", [(n, p) for n, ps in sorted(HUGE_ANGLES.items()) for p in ps])
def test_a_huge_angle_is_refused_not_wrapped(name, pname):
    """1e300 where an angle sits: finite, but its sine or wrap is an arbitrary number (issue 38)."""
    kind = SPECS[name].kinds[pname]
    value = HUGE if np.ndim(kind.valid()) == 0 else np.asarray(kind.valid(), float)
    if np.ndim(value):
        value.reshape(-1)[-1] = HUGE
    failure = fuzz_one(name, pname, "a huge angle", value)
    assert failure is None, failure
