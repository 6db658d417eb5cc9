"""The "joint" time law paced under the moving trunk (``SwingConfig.law_trunk = "moving"``).

Under the swing pose alone the law misjudges a swing up or down a block (the
trunk rises or lowers into the landing pose as the foot climbs or drops, and
a target below the swing pose's reach reads no joint rate at all): the
initial trajectory's limiting joint then peaks at one point, and the
measured timing (``timing.measured_speed``) can shorten the swing only
until that peak meets the limit. Paced under the trunk as it moves, the
same swings are shorter and stay collision-free with the ZMP inside the
support polygon.
"""

from __future__ import annotations

import numpy as np
import pytest

import roughwalk as rw
from roughwalk.errors import ConfigError
from roughwalk.trajectories import straight_crawl_plan
from roughwalk.trajectories.body_keyframes import keyframe_at
from roughwalk.trajectories.config import SwingConfig
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator
from roughwalk.trajectories.initial_trajectory import moving_trunk_leg
from roughwalk.trajectories.whole_body import WholeBody

BLOCK = "barrier:height=0.05,thickness=0.12,center=0.62"
"""A 5 cm high, 12 cm deep block across the way at x = 0.56 … 0.68 m."""


@pytest.fixture(scope="module")
def block_crawl(littledog: rw.Robot):
    """Nine crawl steps of 8 cm from x = 0.4 m: the front feet climb onto the block."""
    terrain = rw.load_terrain(BLOCK)
    plan = straight_crawl_plan(littledog, terrain, (0.4, 0.0), steps=9, stride=0.08)
    out = {}
    for law in ("swing_pose", "moving"):
        config = rw.trajectories.trajectory_config(**{"swing.law_trunk": law})
        gen = FootstepTrajectoryGenerator(littledog, terrain, config=config)
        out[law] = list(gen.iter_steps(gen.prepare(plan)))
    return out


def test_swings_onto_the_block_are_shorter(block_crawl) -> None:
    """0.38 → 0.34 s and 0.26 → 0.20 s for the two front feet's climbs; no swing longer."""
    fixed = np.array([t.report.swing_s for t in block_crawl["swing_pose"]])
    moving = np.array([t.report.swing_s for t in block_crawl["moving"]])
    assert np.all(moving <= fixed + 1e-9)
    assert moving.sum() < fixed.sum() - 0.08


def test_the_shorter_swings_stay_valid(block_crawl) -> None:
    """Collision-free, within the joints' limits, the ZMP inside the support polygon."""
    for traj in block_crawl["moving"]:
        r = traj.report
        assert r.valid, f"step {r.step}: {r.notes}"
        assert r.collision_free and r.velocity_limits_ok and r.reachable
        assert r.zmp_margin_m >= 0.0


def test_moving_trunk_leg_follows_the_trunk(littledog: rw.Robot) -> None:
    """FK(IK(p)) = p under the moving trunk; its ends are the IK at the first and last poses."""
    wb = WholeBody(littledog)
    feet = littledog.nominal_stance.feet.copy()
    feet[:, 2] = littledog.foot_radius
    base = np.array([0.0, 0.0, littledog.nominal_stance.base_height])
    pose = keyframe_at(wb, feet, base, np.zeros(3))
    trunk = np.zeros((11, 6))
    trunk[:, :3] = base
    trunk[:, 0] = np.linspace(0.0, 0.03, 11)
    trunk[:, 2] -= np.linspace(0.0, 0.02, 11)
    trunk[:, 4] = np.linspace(0.0, 0.1, 11)
    angles, to_feet = moving_trunk_leg(wb, pose, trunk, 0)
    start = feet[0]
    path = start + np.linspace(0.0, 1.0, 21)[:, None] * [0.06, 0.0, 0.0]
    path[:, 2] += 0.03 * np.sin(np.linspace(0.0, np.pi, 21))
    q = angles(path)
    np.testing.assert_allclose(to_feet(q), path, atol=1e-6)
    last = keyframe_at(wb, pose.feet, trunk[-1, :3], trunk[-1, 3:])
    np.testing.assert_allclose(q[-1], last.leg_angles(wb, 0)(path[-1:])[0], atol=1e-9)
    np.testing.assert_allclose(q[0], pose.leg_angles(wb, 0)(path[:1])[0], atol=1e-9)


def test_a_rise_gate_leaves_level_swings_as_they_were(littledog: rw.Robot) -> None:
    """With ``law_trunk_rise`` 1 cm a flat crawl is the same trajectory as under the swing pose.

    So the flat-ground push sweeps walk as before; over the block the climbs
    (5 cm) are still paced under the moving trunk.
    """
    terrain = rw.load_terrain("flat:length=1.2,width=0.5")
    plan = straight_crawl_plan(littledog, terrain, (0.3, 0.0), steps=4, stride=0.07)
    made = {}
    for law, rise in (("swing_pose", 0.0), ("moving", 0.01), ("moving", 0.0)):
        config = rw.trajectories.trajectory_config(
            **{"swing.law_trunk": law, "swing.law_trunk_rise": rise}
        )
        gen = FootstepTrajectoryGenerator(littledog, terrain, config=config)
        made[law, rise] = list(gen.iter_steps(gen.prepare(plan)))
    for a, b in zip(made["swing_pose", 0.0], made["moving", 0.01], strict=True):
        np.testing.assert_array_equal(a.q, b.q)
    # Ungated, the moving trunk does change level swings (what the gate is for).
    assert any(
        a.q.shape != b.q.shape or not np.array_equal(a.q, b.q)
        for a, b in zip(made["swing_pose", 0.0], made["moving", 0.0], strict=True)
    )


def test_law_trunk_is_checked() -> None:
    with pytest.raises(ConfigError, match="law_trunk"):
        SwingConfig(law_trunk="still")
    with pytest.raises(ConfigError, match="law_trunk_rise"):
        SwingConfig(law_trunk_rise=-0.01)
