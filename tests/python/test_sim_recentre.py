"""Recentring: after a re-plan finds nothing, a foot steps toward its nominal place."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import roughwalk as rw
from roughwalk import _core
from roughwalk.config import override
from roughwalk.errors import ConfigError
from roughwalk.sim.config import ReflexConfig, SimConfig
from roughwalk.sim.executor import Executor
from roughwalk.sim.foothold_snap import footholds_toward
from roughwalk.sim.footstep_source import PlannerSource, PlanStart, planner_config
from roughwalk.sim.runner import Runner
from roughwalk.sim.world import World

pytestmark = pytest.mark.skipif(
    not hasattr(_core, "FootstepPlanner"), reason="the compiled core has no footstep planner"
)

# Board AE, bench large rocks seed 16 (``bench_littledog.py --expansions 40000``),
# settled after its third reflex at 4.17 s: RH 4.5 cm behind its nominal place, and
# no plan from this stance, nor from one with any foot nudged 2 cm.
AE_SEED16_FEET = np.array(
    [
        [0.28064, 0.38387, 0.02515],
        [0.26711, 0.21290, 0.02432],
        [0.15724, 0.34356, 0.08036],
        [0.06152, 0.23055, 0.05889],
    ]
)
AE_SEED16_TRUNK = (
    np.array([0.19389, 0.29346, 0.19975]),
    np.array([0.99057, 0.03262, 0.13078, 0.02471]),
)
AE_SEED16_GOAL = np.array([0.459, 0.3045])
RH = 3


@pytest.fixture(scope="module")
def settled(littledog_board):
    robot = rw.load_robot("littledog")
    terrain = littledog_board("AE")
    # The walk's settings of session 21, before the 1 cm edge margin.
    config = planner_config(robot, 0.4, {"edge_margin": 0.0})
    source = PlannerSource(robot, terrain, expansions=40000, config=config)
    return robot, terrain, source


def recovered(robot, terrain, source, steps: int) -> tuple[Executor, object]:
    """An executor settled after a reflex with seed 16's feet and trunk measured."""
    config = override(SimConfig(), {"reflex.recentre_steps": steps})
    executor = Executor(robot, terrain, source, config=config)
    executor._goal = AE_SEED16_GOAL
    base, quat = AE_SEED16_TRUNK
    q, _ = robot.inverse_kinematics(AE_SEED16_FEET, base, quat)
    measured = Runner(World(robot, terrain)).reset(q, base, quat)
    return executor, dataclasses.replace(measured, feet=AE_SEED16_FEET.copy())


def test_footholds_toward_are_footholds_within_reach_nearer_their_goal_first(settled) -> None:
    robot, terrain, source = settled
    foot, toward = AE_SEED16_FEET[RH], np.array([0.105, 0.231])
    found = footholds_toward(
        source.planner, terrain, foot, toward, 0.05, robot.foot_radius, front=False
    )
    assert len(found) > 3
    d = np.linalg.norm(found[:, :2] - toward, axis=1)
    assert np.all(np.diff(d) >= -1e-12)
    assert np.all(d <= np.linalg.norm(foot[:2] - toward) - 0.01 + 1e-12)
    assert np.all(np.linalg.norm(found[:, :2] - foot[:2], axis=1) <= 0.05 + 1e-12)
    # Each rests on the ground: its centre one foot radius above the terrain below it.
    ground = np.asarray(terrain.height(found[:, :2]))
    assert np.all(found[:, 2] >= ground + robot.foot_radius - 1e-6)


def test_a_stance_with_no_plan_steps_the_farthest_foot_toward_its_place(settled) -> None:
    robot, terrain, source = settled
    trunk = AE_SEED16_TRUNK
    # The premise: no plan from where the feet stand.
    assert not source.plan(
        PlanStart(feet=AE_SEED16_FEET, next_leg=None, trunk=trunk), AE_SEED16_GOAL, 2.0
    ).ok
    executor, measured = recovered(robot, terrain, source, steps=1)
    assert executor._recentre(measured, AE_SEED16_GOAL, 4.17)
    assert executor.buffer.queued
    (event,) = executor.log.events_of("recentre")
    assert event["leg"] == "RH"
    target, nominal = np.asarray(event["target"]), np.asarray(event["nominal"])
    foot = AE_SEED16_FEET[RH]
    assert np.linalg.norm(target[:2] - nominal) <= np.linalg.norm(foot[:2] - nominal) - 0.01
    assert np.linalg.norm(target[:2] - foot[:2]) <= 0.05 + 1e-9
    # Checked apart from the executor: the stance it makes has a plan.
    moved = AE_SEED16_FEET.copy()
    moved[RH] = target
    assert source.plan(PlanStart(feet=moved, next_leg=None, trunk=trunk), AE_SEED16_GOAL, 2.0).ok
    # The queued motion ends with RH on its target and the other feet where they stood.
    last = executor.buffer.queued[-1].last()
    np.testing.assert_allclose(last.feet[RH], target, atol=1e-9)
    np.testing.assert_allclose(last.feet[:RH], AE_SEED16_FEET[:RH], atol=1e-9)
    # Planning time is charged (``executor.compute_time_scale`` 1): the robot
    # stands for the plans' wall time before it steps.
    hold = executor.buffer.queued[0]
    assert hold.kind == "recovery" and event["charged_s"] > 0
    assert hold.duration == pytest.approx(event["charged_s"], abs=2e-3)
    np.testing.assert_allclose(hold.last().feet, AE_SEED16_FEET, atol=1e-9)
    # One step per reflex: the second call does nothing.
    assert not executor._recentre(measured, AE_SEED16_GOAL, 5.0)


def test_recentring_is_off_by_default(settled) -> None:
    robot, terrain, source = settled
    executor, measured = recovered(robot, terrain, source, steps=0)
    assert not executor._recentre(measured, AE_SEED16_GOAL, 4.17)
    assert not executor.buffer.queued and not executor.log.events_of("recentre")


def test_config_rejects_nonsense() -> None:
    for bad in ({"recentre_steps": -1}, {"recentre_steps": 1.5}, {"recentre_radius_m": -0.01}):
        with pytest.raises(ConfigError, match="recentre"):
            ReflexConfig(**bad)
