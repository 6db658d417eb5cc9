"""Where a run's clock went: the shares sum to the run's time and each lands in its place."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import roughwalk
from roughwalk import _core
from roughwalk.sim import RunLog, run
from roughwalk.sim.footstep_source import PlannerSource
from roughwalk.sim.run_log import MODES, OTHER_PHASE
from roughwalk.sim.time_breakdown import time_breakdown

DT = 0.002
HAVE_PLANNER = hasattr(_core, "FootstepPlanner")


def written_log(tmp_path: Path, pieces: list[tuple[str, int, int, float]], events: list) -> RunLog:
    """A run log of ``pieces`` (mode, phase, step, seconds) back to back, read back from disk."""
    modes, phases, steps = [], [], []
    # The executor's last record: the end, no desired state.
    for mode, phase, step, seconds in [*pieces, ("done", -1, 0, DT)]:
        n = round(seconds / DT)
        modes += [MODES.index(mode)] * n
        phases += [phase] * n
        steps += [step] * n
    n = len(modes)
    feet = np.zeros((n, 4, 3))
    # The swing foot of every footstep moves 8 cm forward over its ticks.
    feet[:, :, 0] = np.linspace(0.0, 0.08, n)[:, None]
    np.savez(
        tmp_path / "run.npz",
        time=np.arange(n) * DT,
        qpos=np.zeros((n, 19)),
        mode=np.asarray(modes, dtype=np.int8),
        phase=np.asarray(phases, dtype=np.int8),
        step=np.asarray(steps, dtype=np.int16),
        feet_desired=feet,
    )
    doc = {"meta": {}, "events": events, "arrays": "run.npz"}
    (tmp_path / "run.json").write_text(json.dumps(doc))
    return RunLog.load(tmp_path / "run.json")


def test_each_share_of_a_scripted_run_lands_in_its_place(tmp_path: Path) -> None:
    # Step 1: shift 0.1 s, swing 0.4 s of which 0.1 s is stretch (fitted 0.3 s);
    # a 0.2 s wait; step 2 unstretched; a reflex's 0.5 s recovery, 0.3 s of
    # re-planning and a 0.2 s blend; the new plan's step 1, its shift
    # stretched from 0.06 to 0.1 s, held 0.05 s at its lift-off (the lift gate).
    pieces = [
        ("walk", 0, 1, 0.1),
        ("walk", 1, 1, 0.4),
        ("wait", 1, 1, 0.2),
        ("walk", 0, 2, 0.1),
        ("walk", 1, 2, 0.3),
        ("recovery", OTHER_PHASE, 0, 0.5),
        ("replan", OTHER_PHASE, 0, 0.3),
        ("walk", OTHER_PHASE, 0, 0.2),
        ("walk", 0, 1, 0.1),
        ("gate", 0, 1, 0.05),
        ("walk", 1, 1, 0.3),
    ]
    events = [
        {"time": 0.0, "kind": "step", "step": 1, "fitted_s": [0.1, 0.3], "stretch_s": [0, 0.1]},
        {"time": 0.7, "kind": "step", "step": 2, "fitted_s": [0.1, 0.3], "stretch_s": [0, 0]},
        {"time": 2.1, "kind": "step", "step": 1, "fitted_s": [0.06, 0.3], "stretch_s": [0.04, 0]},
    ]
    log = written_log(tmp_path, pieces, events)
    split = time_breakdown(log, 0.0, 2.55)
    expected = {
        "shift": 0.1 + 0.1 + 0.06,
        "swing": 0.3 + 0.3 + 0.3,
        "stretch": 0.1 + 0.04,
        "settle": 0.0,
        "wait": 0.2,
        "gate": 0.05,
        "reflex": 0.5,
        "replan": 0.3 + 0.2,
    }
    for name, seconds in expected.items():
        assert split.shares_s[name] == pytest.approx(seconds, abs=1e-9), name
    assert split.total_s == pytest.approx(2.55, abs=1e-9)
    first, second, third = split.footsteps
    assert first.stretch_s == pytest.approx(0.1) and first.wait_s == pytest.approx(0.2)
    assert second.stretch_s == 0.0 and third.stretch_s == pytest.approx(0.04)
    # The hold is the footstep's own, not its shift's stretch.
    assert third.gate_s == pytest.approx(0.05) and third.shift_s == pytest.approx(0.06)
    assert third.duration_s == pytest.approx(0.1 + 0.05 + 0.3)
    summary = split.summary()
    assert sum(summary[f"{k}_fraction"] for k in expected) == pytest.approx(1.0)


def test_a_log_without_fitted_lengths_has_no_stretch(tmp_path: Path) -> None:
    # Logs written before the step events named their fitted lengths.
    log = written_log(
        tmp_path,
        [("walk", 0, 1, 0.1), ("walk", 1, 1, 0.4)],
        [{"time": 0.0, "kind": "step", "step": 1}],
    )
    split = time_breakdown(log, 0.0, 0.5)
    assert split.shares_s["stretch"] == 0.0
    assert split.shares_s["swing"] == pytest.approx(0.4, abs=1e-9)


def test_a_forced_wait_for_optimisation_is_the_wait_share(littledog) -> None:
    # Every footstep's optimisation is charged 30 times its wall time, longer
    # than the footstep it runs beside: the robot waits between steps.
    terrain = roughwalk.load_terrain("flat")
    result = run(
        littledog,
        terrain,
        (0.25, 0.0, 0.0),
        (0.45, 0.0),
        planner=PlannerSource(littledog, terrain, expansions=2000) if HAVE_PLANNER else "crawl",
        **{"executor.compute_time_scale": 30.0},
    )
    o = result.outcome
    assert o.success, o.reason
    split = o.extra["time_breakdown"]
    # The waiting ticks on the speed's clock, counted from the log.
    t = np.asarray(result.log["time"])
    on_clock = (t >= o.extra["first_motion_s"] - 1e-9) & (t < o.extra["reached_at_s"] - 1e-9)
    waiting = np.asarray(result.log["mode"]) == MODES.index("wait")
    assert split["wait_s"] > 0.1
    assert split["wait_s"] == pytest.approx(np.count_nonzero(on_clock & waiting) * 0.002, abs=1e-6)
    shares = ("shift", "swing", "stretch", "settle", "wait", "reflex", "replan")
    assert sum(split[f"{k}_s"] for k in shares) == pytest.approx(o.time_s, abs=0.01)
    assert split["reflex_s"] == 0.0 and split["replan_s"] < 0.01
