"""The :class:`LegDescription`: one leg as a chain of three hinges."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["LegDescription"]


@dataclass(frozen=True, eq=False)
class LegDescription:
    """One leg as a chain of three hinges: the numbers the Rust ``LegChain`` takes.

    Body k's frame sits at ``body_pos[k]`` with orientation ``body_quat[k]``
    (w, x, y, z) in its parent's frame (the parent of body 0 is the canonical
    base frame); joint k turns body k by q_k [rad] about ``axis[k]`` (unit,
    body k's frame) through ``anchor[k]`` [m] (body k's frame), so that
    T_k = T_{k−1} · [R(body_quat_k), body_pos_k] · Trans(anchor_k) · Rot(axis_k, q_k)
    · Trans(−anchor_k), exactly as MuJoCo moves a hinge. ``foot`` is the foot
    centre in the last body's (k = 2) frame [m].
    """

    body_pos: NDArray[np.float64]
    """(3, 3) position of body k in its parent's frame [m]."""
    body_quat: NDArray[np.float64]
    """(3, 4) orientation (w, x, y, z) of body k in its parent's frame."""
    anchor: NDArray[np.float64]
    """(3, 3) joint k's anchor in body k's frame [m]."""
    axis: NDArray[np.float64]
    """(3, 3) joint k's unit axis in body k's frame."""
    lower: NDArray[np.float64]
    """(3,) lower joint limits [rad] (−inf when unlimited)."""
    upper: NDArray[np.float64]
    """(3,) upper joint limits [rad] (+inf when unlimited)."""
    velocity_limit: NDArray[np.float64]
    """(3,) joint speed limits [rad/s] (+inf when unknown)."""
    foot: NDArray[np.float64]
    """(3,) foot centre in the last body's (k = 2) frame [m]."""
    foot_radius: float
    """Foot sphere radius [m] (0 when the foot is a site)."""
    knee_sign: float
    """+1 or −1: the knee branch inverse kinematics prefers, the sign of the angle
    ψ right-handed about the HFE axis from the HFE→KFE segment to the KFE→foot
    segment (both projected across the HFE axis), as in the nominal pose."""
