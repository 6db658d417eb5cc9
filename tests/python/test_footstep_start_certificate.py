"""A re-plan's start certificate searched from the measured trunk (issue 7).

The stance is the one LittleDog stood on after its first reflex on board Y
(``bench_littledog.py --expansions 40000``, sloped rocks seed 1, t = 1.90 s):
the RF foot had slid down a rock face and its shin rested 3.6 mm from the
rock, as the distance field reads it, and RH stood on a rock's edge. A
certificate needs 8.4 mm (``certificate.clearance`` plus the field's error
bound), so no start from these feet existed, and the run fell from the
stance a nudged start made it reach for.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import roughwalk as rw
from roughwalk.planning import FootstepConfig, FootstepPlanner
from roughwalk.terrain import Terrain

# Foot-sphere centres [m], canonical legs (LF, RF, LH, RH), and the trunk's
# position [m] and quaternion (w, x, y, z), as measured in MuJoCo.
FEET = np.array(
    [
        [0.29131, 0.32353, 0.05596],
        [0.29909, 0.20610, 0.02987],
        [0.12690, 0.31591, 0.05412],
        [0.09951, 0.22415, 0.06283],
    ]
)
TRUNK_POS = np.array([0.21034, 0.27209, 0.20705])
TRUNK_QUAT = np.array([0.99743, 0.03758, 0.05295, -0.03023])
GOAL = (0.40, 0.30)


@pytest.fixture(scope="module")
def board_y(littledog_board: Callable[[str], Terrain]) -> Terrain:
    return littledog_board("Y")


@pytest.fixture(scope="module")
def planner(littledog: rw.Robot, board_y: Terrain) -> FootstepPlanner:
    return FootstepPlanner(littledog, board_y)


def test_a_stance_settled_on_a_rock_face_starts_a_plan_from_the_measured_trunk(
    planner: FootstepPlanner,
) -> None:
    cert = planner.config.certificate
    trunk = (TRUNK_POS, TRUNK_QUAT)
    # Without the trunk, no leg can start from these feet.
    for leg in ("LF", "RF"):
        refused = planner.replan(FEET, next_leg=leg, goal=GOAL, time_limit=None, expansions=10)
        assert refused.status == "invalid_input", leg
        assert "no pose certificate" in (refused.reason or "")
    # With it, the start is certified; LF (due to lift) cannot step while the
    # RF shin stays against the rock, RF can.
    blocked = planner.replan(FEET, "LF", GOAL, time_limit=None, expansions=3000, trunk=trunk)
    assert blocked.status == "infeasible", blocked.reason
    plan = planner.replan(FEET, "RF", GOAL, time_limit=None, expansions=3000, trunk=trunk)
    assert plan.status == "solved", plan.reason
    assert plan.footsteps[4].leg == "RF"
    start = plan.initial_pose
    assert start is not None
    # The start keeps the body off the rock, but nearer than a planned stance may.
    assert cert.start_clearance - planner.sdf_error <= start.clearance < cert.clearance
    assert start.com_margin >= cert.com_margin
    # ... in a pose next to the one the robot stands in.
    assert np.linalg.norm(start.base_pos - TRUNK_POS) < 0.02
    # Every stance the plan reaches keeps the full clearance.
    assert len(plan.certificates) == len(plan.footsteps) - 4
    assert min(c.clearance for c in plan.certificates) >= cert.clearance


def test_a_measured_trunk_does_not_certify_an_unreachable_or_buried_stance(
    littledog: rw.Robot, board_y: Terrain, planner: FootstepPlanner
) -> None:
    trunk = (TRUNK_POS, TRUNK_QUAT)
    # LF 25 cm ahead and 6 cm out of where it stands: out of reach from any
    # trunk pose the search reaches from the measured one.
    far = FEET.copy()
    far[0, :2] += (0.25, 0.06)
    plan = planner.replan(far, "RF", GOAL, time_limit=None, expansions=10, trunk=trunk)
    assert plan.status == "invalid_input"
    assert "out of reach" in (plan.reason or "")
    # The body must still not be in the rock: asking the start what a planned
    # stance needs refuses these feet, trunk or not.
    full = planner.config.certificate.clearance + planner.sdf_error
    strict = FootstepPlanner(
        littledog,
        board_y,
        FootstepConfig.for_robot(littledog, certificate_start_clearance=full),
        sdf=planner.sdf,
    )
    plan = strict.replan(FEET, "RF", GOAL, time_limit=None, expansions=10, trunk=trunk)
    assert plan.status == "invalid_input"
    assert "kept clear of the terrain" in (plan.reason or "")
