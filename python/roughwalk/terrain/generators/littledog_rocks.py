"""Random LittleDog-scale rock and log courses, after the DARPA Learning Locomotion boards.

Each generator draws its features between two flat pads of a 2 m × 0.6 m
course, from ``numpy.random.default_rng(seed)``, and never higher than
``max_height`` (10.8 cm, LittleDog's largest test obstacles):

* ``large_rocks`` (board AE): big angular rocks on a jittered grid, faceted
  sides and flat-ish tops;
* ``round_rocks`` (board AC): many small rounded stones, packed densely;
* ``sloped_rocks`` (board Y): slabs, one per tile, each with a tilted top;
* ``logs`` (board AD): half-buried logs lying across the course.

Features overlap by taking the highest surface, as stacked rocks would.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import TerrainError
from roughwalk.terrain.generators.grid import Grid, RandomCourseParams
from roughwalk.terrain.generators.registry import param, register
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "LargeRocksParams",
    "RoundRocksParams",
    "SlopedRocksParams",
    "LogsParams",
    "large_rocks",
    "round_rocks",
    "sloped_rocks",
    "logs",
]


def _window(grid: Grid, cx: float, cy: float, radius: float) -> tuple[slice, slice]:
    """Index slices of the grid points within a square of half-size ``radius`` around (cx, cy)."""
    i0 = max(0, int(np.floor((cx - radius - grid.x0) / grid.dx)))
    i1 = min(grid.nx, int(np.ceil((cx + radius - grid.x0) / grid.dx)) + 1)
    j0 = max(0, int(np.floor((cy - radius - grid.y0) / grid.dy)))
    j1 = min(grid.ny, int(np.ceil((cy + radius - grid.y0) / grid.dy)) + 1)
    return slice(i0, max(i0, i1)), slice(j0, max(j0, j1))


def _local(
    grid: Grid, win: tuple[slice, slice], cx: float, cy: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Offsets (u, v) [m] from (cx, cy) of the grid points in ``win``, shape (wx, wy)."""
    u = grid.x[win[0]][:, None] - cx
    v = grid.y[win[1]][None, :] - cy
    return u, v


def _finish(params: RandomCourseParams, grid: Grid, z: NDArray[np.float64]) -> Terrain:
    """Clip to [0, max_height], flatten the pads, and wrap as a terrain."""
    z = np.clip(z, 0.0, params.max_height)
    z[~params.features_zone(grid)] = 0.0
    return grid.terrain(z)


def _slots(start: float, end: float, spacing: float) -> NDArray[np.float64]:
    """Centres of the whole ``spacing``-wide slots fitting in [start, end], centred there [m]."""
    n = max(1, int(np.floor((end - start) / spacing + 1e-9)))
    mid = (start + end) / 2
    return mid + spacing * (np.arange(n, dtype=np.float64) - (n - 1) / 2)


@dataclass(frozen=True)
class LargeRocksParams(RandomCourseParams):
    """Big angular rocks on a jittered grid (LittleDog board AE holds 3 × 3 per 0.6 m)."""

    rock_spacing: float = param(0.2, "m", "distance between neighbouring rocks", "positive")
    min_height_fraction: float = param(
        0.4, "", "lowest rock top as a fraction of max_height", "fraction"
    )


