"""The joint torques a plan's contact forces ask of a robot's legs.

The NLP plans a single rigid body: it bounds forces by friction and the
feet by a reach box or ball, never by what the leg's motors can push. This
check puts the robot's legs under the plan: at each sample, the joint
angles that place the planned feet under the planned base (analytic IK),
and the torques τ = −Jᵀ f that hold each stance foot's planned force f
(J the foot centre's Jacobian with respect to its leg's joints). The legs'
own weight and inertia are left out: ANYmal C's legs carry ~11 of its 50 kg,
a few N·m at a hip against the limits' 80. A plan whose forces ask more than
the limits cannot be tracked as planned: the controller has to find other
forces (or lose the base).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.trajopt.result import TrajoptResult

if TYPE_CHECKING:
    from roughwalk.robots import Robot

__all__ = ["ImpliedTorques", "implied_torques", "plan_joint_torques"]


@dataclass(frozen=True)
class ImpliedTorques:
    """The largest joint torque a plan's forces imply, and where.

    Attributes
    ----------
    max_nm:
        The largest |τ| [N·m] over joints and samples.
    time_s:
        When [s].
    joint:
        Which joint (the robot's name for it, e.g. "RH_HFE").
    limit_nm:
        That joint's torque limit [N·m] (+inf when the model states none).
    over_limit_fraction:
        Share of the samples at which some joint's |τ| passes its limit.
    unreachable_fraction:
        Share of the samples at which some planned foot is out of its leg's
        reach (its torques are then those of the nearest reachable pose).
    """

    max_nm: float
    time_s: float
    joint: str
    limit_nm: float
    over_limit_fraction: float
    unreachable_fraction: float

    @property
    def over_limit(self) -> bool:
        """Whether the plan asks more than a joint's limit somewhere.

        Not ``max_nm > limit_nm``: the most loaded joint may have the higher
        limit (LittleDog's hips 2.5 N·m, knees 1.4) while another passes its own.
        """
        return self.over_limit_fraction > 0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (an infinite limit as None)."""
        return {
            "max_nm": self.max_nm,
            "time_s": self.time_s,
            "joint": self.joint,
            "limit_nm": self.limit_nm if math.isfinite(self.limit_nm) else None,
            "over_limit_fraction": self.over_limit_fraction,
            "unreachable_fraction": self.unreachable_fraction,
        }

    def describe(self) -> str:
        """One line for people."""
        limit = f" (limit {self.limit_nm:.3g})" if math.isfinite(self.limit_nm) else ""
        return (
            f"the plan's forces ask up to {self.max_nm:.3g} N·m of {self.joint}{limit} "
            f"at {self.time_s:.2f} s; over a limit on {100 * self.over_limit_fraction:.0f} % "
            "of the samples"
        )


def plan_joint_torques(
    robot: Robot,
    base_pos: NDArray[np.float64],
    base_quat: NDArray[np.float64],
    feet: NDArray[np.float64],
    forces: NDArray[np.float64],
    contact: NDArray[np.bool_],
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Joint torques (12,) [N·m, joint_names order] holding ``forces`` at one pose, and reach.

    ``feet`` (4, 3) are the planned contact points [m, world, canonical leg
    order]; each foot's centre sits the robot's foot radius above its
    contact point. ``forces`` (4, 3) [N, world] act on the feet where
    ``contact`` (4,) holds; swing feet ask nothing. Returns the torques and,
    per leg, whether IK reached the foot.
    """
    centres = np.asarray(feet, float) + np.array([0.0, 0.0, robot.foot_radius])
    q, reachable = robot.inverse_kinematics(centres, base_pos, base_quat)
    jacobians = robot.foot_jacobians(q, base_quat)
    canonical = np.zeros((4, 3))
    for leg in range(4):
        if contact[leg]:
            canonical[leg] = -jacobians[leg].T @ np.asarray(forces[leg], float)
    return robot.from_canonical(canonical.reshape(12)), reachable


def implied_torques(result: TrajoptResult, robot: Robot, rate_hz: float = 100.0) -> ImpliedTorques:
    """The largest joint torque ``result``'s planned forces ask of ``robot``'s legs.

    Samples the plan every 1/``rate_hz`` [s] (between the force nodes too).
    """
    plan = result.sample(rate_hz)
    limits = np.asarray(robot.joint_torque_limit, float)
    worst, worst_at, worst_joint = 0.0, 0.0, 0
    over = unreachable = 0
    n = len(plan["t"])
    for k in range(n):
        tau, reachable = plan_joint_torques(
            robot,
            plan["base_position"][k],
            plan["base_quat"][k],
            plan["feet_position"][k],
            plan["forces"][k],
            plan["contact"][k],
        )
        size = np.abs(tau)
        j = int(np.argmax(size))
        if size[j] > worst:
            worst, worst_at, worst_joint = float(size[j]), float(plan["t"][k]), j
        over += bool((size > limits).any())
        unreachable += not bool(reachable.all())
    return ImpliedTorques(
        max_nm=worst,
        time_s=worst_at,
        joint=robot.joint_names[worst_joint],
        limit_nm=float(limits[worst_joint]),
        over_limit_fraction=over / max(n, 1),
        unreachable_fraction=unreachable / max(n, 1),
    )
