"""The robot's collision model: spheres and capsules that contain its collision geoms.

Zucker 2011 (§3.3–3.4) checks the robot against the terrain's signed distance
field with simple primitives, conservatively: every primitive here *contains*
the MJCF geom it stands for, so a positive clearance of the model implies a
positive clearance of the robot.

How each MJCF geom type becomes primitives (all in the frame of the link
that carries the geom):

* sphere → the same sphere; capsule → the same capsule;
* box (half-extents a ≥ b ≥ c along its own axes) → n = ⌈b / c⌉ capsules
  parallel to the longest axis, spread across the middle axis, each of
  radius √((b/n)² + c²) and half-length a — they cover every cross-section
  rectangle of the box;
* cylinder → the capsule of the same radius and axis when it is longer than
  wide, else as its bounding box;
* ellipsoid, mesh → their bounding box in the geom frame (for a
  mesh, MuJoCo's ``geom_aabb``), then as a box.

A sphere is a capsule whose two end points coincide. The foot spheres are
flagged so that distance queries can leave them out (they are meant to touch
the ground).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import RobotModelError
from roughwalk.robots import reference_fk
from roughwalk.robots._rotations import quat_to_matrix

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.terrain.sdf import SignedDistanceField

__all__ = ["CollisionModel", "WholeBodyDistance", "capsules_for_box"]

TRUNK = -1


def capsules_for_box(
    half_extents: ArrayLike,
) -> list[tuple[NDArray[np.float64], NDArray[np.float64], float]]:
    """Capsules ``(a, b, radius)`` in the box frame that together contain the box [m]."""
    h = np.asarray(half_extents, dtype=float)
    if h.shape != (3,) or not np.all(np.isfinite(h)) or np.any(h < 0):
        raise RobotModelError(f"box half-extents must be 3 finite non-negative numbers, got {h}")
    order = np.argsort(-h)  # longest, middle, shortest axis
    a, b, c = h[order]
    n = max(1, math.ceil(b / c - 1e-9)) if c > 0 else 1
    radius = math.sqrt((b / n) ** 2 + c**2)
    out = []
    for k in range(n):
        offset = -b + (2 * k + 1) * b / n
        p = np.zeros(3)
        p[order[1]] = offset
        e = np.zeros(3)
        e[order[0]] = a
        out.append((p - e, p + e, radius))
    return out


@dataclass(frozen=True)
class WholeBodyDistance:
    """The robot's least signed distance to the terrain and where it is attained.

    ``distance`` [m] is the capsule surface's distance (negative: penetration);
    ``point`` (3,) the world point on the capsule's axis where the field is
    least, ``gradient`` (3,) the field's gradient there (moving ``point``
    along it increases the distance); ``primitive`` its row in the model,
    ``leg`` (−1 trunk) and ``link`` (−1 trunk) its owner, ``point_in_link``
    (3,) the same point in that link's frame (the base frame for the trunk);
    ``per_primitive`` (N,) every primitive's distance [m] (+inf if excluded).
    """

    distance: float
    point: NDArray[np.float64]
    gradient: NDArray[np.float64]
    primitive: int
    leg: int
    link: int
    point_in_link: NDArray[np.float64]
    per_primitive: NDArray[np.float64]


@dataclass(frozen=True)
class CollisionModel:
    """Capsules (spheres when a = b) fixed to the trunk or to a leg link.

    Arrays have one row per primitive. ``leg`` is the canonical leg index
    (0–3: LF, RF, LH, RH) or −1 for the trunk; ``link`` is 0/1/2 (hip,
    thigh, shank) or −1 for the trunk; ``a``, ``b`` are the segment ends in
    that link's frame [m] (the canonical base frame for the trunk);
    ``radius`` [m]; ``is_foot`` marks the foot spheres; ``source`` names
    the MJCF geom each primitive contains.
    """

    leg: NDArray[np.int64]
    link: NDArray[np.int64]
    a: NDArray[np.float64]
    b: NDArray[np.float64]
    radius: NDArray[np.float64]
    is_foot: NDArray[np.bool_]
    source: tuple[str, ...]

    @classmethod
    def from_robot(cls, robot: Robot, padding: float = 0.0) -> CollisionModel:
        """Fit the primitives to ``robot``'s collision geoms; ``padding`` [m] inflates each."""
        if not math.isfinite(padding) or padding < 0:
            raise RobotModelError(f"padding must be a finite non-negative distance, got {padding}")
        legs: list[int] = []
        links: list[int] = []
        seg_a: list[NDArray[np.float64]] = []
        seg_b: list[NDArray[np.float64]] = []
        radii: list[float] = []
        feet: list[bool] = []
        names: list[str] = []
        mj = None
        foot_points = [np.asarray(leg.foot, dtype=float) for leg in robot.leg_descriptions]
        for g in robot.collision_geoms:
            leg = TRUNK if g.leg is None else robot.legs.index(g.leg)
            link = TRUNK if g.link is None else int(g.link)
            rot = quat_to_matrix(np.asarray(g.quat, dtype=float))
            pos = np.asarray(g.pos, dtype=float)
            label = g.name or f"{g.body}/{g.type}#{g.geom_id}"
            local: list[tuple[NDArray[np.float64], NDArray[np.float64], float]]
            if g.type == "sphere":
                local = [(np.zeros(3), np.zeros(3), float(g.size[0]))]
            elif g.type == "capsule":
                half = np.array([0.0, 0.0, float(g.size[1])])
                local = [(-half, half, float(g.size[0]))]
            elif g.type == "box":
                local = capsules_for_box(g.size[:3])
            elif g.type == "cylinder":
                r, h = float(g.size[0]), float(g.size[1])
                if h >= r:
                    # A long cylinder: the capsule of the same radius and axis contains it.
                    local = [(np.array([0.0, 0.0, -h]), np.array([0.0, 0.0, h]), r)]
                else:
                    local = capsules_for_box([r, r, h])
            elif g.type == "ellipsoid":
                local = capsules_for_box(g.size[:3])
            elif g.type == "mesh":
                if mj is None:
                    mj = robot.mj_model()
                aabb = np.asarray(mj.geom_aabb[g.geom_id], dtype=float)
                centre, half_ext = aabb[:3], aabb[3:]
                local = [(p + centre, q + centre, r) for p, q, r in capsules_for_box(half_ext)]
            else:
                raise RobotModelError(
                    f"robot '{robot.name}': collision geom '{label}' has type '{g.type}', "
                    "which the collision model cannot bound (sphere, capsule, box, cylinder, "
                    "ellipsoid and mesh are supported)"
                )
            for pa, pb, r in local:
                wa, wb = pos + rot @ pa, pos + rot @ pb
                foot = (
                    g.type == "sphere"
                    and leg != TRUNK
                    and link == 2
                    and bool(np.linalg.norm(wa - foot_points[leg]) < 1e-6)
                )
                legs.append(leg)
                links.append(link)
                seg_a.append(wa)
                seg_b.append(wb)
                radii.append(r + padding)
                feet.append(foot)
                names.append(label)
        if not radii:
            raise RobotModelError(f"robot '{robot.name}' has no collision geoms to model")
        return cls(
            leg=np.asarray(legs, dtype=np.int64),
            link=np.asarray(links, dtype=np.int64),
            a=np.asarray(seg_a),
            b=np.asarray(seg_b),
            radius=np.asarray(radii),
            is_foot=np.asarray(feet, dtype=bool),
            source=tuple(names),
        )

    def __len__(self) -> int:
        return int(self.radius.shape[0])

    def world_segments(
        self,
        robot: Robot,
        q: ArrayLike,
        base_pos: ArrayLike = (0.0, 0.0, 0.0),
        base_quat: ArrayLike = (1.0, 0.0, 0.0, 0.0),
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World end points (N, 3), (N, 3) [m] of every primitive at q (12,) and the base pose."""
        qc = robot.to_canonical(np.asarray(q, dtype=float)).reshape(4, 3)
        rot = quat_to_matrix(np.asarray(base_quat, dtype=float))
        pos = np.asarray(base_pos, dtype=float)
        # One frame per link (13 with the trunk), then every primitive at once.
        origins = np.zeros((13, 3))
        rotations = np.tile(np.eye(3), (13, 1, 1))
        for i, leg in enumerate(robot.leg_descriptions):
            p, r = reference_fk.leg_link_frames(leg, qc[i])
            origins[1 + 3 * i : 4 + 3 * i] = p
            rotations[1 + 3 * i : 4 + 3 * i] = r
        slot = np.where(self.leg == TRUNK, 0, 1 + 3 * self.leg + self.link)
        la = origins[slot] + np.einsum("nij,nj->ni", rotations[slot], self.a)
        lb = origins[slot] + np.einsum("nij,nj->ni", rotations[slot], self.b)
        wa = pos + la @ rot.T
        wb = pos + lb @ rot.T
        return wa, wb

    def distance(
        self,
        robot: Robot,
        sdf: SignedDistanceField,
        q: ArrayLike,
        base_pos: ArrayLike = (0.0, 0.0, 0.0),
        base_quat: ArrayLike = (1.0, 0.0, 0.0, 0.0),
        *,
        exclude_feet: bool = True,
    ) -> WholeBodyDistance:
        """Whole-body signed distance to the terrain SDF at q (12,) and the base pose.

        One batched capsule query in the Rust core (min over samples along each
        segment minus its radius, as Zucker 2011 §3.3 does); feet are left out
        unless ``exclude_feet`` is False.
        """
        wa, wb = self.world_segments(robot, q, base_pos, base_quat)
        keep = ~self.is_foot if exclude_feet else np.ones(len(self), dtype=bool)
        if not keep.any():
            raise RobotModelError("every collision primitive is a foot; nothing to measure")
        d, g, t = sdf.query_capsules(wa[keep], wb[keep], self.radius[keep], return_fraction=True)
        per = np.full(len(self), np.inf)
        per[keep] = d
        rows = np.flatnonzero(keep)
        best = int(np.argmin(d))
        k = int(rows[best])
        frac = float(t[best])
        point = wa[k] + frac * (wb[k] - wa[k])
        local = self.a[k] + frac * (self.b[k] - self.a[k])
        return WholeBodyDistance(
            distance=float(d[best]),
            point=point,
            gradient=np.asarray(g[best], dtype=float),
            primitive=k,
            leg=int(self.leg[k]),
            link=int(self.link[k]),
            point_in_link=local,
            per_primitive=per,
        )
