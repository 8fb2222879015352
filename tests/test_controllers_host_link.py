"""The host-to-robot set-point link (robokit.controllers.host_link): latency, jitter, loss statistics, stale
packets dropped (against a brute-force replay of the arrivals), NaN packets rejected, bad arguments named."""
from __future__ import annotations

import math

import numpy as np
import pytest

from robokit.controllers import SetpointChannel

TICK = 0.002        # the 500 Hz servo reads the link every tick


def _first_seen(link, t_end, tick=TICK):
    """Time at which each set-point (a value = its sequence number) is first held, polling every tick."""
    seen = {}
    for k in range(int(round(t_end / tick)) + 1):
        held = link.receive(k * tick)
        if held is not None and int(held[0]) not in seen:
            seen[int(held[0])] = k * tick
    return seen


def test_latency_shifts_the_arrival():
    link = SetpointChannel(latency=0.0035)
    assert link.send(0.0, [1.0, 2.0])
    assert link.receive(0.0) is None and link.receive(0.00349) is None
    assert link.receive(0.0035).tolist() == [1.0, 2.0]
    assert link.in_flight == 0 and link.delivered == 1


def test_jitter_is_uniform_on_latency_to_latency_plus_jitter():
    # one packet at a time, far apart, and the robot polling every 0.05 ms: each packet's delay
    step, n = 5e-5, 1000
    link = SetpointChannel(period=0.1, latency=0.01, jitter=0.02, rng=4)
    delay = np.empty(n)
    for k in range(n):
        t0 = k * 0.1
        link.send(t0, [float(k)])
        for j in range(1, 1000):
            held = link.receive(t0 + j * step)
            if held is not None and held[0] == k:
                delay[k] = j * step
                break
    assert delay.min() >= 0.01 - 1e-9 and delay.max() <= 0.03 + step + 1e-9
    assert delay.mean() - step / 2 == pytest.approx(0.02, abs=4 * 0.02 / math.sqrt(12 * n))   # latency + jitter / 2
    assert np.histogram(delay, bins=4, range=(0.01, 0.03 + step))[0].min() > 0.2 * n          # flat, not bunched


def test_loss_rate_statistics_with_a_seed():
    n, p = 20_000, 0.2
    link = SetpointChannel(loss=p, rng=7)
    survived = np.array([link.send(0.01 * k, [0.0]) for k in range(n)])
    assert link.lost == n - survived.sum() and link.sent == n
    assert abs(link.lost / n - p) < 4 * math.sqrt(p * (1 - p) / n)
    runs = np.flatnonzero(np.diff(survived.astype(int)))          # independent losses: as many runs as Bernoulli
    expected_runs = 2 * n * p * (1 - p)
    assert abs(len(runs) - expected_runs) < 5 * math.sqrt(expected_runs)
    again = SetpointChannel(loss=p, rng=7)
    assert [again.send(0.01 * k, [0.0]) for k in range(100)] == survived[:100].tolist()    # repeatable


def test_stale_packets_are_dropped_as_a_brute_force_replay_says():
    period, latency, jitter, seed, n = 0.01, 0.002, 0.035, 11, 400
    link = SetpointChannel(period=period, latency=latency, jitter=jitter, rng=seed)
    for k in range(n):
        link.send(k * period, [float(k)])
    # brute force: the same draws (one uniform per packet, in send order), the packets sorted by arrival,
    # each kept only if newer than every packet already held
    u = np.random.default_rng(seed).random(n)
    arrival = np.arange(n) * period + latency + jitter * u
    newest, stale, held_at = -1, 0, []
    for i in np.argsort(arrival, kind="stable"):
        if i < newest:
            stale += 1
        else:
            newest = i
        held_at.append(newest)
    seen = _first_seen(link, n * period + latency + jitter + TICK)
    assert link.stale == stale and stale > 50
    assert link.delivered == n - stale and link.sent == n and link.lost == link.rejected == 0
    held = sorted(seen)
    assert set(held) <= set(held_at) and held[-1] == n - 1      # a packet superseded within a tick is never seen
    assert list(seen.values()) == sorted(seen.values())              # the held sequence never goes back
    for k in held:
        assert seen[k] >= arrival[k] - 1e-12 and seen[k] < arrival[k] + TICK + 1e-12


def test_the_unchecked_path_delivers_what_the_checked_one_does():
    links = [SetpointChannel(period=0.01, latency=0.002, jitter=0.03, loss=0.2, rng=5) for _ in range(2)]
    held = [[], []]
    for k in range(200):
        for j, link in enumerate(links):
            link.send(0.01 * k, np.array([float(k), math.nan if k % 7 == 0 else 0.0]), validate=bool(j))
            got = link.receive(0.01 * k + 0.005, validate=bool(j))
            held[j].append(None if got is None else got.tolist())
    assert held[0] == held[1] and held[0][-1] is not None
    assert [(l.sent, l.delivered, l.lost, l.stale, l.rejected) for l in links][0] == \
        (links[1].sent, links[1].delivered, links[1].lost, links[1].stale, links[1].rejected)
    with pytest.raises(ValueError, match="backwards"):
        links[0].receive(0.0, validate=False)


def test_nan_set_points_are_rejected_and_the_previous_one_held():
    link = SetpointChannel()
    link.send(0.0, [0.1, 0.2])
    first = link.receive(0.0)
    link.send(0.01, [np.nan, 0.2])
    link.send(0.02, [0.3, np.inf])
    assert link.receive(0.025) is first and first.tolist() == [0.1, 0.2]
    assert link.rejected == 2 and link.delivered == 1
    link.send(0.03, [0.4, 0.5])
    assert link.receive(0.03).tolist() == [0.4, 0.5]
    with pytest.raises(ValueError):
        first[0] = 9.0                                                # the held set-point is read-only
    assert link.sent == link.delivered + link.lost + link.stale + link.rejected + link.in_flight


def test_zero_order_hold_between_packets_and_due():
    link = SetpointChannel(period=0.01)
    times = np.arange(0, 0.1, 0.001)
    sends = 0
    for t in times:
        if link.due(t):
            link.send(t, [t])
            sends += 1
        held = link.receive(t)
        assert held[0] == pytest.approx(0.01 * math.floor(t / 0.01 + 1e-9))
    assert sends == 10


@pytest.mark.parametrize("kwargs, name", [({"latency": -0.001}, "latency"), ({"loss": 1.0}, "loss"),
                                          ({"loss": math.nan}, "loss"), ({"period": 0.0}, "period"),
                                          ({"jitter": math.inf}, "jitter"), ({"rng": -1}, "rng")])
def test_constructor_arguments_are_validated(kwargs, name):
    with pytest.raises((ValueError, TypeError), match=name):
        SetpointChannel(**kwargs)


def test_send_and_receive_refuse_bad_calls():
    link = SetpointChannel()
    link.send(0.01, np.zeros(12))
    with pytest.raises(ValueError, match="t"):
        link.send(0.0, np.zeros(12))
    with pytest.raises(ValueError, match="setpoint"):
        link.send(0.02, np.zeros(3))
    with pytest.raises(TypeError, match="setpoint"):
        link.send(0.03, ["a"] * 12)
    link.receive(0.05)
    with pytest.raises(ValueError, match="t"):
        link.receive(0.04)
    with pytest.raises(ValueError, match="t"):
        link.receive(math.nan)
