"""Stability as a CHOMP term: the cart-table ZMP kept inside the support polygon.

Zucker 2011, §5.3 adds a static-stability gradient "analogously to
collision". The body pass moves the trunk, so the CoM moves with it; here the
criterion is the one the trajectory was planned with (§5.2), the ZMP of the
cart-table, p = c − (z_c/g)·c̈, which is the CoM itself when the trunk is at
rest. With the CoM's offset from the trunk o held from the initial
trajectory, c = x + o and c̈ from central differences, the term

    ½·w·h·Σ_t max(0, m* − margin(p_t))²

is a smooth function of the trunk path whose gradient is exact.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories.support_polygon import polygon_margin

__all__ = ["ZmpSupportCost"]


class ZmpSupportCost:
    """The support term of a trunk path sampled every ``dt`` [s].

    Parameters
    ----------
    polygons:
        The distinct support polygons (CCW (k, 2) [m]).
    polygon_index:
        (T,) which polygon supports each sample.
    offset:
        (T, 2) CoM minus trunk position, x–y [m].
    offset_acceleration:
        (T, 2) its second derivative [m/s²].
    com_height:
        z_c [m] above the support.
    dt:
        Sample period [s].
    margin:
        m* [m], the margin asked for.
    weight:
        w·h: the factor on the sum (h the normalised sample spacing).
    gravity:
        g [m/s²].
    """

    def __init__(
        self,
        polygons: Sequence[ArrayLike],
        polygon_index: ArrayLike,
        offset: ArrayLike,
        offset_acceleration: ArrayLike,
        com_height: float,
        dt: float,
        margin: float,
        weight: float,
        gravity: float = 9.81,
    ) -> None:
        self.polygons = [np.asarray(p, dtype=float) for p in polygons]
        self.index = np.asarray(polygon_index, dtype=np.int64)
        if self.index.size and (self.index.min() < 0 or self.index.max() >= len(self.polygons)):
            raise InvalidArgumentError("polygon_index refers to a polygon that was not given")
        self.offset = np.asarray(offset, dtype=float)
        self.offset_acceleration = np.asarray(offset_acceleration, dtype=float)
        self.k = float(com_height) / gravity
        self.dt = float(dt)
        self.margin = float(margin)
        self.weight = float(weight)

    def zmp(self, base_xy: ArrayLike) -> NDArray[np.float64]:
        """ZMP (T − 2, 2) [m] at the interior samples of the trunk path (T, 2)."""
        x = np.asarray(base_xy, dtype=float)
        acc = (x[2:] - 2 * x[1:-1] + x[:-2]) / self.dt**2 + self.offset_acceleration[1:-1]
        return x[1:-1] + self.offset[1:-1] - self.k * acc

    def margins(self, zmp: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Margins (T − 2,) [m] of interior ZMPs to their polygons, and gradients (T − 2, 2)."""
        p = np.asarray(zmp, dtype=float)
        idx = self.index[1:-1]
        m = np.empty(p.shape[0])
        g = np.empty((p.shape[0], 2))
        for k in np.unique(idx):
            sel = idx == k
            m[sel], g[sel] = polygon_margin(p[sel], self.polygons[k])
        return m, g

    def evaluate(
        self, base_xy: ArrayLike
    ) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
        """Value, gradient w.r.t. the interior trunk x–y (T − 2, 2), and the margins (T − 2,)."""
        p = self.zmp(base_xy)
        m, gm = self.margins(p)
        short = np.maximum(self.margin - m, 0.0)
        value = 0.5 * self.weight * float(np.sum(short**2))
        g_p = np.zeros((p.shape[0] + 2, 2))
        g_p[1:-1] = -self.weight * short[:, None] * gm
        c = self.k / self.dt**2
        grad = g_p[1:-1] - c * (g_p[:-2] - 2 * g_p[1:-1] + g_p[2:])
        return value, grad, m
