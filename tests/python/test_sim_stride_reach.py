"""The stride a leg reaches, and the planner's travel cap that longer steps get from it."""

from __future__ import annotations

import numpy as np
import pytest

import roughwalk as rw
from roughwalk.planning.footstep_config import FootstepConfig, hip_to_hip_length
from roughwalk.sim.stride_reach import (
    STRIDE_PER_ACTION,
    STRIDE_REACH_SHARE,
    longer_step_config,
    stride_reach,
)


def reaches(robot: rw.Robot, leg: int, dx: float) -> bool:
    stance = robot.nominal_stance
    base = np.array([0.0, 0.0, stance.base_height])
    feet = np.asarray(stance.feet) + base
    feet[leg, 0] += dx
    _, ok = robot.inverse_kinematics(feet, base, (1.0, 0.0, 0.0, 0.0))
    return bool(np.asarray(ok).reshape(-1)[leg])


def test_the_stride_reach_is_the_span_a_foot_reaches_under_its_hip(littledog) -> None:
    span = stride_reach(littledog)
    # LittleDog's feet reach ~7.5 cm behind and ~8.5 cm ahead of their nominal places.
    assert 0.14 < span < 0.17
    # No leg reaches both ends of a span 1 cm longer, centred anywhere on its nominal place.
    for leg in range(4):
        ends = [
            (lo, lo + span + 0.01)
            for lo in np.arange(-0.12, 0.0, 0.002)
            if reaches(littledog, leg, lo) and reaches(littledog, leg, lo + span + 0.01)
        ]
        assert not ends


def test_longer_steps_raise_the_travel_cap_up_to_the_reach(littledog) -> None:
    length = hip_to_hip_length(littledog)
    default = FootstepConfig.for_robot(littledog)
    assert longer_step_config(littledog, 0.3) == default
    # Longer actions raise the cap to the reach's share, past the steady stride they make.
    cap = STRIDE_REACH_SHARE * stride_reach(littledog)
    longer = longer_step_config(littledog, 0.4)
    assert longer.max_foot_travel == pytest.approx(cap)
    assert longer.max_foot_travel > STRIDE_PER_ACTION * 0.4 * length
    assert max(a[0] for a in longer.actions) == pytest.approx(0.4 * length)
    too_long = longer_step_config(littledog, 0.6)
    assert too_long.max_foot_travel == pytest.approx(cap)
    assert too_long.max_foot_travel < STRIDE_PER_ACTION * 0.6 * length
