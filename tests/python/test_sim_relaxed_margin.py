"""A walk keeps feet off rims by a margin, and plans without it where the margin leaves no plan."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from roughwalk.errors import ConfigError
from roughwalk.robots import load_robot
from roughwalk.sim import run
from roughwalk.sim.config import ExecutorConfig, SimConfig
from roughwalk.sim.footstep_source import (
    PlanAttempt,
    PlannerSource,
    PlanStart,
    planner_config,
)
from roughwalk.terrain import Terrain

START = (0.3, 0.0, 0.0)
GOAL = (0.9, 0.0)


def _pitted_band() -> Terrain:
    """Flat ground crossed at x ∈ (0.42, 0.78) m by 6 mm square pits, 3.5 cm deep, every 3.2 cm.

    Every point of the band lies within 1.84 cm of a pit: with a 1 cm margin
    beyond LittleDog's 1.03 cm foot radius no foothold is left there, and the
    band is wider than any step; without it, strips midway between the pits
    (2.7 mm either side of them, 1.3 cm from the nearest pit) remain.
    """
    d = 0.002
    x = np.arange(0.0, 1.0 + d / 2, d)
    y = np.arange(-0.4, 0.4 + d / 2, d)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    pitch, half = 0.032, 0.003
    pit = (
        (gx > 0.42)
        & (gx < 0.78)
        & (np.abs((gx + pitch / 2) % pitch - pitch / 2) <= half)
        & (np.abs((gy + pitch / 2) % pitch - pitch / 2) <= half)
    )
    return Terrain(np.where(pit, -0.035, 0.0), 0.0, -0.4, d, d, name="pitted band")


@pytest.fixture(scope="module")
def terrain() -> Terrain:
    return _pitted_band()


def test_the_second_planner_plans_where_the_margin_leaves_no_plan(terrain: Terrain) -> None:
    robot = load_robot("littledog")
    walk = planner_config(robot, 0.4, {})
    assert walk.edge_margin == pytest.approx(0.01)  # a walk's default
    strict = PlannerSource(robot, terrain, expansions=3000, config=walk)
    alone = strict.plan(PlanStart(pose=START), np.array(GOAL), 30.0)
    assert not alone.ok and not alone.relaxed
    source = PlannerSource(
        robot, terrain, expansions=3000, config=walk, fallback=replace(walk, edge_margin=0.0)
    )
    attempt = source.plan(PlanStart(pose=START), np.array(GOAL), 30.0)
    assert attempt.ok and attempt.relaxed
    # Every foothold keeps the foot's radius, if not the margin, from the pits'
    # grid points (less the 1.4 mm a foothold lies from the grid point it is judged by).
    pits = np.argwhere(np.asarray(terrain.heights) < -0.01) * terrain.dx + [terrain.x0, terrain.y0]
    near = []
    for step in attempt.plan.footsteps:
        nearest = float(np.min(np.linalg.norm(pits - [step.x, step.y], axis=1)))
        assert nearest > robot.foot_radius - terrain.dx / np.sqrt(2)
        near.append(nearest < robot.foot_radius + 0.01)
    assert any(near)  # and some stand within the margin: the band is crossed


def test_a_run_plans_relaxed_by_default_and_says_so(terrain: Terrain) -> None:
    settings = {"executor.plan_expansions": 3000, "outcome.time_limit_s": 0.2}
    result = run("littledog", terrain, START, GOAL, planner="planner", **settings)
    plan = next(e for e in result.log.events if e["kind"] == "plan")
    assert plan["status"] == "solved" and plan["relaxed"] is True
    assert not result.outcome.reason.startswith("no plan")
    assert result.outcome.relaxed_plans == 1
    assert result.to_dict()["relaxed_plans"] == 1
    for relax in ("replans", "none"):
        off = run(
            "littledog",
            terrain,
            START,
            GOAL,
            planner="planner",
            **settings,
            **{"executor.relax_edge_margin": relax},
        )
        assert off.outcome.reason.startswith("no plan") and off.outcome.relaxed_plans == 0
        assert next(e for e in off.log.events if e["kind"] == "plan")["relaxed"] is False


def test_re_plans_from_the_feet_relax_the_margin_with_or_without_the_pose_fallback(
    terrain: Terrain,
) -> None:
    """From feet standing in the band only the second planner has a step, whether or
    not it plans from start poses too; without one there is no plan."""
    robot = load_robot("littledog")
    walk = planner_config(robot, 0.4, {})
    feet = np.asarray(robot.nominal_stance.feet, dtype=float).copy()
    feet[:, 0] += 0.45 - feet[:, 0].mean()
    feet[:, 2] = robot.foot_radius
    start = PlanStart(feet=feet, next_leg=2)
    relaxed = replace(walk, edge_margin=0.0)
    for from_pose in (True, False):
        source = PlannerSource(
            robot,
            terrain,
            expansions=3000,
            config=walk,
            fallback=relaxed,
            fallback_from_pose=from_pose,
        )
        attempt = source.plan(start, np.array(GOAL), 30.0)
        assert attempt.ok and attempt.relaxed
    alone = PlannerSource(robot, terrain, expansions=3000, config=walk)
    assert not alone.plan(start, np.array(GOAL), 30.0).ok


def test_relax_edge_margin_names_its_values() -> None:
    with pytest.raises(ConfigError, match="relax_edge_margin.*all, replans, none"):
        SimConfig(executor=ExecutorConfig(relax_edge_margin="sometimes"))


@pytest.fixture(scope="module")
def band_source(terrain: Terrain) -> PlannerSource:
    robot = load_robot("littledog")
    walk = planner_config(robot, 0.4, {})
    return PlannerSource(
        robot, terrain, expansions=3000, config=walk, fallback=replace(walk, edge_margin=0.0)
    )


def _band_stance() -> np.ndarray:
    robot = load_robot("littledog")
    feet = np.asarray(robot.nominal_stance.feet, dtype=float).copy()
    feet[:, 0] += 0.45 - feet[:, 0].mean()
    feet[:, 2] = robot.foot_radius
    return feet


def test_wall_time_counts_both_planners_and_the_second_gets_what_is_left(
    band_source: PlannerSource, monkeypatch: pytest.MonkeyPatch
) -> None:
    second = band_source._fallback_planner
    assert second is not None
    limits: list[float] = []

    def failing(start: PlanStart, goal: np.ndarray, time_limit: float) -> PlanAttempt:
        return PlanAttempt(None, "no_solution", "none", 0.7)

    def planning(start: PlanStart, goal: np.ndarray, time_limit: float) -> PlanAttempt:
        limits.append(time_limit)
        return PlanAttempt({"footsteps": []}, "solved", "", 0.4)

    monkeypatch.setattr(band_source, "_plan_once", failing)
    monkeypatch.setattr(second, "_plan_once", planning)
    monkeypatch.setattr(band_source, "expansions", None)  # wall-clock limits
    attempt = band_source.plan(PlanStart(pose=START), np.array(GOAL), 2.0)
    assert attempt.relaxed and attempt.wall_s == pytest.approx(1.1)
    assert limits == [pytest.approx(1.3)]
    # The first planner used the whole limit: no second plan.
    assert not band_source.plan(PlanStart(pose=START), np.array(GOAL), 0.7).ok
    assert len(limits) == 1
    # Under an expansion budget the second planner gets the whole limit again.
    monkeypatch.setattr(band_source, "expansions", 3000)
    band_source.plan(PlanStart(pose=START), np.array(GOAL), 2.0)
    assert limits[-1] == pytest.approx(2.0)


def test_the_second_planner_keeps_out_of_every_foothold_refused_so_far(
    band_source: PlannerSource,
) -> None:
    feet = _band_stance()
    first = band_source.plan(PlanStart(feet=feet, next_leg=2), np.array(GOAL), 30.0)
    assert first.ok and first.relaxed
    step = first.plan.footsteps[4]
    leg = ("LF", "RF", "LH", "RH").index(step.leg)
    refused = ((leg, step.x, step.y, 0.02),)
    again = band_source.plan(
        PlanStart(feet=feet, next_leg=2, refused=refused), np.array(GOAL), 30.0
    )
    assert again.ok and again.relaxed
    hind = step.leg.endswith("H")
    for f in again.plan.footsteps[4:]:
        if f.leg.endswith("H") == hind:
            assert np.hypot(f.x - step.x, f.y - step.y) > 0.02 - 1e-9, f
    # A later plan keeps the refusal though its start no longer names it.
    later = band_source.plan(PlanStart(feet=feet, next_leg=2), np.array(GOAL), 30.0)
    for f in later.plan.footsteps[4:]:
        if f.leg.endswith("H") == hind:
            assert np.hypot(f.x - step.x, f.y - step.y) > 0.02 - 1e-9, f


def test_certifies_asks_the_second_planner_where_the_first_has_no_start(
    terrain: Terrain, band_source: PlannerSource
) -> None:
    robot = load_robot("littledog")
    start = PlanStart(feet=_band_stance(), next_leg=2)
    alone = PlannerSource(robot, terrain, expansions=3000, config=planner_config(robot, 0.4, {}))
    assert not alone.certifies(start, np.array(GOAL))
    assert band_source.certifies(start, np.array(GOAL))
