"""Executing motions with the whole-body controller in MuJoCo (issue 10's required tests)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from roughwalk import load_robot, load_terrain
from roughwalk.tracking import (
    Reference,
    TrackingConfig,
    TrunkPush,
    execute_reference,
    load_trajectory,
    track,
)
from roughwalk.trajopt import Task, TrajoptResult, optimize_motion
from roughwalk.trajopt.variables import NumericSpline


@pytest.fixture(scope="module")
def anymal_c():
    return load_robot("anymal_c")


@pytest.fixture(scope="module")
def trot(anymal_c) -> TrajoptResult:
    """A short optimised flat-ground trot: 6 steps, 0.3 m in 2 s."""
    result = optimize_motion(
        anymal_c,
        load_terrain("flat"),
        Task((0.0, 0.0, 0.0), (0.3, 0.0, 0.0)),
        gait="trot",
        steps=6,
        duration=2.0,
    )
    assert result.solved, result.message
    return result


def test_keeps_anymal_c_standing_under_a_50_n_lateral_push(anymal_c):
    ns = anymal_c.nominal_stance
    base = np.array([0.0, 0.0, ns.base_height])
    feet = ns.feet + base - [0.0, 0.0, anymal_c.foot_radius]
    reference = Reference.standing(base, feet, anymal_c.mass, duration=0.5)
    config = TrackingConfig(stand_after_s=1.0)
    push = TrunkPush((0.0, 50.0, 0.0), at_s=0.3, duration_s=0.2)
    pushed = execute_reference(reference, anymal_c, load_terrain("flat"), config, push=push)
    assert pushed.success, pushed.reason
    assert not pushed.fell
    log = pushed.log
    assert log is not None
    # The push did move the trunk (it was applied), and the controller brought it back.
    assert log.position_error.max() > 2e-3
    assert pushed.final_position_error_m < 0.02
    assert pushed.max_orientation_error_rad < 0.1


def test_a_stalled_qp_tick_ends_the_run_as_a_reported_failure(anymal_c):
    """A solver that hits its iteration limit stops the run at once, named as the reason."""
    ns = anymal_c.nominal_stance
    base = np.array([0.0, 0.0, ns.base_height])
    feet = ns.feet + base - [0.0, 0.0, anymal_c.foot_radius]
    reference = Reference.standing(base, feet, anymal_c.mass, duration=0.5)
    fine = execute_reference(reference, anymal_c, load_terrain("flat"), TrackingConfig())
    assert fine.success, fine.reason
    # One proxqp outer iteration cannot reach 1e-8: every tick stalls.
    starved = TrackingConfig(qp_max_iter=1)
    outcome = execute_reference(reference, anymal_c, load_terrain("flat"), starved)
    assert not outcome.success and not outcome.fell
    assert outcome.reason.startswith("the whole-body QP stalled at t = 0.00 s"), outcome.reason
    assert "iteration limit (1)" in outcome.reason
    assert outcome.simulated_s == 0.0 and outcome.qp_failures == 1


def test_tracks_an_optimised_flat_ground_trot_to_the_goal_within_5_cm(trot):
    outcome = track(trot)
    assert outcome.success, outcome.reason
    assert outcome.final_position_error_m < 0.05
    final = trot.sample(times=[trot.duration])["base_position"][0]
    np.testing.assert_allclose(final[:2], [0.3, 0.0], atol=0.02)  # the planned goal, (x, y)
    log = outcome.log
    assert log is not None and log.t[-1] >= trot.duration + 1.0 - 1e-9
    # Feet touched down as planned: measured normal forces where stance was planned.
    planned = log.contact_ref[: len(log.t) // 2]
    measured = log.forces[: len(log.t) // 2, :, 2] > 5.0
    assert (planned == measured).mean() > 0.9


def test_tracking_the_same_plan_twice_gives_bit_identical_logs(trot):
    # A trot is chaotic in simulation: a 1e-10 difference in one tick's torques
    # (proxqp's dense backend rounds by memory layout) grew into a fall in one
    # run and a tracked motion in the next (issue 10). Same plan, same log.
    first, second = track(trot), track(trot)
    assert first.log is not None and second.log is not None
    for name in first.log.__dataclass_fields__:
        np.testing.assert_array_equal(
            getattr(first.log, name), getattr(second.log, name), err_msg=name
        )
    assert (first.success, first.reason, first.qp_failures) == (
        second.success,
        second.reason,
        second.qp_failures,
    )


def _base_leap(result: TrajoptResult, lateral_m: float) -> TrajoptResult:
    """The base leaps ``lateral_m`` sideways in one 0.1 s polynomial mid-motion, feet unchanged.

    That takes a lateral acceleration of tens of g with the same contact forces:
    no robot can do it, whatever its controller.
    """
    assert result.splines is not None
    base = result.splines.base_linear
    positions = base.positions.copy()
    later = base.node_times >= 0.5 * result.duration
    positions[later, 1] += lateral_m
    leaping = NumericSpline(positions, base.velocities, base.durations)
    splines = dataclasses.replace(result.splines, base_linear=leaping)
    return dataclasses.replace(result, splines=splines)


def test_a_dynamically_infeasible_trajectory_is_a_reported_failure(trot, tmp_path):
    """Through the CLI: exit code 1, a JSON verdict with its reason, and the Figure-4 picture."""
    from roughwalk.cli.main import main

    path = tmp_path / "leap.json"
    data = {"schema": "trajopt_result", "robot": "anymal_c", "terrain": "flat"}
    path.write_text(json.dumps({**data, **_base_leap(trot, 0.4).to_dict()}))
    out, picture = tmp_path / "out.json", tmp_path / "tracking.png"
    code = main(["track", "--trajectory", str(path), "--json", str(out), "-o", str(picture)])
    assert code == 1
    verdict = json.loads(out.read_text())
    assert verdict["schema"] == "tracking_outcome" and verdict["success"] is False
    assert verdict["reason"].split(":")[0] in ("fell", "missed the goal")
    for key in ("final_position_error_m", "max_orientation_error_rad", "mean_position_error_m"):
        assert key in verdict
    assert picture.stat().st_size > 10_000


def test_reference_matches_the_splines_and_its_derivatives(trot):
    reference = Reference.from_result(trot)
    times = np.linspace(0.05, trot.duration - 0.05, 23)
    planned = trot.sample(times=times)
    for i, t in enumerate(times):
        s = reference(float(t))
        np.testing.assert_allclose(s.base_pos, planned["base_position"][i], atol=1e-12)
        np.testing.assert_allclose(s.base_angvel, planned["base_angular_velocity"][i], atol=1e-12)
        np.testing.assert_allclose(s.feet_pos, planned["feet_position"][i], atol=1e-12)
        np.testing.assert_allclose(s.feet_vel, planned["feet_velocity"][i], atol=1e-12)
        np.testing.assert_allclose(s.forces, planned["forces"][i], atol=1e-9)
        assert (s.contact == planned["contact"][i]).all()
        q = s.base_quat
        assert (
            min(
                np.abs(q - planned["base_quat"][i]).max(), np.abs(q + planned["base_quat"][i]).max()
            )
            < 1e-9
        )
        # Velocities and accelerations are the derivatives of positions and velocities.
        h = 1e-5
        a, b = reference(float(t) - h), reference(float(t) + h)
        np.testing.assert_allclose(s.base_vel, (b.base_pos - a.base_pos) / (2 * h), atol=1e-5)
        np.testing.assert_allclose(s.base_acc, (b.base_vel - a.base_vel) / (2 * h), atol=1e-3)
        np.testing.assert_allclose(
            s.base_angacc, (b.base_angvel - a.base_angvel) / (2 * h), atol=1e-3
        )
        # Foot accelerations jump at phase boundaries: compare with the splines' own.
        assert trot.splines is not None
        own = np.array([f.evaluate(t)[2][0] for f in trot.splines.feet])
        np.testing.assert_allclose(s.feet_acc, own, atol=1e-12)


def test_the_optimize_json_round_trips_to_the_same_motion(trot, tmp_path):
    path = tmp_path / "trot.json"
    path.write_text(json.dumps({"schema": "trajopt_result", **trot.to_dict()}))
    loaded = load_trajectory(path)
    times = np.linspace(0.0, trot.duration, 17)
    a, b = trot.sample(times=times), loaded.sample(times=times)
    for key in ("base_position", "base_quat", "feet_position", "forces", "contact"):
        np.testing.assert_allclose(a[key], b[key], atol=1e-12)
    assert loaded.status == trot.status and loaded.schedule == trot.schedule
