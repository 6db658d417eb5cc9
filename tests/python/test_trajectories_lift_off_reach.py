"""swing.lift_off_reach: the trunk is lowered and tilted until the lifting foot is reached."""

from __future__ import annotations

import pytest

import roughwalk as rw
from roughwalk.trajectories import straight_crawl_plan
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator

# The fast swing options, with which the fitted timing makes the preview lead
# the trunk far enough ahead to lose a trailing foot (see TimingConfig).
SETTINGS = {"swing.time_law": "joint", "swing.path": "joint", "swing.ramp_fraction": 0.1}


@pytest.fixture(scope="module")
def crawl() -> tuple[rw.Robot, rw.Terrain, object, dict]:
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain("flat")
    sdf = terrain.sdf(0.005)
    # 10 cm strides: the last step (RF) starts from the back of its foot's reach.
    plan = straight_crawl_plan(robot, terrain, (0.0, 0.0), steps=8, stride=0.10)
    return robot, terrain, sdf, plan


def generated(crawl, lift_off_reach: bool) -> list:
    robot, terrain, sdf, plan = crawl
    config = rw.trajectories.trajectory_config(
        **SETTINGS, **{"swing.lift_off_reach": lift_off_reach}
    )
    gen = FootstepTrajectoryGenerator(robot, terrain, sdf=sdf, config=config)
    return list(gen.iter_steps(gen.prepare(plan)))


def test_without_it_a_long_crawl_s_trailing_foot_is_lost_at_lift_off(crawl) -> None:
    steps = generated(crawl, lift_off_reach=False)
    last = steps[-1].report
    assert last.leg == "RF"
    assert not last.valid
    assert not last.reachable


def test_with_it_every_step_is_valid_at_its_fitted_timing(crawl) -> None:
    steps = generated(crawl, lift_off_reach=True)
    for step in steps:
        r = step.report
        assert r.valid, (r.leg, r.notes)
        # No step fell back to its longer nominal timing or was stretched.
        fitted = r.fitted_shift_s + r.fitted_swing_s + r.settle_s
        assert r.duration_s == pytest.approx(fitted, abs=1e-9), r.leg
