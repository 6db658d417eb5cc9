"""Step timing (Zucker 2011, §5.2), the swing foot spline and the trunk keyframe spline."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import roughwalk as rw
from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.trajectories.body_spline import BodySpline
from roughwalk.trajectories.config import SwingConfig, TimingConfig, TrajectoryConfig
from roughwalk.trajectories.swing_spline import SwingSpline, ramp_profile
from roughwalk.trajectories.timing import StepTiming, min_joint_time, min_profile_time, step_timing


def test_min_joint_time_is_the_slowest_joint() -> None:
    path = np.array([[0.0, 0.0], [0.3, -0.7], [0.6, 0.0]])
    # Joint 0 travels 0.6 rad at 3 rad/s (0.2 s); joint 1 travels 1.4 rad at 14 rad/s (0.1 s).
    assert min_joint_time(path, [3.0, 14.0]) == pytest.approx(0.2)
    assert min_joint_time(path, [3.0, np.inf]) == pytest.approx(0.2)
    with pytest.raises(InvalidArgumentError):
        min_joint_time(path, [3.0])


def test_min_profile_time_scales_the_peak_speed_to_the_limit() -> None:
    s = np.linspace(0.0, 1.0, 101)
    profile = np.stack(
        [np.sin(np.pi * s), 0.5 * s], axis=1
    )  # peak rates π and 0.5 rad per unit time
    t = min_profile_time(profile, [7.5, 14.0])
    assert t == pytest.approx(np.pi / 7.5, rel=1e-3)


def test_step_timing_applies_margins_and_floors() -> None:
    limits = np.full((4, 3), 10.0)
    shift = np.zeros((2, 4, 3))
    shift[1, 0, 1] = 1.0  # 0.1 s at the limit
    swing = np.stack([np.linspace(0, 3.0, 41)] * 3, axis=1)  # 3 rad in unit time: 0.3 s
    cfg = TimingConfig(
        velocity_margin=2.0, swing_velocity_margin=1.5, min_shift_s=0.05, min_swing_s=0.1
    )
    timing = step_timing(shift, swing, limits, cfg, swing_leg=0)
    assert timing.shift_s == pytest.approx(0.2)
    assert timing.swing_s == pytest.approx(0.45)
    slow = step_timing(np.zeros((2, 4, 3)), np.zeros((41, 3)), limits, cfg, 0, settle=True)
    assert (slow.shift_s, slow.swing_s, slow.settle_s) == (0.05, 0.1, cfg.settle_s)
    quantized = StepTiming(0.21, 0.33, 0.0).quantized(0.02)
    assert quantized.samples(0.02) == (11, 17, 0)
    assert StepTiming(0.21, 0.33).scaled(1.3).swing_s == pytest.approx(0.429)
    with pytest.raises(ConfigError, match="velocity_margin"):
        TimingConfig(velocity_margin=0.5)


def test_a_shift_that_moves_the_zmp_less_takes_less_down_to_the_hold() -> None:
    limits = np.full((4, 3), 10.0)
    still = np.zeros((2, 4, 3))
    swing = np.zeros((41, 3))
    cfg = TimingConfig(min_shift_s=0.2, shift_travel_m=0.02, min_hold_s=0.06, velocity_margin=1.6)
    assert cfg.shift_floor(0.03) == pytest.approx(0.2)
    assert cfg.shift_floor(0.01) == pytest.approx(0.1)
    assert cfg.shift_floor(0.0) == pytest.approx(0.06)
    assert step_timing(still, swing, limits, cfg, 0, zmp_travel=0.01).shift_s == pytest.approx(0.1)
    assert step_timing(still, swing, limits, cfg, 0).shift_s == pytest.approx(0.2)
    # The joints' own limit still rules a short travel with a long joint path.
    moving = still.copy()
    moving[1, 0, 1] = 1.0
    assert step_timing(moving, swing, limits, cfg, 0, zmp_travel=0.0).shift_s == pytest.approx(0.16)
    # The shift is timed by its path's peak rate: the same 1 rad, half of it
    # in one tenth of the trunk's path (a leg near the edge of its reach).
    uneven = np.zeros((11, 4, 3))
    uneven[:, 0, 1] = np.r_[np.linspace(0.0, 0.5, 10), 1.0]
    assert step_timing(uneven, swing, limits, cfg, 0, zmp_travel=0.0).shift_s == pytest.approx(
        1.6 * 0.5 * 10 / 10.0
    )
    # Without a travel scale every shift takes min_shift_s.
    assert TimingConfig(min_shift_s=0.2, shift_travel_m=0.0).shift_floor(0.0) == pytest.approx(0.2)
    # The hold never makes a shift longer than min_shift_s.
    assert TimingConfig(min_shift_s=0.05, shift_travel_m=0.02).shift_floor(0.0) == 0.05


def test_a_step_from_rest_keeps_the_first_shift_floor() -> None:
    limits = np.full((4, 3), 10.0)
    still = np.zeros((2, 4, 3))
    swing = np.zeros((41, 3))
    cfg = TimingConfig(min_shift_s=0.1, first_shift_s=0.2)
    assert step_timing(still, swing, limits, cfg, 0).shift_s == pytest.approx(0.1)
    assert step_timing(still, swing, limits, cfg, 0, from_rest=True).shift_s == pytest.approx(0.2)
    # No floor of its own below min_shift_s.
    fast = TimingConfig(min_shift_s=0.2, first_shift_s=0.1)
    assert step_timing(still, swing, limits, fast, 0, from_rest=True).shift_s == pytest.approx(0.2)
    # The generator's first step of a plan is the one from rest.
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain("flat:length=1.2,width=0.5")
    plan = rw.trajectories.straight_crawl_plan(robot, terrain, (0.3, 0.0), steps=3)
    config = rw.trajectories.trajectory_config(
        **{"timing.min_shift_s": 0.1, "timing.first_shift_s": 0.2}
    )
    from roughwalk.trajectories.generator import FootstepTrajectoryGenerator

    gen = FootstepTrajectoryGenerator(robot, terrain, config=config)
    shifts = [t.shift_s for t in gen.nominal_timings(gen.sequence(plan))]
    assert shifts[0] >= 0.2 - 1e-9
    assert min(shifts[1:]) < 0.2 - 1e-9


@settings(max_examples=30, deadline=None)
@given(
    st.floats(-0.02, 0.03),
    st.floats(0.0, 0.12),
    st.floats(-0.03, 0.03),
    st.floats(0.2, 1.0),
    st.floats(0.0, 0.4),
    st.sampled_from(["even", "joint", "knots"]),
)
def test_swing_spline_is_smooth_and_rests_at_both_ends(
    dz: float, stride: float, dy: float, duration: float, lift_fraction: float, law: str
) -> None:
    start = np.array([0.1, 0.05, 0.01])
    target = start + [stride, dy, dz]
    spline = SwingSpline.plan(
        start,
        target,
        duration,
        SwingConfig(lift_height=0.03, lift_fraction=lift_fraction, time_law=law),
    )
    t = np.linspace(0.0, duration, 801)
    pos, vel, acc = spline.evaluate(t)
    np.testing.assert_allclose(pos[0], start, atol=1e-12)
    np.testing.assert_allclose(pos[-1], target, atol=1e-12)
    np.testing.assert_allclose(vel[[0, -1]], 0.0, atol=1e-12)
    np.testing.assert_allclose(acc[[0, -1]], 0.0, atol=1e-9)
    # Passes its lift-off and drop-off points at their times (re-timed: as
    # found by inverting a table of the time law).
    atol = 1e-12 if law == "knots" else 1e-6
    np.testing.assert_allclose(spline.position(spline.times), spline.waypoints, atol=atol)
    # Velocity and acceleration are the derivatives of the path ...
    # (A knot at a sample: the jerk jumps there, so allow h·jerk; the
    # re-timed path turns its corners fast, where h²·jerk matters too.)
    jerk = np.abs(np.diff(acc, axis=0)).max() / (t[1] - t[0])
    h = 1e-6
    inner = t[1:-1]
    p_plus, v_plus, _ = spline.evaluate(inner + h)
    p_minus, v_minus, _ = spline.evaluate(inner - h)
    np.testing.assert_allclose((p_plus - p_minus) / (2 * h), vel[1:-1], atol=1e-6 + h * h * jerk)
    np.testing.assert_allclose(
        (v_plus - v_minus) / (2 * h),
        acc[1:-1],
        atol=1e-4 * max(1.0, np.abs(acc).max()) + 2 * h * jerk,
    )
    # ... and continuous across the waypoints (C²): jumps no bigger than the jerk allows.
    jerk = np.abs(np.diff(acc, axis=0)).max() / (t[1] - t[0])
    for tk in spline.times[1:-1]:
        before = spline.evaluate([tk - 1e-9])
        after = spline.evaluate([tk + 1e-9])
        # The re-timed foot turns a stop (lift_fraction 0) with a jerk finer
        # than the samples see: a jump across ±1 ns must also be 100 times
        # smaller than the one across ±1 µs (a true step would not be).
        wide = zip(spline.evaluate([tk - 1e-6]), spline.evaluate([tk + 1e-6]), strict=True)
        for a, b, (wa, wb) in zip(before, after, wide, strict=True):
            np.testing.assert_allclose(
                a, b, atol=4e-9 * jerk + 1e-12 + 1e-2 * float(np.abs(wb - wa).max())
            )
    # It never swings backward or overshoots sideways, and peaks at the lift height.
    along = (pos[:, :2] - start[:2]) @ (target[:2] - start[:2])
    assert np.all(np.diff(along) >= -1e-12)
    assert pos[:, 2].max() == pytest.approx(max(start[2], target[2]) + 0.03, abs=1e-9)
    assert pos[:, 2].min() >= min(start[2], target[2]) - 1e-12


def test_ramp_profile_starts_and_ends_at_rest_with_the_stated_peak() -> None:
    tau = np.linspace(0.0, 1.0, 20001)
    for ramp in (0.1, 0.2, 0.5):
        phi = ramp_profile(tau, ramp)
        assert phi[0] == 0.0 and phi[-1] == pytest.approx(1.0, abs=1e-12)
        rate = np.gradient(phi, tau)
        assert np.all(np.diff(phi) >= 0)
        assert rate[0] == pytest.approx(0.0, abs=1e-3) and rate[-1] == pytest.approx(0.0, abs=1e-3)
        # Mean rate 1, peak 1 / (1 - ramp), held over the middle.
        assert rate.max() == pytest.approx(1.0 / (1.0 - ramp), rel=1e-3)
        middle = (tau > ramp + 0.01) & (tau < 1 - ramp - 0.01)
        np.testing.assert_allclose(rate[middle], 1.0 / (1.0 - ramp), rtol=1e-3)


def _littledog_swing_time(config: SwingConfig, stride: float) -> float:
    """Least swing time [s] of LittleDog's LF foot over a flat stride, from its IK."""
    robot = rw.load_robot("littledog")
    base = np.array([0.0, 0.0, robot.nominal_stance.base_height])
    feet = robot.nominal_stance.feet + base

    def lf_angles(points: np.ndarray) -> np.ndarray:
        q = []
        for p in points:
            f = feet.copy()
            f[0] = p
            angles, reached = robot.inverse_kinematics(f, base)
            assert reached.all()
            q.append(robot.to_canonical(angles).reshape(4, 3)[0])
        return np.array(q)

    limits = robot.to_canonical(robot.joint_velocity_limit).reshape(4, 3)[0]
    start = feet[0] - [0.5 * stride, 0.0, 0.0]
    spline = SwingSpline.plan(
        start,
        start + [stride, 0.0, 0.0],
        1.0,
        config,
        leg_angles=lf_angles,
        velocity_limit=limits,
    )
    return min_profile_time(lf_angles(spline.position(np.linspace(0.0, 1.0, 401))), limits)


