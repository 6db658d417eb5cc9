"""The terrain the simulated robot stands on: the planner's terrain, grown to cover the motion.

A terrain spec can be smaller than the motion planned over it (``flat`` is
2 m × 0.6 m, while ANYmal C's hind feet start 0.45 m behind its base). The
trajectory optimiser's terrain model holds the edge heights beyond the grid;
the simulation must do the same, or the feet would step off the world.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from roughwalk.terrain.terrain import Terrain

__all__ = ["terrain_covering"]


def terrain_covering(terrain: Terrain, points: ArrayLike, margin: float = 0.75) -> Terrain:
    """``terrain`` padded with its edge heights to cover ``points`` (n, ≥2) [m] plus ``margin`` [m].

    Returns ``terrain`` itself when it already covers them.
    """
    xy = np.asarray(points, dtype=float).reshape(-1, np.shape(points)[-1])[:, :2]
    x_lo, x_hi, y_lo, y_hi = terrain.extent
    want_x = (xy[:, 0].min() - margin, xy[:, 0].max() + margin)
    want_y = (xy[:, 1].min() - margin, xy[:, 1].max() + margin)
    before_x = max(0, math.ceil((x_lo - want_x[0]) / terrain.dx))
    after_x = max(0, math.ceil((want_x[1] - x_hi) / terrain.dx))
    before_y = max(0, math.ceil((y_lo - want_y[0]) / terrain.dy))
    after_y = max(0, math.ceil((want_y[1] - y_hi) / terrain.dy))
    if before_x == after_x == before_y == after_y == 0:
        return terrain
    heights = np.pad(terrain.heights, ((before_x, after_x), (before_y, after_y)), mode="edge")
    return Terrain(
        heights,
        terrain.x0 - before_x * terrain.dx,
        terrain.y0 - before_y * terrain.dy,
        terrain.dx,
        terrain.dy,
        name=terrain.name,
        spec=terrain.spec,
    )
