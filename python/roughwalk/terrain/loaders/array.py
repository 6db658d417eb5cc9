"""NumPy height arrays: ``.npy`` (heights only) and ``.npz`` (heights and grid).

Both hold **x-major** heights [m]: ``heights[i, j]`` is the height at
``(x0 + i·dx, y0 + j·dy)``; NaN marks unknown cells.

``.npz`` keys (anything else is refused, so that a typo is not ignored):

* ``heights`` (required): (nx, ny) array [m];
* the grid spacing, one of: ``resolution`` (a number, or (dx, dy)) [m];
  ``dx`` and ``dy`` [m]; or coordinate vectors ``x`` (nx,) and ``y`` (ny,) [m]
  (uniform, increasing);
* the coordinates of grid point (0, 0), optional: ``x0`` and ``y0``, or
  ``origin`` = (x0, y0) [m] (taken from ``x``/``y`` when those are given);
* ``name`` (optional): the terrain's name.

Values missing from the file come from the loader's ``resolution`` and
``origin`` arguments; values in the file take precedence.
"""

from __future__ import annotations

import zipfile
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import TerrainError
from roughwalk.terrain.loaders._common import (
    existing_file,
    make_terrain,
    pair,
    uniform_axis,
)
from roughwalk.terrain.terrain import Terrain

__all__ = ["load_npy", "load_npz", "save_npz", "NPZ_KEYS"]

#: Every key a terrain ``.npz`` may hold.
NPZ_KEYS = ("heights", "resolution", "dx", "dy", "x", "y", "x0", "y0", "origin", "name")

_READ_ERRORS = (OSError, ValueError, EOFError, zipfile.BadZipFile)


def load_npy(
    path: str | Path,
    *,
    resolution: Any = None,
    origin: Any = (0.0, 0.0),
    name: str | None = None,
) -> Terrain:
    """Load x-major heights [m] from a ``.npy`` file.

    Parameters
    ----------
    path:
        The ``.npy`` file holding a 2-D numeric array (no pickles).
    resolution:
        Grid spacing [m], a number or (dx, dy); required, the file has none.
    origin:
        (x, y) [m] of grid point (0, 0).
    name:
        The terrain's name (default: the file's stem).

    """
    p = existing_file(path)
    if resolution is None:
        raise TerrainError(
            f"{p}: a .npy height array carries no grid spacing; pass resolution=<metres> "
            "(and origin=(x0, y0) if grid point (0, 0) is not at the origin)"
        )
    try:
        a = np.load(p, allow_pickle=False)
    except _READ_ERRORS as e:
        raise TerrainError(f"{p}: cannot read as a .npy array ({e})") from None
    if not isinstance(a, np.ndarray):
        a.close()  # an .npz archive holds its file open
        raise TerrainError(f"{p}: expected a single array, found an archive; name it .npz")
    dx, dy = pair(resolution, "resolution [m]", p, must_be_positive=True)
    x0, y0 = pair(origin, "origin [m]", p)
    return make_terrain(_heights(a, "the array", p), x0, y0, dx, dy, name=name or p.stem, path=p)


