"""Where a run's clock went: per footstep, the shift, swing, settle, waits and reflexes.

The Learning Locomotion speed (Zucker 2011, §1) is the distance over the time
from the first motion to the goal. :func:`time_breakdown` splits that time,
from a :class:`~roughwalk.sim.run_log.RunLog`, by what the executor did at
each control tick:

* ``shift``: a footstep's four-foot phase (the trunk moves the centre of
  pressure into the next support triangle);
* ``swing``: a foot in the air;
* ``settle``: the last footstep's final four-foot phase;
* ``wait``: holding for a footstep whose optimisation has not finished;
* ``reflex``: a reflex's recovery, the re-plan and the blend into the new
  plan (the robot stands or puts its feet down);

and gives each footstep's stride: how far its swing foot moved (x–y) and how
far the feet's centroid advanced. Speed is stride over footstep time, so the
breakdown tells which phase a faster walk has to shorten.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from roughwalk.sim.run_log import MODES, OTHER_PHASE, RunLog

__all__ = ["FootstepTime", "TimeBreakdown", "time_breakdown"]

_SHARES = ("shift", "swing", "settle", "wait", "reflex")


@dataclass(frozen=True)
class FootstepTime:
    """One footstep's times [s] and stride [m]."""

    step: int
    shift_s: float
    swing_s: float
    settle_s: float
    wait_s: float
    stride_m: float
    advance_m: float

    @property
    def duration_s(self) -> float:
        """The footstep's whole time [s], waits included."""
        return self.shift_s + self.swing_s + self.settle_s + self.wait_s


@dataclass(frozen=True)
class TimeBreakdown:
    """Totals [s] of each share of a run's clock, and the footsteps that made it.

    ``total_s`` is the time from the first motion to the goal (or the end):
    the sum of the shares.
    """

    total_s: float
    shares_s: dict[str, float]
    footsteps: list[FootstepTime] = field(default_factory=list)

    def summary(self) -> dict[str, Any]:
        """JSON-ready totals, fractions and means per footstep (small: no per-step list)."""
        n = len(self.footsteps)
        total = max(self.total_s, 1e-12)

        def mean(name: str) -> float | None:
            return float(np.mean([getattr(f, name) for f in self.footsteps])) if n else None

        return {
            "total_s": self.total_s,
            "footsteps": n,
            **{f"{k}_s": v for k, v in self.shares_s.items()},
            **{f"{k}_fraction": v / total for k, v in self.shares_s.items()},
            "mean_shift_s": mean("shift_s"),
            "mean_swing_s": mean("swing_s"),
            "mean_stride_m": mean("stride_m"),
            "mean_advance_m": mean("advance_m"),
        }


def time_breakdown(log: RunLog, start_s: float, stop_s: float) -> TimeBreakdown:
    """Split the run's clock from ``start_s`` to ``stop_s`` [s] by what the executor did.

    A tick counts towards the interval it starts. The ``phase`` column tells
    a footstep's shift (0), swing (1) and settle (2) from the holds, blends
    and recoveries (:data:`~roughwalk.sim.run_log.OTHER_PHASE`); the
    ``mode`` column tells waits and reflexes. A footstep is a run of ticks
    with one ``step`` number (the numbering restarts after a re-plan).
    """
    t = np.asarray(log["time"], dtype=float)
    shares = dict.fromkeys(_SHARES, 0.0)
    if len(t) < 2 or "phase" not in log.arrays or not stop_s > start_s:
        return TimeBreakdown(max(stop_s - start_s, 0.0), shares)
    dt = np.diff(t, append=t[-1])
    inside = (t >= start_s - 1e-9) & (t < stop_s - 1e-9)
    modes = np.asarray(log["mode"])
    phase = np.asarray(log["phase"])
    step = np.asarray(log["step"])
    feet = np.asarray(log["feet_desired"], dtype=float)
    wait, walk = MODES.index("wait"), MODES.index("walk")
    footsteps: list[FootstepTime] = []
    current: dict[str, Any] | None = None

    def close(c: dict[str, Any] | None) -> None:
        if c is None:
            return
        moved = np.linalg.norm(c["feet_end"][:, :2] - c["feet_start"][:, :2], axis=1)
        centroid = c["feet_end"][:, :2].mean(axis=0) - c["feet_start"][:, :2].mean(axis=0)
        footsteps.append(
            FootstepTime(
                step=c["step"],
                shift_s=c["shift"],
                swing_s=c["swing"],
                settle_s=c["settle"],
                wait_s=c["wait"],
                stride_m=float(np.nanmax(moved)),
                advance_m=float(np.linalg.norm(centroid)),
            )
        )

    for k in np.flatnonzero(inside):
        d = float(dt[k])
        if modes[k] == wait:
            shares["wait"] += d
            if current is not None:
                current["wait"] += d
            continue
        if modes[k] != walk or phase[k] in (OTHER_PHASE, -1):
            shares["reflex"] += d
            close(current)
            current = None
            continue
        name = ("shift", "swing", "settle")[int(phase[k])]
        shares[name] += d
        if current is None or current["step"] != int(step[k]):
            close(current)
            current = dict.fromkeys(("shift", "swing", "settle", "wait"), 0.0)
            current.update(step=int(step[k]), feet_start=feet[k])
        current[name] += d
        current["feet_end"] = feet[k]
    close(current)
    return TimeBreakdown(float(sum(shares.values())), shares, footsteps)
