"""The terrain cost the footstep planner uses: c = exp(−w·f) per foothold (Zucker 2011, §4.2).

The planner needs only ``cost_map(terrain, heading=None, leg="front"|"hind")``
→ an (nx, ny) grid aligned with ``terrain.x``/``terrain.y`` (+inf where a
foot may not go), which :class:`~roughwalk.planning.terrain_cost.TerrainCost`
provides. :func:`default_terrain_cost` is the one the planner uses when
given none: the cost learned from preferences and shipped with roughwalk.
:func:`hand_set_terrain_cost` is the hand-set weight vector the planner
shipped with before the learned cost existed, kept as a reference point.
"""

from __future__ import annotations

from pathlib import Path
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from roughwalk.planning.terrain_cost import TerrainCost
from roughwalk.terrain.features import FEATURE_NAMES
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "FootholdCost",
    "default_terrain_cost",
    "hand_set_terrain_cost",
    "load_terrain_cost",
]


class FootholdCost(Protocol):
    """What the footstep planner asks of a terrain cost."""

    def cost_map(
        self, terrain: Terrain, heading: float | None = None, leg: str = "front"
    ) -> NDArray[np.float64]:
        """Cost of every grid cell of ``terrain`` (nx, ny); +inf where no foot may go."""
        ...


def default_terrain_cost() -> TerrainCost:
    """The cost learned from the shipped preferences (``TerrainCost.load()``)."""
    return TerrainCost.load()


def load_terrain_cost(path: str | Path | None) -> TerrainCost:
    """A terrain-cost file (``roughwalk cost learn`` writes them); None gives the default."""
    return default_terrain_cost() if path is None else TerrainCost.load(path)


def hand_set_terrain_cost() -> TerrainCost:
    """A hand-set w over the 2 cm and 4 cm fits: slopes, domes, bumps and deep holes cost more.

    With c = exp(−w·f) and flat ground f = 0 → c = 1: a 30 % slope costs
    exp(3·0.3) ≈ 2.5, a dome of curvature 10 /m exp(0.1·10) ≈ 2.7, a fit
    residual of 5 mm exp(0.005·300) ≈ 4.5.
    """
    radii = (0.02, 0.04)
    w = np.zeros(len(FEATURE_NAMES) * len(radii))
    index = {name: k for k, name in enumerate(FEATURE_NAMES)}
    for r, scale in enumerate((1.0, 0.5)):
        base = r * len(FEATURE_NAMES)
        w[base + index["grad_norm"]] = -3.0 * scale
        # A dome (negative least curvature) costs more; a cup slightly less.
        w[base + index["lambda_min"]] = 0.1 * scale
        w[base + index["lambda_max"]] = -0.05 * scale
        w[base + index["residual"]] = -300.0 * scale
    return TerrainCost(
        {"front": w, "hind": w},
        radii,
        metadata={"source": "hand-set weights (roughwalk.planning.footstep_cost)"},
    )
