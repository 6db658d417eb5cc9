"""``roughwalk trajectory --plan PLAN.json``: the JSON, the samples and the picture."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

import roughwalk as rw
from roughwalk.cli.main import main
from roughwalk.trajectories import straight_crawl_plan


def _plan(tmp_path: Path) -> Path:
    robot = rw.load_robot("littledog")
    terrain = rw.load_terrain("flat:length=0.8,width=0.4")
    path = tmp_path / "plan.json"
    path.write_text(json.dumps(straight_crawl_plan(robot, terrain, (0.25, 0.0), steps=2)))
    return path


def test_trajectory_command_writes_json_samples_and_picture(tmp_path: Path, capsys) -> None:
    plan = _plan(tmp_path)
    out = tmp_path / "traj.json"
    png = tmp_path / "traj.png"
    assert main(["trajectory", "--plan", str(plan), "--json", str(out), "-o", str(png)]) == 0
    table = capsys.readouterr().out
    assert "valid 100% of 2 footsteps" in table
    data = json.loads(out.read_text())
    assert data["schema"] == "footstep_trajectories"
    assert data["robot"] == "littledog" and data["terrain"] == "flat:length=0.8,width=0.4"
    assert data["valid_fraction"] == 1.0
    keys = {
        "duration_s",
        "min_clearance_m",
        "velocity_limits_ok",
        "zmp_margin_m",
        "valid",
        "optimize_ms",
    }
    assert len(data["steps"]) == 2 and all(keys <= set(s) for s in data["steps"])
    with np.load(data["samples_npz"]) as z:
        assert z["q"].shape[1] == 12 and z["q"].shape[0] == z["time"].shape[0]
        assert list(z["joint_names"]) == list(rw.load_robot("littledog").joint_names)
        assert np.all(np.diff(z["time"]) > 0)
    assert png.stat().st_size > 10_000


def test_inline_samples_and_config_overrides(tmp_path: Path) -> None:
    plan = _plan(tmp_path)
    out = tmp_path / "traj.json"
    args = [
        "trajectory",
        "--plan",
        str(plan),
        "--json",
        str(out),
        "--inline-samples",
        "--set",
        "control_rate_hz=50",
        "--set",
        "chomp.max_iterations=5",
    ]
    assert main(args) == 0
    data = json.loads(out.read_text())
    assert (
        data["config"]["control_rate_hz"] == 50 and data["config"]["chomp"]["max_iterations"] == 5
    )
    t = np.array(data["samples"]["time"])
    assert np.allclose(np.diff(t), 0.02)
    assert not (tmp_path / "traj.npz").exists()


def test_bad_plan_file_is_reported(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert main(["trajectory", "--plan", str(bad)]) == 1
    assert "cannot read footstep plan" in capsys.readouterr().err
    assert main(["trajectory", "--plan", str(tmp_path / "missing.json")]) == 1
