"""Trunk height and orientation between pose certificates (Zucker 2011, §5.2).

"The CoM trajectory output by the 2D ZMP preview controller does not specify
body height or orientation, so we independently use splines connecting the
certificate poses to fill in this information." Between consecutive
keyframes each coordinate follows the quintic smoothstep 10s³ − 15s⁴ + 6s⁵
(C², at rest at every keyframe); a keyframe repeated holds the pose, as the
trunk's height and tilt do during a swing.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["BodySpline"]


class BodySpline:
    """Smoothstep interpolation of keyframe values (K, m) at increasing times (K,) [s].

    Orientation keyframes are roll–pitch–yaw [rad]; give them unwrapped
    (consecutive yaws differing by less than π).
    """

    def __init__(self, times: ArrayLike, values: ArrayLike) -> None:
        t = np.asarray(times, dtype=float)
        v = np.asarray(values, dtype=float)
        if v.ndim == 1:
            v = v[:, None]
        if t.ndim != 1 or t.shape[0] < 1 or v.shape[0] != t.shape[0]:
            raise InvalidArgumentError(
                f"body spline needs K times and K values, got {t.shape} and {v.shape}"
            )
        if np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)) or not np.all(np.isfinite(v)):
            raise InvalidArgumentError(f"keyframe times must increase and be finite, got {t}")
        self.times = t
        self.values = v

    def evaluate(
        self, t: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Values, rates and second rates (n, m) at times t [s]; held beyond the ends."""
        tt = np.asarray(t, dtype=float)
        m = self.values.shape[1]
        if self.times.shape[0] == 1:
            zero = np.zeros((tt.shape[0], m))
            return np.broadcast_to(self.values[0], (tt.shape[0], m)).copy(), zero, zero.copy()
        tc = np.clip(tt, self.times[0], self.times[-1])
        i = np.clip(np.searchsorted(self.times, tc, side="right") - 1, 0, len(self.times) - 2)
        h = (self.times[i + 1] - self.times[i])[:, None]
        s = ((tc - self.times[i])[:, None]) / h
        outside = ((tt < self.times[0]) | (tt > self.times[-1]))[:, None]
        dv = self.values[i + 1] - self.values[i]
        s2 = s * s
        blend = s2 * s * (10 - 15 * s + 6 * s2)
        rate = 30 * s2 * (1 - s) ** 2 / h
        curve = 60 * s * (1 - s) * (1 - 2 * s) / (h * h)
        value = self.values[i] + blend * dv
        return value, np.where(outside, 0.0, rate * dv), np.where(outside, 0.0, curve * dv)

    def value(self, t: ArrayLike) -> NDArray[np.float64]:
        """Values (n, m) at times t [s]."""
        return self.evaluate(t)[0]
