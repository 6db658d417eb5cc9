"""The compiled NLP cache: same solutions, keys that follow the structure, safe writes."""

from __future__ import annotations

import textwrap
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from _cache_writers import race_two_writers

from roughwalk.errors import ConfigError
from roughwalk.terrain import load_terrain
from roughwalk.trajopt import (
    TOWR_ANYMAL,
    TrajoptResult,
    clear_cache,
    compiled_nlp,
    make_gait,
    optimize_motion,
    towr_config,
)
from roughwalk.trajopt.optimize import _terrain_key

# A small problem keeps gcc's time low: a 4-step trot over 1 s, 5 iterations.
_TASK = ((0.0, 0.0, 0.0), (0.3, 0.0, 0.0))
_PROBLEM = {"gait": "trot", "steps": 4, "duration": 1.0, "max_iter": 5}


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    root = tmp_path_factory.mktemp("roughwalk_cache")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("ROUGHWALK_CACHE", str(root))
        clear_cache()
        yield root / "nlp"
    clear_cache()


def _solve(compiled: str) -> TrajoptResult:
    clear_cache()
    config = towr_config(body_model="towr_anymal")
    return optimize_motion(None, "flat", _TASK, config=config, compiled=compiled, **_PROBLEM)


def _same(a: TrajoptResult, b: TrajoptResult) -> None:
    assert a.status == b.status
    assert a.iterations == b.iterations
    assert a.objective == pytest.approx(b.objective, abs=1e-9)
    np.testing.assert_allclose(a.x, b.x, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.lam_g, b.lam_g, rtol=0, atol=1e-9)


def test_cache_hit_solves_as_the_expressions_do(cache: Path) -> None:
    expression = _solve("off")
    assert expression.build == "expression"
    assert not cache.exists() or not any(cache.iterdir())  # off stores nothing
    stored = _solve("auto")
    assert stored.build == "serialized"  # auto never compiles: a miss is serialised
    assert len(list(cache.iterdir())) == 1
    deserialized = _solve("auto")
    assert deserialized.build == "deserialized"
    compiled = _solve("on")
    assert compiled.build == "compiled"
    assert len(list(cache.iterdir())) == 2
    cached = _solve("auto")
    assert cached.build == "cached"  # the compiled entry is preferred
    assert cached.summary()["build"] == "cached"
    for result in (stored, deserialized, compiled, cached):
        _same(result, expression)
        assert result.n_constraints == expression.n_constraints
        assert result.violations.keys() == expression.violations.keys()


def _compiled_entry(cache: Path) -> Path:
    (entry,) = [e for e in cache.iterdir() if (e / "nlp.so").is_file()]
    return entry


def test_corrupt_or_partial_entries_are_rebuilt_not_loaded(cache: Path) -> None:
    _solve("on")  # stored (or already there)
    entry = _compiled_entry(cache)
    library = entry / "nlp.so"
    # Truncated. A new file, as a crashed copy would leave: this process has
    # the library mapped, and truncating a mapped file in place kills it.
    damaged = entry / "damaged"
    damaged.write_bytes(library.read_bytes()[:1000])
    damaged.replace(library)
    assert compiled_nlp.load(entry.name) is None
    assert not entry.exists()  # removed, not kept for the next reader
    rebuilt = _solve("on")
    assert rebuilt.build == "compiled"
    _same(rebuilt, _solve("off"))
    (entry / "meta.json").unlink()  # partial: no metadata
    assert _solve("auto").build in ("serialized", "deserialized")
    assert not entry.exists()


def _digest(terrain: str = "flat", **changes: object) -> str:
    config = towr_config(body_model="towr_anymal", **changes)
    schedule = make_gait("trot", 4, 1.0)
    key = _terrain_key(load_terrain(terrain))
    return compiled_nlp.structure_digest(TOWR_ANYMAL, key, schedule, config)


