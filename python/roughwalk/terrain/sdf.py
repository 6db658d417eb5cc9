"""The signed distance field of a terrain (Zucker 2011, §3.3).

A uniform voxel lattice covers the terrain's x–y extent and its height range
plus a margin; each node stores the signed distance [m] to the terrain
surface, negative inside (below a height field, inside a mesh). Queries
interpolate the nodes trilinearly and return the interpolant's own gradient,
batched in Rust: points, spheres (centre distance minus radius) and capsules
(minimum over samples along the segment minus the radius, as the paper does).

How the values are made (see ``crates/roughwalk-core/src/sdf/build.rs``):

* the surface is the height field's triangulation (two triangles per grid
  cell, as :meth:`Terrain.to_mesh`) extended beyond the grid with the edge
  heights, the same clamping every height query uses; for a terrain with a
  ``mesh`` the mesh itself, inside/outside by vertical-ray parity;
* voxels within ``band_cells`` voxels of the surface get their exact
  distance and closest surface point;
* every other voxel takes the distance to the exact closest point of its
  nearest band voxel, found by a linear-time feature transform
  (Felzenszwalb–Huttenlocher), then refined (neighbours' closest points, and
  for height fields one Newton step onto the surface), so lattice values are
  nearly exact everywhere (on the LittleDog course: 0.1 mm mean, < 3 mm worst
  beyond the band) and smooth enough for gradients; the interpolation error
  stays below half a voxel diagonal.

Outside the lattice, queries fall back to the exact signed distance to the
height-field surface (slower, never garbage). For mesh terrain that fall-back
sees only the mesh's upper envelope.
"""

from __future__ import annotations

import json
import math
import time
import zipfile
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk import _core
from roughwalk.config import override
from roughwalk.errors import ConfigError, InvalidArgumentError, TerrainError

if TYPE_CHECKING:
    from roughwalk.terrain.terrain import Terrain

__all__ = ["SdfConfig", "SignedDistanceField", "EDT_BACKENDS", "available_edt_backends"]

EDT_BACKENDS = ("rust", "scipy", "edt")
_FORMAT = "roughwalk.sdf"
_FORMAT_VERSION = 1


def available_edt_backends() -> list[str]:
    """The EDT backends that can run here (optional packages must import)."""
    out = ["rust"]
    for name, module in (("scipy", "scipy.ndimage"), ("edt", "edt")):
        try:
            __import__(module)
        except ImportError:
            continue
        out.append(name)
    return out


@dataclass(frozen=True)
class SdfConfig:
    """How a :class:`SignedDistanceField` is built.

    Attributes
    ----------
    resolution:
        Voxel size [m]. Interpolation error is at most half a voxel diagonal
        (≈ 0.87·resolution); memory and build time grow as 1/resolution³.
        5 mm suits LittleDog (the paper's value).
    z_margin:
        Free space [m] kept below the lowest and above the highest terrain
        point. Queries beyond it use the slower exact fall-back, so it should
        cover where the robot's collision shapes go; each extra centimetre
        costs 2/resolution·1 cm worth of voxel layers.
    band_cells:
        Half-width of the exact band around the surface [voxels], ≥ 1.
        Wider bands cost more exact point–surface distances at build time;
        beyond it values come from the feature transform, which is already
        nearly exact, so 2 (the paper's "one or two grid cells") is plenty.
    edt_backend:
        Feature transform for the voxels outside the band. ``"rust"``
        (default): Felzenszwalb–Huttenlocher in the core, followed by the
        far-field refinement. ``"scipy"``: ``distance_transform_edt`` with
        indices, same field, slower. ``"edt"``: the ``edt`` package has no
        feature transform, only distances to the band, so far values are
        coarse (up to a voxel diagonal off) and the refinement cannot run;
        its build is the quickest but misses the accuracy target. Measured
        on the three-board LittleDog course at 5 mm (2-core VM, see
        ``benchmarks/bench_sdf.py``): transform alone 0.11 / 0.18 / 0.12 s,
        whole build 0.45 / 0.66 / 0.33 s, worst error 2.3 / 2.3 / 5.0 mm
        for rust / scipy / edt.
    max_voxels:
        Refuse lattices with more voxels than this (4 bytes each when built,
        about 16 at the peak of the build), naming the finest resolution that fits.
    """

    resolution: float = 0.005
    z_margin: float = 0.2
    band_cells: float = 2.0
    edt_backend: str = "rust"
    max_voxels: int = 200_000_000

    def __post_init__(self) -> None:
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            raise ConfigError(
                f"sdf.resolution must be a positive length [m], got {self.resolution}"
            )
        if not (math.isfinite(self.z_margin) and self.z_margin >= 0):
            raise ConfigError(f"sdf.z_margin must be a length ≥ 0 [m], got {self.z_margin}")
        if not (math.isfinite(self.band_cells) and self.band_cells >= 1):
            raise ConfigError(f"sdf.band_cells must be ≥ 1 [voxels], got {self.band_cells}")
        if self.edt_backend not in EDT_BACKENDS:
            raise ConfigError(
                f"unknown sdf.edt_backend '{self.edt_backend}'; known: {', '.join(EDT_BACKENDS)}"
            )
        if self.max_voxels < 8:
            raise ConfigError(f"sdf.max_voxels must be ≥ 8, got {self.max_voxels}")


