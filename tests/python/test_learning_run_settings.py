"""A learned run folder records its restart settings and is resumed only under them."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from _learned_models import SPEC, heuristic_guess_model

from roughwalk.errors import ConfigError
from roughwalk.learning import task_space
from roughwalk.learning.experience import generate
from roughwalk.learning.problem_spec import (
    UNRECORDED_SOLVE_SETTINGS,
    ProblemSpec,
    cost_weights,
    solve_settings,
    solver_settings,
)


def _learned(spec: ProblemSpec, n: int, folder: Path) -> dict[str, np.ndarray]:
    data = generate(
        spec,
        task_space("flat"),
        n,
        folder,
        split="test",
        max_iter=3,
        model=heuristic_guess_model(),
        init="learned:tiny",
        progress=None,
    )
    return {"index": data["index"], "x": data["x"]}


def _recorded(folder: Path) -> dict[str, object] | None:
    return json.loads((folder / "run.json").read_text()).get("solver")


def test_resuming_under_the_same_settings_keeps_the_solves(tmp_path: Path) -> None:
    first = _learned(SPEC, 1, tmp_path / "run")
    assert _recorded(tmp_path / "run") == solve_settings(SPEC)
    assert solve_settings(SPEC) == {
        "guess_fallback_after": SPEC.config().solver.guess_fallback_after,
        "dear_guess_restarts": SPEC.config().solver.dear_guess_restarts,
    }
    again = _learned(SPEC, 2, tmp_path / "run")
    assert list(again["index"]) == [0, 1]
    np.testing.assert_array_equal(again["x"][0], first["x"][0])


def test_a_changed_setting_is_refused_naming_it_both_values_and_the_way_out(
    tmp_path: Path,
) -> None:
    _learned(SPEC, 1, tmp_path / "run")
    recorded = SPEC.config().solver.dear_guess_restarts
    other = replace(SPEC, solver=solver_settings([f"solver.dear_guess_restarts={recorded + 1}"]))
    with pytest.raises(ConfigError) as e:
        _learned(other, 2, tmp_path / "run")
    message = str(e.value)
    assert f"made with solver.dear_guess_restarts={recorded};" in message
    assert f"this run has solver.dear_guess_restarts={recorded + 1}" in message
    assert "use a fresh folder" in message
    assert f"--set solver.dear_guess_restarts={recorded} " in message
    assert _recorded(tmp_path / "run") == solve_settings(SPEC)  # the record is kept
    _learned(other, 1, tmp_path / "fresh")  # a fresh folder takes them


def test_a_folder_without_the_record_counts_as_the_settings_before_it(tmp_path: Path) -> None:
    old = replace(
        SPEC,
        solver=solver_settings([f"solver.{k}={v}" for k, v in UNRECORDED_SOLVE_SETTINGS.items()]),
    )
    assert solve_settings(old) == {"guess_fallback_after": 40, "dear_guess_restarts": 0}
    folder = tmp_path / "run"
    first = _learned(old, 1, folder)
    meta = json.loads((folder / "run.json").read_text())
    del meta["solver"]  # as a run folder of session 10 was written
    (folder / "run.json").write_text(json.dumps(meta))
    if SPEC.config().solver.guess_fallback_after != 40:
        with pytest.raises(ConfigError, match="so with solver.guess_fallback_after=40;"):
            _learned(SPEC, 2, folder)
    again = _learned(old, 2, folder)
    np.testing.assert_array_equal(again["x"][0], first["x"][0])
    assert _recorded(folder) == {"guess_fallback_after": 40, "dear_guess_restarts": 0}


def test_a_heuristic_run_records_no_restart_settings(tmp_path: Path) -> None:
    # Its solves use none: one made before resumes under any.
    generate(SPEC, task_space("flat"), 1, tmp_path / "run", max_iter=3, progress=None)
    assert _recorded(tmp_path / "run") is None
    other = replace(SPEC, solver=solver_settings(["solver.guess_fallback_after=none"]))
    generate(other, task_space("flat"), 2, tmp_path / "run", max_iter=3, progress=None)


def test_solver_settings_are_checked_and_kept_only_when_not_the_defaults() -> None:
    default = SPEC.config().solver
    assert solver_settings([f"solver.guess_fallback_after={default.guess_fallback_after}"]) is None
    assert solver_settings(["solver.guess_fallback_after=none", "costs.force.weight=0.1"]) == (
        ("guess_fallback_after", None),
    )
    with pytest.raises(ConfigError, match="not a learned-solve setting"):
        solver_settings(["solver.tol=1e-3"])
    with pytest.raises(ConfigError, match="solver.dear_guess_restarts=-1"):
        solver_settings(["solver.dear_guess_restarts=-1"])
    assert cost_weights(["solver.dear_guess_restarts=0"]) is None
    # Not part of the NLP a model fits: left out of the problem's record.
    spec = replace(SPEC, solver=(("dear_guess_restarts", 0),))
    assert spec.to_dict() == SPEC.to_dict()
    assert spec.config().solver.dear_guess_restarts == 0
