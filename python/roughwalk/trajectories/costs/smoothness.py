"""CHOMP's smoothness term and the metric of its covariant update (Ratliff 2009; Zucker 2011, §5.1).

ξ holds n interior samples (n, m) between two fixed end configurations. With
K the finite-difference matrix of order 1 (velocity) or 2 (acceleration), the
trajectory's change δ = ξ − ξ₀ from the initial one, zero at and beyond the
fixed ends, costs

    f_smooth = ½·λ·Σ_d w_d·δ_dᵀ A δ_d,   A = KᵀK / h^(2·order − 1),

i.e. ξᵀAξ + ξᵀb + c per coordinate with b = −2Aξ₀ and c = ξ₀ᵀAξ₀. h =
1/(n + 1) is the sample spacing in normalised time, so that f_smooth
approximates ∫(dᵒδ/dsᵒ)² ds whatever n is: that, and the obstacle term's
arc-length weighting, make the update ξ ← ξ − α·(A ⊗ W)⁻¹∇U independent of
the number of samples. A is banded (tri- or pentadiagonal); it is factored
once (scipy.linalg.cholesky_banded) and every update is a banded solve.

Samples can also be held inside the trajectory (``fixed``): their change
stays zero, and the metric is A restricted to the free samples, still
banded with the same bandwidth.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import cho_solve_banded, cholesky_banded

from roughwalk.errors import InvalidArgumentError

__all__ = ["Smoothness"]

_STENCILS = {1: (2.0, -1.0), 2: (6.0, -4.0, 1.0)}


class Smoothness:
    """The smoothness term of n samples of m coordinates, and its banded metric.

    Parameters
    ----------
    reference:
        ξ₀ (n, m), the trajectory whose changes are penalised.
    order:
        1 (squared velocities) or 2 (squared accelerations).
    weight:
        λ.
    metric:
        w (m,): the weight of each coordinate in the metric, e.g. [m²/rad²]
        for an angle so that all coordinates count in metres.
    fixed:
        Optional (n,) mask of samples held at the reference.
    """

    def __init__(
        self,
        reference: ArrayLike,
        order: int,
        weight: float,
        metric: ArrayLike,
        fixed: ArrayLike | None = None,
    ) -> None:
        xi0 = np.asarray(reference, dtype=float)
        if xi0.ndim != 2 or xi0.shape[0] < 1:
            raise InvalidArgumentError(f"smoothness reference must be (n ≥ 1, m), got {xi0.shape}")
        if order not in _STENCILS:
            raise InvalidArgumentError(f"smoothness order must be 1 or 2, got {order!r}")
        w = np.asarray(metric, dtype=float)
        if w.shape != (xi0.shape[1],) or np.any(w <= 0):
            raise InvalidArgumentError(
                f"metric weights must be {xi0.shape[1]} positive numbers, got {w.tolist()}"
            )
        self.reference = xi0
        self.order = order
        self.weight = float(weight)
        self.metric = w
        n = xi0.shape[0]
        self.h = 1.0 / (n + 1)
        held = np.zeros(n, dtype=bool) if fixed is None else np.asarray(fixed, dtype=bool)
        if held.shape != (n,):
            raise InvalidArgumentError(
                f"fixed must be a mask of {n} samples, got shape {held.shape}"
            )
        if held.all():
            raise InvalidArgumentError("every sample is fixed: nothing to optimise")
        self.fixed = held
        self.free = np.flatnonzero(~held)
        stencil = _STENCILS[order]
        full = np.zeros((order + 1, n))
        # Upper banded form: band[order − k, j] = A[j − k, j].
        for k, value in enumerate(stencil):
            full[order - k, k:] = value
        full /= self.h ** (2 * order - 1)
        if held.any():
            # A restricted to the free samples: drop rows and columns, keep the band.
            dense = _band_to_dense(full, order)[np.ix_(self.free, self.free)]
            full = _dense_to_band(dense, order)
        self.band = full
        self._factor = cholesky_banded(self.band)

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.reference.shape[0])

    def matrix(self) -> NDArray[np.float64]:
        """A over the free samples as a dense matrix (for inspection and tests)."""
        return _band_to_dense(self.band, self.order)

    def _apply_free(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        u = self.order
        y = self.band[u][:, None] * x
        for k in range(1, u + 1):
            c = self.band[u - k, k:][:, None]
            y[:-k] += c * x[k:]
            y[k:] += c * x[:-k]
        return y

    def apply(self, v: ArrayLike) -> NDArray[np.float64]:
        """A·v for v (n, m), from the band (rows of fixed samples are zero)."""
        x = np.asarray(v, dtype=float)
        out = np.zeros_like(x)
        out[self.free] = self._apply_free(x[self.free])
        return out

    def linear_term(self) -> NDArray[np.float64]:
        """B = −2·A·ξ₀ (n, m) of ξᵀAξ + ξᵀb + c."""
        return -2.0 * self.apply(self.reference)

    def value(self, xi: ArrayLike) -> float:
        """½·λ·Σ_d w_d·δ_dᵀ A δ_d."""
        d = np.asarray(xi, dtype=float) - self.reference
        return 0.5 * self.weight * float(np.sum(self.metric * np.sum(d * self.apply(d), axis=0)))

    def gradient(self, xi: ArrayLike) -> NDArray[np.float64]:
        """λ·w_d·A·δ_d (n, m)."""
        d = np.asarray(xi, dtype=float) - self.reference
        return self.weight * self.metric * self.apply(d)

    def precondition(self, gradient: ArrayLike) -> NDArray[np.float64]:
        """(A ⊗ W)⁻¹·g (n, m) by the banded Cholesky factor: the covariant direction.

        Fixed samples get zero.
        """
        g = np.asarray(gradient, dtype=float)
        out = np.zeros_like(g)
        out[self.free] = cho_solve_banded((self._factor, False), g[self.free]) / self.metric
        return out


def _band_to_dense(band: NDArray[np.float64], order: int) -> NDArray[np.float64]:
    n = band.shape[1]
    a = np.zeros((n, n))
    for k in range(order + 1):
        diag = band[order - k, k:]
        a += np.diag(diag, k)
        if k:
            a += np.diag(diag, -k)
    return a


def _dense_to_band(a: NDArray[np.float64], order: int) -> NDArray[np.float64]:
    n = a.shape[0]
    band = np.zeros((order + 1, n))
    for k in range(order + 1):
        band[order - k, k:] = np.diag(a, k)
    return band
