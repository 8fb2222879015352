"""What an invalid input is, per kind of argument: the vocabulary of tests/test_fuzz_public_api.py.

Each kind holds a valid value (or a factory of one) and lists the invalid values of its kind, as
fixed examples (``invalid()``, every one tried once) and as a hypothesis strategy (``strategy()``,
random variants: where the NaN sits, which shape is wrong, which string). What "invalid" means:

* ``Real`` (a finite real scalar): NaN, +-inf, numeric and other strings, complex numbers (also
  with a zero imaginary part), booleans, ``None`` (unless optional), a list where one number is
  wanted, an arbitrary object. Huge (1e300) is not invalid as such: it must give a clear error or
  a result without NaN or inf.
* ``Int``: the above, plus fractions (1.5) and integers beyond int64 (no numpy size or index
  holds them).
* ``Array`` (numbers of a given shape): a NaN or +-inf element, strings (numeric ones too),
  complex and boolean arrays, shapes its contract does not accept (a column more, a dimension
  more or less, a scalar, no rows where rows are needed), ragged nested lists, ``None``, a
  string, an object; huge elements as for ``Real``.
* ``Choice`` (one of a few strings): an unknown one, a number, bytes, ``None``, a list.
* ``Obj`` (an instance of a robokit class), ``Text`` (free text), ``Func`` (a callable),
  ``Mapping`` (a dict), ``Rng`` (a Generator or a non-negative integer seed): values of other
  types (``None`` only where not optional), and for ``Rng`` negative, fractional, boolean and
  string seeds and the legacy ``RandomState``.
* ``File`` (a path a reader reads): paths of other types and hostile files generated for the run,
  each of which must get the reader's named error naming the argument or the file: empty,
  text, noise, truncated, zeroed in the middle, another format's file, one byte over the reader's
  budget (sparse), a device, a directory, a FIFO, a link to a device, a loop of links, and the
  reader's own (``extra``: nested archives, oversized headers, deep nesting); a missing file or a
  dangling link gets ``FileNotFoundError``.
* ``Flag`` and ``Given`` are not fuzzed: flags follow Python's truthiness, and a given value is
  one that another argument's contract constrains (documented where it is used).

A documented contract that accepts some of these says so in the function's docstring and in the
kind: ``inf_ok=True`` (e.g. sonar ranges, where ``inf`` means "nothing in range") drops +-inf
from the invalid values, and the test checks that the docstring mentions ``inf``.
"""
from __future__ import annotations

import atexit
import copy
import functools
import math
import os
import re
import shutil
import tempfile
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np
from hypothesis import strategies as st

HUGE = 1e300


class Kind:
    """An argument's kind: its valid value and its invalid ones."""

    fuzzed = True

    def __init__(self, valid: Any = None, *, optional: bool = False, accepts: tuple[str, ...] = ()) -> None:
        self._valid = valid
        self._cached = None
        self.optional = optional
        self.accepts = accepts   # labels of invalid values that this argument's contract accepts

    def valid(self) -> Any:
        """The valid value (built once; arrays and lists are copied for every call)."""
        if self._cached is None:
            self._cached = (self._valid() if callable(self._valid) and not isinstance(self._valid, type)
                            else self._valid,)
        value = self._cached[0]
        return copy.deepcopy(value) if isinstance(value, (np.ndarray, list, dict)) else value

    def common(self) -> Iterator[tuple[str, Any]]:
        if not self.optional:
            yield "None", None
        yield "an object", object()

    def invalid(self) -> list[tuple[str, Any]]:
        """Fixed invalid values, each labelled."""
        return list(self.common())

    def cases(self) -> list[tuple[str, Any]]:
        """``invalid()`` less what the contract accepts."""
        return [(label, v) for label, v in self.invalid() if label not in self.accepts]

    def huge(self) -> list[tuple[str, Any]]:
        """Values that are not invalid as such but must not give NaN or inf silently."""
        return []

    def strategy(self) -> st.SearchStrategy:
        """Random invalid values (label, value)."""
        return st.sampled_from(self.cases())


class Flag(Kind):
    """A bool option: Python truthiness, not fuzzed."""

    fuzzed = False


class Given(Kind):
    """A value constrained by another argument (e.g. the features of an image): not fuzzed."""

    fuzzed = False


