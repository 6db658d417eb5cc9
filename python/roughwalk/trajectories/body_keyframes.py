"""Whole-body poses at the footstep boundaries: certificates and heuristic stand-ins.

A :class:`BodyKeyframe` is a trunk pose with the joint angles that hold four
feet, and the resulting centre of mass. The plan's pose certificates
(Zucker 2011, §4.3–4.4) become keyframes; where a plan has none (before its
first step, or a bare footstep list) :func:`pose_over_support` makes one the
way a certificate search starts: the nominal stance fitted to the feet, then
the CoM nudged into the support triangle (§4.4, the support step of the core).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk import _core
from roughwalk.trajectories.euler import matrix_to_rpy, rpy_to_matrix, rpy_to_quat
from roughwalk.trajectories.whole_body import WholeBody

__all__ = ["BodyKeyframe", "keyframe_at", "nominal_fit", "pose_over_support"]


@dataclass(frozen=True)
class BodyKeyframe:
    """A trunk pose holding four feet.

    ``base_pos`` (3,) [m] and ``rpy`` (3,) [rad] place the base frame; ``q``
    (4, 3) canonical joint angles [rad] put the feet on ``feet`` (4, 3)
    [m] (as far as they reach: ``reachable`` per leg); ``com`` (3,) [m] is
    the whole-robot centre of mass in the world.
    """

    base_pos: NDArray[np.float64]
    rpy: NDArray[np.float64]
    q: NDArray[np.float64]
    feet: NDArray[np.float64]
    com: NDArray[np.float64]
    reachable: NDArray[np.bool_]

    @property
    def rotation(self) -> NDArray[np.float64]:
        """(3, 3) trunk orientation R."""
        return rpy_to_matrix(self.rpy)

    @property
    def base_quat(self) -> NDArray[np.float64]:
        """(4,) trunk orientation (w, x, y, z)."""
        return rpy_to_quat(self.rpy)

    @property
    def com_offset(self) -> NDArray[np.float64]:
        """(3,) CoM minus base position, world axes [m]."""
        return self.com - self.base_pos

    def leg_angles(
        self, wb: WholeBody, leg: int
    ) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
        """IK of leg ``leg`` (canonical) from this trunk pose: feet (n, 3) [m] → (n, 3) [rad]."""
        rot = self.rotation
        held = (self.feet - self.base_pos) @ rot

        def angles(points: NDArray[np.float64]) -> NDArray[np.float64]:
            feet_b = np.repeat(held[None], len(points), axis=0)
            feet_b[:, leg] = (np.asarray(points, dtype=float) - self.base_pos) @ rot
            return wb.inverse_kinematics(feet_b)[0][:, leg]

        return angles

    def leg_feet(
        self, wb: WholeBody, leg: int
    ) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
        """FK of leg ``leg`` (canonical) from this pose: angles (n, 3) [rad] → feet (n, 3) [m]."""
        rot = self.rotation

        def feet(angles: NDArray[np.float64]) -> NDArray[np.float64]:
            a = np.asarray(angles, dtype=float).reshape(-1, 3)
            q = np.repeat(self.q[None], len(a), axis=0)
            q[:, leg] = a
            return self.base_pos + wb.foot_positions(q)[:, leg] @ rot.T

        return feet

    def translated(self, wb: WholeBody, shift: ArrayLike) -> BodyKeyframe:
        """The same orientation with the trunk moved by ``shift`` (3,) [m], feet re-solved."""
        return keyframe_at(wb, self.feet, self.base_pos + np.asarray(shift, dtype=float), self.rpy)


def keyframe_at(
    wb: WholeBody, feet: ArrayLike, base_pos: ArrayLike, rpy: ArrayLike
) -> BodyKeyframe:
    """Solve IK for ``feet`` (4, 3) [m] at the trunk pose (base_pos [m], rpy [rad])."""
    f = np.asarray(feet, dtype=float)
    x = np.asarray(base_pos, dtype=float)
    a = np.asarray(rpy, dtype=float)
    rot = rpy_to_matrix(a)
    q, reached = wb.inverse_kinematics(((f - x) @ rot)[None])
    com = x + rot @ wb.center_of_mass(q)[0]
    return BodyKeyframe(x.copy(), a.copy(), q[0], f.copy(), com, reached[0])


def nominal_fit(wb: WholeBody, feet: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Trunk pose (base_pos [m], rpy [rad]) that best fits the nominal stance to ``feet`` (4, 3).

    Yaw from hind-to-front, pitch and roll from the feet's height
    differences, position so the nominal feet's centroid lands on theirs.
    """
    f = np.asarray(feet, dtype=float)
    nominal = wb.robot.nominal_stance.feet
    front, hind = f[:2].mean(axis=0), f[2:].mean(axis=0)
    left, right = f[[0, 2]].mean(axis=0), f[[1, 3]].mean(axis=0)
    yaw = math.atan2(front[1] - hind[1], front[0] - hind[0])
    length = max(float(np.linalg.norm(front[:2] - hind[:2])), 1e-6)
    width = max(float(np.linalg.norm(left[:2] - right[:2])), 1e-6)
    pitch = -math.atan2(front[2] - hind[2], length)
    roll = math.atan2(left[2] - right[2], width)
    rpy = np.array([roll, pitch, yaw])
    base = f.mean(axis=0) - rpy_to_matrix(rpy) @ nominal.mean(axis=0)
    return base, rpy


def pose_over_support(
    wb: WholeBody,
    feet: ArrayLike,
    support: ArrayLike,
    margin: float,
    start: tuple[ArrayLike, ArrayLike] | None = None,
    iterations: int = 8,
) -> BodyKeyframe:
    """A keyframe for ``feet`` (4, 3) with the CoM ``margin`` [m] inside the support polygon.

    ``support`` lists the legs whose feet make the polygon.

    Starts from ``start`` (base_pos, rpy) or :func:`nominal_fit`, then moves
    the trunk horizontally by the core's support step, re-solving IK, until
    the CoM margin is reached (or the incircle centre, if the triangle is too
    small for the margin).
    """
    f = np.asarray(feet, dtype=float)
    legs = np.asarray(support, dtype=np.int64)
    base, rpy = (
        nominal_fit(wb, f) if start is None else (np.asarray(start[0]), np.asarray(start[1]))
    )
    frame = keyframe_at(wb, f, base, rpy)
    quat = rpy_to_quat(rpy)
    rot = rpy_to_matrix(rpy)
    for _ in range(iterations):
        offset_base = rot.T @ frame.com_offset
        step = _core.Quadruped.com_support_step(
            f[legs], frame.base_pos, quat, offset_base, margin, 0.1
        )
        if float(np.linalg.norm(step.delta_x)) < 1e-7:
            break
        frame = keyframe_at(wb, f, np.asarray(step.base_pos), rpy)
    return frame


def rpy_of(quat: ArrayLike) -> NDArray[np.float64]:
    """Roll–pitch–yaw [rad] of a (w, x, y, z) quaternion."""
    from roughwalk.robots._rotations import quat_to_matrix

    return matrix_to_rpy(quat_to_matrix(np.asarray(quat, dtype=float)))
