"""Where footsteps start: the first stance's pose when the plan gives none.

A plan without an initial pose gets one whose CoM stands over the four
feet, also on the sloped LittleDog board AD where the fitted pose alone hangs
it 8 cm outside (its first step was handed on invalid).
"""

from __future__ import annotations

import roughwalk as rw
from roughwalk.trajectories import straight_crawl_plan
from roughwalk.trajectories.body_keyframes import keyframe_at, nominal_fit
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator
from roughwalk.trajectories.step_sequence import StepSequence
from roughwalk.trajectories.support_polygon import convex_polygon, polygon_margin


def test_initial_pose_without_certificate_stands_over_the_feet(littledog_board) -> None:
    robot = rw.load_robot("littledog")
    terrain = littledog_board("AD")
    x0, _, y0, y1 = terrain.extent
    gen = FootstepTrajectoryGenerator(robot, terrain)
    plan = straight_crawl_plan(robot, terrain, (x0 + 0.13, 0.5 * (y0 + y1)), steps=2)
    body = plan.to_json() if hasattr(plan, "to_json") else dict(plan)
    body.pop("initial_pose", None)
    seq = StepSequence.from_plan(body, gen.wb, 0.015, terrain=terrain)
    stance = seq.steps[0].stance_before
    polygon = convex_polygon(stance)
    margin = polygon_margin(seq.initial_pose.com[None, :2], polygon)[0][0]
    assert margin >= 0.01
    # The fitted pose that it starts from does not: the board tilts the trunk.
    base, rpy = nominal_fit(gen.wb, stance)
    fitted = keyframe_at(gen.wb, stance, base, rpy)
    assert polygon_margin(fitted.com[None, :2], polygon)[0][0] < 0
