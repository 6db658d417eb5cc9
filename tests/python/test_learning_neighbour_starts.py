"""Experience grown from solved neighbours (``roughwalk init generate --init nearest:RUN``)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roughwalk.cli.main import main
from roughwalk.errors import ConfigError
from roughwalk.learning import ProblemSpec, TaskSpace, generate
from roughwalk.learning.experience import read_run
from roughwalk.learning.neighbour_starts import SolvedPool, parse_nearest

SPEC = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0)
SPACE = TaskSpace("flat_small", "flat", (-0.1, -0.1, -0.2), (0.1, 0.1, 0.2), (0.4, 0.0, 0.0))
LIMIT = 60


@pytest.fixture(scope="module")
def seed_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two flat tasks solved from the heuristic guess."""
    folder = tmp_path_factory.mktemp("seed") / "run"
    data = generate(SPEC, SPACE, 2, folder, progress=None, max_iter=LIMIT)
    assert (data["max_violation"] < 1e-3).all()
    return folder


def _grown(seed_run: Path, folder: Path, n: int, **kw: Any) -> Any:
    """The first ``n`` tasks of SPACE grown from ``seed_run``'s solves into ``folder``."""
    return generate(SPEC, SPACE, n, folder, progress=None, max_iter=LIMIT, seeds=[seed_run], **kw)


def _scaled(a: np.ndarray, b: np.ndarray) -> float:
    scale = np.array([0.2, 0.2, 0.4, 1.0, 1.0, 1.0])
    return float(np.sqrt((((a - b) / scale) ** 2).sum()))


def test_each_task_starts_from_the_nearest_solve_so_far_nearest_first(
    seed_run: Path, tmp_path: Path
) -> None:
    seed = read_run(seed_run)
    rows = zip(seed["start"], seed["goal"], seed["x"], strict=True)
    pool = [(np.concatenate([start, goal]), x) for start, goal, x in rows]
    order: list[dict[str, Any]] = []
    data = _grown(seed_run, tmp_path / "grown", 6, on_solved=order.append)
    assert sorted(int(r["index"]) for r in order) == list(range(6))
    for row in order:
        task = np.concatenate([row["start"], row["goal"]])
        distances = [_scaled(task, t) for t, _ in pool]
        # Started from the solution of the nearest feasible solve so far ...
        np.testing.assert_array_equal(row["x0"], pool[int(np.argmin(distances))][1])
        # ... and no task left was nearer to one than this one.
        for other in order[order.index(row) + 1 :]:
            there = np.concatenate([other["start"], other["goal"]])
            assert min(_scaled(there, t) for t, _ in pool) >= min(distances) - 1e-12
        if row["max_violation"] <= 1e-3:
            pool.append((task, row["x"]))
    # A seed task restarts at its own solution: converged at once.
    assert int(data["iterations"][list(data["index"]).index(0)]) <= 2
    meta = json.loads((tmp_path / "grown" / "run.json").read_text())
    assert meta["init"] == f"nearest:{seed_run}"


def test_the_cli_grows_a_run_and_refuses_seeds_of_another_problem(
    seed_run: Path, tmp_path: Path
) -> None:
    other = tmp_path / "other"
    generate(
        ProblemSpec("anymal_c", "flat", "walk", 4, 2.5), SPACE, 1, other, progress=None, max_iter=5
    )
    with pytest.raises(ConfigError, match="another problem"):
        generate(SPEC, SPACE, 1, tmp_path / "x", progress=None, seeds=[other])
    code = main(
        ["init", "generate", "--env", "flat", "--goal", "0.4,0,0", "--steps", "4"]
        + ["--duration", "2", "--tasks", "2", "--max-iter", "5"]
        + ["--init", f"nearest:{seed_run}", "--out", str(tmp_path / "cli")]
    )
    assert code == 0
    assert json.loads((tmp_path / "cli" / "run.json").read_text())["init"] == f"nearest:{seed_run}"


def test_nearest_init_names_its_seed_runs() -> None:
    assert parse_nearest("nearest:a,b/c") == [Path("a"), Path("b/c")]
    assert parse_nearest("learned:x") is None
    with pytest.raises(ConfigError, match="run folders"):
        parse_nearest("nearest:")


def test_only_feasible_solves_with_multipliers_join_the_pool() -> None:
    pool = SolvedPool.for_space(SPACE)
    row = {
        "start": np.zeros(3),
        "goal": np.array([0.4, 0.0, 0.0]),
        "x": np.ones(4),
        "lam_x": np.zeros(4),
        "lam_g": np.zeros(2),
        "cost": 1.0,
        "max_violation": 1e-6,
    }
    assert pool.add(row)
    assert not pool.add({**row, "max_violation": 0.5})
    assert not pool.add({**row, "lam_g": np.full(2, np.nan)})
    assert len(pool) == 1
    np.testing.assert_allclose(pool.scale, [0.2, 0.2, 0.4, 1.0, 1.0, 1.0])


def test_a_time_limit_reaches_the_solves_started_from_neighbours(
    seed_run: Path, tmp_path: Path
) -> None:
    data = _grown(seed_run, tmp_path / "grown", 3, time_limit_s=1e-6)
    assert [str(s) for s in data["status"]] == ["timeout"] * 3