def test_even_time_law_lets_the_velocity_limits_allow_a_shorter_swing() -> None:
    # The same path re-timed to a steady speed: LittleDog's peak joint speeds
    # sit nearer their means, so the least duration (§5.2) drops; with
    # rounder corners (lift_fraction 0.3), by a third or more against knot
    # timing with lift_fraction 0.1 (the defaults until session 4).
    for stride in (0.06, 0.1):
        knots = _littledog_swing_time(SwingConfig(time_law="knots", lift_fraction=0.3), stride)
        even = _littledog_swing_time(SwingConfig(time_law="even", lift_fraction=0.3), stride)
        before = _littledog_swing_time(SwingConfig(time_law="knots", lift_fraction=0.1), stride)
        assert even < 0.8 * knots, (stride, even, knots)
        assert even < 0.67 * before, (stride, even, before)


def test_joint_time_law_keeps_the_limiting_joint_near_its_limit_and_shortens_the_swing() -> None:
    # The "even" law's steady foot speed still leaves LittleDog's hip at ~60 %
    # of its limit on average; timed by the leg's own joint speeds the same
    # path needs about 15 % less time.
    for stride in (0.06, 0.1):
        even = _littledog_swing_time(SwingConfig(time_law="even"), stride)
        joint = _littledog_swing_time(SwingConfig(time_law="joint"), stride)
        assert joint < 0.9 * even, (stride, joint, even)


