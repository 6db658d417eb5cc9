"""A recovery that settles at the goal ends the run (``reflex.end_at_goal``; issue 7).

On board AE (bench large rocks seed 5) a reflex fired 0.1 s before the
feet's centroid reached the goal; the run re-planned from there, walked on,
and failed at the next re-plan, though the robot had reached the goal.
"""

from __future__ import annotations

import pytest

from roughwalk.sim import Push, run


@pytest.mark.parametrize("end_at_goal", [True, False])
def test_a_recovery_settled_at_the_goal_ends_the_run_instead_of_re_planning(
    end_at_goal: bool,
) -> None:
    # The goal is 7 cm ahead and 10 cm wide: reached at the first motion;
    # the 1 N·s side push 0.3 s later fires a reflex, whose recovery settles
    # with the feet still inside the goal radius.
    result = run(
        "littledog",
        "flat",
        (0.2, 0.0, 0.0),
        (0.27, 0.0),
        planner="crawl",
        disturbances=[Push(1.0, at_s=0.3)],
        **{
            "reflex.end_at_goal": end_at_goal,
            "executor.compute_time_scale": 0,
            "outcome.goal_radius_m": 0.1,
            "outcome.time_limit_s": 8.0,
        },
    )
    kinds = [e["kind"] for e in result.log.events]
    assert result.outcome.success
    assert result.outcome.reflexes == 1
    assert kinds.index("goal") < kinds.index("reflex")
    if end_at_goal:
        assert result.outcome.replans == 0
        assert kinds[-2:] == ["settled_at_goal", "end"]
    else:
        assert result.outcome.replans == 1
        assert "settled_at_goal" not in kinds
