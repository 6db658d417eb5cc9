"""The friction a plan's base motion needs: by hand, and on a plan at its worst sample."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roughwalk.robots import load_robot
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    Task,
    friction_demand,
    melon_config,
    optimize_motion,
    required_friction,
)


def test_required_friction_by_hand() -> None:
    acc = np.array(
        [
            [0.0, 0.0, 0.0],  # standing: no horizontal force
            [3.0, 4.0, 0.0],  # 5 m/s² sideways and forward over g
            [2.0, 0.0, -4.81],  # a dive: 2 over 5
            [1.0, 0.0, -9.81],  # free fall: the feet cannot push sideways at all
            [0.0, 0.0, -12.0],  # faster than free fall: they would have to pull
        ]
    )
    ratio = required_friction(acc)
    assert ratio[:3] == pytest.approx([0.0, 5.0 / 9.81, 0.4])
    assert math.isinf(ratio[3]) and math.isinf(ratio[4])


def test_a_plan_reports_its_worst_sample_and_share() -> None:
    result = optimize_motion(
        load_robot("anymal_c"),
        load_terrain("flat"),
        Task((0.0, 0.0, 0.0), (0.6, 0.0, 0.0)),
        config=melon_config(gait="walk", steps=8, duration=3.0),
        max_iter=0,
    )
    demand = friction_demand(result, friction=0.3, rate_hz=50.0)
    plan = result.sample(50.0)
    assert result.splines is not None
    acc = result.splines.base_linear.evaluate(plan["t"])[2]
    ratio = required_friction(acc)
    standing = plan["contact"].any(axis=1)
    assert demand.max_ratio == pytest.approx(ratio[standing].max())
    assert plan["contact"][int(np.argmin(np.abs(plan["t"] - demand.time_s)))].any()
    assert demand.over_fraction == pytest.approx((ratio[standing] > 0.3).mean())
    assert friction_demand(result).friction == result.body.friction  # the plan's own μ
    assert demand.to_dict()["friction"] == 0.3
