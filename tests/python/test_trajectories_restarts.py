"""Work the generator no longer wastes: restarts and iterations that cannot help.

A swing that outruns a joint's velocity limit is lengthened before CHOMP by
the measured excess (the nominal timing is made deliberately too short here;
the restart of §5.3 came only after CHOMP's whole budget); a velocity "jump"
that no longer step can fix is not restarted; and the swing pass hands back
to the trunk pass once its own leg is feasible.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from _even_swings import EVEN_SWINGS
from _trajectory_plans import BARRIER, barrier_step_plan

import roughwalk as rw
from roughwalk.trajectories import straight_crawl_plan
from roughwalk.trajectories.footstep_trajectory import (
    resample_footstep,
    swing_leg_angles,
    swing_speed_ratio,
)
from roughwalk.trajectories.generator import RETIME_MARGIN, FootstepTrajectoryGenerator


@pytest.fixture(scope="module")
def crawl(littledog: rw.Robot):
    terrain = rw.load_terrain("flat:length=1.2,width=0.5")
    config = rw.trajectories.trajectory_config(**EVEN_SWINGS)
    gen = FootstepTrajectoryGenerator(littledog, terrain, config=config)
    plan = straight_crawl_plan(littledog, terrain, (0.3, 0.0), steps=4, stride=0.07)
    return gen, gen.prepare(plan)


def _hurried(prepared, factor: float):
    """The same plan with every step's nominal swing shortened by ``factor``.

    Only the swings, which these tests are about: hurried too, the 0.1 s
    side-changing shifts (the default since session 10) move the ZMP so
    fast that a hurried 0.18 s swing before one left the support polygon
    and was restarted for that.
    """
    return dataclasses.replace(
        prepared,
        timings=[
            dataclasses.replace(t, swing_s=t.swing_s * factor).quantized(0.02)
            for t in prepared.timings
        ],
    )


def _swing_leg_speed(traj, littledog: rw.Robot, leg: int, limit: np.ndarray) -> np.ndarray:
    """|q̇| / limit (n, 3) of the swing leg in a produced trajectory."""
    qd = littledog.to_canonical(traj.qd).reshape(-1, 4, 3)[:, leg]
    return np.abs(qd) / limit


def test_swing_speed_ratio_predicts_the_control_rate_check(crawl, littledog: rw.Robot) -> None:
    """The ratio is what resample_footstep's q̇ shows on the airborne swing leg."""
    gen, prepared = crawl
    cfg = gen.config
    for factor in (1.0, 0.6):
        state = gen.initial_state(_hurried(prepared, factor), 1, prepared.start)
        ratio = swing_speed_ratio(state, gen.wb, cfg.control_rate_hz)
        traj = resample_footstep(
            state,
            gen.wb,
            gen.sdf,
            cfg,
            optimize_ms=0.0,
            attempts=1,
            iterations=0,
            initial_min_clearance=0.0,
        )
        leg = state.step.leg
        airborne = ~traj.support[:, leg]
        # The produced swing leg is exactly the spline the ratio differentiates.
        q = littledog.to_canonical(traj.q).reshape(-1, 4, 3)[airborne, leg]
        np.testing.assert_allclose(q, swing_leg_angles(state, gen.wb, traj.time[airborne]))
        speed = _swing_leg_speed(traj, littledog, leg, gen.wb.velocity_limit[leg])[airborne]
        # Away from lift-off and touchdown the differences are the same ones.
        assert np.max(speed[1:-1]) <= ratio + 1e-12
        assert ratio == pytest.approx(np.max(speed), rel=0.05)


