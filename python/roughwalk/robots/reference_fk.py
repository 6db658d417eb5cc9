"""Forward kinematics of :class:`LegDescription` chains in plain numpy.

A slow, obviously-correct reference of the chain semantics the Rust core
implements: it is what the tests hold both MuJoCo and the Rust ``Quadruped``
against, and what :class:`~roughwalk.robots.Robot` uses for link frames and
the centre of mass.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.robots._rotations import axis_angle_matrix, quat_to_matrix
from roughwalk.robots.leg_description import LegDescription

__all__ = ["leg_link_frames", "leg_foot_position", "leg_foot_jacobian", "foot_positions"]


def leg_link_frames(
    leg: LegDescription, q: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Positions (3, 3) [m] and rotations (3, 3, 3) of the leg's three bodies in the base frame.

    ``q`` holds the leg's (HAA, HFE, KFE) angles [rad]. Body k's frame is
    T_{k−1} · [R(body_quat_k), body_pos_k] · Trans(anchor_k) · Rot(axis_k, q_k) ·
    Trans(−anchor_k), MuJoCo's hinge.
    """
    angles = np.asarray(q, dtype=float)
    pos, rot = np.zeros(3), np.eye(3)
    positions, rotations = [], []
    for k in range(3):
        pos = pos + rot @ leg.body_pos[k]
        rot = rot @ quat_to_matrix(leg.body_quat[k])
        turn = axis_angle_matrix(leg.axis[k], angles[k])
        pos = pos + rot @ (leg.anchor[k] - turn @ leg.anchor[k])
        rot = rot @ turn
        positions.append(pos)
        rotations.append(rot)
    return np.array(positions), np.array(rotations)


def leg_foot_position(leg: LegDescription, q: ArrayLike) -> NDArray[np.float64]:
    """Foot centre (3,) in the base frame [m] for the leg's angles q [rad]."""
    positions, rotations = leg_link_frames(leg, q)
    return positions[2] + rotations[2] @ leg.foot


def leg_foot_jacobian(leg: LegDescription, q: ArrayLike) -> NDArray[np.float64]:
    """∂(foot centre)/∂q (3, 3) in the base frame [m/rad]; column k is joint k's.

    A hinge turning about the unit axis a through the point p moves the foot
    centre x at a × (x − p) per radian.
    """
    positions, rotations = leg_link_frames(leg, q)
    foot = positions[2] + rotations[2] @ leg.foot
    columns = []
    for k in range(3):
        axis = rotations[k] @ leg.axis[k]
        through = positions[k] + rotations[k] @ leg.anchor[k]
        columns.append(np.cross(axis, foot - through))
    return np.array(columns).T


def foot_positions(
    legs: Sequence[LegDescription],
    q: ArrayLike,
    base_pos: ArrayLike = (0.0, 0.0, 0.0),
    base_quat: ArrayLike = (1.0, 0.0, 0.0, 0.0),
) -> NDArray[np.float64]:
    """World foot centres (n_legs, 3) [m] for canonical leg-major angles q [rad] and a base pose."""
    angles = np.asarray(q, dtype=float).reshape(len(legs), 3)
    rot = quat_to_matrix(base_quat)
    return np.array(
        [
            np.asarray(base_pos, float) + rot @ leg_foot_position(leg, a)
            for leg, a in zip(legs, angles, strict=True)
        ]
    )