def test_joint_time_law_without_kinematics_is_the_even_law() -> None:
    start, target = np.array([0.1, 0.05, 0.01]), np.array([0.2, 0.05, 0.02])
    t = np.linspace(0.0, 0.4, 50)
    joint = SwingSpline.plan(start, target, 0.4, SwingConfig(time_law="joint")).position(t)
    even = SwingSpline.plan(start, target, 0.4, SwingConfig(time_law="even")).position(t)
    np.testing.assert_allclose(joint, even, atol=1e-12)


def test_swing_spline_clears_the_terrain_it_scans() -> None:
    terrain = rw.load_terrain("barrier:height=0.06,thickness=0.02,center=1.0")
    start, target = np.array([0.96, 0.0, 0.0103]), np.array([1.05, 0.0, 0.0103])
    cfg = SwingConfig(lift_height=0.01, clearance=0.02, lift_fraction=0.0)
    spline = SwingSpline.plan(start, target, 0.5, cfg, terrain=terrain, foot_radius=0.0103)
    assert spline.waypoints[1, 2] == pytest.approx(0.06 + 0.0103 + 0.02, abs=1e-6)
    pos = spline.position(np.linspace(0, 0.5, 400))
    over = (pos[:, 0] > 0.99 - 0.0103) & (pos[:, 0] < 1.01 + 0.0103)
    assert pos[over, 2].min() > 0.06 + 0.0103


