"""TOWR's test terrains (``towr/terrain/examples/height_map_examples``), same numbers.

These are the height maps TOWR's examples optimise over, so that our
trajectory optimiser and TOWR can be compared on the same problem (Melon et
al. 2020 build on TOWR). Every one varies only along x and is flat ground at
z = 0 elsewhere:

* ``towr_block``: a 0.5 m block from x = 0.7 m, 3.5 m long, entered by a
  3 cm-long ramp (TOWR smooths the edge that way for its gradients);
* ``towr_stairs``: 0.2 m from x = 1.0 m for 0.4 m, then 0.4 m for 1.0 m,
  then back to 0;
* ``towr_gap``: a parabolic dip z = a·(x − x₀)(x − x₁) from x₀ = 1.0 m to
  x₁ = 1.5 m, 1.5 m deep in the middle. (The TOWR header we checked uses a
  0.6 m-wide gap; set ``width=0.6`` to match that version.)
* ``towr_slope``: from x = 1.0 m up 0.7 m over 1 m, then down over 1 m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roughwalk.terrain.generators.grid import EDGE_TOLERANCE, FieldParams
from roughwalk.terrain.generators.registry import param, register
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "TowrBlockParams",
    "TowrStairsParams",
    "TowrGapParams",
    "TowrSlopeParams",
    "towr_block",
    "towr_stairs",
    "towr_gap",
    "towr_slope",
]


def _profile(params: FieldParams, z_of_x: NDArray[np.float64]) -> Terrain:
    grid = params.grid()
    return grid.terrain(np.repeat(z_of_x[:, None], grid.ny, axis=1))


@dataclass(frozen=True)
class TowrBlockParams(FieldParams):
    """TOWR's ``Block``."""

    start: float = param(0.7, "m", "x where the ramp up to the block begins")
    length: float = param(3.5, "m", "block length along x, ramp included", "positive")
    height: float = param(0.5, "m", "block height", "positive")
    ramp: float = param(0.03, "m", "length of the ramp at the leading edge", "positive")


@register(
    "towr_block",
    TowrBlockParams,
    "TOWR's block: 0.5 m high from x = 0.7 m, 3.5 m long, 3 cm ramp",
    "towr",
)
def towr_block(params: TowrBlockParams) -> Terrain:
    """Build TOWR's block [m]."""
    x = params.grid().x
    t = EDGE_TOLERANCE
    rise = np.clip((x - params.start) / params.ramp, 0.0, 1.0) * params.height
    on = (x >= params.start - t) & (x <= params.start + params.length + t)
    return _profile(params, np.where(on, rise, 0.0))


@dataclass(frozen=True)
class TowrStairsParams(FieldParams):
    """TOWR's ``Stairs``: two steps up, then straight back down to the ground."""

    start: float = param(1.0, "m", "x of the first step's edge")
    first_length: float = param(0.4, "m", "first step length along x", "positive")
    first_height: float = param(0.2, "m", "first step height")
    second_length: float = param(1.0, "m", "second (top) step length along x", "positive")
    second_height: float = param(0.4, "m", "second step height")


@register(
    "towr_stairs",
    TowrStairsParams,
    "TOWR's stairs: 0.2 m from x = 1.0 m, 0.4 m from 1.4 m to 2.4 m, then 0",
    "towr",
)
def towr_stairs(params: TowrStairsParams) -> Terrain:
    """Build TOWR's stairs [m]."""
    x = params.grid().x
    t = EDGE_TOLERANCE
    second = params.start + params.first_length
    end = second + params.second_length
    z = np.zeros_like(x)
    z[x >= params.start - t] = params.first_height
    z[x >= second - t] = params.second_height
    z[x >= end - t] = 0.0
    return _profile(params, z)


@dataclass(frozen=True)
class TowrGapParams(FieldParams):
    """TOWR's ``Gap``: a parabolic dip, zero at both edges."""

    start: float = param(1.0, "m", "x where the gap begins")
    width: float = param(0.5, "m", "gap width along x", "positive")
    depth: float = param(1.5, "m", "depth at the middle of the gap", "positive")


@register(
    "towr_gap",
    TowrGapParams,
    "TOWR's gap: a parabolic dip from x = 1.0 m to 1.5 m, 1.5 m deep",
    "towr",
)
def towr_gap(params: TowrGapParams) -> Terrain:
    """Build TOWR's gap [m]."""
    x = params.grid().x
    x0, x1 = params.start, params.start + params.width
    # a chosen so that the vertex, at the middle, is at −depth.
    a = 4.0 * params.depth / params.width**2
    z = np.where((x >= x0) & (x <= x1), a * (x - x0) * (x - x1), 0.0)
    return _profile(params, z)


@dataclass(frozen=True)
class TowrSlopeParams(FieldParams):
    """TOWR's ``Slope``: a triangular ridge."""

    start: float = param(1.0, "m", "x where the slope begins")
    up_length: float = param(1.0, "m", "length of the way up", "positive")
    down_length: float = param(1.0, "m", "length of the way down", "positive")
    height: float = param(0.7, "m", "height of the ridge", "positive")


@register(
    "towr_slope",
    TowrSlopeParams,
    "TOWR's slope: from x = 1.0 m up 0.7 m over 1 m, then down over 1 m",
    "towr",
)
def towr_slope(params: TowrSlopeParams) -> Terrain:
    """Build TOWR's slope [m]."""
    x = params.grid().x
    peak = params.start + params.up_length
    up = params.height * (x - params.start) / params.up_length
    down = params.height * (1.0 - (x - peak) / params.down_length)
    z = np.clip(np.minimum(up, down), 0.0, None)
    return _profile(params, z)
