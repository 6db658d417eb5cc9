"""A straight-line crawl in the footstep plan format, for tests and benchmarks.

Not a planner: it puts the nominal stance down at ``start``, moves the legs
in the crawl order LH, LF, RH, RF by one ``stride`` each along the heading,
drops every foot onto the terrain, and gives each step a certificate-like
pose (nominal stance fitted to the feet, CoM nudged into the next support
triangle). It ignores terrain cost and does not search for collision-free
certificates, so on rough ground some of its steps are hard on purpose.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from roughwalk.errors import InvalidArgumentError
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.trajectories.body_keyframes import nominal_fit, pose_over_support
from roughwalk.trajectories.whole_body import WholeBody

if TYPE_CHECKING:
    from roughwalk.robots.robot import Robot
    from roughwalk.terrain.terrain import Terrain

__all__ = ["straight_crawl_plan", "CRAWL_ORDER"]

CRAWL_ORDER = ("LH", "LF", "RH", "RF")


def straight_crawl_plan(
    robot: Robot,
    terrain: Terrain,
    start: ArrayLike,
    *,
    steps: int = 8,
    stride: float = 0.06,
    heading: float = 0.0,
    order: Sequence[str] = CRAWL_ORDER,
    support_margin: float = 0.015,
    stance_scale: float = 1.0,
    first_step_scale: float = 0.5,
    wb: WholeBody | None = None,
) -> dict[str, Any]:
    """A plan dict (``roughwalk plan``'s JSON fields) for a straight crawl.

    Footsteps are contact points, as the planner writes them; the
    certificates put the foot-sphere centres on the terrain.

    Parameters
    ----------
    robot, terrain:
        What walks where. The plan names them by ``robot.name`` and
        ``terrain.spec``.
    start:
        (x, y) [m] of the trunk at the start.
    steps:
        Number of footsteps after the initial stance.
    stride:
        How far each foot moves per step [m]; the first step of each leg moves
        ``first_step_scale`` of it so hind and front feet stay staggered.
    heading:
        Walking direction [rad] from +x.
    order:
        Leg order of the gait.
    support_margin:
        CoM margin [m] of the certificates inside the next support triangle.
    stance_scale:
        Scale of the nominal footprint in x–y.
    wb:
        A :class:`WholeBody` of ``robot`` to reuse.
    """
    if steps < 1:
        raise InvalidArgumentError(f"a crawl needs at least one step, got steps={steps}")
    if not (math.isfinite(stride) and stride > 0):
        raise InvalidArgumentError(f"stride must be a positive length [m], got {stride}")
    legs = [LEG_NAMES.index(name) for name in order]
    body = wb if wb is not None else WholeBody(robot)
    c, s = math.cos(heading), math.sin(heading)
    rot = np.array([[c, -s], [s, c]])
    foot_r = robot.foot_radius
    footprint = robot.nominal_stance.feet[:, :2] * stance_scale
    xy0 = np.asarray(start, dtype=float)[:2]

    # The foot sphere rests on the highest point under it, not on the height at its centre.
    ring = np.array(
        [[0.0, 0.0]]
        + [
            [rho * np.cos(a), rho * np.sin(a)]
            for rho in (0.5 * foot_r, foot_r)
            for a in np.linspace(0.0, 2 * np.pi, 12, endpoint=False)
        ]
    )
    lift = np.sqrt(np.maximum(foot_r**2 - np.sum(ring**2, axis=1), 0.0))

    def on_ground(xy: np.ndarray) -> np.ndarray:
        z = float(np.max(terrain.height(xy[None] + ring) + lift))
        return np.array([xy[0], xy[1], z])

    def contact(centre: np.ndarray) -> dict[str, Any]:
        # The plan format holds contact points: the centre less the radius along the normal.
        c = centre - foot_r * terrain.normal(centre[None, :2])[0]
        return {"x": float(c[0]), "y": float(c[1]), "z": float(c[2])}

    feet = np.array([on_ground(xy0 + rot @ f) for f in footprint])
    footsteps = [{"leg": LEG_NAMES[i], **contact(feet[i])} for i in range(4)]
    direction = rot @ np.array([1.0, 0.0])
    moved = [False] * 4
    sequence = [legs[k % len(legs)] for k in range(steps)]
    certificates = []
    base, rpy = nominal_fit(body, feet)
    for k, leg in enumerate(sequence):
        scale = 1.0 if moved[leg] else first_step_scale
        moved[leg] = True
        feet = feet.copy()
        feet[leg] = on_ground(feet[leg, :2] + scale * stride * direction)
        footsteps.append({"leg": LEG_NAMES[leg], **contact(feet[leg])})
        nxt = sequence[k + 1] if k + 1 < steps else legs[(k + 1) % len(legs)]
        support = [i for i in range(4) if i != nxt]
        fit_base, fit_rpy = nominal_fit(body, feet)
        frame = pose_over_support(body, feet, support, support_margin, start=(fit_base, fit_rpy))
        base = frame.base_pos
        certificates.append(
            {
                "step": k + 1,
                "base_pos": base.tolist(),
                "base_quat": frame.base_quat.tolist(),
                "q": robot.from_canonical(frame.q.reshape(12)).tolist(),
            }
        )
    return {
        "robot": robot.name,
        "terrain": terrain.spec,
        "footsteps": footsteps,
        "certificates": certificates,
    }