def test_a_hurried_swing_is_lengthened_before_chomp(crawl, littledog: rw.Robot) -> None:
    """Timings 60 % too short: every step is stretched at once and keeps the limits.

    (The swings here sit at their 0.2 s floor, ``timing.min_swing_s``, and
    reach 0.89 of the velocity limits; 60 % shorter, 2.5 times them.)
    """
    gen, prepared = crawl
    hurried = _hurried(prepared, 0.4)
    rate = gen.config.control_rate_hz
    ratio = swing_speed_ratio(gen.initial_state(hurried, 0, prepared.start), gen.wb, rate)
    assert ratio > 1.05, "the test needs a first step that breaks the limit"
    for k, traj in enumerate(gen.iter_steps(hurried)):
        r = traj.report
        assert r.velocity_limits_ok, f"step {k + 1}: {r.notes}"
        assert r.attempts == 1, f"step {k + 1} restarted: {r.notes}"
        assert traj.report.duration_s >= hurried.timings[k].duration_s - 1e-9
    first = next(iter(gen.iter_steps(hurried)))
    nominal = hurried.timings[0]
    # Stretched by about the excess (times the margin), not by a whole restart factor.
    # Measured on the swing: the shift's floor for its ZMP travel
    # (timing.shift_travel_m) is put back whatever the stretch.
    stretch = first.report.swing_s / nominal.swing_s
    assert 1.0 < stretch <= ratio * RETIME_MARGIN * 1.1 + 0.05


def test_the_report_names_the_stretch_beyond_the_fitted_timing(littledog: rw.Robot) -> None:
    """Hurried swings kept as fitted (no measured timing): the report says how much they grew.

    What a run's time breakdown counts as stretch (:mod:`roughwalk.sim.time_breakdown`).
    """
    terrain = rw.load_terrain("flat:length=1.2,width=0.5")
    config = rw.trajectories.trajectory_config(**{"timing.measured_speed": 0.0})
    gen = FootstepTrajectoryGenerator(littledog, terrain, config=config)
    plan = straight_crawl_plan(littledog, terrain, (0.3, 0.0), steps=4, stride=0.07)
    hurried = _hurried(gen.prepare(plan), 0.4)
    first = next(iter(gen.iter_steps(hurried)))
    r = first.report
    assert r.fitted_swing_s == pytest.approx(hurried.timings[0].swing_s)
    assert r.fitted_shift_s == pytest.approx(hurried.timings[0].shift_s)
    assert r.swing_s > 1.5 * r.fitted_swing_s
    assert r.stretch_s[1] == pytest.approx(r.swing_s - r.fitted_swing_s)
    assert r.stretch_s[0] == pytest.approx(max(r.shift_s - r.fitted_shift_s, 0.0))


def test_steps_within_the_limits_are_not_stretched(littledog: rw.Robot) -> None:
    """The barrier step at its nominal timing already keeps the limits: its duration stays."""
    terrain = rw.load_terrain(BARRIER)
    gen = FootstepTrajectoryGenerator(littledog, terrain)
    prepared = gen.prepare(barrier_step_plan(littledog, terrain, gen.wb))
    state = gen.initial_state(prepared, 0, prepared.start)
    assert swing_speed_ratio(state, gen.wb, gen.config.control_rate_hz) <= 1.0
    traj = next(iter(gen.iter_steps(prepared)))
    assert traj.report.duration_s == pytest.approx(prepared.timings[0].duration_s)
    assert traj.report.stretch_s == (0.0, 0.0)
    assert traj.report.fitted_swing_s == pytest.approx(traj.report.swing_s)


