"""The tracking bench's ``--trajopt`` and ``--tracking``: the project's dotted overrides."""

from __future__ import annotations

import pickle
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from _benchmarks import load_benchmark


def _job(bench: Any, **fields: Any) -> Any:
    """A flat-ground heuristic job with the given settings."""
    task = {"max_iter": 0, "optimize_durations": False, "index": 0}
    task |= {"start": (0.0, 0.0, 0.0), "goal": (1.0, 0.0, 0.0)}
    return bench.Job("flat", "flat", "heuristic", **task, **fields)


def test_settings_are_kept_as_strings_and_typed_when_the_job_s_config_is_made() -> None:
    bench = load_benchmark("bench_tracking")
    settings = bench._trajopt_settings("dt_dynamics=0.05, optimize_durations=true,")
    assert settings == (("dt_dynamics", "0.05"), ("optimize_durations", "true"))
    pickle.loads(pickle.dumps(_job(bench, trajopt=settings)))  # a Job crosses processes
    config = bench.job_config(_job(bench, trajopt=settings))
    assert config.dt_dynamics == 0.05
    assert config.optimize_durations is True


def test_repeated_flags_add_up_and_a_list_keeps_its_commas() -> None:
    bench = load_benchmark("bench_tracking")
    settings = bench._trajopt_settings(
        "constraints=dynamics,terrain, dt_dynamics=0.05", "dt_dynamics=0.04"
    )
    assert dict(settings) == {"constraints": "dynamics,terrain", "dt_dynamics": "0.04"}
    config = bench.job_config(_job(bench, trajopt=settings))
    assert config.constraints == ("dynamics", "terrain")
    assert config.dt_dynamics == 0.04


def test_added_constraints_are_appended_once() -> None:
    bench = load_benchmark("bench_tracking")
    base = bench.job_config(_job(bench)).constraints
    assert "joint_torques" not in base and base
    added = ("joint_torques", base[0], "joint_torques")
    config = bench.job_config(_job(bench, add_constraints=added))
    assert config.constraints == (*base, "joint_torques")


def test_an_unknown_field_names_the_option_the_field_and_the_known_ones() -> None:
    bench = load_benchmark("bench_tracking")
    with pytest.raises(SystemExit, match="--trajopt: unknown config field 'dt_dynamic' .*known:"):
        bench._trajopt_settings("dt_dynamic=0.05")
    with pytest.raises(SystemExit, match="--tracking: unknown config field 'no_such_gain'"):
        bench._tracking_settings("no_such_gain=1")
    with pytest.raises(SystemExit, match="--trajopt: .*'no_such_weight' for CostWeights"):
        bench._trajopt_settings("costs.no_such_weight=1")
    with pytest.raises(SystemExit, match="--trajopt: .*'wieght' for IntegralCost; known: weight"):
        bench._trajopt_settings("costs.force.wieght=0.1")
    with pytest.raises(SystemExit, match="--trajopt: dt_dynamics: expected a number"):
        bench._trajopt_settings("dt_dynamics=fast")
    with pytest.raises(SystemExit, match="--trajopt: .*expects key=value, got 'fast'"):
        bench._trajopt_settings("fast")


def test_a_dotted_name_changes_one_field_of_melon_configs_nested_config() -> None:
    from roughwalk.trajopt import melon_config

    bench = load_benchmark("bench_tracking")
    settings = bench._trajopt_settings("costs.force_between_nodes_penalty=10")
    config = bench.job_config(_job(bench, trajopt=settings))
    assert config.costs == replace(melon_config().costs, force_between_nodes_penalty=10.0)
    solver = bench.job_config(_job(bench, trajopt=bench._trajopt_settings("solver.tol=0.001")))
    # The other fields stay melon_config's (its adaptive barrier update), not the class default.
    assert solver.solver.ipopt_options == melon_config().solver.ipopt_options
    assert solver.solver.tol == 0.001


def test_a_two_level_name_changes_one_weight_of_a_nested_cost() -> None:
    from roughwalk.trajopt import melon_config

    bench = load_benchmark("bench_tracking")
    settings = bench._trajopt_settings("costs.force.weight=0.1")
    config = bench.job_config(_job(bench, trajopt=settings))
    default = melon_config().costs
    assert config.costs == replace(default, force=replace(default.force, weight=0.1))
    tracking = bench._tracking_settings("gains.base_kp=50,track_com=true")
    assert dict(tracking) == {"gains.base_kp": "50", "track_com": "true"}
    controller = bench.job_tracking(_job(bench, tracking=tracking))
    assert controller.gains.base_kp == 50.0
    assert controller.track_com is True


def test_pyramid_violation_sees_a_stance_force_outside_the_cone_between_nodes() -> None:
    bench = load_benchmark("bench_tracking")
    t = np.linspace(0.0, 2.0, 401)
    forces = np.zeros((t.size, 2, 3))
    forces[..., 2] = 100.0
    contact = np.ones((t.size, 2), dtype=bool)
    forces[200, 0] = [80.0, 0.0, 100.0]  # |f_x| − μ f_z = 30 N at μ = 0.5
    forces[210, 1] = [0.0, 0.0, -20.0]  # pulls: 20 N
    forces[5, 1] = [0.0, 900.0, 100.0]  # inside the first 0.3 s: not counted
    result = SimpleNamespace(
        duration=2.0,
        body=SimpleNamespace(friction=0.5),
        sample=lambda rate: {"t": t, "forces": forces, "contact": contact},
    )
    assert bench.pyramid_violation(result) == pytest.approx(30.0)
    contact[200, 0] = False  # in swing the force is not the ground's
    assert bench.pyramid_violation(result) == pytest.approx(20.0)


def test_start_offset_says_how_far_a_plan_starts_from_its_task() -> None:
    bench = load_benchmark("bench_tracking")
    plan = {"base_position": np.array([[0.3, -0.4, 0.5]]), "base_euler": np.array([[0, 0, 3.0]])}
    result = SimpleNamespace(sample=lambda rate_hz=None, times=None: plan)
    offset, dyaw = bench.start_offset(result, (0.0, 0.0, -3.0))
    assert offset == pytest.approx(0.5)
    assert dyaw == pytest.approx(2 * np.pi - 6.0)  # the short way round
    rows = [
        {"env": "e", "init": "i", "optimize_durations": False, "max_iter": 0, "start_offset_m": o}
        for o in (0.01, 0.32, 0.2)
    ]
    summary = bench.summarise(rows)[0]
    assert summary["off_start"] == 2
    assert summary["median_start_offset_m"] == pytest.approx(0.2)
