"""timing.swing_trunk "moving": the swing is timed under a trunk that moves on with the ZMP."""

from __future__ import annotations

import numpy as np
import pytest
from _even_swings import EVEN_SWINGS

import roughwalk as rw
from roughwalk.trajectories import straight_crawl_plan
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator


@pytest.fixture(scope="module")
def crawl() -> tuple[rw.Robot, rw.Terrain, object, dict]:
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain("flat")
    sdf = terrain.sdf(0.005)
    plan = straight_crawl_plan(robot, terrain, (0.0, 0.0), steps=8, stride=0.1)
    return robot, terrain, sdf, plan


def timings(crawl, trunk: str) -> list:
    robot, terrain, sdf, plan = crawl
    config = rw.trajectories.trajectory_config(**{"timing.swing_trunk": trunk, **EVEN_SWINGS})
    gen = FootstepTrajectoryGenerator(robot, terrain, sdf=sdf, config=config)
    return gen, gen.prepare(plan)


def test_a_trunk_moving_on_during_the_swing_shortens_the_swings(crawl) -> None:
    _, shorter = timings(crawl, "shorter")
    gen, moving = timings(crawl, "moving")
    # The nominal swings (§5.2) that swing_trunk times, before the measured
    # timing (timing.measured_speed) shortens them to the joints' peak speeds.
    n = len(moving.timings)
    before = np.array([shorter.nominal_timing(k).swing_s for k in range(n)])
    after = np.array([moving.nominal_timing(k).swing_s for k in range(n)])
    # "moving" also tries the trunks of "shorter", so it never times a swing longer.
    assert np.all(after <= before + 1e-12)
    # On a straight crawl the ZMP moves forward in most swings: the swing
    # foot's motion in the trunk frame is shorter, and so is its swing.
    assert np.sum(after < before - 1e-9) >= len(before) // 2
    # The guesses are checked: every step keeps the joints' speed limits.
    for step in gen.iter_steps(moving):
        assert step.report.velocity_limits_ok, step.report.notes
