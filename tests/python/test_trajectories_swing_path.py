"""The joint-space swing path (``SwingConfig.path = "joint"``): less hip travel, terrain cleared."""

from __future__ import annotations

import numpy as np
import pytest
from _even_swings import EVEN_SWING_FIELDS

import roughwalk as rw
from roughwalk.errors import ConfigError
from roughwalk.terrain import load_terrain
from roughwalk.trajectories.body_keyframes import keyframe_at
from roughwalk.trajectories.config import SwingConfig
from roughwalk.trajectories.swing_spline import SwingSpline
from roughwalk.trajectories.whole_body import WholeBody

FAST = {"time_law": "joint", "ramp_fraction": 0.1}
ROCKS = "large_rocks:seed=7,max_height=0.05"


@pytest.fixture(scope="module")
def littledog() -> tuple[rw.Robot, WholeBody]:
    robot = rw.load_robot("littledog")
    return robot, WholeBody(robot)


def _swing(
    littledog: tuple[rw.Robot, WholeBody],
    config: SwingConfig,
    leg: int,
    x: float = 0.0,
    stride: float = 0.095,
    terrain: rw.Terrain | None = None,
) -> tuple[SwingSpline, object]:
    """Leg ``leg``'s swing of ``stride`` [m] forward from the nominal stance at ``x`` [m]."""
    robot, wb = littledog
    feet = robot.nominal_stance.feet.copy()
    feet[:, 0] += x
    feet[leg, 0] -= stride / 2
    feet[:, 2] = robot.foot_radius
    if terrain is not None:
        feet[:, 2] += terrain.height(feet[:, :2])
    ground = feet[:, 2].mean() - robot.foot_radius
    base = np.array([x, 0.0, ground + robot.nominal_stance.base_height])
    pose = keyframe_at(wb, feet, base, np.zeros(3))
    start = feet[leg].copy()
    target = start + [stride, 0.0, 0.0]
    if terrain is not None:
        target[2] = terrain.height(target[None, :2])[0] + robot.foot_radius
    angles = pose.leg_angles(wb, leg)
    spline = SwingSpline.plan(
        start,
        target,
        1.0,
        config,
        terrain,
        robot.foot_radius,
        leg_angles=angles,
        velocity_limit=wb.velocity_limit[leg],
        leg_feet=pose.leg_feet(wb, leg),
        joint_range=(wb.lower[leg], wb.upper[leg]),
    )
    return spline, angles


def test_joint_path_moves_the_hip_less_and_allows_a_shorter_swing(littledog) -> None:
    """On a flat 9.5 cm stride: hip travel 1.28 → 0.96 rad, least swing 0.207 → 0.172 s."""
    _, wb = littledog
    for leg in range(4):
        found = {}
        for path in ("cartesian", "joint"):
            spline, angles = _swing(littledog, SwingConfig(path=path, **FAST), leg)
            p = spline.position(np.linspace(0.0, 1.0, 401))
            q = angles(p)
            found[path] = (
                np.abs(np.diff(q[:, 1])).sum(),
                spline.least_time(angles, wb.velocity_limit[leg]),
                p[:, 2].max() - p[0, 2],
            )
        hip, least, lift = found["joint"]
        assert hip < 0.8 * found["cartesian"][0]
        assert least < 0.9 * found["cartesian"][1]
        # Still the lift the settings ask for.
        assert lift >= SwingConfig().lift_height - 1e-3


