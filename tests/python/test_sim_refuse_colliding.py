"""A footstep the generator cannot make collision-free is re-planned, not walked (issue 7)."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

import roughwalk
from roughwalk import _core
from roughwalk.config import override
from roughwalk.sim import CrawlSource
from roughwalk.sim.config import SimConfig
from roughwalk.sim.executor import Executor
from roughwalk.sim.footstep_source import PlanAttempt, PlannerSource, PlanStart
from roughwalk.sim.trajectory_buffer import Segment

HAVE_PLANNER = hasattr(_core, "FootstepPlanner")
GOAL = np.array([0.55, 0.0])


class RecordingCrawl:
    """The crawl, remembering every start it was asked to plan from."""

    name = "recording-crawl"

    def __init__(self, robot: roughwalk.Robot, terrain: roughwalk.Terrain) -> None:
        self.crawl = CrawlSource(robot, terrain)
        self.starts: list[PlanStart] = []

    def plan(self, start: PlanStart, goal: NDArray[np.float64], time_limit: float) -> PlanAttempt:
        self.starts.append(start)
        return self.crawl.plan(start, goal, time_limit)


def _colliding_second(steps: Iterator[Any]) -> Iterator[Any]:
    """The footsteps of ``steps``, the second reported colliding (a shank on a rim)."""
    yield next(steps)
    second = next(steps)
    report = dataclasses.replace(second.report, collision_free=False, valid=False)
    yield dataclasses.replace(second, report=report)
    yield from steps


def _schedule_after_first(refuse_m: float) -> tuple[Executor, RecordingCrawl, Any, Any]:
    """An executor whose first footstep has just started; its second comes back colliding."""
    robot = roughwalk.load_robot("littledog")
    terrain = roughwalk.load_terrain("flat")
    source = RecordingCrawl(robot, terrain)
    config = override(SimConfig(), {"executor.refuse_colliding_m": refuse_m})
    executor = Executor(robot, terrain, source, config=config)
    executor._goal = GOAL
    plan, attempt, _ = executor._make_plan(PlanStart(pose=(0.3, 0.0, 0.0)), GOAL, 1.0)
    assert plan is not None, attempt.reason
    plan.steps = _colliding_second(plan.steps)
    executor._plan = plan
    first, _ = executor._next_step(plan)
    executor.buffer.append(Segment.from_footstep(first))
    executor.buffer.advance(0.0)
    executor._schedule_next(0.0)
    return executor, source, plan, first


def test_a_colliding_footstep_is_walked_as_it_came_when_off() -> None:
    executor, source, plan, _ = _schedule_after_first(0.0)
    assert len(source.starts) == 1  # the first plan only
    assert [s.kind for s in executor.buffer.queued] == ["step"]
    assert executor._plan is plan


def test_a_colliding_footstep_is_replanned_from_the_stance_before_it_with_its_foothold_refused():
    assert SimConfig().executor.refuse_colliding_m == 0.03  # the default since session 17
    executor, source, plan, first = _schedule_after_first(0.03)
    assert len(source.starts) == 2
    start = source.starts[-1]
    leg = plan.legs[1]
    # From where the current footstep leaves the feet, the colliding leg first.
    np.testing.assert_allclose(start.feet, first.feet[-1])
    assert start.next_leg == leg
    ((refused_leg, x, y, radius),) = start.refused
    assert (refused_leg, radius) == (leg, 0.03)
    assert np.hypot(x - first.feet[-1, leg, 0], y - first.feet[-1, leg, 1]) > 0.03  # it moved
    # The new plan's first footstep follows the current one after a blend.
    assert [s.kind for s in executor.buffer.queued] == ["blend", "step"]
    assert executor._plan is not plan
    assert executor.log.events[-1]["kind"] == "refused"


@pytest.mark.skipif(not HAVE_PLANNER, reason="the compiled core has no footstep planner")
def test_the_planner_keeps_the_leg_out_of_a_refused_foothold() -> None:
    robot = roughwalk.load_robot("littledog")
    terrain = roughwalk.load_terrain("flat")
    source = PlannerSource(robot, terrain, expansions=3000)
    first = source.plan(PlanStart(pose=(0.3, 0.0, 0.0)), GOAL, 5.0)
    assert first.ok, first.reason
    feet = np.array([[f.x, f.y, f.z] for f in first.plan.footsteps[:4]])
    step = first.plan.footsteps[4]
    leg = ["LF", "RF", "LH", "RH"].index(step.leg)
    start = PlanStart(feet=feet, next_leg=leg)
    again = source.plan(start, GOAL, 5.0)
    assert again.ok and again.plan.footsteps[4].leg == step.leg
    assert np.hypot(again.plan.footsteps[4].x - step.x, again.plan.footsteps[4].y - step.y) < 0.01
    refused = dataclasses.replace(start, refused=((leg, step.x, step.y, 0.03),))
    moved = source.plan(refused, GOAL, 5.0)
    assert moved.ok, moved.reason
    assert moved.plan.footsteps[4].leg == step.leg
    assert np.hypot(moved.plan.footsteps[4].x - step.x, moved.plan.footsteps[4].y - step.y) > 0.03
