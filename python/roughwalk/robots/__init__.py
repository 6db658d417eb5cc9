"""Robots: quadruped models from MJCF, their kinematic description and kinematics.

Start with :func:`load_robot` (a registered name or any MJCF path); the
shipped models are listed by :func:`list_robots`. This wing knows nothing of
planning or simulation; it uses MuJoCo only to compile model files.
"""

from roughwalk.robots.canonical_frame import LEG_NAMES, leg_label
from roughwalk.robots.mjcf_loader import (
    JOINT_ROLES,
    CollisionGeom,
    LegDescription,
    QuadrupedDescription,
    describe_quadruped,
)
from roughwalk.robots.registry import RobotInfo, list_robots, register_robot, robot_info
from roughwalk.robots.robot import NominalStance, Robot, load_robot

__all__ = [
    "load_robot",
    "Robot",
    "NominalStance",
    "list_robots",
    "robot_info",
    "register_robot",
    "RobotInfo",
    "LegDescription",
    "CollisionGeom",
    "QuadrupedDescription",
    "describe_quadruped",
    "leg_label",
    "LEG_NAMES",
    "JOINT_ROLES",
]
