"""``bench init --first-task``: held-out tasks from an offset of the test split."""

from __future__ import annotations

import json
import sys
from argparse import Namespace
from pathlib import Path

import pytest
from _benchmarks import load_benchmark

from roughwalk.learning import ProblemSpec, task_space


def test_the_first_task_offsets_the_held_out_indices() -> None:
    bench = load_benchmark("bench_init")
    assert bench.held_out_indices(Namespace(tasks=3, first_task=200)) == [200, 201, 202]
    assert bench.held_out_indices(Namespace(tasks=3, first_task=0)) == [0, 1, 2]
    with pytest.raises(SystemExit, match="--first-task"):
        bench.held_out_indices(Namespace(tasks=3, first_task=-1))


def test_test_tasks_beyond_199_are_new_tasks_apart_from_training_and_fixed() -> None:
    space = task_space("single_pallet")
    fresh = [space.task(i, split="test").start for i in range(200, 400)]
    tuned = {space.task(i, split="test").start for i in range(200)}
    train = {space.task(i, split="train").start for i in range(2000)}
    assert len(set(fresh)) == 200
    assert not set(fresh) & tuned
    assert not set(fresh) & train
    # Each task depends on its index alone, not on how many are asked for.
    assert space.sample(400, split="test")[200:] == [
        space.task(i, split="test") for i in range(200, 400)
    ]


def test_a_run_from_the_first_task_solves_those_tasks(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    bench = load_benchmark("bench_init")
    (tmp_path / "no_models").mkdir()
    out = tmp_path / "init.json"
    argv = ["bench_init.py", "--models", str(tmp_path / "no_models"), "--tasks", "2"]
    argv += ["--first-task", "200", "--max-iter", "2", "--timing-tasks", "0", "--skip-table"]
    argv += ["--experience", str(tmp_path / "exp"), "--json", str(out)]
    monkeypatch.setattr(sys, "argv", argv)
    bench.main()
    fig6 = json.loads(out.read_text())["figure_6"]
    assert fig6["task_indices"] == [200, 202]
    assert fig6["initializers"]["Heuristic"]["tasks"] == 2
    (run,) = (tmp_path / "exp").iterdir()
    assert sorted(p.name for p in (run / "solves").iterdir()) == ["000200.npz", "000201.npz"]


def test_timed_and_table_tasks_leave_out_the_refused() -> None:
    # Held-out task 189's start stance is out of its legs' range of motion:
    # Figure 6 leaves it out, and so must the timed and Table I solves.
    bench = load_benchmark("bench_init")
    spec = ProblemSpec("anymal_c", "single_pallet", "walk", 16, 5.5)
    args = Namespace(env="single_pallet", first_task=188, tasks=3)
    tasks = bench.solvable_tasks(args, spec, 3)
    space = task_space("single_pallet")
    assert tasks == [space.task(188, split="test"), space.task(190, split="test")]
