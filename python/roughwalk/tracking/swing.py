"""Swing-foot trajectories over the real terrain, to footholds clear of step edges.

The optimiser plans footholds and swing splines against a smoothed terrain
(TOWR's terrain model; here a quartic B-spline): near a pallet's edge the
planned foot can sit in mid-air over the lower level or inside the riser,
and the planned swing can cut the edge. A controller that tracks those
splines stubs the foot on the riser or lands it on the corner, from which it
slides off. :class:`SwingPlanner` keeps the planned timing and the planned
foothold's neighbourhood but (1) moves a foothold whose foot would straddle
an edge to the nearest flat spot of the same level (Bellicoso et al.'s
controller, which Melon et al. 2020 §V used, likewise takes footholds and
makes its own swing motions) and (2) lifts the foot above everything between
lift-off and touchdown before moving it across: rise, move over, descend.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    from roughwalk.terrain.terrain import Terrain

__all__ = ["SwingPlanner", "SwingTrajectory", "minimum_jerk"]


def minimum_jerk(x: float) -> tuple[float, float, float]:
    """s(x) = 10x³ − 15x⁴ + 6x⁵ on [0, 1] (clamped outside) and its first two derivatives."""
    if x <= 0.0:
        return 0.0, 0.0, 0.0
    if x >= 1.0:
        return 1.0, 0.0, 0.0
    x2 = x * x
    return (
        x2 * x * (10.0 - 15.0 * x + 6.0 * x2),
        30.0 * x2 * (1.0 - 2.0 * x + x2),
        60.0 * x * (1.0 - 3.0 * x + 2.0 * x2),
    )


@dataclass(frozen=True)
class SwingTrajectory:
    """One swing from ``start`` to ``target`` (3,) [m] over [t0, t1] [s], at ``apex`` [m] height.

    The foot rises during the first ``rise`` of the swing, moves across
    between ``move`` = (begin, end) fractions, and descends during the rest
    after ``1 − descend``.
    """

    start: NDArray[np.float64]
    target: NDArray[np.float64]
    t0: float
    t1: float
    apex: float
    rise: float = 0.35
    move: tuple[float, float] = (0.25, 0.85)
    descend: float = 0.45

    def __call__(
        self, t: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Position [m], velocity [m/s] and acceleration [m/s²] at ``t`` [s]."""
        span = max(self.t1 - self.t0, 1e-6)
        s = (t - self.t0) / span
        a, b = self.move
        u, du, ddu = minimum_jerk((s - a) / (b - a))
        k = 1.0 / ((b - a) * span)
        delta = self.target - self.start
        pos = self.start + u * delta
        vel = du * k * delta
        acc = ddu * k * k * delta
        z0, z1 = float(self.start[2]), float(self.target[2])
        if s < 1.0 - self.descend:
            v, dv, ddv = minimum_jerk(s / self.rise)
            k = 1.0 / (self.rise * span)
            lo, hi = z0, self.apex
        else:
            v, dv, ddv = minimum_jerk((s - 1.0 + self.descend) / self.descend)
            k = 1.0 / (self.descend * span)
            lo, hi = self.apex, z1
        pos[2] = lo + v * (hi - lo)
        vel[2] = dv * k * (hi - lo)
        acc[2] = ddv * k * k * (hi - lo)
        return pos, vel, acc


class SwingPlanner:
    """Edge-safe footholds and terrain-clearing swings on ``terrain``.

    Parameters
    ----------
    terrain:
        The terrain the robot really walks on.
    foot_radius:
        Foot sphere radius [m].
    clearance:
        Height [m] the foot's lowest point keeps above the highest terrain
        between lift-off and touchdown.
    edge_margin:
        A foothold is flat when the terrain under a disk of foot radius plus
        this [m] varies by at most ``flatness`` [m].
    flatness:
        See ``edge_margin`` [m].
    max_shift:
        Farthest [m] a foothold moves to get off an edge.
    """

    def __init__(
        self,
        terrain: Terrain,
        foot_radius: float,
        clearance: float = 0.08,
        edge_margin: float = 0.03,
        flatness: float = 0.01,
        max_shift: float = 0.10,
    ) -> None:
        self.terrain = terrain
        self.clearance = clearance
        self.flatness = flatness
        radius = foot_radius + edge_margin
        angles = np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False)
        ring = np.stack([np.cos(angles), np.sin(angles)], axis=1)
        self._disk = np.vstack([[0.0, 0.0], radius * ring, 0.5 * radius * ring])
        rings = np.arange(0.01, max_shift + 1e-9, 0.01)
        dirs = np.stack(
            [
                np.cos(np.linspace(0, 2 * math.pi, 16, endpoint=False)),
                np.sin(np.linspace(0, 2 * math.pi, 16, endpoint=False)),
            ],
            axis=1,
        )
        self._offsets = np.vstack([[0.0, 0.0], (rings[:, None, None] * dirs[None]).reshape(-1, 2)])
        self._side = foot_radius + 0.02

    def foothold(self, planned: ArrayLike, shift: ArrayLike | None = None) -> NDArray[np.float64]:
        """Where [m] to land for the ``planned`` (3,) foothold: off edges, on the ground.

        ``shift`` (3,) [m] is a correction added to the planned foothold (the
        controller's Raibert shift); it is dropped when it would put the foot
        on another level than the planned foothold's own (a foothold near a
        pallet's side edge shifted over it lands 0.3 m lower, beside the pallet).
        """
        p = np.asarray(planned, dtype=float)
        if shift is None:
            return self._flat_spot(p)
        own = self._flat_spot(p)
        shifted = self._flat_spot(p + np.asarray(shift, dtype=float))
        return shifted if abs(shifted[2] - own[2]) <= 2.0 * self.flatness else own

    def _flat_spot(self, p: NDArray[np.float64]) -> NDArray[np.float64]:
        """The nearest flat spot [m] around ``p`` (3,), on the terrain's level at ``p`` if any."""
        level = float(self.terrain.height(p[None, :2])[0])
        centres = p[:2] + self._offsets
        points = (centres[:, None, :] + self._disk[None]).reshape(-1, 2)
        heights = self.terrain.height(points).reshape(len(centres), len(self._disk))
        spread = heights.max(axis=1) - heights.min(axis=1)
        flat = spread <= self.flatness
        if flat[0]:
            return np.array([p[0], p[1], heights[0, 0]])
        if not flat.any():
            return np.array([p[0], p[1], heights[0].max()])
        distance = np.linalg.norm(self._offsets, axis=1)
        other_level = np.abs(heights[:, 0] - level) > 2.0 * self.flatness
        cost = np.where(flat, distance + other_level * 1.0, np.inf)
        best = int(np.argmin(cost))
        return np.array([centres[best, 0], centres[best, 1], heights[best, 0]])

    def swing(self, start: ArrayLike, target: ArrayLike, t0: float, t1: float) -> SwingTrajectory:
        """A swing from ``start`` to ``target`` (3,) [m] between ``t0`` and ``t1`` [s]."""
        a = np.asarray(start, dtype=float)
        b = np.asarray(target, dtype=float)
        s = np.linspace(0.0, 1.0, 21)[:, None]
        line = a[:2] + s * (b[:2] - a[:2])
        d = b[:2] - a[:2]
        n = np.linalg.norm(d)
        side = np.array([-d[1], d[0]]) / n if n > 1e-9 else np.array([0.0, 1.0])
        points = np.vstack([line, line + self._side * side, line - self._side * side])
        top = float(self.terrain.height(points).max())
        apex = max(float(a[2]), float(b[2]), top) + self.clearance
        return SwingTrajectory(a, b, t0, t1, apex)
