"""The :class:`JointController`: PD servos with gravity compensation and soft touchdowns.

Zucker 2011, §6: LittleDog's servos "support per-joint proportional-derivative
(PD) control, as well as force control, which we use to minimize shear
forces and to help soften foot impacts on touchdown". Here:

* the PD part is the robot's position servos (:class:`~roughwalk.sim.runner.Runner`);
* a feed-forward torque τ_ff = g_leg(q) − J_footᵀ·f holds each leg's own
  weight (MuJoCo's bias forces on the leg's joints) and the ground force f
  the trajectory plans for that foot, so the servos do not sag under load;
  planning tangential forces consistent with the cart-table dynamics, and no
  other shear, is how the plan keeps shear small;
* force-aware softening: a swing leg's servo gains drop to a fraction in the
  last moments before the planned touchdown and as soon as its foot meets
  the ground early (measured force above a threshold), then return to full
  stiffness over a short ramp once the leg bears weight.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

from roughwalk.sim.config import ControllerConfig
from roughwalk.sim.runner import ServoCommand

if TYPE_CHECKING:
    from roughwalk.sim.measured_state import MeasuredState
    from roughwalk.sim.trajectory_buffer import DesiredState
    from roughwalk.sim.world import World

__all__ = ["JointController"]


class JointController:
    """Turns commanded joint angles and the desired state into a :class:`ServoCommand`."""

    def __init__(self, world: World, config: ControllerConfig | None = None) -> None:
        self.world = world
        self.config = config if config is not None else ControllerConfig()
        robot = world.robot
        index = np.asarray(robot.canonical_index)
        # leg_joints[l] = positions (in joint_names order) of leg l's three joints.
        self.leg_joints = index.reshape(4, 3)
        self._jac = np.zeros((3, world.model.nv))
        self._soft_last = np.full(4, -np.inf)
        self.stiffness = np.ones(4)

    def reset(self) -> None:
        """Forget the softening history (full stiffness)."""
        self._soft_last[:] = -np.inf
        self.stiffness[:] = 1.0

    def feedforward(self, forces: NDArray[np.float64]) -> NDArray[np.float64]:
        """τ_ff (12,) [N·m]: leg bias torques minus J_footᵀ·f for ground forces f (4, 3) [N].

        f is the force the ground exerts on each foot, world axes.
        """
        w = self.world
        m, d = w.model, w.data
        tau = np.array(d.qfrc_bias[w.joint_dof])
        r = w.robot.foot_radius
        for leg in range(4):
            f = forces[leg]
            if not np.any(f):
                continue
            point = d.geom_xpos[w.roles.foot[leg]] - np.array([0.0, 0.0, r])
            mujoco.mj_jac(m, d, self._jac, None, point, m.geom_bodyid[w.roles.foot[leg]])
            cols = w.joint_dof[self.leg_joints[leg]]
            tau[self.leg_joints[leg]] -= self._jac[:, cols].T @ f
        return tau

    def command(
        self, q_cmd: NDArray[np.float64], desired: DesiredState, measured: MeasuredState
    ) -> ServoCommand:
        """The servo command for joint angles ``q_cmd`` (12,) [rad] at the ``desired`` state."""
        cfg = self.config
        now = measured.time
        normal = measured.foot_forces[:, 2]
        soft = ~desired.support & (
            (desired.touchdown_in <= cfg.touchdown_window_s) | (normal > cfg.impact_force_n)
        )
        self._soft_last[soft] = now
        low = cfg.touchdown_stiffness
        since = now - self._soft_last
        ramp = np.clip(since / max(cfg.recover_s, 1e-9), 0.0, 1.0)
        self.stiffness = np.where(soft, low, low + (1.0 - low) * ramp)
        scale = np.ones(12)
        for leg in range(4):
            scale[self.leg_joints[leg]] = self.stiffness[leg]
        forces = desired.forces * desired.support[:, None]
        tau = self.feedforward(forces) if cfg.gravity_compensation else np.zeros(12)
        qd = desired.qd if cfg.velocity_feedforward else np.zeros(12)
        return ServoCommand(q=q_cmd, qd=qd, tau_ff=tau, stiffness=scale)
