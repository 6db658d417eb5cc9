"""The tracking bench's ``--trajopt`` and ``--tracking`` settings: fields checked by name."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from _benchmarks import load_benchmark


def test_trajopt_settings_are_parsed_as_config_fields() -> None:
    bench = load_benchmark("bench_tracking")
    settings = bench._trajopt_settings("dt_dynamics=0.05, optimize_durations=true")
    assert settings == (("dt_dynamics", 0.05), ("optimize_durations", True))


def test_an_unknown_field_names_the_option_and_the_field() -> None:
    bench = load_benchmark("bench_tracking")
    with pytest.raises(SystemExit, match="--trajopt: TrajoptConfig has no field 'dt_dynamic'"):
        bench._trajopt_settings("dt_dynamic=0.05")
    with pytest.raises(SystemExit, match="--tracking: TrackingConfig has no field"):
        bench._tracking_settings("no_such_gain=1")


def test_a_dotted_name_changes_one_field_of_melon_configs_nested_config() -> None:
    from roughwalk.trajopt import melon_config

    bench = load_benchmark("bench_tracking")
    ((name, costs),) = bench._trajopt_settings("costs.force_between_nodes_penalty=10")
    assert name == "costs"
    assert costs == replace(melon_config().costs, force_between_nodes_penalty=10.0)
    ((_, solver),) = bench._trajopt_settings("solver.tol=0.001")
    # The other fields stay melon_config's (its adaptive barrier update), not the class default.
    assert solver.ipopt_options == melon_config().solver.ipopt_options
    assert solver.tol == 0.001
    with pytest.raises(SystemExit, match="CostWeights has no field 'no_such_weight'"):
        bench._trajopt_settings("costs.no_such_weight=1")


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
