"""Grids the generators draw on: the LittleDog course and the open field.

Two shapes of ground cover every generator:

* a **LittleDog course** (:class:`CourseParams`): x from 0 to ``length``
  (2 m), y from −``width``/2 to ``width``/2 (±0.3 m), 5 mm cells, with flat
  pads at z = 0 at both ends and the features between them;
* an **open field** (:class:`FieldParams`) for the ANYmal-scale tasks of
  Melon et al. 2020 and TOWR: flat ground at z = 0 from x = −1 m to 5 m,
  y = ±1.5 m, 1 cm cells, with one obstacle placed in it.

The grid keeps the requested extent exactly; the spacing is the requested
resolution rounded so that a whole number of cells fits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import TerrainError
from roughwalk.terrain.generators.registry import GeneratorParams, param
from roughwalk.terrain.terrain import Terrain

__all__ = ["CourseParams", "RandomCourseParams", "FieldParams", "Grid", "in_box"]

# More grid points than this is a mistaken resolution, not a terrain (≈ 400 MB of heights).
MAX_GRID_POINTS = 50_000_000

# Grid points within this distance [m] of a box edge count as inside, so that
# a box from 1.0 to 2.2 m includes the points printed as 1.0 and 2.2.
EDGE_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Grid:
    """A regular grid: point (i, j) is at (x0 + i·dx, y0 + j·dy) [m], as in :class:`Terrain`."""

    x0: float
    y0: float
    dx: float
    dy: float
    nx: int
    ny: int

    @classmethod
    def spanning(
        cls, x_min: float, x_max: float, y_min: float, y_max: float, resolution: float
    ) -> Grid:
        """Span (x_min, y_min) to (x_max, y_max) [m] with spacing ≈ ``resolution`` [m]."""
        nx = max(2, round((x_max - x_min) / resolution) + 1)
        ny = max(2, round((y_max - y_min) / resolution) + 1)
        return cls(x_min, y_min, (x_max - x_min) / (nx - 1), (y_max - y_min) / (ny - 1), nx, ny)

    @property
    def x(self) -> NDArray[np.float64]:
        """Grid x coordinates [m], shape (nx,) (same arithmetic as :attr:`Terrain.x`)."""
        return self.x0 + self.dx * np.arange(self.nx, dtype=np.float64)

    @property
    def y(self) -> NDArray[np.float64]:
        """Grid y coordinates [m], shape (ny,)."""
        return self.y0 + self.dy * np.arange(self.ny, dtype=np.float64)

    def zeros(self) -> NDArray[np.float64]:
        """Return a (nx, ny) array of zero heights [m]."""
        return np.zeros((self.nx, self.ny))

    def terrain(self, heights: NDArray[np.float64]) -> Terrain:
        """Wrap ``heights`` [m] on this grid as a :class:`Terrain` (the registry names it)."""
        return Terrain(heights, self.x0, self.y0, self.dx, self.dy)


def _check_size(length: float, width: float, resolution: float) -> None:
    points = (length / resolution + 1) * (width / resolution + 1)
    if points > MAX_GRID_POINTS:
        raise TerrainError(
            f"parameter 'resolution' ({resolution} m) gives {points:.3g} grid points over "
            f"{length} m × {width} m; at most {MAX_GRID_POINTS:.0e} are allowed"
        )


def in_box(
    grid: Grid, x_lo: float, x_hi: float, y_lo: float = -np.inf, y_hi: float = np.inf
) -> NDArray[np.bool_]:
    """Mask (nx, ny) the grid points with x ∈ [x_lo, x_hi], y ∈ [y_lo, y_hi] [m], edges in."""
    t = EDGE_TOLERANCE
    in_x = (grid.x >= x_lo - t) & (grid.x <= x_hi + t)
    in_y = (grid.y >= y_lo - t) & (grid.y <= y_hi + t)
    return in_x[:, None] & in_y[None, :]


@dataclass(frozen=True)
class CourseParams(GeneratorParams):
    """A LittleDog-scale course: x ∈ [0, length], y ∈ [−width/2, width/2], pads at both ends."""

    length: float = param(2.0, "m", "course length along x (x runs from 0)", "positive")
    width: float = param(0.6, "m", "course width along y (centred on y = 0)", "positive")
    resolution: float = param(0.005, "m", "grid spacing (finer is slower)", "positive")
    pad_start: float = param(0.35, "m", "flat pad at z = 0 before the features", "nonnegative")
    pad_end: float = param(0.35, "m", "flat pad after the features", "nonnegative")

    def validate(self) -> None:
        """Check that the pads leave room for features and the grid has cells."""
        if self.pad_start + self.pad_end >= self.length:
            raise TerrainError(
                f"parameters 'pad_start' + 'pad_end' ({self.pad_start} + {self.pad_end} m) "
                f"must be shorter than 'length' ({self.length} m)"
            )
        if self.resolution > min(self.length, self.width) / 2:
            raise TerrainError(
                f"parameter 'resolution' ({self.resolution} m) must be at most half of "
                f"'length' and 'width' ({self.length} m, {self.width} m)"
            )
        _check_size(self.length, self.width, self.resolution)

    @property
    def feature_start(self) -> float:
        """X [m] where the features begin (end of the start pad)."""
        return self.pad_start

    @property
    def feature_end(self) -> float:
        """X [m] where the features end (start of the end pad)."""
        return self.length - self.pad_end

    def grid(self) -> Grid:
        """Return the course grid."""
        half = self.width / 2
        return Grid.spanning(0.0, self.length, -half, half, self.resolution)

    def features_zone(self, grid: Grid) -> NDArray[np.bool_]:
        """(nx, ny) mask of the points between the pads (where features may be)."""
        return in_box(grid, self.feature_start, self.feature_end)


@dataclass(frozen=True)
class _Seeded(GeneratorParams):
    seed: int = param(
        0, "", "random seed (numpy default_rng); same seed, same terrain", "nonnegative"
    )
    max_height: float = param(0.108, "m", "tallest feature above the pads", "positive")


@dataclass(frozen=True)
class RandomCourseParams(CourseParams, _Seeded):
    """A LittleDog-scale course with random features up to ``max_height``.

    LittleDog's test terrains had features up to 10.8 cm, hence the default.
    """

    def rng(self) -> np.random.Generator:
        """Return the generator's random stream, fixed by ``seed``."""
        return np.random.default_rng(self.seed)


@dataclass(frozen=True)
class FieldParams(GeneratorParams):
    """An open field of flat ground at z = 0 around one obstacle (ANYmal scale)."""

    x_min: float = param(-1.0, "m", "start of the field along x")
    x_max: float = param(5.0, "m", "end of the field along x")
    y_min: float = param(-1.5, "m", "right edge of the field")
    y_max: float = param(1.5, "m", "left edge of the field")
    resolution: float = param(0.01, "m", "grid spacing (finer is slower)", "positive")

    def validate(self) -> None:
        """Check that the field spans at least two cells each way."""
        for lo, hi, a, b in (
            (self.x_min, self.x_max, "x_min", "x_max"),
            (self.y_min, self.y_max, "y_min", "y_max"),
        ):
            if hi - lo < 2 * self.resolution:
                raise TerrainError(
                    f"parameters '{a}' < '{b}' must span at least two cells of 'resolution' "
                    f"({self.resolution} m), got {lo} .. {hi} m"
                )
        _check_size(self.x_max - self.x_min, self.y_max - self.y_min, self.resolution)

    def grid(self) -> Grid:
        """Return the field grid."""
        return Grid.spanning(self.x_min, self.x_max, self.y_min, self.y_max, self.resolution)
