"""The footstep planner's contract: statuses, the ε = 1 optimum, determinism, re-plans, config."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest

import roughwalk as rw
from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.planning import FootstepConfig, FootstepPlanner, plan_footsteps
from roughwalk.planning.footstep_config import hip_to_hip_length

SMALL_ROCKS = (
    "round_rocks:seed=4,length=0.7,width=0.5,pad_start=0.2,max_height=0.03,bed_height=0.01"
)
SMALL_ACTIONS = (
    (0.0, 0.0, 0.0),
    (0.02, 0.0, 0.0),
    (0.04, 0.0, 0.0),
    (0.02, 0.01, 0.0),
    (0.02, -0.01, 0.0),
)
ROCKS = "round_rocks:seed=2,length=0.9,width=0.6,pad_start=0.3,pad_end=0.15,max_height=0.04"
START = (0.25, 0.0, 0.0)
GOAL = (0.55, 0.02)


class UnitCost:
    """Every known cell costs 1, unknown ones +inf: no features, so tiny islands stay footholds."""

    def cost_map(
        self, terrain: rw.Terrain, heading: float | None = None, leg: str = "front"
    ) -> np.ndarray:
        return np.where(terrain.known, 1.0, np.inf)


class BumpyCost:
    """A fixed cost pattern in [1, 1.8]: makes optima unique and non-trivial."""

    def cost_map(
        self, terrain: rw.Terrain, heading: float | None = None, leg: str = "front"
    ) -> np.ndarray:
        gx, gy = np.meshgrid(terrain.x, terrain.y, indexing="ij")
        return 1.0 + 0.8 * np.abs(np.sin(25 * gx) * np.cos(30 * gy))


@pytest.fixture(scope="module")
def rocks(littledog: rw.Robot) -> FootstepPlanner:
    return FootstepPlanner(littledog, rw.load_terrain(ROCKS))


@pytest.fixture(scope="module")
def rocks_plan(rocks: FootstepPlanner) -> rw.planning.FootstepPlan:
    return rocks.plan(START, GOAL, time_limit=None, expansions=300)


def test_plan_reaches_the_goal_with_the_issue_json_fields(
    rocks: FootstepPlanner, rocks_plan: Any
) -> None:
    plan = rocks_plan
    assert plan.status == "solved" and plan.reason is None, plan.reason
    assert [f.leg for f in plan.footsteps[:4]] == ["LF", "RF", "LH", "RH"]
    assert plan.steps == len(plan.certificates) > 0
    assert [c.step for c in plan.certificates] == list(range(1, plan.steps + 1))
    # The crawl: LH, LF, RH, RF, LH, ...
    order = ("LH", "LF", "RH", "RF")
    assert [f.leg for f in plan.footsteps[4:]] == [order[k % 4] for k in range(plan.steps)]
    final = plan.stances()[-1]
    centroid = final[:, :2].mean(axis=0)
    assert math.dist(centroid, GOAL) <= rocks.config.goal_radius + 1e-9
    # Footsteps lie on the terrain surface.
    xy = np.array([[f.x, f.y] for f in plan.footsteps])
    z = np.array([f.z for f in plan.footsteps])
    np.testing.assert_allclose(z, rocks.terrain.height(xy), atol=1e-9)
    costs = [s.cost for s in plan.solutions]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    assert plan.cost == pytest.approx(costs[-1])
    assert plan.first_solution_s == plan.solutions[0].time_s > 0
    assert plan.heuristic == "dubins" and not plan.bound_guaranteed
    assert 0 < plan.states_expanded <= 300 and plan.actions_evaluated > plan.states_expanded
    data = json.loads(json.dumps(plan.to_json(), allow_nan=False))
    for key in (
        "status",
        "reason",
        "footsteps",
        "certificates",
        "heuristic",
        "epsilon0",
        "first_solution_s",
        "solutions",
        "states_expanded",
        "actions_evaluated",
        "actions_per_s",
        "cost",
        "epsilon_bound",
        "robot",
        "terrain",
    ):
        assert key in data, key
    assert data["robot"] == "littledog" and data["terrain"] == ROCKS
    assert set(data["footsteps"][0]) == {"leg", "x", "y", "z"}
    cert = data["certificates"][0]
    assert len(cert["base_pos"]) == 3 and len(cert["base_quat"]) == 4 and len(cert["q"]) == 12
    assert set(data["solutions"][0]) >= {"time_s", "cost", "epsilon"}
    assert data["initial_pose"]["step"] == 0


def test_same_inputs_and_expansion_budget_give_the_same_plan(
    littledog: rw.Robot, rocks: FootstepPlanner, rocks_plan: Any
) -> None:
    again = rocks.plan(START, GOAL, time_limit=None, expansions=300)
    fresh = FootstepPlanner(littledog, rocks.terrain, rocks.config, sdf=rocks.sdf).plan(
        START, GOAL, time_limit=None, expansions=300
    )
    for other in (again, fresh):
        assert other.footsteps == rocks_plan.footsteps
        assert other.cost == rocks_plan.cost
        assert other.states_expanded == rocks_plan.states_expanded
    # The search tree (each state once, from its first parent) does not depend on the cache.
    np.testing.assert_array_equal(again.tree, fresh.tree)
    assert 0 < len(fresh.tree) <= fresh.states_generated - 1
    # The warm cache served the repeat: fewer certificate searches, same plan.
    assert again.actions_evaluated < fresh.actions_evaluated
    assert again.certificate_cache_hits > fresh.certificate_cache_hits


def test_epsilon_one_plan_cost_equals_the_exhaustive_optimum(littledog: rw.Robot) -> None:
    # Coarse lattice, five actions, the admissible heuristic: small enough to search exhaustively.
    config = FootstepConfig.for_robot(
        littledog,
        resolution=0.01,
        local_search_radius=0.0,
        actions=SMALL_ACTIONS,
        heuristic="euclidean",
        epsilon0=1.0,
    )
    terrain = rw.load_terrain(SMALL_ROCKS)
    planner = FootstepPlanner(littledog, terrain, config, cost=BumpyCost())
    start, goal = (0.25, 0.0, 0.0), (0.34, 0.0)
    ara = planner.plan(start, goal, time_limit=None)
    exact = planner.plan(start, goal, time_limit=None, search="exhaustive")
    assert ara.status == exact.status == "solved"
    assert ara.bound_guaranteed and ara.epsilon_bound == 1.0
    assert ara.cost == pytest.approx(exact.cost, rel=1e-12)
    assert exact.steps >= 4


def test_admissible_bounds_hold_against_the_exhaustive_optimum(littledog: rw.Robot) -> None:
    config = FootstepConfig.for_robot(
        littledog,
        resolution=0.01,
        local_search_radius=0.0,
        actions=SMALL_ACTIONS,
        heuristic="euclidean",
        epsilon0=3.0,
        epsilon_decrement=0.5,
    )
    terrain = rw.load_terrain(SMALL_ROCKS)
    planner = FootstepPlanner(littledog, terrain, config, cost=BumpyCost())
    start, goal = (0.25, 0.0, 0.0), (0.36, 0.01)
    optimum = planner.plan(start, goal, time_limit=None, search="exhaustive").cost
    plan = planner.plan(start, goal, time_limit=None)
    assert optimum is not None and plan.bound_guaranteed
    for s in plan.solutions:
        assert s.cost <= s.epsilon_bound * optimum * (1 + 1e-12), s
        assert s.epsilon_bound <= s.epsilon
    assert plan.cost == pytest.approx(optimum, rel=1e-12)


def _stepping_stones() -> rw.Terrain:
    """Four 6 cm stones under the start feet of a trunk at (0.2, 0), in a 1 m deep chasm."""
    h = 0.005
    x = np.arange(0.0, 0.6 + h / 2, h)
    y = np.arange(-0.3, 0.3 + h / 2, h)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    heights = np.full(gx.shape, -1.0)
    for cx in (0.108, 0.292):
        for cy in (0.06, -0.06):
            heights[(np.abs(gx - cx) <= 0.031) & (np.abs(gy - cy) <= 0.031)] = 0.0
    return rw.Terrain(heights, x[0], y[0], h, h, name="stepping stones in a chasm")


def test_island_in_a_chasm_is_infeasible_once_open_is_exhausted(littledog: rw.Robot) -> None:
    config = FootstepConfig.for_robot(littledog, resolution=0.02, local_search_radius=0.0)
    planner = FootstepPlanner(littledog, _stepping_stones(), config, cost=UnitCost())
    plan = planner.plan((0.2, 0.0, 0.0), (0.5, 0.0), time_limit=None)
    assert plan.status == "infeasible", plan.reason
    assert plan.footsteps == () and plan.cost is None and plan.states_expanded > 10
    # Every stance on the stones was tried: at most 9 cells a stone, 4 legs to move next.
    assert plan.states_generated <= 4 * 9**4
    assert sum(plan.certificate_failures.values()) > 0


def test_bad_input_is_invalid_with_a_reason(littledog: rw.Robot) -> None:
    # A 16 cm post at (0.45, 0.1): a trunk standing over it collides.
    h = 0.005
    x = np.arange(0.0, 0.8 + h / 2, h)
    y = np.arange(-0.3, 0.3 + h / 2, h)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    heights = np.where(np.hypot(gx - 0.45, gy - 0.1) < 0.03, 0.16, 0.0)
    terrain = rw.Terrain(heights, 0.0, -0.3, h, h, name="post")
    planner = FootstepPlanner(littledog, terrain, cost=UnitCost())
    cases = [
        ((0.2, 0.0, 0.0), (1.5, 0.0), "off the terrain"),
        ((0.2, 0.0, 0.0), (math.nan, 0.0), "finite"),
        ((math.nan, 0.0, 0.0), (0.5, 0.0), "finite"),
        ((0.03, 0.0, 0.0), (0.5, 0.0), "off the terrain"),
        ((0.45, 0.1, 0.0), (0.6, 0.0), "collision or out of reach"),
    ]
    for start, goal, reason in cases:
        plan = planner.plan(start, goal, time_limit=None, expansions=10)
        assert plan.status == "invalid_input", (start, goal)
        assert plan.reason is not None and reason in plan.reason, plan.reason
        assert json.dumps(plan.to_json(), allow_nan=False)
    spread = [[0.65, 0.06], [0.29, -0.06], [0.11, 0.06], [0.11, -0.06]]
    plan = planner.replan(spread, next_leg="LH", goal=(0.6, 0.0), expansions=10)
    assert plan.status == "invalid_input" and "out of reach" in (plan.reason or "")
    with pytest.raises(InvalidArgumentError, match="next_leg"):
        planner.replan(spread, next_leg="XX", goal=(0.6, 0.0))
    with pytest.raises(InvalidArgumentError, match="shape"):
        planner.replan([[0.1, 0.2]], goal=(0.6, 0.0))


def test_replan_from_the_feet_mid_plan_reuses_certificates(
    rocks: FootstepPlanner, rocks_plan: Any
) -> None:
    stance = rocks_plan.stances()[3]
    next_leg = rocks_plan.footsteps[4 + 3].leg
    fresh = FootstepPlanner(rocks.robot, rocks.terrain, rocks.config, sdf=rocks.sdf)
    cold = fresh.replan(stance, next_leg=next_leg, goal=GOAL, time_limit=None, expansions=100)
    warm = rocks.replan(stance, next_leg=next_leg, time_limit=None, expansions=100)
    assert warm.status == cold.status == "solved"
    assert warm.footsteps == cold.footsteps
    np.testing.assert_allclose([[f.x, f.y] for f in warm.footsteps[:4]], stance[:, :2])
    assert warm.footsteps[4].leg == next_leg
    assert warm.certificate_cache_hits > cold.certificate_cache_hits
    assert warm.actions_evaluated < cold.actions_evaluated


def test_callback_sees_each_improved_solution_and_can_stop_the_search(
    rocks: FootstepPlanner,
) -> None:
    seen: list[Any] = []
    rocks.plan(START, GOAL, time_limit=None, expansions=300, callback=seen.append)
    assert len(seen) >= 1 and all(b.cost < a.cost for a, b in zip(seen, seen[1:], strict=False))
    stopped = rocks.plan(START, GOAL, time_limit=None, expansions=300, callback=lambda r: True)
    assert len(stopped.solutions) == 1 and stopped.status == "solved"
    assert stopped.states_expanded == stopped.solutions[0].expansions

    def boom(report: Any) -> None:
        raise RuntimeError("callback failed")

    with pytest.raises(RuntimeError, match="callback failed"):
        rocks.plan(START, GOAL, time_limit=None, expansions=300, callback=boom)


def test_config_scales_with_the_robot_and_refuses_bad_values(littledog: rw.Robot) -> None:
    anymal = rw.load_robot("anymal_c")
    small, large = FootstepConfig.for_robot(littledog), FootstepConfig.for_robot(anymal)
    ratio = hip_to_hip_length(anymal) / hip_to_hip_length(littledog)
    assert large.resolution / small.resolution == pytest.approx(ratio)
    assert large.goal_radius / small.goal_radius == pytest.approx(ratio)
    assert np.asarray(large.actions) / ratio == pytest.approx(
        np.asarray(small.actions) * [1, 1, 0] + np.asarray(small.actions) * [0, 0, 1] / ratio
    )
    assert 12 <= len(small.actions) <= 25
    assert (
        FootstepConfig.for_robot(littledog, certificate_clearance=0.006).certificate.clearance
        == 0.006
    )
    for bad, match in (
        ({"heuristic": "manhattan"}, "heuristic"),
        ({"epsilon0": 0.5}, "epsilon0"),
        ({"walking_order": ("LF", "LF", "RH", "RF")}, "walking_order"),
        ({"resolution": -1.0}, "resolution"),
        ({"banana": 1}, "banana"),
        ({"certificate_max_iterations": 0}, "max_iterations"),
    ):
        with pytest.raises(ConfigError, match=match):
            FootstepConfig.for_robot(littledog, **bad)


def test_plan_footsteps_is_the_one_call_form(littledog: rw.Robot, rocks_plan: Any) -> None:
    terrain = rw.load_terrain(ROCKS)
    plan = plan_footsteps(littledog, terrain, START, GOAL, None, expansions=300)
    assert plan.footsteps == rocks_plan.footsteps
    euclid = plan_footsteps(
        littledog, terrain, START, GOAL, None, expansions=50, heuristic="euclidean"
    )
    assert euclid.heuristic == "euclidean" and euclid.bound_guaranteed


@pytest.mark.parametrize("name", [info.name for info in rw.robots.list_robots()])
def test_every_registered_robot_plans_across_flat_ground(name: str) -> None:
    littledog = rw.load_robot(name)
    config = FootstepConfig.for_robot(littledog)
    length = hip_to_hip_length(littledog)
    terrain = rw.load_terrain(f"flat:length={6 * length:.3f},width={3 * length:.3f}")
    start = (1.5 * length, 0.0, 0.0)
    goal = (4.0 * length, 0.3 * length)
    plan = FootstepPlanner(littledog, terrain, config).plan(
        start, goal, time_limit=None, expansions=200
    )
    assert plan.status == "solved", plan.reason
    final = plan.stances()[-1][:, :2].mean(axis=0)
    assert math.dist(final, goal) <= config.goal_radius + 1e-9
    assert sum(plan.certificate_failures.values()) == 0
