"""Weighted least-squares tasks of the whole-body QP, over x = [q̈, τ, f].

A task asks A x ≈ b with a weight w; the QP minimises Σ w‖A x − b‖². The
motion tasks are accelerations: a point with Jacobian J (J q̇ its velocity)
should accelerate by a_des, i.e. J q̈ = a_des − J̇ q̇, where a_des carries
the planned acceleration plus PD feedback on the planned position and
velocity (Bellicoso et al. 2016, the controller Melon et al. 2020 §V used).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["QPLayout", "LeastSquaresTask", "motion_task", "force_task", "regularisation"]


@dataclass(frozen=True)
class QPLayout:
    """Where each unknown sits in the QP's vector x = [q̈ (nv), τ (nu), f (3·nc)].

    Attributes
    ----------
    nv:
        Degrees of freedom of the floating-base model (6 + joints).
    nu:
        Actuated joints (torques).
    n_contacts:
        Feet whose contact forces are unknowns (the feet in stance).
    """

    nv: int
    nu: int
    n_contacts: int

    @property
    def size(self) -> int:
        """Length of x."""
        return self.nv + self.nu + 3 * self.n_contacts

    @property
    def qacc(self) -> slice:
        """q̈ [rad/s², m/s²] in x."""
        return slice(0, self.nv)

    @property
    def tau(self) -> slice:
        """τ [N·m] in x."""
        return slice(self.nv, self.nv + self.nu)

    def force(self, contact: int) -> slice:
        """The force [N] of the ``contact``-th foot in stance, in x."""
        start = self.nv + self.nu + 3 * contact
        return slice(start, start + 3)


@dataclass(frozen=True)
class LeastSquaresTask:
    """A x ≈ b with weight w (rows of the QP's objective).

    Attributes
    ----------
    name:
        What the task tracks ("base_linear", "swing_foot LF", ...).
    matrix:
        (m, layout.size) A.
    target:
        (m,) b.
    weight:
        w ≥ 0 (residual units: m/s², rad/s² or N).
    """

    name: str
    matrix: NDArray[np.float64]
    target: NDArray[np.float64]
    weight: float

    def residual(self, x: ArrayLike) -> NDArray[np.float64]:
        """A x − b at a QP solution x."""
        return np.asarray(self.matrix @ np.asarray(x, dtype=float) - self.target)


def motion_task(
    name: str,
    layout: QPLayout,
    jacobian: ArrayLike,
    bias_acceleration: ArrayLike,
    desired_acceleration: ArrayLike,
    weight: float,
) -> LeastSquaresTask:
    """J q̈ = a_des − J̇q̇ for a point or frame with Jacobian J (m, nv).

    ``bias_acceleration`` is J̇q̇ [m/s² or rad/s²], ``desired_acceleration``
    a_des, both (m,).
    """
    jac = np.atleast_2d(np.asarray(jacobian, dtype=float))
    a = np.zeros((jac.shape[0], layout.size))
    a[:, layout.qacc] = jac
    b = np.asarray(desired_acceleration, dtype=float) - np.asarray(bias_acceleration, dtype=float)
    return LeastSquaresTask(name, a, b, float(weight))


def force_task(
    layout: QPLayout, contact: int, planned_force: ArrayLike, weight: float, name: str = "force"
) -> LeastSquaresTask:
    """f_i = f_i^plan [N] for the ``contact``-th foot in stance."""
    a = np.zeros((3, layout.size))
    a[:, layout.force(contact)] = np.eye(3)
    return LeastSquaresTask(name, a, np.asarray(planned_force, dtype=float), float(weight))


def regularisation(
    layout: QPLayout, qacc_weight: float, torque_weight: float
) -> list[LeastSquaresTask]:
    """Small ‖q̈‖² and ‖τ‖² terms that make the QP strictly convex."""
    a_q = np.zeros((layout.nv, layout.size))
    a_q[:, layout.qacc] = np.eye(layout.nv)
    a_t = np.zeros((layout.nu, layout.size))
    a_t[:, layout.tau] = np.eye(layout.nu)
    return [
        LeastSquaresTask("joint_acceleration", a_q, np.zeros(layout.nv), qacc_weight),
        LeastSquaresTask("torque", a_t, np.zeros(layout.nu), torque_weight),
    ]
