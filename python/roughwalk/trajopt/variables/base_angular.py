"""Base angular motion: Euler angles ZYX (roll, pitch, yaw) as a spline, as TOWR does.

The node values are the Euler angles [rad] and their rates [rad/s]. The
world-frame angular velocity is ω = M(θ, ψ)·η̇ and its derivative
ω̇ = Ṁ·η̇ + M·η̈, with η = (φ, θ, ψ) and R = R_z(ψ)·R_y(θ)·R_x(φ) the
base-to-world rotation (Winkler 2018, §V-A).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as ca
import numpy as np

from roughwalk.trajopt.variables.base_linear import all_node_index
from roughwalk.trajopt.variables.spline import NodeSpline
from roughwalk.trajopt.variables.variable_set import NodeVariableSet

__all__ = [
    "BaseAngular",
    "euler_to_rotation",
    "euler_rate_matrix",
    "angular_velocity",
    "angular_acceleration",
    "body_angular_velocity",
    "body_angular_acceleration",
    "base_to_world",
    "world_to_base",
]


def _trig(x: Any) -> tuple[Any, Any]:
    if isinstance(x, ca.SX | ca.MX | ca.DM):
        return ca.cos(x), ca.sin(x)
    return np.cos(x), np.sin(x)


def _matrix(rows: list[list[Any]], euler: Any) -> Any:
    """``rows`` as a CasADi matrix where ``euler`` is symbolic, else as a numpy array."""
    if isinstance(euler, ca.SX | ca.MX):
        return ca.vertcat(*[ca.horzcat(*r) for r in rows])
    return np.array(rows, dtype=float)


def euler_to_rotation(euler: Any) -> Any:
    """Base-to-world rotation R = R_z(ψ) R_y(θ) R_x(φ) for η = (φ, θ, ψ) [rad]."""
    cx, sx = _trig(euler[0])
    cy, sy = _trig(euler[1])
    cz, sz = _trig(euler[2])
    rows = [
        [cy * cz, cz * sx * sy - cx * sz, sx * sz + cx * cz * sy],
        [cy * sz, cx * cz + sx * sy * sz, cx * sy * sz - cz * sx],
        [-sy, cy * sx, cx * cy],
    ]
    return _matrix(rows, euler)


def _vector(*entries: Any) -> Any:
    if any(isinstance(e, ca.SX | ca.MX) for e in entries):
        return ca.vertcat(*entries)
    return np.array(entries, dtype=float)


def _turn(angle: Any, v: Any, axis: int) -> Any:
    """The vector v turned by ``angle`` [rad] about coordinate axis ``axis`` (0 x, 1 y, 2 z)."""
    c, s = _trig(angle)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    out = [v[0], v[1], v[2]]
    out[i], out[j] = c * v[i] - s * v[j], s * v[i] + c * v[j]
    return _vector(*out)


def base_to_world(euler: Any, v: Any) -> Any:
    """R·v for η = (φ, θ, ψ): the three elementary turns R_z(ψ) R_y(θ) R_x(φ) applied in turn.

    The same vector as ``euler_to_rotation(euler) @ v``; its derivatives in η,
    which the exact Hessian takes at every sample, cost about a third fewer
    operations than through the full matrix.
    """
    return _turn(euler[2], _turn(euler[1], _turn(euler[0], v, 0), 1), 2)


def world_to_base(euler: Any, v: Any) -> Any:
    """Rᵀ·v for η = (φ, θ, ψ), as :func:`base_to_world` (the turns undone in reverse order)."""
    return _turn(-euler[0], _turn(-euler[1], _turn(-euler[2], v, 2), 1), 0)


def euler_rate_matrix(euler: Any) -> Any:
    """M(η) with ω_world = M(η)·η̇ for Euler angles ZYX."""
    cy, sy = _trig(euler[1])
    cz, sz = _trig(euler[2])
    rows = [[cy * cz, -sz, 0.0], [cy * sz, cz, 0.0], [-sy, 0.0, 1.0]]
    return _matrix(rows, euler)


def _euler_rate_matrix_dot(euler: Any, rates: Any) -> Any:
    """Ṁ(η, η̇)."""
    cy, sy = _trig(euler[1])
    cz, sz = _trig(euler[2])
    yd, zd = rates[1], rates[2]
    rows = [
        [-cz * sy * yd - cy * sz * zd, -cz * zd, 0.0],
        [cy * cz * zd - sy * sz * yd, -sz * zd, 0.0],
        [-cy * yd, 0.0, 0.0],
    ]
    return _matrix(rows, euler)


def angular_velocity(euler: Any, rates: Any) -> Any:
    """World-frame angular velocity ω [rad/s] from Euler angles and rates."""
    return euler_rate_matrix(euler) @ rates


def angular_acceleration(euler: Any, rates: Any, accelerations: Any) -> Any:
    """World-frame angular acceleration ω̇ [rad/s²] from Euler angles, rates and accelerations."""
    return _euler_rate_matrix_dot(euler, rates) @ rates + euler_rate_matrix(euler) @ accelerations


def _body_rate_matrix(euler: Any) -> Any:
    """E(φ, θ) with ω_body = Rᵀω = E·η̇ for Euler angles ZYX."""
    cx, sx = _trig(euler[0])
    cy, sy = _trig(euler[1])
    rows = [[1.0, 0.0, -sy], [0.0, cx, sx * cy], [0.0, -sx, cx * cy]]
    return _matrix(rows, euler)


def _body_rate_matrix_dot(euler: Any, rates: Any) -> Any:
    """Ė(φ, θ, φ̇, θ̇)."""
    cx, sx = _trig(euler[0])
    cy, sy = _trig(euler[1])
    xd, yd = rates[0], rates[1]
    rows = [
        [0.0, 0.0, -cy * yd],
        [0.0, -sx * xd, cx * cy * xd - sx * sy * yd],
        [0.0, -cx * xd, -sx * cy * xd - cx * sy * yd],
    ]
    return _matrix(rows, euler)


def body_angular_velocity(euler: Any, rates: Any) -> Any:
    """Body-frame angular velocity Rᵀω [rad/s] from Euler angles and rates."""
    return _body_rate_matrix(euler) @ rates


def body_angular_acceleration(euler: Any, rates: Any, accelerations: Any) -> Any:
    """Body-frame angular acceleration Rᵀω̇ [rad/s²] from Euler angles, rates and accelerations.

    Rᵀω̇ is the time derivative of Rᵀω (the term Ṙᵀω = −Rᵀ(ω × ω) vanishes),
    so it is Ė·η̇ + E·η̈.
    """
    return _body_rate_matrix_dot(euler, rates) @ rates + _body_rate_matrix(euler) @ accelerations


class BaseAngular(NodeVariableSet):
    """Base Euler angles ZYX [rad] and their rates [rad/s] at every node of the base spline."""

    def __init__(self, durations: Sequence[float], name: str = "base_ang") -> None:
        n_nodes = len(durations) + 1
        super().__init__(name, all_node_index(n_nodes), n_nodes)
        self.durations = list(durations)
        self.spline = NodeSpline(self.node_pos, self.node_vel, self.durations)
