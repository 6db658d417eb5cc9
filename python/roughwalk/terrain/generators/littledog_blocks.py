"""LittleDog-scale courses of blocks: gap, barrier, steps, stairs, stepping stones.

All share the 2 m × 0.6 m course with flat pads at both ends:

* ``gap``: a flat-bottomed trench across the course;
* ``barrier``: a wall across the course, to be stepped over;
* ``steps``: blocks up, a plateau, and blocks back down;
* ``stairs``: steps rising to the end pad, which stays at the top;
* ``stepping_stones``: flat-topped columns over a pit whose floor is
  ``floor_depth`` below the pads (measured ground, not unknown cells).

Only ``stepping_stones`` is random; the others are fixed by their parameters.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from roughwalk.errors import TerrainError
from roughwalk.terrain.generators.grid import CourseParams, RandomCourseParams, in_box
from roughwalk.terrain.generators.registry import param, register
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "GapParams",
    "BarrierParams",
    "StepsParams",
    "StairsParams",
    "SteppingStonesParams",
    "gap",
    "barrier",
    "steps",
    "stairs",
    "stepping_stones",
]


def _check_span(params: CourseParams, start: float, end: float, what: str) -> None:
    """Raise unless [start, end] [m] lies between the pads."""
    eps = 1e-9
    if start < params.feature_start - eps or end > params.feature_end + eps:
        raise TerrainError(
            f"{what} spans x = {start:.3f} .. {end:.3f} m, outside the space between the pads "
            f"({params.feature_start:.3f} .. {params.feature_end:.3f} m); move 'center', "
            f"shrink it or shorten 'pad_start'/'pad_end'"
        )


@dataclass(frozen=True)
class GapParams(CourseParams):
    """A trench across the course."""

    center: float = param(1.0, "m", "x of the middle of the gap")
    gap_width: float = param(0.12, "m", "gap width along x", "positive")
    depth: float = param(0.1, "m", "depth of the trench floor below the pads", "positive")

    def validate(self) -> None:
        """Check that the gap lies between the pads."""
        super().validate()
        half = self.gap_width / 2
        _check_span(self, self.center - half, self.center + half, "the gap ('gap_width')")


@register("gap", GapParams, "a 12 cm-wide, 10 cm-deep trench across the course", "littledog")
def gap(params: GapParams) -> Terrain:
    """Cut a trench [m] across the course."""
    grid = params.grid()
    z = grid.zeros()
    half = params.gap_width / 2
    z[in_box(grid, params.center - half, params.center + half)] = -params.depth
    return grid.terrain(z)


@dataclass(frozen=True)
class BarrierParams(CourseParams):
    """A wall across the course."""

    center: float = param(1.0, "m", "x of the middle of the barrier")
    thickness: float = param(0.05, "m", "barrier thickness along x", "positive")
    height: float = param(0.08, "m", "barrier height", "positive")

    def validate(self) -> None:
        """Check that the barrier lies between the pads."""
        super().validate()
        half = self.thickness / 2
        _check_span(self, self.center - half, self.center + half, "the barrier ('thickness')")


@register("barrier", BarrierParams, "an 8 cm wall, 5 cm thick, across the course", "littledog")
def barrier(params: BarrierParams) -> Terrain:
    """Build a wall [m] across the course."""
    grid = params.grid()
    z = grid.zeros()
    half = params.thickness / 2
    z[in_box(grid, params.center - half, params.center + half)] = params.height
    return grid.terrain(z)


@dataclass(frozen=True)
class StepsParams(CourseParams):
    """Blocks stepping up to a plateau and back down."""

    center: float = param(1.0, "m", "x of the middle of the plateau")
    n_steps: int = param(2, "", "steps up (and as many down)", "positive")
    step_height: float = param(0.054, "m", "rise of each step", "positive")
    step_length: float = param(0.15, "m", "tread of each step along x", "positive")
    top_length: float = param(0.3, "m", "plateau length along x", "positive")

    @property
    def total_length(self) -> float:
        """Length [m] from the first step up to the last step down."""
        return 2 * self.n_steps * self.step_length + self.top_length

    def validate(self) -> None:
        """Check that the steps lie between the pads."""
        super().validate()
        half = self.total_length / 2
        _check_span(self, self.center - half, self.center + half, "the steps")


@register(
    "steps",
    StepsParams,
    "two 5.4 cm blocks up to a 10.8 cm plateau and two back down",
    "littledog",
)
def steps(params: StepsParams) -> Terrain:
    """Build up-then-down blocks [m]: a stepped pyramid across the course."""
    grid = params.grid()
    z = grid.zeros()
    start = params.center - params.total_length / 2
    for k in range(1, params.n_steps + 1):
        # Level k spans from the k-th edge up to the k-th edge down.
        lo = start + (k - 1) * params.step_length
        hi = start + params.total_length - (k - 1) * params.step_length
        z[in_box(grid, lo, hi)] = k * params.step_height
    return grid.terrain(z)


@dataclass(frozen=True)
class StairsParams(CourseParams):
    """Steps rising all the way; the end pad stays at the top."""

    start: float = param(0.5, "m", "x of the first step's edge")
    n_steps: int = param(4, "", "number of steps", "positive")
    step_height: float = param(0.027, "m", "rise of each step", "positive")
    step_length: float = param(0.25, "m", "tread of each step along x", "positive")

    def validate(self) -> None:
        """Check that the stairs lie between the pads."""
        super().validate()
        _check_span(self, self.start, self.start + self.n_steps * self.step_length, "the stairs")


@register(
    "stairs",
    StairsParams,
    "four 2.7 cm steps rising to 10.8 cm; the end pad stays at the top",
    "littledog",
)
def stairs(params: StairsParams) -> Terrain:
    """Build rising steps [m]."""
    grid = params.grid()
    x = grid.x
    # An edge's grid point belongs to the upper step.
    k = np.floor((x - params.start) / params.step_length + 1e-9) + 1
    level = np.clip(k, 0, params.n_steps) * params.step_height
    return grid.terrain(np.repeat(level[:, None], grid.ny, axis=1))


@dataclass(frozen=True)
class SteppingStonesParams(RandomCourseParams):
    """Square flat-topped columns over a pit."""

    max_height: float = param(0.04, "m", "highest stone top above the pads", "nonnegative")
    stone_size: float = param(0.08, "m", "side of each square stone", "positive")
    stone_spacing: float = param(0.12, "m", "distance between stone centres", "positive")
    position_jitter: float = param(0.01, "m", "random shift of each stone", "nonnegative")
    floor_depth: float = param(0.1, "m", "depth of the pit floor below the pads", "positive")

    def validate(self) -> None:
        """Check that stones do not overlap."""
        super().validate()
        if self.stone_size + 2 * self.position_jitter > self.stone_spacing:
            raise TerrainError(
                f"parameters 'stone_size' + 2·'position_jitter' ({self.stone_size} + "
                f"2·{self.position_jitter} m) must not exceed 'stone_spacing' "
                f"({self.stone_spacing} m), or stones merge"
            )


@register(
    "stepping_stones",
    SteppingStonesParams,
    "8 cm stones every 12 cm over a 10 cm-deep pit, tops 0–4 cm",
    "littledog",
    randomized=True,
)
def stepping_stones(params: SteppingStonesParams) -> Terrain:
    """Dig a pit [m] between the pads with stone columns rising out of it."""
    rng = params.rng()
    grid = params.grid()
    z = grid.zeros()
    z[params.features_zone(grid)] = -params.floor_depth
    s = params.stone_spacing
    half = params.stone_size / 2
    # Stones fill the pit; the outermost ones stay a jitter away from the pads.
    margin = half + params.position_jitter
    n_x = max(
        1, int(np.floor((params.feature_end - params.feature_start - 2 * margin) / s + 1e-9)) + 1
    )
    n_y = max(1, int(np.floor((params.width - 2 * margin) / s + 1e-9)) + 1)
    mid_x = (params.feature_start + params.feature_end) / 2
    xs = mid_x + s * (np.arange(n_x) - (n_x - 1) / 2)
    ys = s * (np.arange(n_y) - (n_y - 1) / 2)
    j = params.position_jitter
    for cx in xs:
        for cy in ys:
            dx, dy = rng.uniform(-j, j, 2)
            top = rng.uniform(0.0, params.max_height)
            box = in_box(grid, cx + dx - half, cx + dx + half, cy + dy - half, cy + dy + half)
            z[box] = top
    return grid.terrain(z)
