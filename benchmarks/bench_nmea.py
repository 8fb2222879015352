"""Parse a 100,000-sentence NMEA log with robokit and with pynmea2 in the same process.

Run from the repository root:  .venv/bin/python -m benchmarks.bench_nmea [--count N] [--repeat R]

Both parsers verify checksums and produce every field: robokit converts eagerly into typed records;
pynmea2 converts lazily on attribute access, so its timed loop reads every field of every message
(plus ``latitude``/``longitude``/``timestamp``/``datestamp``) to obtain the same information. After
timing, the fields of both are compared sentence by sentence (the same mapping the test-suite uses).
Prints sentences per second and the ratio; the target is a ratio >= 2 (issue 6).
"""
from __future__ import annotations

import argparse
import time

import numpy as np
import pynmea2

from robokit.outdoor.nmea import NMEAReader, Sentence, parse_sentence
from robokit.outdoor.nmea_write import random_sentences
from tests.test_outdoor_nmea import ours_view, pynmea2_view

_DERIVED = ("latitude", "longitude")


def pynmea2_full(line: str):
    """pynmea2.parse plus reading every field, so that all values are converted."""
    msg = pynmea2.parse(line, check=True)
    for name in msg.name_to_idx:
        getattr(msg, name)
    if msg.sentence_type in ("RMC", "GGA"):
        msg.latitude, msg.longitude
    return msg


def best_interleaved(fns: dict, repeat: int) -> dict:
    """Best time of each function over ``repeat`` rounds, run in turn so that load on a shared
    machine hits every contender alike."""
    best = {name: float("inf") for name in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            best[name] = min(best[name], time.perf_counter() - t0)
    return best


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)

    lines = random_sentences(args.count, np.random.default_rng(2026), empty_fraction=0.1)
    blob = ("\r\n".join(lines) + "\r\n").encode("ascii")
    n = len(lines)

    t = best_interleaved({"ours": lambda: [parse_sentence(s) for s in lines],
                          "stream": lambda: list(NMEAReader(blob)),
                          "theirs": lambda: [pynmea2_full(s) for s in lines],
                          "lazy": lambda: [pynmea2.parse(s, check=True) for s in lines]}, args.repeat)
    t_ours, t_stream, t_theirs, t_lazy = t["ours"], t["stream"], t["theirs"], t["lazy"]

    # identical fields, sentence by sentence
    ours = [parse_sentence(s) for s in lines]
    assert ours == list(NMEAReader(blob))
    mismatches = 0
    for s, rec in zip(lines, ours):
        theirs = pynmea2_view(pynmea2.parse(s, check=True))
        if isinstance(rec, Sentence):
            mismatches += rec.fields != theirs["fields"]
            continue
        mine = ours_view(rec, theirs)
        for k, v in theirs.items():
            w = mine[k]
            same = (abs(w - v) <= 1e-12 * max(1.0, abs(v))) if isinstance(v, float) and w is not None else w == v
            mismatches += not same

    print(f"sentences: {n}  (RMC/GGA/HDG/RMB/GSA/VTG, GP/GN/GL/HC talkers, 10% with empty fields)")
    print(f"robokit parse_sentence  : {n / t_ours:12,.0f} sentences/s")
    print(f"robokit NMEAReader bytes: {n / t_stream:12,.0f} sentences/s")
    print(f"pynmea2 parse + fields  : {n / t_theirs:12,.0f} sentences/s")
    print(f"pynmea2 parse (lazy)    : {n / t_lazy:12,.0f} sentences/s  (fields not converted)")
    print(f"ratio robokit/pynmea2 (all fields)      : {t_theirs / t_ours:5.2f}x  (stream reader {t_theirs / t_stream:5.2f}x)")
    print(f"ratio robokit/pynmea2 (lazy, unconverted): {t_lazy / t_ours:5.2f}x")
    print(f"field mismatches: {mismatches}")


if __name__ == "__main__":
    main()
