"""Where a re-plan starts: the measured feet and trunk, and which leg steps first (issue 7)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

import roughwalk
from roughwalk import _core
from roughwalk.config import override
from roughwalk.sim import CrawlSource
from roughwalk.sim.config import SimConfig
from roughwalk.sim.executor import Executor, later_legs
from roughwalk.sim.footstep_source import PlanAttempt, PlannerSource, PlanStart
from roughwalk.sim.runner import Runner
from roughwalk.sim.world import World

LF, RF, LH, RH = range(4)
HAVE_PLANNER = hasattr(_core, "FootstepPlanner")


class OnlyOneLegSteps:
    """A crawl source with no plan unless ``leg`` steps first (a shin against a rock)."""

    name = "only-one-leg"

    def __init__(self, robot: roughwalk.Robot, terrain: roughwalk.Terrain, leg: int) -> None:
        self.crawl = CrawlSource(robot, terrain)
        self.leg = leg
        self.starts: list[PlanStart] = []

    def plan(self, start: PlanStart, goal: NDArray[np.float64], time_limit: float) -> PlanAttempt:
        self.starts.append(start)
        if start.next_leg != self.leg:
            return PlanAttempt(None, "infeasible", "the planner found no plan (infeasible)", 0.0)
        return self.crawl.plan(start, goal, time_limit)


@pytest.fixture(scope="module")
def standing() -> tuple[roughwalk.Robot, roughwalk.Terrain, Any]:
    robot = roughwalk.load_robot("littledog")
    terrain = roughwalk.load_terrain("flat")
    st = robot.nominal_stance
    base = np.array([0.5, 0.0, st.base_height])
    quat = np.array([1.0, 0.0, 0.0, 0.0])
    q, _ = robot.inverse_kinematics(st.feet + base, base, quat)
    measured = Runner(World(robot, terrain)).reset(q, base, quat)
    return robot, terrain, measured


def replan(standing: Any, from_trunk: bool) -> tuple[bool, OnlyOneLegSteps, dict[str, Any]]:
    robot, terrain, measured = standing
    source = OnlyOneLegSteps(robot, terrain, RF)
    config = override(SimConfig(), {"reflex.replan_from_trunk": from_trunk})
    executor = Executor(robot, terrain, source, config=config)
    executor._reflex_next_leg = LF
    holding = executor._standing(measured)
    ok, _ = executor._replan(measured, holding, np.array([1.0, 0.0]), measured.time)
    return ok, source, executor.log.events[-1]


def test_the_other_legs_are_tried_in_walking_order_after_the_one_due() -> None:
    assert later_legs(LF) == [RH, RF, LH]
    assert later_legs(RF) == [LH, LF, RH]


def test_a_replan_gives_the_measured_trunk_and_lets_another_leg_step_first(standing) -> None:
    _, _, measured = standing
    ok, source, event = replan(standing, from_trunk=True)
    assert ok and event["start"] == "measured, RF first"
    assert [s.next_leg for s in source.starts] == [LF, RH, RF]
    for start in source.starts:
        assert start.trunk is not None
        np.testing.assert_array_equal(start.trunk[0], measured.base_pos)
        np.testing.assert_array_equal(start.trunk[1], measured.base_quat)
        np.testing.assert_array_equal(start.feet, measured.feet)
    # Off: the leg due, without the trunk, and the run ends there.
    ok, source, event = replan(standing, from_trunk=False)
    assert not ok and event["start"] == "measured"
    assert [(s.next_leg, s.trunk) for s in source.starts] == [(LF, None)]


@pytest.mark.skipif(not HAVE_PLANNER, reason="the Rust footstep planner is not built")
def test_the_replan_event_gives_the_start_certificate_s_clearance(standing) -> None:
    """Where the feet stand on flat ground the start needs no relaxing: the event says so."""
    robot, terrain, measured = standing
    source = PlannerSource(robot, terrain, expansions=2000)
    executor = Executor(robot, terrain, source, config=SimConfig())
    executor._reflex_next_leg = LF
    ok, _ = executor._replan(
        measured, executor._standing(measured), np.array([1.0, 0.0]), measured.time
    )
    event = executor.log.events[-1]
    assert ok and event["start"] == "measured"
    full = source.planner.config.certificate.clearance
    assert event["start_clearance_m"] is not None and event["start_clearance_m"] >= full
    # A source that certifies nothing (the crawl) has none to give.
    _, _, crawl_event = replan(standing, from_trunk=True)
    assert crawl_event["start_clearance_m"] is None


class OnlyANudgedStanceWithLHFirst:
    """A crawl source certifying no stance but ``feet`` with one foot moved, and then only LH first.

    Board AE (bench large rocks seed 4): the stance a slid LF left had no
    start for RH, the leg due, and no footstep out of it for the others;
    LF moved 1 cm with LH first had a plan.
    """

    name = "only-nudged-lh-first"

    def __init__(self, robot: roughwalk.Robot, terrain: roughwalk.Terrain, feet: Any) -> None:
        self.crawl = CrawlSource(robot, terrain)
        self.feet = np.array(feet, dtype=float)
        self.starts: list[PlanStart] = []

    def plan(self, start: PlanStart, goal: NDArray[np.float64], time_limit: float) -> PlanAttempt:
        self.starts.append(start)
        assert start.feet is not None
        if np.allclose(start.feet, self.feet):
            return PlanAttempt(None, "invalid_input", "start stance has no pose certificate", 0.0)
        if start.next_leg != LH:
            return PlanAttempt(None, "infeasible", "the planner found no plan (infeasible)", 0.0)
        return self.crawl.plan(start, goal, time_limit)


def nudged_replan(standing: Any, any_leg: bool) -> tuple[bool, OnlyANudgedStanceWithLHFirst, Any]:
    robot, terrain, measured = standing
    source = OnlyANudgedStanceWithLHFirst(robot, terrain, measured.feet)
    config = override(SimConfig(), {"reflex.replan_nudge_any_leg": any_leg})
    executor = Executor(robot, terrain, source, config=config)
    executor._reflex_next_leg = RH
    holding = executor._standing(measured)
    ok, _ = executor._replan(measured, holding, np.array([1.0, 0.0]), measured.time)
    return ok, source, executor.log.events[-1]


def test_a_nudged_stance_may_start_with_another_leg(standing) -> None:
    """``reflex.replan_nudge_any_leg``: the first nudged stance, RH due, LH first."""
    _, _, measured = standing
    ok, source, event = nudged_replan(standing, any_leg=True)
    assert ok and event["start"] == "nudged RH 1 cm, LH first"
    nudged = [s for s in source.starts if not np.allclose(s.feet, measured.feet)]
    # RH's own stances first (it lifts first, so its start matters least), then
    # the legs in walking order after RH (RF has no plan either), up to LH.
    assert [s.next_leg for s in nudged] == [RH, RF, LH]
    assert all(np.allclose(s.feet, nudged[0].feet) for s in nudged)
    moved = np.linalg.norm((nudged[0].feet - measured.feet)[:, :2], axis=1)
    assert moved[RH] == pytest.approx(0.01) and np.all(np.delete(moved, RH) == 0)
    # Off: only RH is tried first from each nudged stance, and the run ends there.
    ok, source, event = nudged_replan(standing, any_leg=False)
    assert not ok and event["start"] == "nudged RH 1 cm"
    nudged = [s for s in source.starts if not np.allclose(s.feet, measured.feet)]
    assert [s.next_leg for s in nudged] == [RH]
