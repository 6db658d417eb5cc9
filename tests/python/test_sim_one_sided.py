"""The one-sided reflex: a side planned down that carries nothing while the trunk rolls off it."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from _sim_states import standing_step

import roughwalk
from roughwalk import _core
from roughwalk.sim import run
from roughwalk.sim.config import ReflexConfig
from roughwalk.sim.footstep_source import PlannerSource
from roughwalk.sim.reflexes import ReflexMonitor, tipping_off

DT = 0.002
HAVE_PLANNER = hasattr(_core, "FootstepPlanner")

# Four feet at a LittleDog-sized stance (LF, RF, LH, RH), x forward, y left.
FEET = np.array([[0.1, 0.05, 0.0], [0.1, -0.05, 0.0], [-0.1, 0.05, 0.0], [-0.1, -0.05, 0.0]])
ALL_DOWN = np.ones(4, dtype=bool)
RIGHT_LOADED = np.array([False, True, False, True])
# Positive roll (about +x) lifts the left side.
ROLLING_RIGHT = np.array([0.34, 0.0, 0.0])


def test_the_trunk_rolling_over_the_loaded_right_feet_lifts_the_left_ones() -> None:
    rate, leg = tipping_off(ALL_DOWN, RIGHT_LOADED, FEET, ROLLING_RIGHT)
    assert rate == pytest.approx(0.34)
    assert leg in (0, 2)  # a left foot
    # Rolling back onto the left feet: they come down, a negative rate.
    rate, _ = tipping_off(ALL_DOWN, RIGHT_LOADED, FEET, -ROLLING_RIGHT)
    assert rate == pytest.approx(-0.34)
    # A pitch does not roll the robot over its right side.
    rate, _ = tipping_off(ALL_DOWN, RIGHT_LOADED, FEET, np.array([0.0, 0.5, 0.0]))
    assert rate == pytest.approx(0.0, abs=1e-12)


def test_a_robot_on_a_diagonal_is_not_watched() -> None:
    # RF and LH loaded, LF lifted for its swing, RH planned down: the crawl's
    # ordinary stance, which the three-foot foot-force check judges.
    three_down = np.array([False, True, True, True])
    diagonal = np.array([False, True, True, False])
    assert tipping_off(three_down, diagonal, FEET, np.array([-0.3, -0.3, 0.0])) == (0.0, None)


def test_feet_loaded_on_both_sides_or_none_loaded_is_not_one_sided() -> None:
    three = np.array([True, True, False, True])
    assert tipping_off(ALL_DOWN, three, FEET, ROLLING_RIGHT) == (0.0, None)
    assert tipping_off(ALL_DOWN, np.zeros(4, dtype=bool), FEET, ROLLING_RIGHT) == (0.0, None)
    # The left feet are not planned down (nothing to lift): no state either.
    right_down = np.array([False, True, False, True])
    assert tipping_off(right_down, RIGHT_LOADED, FEET, ROLLING_RIGHT) == (0.0, None)


def pushed_right(desired: object, t: float) -> object:
    """The measured state of the 1 N·s right push at 1.8 s, 2.146 s in (``bench_push_recovery``).

    LF has just landed, all four feet are planned down, RF and RH bear
    17.7 and 10.6 N, LF and LH nothing, and the trunk rolls right at 0.34
    rad/s, still nearly level (0.7°) and where planned.
    """
    forces = np.zeros((4, 3))
    forces[:, 2] = [0.0, 17.7, 0.0, 10.6]
    return SimpleNamespace(
        time=t,
        base_pos=np.array(desired.base_pos, dtype=float),
        base_quat=np.array(desired.base_quat, dtype=float),
        base_angvel=ROLLING_RIGHT,
        com=np.array(desired.base_pos, dtype=float),
        feet=np.array(desired.feet, dtype=float),
        foot_forces=forces,
    )


def ticks_until_reflex(monitor: ReflexMonitor, desired: object, n: int = 50) -> object:
    for k in range(n):
        trigger = monitor.check(desired, pushed_right(desired, 1.0 + k * DT))
        if trigger is not None:
            return trigger
    return None


def test_a_side_carrying_nothing_with_four_feet_down_fires_the_one_sided_reflex() -> None:
    desired = standing_step(roughwalk.load_robot("littledog"))
    # By default (as before the check) 0.1 s of it fires nothing: with four
    # feet planned down the foot-force check does not judge loads, and the
    # trunk is still level.
    assert ticks_until_reflex(ReflexMonitor(ReflexConfig()), desired) is None
    trigger = ticks_until_reflex(ReflexMonitor(ReflexConfig(one_sided=True)), desired)
    assert trigger is not None and trigger.kind == "one_sided"
    assert trigger.leg in ("LF", "LH")
    assert trigger.time == pytest.approx(1.0 + ReflexConfig().one_sided_persist_s)
    assert trigger.value == pytest.approx(0.34, rel=1e-3)


@pytest.mark.skipif(not HAVE_PLANNER, reason="the compiled core has no FootstepPlanner")
@pytest.mark.parametrize("terrain", ["flat", "large_rocks:seed=1,max_height=0.05"])
def test_a_walk_undisturbed_with_the_check_on_fires_no_reflex(littledog, terrain: str) -> None:
    ground = roughwalk.load_terrain(terrain)
    result = run(
        littledog,
        ground,
        (0.25, 0.0, 0.0),
        (0.75, 0.0),
        planner=PlannerSource(littledog, ground, expansions=2000),
        **{"executor.compute_time_scale": 0.0, "reflex.one_sided": True},
    )
    assert result.outcome.success, result.outcome.reason
    assert not [e for e in result.log.events if e["kind"] == "reflex"]
