"""Experience datasets: npz + JSON round trip, and a killed run resumed gives the same dataset."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.learning import Dataset, ProblemSpec, TaskSpace, experience, generate
from roughwalk.learning.dataset import COLUMNS
from roughwalk.learning.experience import jittered, read_run
from roughwalk.learning.problem_spec import task_refusal

SPEC = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0)
SPACE = TaskSpace("flat_small", "flat", (-0.1, -0.1, -0.2), (0.1, 0.1, 0.2), (0.4, 0.0, 0.0))


class Killed(Exception):
    """Stands for the process being killed after some solves."""


def test_task_sampling_is_seeded_extendable_and_held_out_apart() -> None:
    first = SPACE.sample(5, seed=3)
    assert SPACE.sample(8, seed=3)[:5] == first  # asking for more keeps the first ones
    assert SPACE.sample(5, seed=4) != first
    held_out = SPACE.sample(5, seed=3, split="test")
    assert not {t.start for t in held_out} & {t.start for t in first}
    starts = np.array([t.start for t in SPACE.sample(200)])
    assert np.all(starts >= SPACE.start_low) and np.all(starts <= SPACE.start_high)
    with pytest.raises(ConfigError, match="unknown split 'validation'"):
        SPACE.task(0, split="validation")


def test_dataset_round_trips_through_npz_and_json(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    rows = [
        {
            "index": i,
            "start": rng.normal(size=3),
            "goal": rng.normal(size=3),
            "x0": rng.normal(size=7),
            "x": rng.normal(size=7),
            "lam_x": rng.normal(size=7),
            "lam_g": rng.normal(size=5),
            "cost": float(rng.uniform()),
            "status": ["exact", "iteration_limit"][i % 2],
            "iterations": int(rng.integers(1, 100)),
            "max_violation": float(rng.uniform()),
            "max_force_n": 300.0,
            "solve_time_s": 0.5,
            "first_iteration_s": 0.1,
            "time_per_iteration_s": float("nan"),
        }
        for i in (3, 0, 2, 1)
    ]
    meta = {"problem": SPEC.to_dict(), "layout": [["x", 7]], "split": "train", "seed": 0}
    data = Dataset.from_rows(rows, meta)
    assert data["index"].tolist() == [0, 1, 2, 3]
    data.save(tmp_path / "d.npz")
    back = Dataset.load(tmp_path / "d.npz")
    assert back.same_rows(data, ignore=())
    assert back.meta == json.loads(json.dumps(meta))
    schema = json.loads((tmp_path / "d.json").read_text())
    assert schema["version"] == 1 and set(schema["columns"]) == set(COLUMNS)
    assert schema["columns"]["x"]["shape"] == [4, 7]
    # Appending refuses overlapping tasks and other problems.
    with pytest.raises(InvalidArgumentError, match="task indices are in both"):
        data.append(back)
    other = Dataset(back.columns, {**meta, "problem": {**SPEC.to_dict(), "steps": 8}})
    with pytest.raises(InvalidArgumentError, match="differ in 'problem'"):
        data.select(data["index"] < 2).append(other.select(other["index"] >= 2))
    joined = data.select(data["index"] < 2).append(back.select(back["index"] >= 2))
    assert joined.same_rows(data, ignore=())
    # A changed value is named by its column; timings are ignored by default.
    changed = {**back.columns, "cost": back["cost"] + 1e-12, "solve_time_s": back["cost"]}
    assert Dataset(changed, back.meta).differing_columns(data) == ["cost"]
    assert not Dataset(changed, back.meta).same_rows(data)


def test_killed_run_resumes_to_the_same_dataset(tmp_path: Path) -> None:
    whole = generate(SPEC, SPACE, 4, tmp_path / "whole", progress=None)

    def kill_after_two(row: dict[str, object]) -> None:
        if int(row["index"]) == 1:  # type: ignore[call-overload]
            raise Killed

    with pytest.raises(Killed):
        generate(SPEC, SPACE, 4, tmp_path / "resumed", progress=None, on_solved=kill_after_two)
    # A half-written file from the moment of the kill is ignored.
    (tmp_path / "resumed" / "solves" / "000002.npz.part").write_bytes(b"half")
    assert len(read_run(tmp_path / "resumed")) == 2
    seen: list[int] = []
    resumed = generate(
        SPEC,
        SPACE,
        4,
        tmp_path / "resumed",
        progress=None,
        on_solved=lambda r: seen.append(r["index"]),
    )
    assert seen == [2, 3]  # the finished solves were not redone
    assert resumed.same_rows(whole)
    assert Dataset.load(tmp_path / "resumed" / "dataset.npz").same_rows(whole)
    with pytest.raises(ConfigError, match="another 'seed'"):
        generate(SPEC, SPACE, 4, tmp_path / "resumed", seed=1, progress=None)


def test_a_run_is_not_resumed_under_another_constraint_set(tmp_path: Path) -> None:
    """Solves of a problem with other constraints must not be mixed into the run."""
    from dataclasses import replace

    from roughwalk.trajopt.parameters import MELON_CONSTRAINTS

    generate(SPEC, SPACE, 0, tmp_path / "run", progress=None)
    without_reach = replace(SPEC, constraints=MELON_CONSTRAINTS)
    with pytest.raises(ConfigError, match="another 'constraints'"):
        generate(without_reach, SPACE, 0, tmp_path / "run", progress=None)


def test_a_run_that_did_not_record_a_setting_is_not_resumed(tmp_path: Path) -> None:
    """A run made before a setting was recorded cannot prove it matches: refused, kept intact."""
    generate(SPEC, SPACE, 1, tmp_path / "run", progress=None)
    meta_path = tmp_path / "run" / "run.json"
    meta = json.loads(meta_path.read_text())
    del meta["constraints"]
    meta_path.write_text(json.dumps(meta))
    with pytest.raises(ConfigError, match="does not record 'constraints'"):
        generate(SPEC, SPACE, 2, tmp_path / "run", progress=None)
    assert "constraints" not in json.loads(meta_path.read_text())  # nothing rewritten
    assert len(read_run(tmp_path / "run")) == 1


def test_generate_selects_the_constraint_set(tmp_path: Path) -> None:
    """``init generate --constraints`` builds (and records) the NLP with the named set."""
    from roughwalk.cli.main import main
    from roughwalk.learning.problem_spec import build_problem, constraint_set
    from roughwalk.trajopt.parameters import MELON_CONSTRAINTS, MELON_REACH_CONSTRAINTS

    common = ["init", "generate", "--env", "flat", "--steps", "4", "--duration", "2.0"]
    for name, expected in (("melon", MELON_CONSTRAINTS), (None, MELON_REACH_CONSTRAINTS)):
        out = tmp_path / str(name)
        extra = [] if name is None else ["--constraints", name]
        assert main([*common, "--tasks", "0", "--out", str(out), *extra]) == 0
        meta = json.loads((out / "run.json").read_text())
        assert meta["constraints"] == list(expected)
        spec = ProblemSpec.from_dict(meta["problem"])
        assert spec.config().constraints == expected
        assert ProblemSpec.from_dict(spec.to_dict()) == spec
    # The reach ball adds rows: the two sets are two problems.
    with_reach = build_problem(ProblemSpec("anymal_c", "flat", "walk", 4, 2.0))
    without = build_problem(
        ProblemSpec("anymal_c", "flat", "walk", 4, 2.0, False, MELON_CONSTRAINTS)
    )
    assert with_reach.formulation.n_constraints > without.formulation.n_constraints
    assert constraint_set("terrain,dynamics") == ("terrain", "dynamics")
    with pytest.raises(ConfigError, match="unknown constraint set or names 'reach'"):
        constraint_set("reach")


def test_best_per_task_keeps_each_task_s_feasible_cheapest_solve() -> None:
    """Re-solves of the same tasks (Algorithm 1's rounds) merge into one row per task."""
    from roughwalk.learning.filtering import best_per_task

    def rows(cost: list[float], violation: list[float], tag: float) -> Dataset:
        n = len(cost)
        return Dataset.from_rows(
            [
                {
                    "index": i,
                    "start": np.zeros(3),
                    "goal": np.zeros(3),
                    "x0": np.full(2, tag),
                    "x": np.full(2, tag),
                    "cost": cost[i],
                    "status": "exact",
                    "iterations": 10,
                    "max_violation": violation[i],
                    "max_force_n": 0.0,
                    "solve_time_s": 0.0,
                    "first_iteration_s": 0.0,
                    "time_per_iteration_s": 0.0,
                }
                for i in range(n)
            ],
            {},
        )

    first = rows([1.0, 2.0, 3.0, 4.0], [0.0, 0.0, 1.0, 0.0], 1.0)
    second = rows([2.0, 1.0, 9.0], [0.0, 0.0, 0.0], 2.0)  # task 3 not re-solved
    merged = best_per_task([first, second])
    assert merged["index"].tolist() == [0, 1, 2, 3]
    # Task 0: cheaper first; 1: cheaper second; 2: the feasible one, dearer; 3: only first.
    assert merged["x"][:, 0].tolist() == [1.0, 2.0, 2.0, 1.0]
    assert merged["cost"].tolist() == [1.0, 1.0, 9.0, 4.0]


def test_jittered_starts_depend_on_seed_and_index_only() -> None:
    tasks = SPACE.sample(4)
    moved = jittered(tasks, [0, 1, 2, 3], (0.1, 0.1, 0.2), seed=5)
    # Resumed with the first two done, the rest are asked the same.
    assert jittered(tasks[2:], [2, 3], (0.1, 0.1, 0.2), seed=5) == moved[2:]
    assert jittered(tasks, [0, 1, 2, 3], (0.1, 0.1, 0.2), seed=6) != moved
    for task, new in zip(tasks, moved, strict=True):
        assert new.goal == task.goal and new.start != task.start
        assert np.all(np.abs(np.subtract(new.start, task.start)) < 5 * np.array([0.1, 0.1, 0.2]))
    assert jittered(tasks, [0, 1, 2, 3], (0.0, 0.0, 0.0), seed=5) == tasks
    with pytest.raises(ConfigError, match="three standard deviations"):
        jittered(tasks, [0, 1, 2, 3], (0.1, 0.1), seed=5)


def test_generate_cli_selects_far_starts_and_checks_jitter(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--start-x-max`` / ``--start-x-min`` solve only the far / near starts; ``--jitter``
    needs a model and 3 numbers."""
    from roughwalk.cli.main import main
    from roughwalk.learning.task_space import ENVIRONMENTS

    common = ["init", "generate", "--env", "flat", "--steps", "4", "--duration", "2.0"]
    starts = [ENVIRONMENTS["flat"].task(i).start[0] for i in range(6)]
    x_max = float(np.median(starts))
    out = tmp_path / "far"
    args = [*common, "--tasks", "6", "--max-iter", "0", "--start-x-max", str(x_max)]
    assert main([*args, "--out", str(out)]) == 0
    far = [i for i, x in enumerate(starts) if x <= x_max]
    assert 0 < len(far) < 6
    assert read_run(out)["index"].tolist() == far
    near = tmp_path / "near"
    args = [*common, "--tasks", "6", "--max-iter", "0", "--start-x-min", str(x_max)]
    assert main([*args, "--out", str(near)]) == 0
    assert read_run(near)["index"].tolist() == [i for i, x in enumerate(starts) if x >= x_max]
    capsys.readouterr()
    for bad, says in (
        (["--jitter", "0.1,0.1,0.1"], "give --init learned:MODEL"),
        (["--init", "learned", "--jitter", "0.1,-1,0"], "three numbers >= 0"),
    ):
        assert main([*common, "--tasks", "1", "--out", str(tmp_path / "bad"), *bad]) == 1
        assert says in capsys.readouterr().err
    assert not (tmp_path / "bad" / "dataset.npz").exists()


def test_generate_cli_keeps_starts_within_the_y_bounds_and_the_box(tmp_path: Path) -> None:
    """``--start-y-max`` / ``--start-y-min`` solve only the starts right / left of a y, and
    with the x bounds only those in the box: every stored start lies within the bounds,
    and every task of the span that lies within them is solved (tasks from
    ``--first-task`` on)."""
    from roughwalk.cli.main import main
    from roughwalk.learning.task_space import ENVIRONMENTS

    space = ENVIRONMENTS["flat"]
    span = range(3, 15)
    starts = {i: space.task(i).start for i in span}
    x_cut = float(np.median([s[0] for s in starts.values()]))
    y_cut = float(np.median([s[1] for s in starts.values()]))
    common = ["init", "generate", "--env", "flat", "--steps", "4", "--duration", "2.0"]
    common += ["--tasks", "12", "--first-task", "3", "--max-iter", "0"]
    cases = {
        "right": (["--start-y-max", str(y_cut)], lambda s: s[1] <= y_cut),
        "left": (["--start-y-min", str(y_cut)], lambda s: s[1] >= y_cut),
        "corner": (
            ["--start-x-max", str(x_cut), "--start-y-max", str(y_cut)],
            lambda s: s[0] <= x_cut and s[1] <= y_cut,
        ),
    }
    for name, (bounds, inside) in cases.items():
        out = tmp_path / name
        assert main([*common, *bounds, "--out", str(out)]) == 0
        run = read_run(out)
        wanted = [i for i in span if inside(starts[i])]
        assert 0 < len(wanted) < len(span)
        assert run["index"].tolist() == wanted
        assert all(inside(start) for start in run["start"])
        assert np.array_equal(run["start"], [starts[i] for i in wanted])
    # The box is the x bounds' and the y bounds' intersection, not the y bound alone.
    corner = set(read_run(tmp_path / "corner")["index"].tolist())
    assert corner < set(read_run(tmp_path / "right")["index"].tolist())


def test_generate_cli_first_task_gives_fresh_tasks_that_aggregate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--first-task K`` solves tasks K..K+N−1 of the same stream: the tasks a run of
    K+N tasks would solve there, none of the first run's, and ``init train`` merges
    both runs into one dataset (Algorithm 1's aggregate of rounds)."""
    from roughwalk.cli.main import main
    from roughwalk.learning.task_space import ENVIRONMENTS
    from roughwalk.learning.training import load_datasets

    common = ["init", "generate", "--env", "flat", "--steps", "4", "--duration", "2.0"]
    common += ["--max-iter", "0", "--tasks", "3"]
    assert main([*common, "--out", str(tmp_path / "first")]) == 0
    assert main([*common, "--first-task", "3", "--out", str(tmp_path / "fresh")]) == 0
    fresh = read_run(tmp_path / "fresh")
    assert fresh["index"].tolist() == [3, 4, 5]
    space = ENVIRONMENTS["flat"]
    assert np.array_equal(fresh["start"], [space.task(i).start for i in (3, 4, 5)])
    merged = load_datasets([tmp_path / "first", tmp_path / "fresh"])
    assert merged["index"].tolist() == [0, 1, 2, 3, 4, 5]
    capsys.readouterr()
    assert main([*common, "--first-task", "-1", "--out", str(tmp_path / "bad")]) == 1
    assert "--first-task and --tasks must be >= 0" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()


def test_a_run_leaves_out_the_tasks_the_problem_refuses(tmp_path: Path) -> None:
    # Starts at held-out single-pallet task 189's: near the edge, turned right, one
    # front foot up the smoothed edge beyond its range of motion on some of them.
    spec = ProblemSpec("anymal_c", "single_pallet", "walk", 4, 2.0)
    space = TaskSpace(
        "edge", "single_pallet", (0.40, 0.30, -0.39), (0.50, 0.33, -0.38), (1.6, 0.0, 0.0)
    )
    refused = [i for i in range(6) if task_refusal(spec, space.task(i)) is not None]
    assert 0 < len(refused) < 6
    data = generate(spec, space, 6, tmp_path / "run", max_iter=1, progress=None)
    assert sorted(set(range(6)) - set(data["index"].tolist())) == refused
    meta = json.loads((tmp_path / "run" / "run.json").read_text())
    assert sorted(int(i) for i in meta["refused"]) == refused
    assert all("range of motion" in reason for reason in meta["refused"].values())


def test_reading_a_run_solved_before_the_refusal_leaves_the_refused_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A folder solved before tasks were refused holds their solves; resumed, it
    # records the refusals, and read_run (init train, init iterate) must leave
    # them out as generate's dataset does.
    spec = ProblemSpec("anymal_c", "single_pallet", "walk", 4, 2.0)
    space = TaskSpace(
        "edge", "single_pallet", (0.40, 0.30, -0.39), (0.50, 0.33, -0.38), (1.6, 0.0, 0.0)
    )
    refused = [i for i in range(6) if task_refusal(spec, space.task(i)) is not None]
    assert refused
    with monkeypatch.context() as m:
        m.setattr(experience, "task_refusal", lambda spec, task: None)
        generate(spec, space, 6, tmp_path / "run", max_iter=1, progress=None)
    assert read_run(tmp_path / "run")["index"].tolist() == list(range(6))
    data = generate(spec, space, 6, tmp_path / "run", max_iter=1, progress=None)
    kept = sorted(set(range(6)) - set(refused))
    assert data["index"].tolist() == kept
    assert read_run(tmp_path / "run")["index"].tolist() == kept


def test_a_task_no_longer_refused_is_solved_and_read_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A refusal recorded by an earlier check that no longer refuses the task
    # must not keep its new solve out of read_run.
    with monkeypatch.context() as m:
        m.setattr(experience, "task_refusal", lambda spec, task: "refused by an older check")
        generate(SPEC, SPACE, 2, tmp_path / "run", max_iter=1, progress=None)
    assert read_run(tmp_path / "run")["index"].tolist() == []
    data = generate(SPEC, SPACE, 2, tmp_path / "run", max_iter=1, progress=None)
    assert data["index"].tolist() == [0, 1]
    assert read_run(tmp_path / "run")["index"].tolist() == [0, 1]
    assert "refused" not in json.loads((tmp_path / "run" / "run.json").read_text())
