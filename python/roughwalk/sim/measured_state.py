"""The :class:`MeasuredState`: what the robot's sensors tell the controller each tick.

LittleDog's software saw the trunk pose from motion capture, the joint
angles from encoders and a three-axis force per foot (Zucker 2011, §1); the
simulation reads the same quantities, exactly, from MuJoCo's state and
contacts.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

from roughwalk.robots._rotations import quat_to_matrix

if TYPE_CHECKING:
    from roughwalk.sim.world import World

__all__ = ["MeasuredState", "measure"]


@dataclass(frozen=True)
class MeasuredState:
    """The robot's state at one instant.

    Attributes
    ----------
    time:
        Simulated time [s].
    q, qd:
        (12,) joint angles [rad] and velocities [rad/s], ``Robot.joint_names`` order.
    base_pos, base_quat:
        Trunk position [m] and orientation (w, x, y, z) of the canonical base frame.
    base_vel, base_angvel:
        (3,) trunk linear [m/s] and angular [rad/s] velocity, world axes.
    com:
        (3,) the whole robot's centre of mass [m] (MuJoCo's centre of mass
        of the trunk's subtree, from the physics step's start state).
    feet:
        (4, 3) foot centres [m], canonical legs.
    foot_forces:
        (4, 3) ground reaction force on each foot [N], world axes.
    trunk_contact:
        True when a trunk geom touches the terrain.
    shin_contact:
        (4,) True when a leg geom other than the foot touches the terrain.
    actuator_force:
        (12,) joint torques the servos produced on the last physics step [N·m].
    self_contact:
        True when two of the robot's own geoms are in contact (a leg and the
        trunk, two legs, two links of one leg that are not parent and child):
        contacts no planner here models, which a robot file's collision
        shapes can make by mistake (a trunk hull the legs rub).
    """

    time: float
    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    base_pos: NDArray[np.float64]
    base_quat: NDArray[np.float64]
    base_vel: NDArray[np.float64]
    base_angvel: NDArray[np.float64]
    com: NDArray[np.float64]
    feet: NDArray[np.float64]
    foot_forces: NDArray[np.float64]
    trunk_contact: bool
    shin_contact: NDArray[np.bool_]
    actuator_force: NDArray[np.float64]
    self_contact: bool = False

    @property
    def rotation(self) -> NDArray[np.float64]:
        """(3, 3) trunk orientation R̄."""
        return quat_to_matrix(self.base_quat)

    @property
    def roll_pitch(self) -> tuple[float, float]:
        """Trunk roll and pitch [rad] (z–y–x Euler angles)."""
        r = self.rotation
        pitch = float(np.arcsin(np.clip(-r[2, 0], -1.0, 1.0)))
        roll = float(np.arctan2(r[2, 1], r[2, 2]))
        return roll, pitch

    @property
    def feet_centroid(self) -> NDArray[np.float64]:
        """(3,) mean of the four foot centres [m]."""
        return self.feet.mean(axis=0)


def measure(world: World) -> MeasuredState:
    """Read the state of ``world.data`` (after ``mj_step`` or ``mj_forward``)."""
    m, d = world.model, world.data
    robot = world.robot
    base_pos, base_quat = robot.base_pose_from_qpos(d.qpos)
    roles = world.roles
    forces = np.zeros((4, 3))
    trunk = False
    shin = np.zeros(4, dtype=bool)
    self_contact = False
    wrench = np.zeros(6)
    terrain = roles.terrain
    for i in range(d.ncon):
        c = d.contact[i]
        g1, g2 = int(c.geom1), int(c.geom2)
        if g1 == terrain:
            other, sign = g2, 1.0
        elif g2 == terrain:
            other, sign = g1, -1.0
        else:
            self_contact = self_contact or (roles.on_robot(g1) and roles.on_robot(g2))
            continue
        leg = int(roles.leg[other])
        if leg == -1:
            trunk = True
            continue
        if leg < 0:
            continue
        if other != roles.foot[leg]:
            shin[leg] = True
            continue
        mujoco.mj_contactForce(m, d, i, wrench)
        # The contact force acts on geom2 along the frame's normal (from geom1
        # to geom2); flip it when the terrain is geom2.
        forces[leg] += sign * (c.frame.reshape(3, 3).T @ wrench[:3])
    # Velocities of the free joint: linear in world axes, angular in the body frame.
    vel = np.zeros(6)
    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, world.base_body, vel, 0)
    return MeasuredState(
        time=float(d.time),
        q=d.qpos[world.joint_qpos].copy(),
        qd=d.qvel[world.joint_dof].copy(),
        base_pos=base_pos,
        base_quat=base_quat,
        base_vel=vel[3:].copy(),
        base_angvel=vel[:3].copy(),
        com=d.subtree_com[world.base_body].copy(),
        feet=d.geom_xpos[roles.foot].copy(),
        foot_forces=forces,
        trunk_contact=trunk,
        shin_contact=shin,
        actuator_force=d.actuator_force[world.actuator_of_joint].copy(),
        self_contact=self_contact,
    )
