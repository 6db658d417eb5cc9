"""Terrain file loaders: one module per format, one entry point, :func:`load_file`.

============  =======================================  =====================
suffix        format                                   options
============  =======================================  =====================
``.mat``      LittleDog board (``x``, ``y``, ``Z``)    ``name``
``.png``      grid_map elevation image                 ``resolution``,
                                                       ``scale``, ``origin``,
                                                       ``name``
``.npy``      x-major height array                     ``resolution``
                                                       (required),
                                                       ``origin``, ``name``
``.npz``      heights and grid (see :mod:`.array`)     ``resolution``,
                                                       ``origin``, ``name``
``.stl``,     triangle mesh (see :mod:`.mesh`)         ``resolution``,
``.obj``,                                              ``name``
``.ply``
============  =======================================  =====================

Every loader returns a :class:`~roughwalk.terrain.terrain.Terrain` on the
file's own grid (x-major heights, NaN = unknown) and raises
:class:`~roughwalk.errors.TerrainError` naming the file for anything it cannot
use.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from roughwalk.errors import TerrainError
from roughwalk.terrain.loaders._common import existing_file
from roughwalk.terrain.loaders.array import NPZ_KEYS, load_npy, load_npz, save_npz
from roughwalk.terrain.loaders.image import load_png
from roughwalk.terrain.loaders.mat import load_mat
from roughwalk.terrain.loaders.mesh import load_mesh, mesh_to_heights
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "SUPPORTED_SUFFIXES",
    "NPZ_KEYS",
    "load_file",
    "load_mat",
    "load_png",
    "load_npy",
    "load_npz",
    "load_mesh",
    "mesh_to_heights",
    "save_npz",
]

_LOADERS: dict[str, tuple[Callable[..., Terrain], frozenset[str]]] = {
    ".mat": (load_mat, frozenset({"name"})),
    ".png": (load_png, frozenset({"resolution", "scale", "origin", "name"})),
    ".npy": (load_npy, frozenset({"resolution", "origin", "name"})),
    ".npz": (load_npz, frozenset({"resolution", "origin", "name"})),
    ".stl": (load_mesh, frozenset({"resolution", "name"})),
    ".obj": (load_mesh, frozenset({"resolution", "name"})),
    ".ply": (load_mesh, frozenset({"resolution", "name"})),
}

#: File suffixes :func:`load_file` reads.
SUPPORTED_SUFFIXES = tuple(_LOADERS)
_ALL_OPTIONS = frozenset().union(*(opts for _, opts in _LOADERS.values()))


def load_file(path: str | Path, **options: Any) -> Terrain:
    """Load a terrain file, choosing the loader by its suffix.

    Parameters
    ----------
    path:
        A ``.mat``, ``.png``, ``.npy``, ``.npz``, ``.stl``, ``.obj`` or ``.ply`` file.
    **options:
        Loader options (see the table in this module's docs). Options another
        format takes are ignored, since a course passes the same options to
        each of its boards; an option no loader takes is a :class:`TerrainError`.

    """
    p = Path(path)
    unknown = sorted(set(options) - _ALL_OPTIONS)
    if unknown:
        raise TerrainError(
            f"{p}: unknown loader option(s) {', '.join(unknown)}; "
            f"known: {', '.join(sorted(_ALL_OPTIONS))}"
        )
    suffix = p.suffix.lower()
    if suffix not in _LOADERS:
        raise TerrainError(
            f"{p}: unsupported terrain file type {suffix or '(no suffix)'!r}; "
            f"supported: {', '.join(SUPPORTED_SUFFIXES)}"
        )
    existing_file(p)
    loader, accepted = _LOADERS[suffix]
    return loader(p, **{k: v for k, v in options.items() if k in accepted})
