"""Where a run's clock went: per footstep, the shift, swing, stretch, settle, waits and reflexes.

The Learning Locomotion speed (Zucker 2011, §1) is the distance over the time
from the first motion to the goal. :func:`time_breakdown` splits that time,
from a :class:`~roughwalk.sim.run_log.RunLog`, by what the executor did at
each control tick:

* ``shift``: a footstep's four-foot phase (the trunk moves the centre of
  pressure into the next support triangle), as long as its fitted timing;
* ``swing``: a foot in the air, as long as its fitted timing;
* ``stretch``: the part of a shift or swing beyond its fitted timing (what
  the generator's re-timing for joint speed limits, its restarts (§5.3) and
  its fall-back to the nominal timing added; from the ``step`` events'
  ``fitted_s``);
* ``settle``: the last footstep's final four-foot phase;
* ``wait``: holding for a footstep whose optimisation has not finished;
* ``gate``: holding a footstep at its lift-off until the feet that stay
  down bear (:class:`~roughwalk.sim.lift_gate.LiftGate`, opt-in);
* ``reflex``: a reflex's recovery (the feet put down, the robot settling);
* ``replan``: standing while the re-plan's charged time runs, and the blend
  into the new plan;

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

_SHARES = ("shift", "swing", "stretch", "settle", "wait", "gate", "reflex", "replan")
_PHASES = ("shift", "swing", "settle")


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
    stretch_s: float = 0.0
    gate_s: float = 0.0

    @property
    def duration_s(self) -> float:
        """The footstep's whole time [s], stretch, waits and lift-off holds included."""
        return (
            self.shift_s + self.swing_s + self.stretch_s + self.settle_s + self.wait_s + self.gate_s
        )


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
            "mean_stretch_s": mean("stretch_s"),
            "mean_stride_m": mean("stride_m"),
            "mean_advance_m": mean("advance_m"),
        }


def _fitted_lengths(log: RunLog) -> list[tuple[float, int, tuple[float, float]]]:
    """(time [s], step, fitted (shift, swing) [s]) of every footstep's start, in time order.

    Inf where the phase was not stretched or the ``step`` event does not say
    (an older log, a footstep that was not fitted): none of that phase's
    ticks then count as stretch (a phase's ticks can outnumber its
    samples' time by one, where consecutive segments share a sample).
    """
    out = []
    for e in log.events_of("step"):
        fitted = e.get("fitted_s") or (None, None)
        stretch = e.get("stretch_s") or (0.0, 0.0)
        lengths = tuple(
            float(f) if f is not None and (s or 0.0) > 1e-9 else np.inf
            for f, s in zip(fitted[:2], stretch[:2], strict=True)
        )
        out.append((float(e["time"]), int(e.get("step") or 0), (lengths[0], lengths[1])))
    return out


def time_breakdown(log: RunLog, start_s: float, stop_s: float) -> TimeBreakdown:
    """Split the run's clock from ``start_s`` to ``stop_s`` [s] by what the executor did.

    A tick counts towards the interval it starts. The ``phase`` column tells
    a footstep's shift (0), swing (1) and settle (2) from the holds, blends
    and recoveries (:data:`~roughwalk.sim.run_log.OTHER_PHASE`); the
    ``mode`` column tells waits, recoveries and re-plans. A footstep is a
    run of ticks with one ``step`` number (the numbering restarts after a
    re-plan); the ``step`` event that started it gives its shift's and
    swing's fitted lengths (``fitted_s``), and their ticks past those count
    as ``stretch``.
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
    wait, walk, recovery = MODES.index("wait"), MODES.index("walk"), MODES.index("recovery")
    gate = MODES.index("gate")
    starts = _fitted_lengths(log)
    footsteps: list[FootstepTime] = []
    current: dict[str, Any] | None = None

    def fitted_of(number: int, now: float) -> tuple[float, float]:
        """The fitted lengths of the latest start of footstep ``number`` at or before ``now``."""
        found = (np.inf, np.inf)
        for when, n, lengths in starts:
            if when > now + 1e-9:
                break
            if n == number:
                found = lengths
        return found

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
                stretch_s=c["stretch"],
                gate_s=c["gate"],
            )
        )

    for k in np.flatnonzero(inside):
        d = float(dt[k])
        if modes[k] in (wait, gate):
            share = "wait" if modes[k] == wait else "gate"
            shares[share] += d
            if current is not None:
                current[share] += d
            continue
        if modes[k] != walk or phase[k] in (OTHER_PHASE, -1):
            shares["reflex" if modes[k] == recovery else "replan"] += d
            close(current)
            current = None
            continue
        name = _PHASES[int(phase[k])]
        if current is None or current["step"] != int(step[k]):
            close(current)
            current = dict.fromkeys(("shift", "swing", "stretch", "settle", "wait", "gate"), 0.0)
            fitted = fitted_of(int(step[k]), float(t[k]))
            current.update(
                step=int(step[k]),
                feet_start=feet[k],
                elapsed=dict.fromkeys(_PHASES, 0.0),
                fitted={"shift": fitted[0], "swing": fitted[1], "settle": np.inf},
            )
        # A phase's fitted length comes first; its ticks past that are the stretch.
        elapsed = current["elapsed"][name]
        current["elapsed"][name] = elapsed + d
        part = "stretch" if elapsed >= current["fitted"][name] - 1e-9 else name
        current[part] += d
        shares[part] += d
        current["feet_end"] = feet[k]
    close(current)
    return TimeBreakdown(float(sum(shares.values())), shares, footsteps)
