"""The host's set-points on their way to the robot: a wireless link with latency, jitter and loss.

LittleDog's host computer runs the control loop at 100 Hz and sends the robot a command every
10 ms over 802.11b wireless; the joint servos on the robot run at 500 Hz (LittleDog User Guide,
Sec. 2). Between two commands, and when one is late or lost, the servo holds the newest set-point
it has (a zero-order hold). :class:`SetpointChannel` models that link with what goes wrong on a
wireless one: each packet is delayed by a fixed latency plus a random jitter, dropped with a
probability, and may overtake an older one; on the robot's side an older packet arriving after a
newer one is discarded as stale (it carries a sequence number), and a packet holding a NaN or an
infinity is rejected and counted: the robot keeps its previous set-point rather than stop on one
bad packet. Losses are independent from packet to packet (a Bernoulli channel; the bursts a real
802.11b link also has are left out).

References
----------
.. [1] Boston Dynamics, *LittleDog User Guide*, v1.0.2, 2006.
"""
from __future__ import annotations

import heapq
from typing import Any

import numpy as np

from ..validation import as_array, as_rng, as_finite_scalar, as_positive

__all__ = ["SetpointChannel"]


class SetpointChannel:
    """A one-way set-point link, host to robot: latency, uniform jitter, Bernoulli loss, ZOH on arrival.

    Parameters
    ----------
    period : float, default 0.01
        The host's send period (s, > 0): 100 Hz on LittleDog. :meth:`due` says when a send is due.
    latency : float, default 0
        Fixed part of the delay (s, >= 0).
    jitter : float, default 0
        Random part of the delay (s, >= 0): each packet's delay is ``latency + U(0, jitter)``, uniform,
        so ``latency`` is the shortest delay and ``latency + jitter / 2`` the mean. A jitter longer
        than ``period`` lets packets arrive out of order.
    loss : float, default 0
        Probability that a packet is lost, independently of the others, in ``[0, 1)``.
    rng : numpy.random.Generator or int, default 0
        Source of the jitter and the losses (a seed gives a repeatable link).

    Attributes
    ----------
    sent, delivered, lost, stale, rejected : int
        Packets handed to :meth:`send`; accepted by the robot; lost on the air; arrived after a
        newer one (discarded); arrived holding NaN or inf (discarded). ``sent = delivered + lost +
        stale + rejected + in_flight``.

    Notes
    -----
    :meth:`receive` runs every servo tick, so it costs one comparison when nothing has arrived
    (the packets in flight sit in a heap ordered by arrival time).

    Examples
    --------
    >>> link = SetpointChannel(latency=0.004)
    >>> link.send(0.0, [0.1, 0.2])
    True
    >>> link.receive(0.002) is None, link.receive(0.004).tolist()      # arrives 4 ms later
    (True, [0.1, 0.2])
    >>> _ = link.send(0.01, [float("nan"), 0.2])                          # a bad packet: kept out
    >>> link.receive(0.02).tolist(), link.rejected
    ([0.1, 0.2], 1)
    """

    def __init__(self, period: float = 0.01, latency: float = 0.0, jitter: float = 0.0, loss: float = 0.0,
                 rng: Any = 0) -> None:
        self.period = as_positive(period, "period")
        self.latency = as_positive(latency, "latency", allow_zero=True)
        self.jitter = as_positive(jitter, "jitter", allow_zero=True)
        p = as_positive(loss, "loss", allow_zero=True)
        if not p < 1:
            raise ValueError(f"loss: expected a probability in [0, 1), got {p}")
        self.loss = p
        self.rng = as_rng(rng)
        self.sent = self.delivered = self.lost = self.stale = self.rejected = 0
        self._queue: list[tuple[float, int, np.ndarray]] = []      # (arrival, sequence, set-point)
        self._held: np.ndarray | None = None
        self._held_seq = -1
        self._shape: tuple[int, ...] | None = None
        self._last_send = -np.inf
        self._last_receive = -np.inf

    @property
    def in_flight(self) -> int:
        """Packets sent, not lost, and not yet arrived."""
        return len(self._queue)

    def due(self, t: float) -> bool:
        """Whether the host's next send is due at time ``t`` (s): one ``period`` after the last send.

        Examples
        --------
        >>> link = SetpointChannel(period=0.01)
        >>> link.due(0.0), link.send(0.0, [0.0]), link.due(0.005), link.due(0.01)
        (True, True, False, True)
        """
        now = as_finite_scalar(t, "t")
        return now >= self._last_send + self.period * (1 - 1e-9)

    def send(self, t: float, setpoint: Any, *, validate: bool = True) -> bool:
        """Put a set-point on the air at time ``t`` (s); return whether it survives (is not lost).

        Parameters
        ----------
        t : float
            Send time (s), not before the previous send.
        setpoint : array_like
            Numbers, the same shape at every send (12 joint angles for LittleDog). NaN and inf are
            let through: the host may send them, and the robot rejects them on arrival.
        validate : bool, default True
            Check ``t`` and ``setpoint``; ``False`` is the simulator's fast path (a float time and a
            float array it made itself; the order of the times is still checked).

        Returns
        -------
        bool
            ``False`` if the packet is lost (counted in ``lost``).

        Raises
        ------
        ValueError, TypeError
            A time that is not finite or goes backwards, a set-point that is not numbers or changes shape.

        Examples
        --------
        >>> link = SetpointChannel(loss=0.5, rng=1)
        >>> [link.send(0.01 * k, [0.0]) for k in range(6)], link.lost
        ([True, True, False, True, False, False], 3)
        """
        now = as_finite_scalar(t, "t") if validate else t
        if now < self._last_send:
            raise ValueError(f"t: expected send times that do not go backwards, got {now} after {self._last_send}")
        value = np.array(as_array(setpoint, "setpoint", finite=False) if validate else setpoint, dtype=float)
        if self._shape is None:
            self._shape = value.shape
        elif value.shape != self._shape:
            raise ValueError(f"setpoint: expected shape {self._shape} (as sent before), got shape {value.shape}")
        value.flags.writeable = False
        self._last_send = now
        seq = self.sent
        self.sent += 1
        if self.loss and self.rng.random() < self.loss:
            self.lost += 1
            return False
        delay = self.latency + (self.jitter * self.rng.random() if self.jitter else 0.0)   # latency + U(0, jitter)
        heapq.heappush(self._queue, (now + delay, seq, value))
        return True

    def receive(self, t: float, *, validate: bool = True) -> np.ndarray | None:
        """The set-point the robot holds at time ``t`` (s): the newest valid packet arrived by ``t``.

        Parameters
        ----------
        t : float
            The robot's clock (s), not going backwards.
        validate : bool, default True
            Check ``t``; ``False`` is the simulator's fast path (called every servo tick with a float
            it computed; the order of the times is still checked).

        Returns
        -------
        numpy.ndarray or None
            The newest (by sequence number) finite set-point arrived at or before ``t``, read-only,
            held until a newer one arrives; ``None`` before the first arrives. Packets arriving after
            a newer one count as ``stale``; packets holding NaN or inf count as ``rejected`` and
            leave the held set-point unchanged (documented behaviour, not an exception).

        Examples
        --------
        >>> link = SetpointChannel(latency=0.002, jitter=0.03, rng=7)
        >>> for k in range(4):
        ...     _ = link.send(0.01 * k, [float(k)])
        >>> [link.receive(t).tolist() for t in (0.03, 0.1)], link.delivered, link.stale   # 3 overtook 1 and 2
        ([[0.0], [3.0]], 2, 2)
        """
        now = as_finite_scalar(t, "t") if validate else t
        if now < self._last_receive:
            raise ValueError(f"t: expected a clock that does not go backwards, got {now} after {self._last_receive}")
        self._last_receive = now
        queue = self._queue
        while queue and queue[0][0] <= now:
            _, seq, value = heapq.heappop(queue)
            if seq < self._held_seq:
                self.stale += 1
            elif not np.all(np.isfinite(value)):
                self.rejected += 1
            else:
                self._held, self._held_seq = value, seq
                self.delivered += 1
        return self._held
