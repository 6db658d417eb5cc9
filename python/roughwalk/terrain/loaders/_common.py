"""Checks shared by every terrain loader: files, numbers, grid axes."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import TerrainError
from roughwalk.terrain.terrain import Terrain

__all__ = ["AXIS_JITTER", "existing_file", "positive", "pair", "uniform_axis", "make_terrain"]

#: How far [fraction of a spacing] a coordinate may sit from its uniform grid position.
#: The LittleDog boards deviate by ~1e-13 of a spacing (float rounding); a grid off by
#: more than this would put heights at the wrong place, so it is refused.
AXIS_JITTER = 1e-3


def existing_file(path: str | Path) -> Path:
    """``path`` as a :class:`Path`, or a :class:`TerrainError` if it is not a readable file."""
    p = Path(path)
    if not p.exists():
        raise TerrainError(f"terrain file '{p}' does not exist")
    if not p.is_file():
        raise TerrainError(f"terrain file '{p}' is not a regular file")
    return p


def positive(value: Any, label: str, path: Path) -> float:
    """``value`` as a finite positive float, or a :class:`TerrainError` naming ``label``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise TerrainError(f"{path}: {label} must be a number, got {value!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise TerrainError(f"{path}: {label} must be finite and positive, got {v}")
    return v


def pair(
    value: Any, label: str, path: Path, *, must_be_positive: bool = False
) -> tuple[float, float]:
    """Read a scalar or 2-sequence as a pair of finite floats (a scalar serves both)."""
    try:
        a = np.asarray(value, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise TerrainError(f"{path}: {label} must be a number or a pair, got {value!r}") from None
    if a.size == 1:
        a = np.repeat(a, 2)
    if a.size != 2:
        raise TerrainError(f"{path}: {label} must be a number or an (x, y) pair, got {value!r}")
    if not np.all(np.isfinite(a)):
        raise TerrainError(f"{path}: {label} must be finite, got {a.tolist()}")
    if must_be_positive and np.any(a <= 0):
        raise TerrainError(f"{path}: {label} must be positive, got {a.tolist()}")
    return float(a[0]), float(a[1])


def uniform_axis(values: ArrayLike, label: str, path: Path) -> tuple[float, float, bool]:
    """Start [m], spacing [m] and whether it runs backwards, for a uniform coordinate vector.

    The spacing is taken from the end points, so the first and last coordinates
    are exact; interior coordinates may deviate by :data:`AXIS_JITTER` of a
    spacing. Strictly decreasing axes are accepted (the caller flips the data);
    anything else is a :class:`TerrainError`.
    """
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 1:
        raise TerrainError(f"{path}: '{label}' must be a vector, got shape {v.shape}")
    if v.size < 2:
        raise TerrainError(f"{path}: '{label}' needs at least 2 coordinates, got {v.size}")
    if not np.all(np.isfinite(v)):
        bad = int(np.flatnonzero(~np.isfinite(v))[0])
        raise TerrainError(f"{path}: '{label}'[{bad}] is not finite ({v[bad]})")
    steps = np.diff(v)
    flipped = bool(steps[0] < 0)
    if flipped:
        v = v[::-1]
        steps = -steps[::-1]
    if np.any(steps <= 0):
        bad = int(np.flatnonzero(steps <= 0)[0])
        raise TerrainError(
            f"{path}: '{label}' must be strictly increasing or strictly decreasing; "
            f"it is not at index {bad} ({v[bad]} then {v[bad + 1]})"
        )
    step = (v[-1] - v[0]) / (v.size - 1)
    deviation = float(np.max(np.abs(v - (v[0] + step * np.arange(v.size)))))
    if deviation > AXIS_JITTER * step:
        raise TerrainError(
            f"{path}: '{label}' is not uniformly spaced (a coordinate is {deviation:.3g} m "
            f"off the uniform grid of spacing {step:.6g} m; at most {AXIS_JITTER:g} of a "
            "spacing is accepted); resample it onto a regular grid first"
        )
    return float(v[0]), float(step), flipped


def make_terrain(
    heights: NDArray[np.float64],
    x0: float,
    y0: float,
    dx: float,
    dy: float,
    *,
    name: str,
    path: Path,
    mesh: Any = None,
) -> Terrain:
    """Build the :class:`Terrain`, naming ``path`` in any error it raises."""
    try:
        return Terrain(heights, x0, y0, dx, dy, name=name, spec=str(path), mesh=mesh)
    except TerrainError as e:
        raise TerrainError(f"{path}: {e}") from None
