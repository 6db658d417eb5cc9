"""The :class:`Terrain`: a height field on a regular grid, with unknown cells.

Conventions (used by every part of roughwalk):

* x forward, y left, z up, metres.
* ``heights`` has shape ``(nx, ny)`` and is **x-major**: ``heights[i, j]`` is
  the height at ``(x[i], y[j])`` with ``x[i] = x0 + i·dx`` and
  ``y[j] = y0 + j·dy``. (Loaders convert from each file format's own order.)
* Unknown cells: NaN in the source. They are kept in :attr:`Terrain.known`
  (False there), are never footholds (:meth:`Terrain.is_known`), and are
  *filled conservatively* in :attr:`Terrain.heights`: each connected region of
  unknown cells becomes a plateau at the highest known height on its border,
  so that the SDF treats unmeasured ground as an obstacle rather than a hole.
  :attr:`Terrain.raw_heights` keeps the NaNs.
* Queries outside the grid clamp to the nearest edge height.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from roughwalk import _core
from roughwalk.errors import InvalidArgumentError, TerrainError

if TYPE_CHECKING:
    import trimesh

    from roughwalk.terrain.features import TerrainFeatures
    from roughwalk.terrain.sdf import SignedDistanceField

__all__ = ["Terrain", "Interpolation", "MujocoHeightField"]

Interpolation = Literal["bilinear", "bicubic"]


@dataclass(frozen=True)
class MujocoHeightField:
    """Height-field data in MuJoCo's layout (see MJCF ``<hfield>``).

    ``elevation`` has shape (nrow, ncol), row index along y and column index
    along x, normalised to [0, 1]; ``size`` is MuJoCo's (radius_x, radius_y,
    elevation_z, base_z) [m]; ``center`` the (x, y, z) [m] where the geom goes
    so that heights come out in the terrain's own frame.
    """

    elevation: NDArray[np.float64]
    size: tuple[float, float, float, float]
    center: tuple[float, float, float]


def _fill_unknown(raw: NDArray[np.float64]) -> NDArray[np.float64]:
    """Fill each connected unknown region with the highest known height on its border.

    A region's border is every known cell touching it, diagonals included.
    """
    unknown = ~np.isfinite(raw)
    if not unknown.any():
        return raw.copy()
    labels, n = ndimage.label(unknown)
    nx, ny = raw.shape
    padded = np.pad(raw, 1, constant_values=np.nan)
    top = np.full(n + 1, -np.inf)
    # A known cell may border several regions, so every neighbour direction
    # feeds every region it touches.
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di == 0 and dj == 0:
                continue
            neighbour = padded[1 + di : 1 + di + nx, 1 + dj : 1 + dj + ny]
            sel = unknown & np.isfinite(neighbour)
            np.maximum.at(top, labels[sel], neighbour[sel])
    # Every region touches a known cell (an all-unknown grid is refused); keep a
    # conservative fallback all the same.
    top[~np.isfinite(top)] = float(np.nanmax(raw))
    filled = raw.copy()
    filled[unknown] = top[labels[unknown]]
    return filled


class Terrain:
    """A height field [m] on a regular x–y grid, with a mask of unknown cells.

    Parameters
    ----------
    heights:
        (nx, ny) heights [m], x-major; NaN marks unknown cells.
    x0, y0:
        Coordinates [m] of grid point (0, 0).
    dx, dy:
        Grid spacing [m] along x and y.
    name:
        A short human name ("terrainA", "large_rocks").
    spec:
        The spec string that rebuilds this terrain with :func:`load_terrain`.
    mesh:
        For meshes that are not 2.5-D: the original triangle mesh, used by the
        SDF instead of the height field (the heights are its upper envelope).

    """

    def __init__(
        self,
        heights: ArrayLike,
        x0: float,
        y0: float,
        dx: float,
        dy: float,
        *,
        name: str = "terrain",
        spec: str | None = None,
        mesh: trimesh.Trimesh | None = None,
    ) -> None:
        raw = np.array(heights, dtype=np.float64)
        if raw.ndim != 2 or raw.shape[0] < 2 or raw.shape[1] < 2:
            raise TerrainError(
                f"terrain '{name}': heights must be a 2-D array of at least 2×2, "
                f"got shape {raw.shape}"
            )
        for label, v in (("x0", x0), ("y0", y0), ("dx", dx), ("dy", dy)):
            if not np.isfinite(v):
                raise TerrainError(f"terrain '{name}': {label} must be finite, got {v}")
        if dx <= 0 or dy <= 0:
            raise TerrainError(
                f"terrain '{name}': grid spacing must be positive, got dx={dx}, dy={dy}"
            )
        raw[np.isinf(raw)] = np.nan
        known = np.isfinite(raw)
        if not known.any():
            raise TerrainError(f"terrain '{name}': every cell is unknown (NaN); nothing to use")
        self._raw = raw
        self._raw.flags.writeable = False
        self._known = known
        self._known.flags.writeable = False
        self._heights = _fill_unknown(raw)
        self._heights.flags.writeable = False
        self.x0, self.y0, self.dx, self.dy = float(x0), float(y0), float(dx), float(dy)
        self.name = name
        self.spec = spec if spec is not None else name
        self.mesh = mesh
        self._hf = _core.HeightField(self.x0, self.y0, self.dx, self.dy, self._heights, self._known)

    # ----------------------------------------------------------------- grid
    @property
    def heights(self) -> NDArray[np.float64]:
        """(nx, ny) heights [m] with unknown cells filled conservatively (read-only)."""
        return self._heights

    @property
    def raw_heights(self) -> NDArray[np.float64]:
        """(nx, ny) heights [m] as loaded, NaN where unknown (read-only)."""
        return self._raw

    @property
    def known(self) -> NDArray[np.bool_]:
        """(nx, ny) mask, True where the height was measured (read-only)."""
        return self._known

    @property
    def shape(self) -> tuple[int, int]:
        """Grid shape (nx, ny)."""
        return (int(self._heights.shape[0]), int(self._heights.shape[1]))

    @property
    def x(self) -> NDArray[np.float64]:
        """Grid x coordinates [m], shape (nx,)."""
        return np.arange(self.shape[0], dtype=np.float64) * self.dx + self.x0

    @property
    def y(self) -> NDArray[np.float64]:
        """Grid y coordinates [m], shape (ny,)."""
        return np.arange(self.shape[1], dtype=np.float64) * self.dy + self.y0

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) [m] of the grid."""
        nx, ny = self.shape
        return (
            self.x0,
            self.x0 + (nx - 1) * self.dx,
            self.y0,
            self.y0 + (ny - 1) * self.dy,
        )

    @property
    def height_range(self) -> tuple[float, float]:
        """(min, max) of the filled heights [m]."""
        return float(self._heights.min()), float(self._heights.max())

    @property
    def core(self) -> _core.HeightField:
        """The Rust height field behind this terrain (for other core routines)."""
        return self._hf

    # -------------------------------------------------------------- queries
    @staticmethod
    def _xy(xy: ArrayLike) -> NDArray[np.float64]:
        a = np.asarray(xy, dtype=np.float64)
        if a.ndim == 1 and a.shape[0] == 2:
            a = a[None, :]
        if a.ndim != 2 or a.shape[1] != 2:
            raise InvalidArgumentError(f"expected xy of shape (N, 2), got {a.shape}")
        return np.ascontiguousarray(a)

    def height(
        self, xy: ArrayLike, interpolation: Interpolation = "bilinear"
    ) -> NDArray[np.float64]:
        """Heights [m] at the (N, 2) points ``xy`` [m]."""
        return self._hf.height(self._xy(xy), interpolation)

    def height_and_gradient(
        self, xy: ArrayLike, interpolation: Interpolation = "bilinear"
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Heights [m] (N,) and gradients (∂z/∂x, ∂z/∂y) (N, 2) at ``xy`` [m]."""
        return self._hf.height_and_gradient(self._xy(xy), interpolation)

    def normal(
        self, xy: ArrayLike, interpolation: Interpolation = "bilinear"
    ) -> NDArray[np.float64]:
        """Return unit upward surface normals (N, 3) at ``xy`` [m]."""
        _, g = self.height_and_gradient(xy, interpolation)
        n = np.column_stack([-g[:, 0], -g[:, 1], np.ones(len(g))])
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    def disc_normal(self, xy: ArrayLike, radius: float) -> NDArray[np.float64]:
        """Unit upward normals (N, 3) of the mean slope over the disc of ``radius`` [m] at ``xy``.

        The bilinear gradient averaged over the points of a square grid of
        spacing r / ⌈r / min(dx, dy)⌉ within the disc: about the mean slope
        the foothold checks judge a foot's disc by (they average central
        differences at the grid points)
        (:func:`~roughwalk.planning.foothold_safety.steep_footholds`), and
        the footstep planner's foot-centre normal with
        ``footstep.normal_radius``. ``radius`` 0 gives :meth:`normal`.
        """
        return np.asarray(self._hf.disc_normal(self._xy(xy), float(radius)), dtype=float)

    def slope(
        self, xy: ArrayLike, interpolation: Interpolation = "bilinear"
    ) -> NDArray[np.float64]:
        """Surface inclination from horizontal [rad] at ``xy`` [m]."""
        _, g = self.height_and_gradient(xy, interpolation)
        return np.arctan(np.hypot(g[:, 0], g[:, 1]))

    def is_known(self, xy: ArrayLike) -> NDArray[np.bool_]:
        """Return True where every grid corner of the cell under ``xy`` was measured."""
        return self._hf.is_known(self._xy(xy))

    # ----------------------------------------------------- derived products
    def sdf(self, resolution: float = 0.005, **options: Any) -> SignedDistanceField:
        """Build the signed distance field (see :class:`SignedDistanceField`)."""
        from roughwalk.terrain.sdf import SignedDistanceField

        return SignedDistanceField.build(self, resolution=resolution, **options)

    def features(self, **options: Any) -> TerrainFeatures:
        """Local quadratic-fit features of every cell (see :func:`compute_features`)."""
        from roughwalk.terrain.features import compute_features

        return compute_features(self, **options)

    def to_mesh(self) -> trimesh.Trimesh:
        """Return the height field as a triangle mesh [m].

        One vertex per grid point at its (filled) height, two upward-facing
        triangles per cell, top surface only (an open sheet, no walls or base).
        """
        import trimesh

        nx, ny = self.shape
        gx, gy = np.meshgrid(self.x, self.y, indexing="ij")
        verts = np.column_stack([gx.ravel(), gy.ravel(), self._heights.ravel()])
        idx = np.arange(nx * ny).reshape(nx, ny)
        a = idx[:-1, :-1].ravel()
        b = idx[1:, :-1].ravel()
        c = idx[1:, 1:].ravel()
        d = idx[:-1, 1:].ravel()
        faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
        return trimesh.Trimesh(vertices=verts, faces=faces, process=False)

    def to_mujoco_hfield(self, base_thickness: float = 0.05) -> MujocoHeightField:
        """Height-field data for a MuJoCo ``<hfield>`` (rows along y, columns along x).

        ``base_thickness`` [m] is the solid slab MuJoCo puts under the lowest point.
        """
        lo, hi = self.height_range
        span = max(hi - lo, 1e-6)
        elevation = (self._heights.T - lo) / span
        x_min, x_max, y_min, y_max = self.extent
        size = ((x_max - x_min) / 2, (y_max - y_min) / 2, span, float(base_thickness))
        center = ((x_min + x_max) / 2, (y_min + y_max) / 2, lo)
        return MujocoHeightField(np.ascontiguousarray(elevation), size, center)

    def info(self) -> dict[str, Any]:
        """Return a JSON-ready summary of the terrain."""
        x_min, x_max, y_min, y_max = self.extent
        lo, hi = self.height_range
        return {
            "name": self.name,
            "spec": self.spec,
            "shape": list(self.shape),
            "resolution": [self.dx, self.dy],
            "extent": {"x": [x_min, x_max], "y": [y_min, y_max], "z": [lo, hi]},
            "unknown_fraction": float(1.0 - self._known.mean()),
            "is_mesh": self.mesh is not None,
        }

    def __repr__(self) -> str:
        x_min, x_max, y_min, y_max = self.extent
        return (
            f"Terrain({self.name!r}, {self.shape[0]}×{self.shape[1]} at "
            f"{self.dx * 1000:.2f}×{self.dy * 1000:.2f} mm, x∈[{x_min:.3f}, {x_max:.3f}], "
            f"y∈[{y_min:.3f}, {y_max:.3f}] m)"
        )
