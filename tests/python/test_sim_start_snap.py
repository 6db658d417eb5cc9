"""A start pose whose nominal stance puts a foot on a rock's rim (``executor.start_snap_m``).

Board AE, bench large rocks seeds 2 and 3: the start put RF on a 7.5 cm
rock's rim, which ``footstep.edge_drop`` refuses as a foothold. Refused
outright, the bench moved the whole robot 3 cm at a time until every foot
missed every rim (board Y, sloped rocks seed 1: none of 18 starts did); now
the foot on the rim goes onto the nearest foothold, as a re-plan's feet do.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import roughwalk as rw
from roughwalk import _core
from roughwalk.planning import FootstepConfig
from roughwalk.planning.foothold_safety import steep_footholds
from roughwalk.sim.footstep_source import PlannerSource, PlanStart, planner_config
from roughwalk.terrain import Terrain

pytestmark = pytest.mark.skipif(
    not hasattr(_core, "FootstepPlanner"), reason="the compiled core has no footstep planner"
)
DX = 0.002
POSE = (0.28, 0.24, 0.0)
GOAL = np.array([0.6, 0.24])


def _rock_under_rf() -> Terrain:
    """Flat floor with a 4 cm box rock whose left rim runs 1.7 mm beside RF's nominal place."""
    x = np.arange(0.0, 0.8, DX)
    y = np.arange(0.0, 0.5, DX)
    xx, yy = np.meshgrid(x, y, indexing="ij")
    h = np.where((xx >= 0.33) & (xx <= 0.45) & (yy <= 0.1837), 0.04, 0.0)
    return Terrain(h, x0=0.0, y0=0.0, dx=DX, dy=DX, name="rock")


@pytest.mark.parametrize("snap", [0.0, 0.015])
def test_a_start_foot_on_a_rim_goes_onto_the_nearest_foothold(snap: float) -> None:
    robot = rw.load_robot("littledog")
    rims_refused = FootstepConfig.for_robot(robot, edge_drop=0.03)
    source = PlannerSource(
        robot, _rock_under_rf(), expansions=500, start_snap_m=snap, config=rims_refused
    )
    attempt = source.plan(PlanStart(pose=POSE), GOAL, 30.0)
    if snap == 0.0:
        assert attempt.status == "invalid_input"
        assert "foot RF" in attempt.reason and "not on a foothold" in attempt.reason
        return
    assert attempt.ok, attempt.reason
    stance = {f.leg: np.array([f.x, f.y, f.z]) for f in attempt.plan.footsteps[:4]}
    nominal = source._stance_at(POSE)
    # RF moved off the rim onto the rock's top, at most start_snap_m; the rest stay.
    moved = np.linalg.norm(stance["RF"][:2] - nominal[1, :2])
    assert 0.005 < moved <= snap + 1e-9
    assert stance["RF"][1] < 0.1837 - robot.foot_radius
    assert stance["RF"][2] == pytest.approx(0.04)
    for leg, k in (("LF", 0), ("LH", 2), ("RH", 3)):
        assert np.linalg.norm(stance[leg][:2] - nominal[k, :2]) < 0.004, leg


def test_a_start_foot_on_a_flank_steeper_than_the_start_limit_moves_onto_gentler_ground(
    littledog_board: Callable[[str], Terrain],
) -> None:
    """Board AE, bench large rocks seed 4 (``--expansions 40000``): RF's start on a 41° flank.

    The footstep settings' 45° limit lets RF stand there; no re-plan moved
    it, and the run fell after two reflexes. With ``executor.start_max_slope``
    40° RF goes onto the nearest foothold no steeper than that.
    """
    robot = rw.load_robot("littledog")
    board = littledog_board("AE")
    # Without the walk's 1 cm edge margin, which itself moves this RF off the
    # flank (ground 7 cm below its sole lies within 2 cm of it).
    config = planner_config(robot, 0.4, {"edge_margin": 0.0})
    start = (0.1877222442228947, 0.3047265510562872, 0.047624370570770416)
    goal = np.array([0.459, 0.3045])
    limit = np.radians(40.0)
    steep = steep_footholds(board, robot.foot_radius, limit)

    def stance(max_slope: float) -> dict[str, np.ndarray]:
        source = PlannerSource(
            robot, board, expansions=200, start_max_slope=max_slope, config=config
        )
        attempt = source.plan(PlanStart(pose=start), goal, 60.0)
        assert attempt.ok, attempt.reason
        return {f.leg: np.array([f.x, f.y]) for f in attempt.plan.footsteps[:4]}

    def on_steep(xy: np.ndarray) -> bool:
        i = int(round((xy[0] - board.x0) / board.dx))
        j = int(round((xy[1] - board.y0) / board.dy))
        return bool(steep[i, j])

    before = stance(0.5 * np.pi)
    assert on_steep(before["RF"])  # within the footstep settings' 45°, beyond 40°
    after = stance(float(limit))
    for leg, xy in after.items():
        assert not on_steep(xy), leg
        assert np.linalg.norm(xy - before[leg]) <= 0.015 + 1e-9, leg
    assert np.linalg.norm(after["RF"] - before["RF"]) > 0.0
    assert np.linalg.norm(after["LF"] - before["LF"]) < 1e-9  # a foot on gentle ground stays