def load_npz(
    path: str | Path,
    *,
    resolution: Any = None,
    origin: Any = None,
    name: str | None = None,
) -> Terrain:
    """Load a height grid from a ``.npz`` archive (keys: see the module docs).

    Parameters
    ----------
    path:
        The ``.npz`` file.
    resolution:
        Grid spacing [m] if the file has none (a number or (dx, dy)).
    origin:
        (x, y) [m] of grid point (0, 0) if the file has none (default (0, 0)).
    name:
        The terrain's name (default: the file's ``name`` key, else its stem).

    """
    p = existing_file(path)
    try:
        loaded = np.load(p, allow_pickle=False)
        if isinstance(loaded, np.ndarray):
            raise TerrainError(f"{p}: expected a .npz archive, found a single array (.npy)")
        with loaded as archive:
            data = {k: archive[k] for k in archive.files}
    except TerrainError:
        raise
    except _READ_ERRORS as e:
        raise TerrainError(f"{p}: cannot read as a .npz archive ({e})") from None
    unknown = sorted(set(data) - set(NPZ_KEYS))
    if unknown:
        raise TerrainError(
            f"{p}: unknown key(s) {', '.join(unknown)}; a terrain .npz may hold "
            f"{', '.join(NPZ_KEYS)}"
        )
    if "heights" not in data:
        raise TerrainError(
            f"{p}: missing key 'heights' (x-major (nx, ny) array [m]); "
            f"the file holds: {', '.join(sorted(data)) or 'nothing'}"
        )
    heights = _heights(data["heights"], "'heights'", p)
    nx, ny = heights.shape

    spacing = [k for k in ("resolution", "dx", "x") if k in data]
    if len(spacing) > 1:
        raise TerrainError(
            f"{p}: give the grid spacing once: keys {', '.join(spacing)} are all present"
        )
    file_origin: tuple[float, float] | None = None
    if "x" in data or "y" in data:
        if "x" not in data or "y" not in data:
            raise TerrainError(f"{p}: keys 'x' and 'y' go together; only one is present")
        xs, ys = (np.asarray(data[k], dtype=np.float64).ravel() for k in ("x", "y"))
        if xs.size != nx or ys.size != ny:
            raise TerrainError(
                f"{p}: 'heights' has shape {heights.shape} (x-major) but 'x' has {xs.size} "
                f"and 'y' {ys.size} values; expected {nx} and {ny}"
            )
        x0, dx, flip_x = uniform_axis(xs, "x", p)
        y0, dy, flip_y = uniform_axis(ys, "y", p)
        if flip_x or flip_y:
            raise TerrainError(f"{p}: 'x' and 'y' must be increasing")
        file_origin = (x0, y0)
    elif "resolution" in data:
        dx, dy = pair(data["resolution"], "'resolution' [m]", p, must_be_positive=True)
    elif "dx" in data or "dy" in data:
        if "dx" not in data or "dy" not in data:
            raise TerrainError(f"{p}: keys 'dx' and 'dy' go together; only one is present")
        dx, _ = pair(data["dx"], "'dx' [m]", p, must_be_positive=True)
        dy, _ = pair(data["dy"], "'dy' [m]", p, must_be_positive=True)
    elif resolution is not None:
        dx, dy = pair(resolution, "resolution [m]", p, must_be_positive=True)
    else:
        raise TerrainError(
            f"{p}: no grid spacing: add key 'resolution' (or 'dx' and 'dy', or 'x' and 'y') "
            "to the file, or pass resolution=<metres>"
        )

    if "origin" in data and ("x0" in data or "y0" in data):
        raise TerrainError(f"{p}: give the origin once: 'origin' or 'x0'/'y0', not both")
    if ("x0" in data or "y0" in data or "origin" in data) and file_origin is not None:
        raise TerrainError(f"{p}: 'x'/'y' already fix the origin; drop 'x0'/'y0'/'origin'")
    if "origin" in data:
        file_origin = pair(data["origin"], "'origin' [m]", p)
    elif "x0" in data or "y0" in data:
        if "x0" not in data or "y0" not in data:
            raise TerrainError(f"{p}: keys 'x0' and 'y0' go together; only one is present")
        file_origin = (
            pair(data["x0"], "'x0' [m]", p)[0],
            pair(data["y0"], "'y0' [m]", p)[0],
        )
    if file_origin is not None:
        x0, y0 = file_origin
    elif origin is not None:
        x0, y0 = pair(origin, "origin [m]", p)
    else:
        x0, y0 = 0.0, 0.0

    if name is None and "name" in data:
        name = str(data["name"])
    return make_terrain(heights, x0, y0, dx, dy, name=name or p.stem, path=p)


def save_npz(terrain: Terrain, path: str | Path) -> Path:
    """Write ``terrain`` as a ``.npz`` that :func:`load_npz` reads back exactly.

    The heights are the raw ones (NaN where unknown), so the unknown mask
    survives the round trip; a kept mesh does not (save it with trimesh).
    """
    p = Path(path)
    if p.suffix.lower() != ".npz":
        raise TerrainError(f"'{p}': a terrain array file must end in .npz")
    with p.open("wb") as f:
        np.savez_compressed(
            f,
            heights=terrain.raw_heights,
            dx=terrain.dx,
            dy=terrain.dy,
            x0=terrain.x0,
            y0=terrain.y0,
            name=np.array(terrain.name),
        )
    return p


def _heights(a: Any, label: str, path: Path) -> NDArray[np.float64]:
    """Check that ``a`` is a 2-D numeric array and return it as floats."""
    arr = np.asarray(a)
    if arr.dtype.kind not in "biuf":
        raise TerrainError(f"{path}: {label} must be numeric, got dtype {arr.dtype}")
    if arr.ndim != 2:
        raise TerrainError(
            f"{path}: {label} must be a 2-D x-major (nx, ny) height array, got shape {arr.shape}"
        )
    return arr.astype(np.float64)
