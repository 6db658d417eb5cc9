"""Phase durations of one foot: fixed numbers, or decision variables (Winkler 2018, §V-C).

When optimised, every phase but the last is a variable bounded to
[min, max] (TOWR's 0.2–1.0 s), or, with ``admit_nominal``, to that interval
widened to hold the phase's own nominal duration; the last phase takes what
is left of the total duration, so each foot's phases always sum to it.

A spline sample at time t must consider every polynomial that may hold t
(see :class:`~roughwalk.trajopt.variables.spline.NodeSpline`);
:meth:`PhaseDurations.poly_window` bounds when a polynomial can start and end
from both ends of the schedule: the phases before it at their lower or upper
bounds, and the phases after it (the last one included) no shorter than
their lower bounds and zero.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.trajopt.variables.variable_set import VariableSet

__all__ = ["PhaseDurations", "ADMIT_MARGIN"]

ADMIT_MARGIN = 0.01
"""[s] an admitted nominal phase keeps from its widened bound.

IPOPT moves a starting point that sits on a bound inside it (``bound_push``,
``bound_frac``: 1e-5 of the bound or of the interval in a learned start's
options), and the last phase absorbs the difference: the front-right foot's
first stance, held at the gait's 1.098 s on its bound, became 9 µs shorter at
0 iterations, and that plan (double pallet seed 1, task 11) fell where the
fixed-duration plan, equal to it but for those 9 µs, tracks."""


class PhaseDurations(VariableSet):
    """The phase durations [s] of foot ``foot``; symbolic when ``optimize``.

    Attributes
    ----------
    durations:
        Every phase's duration: floats, or SX expressions when optimised
        (the last one is the total minus the others).
    bounds:
        (min, max) [s] over every free phase: ``bounds`` as given, or with
        ``admit_nominal`` the widest phase's (what :meth:`poly_window`
        assumes of each, a superset of every phase's own window).

    With ``admit_nominal`` each free phase i is bounded to
    [min(min, d_i − m), max(max, d_i + m)], d_i its nominal duration and m
    :data:`ADMIT_MARGIN`, so that the nominal schedule is feasible as given
    and off every bound (the front-right foot's 1.079 s first stance of the
    16-step walk in 5.5 s against TOWR's 1.0 s).
    """

    def __init__(
        self,
        foot: int,
        durations: Sequence[float],
        bounds: tuple[float, float],
        optimize: bool,
        name: str | None = None,
        admit_nominal: bool = False,
    ) -> None:
        n = len(durations)
        super().__init__(name or f"durations_{foot}", n - 1 if optimize else 0)
        self.foot = foot
        self.nominal = [float(d) for d in durations]
        self.total = float(sum(durations))
        self.optimize = optimize
        lo, hi = bounds[0], min(bounds[1], self.total)
        if optimize:
            self.lower[:] = lo
            self.upper[:] = hi
            if admit_nominal and n > 1:
                own = np.asarray(self.nominal[:-1])
                # Never down to 0: a phase of the gait shorter than the margin keeps half of itself.
                self.lower[:] = np.minimum(lo, np.maximum(own - ADMIT_MARGIN, 0.5 * own))
                self.upper[:] = np.minimum(np.maximum(hi, own + ADMIT_MARGIN), self.total)
                lo, hi = float(self.lower.min()), float(self.upper.max())
        self.bounds = (float(lo), float(hi))
        if optimize:
            free: list[Any] = [self.symbols[i] for i in range(n - 1)]
            last = self.total - sum(free[1:], free[0]) if free else self.total
            self.durations: list[Any] = [*free, last]
        else:
            self.durations = list(self.nominal)

    @property
    def n_phases(self) -> int:
        """Number of phases of this foot."""
        return len(self.nominal)

    def poly_window(self, phase: int, index: int, count: int) -> tuple[float, float]:
        """(Earliest start, latest end) [s] of polynomial ``index`` of ``count`` in ``phase``.

        The polynomials of a phase share its duration equally. Optimised, the
        window holds for every duration within its bounds with a last phase
        of non-negative duration (the free ones sum to at most T): polynomial
        j of m in phase i starts at Σ_{l<i} d_l + j/m·d_i, at the earliest with
        every d_l at its lower bound; it ends at Σ_{l<i} d_l + (j+1)/m·d_i, at
        the latest with the earlier phases lengthened first (weight 1 before
        (j+1)/m) within the room T − (n−1)·min that the phases after it leave.
        In the last phase, which takes what the others leave, polynomial j
        starts at (1 − j/m)·S + j/m·T with S = Σ of the others, at the
        earliest with S = (n−1)·min. On the 16-step walk (T = 3.5 s, 9 phases
        of 0.2–1.0 s) these windows cut the polynomials a spline sample
        selects among by a fifth against the phases' own windows
        ((i·min, (i+1)·max)); wherever the old windows held the polynomial
        in effect, the NLP's values are the same.
        """
        j, m = index, count
        n, total = self.n_phases, self.total
        if not self.optimize:
            start = float(sum(self.nominal[:phase])) + j * self.nominal[phase] / m
            return start, start + self.nominal[phase] / m
        lo, hi = self.bounds
        if phase == n - 1:
            others = (n - 1) * lo
            return (1 - j / m) * others + j / m * total, total
        room = max(total - (n - 1) * lo, 0.0)
        before = min(room, phase * (hi - lo))
        own = min(room - before, hi - lo)
        latest = (phase + (j + 1) / m) * lo + before + (j + 1) / m * own
        return (phase + j / m) * lo, min(latest, total)

    def pack(self, durations: ArrayLike) -> NDArray[np.float64]:
        """Variables from all phase durations [s] (the last one is implied)."""
        d = np.asarray(durations, dtype=float)
        return d[: self.size].copy()

    def unpack(self, values: ArrayLike) -> NDArray[np.float64]:
        """All phase durations [s] from this set's variables."""
        if not self.optimize:
            return np.asarray(self.nominal)
        v = np.asarray(values, dtype=float)
        return np.concatenate([v, [self.total - v.sum()]])