@register(
    "large_rocks",
    LargeRocksParams,
    "big angular rocks, one per 0.2 m cell, up to 10.8 cm (board AE)",
    "littledog",
    randomized=True,
)
def large_rocks(params: LargeRocksParams) -> Terrain:
    """Place big faceted rocks [m]: truncated irregular pyramids, tops slightly tilted."""
    rng = params.rng()
    grid = params.grid()
    z = grid.zeros()
    s = params.rock_spacing
    half_w = params.width / 2
    for cx0 in _slots(params.feature_start, params.feature_end, s):
        for cy0 in _slots(-half_w, half_w, s):
            radius = s * rng.uniform(0.4, 0.5)
            # Keep the footprint off the pads.
            jitter = max(0.0, s / 2 - radius)
            cx = cx0 + rng.uniform(-jitter, jitter)
            cy = cy0 + rng.uniform(-jitter, jitter)
            top = params.max_height * rng.uniform(params.min_height_fraction, 1.0)
            n_facets = int(rng.integers(5, 8))
            angles = 2 * np.pi * (np.arange(n_facets) + rng.uniform(-0.3, 0.3, n_facets)) / n_facets
            reach = radius * rng.uniform(0.8, 1.0, n_facets)
            # The pyramid would peak above the top; truncating it leaves a flat face.
            apex = top * rng.uniform(1.5, 2.5)
            tilt = rng.uniform(-0.15, 0.15, 2)
            win = _window(grid, cx, cy, radius)
            u, v = _local(grid, win, cx, cy)
            rock = top + tilt[0] * u + tilt[1] * v
            for a, r in zip(angles, reach, strict=True):
                rock = np.minimum(rock, apex * (1.0 - (np.cos(a) * u + np.sin(a) * v) / r))
            z[win] = np.maximum(z[win], rock)
    return _finish(params, grid, z)


@dataclass(frozen=True)
class RoundRocksParams(RandomCourseParams):
    """Densely packed small rounded stones (LittleDog board AC)."""

    density: float = param(150.0, "1/m²", "stones per square metre of course", "positive")
    min_radius: float = param(0.02, "m", "smallest stone radius", "positive")
    max_radius: float = param(0.05, "m", "largest stone radius", "positive")
    bed_height: float = param(
        0.02, "m", "height of the gravel bed the stones sit in", "nonnegative"
    )
    min_height_fraction: float = param(
        0.3, "", "lowest stone top, as a fraction of the way from the bed to max_height", "fraction"
    )

    def validate(self) -> None:
        """Check that the radii are ordered."""
        super().validate()
        if self.min_radius > self.max_radius:
            raise TerrainError(
                f"parameter 'min_radius' ({self.min_radius} m) must not exceed "
                f"'max_radius' ({self.max_radius} m)"
            )
        if self.bed_height >= self.max_height:
            raise TerrainError(
                f"parameter 'bed_height' ({self.bed_height} m) must be below "
                f"'max_height' ({self.max_height} m)"
            )


@register(
    "round_rocks",
    RoundRocksParams,
    "rounded stones 4–10 cm across in a 2 cm gravel bed, up to 10.8 cm (board AC)",
    "littledog",
    randomized=True,
)
def round_rocks(params: RoundRocksParams) -> Terrain:
    """Scatter rounded stones [m] (random half-ellipsoids) over a gravel bed."""
    rng = params.rng()
    grid = params.grid()
    z = grid.zeros()
    z[params.features_zone(grid)] = params.bed_height
    length = params.feature_end - params.feature_start
    count = int(round(params.density * length * params.width))
    half_w = params.width / 2
    for _ in range(count):
        a = rng.uniform(params.min_radius, params.max_radius)
        b = a * rng.uniform(0.6, 1.0)
        # The long axis fits when it lies along x, so the footprint stays off the pads.
        lo, hi = params.feature_start + a, params.feature_end - a
        cx = rng.uniform(lo, hi) if hi > lo else (lo + hi) / 2
        cy = rng.uniform(-half_w, half_w)
        yaw = rng.uniform(0.0, np.pi)
        lowest = params.bed_height + params.min_height_fraction * (
            params.max_height - params.bed_height
        )
        top = rng.uniform(lowest, params.max_height)
        win = _window(grid, cx, cy, a)
        u, v = _local(grid, win, cx, cy)
        c, s = np.cos(yaw), np.sin(yaw)
        rho2 = ((c * u + s * v) / a) ** 2 + ((-s * u + c * v) / b) ** 2
        stone = top * np.sqrt(np.clip(1.0 - rho2, 0.0, None))
        z[win] = np.maximum(z[win], stone)
    return _finish(params, grid, z)


@dataclass(frozen=True)
class SlopedRocksParams(RandomCourseParams):
    """Slabs with tilted tops, one per tile (LittleDog board Y holds 3 × 3 per 0.6 m)."""

    tile_size: float = param(0.2, "m", "size of the square tile each slab stands in", "positive")
    max_slope: float = param(0.35, "rad", "steepest slab top", "nonnegative")


