"""Batched roll–pitch–yaw (ZYX) angles: the trunk orientation coordinates CHOMP moves.

R = R_z(ψ)·R_y(θ)·R_x(φ) with rpy = (φ, θ, ψ) [rad]. The map from rpy rates
to the world angular velocity ω = E(rpy)·d(rpy)/dt is exact, so a world-frame
rotational Jacobian J_p(R) (Zucker 2011, §3.4) becomes ∂p/∂rpy = J_p(R)·E.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "rpy_to_matrix",
    "matrix_to_rpy",
    "rpy_rate_matrix",
    "rpy_to_quat",
    "quat_to_rpy",
    "skew",
]


def skew(v: ArrayLike) -> NDArray[np.float64]:
    """[v]× (..., 3, 3) of vectors v (..., 3): [v]×·u = v × u."""
    a = np.asarray(v, dtype=float)
    out = np.zeros((*a.shape[:-1], 3, 3))
    out[..., 0, 1] = -a[..., 2]
    out[..., 0, 2] = a[..., 1]
    out[..., 1, 0] = a[..., 2]
    out[..., 1, 2] = -a[..., 0]
    out[..., 2, 0] = -a[..., 1]
    out[..., 2, 1] = a[..., 0]
    return out


def rpy_to_matrix(rpy: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices (..., 3, 3) of roll–pitch–yaw angles (..., 3) [rad]."""
    a = np.asarray(rpy, dtype=float)
    cr, sr = np.cos(a[..., 0]), np.sin(a[..., 0])
    cp, sp = np.cos(a[..., 1]), np.sin(a[..., 1])
    cy, sy = np.cos(a[..., 2]), np.sin(a[..., 2])
    out = np.empty((*a.shape[:-1], 3, 3))
    out[..., 0, 0] = cy * cp
    out[..., 0, 1] = cy * sp * sr - sy * cr
    out[..., 0, 2] = cy * sp * cr + sy * sr
    out[..., 1, 0] = sy * cp
    out[..., 1, 1] = sy * sp * sr + cy * cr
    out[..., 1, 2] = sy * sp * cr - cy * sr
    out[..., 2, 0] = -sp
    out[..., 2, 1] = cp * sr
    out[..., 2, 2] = cp * cr
    return out


def matrix_to_rpy(rotation: ArrayLike) -> NDArray[np.float64]:
    """Roll–pitch–yaw (..., 3) [rad] of rotation matrices (..., 3, 3); pitch in [−π/2, π/2]."""
    r = np.asarray(rotation, dtype=float)
    pitch = np.arcsin(np.clip(-r[..., 2, 0], -1.0, 1.0))
    roll = np.arctan2(r[..., 2, 1], r[..., 2, 2])
    yaw = np.arctan2(r[..., 1, 0], r[..., 0, 0])
    return np.stack([roll, pitch, yaw], axis=-1)


def rpy_rate_matrix(rpy: ArrayLike) -> NDArray[np.float64]:
    """E (..., 3, 3) with ω_world = E·d(rpy)/dt: columns R_z·R_y·e_x, R_z·e_y, e_z."""
    a = np.asarray(rpy, dtype=float)
    cp, sp = np.cos(a[..., 1]), np.sin(a[..., 1])
    cy, sy = np.cos(a[..., 2]), np.sin(a[..., 2])
    out = np.zeros((*a.shape[:-1], 3, 3))
    out[..., 0, 0] = cy * cp
    out[..., 1, 0] = sy * cp
    out[..., 2, 0] = -sp
    out[..., 0, 1] = -sy
    out[..., 1, 1] = cy
    out[..., 2, 2] = 1.0
    return out


def rpy_to_quat(rpy: ArrayLike) -> NDArray[np.float64]:
    """Unit quaternions (..., 4) (w, x, y, z), w ≥ 0, of roll–pitch–yaw angles (..., 3) [rad]."""
    a = np.asarray(rpy, dtype=float) * 0.5
    cr, sr = np.cos(a[..., 0]), np.sin(a[..., 0])
    cp, sp = np.cos(a[..., 1]), np.sin(a[..., 1])
    cy, sy = np.cos(a[..., 2]), np.sin(a[..., 2])
    q = np.stack(
        [
            cy * cp * cr + sy * sp * sr,
            cy * cp * sr - sy * sp * cr,
            cy * sp * cr + sy * cp * sr,
            sy * cp * cr - cy * sp * sr,
        ],
        axis=-1,
    )
    return np.where(q[..., :1] < 0, -q, q)


def quat_to_rpy(quat: ArrayLike) -> NDArray[np.float64]:
    """Roll–pitch–yaw (..., 3) [rad] of quaternions (..., 4) (w, x, y, z), normalised first."""
    q = np.asarray(quat, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    r = np.empty((*q.shape[:-1], 3, 3))
    r[..., 0, 0] = 1 - 2 * (y * y + z * z)
    r[..., 1, 0] = 2 * (x * y + w * z)
    r[..., 2, 0] = 2 * (x * z - w * y)
    r[..., 2, 1] = 2 * (y * z + w * x)
    r[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return matrix_to_rpy(r)
