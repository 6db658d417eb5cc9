"""Held-out starts the solver refuses as input are drawn again, never silently dropped."""

from __future__ import annotations

import pytest
from _benchmarks import load_benchmark

from roughwalk.errors import ConfigError
from roughwalk.learning import task_space
from roughwalk.learning.problem_spec import task_refusal


def test_a_space_redraws_only_the_task_its_check_refuses_and_says_why() -> None:
    space = task_space("flat")
    first = space.task(3, seed=5, split="test")
    seen: list[tuple[float, float, float]] = []

    def refuse_first(task: object) -> str | None:
        seen.append(task.start)  # type: ignore[attr-defined]
        return "refused for the test" if len(seen) == 1 else None

    task, refused = space.draw(3, seed=5, split="test", refuse=refuse_first)
    assert refused == [(first, "refused for the test")]
    assert task.start != first.start and task.goal == first.goal
    lo, hi = space.start_low, space.start_high
    assert all(a <= v <= b for a, v, b in zip(lo, task.start, hi, strict=True))
    again, _ = space.draw(3, seed=5, split="test", refuse=lambda t: None if t != first else "x")
    assert again == task  # a redraw is the same on every run
    kept, none = space.draw(3, seed=5, split="test", refuse=lambda t: None)
    assert kept == first and none == []  # a valid task never moves


def test_a_task_refused_on_every_draw_is_an_error_that_names_the_reason() -> None:
    space = task_space("flat")
    with pytest.raises(ConfigError, match="refused 3 times.*always"):
        space.draw(0, seed=0, split="test", refuse=lambda t: "always", attempts=2)


def test_the_tracking_bench_redraws_held_out_task_6_of_seed_1_whose_stance_cannot_stand() -> None:
    bench = load_benchmark("bench_tracking")
    for env in ("double_pallet", "single_pallet"):
        _, counted, _ = bench.held_out_tasks(env, 8, seed=1, refused="count")
        _, drawn, note = bench.held_out_tasks(env, 8, seed=1)
        spec = bench._spec(env, False)
        assert task_refusal(spec, counted[6]) is not None  # the solver refuses it as input
        assert task_refusal(spec, drawn[6]) is None
        assert drawn[:6] == counted[:6] and drawn[7] == counted[7]
        assert "task 6 redrawn" in note and "too uneven for a level base" in note
