"""The executor's first-in, first-out trajectory buffer (Zucker 2011, §6).

"The footstep execution module maintains a trajectory buffer that operates
in first-in, first-out (FIFO) fashion. The trajectory specifies not only the
desired joint angles and velocities over time, but also additional
information such as desired body position and orientation, corresponding
velocities and accelerations, which feet should be supporting, and
estimated ground interaction forces."

A :class:`Segment` is one such piece (a footstep, a recovery, a blend); the
buffer plays them back to back. A segment may carry a ``ready_at`` time: the
simulated instant its optimisation finished. When playback reaches a segment
that is not ready, the robot holds the last desired state and the wait is
counted.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["Segment", "DesiredState", "TrajectoryBuffer"]


@dataclass(frozen=True)
class DesiredState:
    """The desired state at one instant (one row of a :class:`Segment`).

    ``touchdown_in`` (4,) is the time [s] until each leg's planned touchdown
    (inf for a leg that is down and stays down, or has no touchdown ahead in
    its segment).
    """

    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    base_pos: NDArray[np.float64]
    base_quat: NDArray[np.float64]
    feet: NDArray[np.float64]
    support: NDArray[np.bool_]
    forces: NDArray[np.float64]
    touchdown_in: NDArray[np.float64]
    phase: int
    kind: str
    step: int


@dataclass(frozen=True)
class Segment:
    """A stretch of desired states sampled at times ``t`` (n,) [s] from the segment's start.

    Arrays: ``q``, ``qd`` (n, 12) [rad, rad/s]; ``base_pos`` (n, 3) [m];
    ``base_quat`` (n, 4); ``feet`` (n, 4, 3) [m]; ``support`` (n, 4);
    ``forces`` (n, 4, 3) [N]; ``phase`` (n,). ``kind`` names it ("step",
    "recovery", "blend", "hold"), ``step`` is the footstep number (0 when not
    a footstep), ``ready_at`` the simulated time [s] from which it may play.
    """

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    base_pos: NDArray[np.float64]
    base_quat: NDArray[np.float64]
    feet: NDArray[np.float64]
    support: NDArray[np.bool_]
    forces: NDArray[np.float64]
    phase: NDArray[np.int64]
    kind: str = "step"
    step: int = 0
    ready_at: float = 0.0
    info: dict[str, Any] = field(default_factory=dict)
    touchdown_in: NDArray[np.float64] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        n = len(self.t)
        if n < 1 or np.any(np.diff(self.t) <= 0) or abs(float(self.t[0])) > 1e-12:
            raise InvalidArgumentError(
                "a segment's times must start at 0 and increase strictly, "
                f"got {np.asarray(self.t)[:5].tolist()}…"
            )
        for name, shape in (
            ("q", (n, 12)),
            ("qd", (n, 12)),
            ("base_pos", (n, 3)),
            ("base_quat", (n, 4)),
            ("feet", (n, 4, 3)),
            ("support", (n, 4)),
            ("forces", (n, 4, 3)),
            ("phase", (n,)),
        ):
            a = getattr(self, name)
            if np.shape(a) != shape:
                raise InvalidArgumentError(
                    f"segment {name} must have shape {shape}, got {np.shape(a)}"
                )
        # Time to each leg's next touchdown, by a backward sweep.
        down = np.asarray(self.support, dtype=bool)
        until = np.full((n, 4), np.inf)
        for k in range(n - 2, -1, -1):
            lands = ~down[k] & down[k + 1]
            flying = ~down[k] & ~down[k + 1]
            dt = self.t[k + 1] - self.t[k]
            until[k] = np.where(lands, dt, np.where(flying, until[k + 1] + dt, np.inf))
        object.__setattr__(self, "touchdown_in", until)

    @property
    def duration(self) -> float:
        """Length [s]."""
        return float(self.t[-1])

    @classmethod
    def from_footstep(cls, traj: Any, ready_at: float = 0.0) -> Segment:
        """A segment from a :class:`~roughwalk.trajectories.FootstepTrajectory`."""
        t = np.asarray(traj.time, dtype=float)
        return cls(
            t=t - t[0],
            q=np.asarray(traj.q, dtype=float),
            qd=np.asarray(traj.qd, dtype=float),
            base_pos=np.asarray(traj.base_pos, dtype=float),
            base_quat=np.asarray(traj.base_quat, dtype=float),
            feet=np.asarray(traj.feet, dtype=float),
            support=np.asarray(traj.support, dtype=bool),
            forces=np.asarray(traj.contact_forces, dtype=float),
            phase=np.asarray(traj.phase, dtype=np.int64),
            kind="step",
            step=int(traj.step),
            ready_at=ready_at,
            info={"leg": traj.leg, "valid": bool(traj.valid), **_fitting(traj)},
        )

    def with_ready_at(self, ready_at: float) -> Segment:
        """The same segment, ready from ``ready_at`` [s]."""
        return replace(self, ready_at=float(ready_at))

    def sample(self, tau: float) -> DesiredState:
        """The desired state ``tau`` [s] into the segment (clamped to its ends).

        Joint angles, positions and forces are interpolated linearly between
        samples; support flags and the phase are those of the sample at or
        before ``tau``.
        """
        t = self.t
        if tau <= 0.0 or len(t) == 1:
            k, a = 0, 0.0
        elif tau >= t[-1]:
            k, a = len(t) - 2, 1.0
        else:
            k = int(np.searchsorted(t, tau, side="right")) - 1
            a = float((tau - t[k]) / (t[k + 1] - t[k]))
        j = min(k + 1, len(t) - 1)
        k_disc = j if a >= 1.0 else k

        def lerp(x: NDArray[np.float64]) -> NDArray[np.float64]:
            return (1.0 - a) * x[k] + a * x[j]

        quat = lerp(self.base_quat)
        if float(np.dot(self.base_quat[k], self.base_quat[j])) < 0:
            quat = (1.0 - a) * self.base_quat[k] - a * self.base_quat[j]
        quat = quat / np.linalg.norm(quat)
        touchdown = self.touchdown_in[k_disc] - (a * (t[j] - t[k]) if k_disc == k else 0.0)
        return DesiredState(
            q=lerp(self.q),
            qd=lerp(self.qd),
            base_pos=lerp(self.base_pos),
            base_quat=quat,
            feet=lerp(self.feet),
            support=self.support[k_disc].copy(),
            forces=lerp(self.forces),
            touchdown_in=touchdown,
            phase=int(self.phase[k_disc]),
            kind=self.kind,
            step=self.step,
        )

    def last(self) -> DesiredState:
        """The final desired state."""
        return self.sample(self.duration)


def _fitting(traj: Any) -> dict[str, list[float]]:
    """A footstep's fitted shift and swing lengths [s], and how much longer they came out.

    (:class:`~roughwalk.trajectories.step_report.StepReport`; NaN lengths
    where the generator did not fit them.)
    """
    report = traj.report
    fitted = [
        float(getattr(report, "fitted_shift_s", np.nan)),
        float(getattr(report, "fitted_swing_s", np.nan)),
    ]
    stretch = getattr(report, "stretch_s", (0.0, 0.0))
    return {"fitted_s": fitted, "stretch_s": [float(stretch[0]), float(stretch[1])]}


class TrajectoryBuffer:
    """Segments played back to back, first in, first out.

    Call :meth:`advance` once per control tick with the simulated time; it
    returns the desired state and whether the robot is waiting for a segment
    that is not ready yet (it then holds the last desired state).
    """

    def __init__(self) -> None:
        self._queue: deque[Segment] = deque()
        self._current: Segment | None = None
        self._started_at = 0.0
        self._free_since = -np.inf
        self._hold: DesiredState | None = None

    def __len__(self) -> int:
        """Segments queued, the playing one included."""
        return len(self._queue) + (1 if self._current is not None else 0)

    @property
    def current(self) -> Segment | None:
        """The segment playing now."""
        return self._current

    @property
    def started_at(self) -> float:
        """Simulated time [s] at which the playing segment started."""
        return self._started_at

    @property
    def queued(self) -> tuple[Segment, ...]:
        """Segments waiting to play."""
        return tuple(self._queue)

    def append(self, segment: Segment) -> None:
        """Queue a segment at the back."""
        self._queue.append(segment)

    def clear(self, hold: DesiredState | None = None) -> None:
        """Drop every segment; hold ``hold`` (default: the current desired state) meanwhile."""
        self._queue.clear()
        self._current = None
        if hold is not None:
            self._hold = hold

    def set_hold(self, state: DesiredState) -> None:
        """The state to hold while nothing is ready."""
        self._hold = state

    def advance(self, now: float) -> tuple[DesiredState | None, bool, bool]:
        """The desired state at simulated time ``now`` [s].

        Returns ``(state, waiting, started)``: ``waiting`` is True when the
        next segment exists but is not ready (the state is then the hold),
        ``started`` when a new segment began on this call. ``state`` is None
        only before anything was queued or held.

        A segment starts where the previous one ended, or at its
        ``ready_at`` if that is later: so ``ready_at`` must be no earlier than
        the moment the segment was appended.
        """
        started = False
        while True:
            if self._current is not None:
                tau = now - self._started_at
                if tau <= self._current.duration + 1e-9:
                    return self._current.sample(tau), False, started
                self._free_since = self._started_at + self._current.duration
                self._hold = self._current.last()
                self._current = None
            if not self._queue:
                return self._hold, False, started
            head = self._queue[0]
            if head.ready_at > now + 1e-9:
                return self._hold, True, started
            self._current = self._queue.popleft()
            # Consecutive footsteps share their boundary sample: the next one
            # starts where the last ended, not a tick later.
            self._started_at = max(self._free_since, head.ready_at)
            started = True

    def delay(self, dt: float) -> None:
        """Stop the playing segment's clock for ``dt`` [s]: it, and what follows, play that late.

        The next :meth:`advance` at ``now + dt`` then returns the state this
        one did (a :class:`~roughwalk.sim.lift_gate.LiftGate` hold).
        """
        if self._current is not None:
            self._started_at += dt

    def time_left(self, now: float) -> float:
        """Time [s] until the queued segments run out, from ``now``."""
        left = sum(s.duration for s in self._queue)
        if self._current is not None:
            left += max(self._current.duration - (now - self._started_at), 0.0)
        return left
