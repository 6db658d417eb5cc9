"""The :class:`LegIntegrator`: slow per-leg integrators that hold the trunk on its path.

Zucker 2011, §6: with the desired trunk pose (x, R), a supporting foot's
desired body-frame position f_B and its desired world position
f_W = R·f_B + x, and the observed trunk pose (x̄, R̄), the foot as seen from
the observed trunk is f̄_B = R̄ᵀ(f_W − x̄), and each supporting leg runs

    Δ ← Δ + γ(f_B − f̄_B),    q ← IK_B(f_B + Δ),

shortening a leg when the trunk is too high and lengthening it when too
low. While a foot is in flight its Δ decays to zero, so it lands where
planned; while a foot planned to support bears no load (a trunk rocking
onto its other feet) its Δ holds, since that leg cannot move the trunk.
f_B is taken as FK_B(q_d), the body-frame foot of the desired joint
angles, which for a supporting leg is the same point and for a swing leg
follows its swing.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from roughwalk.robots._rotations import quat_to_matrix
from roughwalk.sim.config import IntegratorConfig

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.sim.trajectory_buffer import DesiredState

__all__ = ["LegIntegrator"]


class LegIntegrator:
    """The four legs' integrators Δ (4, 3) [m, base frame] and the joint angles they command.

    Parameters
    ----------
    robot:
        The robot (for body-frame FK and IK).
    config:
        Gain, bound and flight decay (:class:`IntegratorConfig`).
    control_dt:
        The control period [s] (one update per tick).
    """

    def __init__(
        self, robot: Robot, config: IntegratorConfig | None = None, control_dt: float = 0.002
    ) -> None:
        self.robot = robot
        self.config = config if config is not None else IntegratorConfig()
        self.delta = np.zeros((4, 3))
        self._leg_joints = np.asarray(robot.canonical_index).reshape(4, 3)
        self._decay = math.exp(-control_dt / self.config.flight_decay_s)

    def reset(self) -> None:
        """Zero every Δ."""
        self.delta[:] = 0.0

    def update(
        self,
        desired: DesiredState,
        measured: MeasuredState,
        offset: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        """Update Δ from the trunk error and return the commanded joint angles q (12,) [rad].

        ``offset`` (4, 3) [m, base frame] moves every foot target on top of Δ
        (the CoP stabiliser's trunk shift).
        """
        cfg = self.config
        moved = offset is not None and bool(np.any(offset))
        if not cfg.enabled:
            return self._solve(desired, offset if moved else None)
        rot = quat_to_matrix(desired.base_quat)
        rot_bar = measured.rotation
        f_w = desired.feet
        f_b = (f_w - desired.base_pos) @ rot
        f_b_bar = (f_w - measured.base_pos) @ rot_bar
        down = desired.support
        # Anti-windup: a planned supporting foot that bears no load cannot move
        # the trunk, so its Δ holds still. Integrating there (a trunk rocking on
        # two feet, the other two in the air) lengthens the lifted legs while
        # they hang, and they kick the trunk back when they land: the rocking
        # grows until the robot falls (a 1.5 N·s push on a standing LittleDog).
        acting = down & (np.asarray(measured.foot_forces)[:, 2] >= cfg.min_load_n)
        self.delta[acting] += cfg.gain * (f_b[acting] - f_b_bar[acting])
        self.delta[~down] *= self._decay
        norm = np.linalg.norm(self.delta, axis=1, keepdims=True)
        self.delta *= np.minimum(1.0, cfg.max_offset_m / np.maximum(norm, 1e-12))
        return self._solve(desired, offset if moved else None)

    def _solve(
        self, desired: DesiredState, offset: NDArray[np.float64] | None
    ) -> NDArray[np.float64]:
        """Joint angles IK_B(f_B + Δ + offset); legs without a correction keep the plan's."""
        change = self.delta if offset is None else self.delta + offset
        active = np.any(np.abs(change) > 1e-7, axis=1)
        if not np.any(active):
            return desired.q
        feet_b = self.robot.foot_positions(desired.q) + change
        q, _ = self.robot.inverse_kinematics(feet_b)
        # Legs without a correction keep their planned angles exactly.
        keep = self._leg_joints[~active].ravel()
        q[keep] = desired.q[keep]
        return q