def test_a_velocity_jump_is_not_restarted(crawl, littledog: rw.Robot) -> None:
    """A joint 'speed' no lengthening can bring under its limit is handed on, not restarted.

    Such jumps come from IK switching branch where a supporting foot is lost
    (the LittleDog AD crawl fall-back's first step: 100–250 rad/s); a mild
    excess is still worth the longer step of §5.3.
    """
    gen, prepared = crawl
    traj = next(iter(gen.iter_steps(prepared)))
    limit = littledog.from_canonical(gen.wb.velocity_limit.reshape(12))

    def breaking(factor: float):
        qd = traj.qd.copy()
        qd[len(qd) // 2, 4] = factor * limit[4]
        report = dataclasses.replace(
            traj.report,
            valid=False,
            velocity_limits_ok=False,
            velocity_margin_rad_s=float(np.min(limit - np.abs(qd))),
            chomp_status="converged",
            used_shortcut=False,
        )
        return dataclasses.replace(traj, qd=qd, report=report)

    longest = 1.3**2
    assert gen._worth_restarting(breaking(1.1), None, False, longest)
    assert not gen._worth_restarting(breaking(20.0), None, False, longest)
    # A collision is still worth a longer step whatever the speeds.
    colliding = breaking(20.0)
    colliding = dataclasses.replace(
        colliding, report=dataclasses.replace(colliding.report, collision_free=False)
    )
    assert gen._worth_restarting(colliding, None, False, longest)


def test_the_swing_pass_stops_when_its_leg_is_clear_though_the_rest_is_not(
    littledog: rw.Robot,
) -> None:
    """Coordinate descent hands back to the trunk once the swing leg is done.

    The Figure-8 barrier step with a supporting foot moved out of reach at the
    last sample (which CHOMP cannot move): the step can never be valid. The
    swing pass must still clear the barrier, then stop, instead of running
    out the whole iteration budget on a leg that is already feasible.
    """
    from _trajectory_plans import low_swing_config

    from roughwalk.trajectories.chomp import ChompStatus
    from roughwalk.trajectories.step_report import capsule_clearances

    terrain = rw.load_terrain(BARRIER)
    cfg = rw.trajectories.trajectory_config(**low_swing_config())
    gen = FootstepTrajectoryGenerator(littledog, terrain, config=cfg)
    prepared = gen.prepare(barrier_step_plan(littledog, terrain, gen.wb))
    state = gen.initial_state(prepared, 0, prepared.start)
    leg = state.step.leg
    other = (leg + 1) % 4
    state.feet[-1, other, 2] -= 0.1
    state.solve_legs(gen.wb)
    assert not state.reached[-1, other]
    swing_links = (gen.wb.collision.leg == leg) & ~gen.wb.collision.is_foot
    before = capsule_clearances(gen.wb, gen.sdf, state.q, state.body[:, :3], state.rotation)
    assert before[:, swing_links].min() < 0, "the blind swing must hit the barrier"

    outcome = gen.optimize(state)

    assert outcome.status != ChompStatus.VALID
    after = capsule_clearances(gen.wb, gen.sdf, state.q, state.body[:, :3], state.rotation)
    assert after[:, swing_links].min() >= cfg.validity.min_clearance - 1e-9
    assert outcome.iterations < cfg.chomp.max_iterations


def test_without_stretch_shift_only_the_swing_is_lengthened(littledog: rw.Robot) -> None:
    """``timing.stretch_shift`` off: the hurried swings grow as before, their shifts do not.

    The re-timing measures only the swing leg in the air, so the shift's share
    of the stretch is time no limit asked for; the steps stay valid (the ZMP
    inside the support polygon, the joints within their limits, no collision).
    """
    terrain = rw.load_terrain("flat:length=1.2,width=0.5")
    plan = straight_crawl_plan(littledog, terrain, (0.3, 0.0), steps=4, stride=0.07)
    shifts = {}
    for stretch_shift in (True, False):
        config = rw.trajectories.trajectory_config(
            **EVEN_SWINGS, **{"timing.measured_speed": 0.0, "timing.stretch_shift": stretch_shift}
        )
        gen = FootstepTrajectoryGenerator(littledog, terrain, config=config)
        hurried = _hurried(gen.prepare(plan), 0.4)
        steps = list(gen.iter_steps(hurried))
        for traj in steps:
            r = traj.report
            assert r.valid and r.velocity_limits_ok, f"step {r.step}: {r.notes}"
            assert r.swing_s > 1.5 * r.fitted_swing_s
        shifts[stretch_shift] = np.array([t.report.shift_s for t in steps])
        if not stretch_shift:
            fitted = np.array([t.report.fitted_shift_s for t in steps])
            # At most the shift's floor for its ZMP travel is put back.
            assert np.all(shifts[False] <= np.maximum(fitted, gen.config.timing.min_shift_s) + 1e-9)
    assert np.all(shifts[False] <= shifts[True] + 1e-9)
    assert shifts[False].sum() < shifts[True].sum() - 0.05
