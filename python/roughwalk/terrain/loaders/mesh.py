"""Triangle meshes (STL, OBJ, PLY via trimesh) turned into height fields.

A mesh is sampled by vertical rays cast down through a regular x–y grid.
It is **2.5-D** when no ray meets the surface at two different heights, so
that the mesh is the graph of a function z(x, y):

* faces steeper than :data:`WALL_NZ` (vertical walls, as at the side of a
  step) are ignored, since a vertical ray only grazes them;
* a closed (watertight, consistently wound) solid may also have a bottom:
  it is 2.5-D when every ray enters it through one upward-facing surface and
  leaves through one downward-facing one (the top is the terrain);
* rays that only touch edges or vertices do not decide (a ray along the foot
  of a vertical wall touches the top and the bottom edge); the decision uses
  the grid points and a second grid offset by an irrational-looking fraction
  of a cell, so that grid-aligned meshes are tested inside their faces.

A 2.5-D mesh becomes a plain height field; any other mesh is kept on the
terrain (``Terrain.mesh``) for the signed distance field, with heights set to
its upper envelope. Grid points no ray hits are unknown (NaN).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import TerrainError
from roughwalk.terrain.loaders._common import existing_file, make_terrain, pair
from roughwalk.terrain.terrain import Terrain

if TYPE_CHECKING:
    import trimesh

__all__ = ["load_mesh", "mesh_to_heights", "MeshHeights", "WALL_NZ"]

#: Faces whose unit normal has |n_z| below this (steeper than ~89.94°) count as walls.
WALL_NZ = 1e-3
#: Limits on the grid: default resolutions are coarsened to stay under the first,
#: explicit ones that would exceed the second are refused (memory).
_DEFAULT_MAX_POINTS = 4_000_000
_MAX_POINTS = 25_000_000
#: Candidate (ray, triangle) pairs handled per vectorised batch.
_BATCH = 1_000_000
#: Offset [fraction of a cell] of the second grid used only for the 2.5-D decision.
_PROBE_OFFSET = (0.3819660113, 0.6180339887)


@dataclass(frozen=True)
class MeshHeights:
    """The result of sampling a mesh on a grid.

    ``heights`` (nx, ny) [m] is the upper envelope (NaN where no ray hits);
    ``is_2_5d`` whether the mesh is a height field (see the module docs).
    """

    heights: NDArray[np.float64]
    x0: float
    y0: float
    dx: float
    dy: float
    is_2_5d: bool


def load_mesh(path: str | Path, *, resolution: Any = None, name: str | None = None) -> Terrain:
    """Load a triangle mesh [m] (STL, OBJ, PLY) as a terrain.

    Parameters
    ----------
    path:
        The mesh file; z must be up.
    resolution:
        Grid spacing [m] of the height field, a number or (dx, dy). Default:
        the mean edge length,
        clipped to [1 mm, 5 cm] (and coarsened if the grid would exceed 4
        million points). The spacing is adjusted down so that the grid spans
        the mesh's x–y bounds exactly.
    name:
        The terrain's name (default: the file's stem).

    Returns
    -------
    Terrain
        The height field; ``mesh`` is set to the loaded mesh when it is not
        2.5-D.

    """
    import trimesh

    p = existing_file(path)
    try:
        mesh = trimesh.load(p, force="mesh")
    # trimesh's parsers raise whatever their format code hits (ValueError,
    # KeyError, IndexError, struct.error, ...); all of them mean "unreadable".
    except Exception as e:  # noqa: BLE001
        raise TerrainError(
            f"{p}: cannot read as a triangle mesh ({type(e).__name__}: {e})"
        ) from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise TerrainError(f"{p}: the mesh has no triangles")
    if not np.all(np.isfinite(mesh.vertices)):
        raise TerrainError(f"{p}: the mesh has non-finite vertex coordinates")
    res = (
        None if resolution is None else pair(resolution, "resolution [m]", p, must_be_positive=True)
    )
    try:
        sampled = mesh_to_heights(mesh, res)
    except TerrainError as e:
        raise TerrainError(f"{p}: {e}") from None
    return make_terrain(
        sampled.heights,
        sampled.x0,
        sampled.y0,
        sampled.dx,
        sampled.dy,
        name=name or p.stem,
        path=p,
        mesh=None if sampled.is_2_5d else mesh,
    )


def mesh_to_heights(
    mesh: trimesh.Trimesh, resolution: tuple[float, float] | None = None
) -> MeshHeights:
    """Sample ``mesh`` by vertical rays on a grid of spacing ≤ ``resolution`` (dx, dy) [m]."""
    tri = np.asarray(mesh.triangles, dtype=np.float64)
    lo = tri.reshape(-1, 3).min(axis=0)
    hi = tri.reshape(-1, 3).max(axis=0)
    span = hi - lo
    if span[0] <= 0 or span[1] <= 0:
        raise TerrainError(
            f"the mesh has no horizontal extent (x span {span[0]:g} m, y span {span[1]:g} m)"
        )
    if resolution is None:
        edges = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2)
        res = float(np.clip(edges.mean(), 1e-3, 5e-2))
        res = max(res, float(np.sqrt(span[0] * span[1] / _DEFAULT_MAX_POINTS)))
        res_x, res_y = res, res
    else:
        res_x, res_y = resolution
    nx = max(2, round(span[0] / res_x) + 1)
    ny = max(2, round(span[1] / res_y) + 1)
    if nx * ny > _MAX_POINTS:
        raise TerrainError(
            f"resolution ({res_x:g}, {res_y:g}) m gives a {nx}×{ny} grid over "
            f"{span[0]:g}×{span[1]:g} m; "
            f"at most {_MAX_POINTS:,} points are allowed, choose a coarser resolution"
        )
    dx = span[0] / (nx - 1)
    dy = span[1] / (ny - 1)
    x0, y0 = float(lo[0]), float(lo[1])
    # Closeness [m] under which a ray counts as touching a face's edge, and two
    # heights as one: float32 files (STL) are good to ~1e-7 of their size.
    size = max(1.0, float(span.max()), float(np.abs(lo).max()), float(np.abs(hi).max()))
    tol = 1e-6 * size

    faces = _RayFaces(tri, tol)
    if faces.count == 0:
        raise TerrainError("the mesh has no face that is not vertical")
    oriented = bool(mesh.is_watertight and mesh.is_winding_consistent)
    if oriented and mesh.volume < 0:
        faces.up = ~faces.up  # wound inside out

    grid = (x0, dx, nx, y0, dy, ny)
    idx, z, up, interior = faces.hits(*grid)
    heights = np.full(nx * ny, -np.inf)
    # A closed solid's terrain is its top: the upward-facing surface.
    top_sel = up if oriented else np.ones_like(up)
    np.maximum.at(heights, idx[top_sel], z[top_sel])
    stray = ~np.isfinite(heights)
    if oriented and stray.any():
        fallback = np.full(nx * ny, -np.inf)
        np.maximum.at(fallback, idx, z)
        heights[stray] = fallback[stray]
    heights[~np.isfinite(heights)] = np.nan

    layered = _layered(idx, z, up, interior, nx * ny, oriented, tol)
    if not layered:
        ox, oy = _PROBE_OFFSET
        probe = (x0 + ox * dx, dx, nx - 1, y0 + oy * dy, dy, ny - 1)
        layered = _layered(*faces.hits(*probe), (nx - 1) * (ny - 1), oriented, tol)
    return MeshHeights(heights.reshape(nx, ny), x0, y0, dx, dy, not layered)


def _layered(
    idx: NDArray[np.intp],
    z: NDArray[np.float64],
    up: NDArray[np.bool_],
    interior: NDArray[np.bool_],
    n: int,
    oriented: bool,
    tol: float,
) -> bool:
    """Whether some ray meets face interiors at two heights (per facing, for solids)."""
    groups = [up, ~up] if oriented else [np.ones_like(up)]
    for g in groups:
        sel = g & interior
        if not sel.any():
            continue
        zmax = np.full(n, -np.inf)
        zmin = np.full(n, np.inf)
        np.maximum.at(zmax, idx[sel], z[sel])
        np.minimum.at(zmin, idx[sel], z[sel])
        hit = np.isfinite(zmax)
        if np.any(zmax[hit] - zmin[hit] > tol):
            return True
    return False


class _RayFaces:
    """The non-vertical faces of a mesh, prepared for vertical ray tests."""

    def __init__(self, tri: NDArray[np.float64], tol: float) -> None:
        a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
        normal = np.cross(b - a, c - a)
        norm = np.linalg.norm(normal, axis=1)
        keep = np.abs(normal[:, 2]) > WALL_NZ * norm
        self.tri = tri[keep]
        # Twice the signed projected area: > 0 for counter-clockwise seen from above.
        self.det = normal[keep, 2]
        self.up = self.det > 0
        # Barycentric slack for each vertex: tol divided by that vertex's altitude.
        edges = np.stack(
            [
                np.linalg.norm(self.tri[:, 2, :2] - self.tri[:, 1, :2], axis=1),
                np.linalg.norm(self.tri[:, 0, :2] - self.tri[:, 2, :2], axis=1),
                np.linalg.norm(self.tri[:, 1, :2] - self.tri[:, 0, :2], axis=1),
            ],
            axis=1,
        )
        self.slack = tol * edges / np.abs(self.det)[:, None]
        self.tol = tol
        self.count = len(self.tri)

    def hits(
        self, x0: float, dx: float, nx: int, y0: float, dy: float, ny: int
    ) -> tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_]]:
        """Every (grid point, face) crossing: flat point index, height [m], face up, interior.

        Grid point (i, j) is at (x0 + i·dx, y0 + j·dy) and has flat index i·ny + j.
        """
        xy = self.tri[:, :, :2]
        lo = xy.min(axis=1) - self.tol
        hi = xy.max(axis=1) + self.tol
        i_lo = np.clip(np.ceil((lo[:, 0] - x0) / dx), 0, nx).astype(np.int64)
        i_hi = np.clip(np.floor((hi[:, 0] - x0) / dx), -1, nx - 1).astype(np.int64)
        j_lo = np.clip(np.ceil((lo[:, 1] - y0) / dy), 0, ny).astype(np.int64)
        j_hi = np.clip(np.floor((hi[:, 1] - y0) / dy), -1, ny - 1).astype(np.int64)
        ni = np.maximum(i_hi - i_lo + 1, 0)
        nj = np.maximum(j_hi - j_lo + 1, 0)

        # Split faces covering many grid points into bands of rows, so that no
        # batch holds more than _BATCH candidates.
        rows_per_band = np.maximum(1, _BATCH // np.maximum(nj, 1))
        bands = np.where(ni > 0, -(-ni // rows_per_band), 0)
        face = np.repeat(np.arange(self.count), bands)
        first = np.arange(len(face)) - np.repeat(np.cumsum(bands) - bands, bands)
        band_i0 = i_lo[face] + first * rows_per_band[face]
        band_ni = np.minimum(rows_per_band[face], i_hi[face] + 1 - band_i0)
        work = band_ni * nj[face]

        out: list[tuple[NDArray, ...]] = []
        bounds = np.cumsum(work)
        start = 0
        while start < len(face):
            stop = int(np.searchsorted(bounds, bounds[start] - work[start] + _BATCH, "right"))
            stop = max(stop, start + 1)
            out.append(
                self._batch(
                    face[start:stop],
                    band_i0[start:stop],
                    band_ni[start:stop],
                    j_lo,
                    nj,
                    x0,
                    dx,
                    y0,
                    dy,
                    ny,
                )
            )
            start = stop
        if not out:
            empty = np.zeros(0)
            return empty.astype(np.intp), empty, empty.astype(bool), empty.astype(bool)
        idx, z, up, interior = (np.concatenate(parts) for parts in zip(*out, strict=True))
        return idx, z, up, interior

    def _batch(
        self,
        face: NDArray[np.int64],
        i0: NDArray[np.int64],
        ni: NDArray[np.int64],
        j_lo: NDArray[np.int64],
        nj_all: NDArray[np.int64],
        x0: float,
        dx: float,
        y0: float,
        dy: float,
        ny: int,
    ) -> tuple[NDArray, ...]:
        nj = nj_all[face]
        count = ni * nj
        f = np.repeat(face, count)
        k = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        njf = np.repeat(nj, count)
        i = np.repeat(i0, count) + k // njf
        j = j_lo[f] + k % njf
        px = x0 + i * dx
        py = y0 + j * dy
        t = self.tri[f]
        ax, ay = t[:, 0, 0], t[:, 0, 1]
        det = self.det[f]
        l1 = ((px - ax) * (t[:, 2, 1] - ay) - (t[:, 2, 0] - ax) * (py - ay)) / det
        l2 = ((t[:, 1, 0] - ax) * (py - ay) - (px - ax) * (t[:, 1, 1] - ay)) / det
        lam = np.column_stack([1.0 - l1 - l2, l1, l2])
        slack = self.slack[f]
        inside = np.all(lam >= -slack, axis=1)
        interior = np.all(lam > slack, axis=1)[inside]
        lam = np.clip(lam[inside], 0.0, None)
        lam /= lam.sum(axis=1, keepdims=True)
        z = np.einsum("nk,nk->n", lam, t[inside, :, 2])
        idx = (i * ny + j)[inside].astype(np.intp)
        return idx, z, self.up[f[inside]], interior
