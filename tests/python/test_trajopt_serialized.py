"""The serialised NLP cache (no compiler): same solutions, safe entries, its own key."""

from __future__ import annotations

import textwrap
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from _cache_writers import race_two_writers

from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    CostWeights,
    TrajoptResult,
    clear_cache,
    compiled_nlp,
    make_gait,
    optimize_motion,
    serialized_nlp,
    towr_config,
)
from roughwalk.trajopt.optimize import _terrain_key

_TASK = ((0.0, 0.0, 0.0), (0.3, 0.0, 0.0))
_PROBLEM = {"gait": "trot", "steps": 4, "duration": 1.0, "max_iter": 5}


def _solve(compiled: str, **changes: object) -> TrajoptResult:
    clear_cache()
    config = towr_config(body_model="towr_anymal", **changes)
    return optimize_motion(None, "flat", _TASK, config=config, compiled=compiled, **_PROBLEM)


def _same(a: TrajoptResult, b: TrajoptResult) -> None:
    assert a.status == b.status
    assert a.iterations == b.iterations
    assert a.objective == pytest.approx(b.objective, abs=1e-12)
    np.testing.assert_array_equal(a.x, b.x)
    np.testing.assert_array_equal(a.lam_g, b.lam_g)


@pytest.mark.parametrize("changes", [{}, {"optimize_durations": True}])
def test_a_deserialized_nlp_solves_exactly_as_the_expressions_do(
    nlp_cache_dir: Path, changes: dict[str, object]
) -> None:
    expression = _solve("off", **changes)
    stored = _solve("auto", **changes)
    assert stored.build == "serialized"
    (entry,) = nlp_cache_dir.iterdir()
    assert (entry / "nlp.casadi").is_file()
    loaded = _solve("auto", **changes)
    assert loaded.build == "deserialized"
    for result in (stored, loaded):
        _same(result, expression)
        assert result.violations.keys() == expression.violations.keys()


def test_the_exact_hessian_is_stored_with_costs(nlp_cache_dir: Path) -> None:
    # Melon's costs select the exact Hessian: it is stored and read back too.
    costs = CostWeights()
    expression = _solve("off", costs=costs)
    assert _solve("auto", costs=costs).build == "serialized"
    loaded = _solve("auto", costs=costs)
    assert loaded.build == "deserialized"
    (entry,) = nlp_cache_dir.iterdir()
    assert "nlp_hess_l" in (entry / "meta.json").read_text()
    _same(loaded, expression)


def test_a_damaged_or_partial_entry_is_removed_and_rebuilt(nlp_cache_dir: Path) -> None:
    _solve("auto")
    (entry,) = nlp_cache_dir.iterdir()
    data = entry / "nlp.casadi"
    data.write_bytes(data.read_bytes()[:-100])  # truncated
    assert serialized_nlp.load(entry.name) is None
    assert not entry.exists()
    assert _solve("auto").build == "serialized"
    assert _solve("auto").build == "deserialized"
    (entry / "meta.json").unlink()
    assert _solve("auto").build == "serialized"


def test_the_key_names_the_kind() -> None:
    config = towr_config(body_model="towr_anymal")
    schedule = make_gait("trot", 4, 1.0)
    key = _terrain_key(load_terrain("flat"))
    compiled = compiled_nlp.structure_digest(TOWR_ANYMAL, key, schedule, config)
    serialized = compiled_nlp.structure_digest(
        TOWR_ANYMAL, key, schedule, config, kind=serialized_nlp.KIND
    )
    assert serialized != compiled
    # A compiled entry is not read as a serialised one, nor the other way round.
    assert serialized_nlp.load(compiled) is None


_WRITER = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    import casadi as ca
    import numpy as np
    from roughwalk.trajopt import serialized_nlp

    x = ca.SX.sym("x", 3)
    p = ca.SX.sym("p", 1)
    f = sum(ca.sin(x[i % 3] * (i + 1) + p) for i in range(20000))
    evaluate = ca.Function("evaluate", [x, p], [f, x, ca.vertcat(f)])
    layout = {"lbg": np.zeros(3), "ubg": np.full(3, np.inf), "row_layout": [("box", 3)],
              "cost_names": ["sines"], "n_variables": 3}
    serialized_nlp.store("race", {"evaluate": evaluate}, layout, Path(sys.argv[1]))
    """
)


def test_concurrent_writers_leave_one_intact_entry(tmp_path: Path) -> None:
    race_two_writers(_WRITER, tmp_path, timeout_s=120)
    loaded = serialized_nlp.load("race", tmp_path)
    assert loaded is not None
    assert loaded.cost_names == ["sines"]
    assert np.isinf(loaded.ubg).all()
    f, g = loaded.functions["nlp"](ca.DM([0.1, 0.2, 0.3]), 0.5)
    x = [0.1, 0.2, 0.3]
    expected = sum(np.sin(x[i % 3] * (i + 1) + 0.5) for i in range(20000))
    assert float(f) == pytest.approx(expected, rel=1e-12)
    np.testing.assert_array_equal(np.asarray(g).ravel(), x)