@register(
    "sloped_rocks",
    SlopedRocksParams,
    "slabs with tops tilted up to 20°, one per 0.2 m tile (board Y)",
    "littledog",
    randomized=True,
)
def sloped_rocks(params: SlopedRocksParams) -> Terrain:
    """Set slabs [m]: rounded rectangles with vertical sides and a tilted planar top."""
    rng = params.rng()
    grid = params.grid()
    z = grid.zeros()
    t = params.tile_size
    half_w = params.width / 2
    for cx in _slots(params.feature_start, params.feature_end, t):
        for cy in _slots(-half_w, half_w, t):
            hx, hy = t / 2 * rng.uniform(0.78, 0.92, 2)
            corner = 0.2 * t
            centre_height = params.max_height * rng.uniform(0.4, 0.7)
            direction = rng.uniform(0.0, 2 * np.pi)
            grade = np.tan(params.max_slope * rng.uniform(0.3, 1.0))
            win = _window(grid, cx, cy, max(hx, hy))
            u, v = _local(grid, win, cx, cy)
            # Rounded-rectangle footprint: distance outside the inner box ≤ corner radius.
            qx = np.clip(np.abs(u) - (hx - corner), 0.0, None)
            qy = np.clip(np.abs(v) - (hy - corner), 0.0, None)
            inside = qx**2 + qy**2 <= corner**2
            top = centre_height + grade * (np.cos(direction) * u + np.sin(direction) * v)
            # A slab keeps some thickness even where its top dips.
            top = np.maximum(top, 0.15 * params.max_height)
            z[win] = np.where(inside, np.maximum(z[win], top), z[win])
    return _finish(params, grid, z)


@dataclass(frozen=True)
class LogsParams(RandomCourseParams):
    """Half-buried logs across the course (LittleDog board AD)."""

    log_spacing: float = param(0.25, "m", "distance between neighbouring logs along x", "positive")
    min_radius: float = param(0.035, "m", "thinnest log radius", "positive")
    max_radius: float = param(0.06, "m", "thickest log radius", "positive")
    max_yaw: float = param(0.35, "rad", "largest angle between a log and the y axis", "nonnegative")

    def validate(self) -> None:
        """Check that the radii are ordered."""
        super().validate()
        if self.min_radius > self.max_radius:
            raise TerrainError(
                f"parameter 'min_radius' ({self.min_radius} m) must not exceed "
                f"'max_radius' ({self.max_radius} m)"
            )


@register(
    "logs",
    LogsParams,
    "half-buried logs across the course, one per 0.25 m, up to 10.8 cm (board AD)",
    "littledog",
    randomized=True,
)
def logs(params: LogsParams) -> Terrain:
    """Lay logs [m]: capsules (cylinders with round ends), partly sunk."""
    rng = params.rng()
    grid = params.grid()
    z = grid.zeros()
    half_w = params.width / 2
    for cx0 in _slots(params.feature_start, params.feature_end, params.log_spacing):
        radius = rng.uniform(params.min_radius, params.max_radius)
        half_len = half_w * rng.uniform(0.6, 1.0)
        yaw = rng.uniform(-params.max_yaw, params.max_yaw)
        # Axis direction: along y, turned by yaw.
        ax, ay = -np.sin(yaw), np.cos(yaw)
        reach_x = abs(ax) * half_len + radius
        lo, hi = params.feature_start + reach_x, params.feature_end - reach_x
        jitter = 0.2 * params.log_spacing
        cx = float(np.clip(cx0 + rng.uniform(-jitter, jitter), lo, max(lo, hi)))
        cy = rng.uniform(-0.2, 0.2) * params.width
        top = params.max_height * rng.uniform(0.6, 1.0)
        axis_height = top - radius
        win = _window(grid, cx, cy, half_len + radius)
        u, v = _local(grid, win, cx, cy)
        along = np.clip(ax * u + ay * v, -half_len, half_len)
        d2 = (u - along * ax) ** 2 + (v - along * ay) ** 2
        log = np.where(d2 < radius**2, axis_height + np.sqrt(np.clip(radius**2 - d2, 0, None)), 0.0)
        z[win] = np.maximum(z[win], log)
    return _finish(params, grid, z)
