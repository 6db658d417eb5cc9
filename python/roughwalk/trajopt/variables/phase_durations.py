"""Phase durations of one foot: fixed numbers, or decision variables (Winkler 2018, §V-C).

When optimised, every phase but the last is a variable bounded to
[min, max] (TOWR's 0.2–1.0 s); the last phase takes what is left of the total
duration, so each foot's phases always sum to it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.trajopt.variables.variable_set import VariableSet

__all__ = ["PhaseDurations"]


class PhaseDurations(VariableSet):
    """The phase durations [s] of foot ``foot``; symbolic when ``optimize``.

    Attributes
    ----------
    durations:
        Every phase's duration: floats, or SX expressions when optimised
        (the last one is the total minus the others).
    windows:
        Per phase, (earliest start, latest end) [s] that the variable bounds allow.

    """

    def __init__(
        self,
        foot: int,
        durations: Sequence[float],
        bounds: tuple[float, float],
        optimize: bool,
        name: str | None = None,
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
            free: list[Any] = [self.symbols[i] for i in range(n - 1)]
            last = self.total - sum(free[1:], free[0]) if free else self.total
            self.durations: list[Any] = [*free, last]
            self.windows = [
                (i * lo, min((i + 1) * hi, self.total) if i < n - 1 else self.total)
                for i in range(n)
            ]
        else:
            self.durations = list(self.nominal)
            ends = np.cumsum(self.nominal)
            self.windows = [
                (float(e - d), float(e)) for e, d in zip(ends, self.nominal, strict=True)
            ]

    @property
    def n_phases(self) -> int:
        """Number of phases of this foot."""
        return len(self.nominal)

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
