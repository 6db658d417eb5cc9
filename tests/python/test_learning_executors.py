"""The Ray executor and the local pool give the same dataset for the same seed."""

from __future__ import annotations

from pathlib import Path

import pytest

from roughwalk.learning import LocalExecutor, ProblemSpec, RayExecutor, TaskSpace, generate

SPEC = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0)
SPACE = TaskSpace("flat_small", "flat", (-0.1, -0.1, -0.2), (0.1, 0.1, 0.2), (0.4, 0.0, 0.0))
LIMIT_S = 3600.0
"""Each solve's wall-time limit [s]: the default 40 s can be reached on a loaded machine."""


def test_ray_and_local_pool_give_the_same_dataset(tmp_path: Path) -> None:
    ray = pytest.importorskip("ray")
    # The solve's wall-time limit is the one thing load can change: set far
    # beyond a solve's time, so that a starved worker still runs to the same end.
    local = generate(
        SPEC,
        SPACE,
        3,
        tmp_path / "local",
        seed=7,
        progress=None,
        executor=LocalExecutor(1),
        time_limit_s=LIMIT_S,
    )
    ray.init(num_cpus=1, include_dashboard=False, log_to_driver=False)
    try:
        remote = generate(
            SPEC,
            SPACE,
            3,
            tmp_path / "ray",
            seed=7,
            progress=None,
            executor=RayExecutor(),
            time_limit_s=LIMIT_S,
        )
    finally:
        ray.shutdown()
    assert len(remote) == 3
    # Which columns differ, if any, says where a difference came from (it
    # happened twice under heavy load, sessions 8 and 10, never when re-run).
    assert remote.differing_columns(local) == [], (local["status"], remote["status"])
    assert remote.same_rows(local)