def test_joint_path_clears_the_rocks_by_brute_force(littledog) -> None:
    """Over generated rocks the shaped swings keep the foot sphere off the terrain surface.

    Brute force: the distance from each foot centre to the height field
    sampled every 2 mm within 4 cm, minus the foot's radius. The shape asks
    for ``clearance`` (2.5 cm) vertically above the ground under the foot's
    disc where the lift is full; a rock's flank beside the foot can come
    nearer than that, so the surface distance there is only held to 1 cm.
    """
    robot, _ = littledog
    terrain = load_terrain(ROCKS)
    grid = np.mgrid[-0.04:0.0401:0.002, -0.04:0.0401:0.002].reshape(2, -1).T
    shaped = 0
    for x in (0.30, 0.35, 0.45, 0.50, 0.70):
        for leg in range(4):
            spline, _ = _swing(littledog, SwingConfig(path="joint", **FAST), leg, x, 0.09, terrain)
            if len(spline.waypoints) == 4:
                continue  # the heuristic path was kept
            shaped += 1
            tau = np.linspace(0.0, 1.0, 121)
            p = spline.position(tau)
            gap = []
            for point in p:
                xy = grid + point[:2]
                surface = np.column_stack([xy, terrain.height(xy)])
                gap.append(np.linalg.norm(surface - point, axis=1).min() - robot.foot_radius)
            gap = np.array(gap)
            assert gap[10:-10].min() > -0.0015, (x, leg)
            assert gap[(tau > 0.35) & (tau < 0.65)].min() > 0.01, (x, leg)
    assert shaped >= 10


def test_joint_path_is_never_slower_than_the_heuristic(littledog) -> None:
    """Where the shape's cost misjudges the time law, the heuristic path is kept."""
    _, wb = littledog
    terrain = load_terrain(ROCKS)
    for x in (0.40, 0.55, 0.60, 0.75):
        for leg in range(4):
            times = []
            for path in ("cartesian", "joint"):
                spline, angles = _swing(
                    littledog, SwingConfig(path=path, **FAST), leg, x, 0.09, terrain
                )
                times.append(spline.least_time(angles, wb.velocity_limit[leg]))
            assert times[1] <= times[0] + 1e-9


def test_joint_path_only_under_the_joint_time_law(littledog) -> None:
    """Under the "even" law (which it does not speed up) the heuristic path is kept."""
    even = {**EVEN_SWING_FIELDS, "path": "joint"}
    spline, _ = _swing(littledog, SwingConfig(**even), 0)
    assert len(spline.waypoints) == 4
    spline, _ = _swing(littledog, SwingConfig(path="joint", **FAST), 0)
    assert len(spline.waypoints) == 17


def test_joint_path_needs_the_legs_kinematics() -> None:
    """Without the leg's FK the heuristic four-waypoint path is planned."""
    spline = SwingSpline.plan(
        [0.0, 0.0, 0.0], [0.1, 0.0, 0.0], 0.3, SwingConfig(path="joint", **FAST)
    )
    assert len(spline.waypoints) == 4
    with pytest.raises(ConfigError):
        SwingConfig(path="straight")


def test_fast_swing_relief_takes_the_fast_options_only_over_level_ground(littledog) -> None:
    """Flat ground: the joint law and path, the shorter swing; over rocks: the settings as set."""
    _, wb = littledog
    gated = SwingConfig(fast_swing_relief=0.01, **EVEN_SWING_FIELDS)
    flat = load_terrain("flat")
    spline, angles = _swing(littledog, gated, 0, 0.5, 0.09, flat)
    plain, _ = _swing(littledog, SwingConfig(**EVEN_SWING_FIELDS), 0, 0.5, 0.09, flat)
    fast, _ = _swing(littledog, SwingConfig(path="joint", **FAST), 0, 0.5, 0.09, flat)
    assert len(spline.waypoints) == len(fast.waypoints) == 17
    least = spline.least_time(angles, wb.velocity_limit[0])
    assert least == pytest.approx(fast.least_time(angles, wb.velocity_limit[0]))
    assert least < 0.9 * plain.least_time(angles, wb.velocity_limit[0])
    rocks = load_terrain(ROCKS)
    kept = 0
    for x in (0.30, 0.45, 0.60, 0.75):
        for leg in range(4):
            spline, angles = _swing(littledog, gated, leg, x, 0.09, rocks)
            plain, _ = _swing(littledog, SwingConfig(**EVEN_SWING_FIELDS), leg, x, 0.09, rocks)
            if len(spline.waypoints) == 4:
                kept += 1
                limit = wb.velocity_limit[leg]
                assert spline.least_time(angles, limit) == plain.least_time(angles, limit)
    assert kept >= 8
