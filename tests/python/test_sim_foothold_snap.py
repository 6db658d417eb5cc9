"""Re-plan starts: a measured foot just off the planner's footholds is moved onto the nearest."""

from __future__ import annotations

import numpy as np
import pytest

import roughwalk as rw
from roughwalk.planning.footstep_planner import FootstepPlanner
from roughwalk.sim.foothold_snap import snap_to_footholds


@pytest.fixture(scope="module")
def planner() -> tuple[rw.Robot, rw.Terrain, FootstepPlanner]:
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain("flat")
    return robot, terrain, FootstepPlanner(robot, terrain)


def stance_at(robot: rw.Robot, x: float, y: float) -> np.ndarray:
    nominal = robot.nominal_stance.feet
    feet = nominal - nominal.mean(axis=0)
    feet[:, 0] += x
    feet[:, 1] += y
    feet[:, 2] = 0.0
    return feet


def test_a_foot_off_the_foothold_border_is_snapped_and_the_replan_starts(planner) -> None:
    robot, terrain, fp = planner
    x0, y0, h, nx, ny = fp.lattice
    # The cost maps leave no footholds near the terrain's edge (their feature
    # radius): find the first foothold column along x at the middle row.
    j = ny // 2
    xs = x0 + h * np.arange(nx)
    front = np.isfinite(np.asarray(fp.cost_front).reshape(terrain.shape))
    assert not front.all(), "the test needs a terrain edge without footholds"
    feet = stance_at(robot, 0.0, y0 + h * j)
    hind_x = float(feet[2:, 0].min() - feet[:, 0].mean())
    goal = (0.5 * (terrain.extent[0] + terrain.extent[1]), y0 + h * j)
    # Shift the stance back until its hind feet stand a cell or two past the border.
    for x in xs:
        trial = stance_at(robot, x - hind_x, y0 + h * j)
        result = fp.replan(trial, "LF", goal=goal, time_limit=0.5)
        if result.start_off_foothold is None:
            border = x
            break
    else:
        pytest.fail("no stance on footholds along the middle row")
    off = stance_at(robot, border - hind_x - 1.5 * h, y0 + h * j)
    refused = fp.replan(off, "LF", goal=goal, time_limit=0.5)
    assert "not on a foothold" in (refused.reason or "")
    assert refused.start_off_foothold in ("LH", "RH")
    snapped, moved = snap_to_footholds(fp, terrain, off, radius=0.02)
    assert moved and set(moved) <= {2, 3}
    shift = np.linalg.norm((snapped - off)[:, :2], axis=1)
    assert np.all(shift <= 0.02 + 1e-12) and np.all(shift[[0, 1]] == 0.0)
    np.testing.assert_array_equal(snapped[:, 2], off[:, 2])
    accepted = fp.replan(snapped, "LF", goal=goal, time_limit=0.5)
    assert accepted.start_off_foothold is None
    assert "not on a foothold" not in (accepted.reason or "")
    # Feet already on footholds stay exactly where they are; too far, they stay too.
    same, none = snap_to_footholds(fp, terrain, snapped, radius=0.02)
    assert none == [] and np.array_equal(same, snapped)
    far = stance_at(robot, border - hind_x - 0.05, y0 + h * j)
    kept, moved_far = snap_to_footholds(fp, terrain, far, radius=0.01)
    assert moved_far == [] and np.array_equal(kept, far)