def _node_count(length: float, resolution: float) -> int:
    """Nodes needed to cover ``length`` [m] at ``resolution`` [m], both ends included."""
    # A millionth of a voxel of slack so that rounding in the extent never adds a layer.
    return int(math.ceil(length / resolution - 1e-6)) + 1


def _lattice_shape(lengths: tuple[float, float, float], resolution: float) -> tuple[int, int, int]:
    nx, ny, nz = (max(_node_count(v, resolution), 2) for v in lengths)
    return nx, ny, nz


def finest_resolution(lengths: tuple[float, float, float], max_voxels: int) -> float:
    """Return the finest resolution [m] that keeps a lattice within ``max_voxels``.

    ``lengths`` [m] is the box the lattice covers; the answer is rounded up
    to 3 significant digits.
    """
    volume = max(lengths[0], 1e-9) * max(lengths[1], 1e-9) * max(lengths[2], 1e-9)
    r = (volume / max_voxels) ** (1.0 / 3.0)
    while math.prod(_lattice_shape(lengths, r)) > max_voxels:
        r *= 1.002
    # Round up to a number a person would type, and make sure it still fits.
    step = 10.0 ** (math.floor(math.log10(r)) - 2)
    nice = math.ceil(r / step) * step
    while math.prod(_lattice_shape(lengths, nice)) > max_voxels:
        nice += step
    return float(f"{nice:.3g}")


def _as_points(points: ArrayLike, name: str) -> NDArray[np.float64]:
    try:
        a = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InvalidArgumentError(f"{name}: expected an (N, 3) array of numbers ({e})") from None
    if a.ndim == 1 and a.shape[0] == 3:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 3:
        raise InvalidArgumentError(f"{name}: expected shape (N, 3), got {a.shape}")
    return np.ascontiguousarray(a)


