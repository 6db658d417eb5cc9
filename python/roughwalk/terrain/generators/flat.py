"""``flat``: level ground on the LittleDog course, the baseline every planner must walk."""

from __future__ import annotations

from dataclasses import dataclass

from roughwalk.terrain.generators.grid import CourseParams
from roughwalk.terrain.generators.registry import param, register
from roughwalk.terrain.terrain import Terrain

__all__ = ["FlatParams", "flat"]


@dataclass(frozen=True)
class FlatParams(CourseParams):
    """Level ground over the whole course (the pads are simply part of it)."""

    height: float = param(0.0, "m", "height of the ground")


@register("flat", FlatParams, "level ground, 2 m × 0.6 m (LittleDog course)", "littledog")
def flat(params: FlatParams) -> Terrain:
    """Make level ground at ``params.height`` [m] over the course."""
    grid = params.grid()
    return grid.terrain(grid.zeros() + params.height)
