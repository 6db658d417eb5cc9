"""``init generate --time-limit``: each solve's wall-time limit reaches IPOPT, and the run says so.

On a busy machine a solve can stop on time before its iteration limit;
the limit changes where it stops, not the problem, so a folder resumes
under another limit and records the last one used.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _learned_models import SPEC

from roughwalk.cli.main import main
from roughwalk.errors import ConfigError
from roughwalk.learning import task_space
from roughwalk.learning.experience import generate


def _statuses(folder: Path, n: int, time_limit_s: float | None) -> list[str]:
    data = generate(
        SPEC,
        task_space("flat"),
        n,
        folder,
        split="test",
        max_iter=50,
        progress=None,
        time_limit_s=time_limit_s,
    )
    return [str(s) for s in data["status"]]


def test_a_tiny_limit_stops_every_solve_on_time_and_is_recorded(tmp_path: Path) -> None:
    assert _statuses(tmp_path / "run", 1, 1e-6) == ["timeout"]
    assert json.loads((tmp_path / "run" / "run.json").read_text())["time_limit_s"] == 1e-6
    # The same task under the default limit runs to its iteration limit or converges:
    # the limit, not the task, stopped it.
    assert _statuses(tmp_path / "free", 1, None)[0] != "timeout"


def test_a_folder_resumes_under_another_limit_and_keeps_its_solves(tmp_path: Path) -> None:
    assert _statuses(tmp_path / "run", 1, 1e-6) == ["timeout"]
    statuses = _statuses(tmp_path / "run", 2, 400.0)
    assert statuses[0] == "timeout"  # kept, not redone
    assert statuses[1] != "timeout"
    assert json.loads((tmp_path / "run" / "run.json").read_text())["time_limit_s"] == 400.0
    # Resumed under the problem's own limit, the record says so (null), not 400 s.
    _statuses(tmp_path / "run", 2, None)
    assert json.loads((tmp_path / "run" / "run.json").read_text())["time_limit_s"] is None


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_a_limit_that_is_not_positive_is_refused_before_the_folder_is_made(
    tmp_path: Path, bad: float
) -> None:
    with pytest.raises(ConfigError, match="time_limit_s must be > 0 seconds"):
        _statuses(tmp_path / "run", 1, bad)
    assert not (tmp_path / "run").exists()


def test_the_cli_passes_time_limit_to_every_solve(tmp_path: Path) -> None:
    out = tmp_path / "run"
    code = main(
        ["init", "generate", "--env", "flat", "--tasks", "1", "--max-iter", "50"]
        + ["--time-limit", "1e-6", "--out", str(out)]
    )
    assert code == 0
    assert json.loads((out / "run.json").read_text())["time_limit_s"] == 1e-6
    (solve,) = (out / "solves").glob("*.npz")
    with np.load(solve) as row:
        assert str(row["status"]) == "timeout"


def test_a_model_of_another_problem_is_refused_before_the_folder_is_made(tmp_path: Path) -> None:
    from dataclasses import replace

    from _learned_models import heuristic_guess_model

    with pytest.raises(ConfigError, match="does not fit"):
        generate(
            replace(SPEC, optimize_durations=True),
            task_space("flat"),
            1,
            tmp_path / "run",
            model=heuristic_guess_model(),
            progress=None,
        )
    assert not (tmp_path / "run").exists()
    code = main(
        ["init", "generate", "--env", "flat", "--tasks", "1", "--optimize-durations"]
        + ["--init", "learned_fixed_durations", "--out", str(tmp_path / "cli")]
    )
    assert code != 0
    assert not (tmp_path / "cli").exists()