def test_the_key_follows_everything_that_defines_the_structure() -> None:
    base = _digest()
    assert _digest() == base
    assert _digest(optimize_durations=True) != base
    assert _digest(dt_dynamics=0.05) != base
    assert _digest(constraints=("dynamics",)) != base
    assert _digest(terrain="towr_block") != base
    # Where the guess comes from and how the result is sampled build nothing.
    assert _digest(init="footsteps", sample_rate_hz=50.0) == base
    heavier = replace(TOWR_ANYMAL, mass=TOWR_ANYMAL.mass + 1.0)
    schedule = make_gait("trot", 4, 1.0)
    config = towr_config(body_model="towr_anymal")
    flat_key = _terrain_key(load_terrain("flat"))
    assert compiled_nlp.structure_digest(heavier, flat_key, schedule, config) != base
    longer = make_gait("trot", 4, 1.2)
    assert compiled_nlp.structure_digest(TOWR_ANYMAL, flat_key, longer, config) != base


def test_the_mode_must_be_known() -> None:
    with pytest.raises(ConfigError, match="compiled must be one of"):
        towr_config(compiled="yes")


_WRITER = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    import casadi as ca
    import numpy as np
    from roughwalk.trajopt import compiled_nlp

    x = ca.SX.sym("x", 3)
    p = ca.SX.sym("p", 1)
    # Enough code that the two compilations overlap.
    f = sum(ca.sin(x[i % 3] * (i + 1) + p) for i in range(500))
    nlp = ca.Function("nlp", [x, p], [f, x], ["x", "p"], ["f", "g"])
    layout = {"lbg": np.zeros(3), "ubg": np.full(3, np.inf), "row_layout": [("box", 3)],
              "cost_names": [], "n_variables": 3}
    compiled_nlp.compile_and_store("race", {"nlp": nlp}, layout, Path(sys.argv[1]))
    """
)


def test_concurrent_writers_leave_one_intact_entry(tmp_path: Path) -> None:
    race_two_writers(_WRITER, tmp_path, timeout_s=300)
    loaded = compiled_nlp.load("race", tmp_path)
    assert loaded is not None
    assert loaded.row_layout == [("box", 3)]
    assert np.isinf(loaded.ubg).all()
    f, g = loaded.functions["nlp"](ca.DM([0.1, 0.2, 0.3]), 0.5)
    x = [0.1, 0.2, 0.3]
    expected = sum(np.sin(x[i % 3] * (i + 1) + 0.5) for i in range(500))
    assert float(f) == pytest.approx(expected, rel=1e-12)
    np.testing.assert_array_equal(np.asarray(g).ravel(), x)


def test_a_failed_compilation_falls_back_and_is_not_retried(
    cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # An option gcc refuses stands for any failure (no compiler, its memory limit).
    monkeypatch.setattr(compiled_nlp, "COMPILER_FLAGS", ("-fno-such-option",))
    with pytest.warns(UserWarning, match="gcc failed"):
        first = _solve("on")
    # CasADi's form instead: stored now, or already stored by an earlier test
    # (then the expressions built for the compiler serve this solve).
    assert first.build in ("serialized", "expression")
    (marker,) = cache.glob("*.failed")
    # gcc is not tried again: the serialised entry serves.
    assert _solve("on").build == "deserialized"
    _same(first, _solve("off"))
    assert marker.is_file()


def test_a_failed_compilation_keeps_a_stored_serialised_entry(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # An earlier "auto" run stored CasADi's serialised form; "on" then fails to
    # compile: the entry is neither rewritten nor claimed as written by this run.
    monkeypatch.setenv("ROUGHWALK_CACHE", str(tmp_path))
    assert _solve("auto").build == "serialized"
    (entry,) = (tmp_path / "nlp").iterdir()
    before = {p.name: p.stat().st_mtime_ns for p in entry.iterdir()}
    monkeypatch.setattr(compiled_nlp, "COMPILER_FLAGS", ("-fno-such-option",))
    with pytest.warns(UserWarning, match="gcc failed"):
        result = _solve("on")
    assert result.build == "expression"
    assert {p.name: p.stat().st_mtime_ns for p in entry.iterdir()} == before
    clear_cache()