def test_body_spline_holds_and_blends_keyframes() -> None:
    spline = BodySpline([0.0, 0.3, 0.7, 1.0], [[0.0, 1.0], [1.0, 2.0], [1.0, 2.0], [0.0, 0.0]])
    t = np.linspace(-0.1, 1.1, 1201)
    v, d, dd = spline.evaluate(t)
    np.testing.assert_allclose(
        spline.value([0.0, 0.3, 0.5, 0.7, 1.0]), [[0, 1], [1, 2], [1, 2], [1, 2], [0, 0]]
    )
    np.testing.assert_allclose(v[t < 0], [[0.0, 1.0]] * int((t < 0).sum()))
    h = 1e-6
    plus, minus = spline.evaluate(t + h), spline.evaluate(t - h)
    np.testing.assert_allclose((plus[0] - minus[0]) / (2 * h), d, atol=1e-6)
    np.testing.assert_allclose((plus[1] - minus[1]) / (2 * h), dd, atol=3e-3)  # C², not C³
    # At rest at every keyframe.
    np.testing.assert_allclose(spline.evaluate([0.3, 0.7])[1], 0.0, atol=1e-12)
    with pytest.raises(InvalidArgumentError):
        BodySpline([0.0, 0.0], [[0.0], [1.0]])


def test_config_refuses_nonsense() -> None:
    with pytest.raises(ConfigError, match="chomp.smoothness_order"):
        rw.trajectories.trajectory_config(**{"chomp.smoothness_order": 3})
    with pytest.raises(ConfigError, match="unknown config field"):
        rw.trajectories.trajectory_config(**{"chomp.nonsense": 3})
    cfg = rw.trajectories.trajectory_config(
        chomp={"max_iterations": 7}, **{"zmp.shortcut": "false"}
    )
    assert cfg.chomp.max_iterations == 7 and cfg.zmp.shortcut is False
    assert isinstance(cfg, TrajectoryConfig)


def test_joint_time_law_does_not_dash_where_the_leg_misses_its_path() -> None:
    # A downhill swing planned at the swing pose, whose leg does not reach the
    # target 3 cm down (LittleDog board AC): the clamped IK stops there, its
    # rate reads zero, and the law dashed through the drop, which the trunk,
    # lowered by the time the foot lands, follows at joint speeds 21 % over
    # the "even" law's. With the leg's FK the law sees the miss and is "even";
    # where the leg reaches its path, FK changes nothing.
    from roughwalk.trajectories.body_keyframes import keyframe_at
    from roughwalk.trajectories.whole_body import WholeBody

    robot = rw.load_robot("littledog")
    wb = WholeBody(robot)
    leg, stride, drop = 0, 0.08, 0.03
    feet = robot.nominal_stance.feet.copy()
    feet[:, 2] = robot.foot_radius
    feet[leg, 0] -= stride / 2
    base = np.array([0.0, 0.0, robot.nominal_stance.base_height])
    high = keyframe_at(wb, feet, base, np.zeros(3))
    low = keyframe_at(wb, feet, base - [0.0, 0.0, drop], np.zeros(3))
    start = feet[leg].copy()
    target = start + [stride, 0.0, -drop]
    limit = wb.velocity_limit[leg]

    def least_time(law: str, pose, landed) -> float:
        spline = SwingSpline.plan(
            start,
            target,
            1.0,
            SwingConfig(time_law=law, ramp_fraction=0.1),
            leg_angles=pose.leg_angles(wb, leg),
            velocity_limit=limit,
            leg_feet=pose.leg_feet(wb, leg),
        )
        return spline.least_time(landed.leg_angles(wb, leg), limit)

    missed = high.leg_feet(wb, leg)(high.leg_angles(wb, leg)(target[None]))[0]
    assert np.linalg.norm(missed - target) > 0.01
    assert least_time("joint", high, low) <= 1.01 * least_time("even", high, low)
    assert least_time("joint", low, low) < 0.9 * least_time("even", low, low)