class Real(Kind):
    """A finite real number (``inf_ok``: +-inf is part of the contract)."""

    def __init__(self, valid: float, *, inf_ok: bool = False, **kw: Any) -> None:
        super().__init__(valid, **kw)
        self.inf_ok = inf_ok

    def invalid(self) -> list[tuple[str, Any]]:
        v = self.valid()
        out = [("NaN", math.nan)] + ([] if self.inf_ok else [("inf", math.inf), ("-inf", -math.inf)])
        out += [("a numeric string", repr(float(v))), ("a string", "abc"), ("bytes", b"1"),
                ("complex", complex(v, 1.0)), ("complex with zero imaginary part", complex(v)),
                ("a bool", True), ("a numpy bool", np.True_), ("a list", [v, v]),
                ("a 0-d string array", np.array(str(v)))]
        return out + list(self.common())

    def huge(self) -> list[tuple[str, Any]]:
        return [("huge", HUGE), ("huge negative", -HUGE)]

    def strategy(self) -> st.SearchStrategy:
        text = st.text(alphabet="0123456789.e-+naif ", min_size=1, max_size=8).map(lambda s: ("a string", s))
        cplx = st.complex_numbers(allow_nan=False, allow_infinity=False, max_magnitude=1e6).map(
            lambda z: ("complex", complex(z.real, z.imag or 1.0)))
        return st.one_of(st.sampled_from(self.cases()), text, cplx)


class Int(Kind):
    """An integer."""

    def invalid(self) -> list[tuple[str, Any]]:
        v = self.valid()
        return [("NaN", math.nan), ("inf", math.inf), ("a fraction", v + 0.5), ("a numeric string", str(v)),
                ("a bool", True), ("complex", complex(v, 1)), ("a list", [v]), ("beyond int64", 2 ** 64),
                ("below int64", -(2 ** 64))] + list(self.common())

    def strategy(self) -> st.SearchStrategy:
        frac = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6).filter(
            lambda x: x != int(x)).map(lambda x: ("a fraction", x))
        big = st.integers(min_value=2 ** 63, max_value=2 ** 80).map(lambda n: ("beyond int64", n))
        return st.one_of(st.sampled_from(self.cases()), frac, big)


class Rng(Kind):
    """A numpy Generator or a non-negative integer seed (``None``: the default seed)."""

    def __init__(self, valid: Any = 0, **kw: Any) -> None:
        super().__init__(valid, optional=True, **kw)

    def invalid(self) -> list[tuple[str, Any]]:
        return [("a negative seed", -1), ("a fractional seed", 1.5), ("a string seed", "0"), ("a bool", True),
                ("a legacy RandomState", np.random.RandomState(0)), ("NaN", math.nan)] + list(self.common())


class Choice(Kind):
    """One of a few strings."""

    def invalid(self) -> list[tuple[str, Any]]:
        v = self.valid()
        return [("an unknown choice", "no-such-choice"), ("a number", 42), ("bytes", str(v).encode()),
                ("a list", [v])] + list(self.common())

    def strategy(self) -> st.SearchStrategy:
        return st.one_of(st.sampled_from(self.cases()),
                         st.text(max_size=12).filter(lambda s: s != self.valid()).map(lambda s: ("an unknown choice", s)))


class Text(Kind):
    """Free text (a title, a path in a scene, a sentence)."""

    def invalid(self) -> list[tuple[str, Any]]:
        return [("a number", 42), ("a float", 1.5), ("bytes", b"\xff"), ("a list", ["x"])] + list(self.common())


class Obj(Kind):
    """An instance of a robokit class (or anything its contract names)."""

    def invalid(self) -> list[tuple[str, Any]]:
        return [("a number", 42), ("a string", "text"), ("an array", np.zeros(3))] + list(self.common())


class Func(Kind):
    """A callable."""

    def invalid(self) -> list[tuple[str, Any]]:
        return [("a number", 42), ("a string", "print")] + list(self.common())


class Mapping(Kind):
    """A dict."""

    def invalid(self) -> list[tuple[str, Any]]:
        return [("a number", 42), ("a string", "a=1"), ("a list", [1, 2])] + list(self.common())


@functools.cache
def fuzz_folder() -> Path:
    """One temporary folder for every file the fuzz writes, removed when the test process ends."""
    folder = Path(tempfile.mkdtemp(prefix="robokit-fuzz-"))
    atexit.register(shutil.rmtree, folder, True)
    return folder


