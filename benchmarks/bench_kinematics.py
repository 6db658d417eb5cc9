"""Leg FK and IK throughput through the Python bindings: single calls and batches.

Uses the registered LittleDog model when ``roughwalk.load_robot("littledog")``
exists, else a synthetic LittleDog-sized chain. Prints a table and writes
``benchmarks/results/kinematics.json``.

Run: ``python3 benchmarks/bench_kinematics.py [--quick]``.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from roughwalk._core import LegChain, Quadruped
from roughwalk.cli.common import machine_description, result_envelope, write_json
from roughwalk.errors import RoughwalkError

RESULTS = Path(__file__).resolve().parent / "results" / "kinematics.json"


def synthetic_littledog() -> tuple[str, Quadruped, np.ndarray]:
    """LittleDog's leg numbers (MIT's URDF) as four chains, and a stance q [rad]."""
    legs = []
    for name, front, side in (("LF", 1, 1), ("RF", 1, -1), ("LH", 0, 1), ("RH", 0, -1)):
        legs.append(
            LegChain(
                body_pos=[
                    [0.101 if front else -0.101, side * 0.03625, 0.0],
                    [0.0, side * 0.0236, -0.0166],
                    [0.0, 0.0, -0.0751],
                ],
                body_quat=[[1.0, 0.0, 0.0, 0.0]] * 3,
                anchor=np.zeros((3, 3)),
                axis=[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
                lower=[-0.6, -3.5, -3.1] if front else [-0.6, -2.4, -1.0],
                upper=[0.6, 2.4, 1.0] if front else [0.6, 3.5, 3.1],
                velocity_limit=[np.inf] * 3,
                foot=[-0.0265 if front else 0.0265, 0.0, -0.0985],
                foot_radius=0.01,
                knee_sign=-1.0 if front else 1.0,
                name=name,
            )
        )
    q = np.array([0.0, 0.6, -1.2] * 2 + [0.0, -0.6, 1.2] * 2)
    return "synthetic littledog-sized chain", Quadruped(legs), q


def littledog() -> tuple[str, Quadruped, np.ndarray]:
    """The registered LittleDog model if there is one, else the synthetic chain."""
    try:
        from roughwalk import load_robot

        robot = load_robot("littledog")
    except (ImportError, RoughwalkError):
        return synthetic_littledog()
    legs = [
        LegChain(
            d.body_pos,
            d.body_quat,
            d.anchor,
            d.axis,
            d.lower,
            d.upper,
            d.velocity_limit,
            d.foot,
            d.foot_radius,
            d.knee_sign,
            name=name,
        )
        for name, d in zip(robot.legs, robot.leg_descriptions, strict=True)
    ]
    return "littledog (load_robot)", Quadruped(legs), robot.to_canonical(robot.nominal_q)


def rate(fn: Callable[[], object], items_per_call: int, min_time: float) -> float:
    """Items per second of ``fn``, repeating it for at least ``min_time`` [s]."""
    fn()
    calls, start = 0, time.perf_counter()
    while True:
        fn()
        calls += 1
        elapsed = time.perf_counter() - start
        if elapsed >= min_time:
            return calls * items_per_call / elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter timings (smoke run)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="JSON output path")
    args = parser.parse_args()
    min_time = 0.2 if args.quick else 1.0
    batch = 2_000 if args.quick else 20_000

    model, robot, q_nominal = littledog()
    leg = robot.legs[0]
    rng = np.random.default_rng(0)
    q_leg = q_nominal[:3]
    reachable = leg.fk(q_leg)
    hip = leg.link_frames(np.zeros(3))[0][0]
    far = hip + np.array([0.3, 0.1, -0.2])

    lower = np.concatenate([lg.lower for lg in robot.legs])
    upper = np.concatenate([lg.upper for lg in robot.legs])
    q_batch = rng.uniform(lower, upper, size=(batch, 12))
    feet_batch = robot.fk_batch(q_batch)
    far_batch = feet_batch[: batch // 10] + rng.normal(scale=0.2, size=(batch // 10, 4, 3))
    feet_nominal = robot.foot_positions(q_nominal)

    rows = [
        ("LegChain.fk", "single", "feet", rate(lambda: leg.fk(q_leg), 1, min_time)),
        ("LegChain.jacobian", "single", "legs", rate(lambda: leg.jacobian(q_leg), 1, min_time)),
        ("LegChain.ik (reachable)", "single", "feet", rate(lambda: leg.ik(reachable), 1, min_time)),
        ("LegChain.ik (out of reach)", "single", "feet", rate(lambda: leg.ik(far), 1, min_time)),
        (
            "Quadruped.foot_positions",
            "single",
            "feet",
            rate(lambda: robot.foot_positions(q_nominal), 4, min_time),
        ),
        (
            "Quadruped.inverse_kinematics",
            "single",
            "feet",
            rate(lambda: robot.inverse_kinematics(feet_nominal), 4, min_time),
        ),
        (
            f"Quadruped.fk_batch (N={batch})",
            "batch",
            "feet",
            rate(lambda: robot.fk_batch(q_batch), 4 * batch, min_time),
        ),
        (
            f"Quadruped.ik_batch (N={batch}, reachable)",
            "batch",
            "feet",
            rate(lambda: robot.ik_batch(feet_batch), 4 * batch, min_time),
        ),
        (
            f"Quadruped.ik_batch (N={batch // 10}, perturbed 0.2 m)",
            "batch",
            "feet",
            rate(lambda: robot.ik_batch(far_batch), 4 * (batch // 10), min_time),
        ),
    ]
    reached = robot.ik_batch(far_batch)[1].mean()

    print(f"Kinematics throughput: {model}")
    print(f"{'operation':<48} {'kind':<7} {'per second':>14}")
    for name, kind, unit, per_s in rows:
        print(f"{name:<48} {kind:<7} {per_s:>12,.0f} {unit}")
    print(
        f"(perturbed batch: {reached:.0%} of feet reachable; the rest take the closest-point path)"
    )

    write_json(
        args.out,
        result_envelope(
            "benchmark.kinematics",
            robot=model,
            machine=machine_description(),
            quick=args.quick,
            perturbed_reachable_fraction=float(reached),
            results=[
                {"operation": n, "kind": k, "unit": u, "per_second": r} for n, k, u, r in rows
            ],
        ),
    )
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