def _as_radii(radii: ArrayLike, n: int) -> NDArray[np.float64]:
    try:
        r = np.asarray(radii, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InvalidArgumentError(f"radii: expected numbers [m] ({e})") from None
    if r.ndim == 0:
        r = np.full(n, float(r))
    if r.shape != (n,):
        raise InvalidArgumentError(f"radii: expected shape ({n},) or a scalar, got {r.shape}")
    return np.ascontiguousarray(r)


class SignedDistanceField:
    """Signed distance [m] to a terrain surface on a voxel lattice (Zucker 2011, §3.3).

    Build with :meth:`build` (or :meth:`Terrain.sdf`), query with
    :meth:`query`, :meth:`query_spheres` and :meth:`query_capsules`, store
    with :meth:`save` and :meth:`load`.
    """

    def __init__(
        self,
        core: _core.SdfField,
        terrain: Terrain,
        config: SdfConfig,
        *,
        backend: str,
        build_time_s: float,
    ) -> None:
        self._core = core
        self._terrain = terrain
        self._config = config
        self._backend = backend
        self._build_time_s = float(build_time_s)

    # -------------------------------------------------------------- building
    @classmethod
    def lattice_for(
        cls, terrain: Terrain, config: SdfConfig
    ) -> tuple[tuple[float, float, float], tuple[int, int, int]]:
        """Origin [m] and shape (nx, ny, nz) of the lattice ``config`` puts over ``terrain``.

        Raises :class:`TerrainError` when the lattice has more than
        ``config.max_voxels`` voxels, naming the finest resolution that fits.
        """
        x_min, x_max, y_min, y_max = terrain.extent
        z_lo, z_hi = terrain.height_range
        if terrain.mesh is not None:
            bounds = np.asarray(terrain.mesh.bounds, dtype=np.float64)
            z_lo, z_hi = min(z_lo, float(bounds[0, 2])), max(z_hi, float(bounds[1, 2]))
        z_lo -= config.z_margin
        z_hi += config.z_margin
        lengths = (x_max - x_min, y_max - y_min, z_hi - z_lo)
        shape = _lattice_shape(lengths, config.resolution)
        voxels = math.prod(shape)
        if voxels > config.max_voxels:
            fit = finest_resolution(lengths, config.max_voxels)
            raise TerrainError(
                f"an SDF of terrain '{terrain.name}' at resolution={config.resolution:g} m needs "
                f"{voxels:,} voxels (shape {shape}), more than max_voxels={config.max_voxels:,}; "
                f"the finest resolution that fits is resolution={fit:g} m "
                f"(or raise max_voxels, or lower z_margin)"
            )
        return (x_min, y_min, z_lo), shape

    @classmethod
    def build(
        cls,
        terrain: Terrain,
        resolution: float | None = None,
        *,
        config: SdfConfig | None = None,
        **options: Any,
    ) -> SignedDistanceField:
        """Build the field of ``terrain``.

        Parameters
        ----------
        terrain:
            The terrain; its ``mesh``, if any, is used instead of the height field.
        resolution:
            Voxel size [m]; overrides ``config.resolution``.
        config:
            Build settings (default :class:`SdfConfig`).
        **options:
            Individual :class:`SdfConfig` fields to override
            (``z_margin=0.1``, ``edt_backend="scipy"``, ...).
        """
        cfg = config if config is not None else SdfConfig()
        changes = dict(options)
        if resolution is not None:
            changes["resolution"] = resolution
        if changes:
            cfg = override(cfg, changes)
        if cfg.edt_backend not in available_edt_backends():
            raise TerrainError(
                f"SDF edt_backend '{cfg.edt_backend}' is not installed here; "
                f"available: {', '.join(available_edt_backends())}"
            )
        origin, shape = cls.lattice_for(terrain, cfg)
        start = time.perf_counter()
        if terrain.mesh is not None:
            band = _core.SdfBand.from_mesh(
                terrain.core,
                np.ascontiguousarray(terrain.mesh.vertices, dtype=np.float64),
                np.ascontiguousarray(terrain.mesh.faces, dtype=np.int64),
                origin,
                cfg.resolution,
                shape,
                cfg.band_cells,
            )
        else:
            band = _core.SdfBand.from_heightfield(
                terrain.core, origin, cfg.resolution, shape, cfg.band_cells
            )
        core = _finish(band, cfg, shape)
        elapsed = time.perf_counter() - start
        return cls(core, terrain, cfg, backend=cfg.edt_backend, build_time_s=elapsed)

    # --------------------------------------------------------------- queries
    def query(self, points: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Signed distances [m] (N,) and gradients (N, 3) at (N, 3) points [m].

        Inside the lattice: trilinear interpolation and its exact gradient.
        Outside: the exact signed distance to the height-field surface and
        the unit vector away from its closest point.
        """
        return self._core.query(_as_points(points, "points"))

    def query_spheres(
        self, centers: ArrayLike, radii: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Sphere distances: field at the (N, 3) centres [m] minus the radii [m] (N,).

        Returns distances [m] (N,) and gradients w.r.t. the centres (N, 3).
        """
        c = _as_points(centers, "centers")
        return self._core.query_spheres(c, _as_radii(radii, len(c)))

    def query_capsules(
        self,
        a: ArrayLike,
        b: ArrayLike,
        radii: ArrayLike,
        samples: int | None = None,
        *,
        return_fraction: bool = False,
    ) -> Any:
        """Capsule distances: minimum of the field over samples of segment a–b, minus the radius.

        Parameters
        ----------
        a, b:
            (N, 3) segment ends [m].
        radii:
            (N,) capsule radii [m] (or one scalar).
        samples:
            Points per segment, ends included (≥ 2). Default: spacing of at
            most one voxel.
        return_fraction:
            Also return t (N,), the minimising sample's fraction along a→b,
            so that ∂d/∂a = (1 − t)·g and ∂d/∂b = t·g.

        Returns
        -------
        distances [m] (N,), gradients (N, 3) of the field at the minimising
        sample point, and t (N,) if ``return_fraction``.
        """
        pa = _as_points(a, "a")
        pb = _as_points(b, "b")
        if pa.shape != pb.shape:
            raise InvalidArgumentError(
                f"capsule ends a and b must have the same shape, got {pa.shape} and {pb.shape}"
            )
        if samples is not None and (
            isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 2
        ):
            raise InvalidArgumentError(f"samples must be an integer ≥ 2, got {samples!r}")
        d, g, t = self._core.query_capsules(
            pa, pb, _as_radii(radii, len(pa)), None if samples is None else int(samples)
        )
        return (d, g, t) if return_fraction else (d, g)

    def surface_query(self, points: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Exact signed distances [m] and gradients to the height-field surface, no lattice.

        The fall-back :meth:`query` uses outside the lattice; slower (a
        branch-and-bound over the terrain grid per point).
        """
        return self._core.surface_query(_as_points(points, "points"))

    # ------------------------------------------------------------ properties
    @property
    def resolution(self) -> float:
        """Voxel size [m]."""
        return float(self._core.resolution)

    @property
    def shape(self) -> tuple[int, int, int]:
        """Number of lattice nodes (nx, ny, nz)."""
        nx, ny, nz = self._core.shape
        return (int(nx), int(ny), int(nz))

    @property
    def origin(self) -> tuple[float, float, float]:
        """Position [m] of lattice node (0, 0, 0), its lower corner."""
        x, y, z = self._core.origin
        return (float(x), float(y), float(z))

    @property
    def upper(self) -> tuple[float, float, float]:
        """Position [m] of the last lattice node, its upper corner."""
        return tuple(
            o + (n - 1) * self.resolution for o, n in zip(self.origin, self.shape, strict=False)
        )  # type: ignore[return-value]

    @property
    def build_time_s(self) -> float:
        """Wall time [s] the build took (0 for a field loaded from a file)."""
        return self._build_time_s

    @property
    def backend(self) -> str:
        """The EDT backend that filled the voxels outside the band."""
        return self._backend

    @property
    def config(self) -> SdfConfig:
        """The settings the field was built with."""
        return self._config

    @property
    def terrain(self) -> Terrain:
        """The terrain the field measures."""
        return self._terrain

    @property
    def values(self) -> NDArray[np.float32]:
        """A copy of the lattice values [m], shape (nx, ny, nz), float32."""
        return self._core.values()

    @property
    def memory_bytes(self) -> int:
        """Bytes the lattice values take."""
        return 4 * math.prod(self.shape)

    def info(self) -> dict[str, Any]:
        """A JSON-ready summary."""
        return {
            "shape": list(self.shape),
            "resolution": self.resolution,
            "origin": list(self.origin),
            "upper": list(self.upper),
            "build_time_s": self.build_time_s,
            "backend": self.backend,
            "memory_bytes": self.memory_bytes,
            "z_margin": self._config.z_margin,
            "band_cells": self._config.band_cells,
            "terrain": self._terrain.spec,
        }

    def __repr__(self) -> str:
        nx, ny, nz = self.shape
        return (
            f"SignedDistanceField({self._terrain.name!r}, {nx}×{ny}×{nz} at "
            f"{self.resolution * 1000:.2f} mm, backend={self.backend!r})"
        )

    # ----------------------------------------------------------- save / load
    def save(self, path: str | Path) -> None:
        """Write the field, its settings and its terrain's height field to ``path`` (.npz)."""
        t = self._terrain
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        with p.open("wb") as f:
            np.savez(
                f,
                format=np.array(_FORMAT),
                format_version=np.array(_FORMAT_VERSION),
                values=self._core.values(),
                origin=np.array(self.origin),
                resolution=np.array(self.resolution),
                config=np.array(json.dumps(asdict(self._config))),
                backend=np.array(self._backend),
                build_time_s=np.array(self._build_time_s),
                terrain_name=np.array(t.name),
                terrain_spec=np.array(t.spec),
                terrain_heights=t.raw_heights,
                terrain_grid=np.array([t.x0, t.y0, t.dx, t.dy]),
            )

    @classmethod
    def load(cls, path: str | Path) -> SignedDistanceField:
        """Read a field written by :meth:`save`.

        The terrain comes back as a height field (a mesh terrain's mesh is
        not stored; its lattice values are). Raises :class:`TerrainError`
        naming the file when it is missing or not an SDF file.
        """
        from roughwalk.terrain.terrain import Terrain

        p = Path(path)
        try:
            with np.load(p, allow_pickle=False) as z:
                data = {k: z[k] for k in z.files}
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as e:
            raise TerrainError(f"cannot read SDF file '{p}': {e}") from None
        if str(data.get("format", "")) != _FORMAT:
            raise TerrainError(
                f"'{p}' is not a roughwalk SDF file (no format='{_FORMAT}' entry); "
                f"write one with SignedDistanceField.save"
            )
        try:
            version = int(data["format_version"])
            if version != _FORMAT_VERSION:
                raise TerrainError(
                    f"SDF file '{p}' has format version {version}; this roughwalk reads "
                    f"version {_FORMAT_VERSION}"
                )
            cfg_fields = {f.name for f in fields(SdfConfig)}
            cfg_data = {k: v for k, v in json.loads(str(data["config"])).items() if k in cfg_fields}
            config = SdfConfig(**cfg_data)
            x0, y0, dx, dy = (float(v) for v in data["terrain_grid"])
            terrain = Terrain(
                data["terrain_heights"],
                x0,
                y0,
                dx,
                dy,
                name=str(data["terrain_name"]),
                spec=str(data["terrain_spec"]),
            )
            values = np.ascontiguousarray(data["values"], dtype=np.float32)
            origin = tuple(float(v) for v in data["origin"])
            core = _core.SdfField(terrain.core, origin, float(data["resolution"]), values)
            return cls(
                core,
                terrain,
                config,
                backend=str(data["backend"]),
                build_time_s=float(data["build_time_s"]),
            )
        except TerrainError as e:
            if str(p) in str(e):
                raise
            raise TerrainError(f"SDF file '{p}' is damaged: {e}") from None
        except (KeyError, ValueError, TypeError, ConfigError) as e:
            raise TerrainError(f"SDF file '{p}' is damaged or incomplete: {e}") from None


def _finish(band: _core.SdfBand, cfg: SdfConfig, shape: tuple[int, int, int]) -> _core.SdfField:
    """Fill the voxels outside the exact band with the configured EDT backend."""
    if cfg.edt_backend == "rust":
        return band.finish()
    if cfg.edt_backend == "scipy":
        from scipy import ndimage

        seeds = band.seed_mask()
        nearest = ndimage.distance_transform_edt(
            ~seeds, return_distances=False, return_indices=True
        )
        flat = np.ravel_multi_index(tuple(nearest), shape).astype(np.int64, copy=False)
        return band.finish_with_nearest_voxel(flat.ravel())
    import os

    import edt

    # `edt` has no feature transform: measure to the band voxels within
    # `offset` of the surface and add `offset` (see Band::finish_with_seed_distance).
    offset = cfg.band_cells * cfg.resolution
    seeds = band.seed_mask(offset)
    dist = edt.edt(np.ascontiguousarray(~seeds), parallel=os.cpu_count() or 1)
    return band.finish_with_seed_distance(np.ascontiguousarray(dist, dtype=np.float32), offset)
