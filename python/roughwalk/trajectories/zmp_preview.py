"""ZMP preview control of the cart-table model (Kajita et al. 2003; Zucker 2011, §5.2).

The trunk is a cart of height z_c on a massless table: per horizontal axis
the state x = (c, ċ, c̈) [m, m/s, m/s²] is driven by the jerk u [m/s³],

    x_{k+1} = A·x_k + B·u_k,   p_k = C·x_k = c_k − (z_c/g)·c̈_k   (the ZMP).

The controller minimises Σ_k Q·(p_k − p_ref,k)² + R·u_k² with the reference
known N samples ahead. With P from the discrete algebraic Riccati equation
(:func:`riccati_doubling`) the optimum is

    u_k = −K·x_k + Σ_{j=1..N} f_j·p_ref,k+j,
    K = (R + BᵀPB)⁻¹BᵀPA,   f_j = (R + BᵀPB)⁻¹Bᵀ·((A − BK)ᵀ)^{j−1}·CᵀQ,

Kajita's preview law without the integrator his servo adds against model
error (the model here is exact, and a reference at rest is then held at rest).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["PreviewRun", "ZmpPreviewController", "riccati_doubling"]


def riccati_doubling(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    q: NDArray[np.float64],
    r: NDArray[np.float64],
    *,
    tolerance: float = 1e-14,
    max_iterations: int = 64,
) -> NDArray[np.float64]:
    """P of the discrete algebraic Riccati equation by the doubling algorithm.

    P = AᵀPA − AᵀPB(R + BᵀPB)⁻¹BᵀPA + Q, the same P as
    ``scipy.linalg.solve_discrete_are`` (the tests compare them). The
    structure-preserving doubling iteration (Chu, Fan, Lin 2005) with
    G = BR⁻¹Bᵀ and W = I + GH:

        A ← A·W⁻¹·A,   G ← G + A·W⁻¹·G·Aᵀ,   H ← H + Aᵀ·H·W⁻¹·A,

    H → P quadratically (9–12 iterations for the cart-table). Why not scipy:
    its QZ route wakes OpenBLAS's worker threads, which then spin for the
    rest of the footstep; one controller per CoM height tripled a
    footstep's CPU time on a 2-core machine.
    """
    n = a.shape[0]
    eye = np.eye(n)
    g = b @ np.linalg.solve(r, b.T)
    h = np.array(q, dtype=float)
    a = np.array(a, dtype=float)
    # An unstabilisable pair makes the iterates overflow: caught below, not warned.
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(max_iterations):
            w = eye + g @ h
            wa = np.linalg.solve(w, a)
            wg = np.linalg.solve(w, g)
            h_next = h + a.T @ h @ wa
            g = g + a @ wg @ a.T
            a = a @ wa
            if not np.all(np.isfinite(h_next)):
                break
            converged = np.max(np.abs(h_next - h)) <= tolerance * np.max(np.abs(h_next))
            h = h_next
            if converged:
                return 0.5 * (h + h.T)
    raise InvalidArgumentError(
        f"the Riccati doubling iteration did not converge in {max_iterations} steps "
        "(is (A, B) stabilisable and Q ≥ 0?)"
    )


@dataclass(frozen=True)
class PreviewRun:
    """The controller's output over a run of n samples (n + 1 states, both ends included).

    ``com``, ``com_velocity``, ``com_acceleration`` and ``zmp`` are (n + 1, 2)
    [m, m/s, m/s², m]; ``jerk`` (n, 2) [m/s³]; ``final_state`` (3, 2) is the
    state at the last sample, to continue from.
    """

    com: NDArray[np.float64]
    com_velocity: NDArray[np.float64]
    com_acceleration: NDArray[np.float64]
    zmp: NDArray[np.float64]
    jerk: NDArray[np.float64]

    @property
    def final_state(self) -> NDArray[np.float64]:
        """(3, 2): position, velocity, acceleration per axis at the last sample."""
        return np.stack([self.com[-1], self.com_velocity[-1], self.com_acceleration[-1]])


class ZmpPreviewController:
    """Preview control of the cart-table ZMP on both horizontal axes.

    Parameters
    ----------
    com_height:
        z_c, the CoM's height above the support surface [m].
    dt:
        Sample period [s].
    tracking_weight:
        Q [1/m²].
    jerk_weight:
        R [s⁶/m²].
    gravity:
        g [m/s²].
    """

    def __init__(
        self,
        com_height: float,
        dt: float,
        *,
        tracking_weight: float = 1.0,
        jerk_weight: float = 1e-6,
        gravity: float = 9.81,
    ) -> None:
        for name, v in (
            ("com_height", com_height),
            ("dt", dt),
            ("tracking_weight", tracking_weight),
            ("jerk_weight", jerk_weight),
            ("gravity", gravity),
        ):
            if not (math.isfinite(v) and v > 0):
                raise InvalidArgumentError(f"ZMP preview {name} must be positive, got {v}")
        self.com_height = float(com_height)
        self.dt = float(dt)
        t = self.dt
        self.A = np.array([[1.0, t, t * t / 2], [0.0, 1.0, t], [0.0, 0.0, 1.0]])
        self.B = np.array([[t**3 / 6], [t * t / 2], [t]])
        self.C = np.array([[1.0, 0.0, -self.com_height / gravity]])
        q = float(tracking_weight)
        r = np.array([[float(jerk_weight)]])
        p = riccati_doubling(self.A, self.B, self.C.T @ self.C * q, r)
        self.P = p
        g = 1.0 / float(r[0, 0] + (self.B.T @ p @ self.B)[0, 0])
        self.K = (g * self.B.T @ p @ self.A).reshape(3)
        self._closed_t = (self.A - self.B @ self.K[None, :]).T
        self._gain_scale = g
        self._q = q
        self._gains = np.zeros(0)

    def preview_gains(self, n: int) -> NDArray[np.float64]:
        """f_1 … f_n, the weights of the reference 1 … n samples ahead."""
        if n > self._gains.shape[0]:
            out = np.empty(n)
            v = self.C.T[:, 0] * self._q
            for j in range(n):
                out[j] = self._gain_scale * float(self.B[:, 0] @ v)
                v = self._closed_t @ v
            self._gains = out
        return self._gains[:n]

    def zmp(self, state: ArrayLike) -> NDArray[np.float64]:
        """ZMP (..., 2) of states (..., 3, 2) [m]."""
        s = np.asarray(state, dtype=float)
        return s[..., 0, :] + self.C[0, 2] * s[..., 2, :]

    def run(
        self,
        reference: ArrayLike,
        n: int,
        initial_state: ArrayLike | None = None,
        preview: int | None = None,
    ) -> PreviewRun:
        """Drive the cart for ``n`` samples along a ZMP reference.

        Parameters
        ----------
        reference:
            (M, 2) reference ZMP [m] at samples 0, 1, ... of this run (sample
            0 is the current one); held at its last value beyond M.
        n:
            Number of samples to advance.
        initial_state:
            (3, 2) CoM position, velocity, acceleration per axis; default at
            rest on the first reference point.
        preview:
            Samples N of preview; default all of ``reference`` ahead.
        """
        ref = np.asarray(reference, dtype=float)
        if ref.ndim != 2 or ref.shape[1] != 2 or ref.shape[0] < 1:
            raise InvalidArgumentError(f"ZMP reference must have shape (M, 2), got {ref.shape}")
        if n < 0:
            raise InvalidArgumentError(f"number of samples must be ≥ 0, got {n}")
        x = (
            np.array([ref[0], [0.0, 0.0], [0.0, 0.0]])
            if initial_state is None
            else np.array(initial_state, dtype=float).reshape(3, 2)
        )
        horizon = max(ref.shape[0] - 1, 1) if preview is None else max(int(preview), 1)
        f = self.preview_gains(horizon)
        # Pad with the last value so every window k+1 … k+N exists.
        padded = np.concatenate([ref, np.repeat(ref[-1:], n + horizon + 1, axis=0)])
        # feed[k] = Σ_j f_j·r_{k+j}: a correlation, computed once.
        feed = np.stack(
            [np.correlate(padded[1:, a], f, mode="valid")[: n + 1] for a in range(2)], axis=1
        )
        states = np.empty((n + 1, 3, 2))
        jerk = np.empty((n, 2))
        states[0] = x
        for k in range(n):
            u = -self.K @ x + feed[k]
            jerk[k] = u
            x = self.A @ x + self.B @ u[None, :]
            states[k + 1] = x
        return PreviewRun(
            com=states[:, 0].copy(),
            com_velocity=states[:, 1].copy(),
            com_acceleration=states[:, 2].copy(),
            zmp=self.zmp(states),
            jerk=jerk,
        )
