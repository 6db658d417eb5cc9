"""Terrain features for the learned foothold cost: local quadratic fits over discs.

Zucker 2011, §4.2: around every grid cell c, the heights within a disc of
radius r are fitted by least squares with

    z(x, y) − z_c = [u_x u_y] K [u_x u_y]ᵀ + [u_x u_y] k + k_z,
    K = [[k_xx, k_xy], [k_xy, k_yy]],  k = (k_x, k_y),  u = (x − x_c, y − y_c),

for several radii (1–6 cm by default). Heights are taken relative to the
centre cell, so k is the local gradient, K half the local Hessian, k_z the
centre's deviation from its neighbourhood, and flat ground at any height
gives the zero vector, which the cost exp(−w·f) maps to unit cost.

Per cell and radius the feature vector is, in this order
(:data:`FEATURE_NAMES`)::

    k_xx, k_xy, k_yy [1/m], k_x, k_y [-], λ_min(K), λ_max(K) [1/m], |k| [-], residual [m]

where ``residual`` is the RMS of the fit's residuals over the disc. k_z is
fitted (it absorbs the centre cell's own deviation) but is not a feature.
:attr:`TerrainFeatures.names` spells them out per radius (``r0.02/k_xx``).

How it is computed: with φ(u) = (u_x², 2u_x u_y, u_y², u_x, u_y, 1), the
normal matrix A = Σ φ(u) φ(u)ᵀ over the disc is the same at every cell, so
the coefficients are A⁻¹ b with b_m = Σ φ_m(u) z(c + u) − z_c Σ φ_m(u): six
correlations of the height field with fixed kernels, done with FFTs (one
forward transform per board, seven inverse ones per radius). The residual
comes from Σ (z − z_c)² − βᵀb. FFT round-off spreads a little noise over the
whole board, so coefficients below their round-off floor are set to exactly
zero: flat and planar ground give exact zeros where they should.

Cells whose disc leaves the grid or touches an unknown cell are computed
(with edge padding and the filled heights) but flagged invalid.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike, DTypeLike, NDArray

from roughwalk.errors import InvalidArgumentError, TerrainError
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "FEATURE_NAMES",
    "DEFAULT_RADII",
    "TerrainFeatures",
    "compute_features",
    "orient_features",
]

FEATURE_NAMES = (
    "k_xx",
    "k_xy",
    "k_yy",
    "k_x",
    "k_y",
    "lambda_min",
    "lambda_max",
    "grad_norm",
    "residual",
)
DEFAULT_RADII = (0.01, 0.02, 0.03, 0.04, 0.05, 0.06)

# A disc narrower than this many cells has too few points for six coefficients.
MIN_RADIUS_CELLS = 1.5
# Round-off floor of an FFT correlation, relative to the largest sum it could give.
# Measured noise is ~1e-16; the margin keeps real curvatures far above the floor.
_FFT_RELATIVE_NOISE = 1e-13

_N = len(FEATURE_NAMES)


@dataclass(frozen=True)
class _Disc:
    """The fixed part of the fit for one radius, in coordinates scaled by 1/r."""

    radius: float
    half_cells: tuple[int, int]
    kernels: NDArray[np.float64]  # (6, 2P+1, 2Q+1): φ_m at every offset, 0 outside the disc
    a_inv: NDArray[np.float64]  # (6, 6)
    count: int

    @classmethod
    def build(cls, radius: float, dx: float, dy: float) -> _Disc:
        if not np.isfinite(radius) or radius <= 0:
            raise TerrainError(f"feature radius must be a positive number [m], got {radius!r}")
        smallest = MIN_RADIUS_CELLS * max(dx, dy)
        if radius < smallest - 1e-12:
            raise TerrainError(
                f"feature radius {radius} m is smaller than {MIN_RADIUS_CELLS} grid cells "
                f"({smallest:.4g} m at dx={dx:.4g} m, dy={dy:.4g} m): too few heights for a "
                f"quadratic fit; use radii ≥ {smallest:.4g} m or a finer grid"
            )
        p = int(np.floor(radius / dx + 1e-9))
        q = int(np.floor(radius / dy + 1e-9))
        ux = np.arange(-p, p + 1)[:, None] * dx / radius
        uy = np.arange(-q, q + 1)[None, :] * dy / radius
        ux, uy = np.broadcast_arrays(ux, uy)
        inside = ux**2 + uy**2 <= 1.0 + 1e-9
        phi = np.stack([ux**2, 2 * ux * uy, uy**2, ux, uy, np.ones_like(ux)]) * inside
        flat = phi.reshape(6, -1)
        a = flat @ flat.T
        if np.linalg.cond(a) > 1e10:
            raise TerrainError(
                f"feature radius {radius} m covers too few grid points for a quadratic fit"
            )
        return cls(radius, (p, q), phi, np.linalg.inv(a), int(inside.sum()))

    @property
    def scale(self) -> NDArray[np.float64]:
        """Factors from scaled to metric coefficients (k_xx, k_xy, k_yy, k_x, k_y, k_z)."""
        r = self.radius
        return np.array([r**-2, r**-2, r**-2, 1 / r, 1 / r, 1.0])


class _Correlator:
    """Correlations of one field (or its square) with many small kernels, by FFT."""

    def __init__(self, field: NDArray[np.float64], pad: tuple[int, int]) -> None:
        self.shape = field.shape
        self.pad = pad
        self.padded = np.pad(field, ((pad[0], pad[0]), (pad[1], pad[1])), mode="edge")
        self.size = tuple(scipy.fft.next_fast_len(n, real=True) for n in self.padded.shape)
        self._spectra: dict[int, NDArray[np.complex128]] = {}

    def _spectrum(self, power: int) -> NDArray[np.complex128]:
        if power not in self._spectra:
            self._spectra[power] = scipy.fft.rfft2(self.padded**power, s=self.size)
        return self._spectra[power]

    def correlate(self, kernel: NDArray[np.float64], power: int = 1) -> NDArray[np.float64]:
        """Σ_{p,q} kernel[p, q] · field[i + p, j + q]^power at every cell (i, j), edge-padded."""
        spectrum = self._spectrum(power)
        p, q = kernel.shape[0] // 2, kernel.shape[1] // 2
        embedded = np.zeros(self.size)
        # Flipped and wrapped, so that a convolution computes the correlation.
        rows = (-np.arange(-p, p + 1)) % self.size[0]
        cols = (-np.arange(-q, q + 1)) % self.size[1]
        embedded[np.ix_(rows, cols)] = kernel
        full = scipy.fft.irfft2(spectrum * scipy.fft.rfft2(embedded), s=self.size)
        i0, j0 = self.pad
        return full[i0 : i0 + self.shape[0], j0 : j0 + self.shape[1]]


def _fit_radius(
    disc: _Disc, corr: _Correlator, z: NDArray[np.float64], z_max: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Scaled coefficients β̃ (6, nx, ny) and residual energy Σ r² [m²] for one radius."""
    sums = np.stack([corr.correlate(k) for k in disc.kernels])
    kernel_sums = disc.kernels.reshape(6, -1).sum(axis=1)
    b = sums - z[None] * kernel_sums[:, None, None]
    beta = np.einsum("ij,jxy->ixy", disc.a_inv, b)
    # Round-off floor of each b_m, then of each β_i through A⁻¹.
    b_floor = _FFT_RELATIVE_NOISE * z_max * np.abs(disc.kernels).reshape(6, -1).sum(axis=1)
    beta_floor = np.abs(disc.a_inv) @ b_floor
    for i in range(6):
        beta[i][np.abs(beta[i]) <= beta_floor[i]] = 0.0
    sum_sq = corr.correlate(disc.kernels[5], power=2)
    # Σ (z − z_c)² = Σ z² − 2 z_c Σ z + n z_c²; the fit explains βᵀb of it.
    energy = sum_sq - 2 * z * sums[5] + disc.count * z**2 - np.einsum("ixy,ixy->xy", beta, b)
    energy_floor = 8 * _FFT_RELATIVE_NOISE * disc.count * z_max**2
    energy[energy <= energy_floor] = 0.0
    return beta, energy


