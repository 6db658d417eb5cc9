"""The robot's whole body over a trajectory: batched kinematics and point Jacobians.

CHOMP needs, at every sample of a footstep, the world positions of points
spread over the robot's collision capsules and how they move when the
optimised variables move (Zucker 2011, §5.1: "a trajectory for a robot can be
viewed as a collection of paths through the workspace, jointly constrained by
the robot's kinematics"). Two sets of variables are moved (§5.3):

* the trunk pose (x, rpy) with the supporting legs following by IK, so that a
  point p on a supporting leg moves as J_p(x) = I − R·J_pB·J_fB⁻¹·Rᵀ and
  J_p(R) = R·(J_pB·J_fB⁻¹·[f_B]× − [p_B]×)·Rᵀ (§3.4), while points on the
  trunk and on a lifted leg move rigidly with it;
* the swing leg's joint angles, with the trunk held: ∂p/∂q = R·J_pB.

Everything is numpy over (samples, legs/points); inverse kinematics is the
Rust core's batched analytic IK.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk import _core
from roughwalk.errors import InvalidArgumentError, RobotModelError
from roughwalk.robots._rotations import quat_to_matrix
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.robots.collision_model import CollisionModel
from roughwalk.robots.robot import Robot
from roughwalk.trajectories.euler import rpy_rate_matrix, skew

__all__ = ["WholeBody", "BodyPoints", "Frames", "LINK_NAMES"]

LINK_NAMES = ("hip", "thigh", "shank")
_TRUNK = -1

Frames = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
"""Link frames of :meth:`WholeBody.link_frames`: positions, rotations, joint axes, joint anchors."""


@dataclass(frozen=True)
class BodyPoints:
    """Spheres spread along the collision capsules: the body points u of CHOMP.

    One row per point: ``leg`` (−1 trunk, else canonical leg 0–3), ``link``
    (0 hip, 1 thigh, 2 shank; −1 trunk), ``local`` position in that link's
    frame [m] (base frame for the trunk), ``radius`` [m], ``is_foot``, and
    ``primitive``, the row of the :class:`CollisionModel` it samples.
    """

    leg: NDArray[np.int64]
    link: NDArray[np.int64]
    local: NDArray[np.float64]
    radius: NDArray[np.float64]
    is_foot: NDArray[np.bool_]
    primitive: NDArray[np.int64]

    def __len__(self) -> int:
        return int(self.radius.shape[0])

    @classmethod
    def from_collision_model(cls, model: CollisionModel, spacing: float) -> BodyPoints:
        """Points every ≤ ``spacing`` [m] along each capsule (ends included); spheres stay one."""
        if not (math.isfinite(spacing) and spacing > 0):
            raise InvalidArgumentError(
                f"point spacing must be a positive length [m], got {spacing}"
            )
        legs, links, local, radii, feet, prims = [], [], [], [], [], []
        for k in range(len(model)):
            a, b = model.a[k], model.b[k]
            length = float(np.linalg.norm(b - a))
            n = max(1, math.ceil(length / spacing - 1e-9) + 1) if length > 1e-9 else 1
            for s in np.linspace(0.0, 1.0, n) if n > 1 else [0.0]:
                legs.append(int(model.leg[k]))
                links.append(int(model.link[k]))
                local.append(a + s * (b - a))
                radii.append(float(model.radius[k]))
                feet.append(bool(model.is_foot[k]))
                prims.append(k)
        return cls(
            leg=np.asarray(legs, dtype=np.int64),
            link=np.asarray(links, dtype=np.int64),
            local=np.asarray(local, dtype=float),
            radius=np.asarray(radii, dtype=float),
            is_foot=np.asarray(feet, dtype=bool),
            primitive=np.asarray(prims, dtype=np.int64),
        )


def _axis_angle_batch(axis: NDArray[np.float64], angle: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rodrigues rotations (..., 3, 3) about unit axes (..., 3) by angles (...) [rad]."""
    k = skew(axis)
    s = np.sin(angle)[..., None, None]
    c = np.cos(angle)[..., None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


class WholeBody:
    """Batched kinematics of one robot: link frames, IK, body points and their Jacobians.

    Joint angles here are canonical and shaped (N, 4, 3): sample, leg (LF, RF,
    LH, RH), joint (HAA, HFE, KFE). Convert with :meth:`Robot.to_canonical`.

    Parameters
    ----------
    robot:
        The robot; its legs must have the analytic-IK structure.
    collision:
        Its collision model (default :meth:`CollisionModel.from_robot`).
    point_spacing:
        Spacing [m] of the body points along each capsule. Finer spacing
        makes the obstacle cost follow the capsule more closely at a linear
        cost in time; the 1-Lipschitz SDF bounds the error by half of it.
    """

    def __init__(
        self,
        robot: Robot,
        collision: CollisionModel | None = None,
        point_spacing: float = 0.02,
    ) -> None:
        self.robot = robot
        self.collision = collision if collision is not None else CollisionModel.from_robot(robot)
        self.points = BodyPoints.from_collision_model(self.collision, point_spacing)
        legs = robot.leg_descriptions
        self._body_pos = np.array([leg.body_pos for leg in legs])
        self._body_rot = np.array([[quat_to_matrix(q) for q in leg.body_quat] for leg in legs])
        self._anchor = np.array([leg.anchor for leg in legs])
        self._axis = np.array([leg.axis for leg in legs])
        self._axis /= np.linalg.norm(self._axis, axis=-1, keepdims=True)
        self._foot = np.array([leg.foot for leg in legs])
        # Column vectors and the axes' cross-product matrices, for batched matmuls.
        self._body_pos_col = self._body_pos[..., None]
        self._anchor_col = self._anchor[..., None]
        self._axis_col = self._axis[..., None]
        self._k1 = skew(self._axis)
        self._k2 = self._k1 @ self._k1
        self._k1_anchor = self._k1 @ self._anchor_col
        self._k2_anchor = self._k2 @ self._anchor_col
        self.lower = np.array([leg.lower for leg in legs])
        self.upper = np.array([leg.upper for leg in legs])
        self.velocity_limit = np.array([leg.velocity_limit for leg in legs])
        # The farthest each foot gets from its hip anchor, over its joint ranges.
        grid = np.stack(
            np.meshgrid(*[np.linspace(0.0, 1.0, 9)] * 3, indexing="ij"), axis=-1
        ).reshape(-1, 3)
        lo = np.where(np.isfinite(self.lower), self.lower, -np.pi)
        hi = np.where(np.isfinite(self.upper), self.upper, np.pi)
        samples = lo[None] + grid[:, None, :] * (hi - lo)[None]
        self.hips = np.asarray(robot.hip_positions, dtype=float)
        """(4, 3) the legs' hip (HAA) anchors in the base frame [m]."""
        feet = self.foot_positions(samples, self.link_frames(samples))
        self.max_reach = np.linalg.norm(feet - self.hips[None], axis=-1).max(axis=0)
        """(4,) the farthest each foot gets from its hip (HAA anchor) [m]."""
        self.nominal_feet = np.asarray(robot.nominal_stance.feet, dtype=float)
        """(4, 3) feet in the base frame at the nominal joint angles [m]: an IK
        target that is always reached, for legs whose solution is not used
        (an unreachable one costs IK a search for the closest foot)."""
        d = robot.description
        self._link_mass = np.asarray(d.link_mass, dtype=float)
        self._link_com = np.asarray(d.link_com, dtype=float)
        self._base_mass = float(d.base_mass)
        self._base_com = np.asarray(d.base_com, dtype=float)
        self.mass = float(robot.mass)
        try:
            self._core = _core.Quadruped(
                [
                    _core.LegChain(
                        leg.body_pos,
                        leg.body_quat,
                        leg.anchor,
                        leg.axis,
                        leg.lower,
                        leg.upper,
                        leg.velocity_limit,
                        leg.foot,
                        leg.foot_radius,
                        leg.knee_sign,
                        name=f"{robot.name} {name}",
                    )
                    for name, leg in zip(LEG_NAMES, legs, strict=True)
                ]
            )
        except RobotModelError as e:
            raise RobotModelError(
                f"robot '{robot.name}' cannot be used for footstep trajectories: {e}"
            ) from None

    @property
    def core(self) -> _core.Quadruped:
        """The Rust core's model of the four legs (batched IK, CHOMP pass evaluation)."""
        return self._core

    # ---- frames ---------------------------------------------------------------

    def link_frames(self, q: ArrayLike) -> Frames:
        """Frames of every link in the base frame for joint angles q (N, 4, 3) [rad].

        Returns positions (N, 4, 3, 3) and rotations (N, 4, 3, 3, 3) of the
        bodies [sample, leg, link], and each joint's axis (N, 4, 3, 3) and
        anchor (N, 4, 3, 3) [m] in the base frame.
        """
        angles = np.asarray(q, dtype=float)
        n = angles.shape[0]
        sin, cos = np.sin(angles)[..., None, None], 1.0 - np.cos(angles)[..., None, None]
        pos = np.zeros((n, 4, 3, 1))
        rot = np.broadcast_to(np.eye(3), (n, 4, 3, 3))
        positions = np.empty((n, 4, 3, 3))
        rotations = np.empty((n, 4, 3, 3, 3))
        axes = np.empty((n, 4, 3, 3))
        anchors = np.empty((n, 4, 3, 3))
        for k in range(3):
            pos = pos + rot @ self._body_pos_col[:, k]
            rot = rot @ self._body_rot[:, k]
            anchor_base = pos + rot @ self._anchor_col[:, k]
            # Rodrigues with the axis' constant [a]× and [a]×²: turn = I + sin·K + (1 − cos)·K².
            turn = np.eye(3) + sin[:, :, k] * self._k1[:, k] + cos[:, :, k] * self._k2[:, k]
            turned_anchor = (
                self._anchor_col[:, k]
                + sin[:, :, k] * self._k1_anchor[:, k]
                + cos[:, :, k] * self._k2_anchor[:, k]
            )
            axes[:, :, k] = (rot @ self._axis_col[:, k])[..., 0]
            pos = anchor_base - rot @ turned_anchor
            rot = rot @ turn
            positions[:, :, k] = pos[..., 0]
            rotations[:, :, k] = rot
            anchors[:, :, k] = anchor_base[..., 0]
        return positions, rotations, axes, anchors

    def foot_positions(self, q: ArrayLike, frames: Frames | None = None) -> NDArray[np.float64]:
        """Foot centres (N, 4, 3) in the base frame [m] for joint angles q (N, 4, 3)."""
        if frames is None:
            rows = np.ascontiguousarray(np.asarray(q, dtype=float).reshape(-1, 12))
            return np.asarray(self._core.fk_batch(rows)).reshape(-1, 4, 3)
        positions, rotations, _, _ = frames
        return positions[:, :, 2] + np.einsum("nlij,lj->nli", rotations[:, :, 2], self._foot)

    def foot_jacobians(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Base-frame feet (N, 4, 3) [m] and ∂f_B/∂q (N, 4, 3, 3) [m/rad], column j for joint j."""
        positions, rotations, axes, anchors = self.link_frames(q)
        feet = positions[:, :, 2] + np.einsum("nlij,lj->nli", rotations[:, :, 2], self._foot)
        jac = np.cross(axes, feet[:, :, None, :] - anchors)
        return feet, np.swapaxes(jac, -1, -2)

    def inverse_kinematics(
        self, feet_base: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """IK_B of base-frame feet (N, 4, 3) [m]: q (N, 4, 3) [rad] and reached (N, 4).

        An unreachable foot gets the in-limit angles whose foot is closest to
        its target (Zucker 2011, §3.1).
        """
        f = np.ascontiguousarray(feet_base, dtype=float)
        q, reached = self._core.ik_batch(f)
        return np.asarray(q).reshape(-1, 4, 3), np.asarray(reached, dtype=bool)

    def center_of_mass(self, q: ArrayLike, frames: Frames | None = None) -> NDArray[np.float64]:
        """Whole-robot centre of mass (N, 3) in the base frame [m] for q (N, 4, 3)."""
        if frames is None:
            return _core.center_of_mass_batch(
                self._core,
                np.asarray(q, dtype=float).reshape(-1, 4, 3),
                self._link_mass,
                self._link_com,
                self._base_mass,
                self._base_com,
            )
        positions, rotations, _, _ = frames
        coms = positions + np.einsum("nlkij,lkj->nlki", rotations, self._link_com)
        weighted = np.einsum("nlki,lk->ni", coms, self._link_mass)
        return (weighted + self._base_mass * self._base_com) / self.mass

    # ---- body points ------------------------------------------------------------

    def points_base(
        self, q: ArrayLike, frames: Frames | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Body points (N, U, 3) and feet (N, 4, 3) in the base frame [m] for q (N, 4, 3)."""
        positions, rotations, _, _ = self.link_frames(q) if frames is None else frames
        pts = self.points
        leg = np.maximum(pts.leg, 0)
        link = np.maximum(pts.link, 0)
        on_leg = pts.leg != _TRUNK
        p = positions[:, leg, link] + np.einsum("nuij,uj->nui", rotations[:, leg, link], pts.local)
        p = np.where(on_leg[None, :, None], p, pts.local[None])
        feet = positions[:, :, 2] + np.einsum("nlij,lj->nli", rotations[:, :, 2], self._foot)
        return p, feet

    def point_joint_jacobians(
        self,
        frames: Frames,
        p_base: NDArray[np.float64],
        t: NDArray[np.int64],
        u: NDArray[np.int64],
    ) -> NDArray[np.float64]:
        """∂p_B/∂q (K, 3, 3) of body points u at samples t, w.r.t. their own leg's joints.

        ``p_base`` (K, 3) are those points in the base frame. Columns of
        joints below the point's link, and every column of a trunk point, are zero.
        """
        _, _, axes, anchors = frames
        pts = self.points
        leg = np.maximum(pts.leg[u], 0)
        link = pts.link[u]
        col = np.cross(axes[t, leg], p_base[:, None, :] - anchors[t, leg])  # (K, joint, 3)
        active = (pts.leg[u] != _TRUNK)[:, None] & (np.arange(3)[None, :] <= link[:, None])
        return np.swapaxes(col * active[:, :, None], -1, -2)

    def body_pass_jacobians_at(
        self,
        q: NDArray[np.float64],
        frames: Frames,
        p_base: NDArray[np.float64],
        feet_base: NDArray[np.float64],
        rotation: NDArray[np.float64],
        rpy: NDArray[np.float64],
        support: NDArray[np.bool_],
        t: NDArray[np.int64],
        u: NDArray[np.int64],
        damping: float = 1e-3,
    ) -> NDArray[np.float64]:
        """∂p/∂(x, rpy) (K, 3, 6) of body points u at samples t, supporting feet held by IK.

        Zucker 2011, §3.4: a point on a supporting leg moves with J_p(x) =
        I − R·J_pB·J_fB⁻¹·Rᵀ and J_p(R) = R·(J_pB·J_fB⁻¹·[f_B]× − [p_B]×)·Rᵀ;
        other points move rigidly with the trunk. J_fB⁻¹ is damped by
        ``damping`` [m/rad] so a straight leg does not blow up; ∂p/∂rpy =
        J_p(R)·E(rpy). ``p_base`` (N, U, 3) and ``feet_base`` (N, 4, 3) come
        from :meth:`points_base` with the same ``frames``.
        """
        pts = self.points
        leg = np.maximum(pts.leg[u], 0)
        held = (pts.leg[u] != _TRUNK) & support[t, leg]
        pb = p_base[t, u]
        r = rotation[t]
        rt = np.swapaxes(r, -1, -2)
        p_rot = np.einsum("kij,kj->ki", r, pb)
        k = t.shape[0]
        jx = np.broadcast_to(np.eye(3), (k, 3, 3)).copy()
        jw = -skew(p_rot)
        if np.any(held):
            h = np.flatnonzero(held)
            th, lh = t[h], leg[h]
            j_pb = self.point_joint_jacobians(frames, pb[h], th, u[h])
            positions, rotations, axes, anchors = frames
            fb = feet_base[th, lh]
            j_fb = np.swapaxes(np.cross(axes[th, lh], fb[:, None, :] - anchors[th, lh]), -1, -2)
            # Damped pseudo-inverse: (JᵀJ + μ²I)⁻¹Jᵀ.
            jt = np.swapaxes(j_fb, -1, -2)
            j_pinv = np.linalg.solve(jt @ j_fb + damping**2 * np.eye(3), jt)
            m = j_pb @ j_pinv
            rh, rth = r[h], rt[h]
            jx[h] = np.eye(3) - rh @ m @ rth
            jw[h] = rh @ (m @ skew(fb) - skew(pb[h])) @ rth
        e = rpy_rate_matrix(rpy[t])
        return np.concatenate([jx, jw @ e], axis=-1)

    def body_pass_jacobians(
        self,
        q: ArrayLike,
        base_pos: ArrayLike,
        rotation: ArrayLike,
        rpy: ArrayLike,
        support: ArrayLike,
        damping: float = 1e-3,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World body points (N, U, 3) [m] and ∂p/∂(x, rpy) (N, U, 3, 6) of every point.

        The dense form of :meth:`body_pass_jacobians_at`.
        """
        qq = np.asarray(q, dtype=float)
        frames = self.link_frames(qq)
        p_b, feet_b = self.points_base(qq, frames)
        rot = np.asarray(rotation, dtype=float)
        n, u = p_b.shape[:2]
        tt, uu = np.divmod(np.arange(n * u), u)
        jac = self.body_pass_jacobians_at(
            qq,
            frames,
            p_b,
            feet_b,
            rot,
            np.asarray(rpy, dtype=float),
            np.asarray(support, dtype=bool),
            tt,
            uu,
            damping,
        )
        world = np.asarray(base_pos, dtype=float)[:, None, :] + np.einsum("nij,nuj->nui", rot, p_b)
        return world, jac.reshape(n, u, 3, 6)

    def swing_pass_jacobians_at(
        self,
        frames: Frames,
        p_base: NDArray[np.float64],
        rotation: NDArray[np.float64],
        t: NDArray[np.int64],
        u: NDArray[np.int64],
    ) -> NDArray[np.float64]:
        """∂p/∂q_leg (K, 3, 3) = R·J_pB of leg points u at samples t, the trunk held.

        ``p_base`` (K, 3) are those points in the base frame.
        """
        j_pb = self.point_joint_jacobians(frames, p_base, t, u)
        return np.einsum("kij,kjm->kim", rotation[t], j_pb)
