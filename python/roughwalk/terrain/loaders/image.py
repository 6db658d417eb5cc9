"""Elevation-map images (PNG) in ETH grid_map's convention.

grid_map (and OCS2's perceptive demos, which use it) turns an image into a
map like this: image **rows run along x, row 0 at the largest x**; image
**columns run along y, column 0 at the largest y**; the map is centred on its
position; pixel ``(r, c)`` is the centre of a cell of side ``resolution``.
Height = gray / max_gray × ``scale`` (grid_map's ``lowerValue = 0``,
``upperValue = scale``). Pixels whose alpha is below one half are unknown
(grid_map leaves them empty).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from roughwalk.errors import TerrainError
from roughwalk.terrain.loaders._common import existing_file, make_terrain, pair, positive
from roughwalk.terrain.terrain import Terrain

__all__ = ["load_png", "image_gray"]

#: ITU-R BT.601 luma weights, the ones OpenCV's BGR2GRAY (used by grid_map) applies.
_LUMA = np.array([0.299, 0.587, 0.114])


def load_png(
    path: str | Path,
    *,
    resolution: float = 0.04,
    scale: float = 0.35,
    origin: Any = (0.0, 0.0),
    name: str | None = None,
) -> Terrain:
    """Load an elevation-map image.

    Parameters
    ----------
    path:
        The image (8- or 16-bit, gray or RGB(A); PNG is what is dispatched here).
    resolution:
        Cell size [m/pixel]; 0.04 is what OCS2's ANYmal demo uses.
    scale:
        Height [m] of a white pixel (black is 0 m); OCS2's demo uses 0.35.
    origin:
        (x, y) [m] of the map's centre.
    name:
        The terrain's name (default: the file's stem).

    Returns
    -------
    Terrain
        ``rows × cols`` grid points at spacing ``resolution``:
        ``heights[i, j] = image[rows−1−i, cols−1−j] / max × scale``, with grid
        point (0, 0) at ``origin − ((rows−1)/2, (cols−1)/2) × resolution``.

    """
    p = existing_file(path)
    res = positive(resolution, "resolution [m/pixel]", p)
    sc = positive(scale, "scale [m]", p)
    ox, oy = pair(origin, "origin [m]", p)
    gray, known = image_gray(p)
    rows, cols = gray.shape
    if rows < 2 or cols < 2:
        raise TerrainError(f"{p}: an elevation map needs at least 2×2 pixels, got {cols}×{rows}")
    heights = np.where(known, gray * sc, np.nan)
    # grid_map: row 0 is the largest x and column 0 the largest y, so both axes flip.
    heights = heights[::-1, ::-1]
    x0 = ox - 0.5 * (rows - 1) * res
    y0 = oy - 0.5 * (cols - 1) * res
    return make_terrain(heights, x0, y0, res, res, name=name or p.stem, path=p)


def image_gray(path: Path) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Gray level in [0, 1] of every pixel (rows, cols), and where alpha ≥ ½.

    Gray images are divided by their maximum value (255, or 65535 for 16-bit);
    RGB pixels with R = G = B use that value, other colours their BT.601 luma
    (0.299 R + 0.587 G + 0.114 B), as grid_map's OpenCV conversion does.
    """
    try:
        with Image.open(path) as opened:
            opened.load()
            im: Image.Image = opened
            if im.mode == "1":
                im = im.convert("L")
            elif im.mode in ("P", "PA"):
                im = im.convert("RGBA" if im.mode == "PA" or "transparency" in im.info else "RGB")
            mode = im.mode
            a = np.asarray(im)
    except (OSError, ValueError, SyntaxError) as e:
        raise TerrainError(f"{path}: cannot read as an image ({e})") from None
    if mode in ("L", "LA", "RGB", "RGBA"):
        full = 255.0
    elif mode.startswith("I;16") or mode == "I":
        # Pillow opens 16-bit gray PNGs as "I;16" (or "I" in older versions).
        full = 65535.0
        if a.size and (a.min() < 0 or a.max() > full):
            raise TerrainError(f"{path}: {mode} pixel values outside 0..65535")
    else:
        raise TerrainError(
            f"{path}: unsupported image mode {mode!r}; use 8- or 16-bit gray, RGB or RGBA"
        )
    a = a.astype(np.float64)
    known = np.ones(a.shape[:2], dtype=bool)
    if mode in ("LA", "RGBA"):
        known = a[..., -1] >= 0.5 * full
        a = a[..., :-1]
    if a.ndim == 3:
        if a.shape[2] == 1:
            a = a[..., 0]
        elif np.array_equal(a[..., 0], a[..., 1]) and np.array_equal(a[..., 0], a[..., 2]):
            a = a[..., 0]
        else:
            a = a[..., :3] @ _LUMA
    return a / full, known