def _feature_block(
    beta: NDArray[np.float64], disc: _Disc, energy: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Turn scaled coefficients into the 9 features (nx, ny, 9)."""
    k = beta[:5] * disc.scale[:5, None, None]
    k_xx, k_xy, k_yy, k_x, k_y = k
    mean = (k_xx + k_yy) / 2
    spread = np.hypot((k_xx - k_yy) / 2, k_xy)
    residual = np.sqrt(energy / disc.count)
    return np.stack(
        [k_xx, k_xy, k_yy, k_x, k_y, mean - spread, mean + spread, np.hypot(k_x, k_y), residual],
        axis=-1,
    )


def orient_features(values: ArrayLike, heading: ArrayLike) -> NDArray[np.floating]:
    """Express features in a frame turned by ``heading`` [rad] about z.

    ``values`` has shape (..., 9·R) (the layout of :attr:`TerrainFeatures.values`);
    ``heading`` is a scalar or broadcasts to ``values.shape[:-1]``. With R the
    rotation by ``heading``, the fit in the turned frame is K' = Rᵀ K R and
    k' = Rᵀ k; eigenvalues, |k| and the residual do not change. Rotating by
    ψ₁ then ψ₂ equals rotating by ψ₁ + ψ₂.
    """
    v = np.asarray(values)
    if v.ndim < 1 or v.shape[-1] % _N != 0:
        raise InvalidArgumentError(
            f"feature values must have a last axis of 9 × number of radii, got shape {v.shape}"
        )
    psi = np.asarray(heading, dtype=np.float64)
    if not np.all(np.isfinite(psi)):
        raise InvalidArgumentError("heading must be finite [rad]")
    try:
        psi = np.broadcast_to(psi, v.shape[:-1])
    except ValueError:
        raise InvalidArgumentError(
            f"heading of shape {psi.shape} does not broadcast to the feature rows {v.shape[:-1]}"
        ) from None
    out = v.reshape(*v.shape[:-1], -1, _N).copy()
    c = np.cos(psi)[..., None]
    s = np.sin(psi)[..., None]
    a, b, g = out[..., 0], out[..., 1], out[..., 2]
    kx, ky = out[..., 3], out[..., 4]
    # K' = Rᵀ K R with R's columns (c, s) and (−s, c); k' = Rᵀ k.
    new = (
        a * c * c + 2 * b * c * s + g * s * s,
        (g - a) * c * s + b * (c * c - s * s),
        a * s * s - 2 * b * c * s + g * c * c,
        c * kx + s * ky,
        -s * kx + c * ky,
    )
    for i, column in enumerate(new):
        out[..., i] = column
    return out.reshape(v.shape)


class TerrainFeatures:
    """Per-cell quadratic-fit features of a terrain, for several radii.

    Attributes
    ----------
    values:
        (nx, ny, F) features, F = 9 · len(radii), radius-major: the 9 features
        of :data:`FEATURE_NAMES` for ``radii[0]``, then for ``radii[1]``, ...
    names:
        F names like ``r0.02/k_xx``.
    valid:
        (nx, ny) True where every radius' disc lies inside the grid on known cells.
    valid_by_radius:
        (R, nx, ny) the same per radius.
    radii:
        Disc radii [m].
    heading:
        The frame of ``values``: None for the terrain's x–y axes, else the
        heading [rad] whose frame they are expressed in.
    x0, y0, dx, dy:
        The terrain's grid [m].

    """

    def __init__(
        self,
        values: NDArray[np.floating],
        valid_by_radius: NDArray[np.bool_],
        radii: Sequence[float],
        grid: tuple[float, float, float, float],
        heading: float | None = None,
    ) -> None:
        self.values = values
        self.valid_by_radius = valid_by_radius
        self.valid: NDArray[np.bool_] = np.asarray(valid_by_radius.all(axis=0))
        self.radii = tuple(float(r) for r in radii)
        self.names = tuple(f"r{r:g}/{n}" for r in self.radii for n in FEATURE_NAMES)
        self.x0, self.y0, self.dx, self.dy = grid
        self.heading = heading

    @property
    def shape(self) -> tuple[int, int]:
        """Grid shape (nx, ny)."""
        return (int(self.values.shape[0]), int(self.values.shape[1]))

    @property
    def n_features(self) -> int:
        """Length F of one feature vector."""
        return int(self.values.shape[2])

    def index(self, name: str) -> int:
        """Column of feature ``name`` (e.g. ``"r0.02/k_xx"``) in :attr:`values`."""
        try:
            return self.names.index(name)
        except ValueError:
            raise InvalidArgumentError(
                f"unknown feature '{name}'; radii {self.radii} with features "
                f"{', '.join(FEATURE_NAMES)} (e.g. '{self.names[0]}')"
            ) from None

    def _cells(
        self, xy: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
        a = np.asarray(xy, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] != 2:
            raise InvalidArgumentError(f"expected xy of shape (N, 2), got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise InvalidArgumentError("xy must be finite [m]")
        nx, ny = self.shape
        fi = (a[:, 0] - self.x0) / self.dx
        fj = (a[:, 1] - self.y0) / self.dy
        inside = (fi >= -1e-9) & (fi <= nx - 1 + 1e-9) & (fj >= -1e-9) & (fj <= ny - 1 + 1e-9)
        return np.clip(fi, 0, nx - 1), np.clip(fj, 0, ny - 1), inside

    def at(
        self,
        xy: ArrayLike,
        heading: ArrayLike | None = None,
        interpolation: Literal["bilinear", "nearest"] = "bilinear",
    ) -> NDArray[np.floating]:
        """Feature vectors (N, F) at the (N, 2) points ``xy`` [m].

        Points outside the grid take the nearest edge cell (see :meth:`valid_at`).
        With ``heading`` [rad] (scalar or (N,)), the vectors are expressed in the
        robot's heading frame (Zucker 2011, §4.2: oriented features).
        """
        fi, fj, _ = self._cells(xy)
        if interpolation == "nearest":
            out = self.values[np.rint(fi).astype(int), np.rint(fj).astype(int)]
        elif interpolation == "bilinear":
            nx, ny = self.shape
            i0 = np.minimum(np.floor(fi).astype(int), nx - 2)
            j0 = np.minimum(np.floor(fj).astype(int), ny - 2)
            wi = (fi - i0)[:, None]
            wj = (fj - j0)[:, None]
            v = self.values
            out = (
                v[i0, j0] * (1 - wi) * (1 - wj)
                + v[i0 + 1, j0] * wi * (1 - wj)
                + v[i0, j0 + 1] * (1 - wi) * wj
                + v[i0 + 1, j0 + 1] * wi * wj
            )
        else:
            raise InvalidArgumentError(
                f"unknown interpolation {interpolation!r}; known: bilinear, nearest"
            )
        if heading is None:
            return out
        relative = np.asarray(heading, dtype=np.float64) - (self.heading or 0.0)
        return orient_features(out, relative)

    def valid_at(self, xy: ArrayLike) -> NDArray[np.bool_]:
        """(N,) True where ``xy`` [m] is inside the grid and its surrounding cells are valid."""
        fi, fj, inside = self._cells(xy)
        nx, ny = self.shape
        i0 = np.minimum(np.floor(fi).astype(int), nx - 2)
        j0 = np.minimum(np.floor(fj).astype(int), ny - 2)
        v = self.valid
        ok = v[i0, j0] & v[i0 + 1, j0] & v[i0, j0 + 1] & v[i0 + 1, j0 + 1]
        return np.asarray(ok & inside)

    def at_footholds(
        self, footholds: ArrayLike, heading: ArrayLike | None = None
    ) -> NDArray[np.floating]:
        """Feature vectors (..., F) at footholds of shape (..., 2) [m] (e.g. (N, 4, 2) stances).

        ``heading`` [rad] is None, a scalar, or broadcasts to ``footholds.shape[:-1]``
        (one heading per stance: shape (N, 1)).
        """
        f = np.asarray(footholds, dtype=np.float64)
        if f.ndim < 1 or f.shape[-1] != 2:
            raise InvalidArgumentError(f"footholds must have shape (..., 2), got {f.shape}")
        lead = f.shape[:-1]
        flat_heading = None
        if heading is not None:
            try:
                flat_heading = np.broadcast_to(np.asarray(heading, dtype=np.float64), lead).ravel()
            except ValueError:
                raise InvalidArgumentError(
                    f"heading of shape {np.shape(heading)} does not broadcast to footholds {lead}"
                ) from None
        out = self.at(f.reshape(-1, 2), heading=flat_heading)
        return out.reshape(*lead, self.n_features)

    def __repr__(self) -> str:
        frame = "world" if self.heading is None else f"heading {self.heading:.3f} rad"
        return (
            f"TerrainFeatures({self.shape[0]}×{self.shape[1]} cells, radii {self.radii} m, "
            f"{self.n_features} features, {frame}, {self.valid.mean():.0%} valid)"
        )


def compute_features(
    terrain: Terrain,
    radii: Sequence[float] = DEFAULT_RADII,
    oriented_heading: float | None = None,
    dtype: DTypeLike = np.float64,
) -> TerrainFeatures:
    """Quadratic-fit features of every cell of ``terrain`` (Zucker 2011, §4.2).

    Parameters
    ----------
    terrain:
        The height field; unknown cells use the filled heights and are flagged.
    radii:
        Disc radii [m]; each must be at least 1.5 grid cells.
    oriented_heading:
        If given [rad], express every fit in the frame turned by this heading
        (k' = Rᵀ k, K' = Rᵀ K R), as for a robot walking that way.
    dtype:
        Storage type of the values (float32 halves the memory).

    Returns
    -------
    TerrainFeatures
        Values (nx, ny, 9·len(radii)) with their names and validity mask.

    """
    radii_t = tuple(float(r) for r in np.atleast_1d(np.asarray(radii, dtype=np.float64)))
    if not radii_t:
        raise TerrainError("feature radii must not be empty; e.g. (0.01, 0.02, ..., 0.06) m")
    if len(set(radii_t)) != len(radii_t):
        raise TerrainError(f"feature radii must be distinct, got {radii_t}")
    discs = [_Disc.build(r, terrain.dx, terrain.dy) for r in radii_t]
    nx, ny = terrain.shape
    pad = (max(d.half_cells[0] for d in discs), max(d.half_cells[1] for d in discs))
    heights = terrain.heights
    # Relative heights keep the FFT's round-off small where the ground is level.
    reference = float(np.median(heights))
    z = heights - reference
    z_max = float(np.max(np.abs(heights))) + float(np.max(np.abs(z)))
    corr = _Correlator(z, pad)
    unknown = None
    if not terrain.known.all():
        unknown = _Correlator((~terrain.known).astype(np.float64), pad)
    values = np.empty((nx, ny, _N * len(discs)), dtype=dtype)
    valid = np.empty((len(discs), nx, ny), dtype=bool)
    for n, disc in enumerate(discs):
        beta, energy = _fit_radius(disc, corr, z, z_max)
        values[:, :, n * _N : (n + 1) * _N] = _feature_block(beta, disc, energy)
        p, q = disc.half_cells
        ok = np.zeros((nx, ny), dtype=bool)
        ok[p : nx - p, q : ny - q] = True
        if unknown is not None:
            touched = unknown.correlate(disc.kernels[5]) > 0.5
            ok &= ~touched
        valid[n] = ok
    if oriented_heading is not None:
        if not np.isfinite(oriented_heading):
            raise TerrainError(f"oriented_heading must be finite [rad], got {oriented_heading}")
        values = orient_features(values, float(oriented_heading)).astype(dtype, copy=False)
    return TerrainFeatures(
        values,
        valid,
        radii_t,
        (terrain.x0, terrain.y0, terrain.dx, terrain.dy),
        None if oriented_heading is None else float(oriented_heading),
    )
