"""``single_pallet`` and ``double_pallet``: the ledges of Melon et al. 2020, §V.

A single pallet is a standard 1.2 m × 1 m industrial pallet with plywood on
top, 16.5 cm high in total; the double pallet is two steps of 14.5 cm and
16.5 cm whose edges are 40 cm apart. We place the pallet's near edge at
x = 1 m and centre it on y = 0, in an open field of flat ground.
"""

from __future__ import annotations

from dataclasses import dataclass

from roughwalk.errors import TerrainError
from roughwalk.terrain.generators.grid import FieldParams, in_box
from roughwalk.terrain.generators.registry import param, register
from roughwalk.terrain.terrain import Terrain

__all__ = ["SinglePalletParams", "DoublePalletParams", "single_pallet", "double_pallet"]


@dataclass(frozen=True)
class SinglePalletParams(FieldParams):
    """One box on flat ground: x ∈ [start, start + length], y ∈ [−width/2, width/2]."""

    start: float = param(1.0, "m", "x of the pallet's near edge")
    length: float = param(1.2, "m", "pallet size along x", "positive")
    width: float = param(1.0, "m", "pallet size along y (centred on y = 0)", "positive")
    height: float = param(0.165, "m", "pallet height, plywood included", "positive")


@dataclass(frozen=True)
class DoublePalletParams(FieldParams):
    """A first box and a second, shorter one on top of it, flush with its far edge."""

    start: float = param(1.0, "m", "x of the lower pallet's near edge")
    length: float = param(1.2, "m", "lower pallet size along x", "positive")
    width: float = param(1.0, "m", "pallet size along y (centred on y = 0)", "positive")
    height: float = param(0.145, "m", "lower pallet height", "positive")
    top_offset: float = param(0.4, "m", "distance from the lower to the upper edge", "positive")
    top_height: float = param(0.165, "m", "upper pallet height (above the lower one)", "positive")

    def validate(self) -> None:
        """Check that the upper pallet sits on the lower one."""
        super().validate()
        if self.top_offset >= self.length:
            raise TerrainError(
                f"parameter 'top_offset' ({self.top_offset} m) must be shorter than "
                f"'length' ({self.length} m), or the upper pallet has nothing to stand on"
            )


@register(
    "single_pallet",
    SinglePalletParams,
    "a 1.2 m × 1.0 m × 0.165 m pallet from x = 1.0 m (Melon et al. 2020)",
    "pallets",
)
def single_pallet(params: SinglePalletParams) -> Terrain:
    """Place a pallet [m] in an open field."""
    grid = params.grid()
    z = grid.zeros()
    half = params.width / 2
    z[in_box(grid, params.start, params.start + params.length, -half, half)] = params.height
    return grid.terrain(z)


@register(
    "double_pallet",
    DoublePalletParams,
    "two stacked pallets, 0.145 m then 0.31 m high, edges 0.4 m apart (Melon et al. 2020)",
    "pallets",
)
def double_pallet(params: DoublePalletParams) -> Terrain:
    """Place two stacked pallets [m] in an open field."""
    grid = params.grid()
    z = grid.zeros()
    half = params.width / 2
    end = params.start + params.length
    z[in_box(grid, params.start, end, -half, half)] = params.height
    top = in_box(grid, params.start + params.top_offset, end, -half, half)
    z[top] = params.height + params.top_height
    return grid.terrain(z)
