"""Footholds follow the base's drift from the plan (the controller's Raibert correction).

Issue 10, session 17: on the double pallet's far-corner tasks the trunk drifts
sideways off its plan during the climb (both left feet swing while the right
pair, one on the ground and one on the upper pallet, carries it). Shifted by
half that drift, the left feet land at the edge of the legs' reach, carry no
load, and the robot rolls off the pallet's side; shifted by the whole drift
they land under the trunk as planned relative to it.
"""

from __future__ import annotations

import numpy as np
import pytest
from _benchmarks import load_benchmark

pytest.importorskip("roughwalk.learning")

from roughwalk.tracking import TrackingConfig  # noqa: E402


def test_the_default_shifts_a_foothold_by_the_whole_base_position_error() -> None:
    gains = TrackingConfig().gains
    assert gains.foothold_position_gain == 1.0
    assert gains.max_foothold_shift_m == pytest.approx(0.12)


def _double_pallet_job(bench, seed: int, index: int, max_iter: int, tracking=()):  # type: ignore[no-untyped-def]
    """The tracking bench's job for held-out double-pallet task ``index`` of ``seed``."""
    terrain, tasks, _ = bench.held_out_tasks("double_pallet", index + 1, seed)
    init = bench.learned_init("double_pallet", False, None)
    constraints, costs = bench.learned_problem("double_pallet", False, init)
    task = tasks[index]
    return bench.Job(
        "double_pallet",
        terrain,
        init,
        max_iter,
        False,
        index,
        task.start,
        task.goal,
        tuple(tracking),
        constraints,
        (),
        (),
        costs,
    )


def test_a_far_corner_double_pallet_walk_tracks_with_footholds_under_the_drifted_trunk() -> None:
    """Seed 1's task 20 (start x = −0.31 m, y = −0.48 m, yaw −27°), 5 iterations, tracks to
    within 1 cm of the goal. With session 16's model its plan drifted: with half the drift
    added to the footholds the trunk ended 0.58 m right of the plan at 5.96 s and rolled
    past 45°, with the whole drift it tracked. Since session 26 the shipped model's plans
    (torque-feasible, the start box's corner grown) no longer drift that far: this task and
    seed 0's 12 and 26, seed 1's 18 and seed 3's 5 and 24 track with half the correction,
    and this one, seed 0's 12 and seed 1's 18 with none (gain 0), so the contrast no longer
    shows on a shipped plan."""
    bench = load_benchmark("bench_tracking")
    job = _double_pallet_job(bench, seed=1, index=20, max_iter=5)
    assert np.allclose(job.start, (-0.311, -0.482, -0.476), atol=2e-3)
    tracked = bench.run_job(job)
    assert tracked["success"], tracked["reason"]
    assert tracked["final_position_error_m"] < 0.01
