"""timing.measured_speed: each footstep's phases are timed by its joints' measured peak speeds."""

from __future__ import annotations

import numpy as np
import pytest

import roughwalk as rw
from roughwalk.trajectories import straight_crawl_plan
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator

TARGET = 0.9
# The "even" swing law: with the "joint" law the fitted 9 cm crawl's last step
# (RF) ends invalid, a supporting foot out of reach at a fixed sample.
SETTINGS = {"timing.min_swing_s": 0.2, "swing.time_law": "even", "swing.ramp_fraction": 0.2}


@pytest.fixture(scope="module")
def crawl() -> tuple[rw.Robot, rw.Terrain, object, dict]:
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain("flat")
    sdf = terrain.sdf(0.005)
    # A 9 cm crawl is valid throughout (a 10 cm one's last step is not, see TimingConfig).
    plan = straight_crawl_plan(robot, terrain, (0.0, 0.0), steps=8, stride=0.09)
    return robot, terrain, sdf, plan


def generated(crawl, **settings) -> tuple[FootstepTrajectoryGenerator, list]:
    robot, terrain, sdf, plan = crawl
    config = rw.trajectories.trajectory_config(**{**SETTINGS, **settings})
    gen = FootstepTrajectoryGenerator(robot, terrain, sdf=sdf, config=config)
    return gen, list(gen.iter_steps(gen.prepare(plan)))


def swing_peaks(gen: FootstepTrajectoryGenerator, steps: list) -> np.ndarray:
    """Each step's peak |q̇| / limit over every joint while its foot is in the air."""
    limit = gen.wb.velocity_limit.reshape(12)
    out = []
    for step in steps:
        qd = gen.robot.to_canonical(step.qd).reshape(-1, 12)
        out.append(float(np.max(np.abs(qd[step.phase == 1]) / limit)))
    return np.array(out)


def test_measured_timing_runs_the_swings_near_the_target_share_of_the_limits(crawl) -> None:
    gen, steps = generated(crawl, **{"timing.measured_speed": TARGET})
    peaks = swing_peaks(gen, steps)
    floored = np.array([s.report.swing_s <= gen.config.timing.min_swing_s + 1e-9 for s in steps])
    for step in steps:
        assert step.report.valid, step.report.notes
    # Every swing not at its floor is timed so its fastest joint runs close
    # to the target (the nominal estimate leaves 10-30 % of the limits unused).
    assert np.all(peaks[~floored] > TARGET - 0.08), peaks
    assert np.all(peaks <= 1.0), peaks


def test_measured_timing_walks_the_crawl_faster_than_the_nominal_estimate(crawl) -> None:
    _, nominal = generated(crawl, **{"timing.measured_speed": 0.0})
    gen, fitted = generated(crawl, **{"timing.measured_speed": TARGET})
    before = sum(s.report.duration_s for s in nominal)
    after = sum(s.report.duration_s for s in fitted)
    assert after < 0.92 * before, (before, after)
    # Never longer, step by step: the fit only shortens the nominal timing.
    for a, b in zip(fitted, nominal, strict=True):
        assert a.report.swing_s <= b.report.swing_s + 1e-9
        assert a.report.shift_s <= b.report.shift_s + 1e-9
    # The shift floors hold: the first step from rest, every hold.
    timing = gen.config.timing
    assert fitted[0].report.shift_s >= timing.first_shift_s - 1e-9
    assert min(s.report.shift_s for s in fitted) >= timing.min_hold_s - 1e-9


def test_the_preview_plans_with_the_fitted_timings_of_the_steps_ahead(crawl) -> None:
    robot, terrain, sdf, plan = crawl
    config = rw.trajectories.trajectory_config(**{**SETTINGS, "timing.measured_speed": TARGET})
    gen = FootstepTrajectoryGenerator(robot, terrain, sdf=sdf, config=config)
    prepared = gen.prepare(plan)
    assert prepared.nominal is not None
    shorter = [
        a.duration_s < b.duration_s - 1e-9
        for a, b in zip(prepared.timings, prepared.nominal, strict=True)
    ]
    assert sum(shorter) >= len(shorter) // 2, (prepared.timings, prepared.nominal)


def test_measured_speed_is_checked() -> None:
    with pytest.raises(rw.ConfigError, match="measured_speed"):
        rw.trajectories.trajectory_config(**{"timing.measured_speed": 1.5})
