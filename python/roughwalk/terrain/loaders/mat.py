"""The LittleDog board format: MATLAB ``.mat`` files with ``x``, ``y`` and ``Z``.

The boards of the DARPA Learning Locomotion program (as shipped with MIT's
Drake) store ``x`` (1×N or N×1), ``y`` (1×M or M×1) and ``Z`` (M×N) [m], where
``Z[i, j]`` is the height at ``(x[j], y[i])``: MATLAB's ``meshgrid``
convention, rows along y. Board A's barrier therefore runs across x (a ridge
at nearly constant x spanning the whole y range), as its picture shows.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.io

from roughwalk.errors import TerrainError
from roughwalk.terrain.loaders._common import existing_file, make_terrain, uniform_axis
from roughwalk.terrain.terrain import Terrain

__all__ = ["load_mat"]


def load_mat(path: str | Path, *, name: str | None = None) -> Terrain:
    """Load a LittleDog-style board: ``x`` (1×N), ``y`` (M×1) and ``Z`` (M×N) [m].

    Parameters
    ----------
    path:
        The ``.mat`` file (MATLAB v4–v7.2; v7.3/HDF5 files are refused).
    name:
        The terrain's name (default: the file's stem).

    Returns
    -------
    Terrain
        On the file's own grid: x0 = min(x), dx = (max(x) − min(x))/(N − 1),
        likewise for y, and heights ``Z.T`` (x-major), so that the height at
        each file grid point is exactly ``Z[i, j]``. Decreasing axes are
        flipped; NaN in ``Z`` marks unknown cells.

    Raises
    ------
    TerrainError
        If the file is missing or unreadable, a variable is missing, ``Z``
        does not match ``x`` and ``y``, or a coordinate axis is not finite,
        monotonic and uniform (see :func:`uniform_axis`).

    """
    p = existing_file(path)
    try:
        data = scipy.io.loadmat(p)
    except NotImplementedError:
        raise TerrainError(
            f"{p}: MATLAB v7.3 (HDF5) files are not supported; save it with -v7"
        ) from None
    except (OSError, ValueError, TypeError, IndexError) as e:
        raise TerrainError(f"{p}: cannot read as a MATLAB .mat file ({e})") from None
    present = sorted(k for k in data if not k.startswith("__"))
    missing = [k for k in ("x", "y", "Z") if k not in data]
    if missing:
        raise TerrainError(
            f"{p}: missing variable(s) {', '.join(missing)}; a terrain board needs x (1×N), "
            f"y (M×1) and Z (M×N); the file holds: {', '.join(present) or 'nothing'}"
        )
    x = _vector(data["x"], "x", p)
    y = _vector(data["y"], "y", p)
    z = _real(data["Z"], "Z", p)
    if z.shape != (y.size, x.size):
        raise TerrainError(
            f"{p}: 'Z' has shape {z.shape} but x has {x.size} and y has {y.size} values; "
            f"expected Z of shape (len(y), len(x)) = ({y.size}, {x.size}) (rows along y)"
        )
    x0, dx, flip_x = uniform_axis(x, "x", p)
    y0, dy, flip_y = uniform_axis(y, "y", p)
    heights = z.T
    if flip_x:
        heights = heights[::-1, :]
    if flip_y:
        heights = heights[:, ::-1]
    return make_terrain(heights, x0, y0, dx, dy, name=name or p.stem, path=p)


def _vector(a: object, label: str, path: Path) -> np.ndarray:
    """Read a MATLAB row or column vector as a 1-D float array."""
    v = _real(a, label, path)
    if v.ndim > 2 or (v.ndim == 2 and min(v.shape) != 1):
        raise TerrainError(f"{path}: '{label}' must be a 1×n or n×1 vector, got shape {v.shape}")
    return v.ravel()


def _real(a: object, label: str, path: Path) -> np.ndarray:
    """Read a MATLAB numeric array as floats, refusing text, cells, structs and complex."""
    arr = np.asarray(a)
    if arr.dtype.kind not in "biuf":
        raise TerrainError(
            f"{path}: '{label}' must be a real numeric array, got MATLAB data of dtype {arr.dtype}"
        )
    return arr.astype(np.float64)