class File(Kind):
    """A path to a file a reader reads (``valid``: a factory of a valid file's path).

    ``budget``: the reader's byte bound; ``foreign``: a factory of another format's valid file;
    ``extra``: ``valid bytes -> {label: bytes}``, the reader's own hostile contents; ``missing``: what
    the reader documents for a missing file (``FileNotFoundError`` unless it says otherwise).
    """

    #: Labels whose right answer is ``FileNotFoundError`` (naming the file), not the reader's error.
    MISSING = ("a missing file", "a dangling link")

    def __init__(self, valid: Any, *, budget: int, foreign: Callable[[], Any], error: type = ValueError,
                 missing: type = FileNotFoundError, extra: Callable[[bytes], dict] | None = None, **kw: Any) -> None:
        super().__init__(valid, **kw)
        self.budget, self.foreign, self.error, self.missing, self.extra = budget, foreign, error, missing, extra
        self._files: list[tuple[str, Any]] | None = None

    def hostile(self, label: str) -> bool:
        """Whether ``label`` is a hostile file (which must get ``error``), not a value of another type."""
        return label in dict(self._files or ())

    def _hostile_files(self) -> list[tuple[str, Any]]:
        valid = Path(self.valid())
        data = valid.read_bytes()
        folder = Path(tempfile.mkdtemp(prefix="file-", dir=fuzz_folder()))
        n = len(data)
        contents = {"an empty file": b"", "text": b"this is not the file you are looking for\n",
                    "binary noise": np.random.default_rng(0).bytes(4096), "truncated": data[: n // 2],
                    "zeroed in the middle": data[: n // 3] + bytes(n // 3) + data[2 * n // 3:],
                    "another format's file": Path(self.foreign()).read_bytes(),
                    **(self.extra(data) if self.extra else {})}
        out = []
        for label, content in contents.items():
            path = folder / (re.sub(r"\W+", "-", label) + valid.suffix)
            path.write_bytes(content)
            out.append((label, str(path)))
        oversized = folder / f"oversized{valid.suffix}"
        with open(oversized, "wb") as fh:
            fh.truncate(self.budget + 1)                     # sparse: costs no disk
        os.mkfifo(folder / "a-fifo")
        (folder / "device-link").symlink_to("/dev/zero")
        (folder / "loop-a").symlink_to(folder / "loop-b")
        (folder / "loop-b").symlink_to(folder / "loop-a")
        (folder / "dangling-link").symlink_to(folder / "nowhere")
        out += [("one byte over the budget", str(oversized)), ("a device", "/dev/zero"),
                ("a directory", str(folder)), ("a FIFO", str(folder / "a-fifo")),
                ("a link to a device", str(folder / "device-link")), ("a loop of links", str(folder / "loop-a")),
                ("a dangling link", str(folder / "dangling-link")), ("a missing file", str(folder / "missing-file"))]
        return out

    def invalid(self) -> list[tuple[str, Any]]:
        if self._files is None:
            self._files = self._hostile_files()
        return [("a number", 42), ("bytes", b"x"), ("an empty path", ""), ("a list", [str(self.valid())])] + \
            self._files + list(self.common())


def npy_header(shape: tuple, descr: str = "<f8") -> bytes:
    """An ``.npy`` header declaring ``shape`` and ``descr``, with no data after it."""
    text = f"{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape!r}, }}".encode()
    text += b" " * (63 - (10 + len(text)) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text


def zip_of(members: dict) -> bytes:
    """A zip archive holding ``{name: bytes}``."""
    import io
    import zipfile
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return buffer.getvalue()


def npz_extras(valid: bytes) -> dict:
    """Hostile ``.npz`` contents (``File(extra=...)``): headers that lie, objects, foreign and nested members."""
    return {
        "a 10^12-row header": zip_of({"poses.npy": npy_header((10**12, 3)), "format.npy": npy_header(())}),
        "Python objects": zip_of({"poses.npy": npy_header((3,), "|O")}),
        "a foreign member": zip_of({"poses.txt": b"1 2 3"}),
        "a damaged header": zip_of({"poses.npy": b"\x93NUMPY\x01\x00\x20\x00{'descr': (((((((((((((((\n"}),
        "a nested archive": zip_of({"poses.npy": valid}),
        "10^5 empty members": zip_of({f"a{i}.npy": b"" for i in range(100_000)}),
    }


class Options(Kind):
    """``**options``: keyword arguments passed on; an unknown one must be named in the error."""

    UNKNOWN = "no_such_option"

    def invalid(self) -> list[tuple[str, Any]]:
        return [("an unknown option", {self.UNKNOWN: 1})]


def _accepts(shape: tuple, patterns: list[tuple], valid: tuple) -> bool:
    for p in patterns:
        if p[:1] == ("*",):     # "*": any shape that broadcasts with the valid one; "...,2,2": any leading axes
            try:
                np.broadcast_shapes(shape, valid)
                return True
            except ValueError:
                continue
        if p[:1] == ("...",):
            tail = p[1:]
            if len(shape) >= len(tail) and all(q is None or q == s for q, s in zip(tail, shape[len(shape) - len(tail):])):
                return True
        elif len(p) == len(shape) and all(q is None or q == s for q, s in zip(p, shape)):
            return True
    return False


class Array(Kind):
    """Numbers of a given shape.

    ``shapes``: the accepted shapes as strings such as ``"N,3"`` or ``"4,4|N,4,4"`` (``N``: any
    length >= ``min_rows``; ``""``: a scalar; ``"...,2,2"``: any leading axes; ``"*"``: anything
    that broadcasts); the valid value must have one of them.
    """

    def __init__(self, valid: Any, shapes: str, *, inf_ok: bool = False, min_rows: int = 1, **kw: Any) -> None:
        super().__init__(valid, **kw)
        self.patterns = [tuple(None if d.strip() == "N" else d.strip() if d.strip() in ("*", "...") else int(d)
                               for d in p.split(",") if d.strip()) for p in shapes.split("|")]
        self.inf_ok = inf_ok
        self.min_rows = min_rows

    def _bad_shapes(self, v: np.ndarray) -> Iterator[tuple[str, np.ndarray]]:
        cands = [("a scalar", v.reshape(-1)[:1].reshape(()))]
        if v.ndim:
            cands += [("one column more", np.concatenate([v, v[..., :1]], axis=-1)),
                      ("one dimension less", v[..., 0]), ("one dimension more", v[..., None]),
                      ("a stack of two", np.stack([v, v]))]
            if self.min_rows > 0:
                cands.append(("no rows", v[:0]))
        for label, arr in cands:
            if not _accepts(arr.shape, self.patterns, v.shape) and (arr.ndim == 0 or arr.shape[0] >= self.min_rows
                                                           or label == "no rows"):
                yield label, arr

    def invalid(self) -> list[tuple[str, Any]]:
        v = np.asarray(self.valid())
        out = []
        if v.size:
            for label, x in [("a NaN element", np.nan)] + ([] if self.inf_ok else [("an inf element", np.inf),
                                                                                   ("a -inf element", -np.inf)]):
                w = v.astype(float)
                w.reshape(-1)[-1] = x
                out.append((label, w))
        out += [("numeric strings", v.astype(str)), ("complex", v + 1j), ("complex with zero imaginary part", v + 0j),
                ("booleans", v != 0), ("a string", "abc")]
        out += list(self._bad_shapes(v))
        if v.ndim >= 1 and v.size:
            rows = v.tolist()
            out.append(("a ragged list", [rows[0], [rows[0]]] if v.ndim == 1 else [rows[0], rows[0][:-1] or [1.0, 2.0]]))
        return out + list(self.common())

    def huge(self) -> list[tuple[str, Any]]:
        v = np.asarray(self.valid()).astype(float)
        if not v.size:
            return []
        w = v.copy()
        w.reshape(-1)[-1] = HUGE
        return [("a huge element", w)]

    def strategy(self) -> st.SearchStrategy:
        v = np.asarray(self.valid())
        if not v.size:
            return super().strategy()
        bad = [np.nan] + ([] if self.inf_ok else [np.inf, -np.inf])

        def poke(args: tuple[int, float]) -> tuple[str, Any]:
            w = v.astype(float)
            w.reshape(-1)[args[0]] = args[1]
            return f"{args[1]} at flat index {args[0]}", w

        return st.one_of(st.sampled_from(self.cases()),
                         st.tuples(st.integers(0, v.size - 1), st.sampled_from(bad)).map(poke))


Spec = dict[str, Kind]
Factory = Callable[[], Any]
