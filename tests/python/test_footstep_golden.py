"""The golden sideways scenario (tests/data): the Dubins heuristic against the Euclidean one.

Zucker 2011, §4.1: with the goal beside the robot, the Euclidean heuristic
badly underestimates the cost of side-stepping and turning, and the paper
reports over a twofold speed-up from the Dubins heuristic. Measured here in
deterministic mode: the expansions each heuristic needs to its first plan.
The same scenario file drives ``benchmarks/bench_planner.py --golden``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import roughwalk as rw
from roughwalk.planning import FootstepConfig, FootstepPlanner

SCENARIO = Path(__file__).resolve().parents[1] / "data" / "footstep_golden_sideways.json"


@pytest.fixture(scope="module")
def scenario() -> dict[str, Any]:
    return dict(json.loads(SCENARIO.read_text()))


def test_dubins_expands_at_least_twice_fewer_states_than_euclidean(
    scenario: dict[str, Any],
) -> None:
    robot = rw.load_robot(scenario["robot"])
    terrain = rw.load_terrain(scenario["terrain"])
    settings = scenario["settings"]
    dubins = FootstepPlanner(
        robot, terrain, FootstepConfig.for_robot(robot, heuristic="dubins", **settings)
    )
    first = dubins.plan(
        scenario["start"],
        scenario["goal"],
        time_limit=None,
        expansions=scenario["dubins_expansions"],
    )
    assert first.status == "solved", first.reason
    needed = first.solutions[0].expansions
    # The Euclidean search gets `ratio` times the Dubins search's expansions
    # to its first plan; finding none within them proves the ratio.
    ratio = scenario["expected_ratio"]
    euclid = FootstepPlanner(
        robot,
        terrain,
        FootstepConfig.for_robot(robot, heuristic="euclidean", **settings),
        sdf=dubins.sdf,
    )
    budget = int(ratio * needed)
    other = euclid.plan(scenario["start"], scenario["goal"], time_limit=None, expansions=budget)
    assert other.states_expanded == budget
    assert not other.solutions, (
        f"Euclidean found a plan after {other.solutions[0].expansions} expansions, "
        f"Dubins after {needed}: ratio below {ratio}"
    )
