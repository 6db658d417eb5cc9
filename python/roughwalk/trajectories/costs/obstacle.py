"""CHOMP's workspace obstacle term (Ratliff et al. 2009; Zucker 2011, §5.1).

Every body point u (a sphere of radius r on a collision capsule) pays the
potential c(x) of its clearance d = SDF(x) − r,

    c = −d + ε/2 (d < 0),   (d − ε)²/(2ε) (0 ≤ d ≤ ε),   0 (d > ε),

weighted by arc length: f_obs = ∫_u ∫_t c(x(u, t))·‖ẋ(u, t)‖ dt du, discretised
over the interior samples as Σ_t c(x_t)·‖x_{t+1} − x_{t−1}‖/2. The arc-length
weighting makes the functional gradient

    ∇f_obs = Jᵀ·‖ẋ‖·[(I − x̂′x̂′ᵀ)∇c − c·κ],   κ = ‖ẋ‖⁻²(I − x̂′x̂′ᵀ)ẍ,

act orthogonally to each point's path, so updates move the path instead of
sliding points along it. ``gradient="functional"`` uses that formula
(discretised, Δt cancels), ``"exact"`` the Euclidean gradient of the discrete
sum; they agree as the sampling gets finer.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["ObstacleCost", "ObstacleEvaluation", "obstacle_potential"]

# Smooths ‖v‖ near zero so that resting points keep a differentiable cost [m].
_NORM_EPS = 1e-6


def obstacle_potential(
    clearance: ArrayLike, epsilon: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """c(d) and dc/dd of clearances d [m] for the margin ε [m] (Ratliff 2009)."""
    d = np.asarray(clearance, dtype=float)
    c = np.where(
        d < 0, -d + 0.5 * epsilon, np.where(d <= epsilon, (d - epsilon) ** 2 / (2 * epsilon), 0.0)
    )
    dc = np.where(d < 0, -1.0, np.where(d <= epsilon, (d - epsilon) / epsilon, 0.0))
    return c, dc


def _smooth_norm(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.sqrt(np.sum(v * v, axis=-1) + _NORM_EPS**2)


@dataclass(frozen=True)
class ObstacleEvaluation:
    """One evaluation: value, workspace gradient (T − 2, U, 3) and clearances d (T, U) [m]."""

    value: float
    workspace_gradient: NDArray[np.float64]
    clearance: NDArray[np.float64]


class ObstacleCost:
    """The arc-length-weighted obstacle potential of body points along a trajectory.

    Parameters
    ----------
    sdf:
        Anything with ``query_spheres(centers (N, 3), radii (N,))`` returning
        distances (N,) [m] and gradients (N, 3) (a
        :class:`~roughwalk.terrain.SignedDistanceField`).
    radii:
        (U,) sphere radius of each body point [m].
    epsilon:
        ε [m], the clearance beyond which the potential vanishes.
    weight:
        Factor on the term.
    gradient:
        ``"functional"`` or ``"exact"`` (module docstring).
    """

    def __init__(
        self,
        sdf: Any,
        radii: ArrayLike,
        epsilon: float,
        weight: float = 1.0,
        gradient: str = "functional",
    ) -> None:
        if gradient not in ("functional", "exact"):
            raise InvalidArgumentError(
                f"obstacle gradient must be 'functional' or 'exact', got {gradient!r}"
            )
        if not epsilon > 0:
            raise InvalidArgumentError(f"obstacle epsilon must be positive [m], got {epsilon}")
        self.sdf = sdf
        self.radii = np.asarray(radii, dtype=float)
        self.epsilon = float(epsilon)
        self.weight = float(weight)
        self.mode = gradient

    def clearance(
        self, points: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Clearances d (T, U) [m] of the spheres at points (T, U, 3) and ∇d (T, U, 3)."""
        t, u = points.shape[:2]
        d, g = self.sdf.query_spheres(
            np.ascontiguousarray(points.reshape(-1, 3)), np.tile(self.radii, t)
        )
        return np.asarray(d).reshape(t, u), np.asarray(g).reshape(t, u, 3)

    def evaluate(self, points: ArrayLike, active: ArrayLike) -> ObstacleEvaluation:
        """Cost and workspace gradient of a whole trajectory of body points.

        Parameters
        ----------
        points:
            (T, U, 3) world positions [m] at every sample, fixed ends included.
        active:
            (T, U) which points count (a supporting foot does not).

        Returns
        -------
        The value (weight included) and ∂f/∂x_t (T − 2, U, 3) for the
        interior samples t = 1 … T − 2.
        """
        x = np.asarray(points, dtype=float)
        on = np.asarray(active, dtype=bool)
        d, grad_d = self.clearance(x)
        c, dc = obstacle_potential(d, self.epsilon)
        c = np.where(on, c, 0.0)
        grad_c = np.where(on[..., None], dc[..., None] * grad_d, 0.0)
        central = x[2:] - x[:-2]  # x_{t+1} − x_{t−1}
        length = 0.5 * _smooth_norm(central)  # arc length per interior sample
        ci = c[1:-1]
        value = self.weight * float(np.sum(ci * length))
        if self.mode == "exact":
            g = length[..., None] * grad_c[1:-1]
            unit = central / (4.0 * length[..., None])  # ∂(½‖v‖)/∂v
            # Sample t's length term depends on x_{t±1}: push to neighbours.
            g[1:] += ci[:-1, :, None] * unit[:-1]
            g[:-1] -= ci[1:, :, None] * unit[1:]
        else:
            tangent = central / (2.0 * length[..., None])
            gc = grad_c[1:-1]
            along = np.sum(gc * tangent, axis=-1, keepdims=True)
            second = x[2:] - 2.0 * x[1:-1] + x[:-2]
            normal_second = second - np.sum(second * tangent, axis=-1, keepdims=True) * tangent
            # With ẋ = (x_{t+1} − x_{t−1})/2h and ẍ = Δ²x/h²: ‖ẋ‖h·c·κ = c·(I − x̂′x̂′ᵀ)Δ²x/ℓ_t.
            g = (
                length[..., None] * (gc - along * tangent)
                - ci[..., None] * normal_second / (length[..., None])
            )
        return ObstacleEvaluation(value, self.weight * g, d)

    @staticmethod
    def gradient_pairs(
        workspace_gradient: ArrayLike,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """(t, u) of the interior samples and points whose workspace gradient is nonzero.

        Only these need a Jacobian: most body points are farther than ε
        from the terrain, where the potential and its gradient vanish.
        """
        g = np.asarray(workspace_gradient)
        t, u = np.nonzero(np.any(g != 0.0, axis=-1))
        return t.astype(np.int64), u.astype(np.int64)

    @staticmethod
    def to_coordinates(
        workspace_gradient: ArrayLike,
        jacobian: ArrayLike,
        t: ArrayLike,
        u: ArrayLike,
        n: int,
    ) -> NDArray[np.float64]:
        """Σ_u J_uᵀ·g_u per interior sample (n, m).

        From workspace gradients g (n, U, 3) and the Jacobians J (K, 3, m) of
        the pairs (t, u).
        """
        g = np.asarray(workspace_gradient, dtype=float)
        jac = np.asarray(jacobian, dtype=float)
        tt = np.asarray(t, dtype=np.int64)
        contrib = np.einsum("kim,ki->km", jac, g[tt, np.asarray(u, dtype=np.int64)])
        out = np.zeros((n, jac.shape[-1]))
        np.add.at(out, tt, contrib)
        return out
