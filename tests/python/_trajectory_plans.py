"""Footstep plans for the trajectory tests, written by hand in ``roughwalk plan``'s format."""

from __future__ import annotations

from typing import Any

import numpy as np

import roughwalk as rw
from roughwalk.robots import LEG_NAMES
from roughwalk.trajectories.body_keyframes import nominal_fit, pose_over_support
from roughwalk.trajectories.euler import rpy_to_quat
from roughwalk.trajectories.whole_body import WholeBody

BARRIER = "barrier:height=0.04,thickness=0.01,center=1.0"
"""A 4 cm high, 1 cm thick wall across the board at x = 1 m (0.995 … 1.005)."""


def one_step_plan(
    robot: rw.Robot,
    terrain: rw.Terrain,
    wb: WholeBody,
    feet: np.ndarray,
    leg: str,
    target: np.ndarray,
    lower: float,
) -> dict[str, Any]:
    """The plan of one step of ``leg`` from the foot centres ``feet`` to ``target``.

    The trunk is ``lower`` [m] below the nominal stance fitted to the feet,
    before and after; the certificate after the step keeps all four feet
    in reach. Contact points are the foot centres less the radius.
    """
    r = robot.foot_radius
    base, rpy = nominal_fit(wb, feet)
    base[2] -= lower
    after = feet.copy()
    after[LEG_NAMES.index(leg)] = target
    end_base, end_rpy = nominal_fit(wb, after)
    end_base[2] -= lower
    end = pose_over_support(wb, after, [0, 1, 2, 3], 0.015, start=(end_base, end_rpy))
    return {
        "robot": robot.name,
        "terrain": terrain.spec,
        "footsteps": [
            {"leg": name, "x": float(f[0]), "y": float(f[1]), "z": float(f[2] - r)}
            for name, f in zip(LEG_NAMES, feet, strict=True)
        ]
        + [{"leg": leg, "x": float(target[0]), "y": float(target[1]), "z": float(target[2] - r)}],
        "initial_pose": {"base_pos": base.tolist(), "base_quat": rpy_to_quat(rpy).tolist()},
        "certificates": [
            {
                "step": 1,
                "base_pos": end.base_pos.tolist(),
                "base_quat": end.base_quat.tolist(),
                "q": robot.from_canonical(end.q.reshape(12)).tolist(),
            }
        ],
    }


def barrier_step_plan(
    robot: rw.Robot,
    terrain: rw.Terrain,
    wb: WholeBody,
    *,
    leg: str = "LF",
    foot_x: float = 0.98,
    stride: float = 0.08,
    lower: float = 0.02,
) -> dict[str, Any]:
    """One step of ``leg`` from just before the barrier (``foot_x``) to ``stride`` beyond.

    The other side's hind foot is set 5 cm back (a crawl's stagger); the
    trunk is ``lower`` [m] below the nominal stance so the foot reaches. The
    plan has an initial pose and the certificate after the step.
    """
    i = LEG_NAMES.index(leg)
    feet = robot.nominal_stance.feet.copy()
    feet[:, 0] += foot_x - feet[i, 0]
    feet[:, 2] = robot.foot_radius
    feet[3 if i == 2 else 2, 0] -= 0.05
    target = feet[i].copy()
    target[0] += stride
    return one_step_plan(robot, terrain, wb, feet, leg, target, lower)


def low_swing_config(**more: Any) -> dict[str, Any]:
    """Settings whose swing spline ignores the terrain and lifts 2 cm: it hits a 4 cm barrier.

    It lifts nearly vertically on the knot timing (lift-off at 0.1 of the
    stride, the defaults before the re-timed swing), so that CHOMP has the
    same deep collision to repair.

    Validity asks for 2 mm of clearance and no dip of the foot, so that an
    independent check can prove the result collision-free.
    """
    return {
        "swing.scan_terrain": False,
        "swing.lift_height": 0.02,
        "swing.lift_fraction": 0.1,
        "swing.time_law": "knots",
        "zmp.shortcut": False,
        "validity.foot_tolerance": 0.0,
        "validity.min_clearance": 0.002,
        **more,
    }


def unit(v: np.ndarray) -> np.ndarray:
    """v / ‖v‖."""
    return v / np.linalg.norm(v)


def step_down_plan(
    robot: rw.Robot, terrain: rw.Terrain, wb: WholeBody, *, stride: float = 0.08
) -> dict[str, Any]:
    """LF steps ``stride`` [m] down from the top of an 8 cm block centred at x = 1 m.

    ``terrain``: ``barrier:height=0.08,thickness=0.06,center=1.0``. RF stands
    behind the block, the hind feet on the ground; the trunk 2 cm below the
    nominal stance fitted to the feet, before and after.
    """
    r = robot.foot_radius
    feet = robot.nominal_stance.feet.copy()
    feet[:, 0] += 1.0 - feet[0, 0]
    feet[1, 0] -= 0.07
    feet[:, 2] = r
    feet[0, 2] = 0.08 + r
    target = feet[0].copy()
    target[0] += stride
    target[2] = r
    return one_step_plan(robot, terrain, wb, feet, "LF", target, 0.02)
