"""The :class:`Runner`: one control tick = one servo command, then whole physics steps.

The physics step is an integer fraction of the control period
(:attr:`WorldConfig.substeps <roughwalk.sim.config.WorldConfig.substeps>`):
the command is held for that many steps, as a digital controller's output
is between its ticks.

Actuator limits. Torque limits are the servos' ``forcerange``, which MuJoCo
clamps on every physics step. MuJoCo has no joint velocity limit, so the
runner enforces the robot's (``Robot.joint_velocity_limit``) on what it
commands: the servo target moves at most v_max·Δt_control per tick, so
however a controller jumps (an integrator correction, a reflex), the target
never runs faster than the joint can. Measured speeds can still exceed the
limit briefly on impacts; the runner records the largest ratio seen so
reports can show it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

from roughwalk.sim.measured_state import MeasuredState, measure

if TYPE_CHECKING:
    from roughwalk.sim.world import World

__all__ = ["Runner", "ServoCommand"]


@dataclass(frozen=True)
class ServoCommand:
    """What the controller asks of the 12 servos for one tick, ``Robot.joint_names`` order.

    ``q`` [rad] is the position target, ``qd`` [rad/s] the velocity the servo
    damps towards, ``tau_ff`` [N·m] a feed-forward torque, ``stiffness`` (0–1]
    the scale of each servo's gains.
    """

    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    tau_ff: NDArray[np.float64]
    stiffness: NDArray[np.float64]


class Runner:
    """Steps a :class:`~roughwalk.sim.world.World` under servo commands.

    The servos are the model's own position actuators, τ = kp·(u − q) − kv·q̇
    clamped to their force range; a command becomes u = q_t + (kv·q̇_d + τ_ff)/kp
    with q_t the rate-limited target, so that τ = kp·(q_t − q) + kv·(q̇_d − q̇) + τ_ff
    before clamping. Gains are scaled per joint by ``stiffness``.
    """

    def __init__(self, world: World) -> None:
        self.world = world
        self._target: NDArray[np.float64] | None = None
        self.max_actuator_force = np.zeros(12)
        self.max_speed_ratio = 0.0
        self.ticks = 0
        self._limit = np.asarray(world.robot.joint_velocity_limit, dtype=float)

    @property
    def target(self) -> NDArray[np.float64] | None:
        """The last rate-limited position target [rad]."""
        return None if self._target is None else self._target.copy()

    def reset(
        self,
        q: NDArray[np.float64],
        base_pos: NDArray[np.float64],
        base_quat: NDArray[np.float64],
    ) -> MeasuredState:
        """Place the robot (see :meth:`World.reset`) and return its state."""
        self.world.reset(q, base_pos, base_quat)
        self._target = np.asarray(q, dtype=float).copy()
        self._set_stiffness(np.ones(12))
        return measure(self.world)

    def _set_stiffness(self, scale: NDArray[np.float64]) -> None:
        w = self.world
        a = w.actuator_of_joint
        kp = w.kp * scale
        w.model.actuator_gainprm[a, 0] = kp
        w.model.actuator_biasprm[a, 1] = -kp
        # Damping ∝ √stiffness keeps the servo's damping ratio.
        w.model.actuator_biasprm[a, 2] = -w.kv * np.sqrt(scale)

    def step(self, command: ServoCommand) -> MeasuredState:
        """Apply ``command`` for one control period and return the new state."""
        w = self.world
        dt = w.control_dt
        q_cmd = np.asarray(command.q, dtype=float)
        if self._target is None:
            self._target = q_cmd.copy()
        else:
            reach = self._limit * dt
            self._target = self._target + np.clip(q_cmd - self._target, -reach, reach)
        scale = np.clip(np.asarray(command.stiffness, dtype=float), 1e-3, 1.0)
        self._set_stiffness(scale)
        kp = w.kp * scale
        kv = w.kv * np.sqrt(scale)
        u = self._target + (kv * command.qd + command.tau_ff) / kp
        w.data.ctrl[w.actuator_of_joint] = np.clip(u, w.ctrl_lower, w.ctrl_upper)
        force = w.data.actuator_force
        a = w.actuator_of_joint
        for _ in range(w.config.substeps):
            mujoco.mj_step(w.model, w.data)
            np.maximum(self.max_actuator_force, np.abs(force[a]), out=self.max_actuator_force)
        self.ticks += 1
        state = measure(w)
        ratio = float(np.max(np.abs(state.qd) / self._limit))
        if np.isfinite(ratio):
            self.max_speed_ratio = max(self.max_speed_ratio, ratio)
        return state
