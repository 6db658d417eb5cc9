"""How long a stride a robot's legs reach, and the planner's settings for longer steps.

In a crawl each foot stays down while the trunk moves on by one stride, so
the stride cannot exceed the fore–aft span its foot reaches under the hip
at the stance height. On LittleDog (L = 0.202 m) that span is about 0.155 m
(0.77 L: from 7.5 cm behind to 8.5 cm ahead of a front foot's nominal
place); the planner's default cap on a foot's move, ``max_foot_travel`` =
0.6 L, sits well inside it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["longer_step_config", "stride_reach", "STRIDE_REACH_SHARE", "STRIDE_PER_ACTION"]

# A steady crawl's stride over its longest forward action (4 steps of ~0.4 of it each).
STRIDE_PER_ACTION = 1.6
# Share of the reachable span one foot's move may use: the rest is left to the
# trunk's sway and tilt on rough ground, which move the hips under the feet.
# 0.88 (~0.14 m on LittleDog) since session 24; before, the cap was the
# steady stride, 1.6 × the longest action (0.129 m at 0.4 L).
STRIDE_REACH_SHARE = 0.88
# Resolution [m] of the reach scan.
_SCAN_M = 0.002


def stride_reach(robot: Any) -> float:
    """The shortest fore–aft span [m] over the four legs that a foot reaches at the stance height.

    Each foot, the others held at the nominal stance, is moved along the
    trunk's x axis at the nominal foot height until the leg's inverse
    kinematics no longer reaches it (joint limits included).
    """
    stance = robot.nominal_stance
    base = np.array([0.0, 0.0, float(stance.base_height)])
    quat = np.array([1.0, 0.0, 0.0, 0.0])
    feet = np.asarray(stance.feet, dtype=float) + base
    offsets = np.arange(-0.5, 0.5 + 1e-12, _SCAN_M) * float(np.max(robot.leg_lengths.sum(axis=1)))
    spans = []
    for leg in range(4):
        reached = []
        for dx in offsets:
            f = feet.copy()
            f[leg, 0] += dx
            _, ok = robot.inverse_kinematics(f, base, quat)
            reached.append(bool(np.asarray(ok).reshape(-1)[leg]))
        inside = offsets[np.asarray(reached)]
        spans.append(float(inside.max() - inside.min()) if inside.size else 0.0)
    return min(spans)


def longer_step_config(robot: Any, longest: float) -> Any:
    """The footstep planner's settings with forward actions of ``longest`` × L added.

    ``footstep.max_foot_travel`` grows to :data:`STRIDE_REACH_SHARE` of
    :func:`stride_reach` where it was shorter: a steady crawl's stride is
    only :data:`STRIDE_PER_ACTION` times the longest action, but the
    search's sideways actions and its local search around each target make
    single moves longer than that, and a cap at the steady stride cut them
    back. The planner's pose certificates still check every stance's reach.
    """
    from roughwalk.planning.footstep_config import FootstepConfig, hip_to_hip_length

    base = FootstepConfig.for_robot(robot)
    length = hip_to_hip_length(robot)
    if longest * length <= max(a[0] for a in base.actions) + 1e-12:
        return base
    extra = tuple((longest * length, dy * length, 0.0) for dy in (-0.1, 0.0, 0.1))
    travel = STRIDE_REACH_SHARE * stride_reach(robot)
    return FootstepConfig.for_robot(
        robot,
        actions=base.actions + extra,
        max_foot_travel=max(base.max_foot_travel, travel),
    )
